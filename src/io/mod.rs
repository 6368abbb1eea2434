//! Everything that touches text: exact number parsing and formatting, and the JSON-lines
//! query protocol of `collide roots` and `collide contact-time`.

pub mod config;
pub mod numbers;
pub mod output;
pub mod query;
