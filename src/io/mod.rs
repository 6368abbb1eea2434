//! Everything that touches text and files: exact number parsing and formatting, the
//! JSON-lines query protocol of `collide roots` and `collide contact-time`, the run
//! configuration, the output directory and the files of a run, and short messages about
//! bad input.

pub mod config;
pub mod numbers;
pub mod output;
pub mod query;
pub mod rundir;
pub mod text;
