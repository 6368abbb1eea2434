//! The product's integration tests, one test binary: every file here is a module of it.
//!
//! One binary rather than one per file: the engine is generic, so each test binary compiled
//! and optimised its own copies of it, and linked the whole library again — most of a CI
//! build's time went there. In one binary the tests also share the two cores, instead of
//! waiting on each other file by file. Run one file's tests with a filter:
//! `cargo test --release --test product -- lab::`.
//!
//! The tests of each module use their own scratch directories (named after the test), as
//! they all run in one process.

mod common;

mod bad_input;
mod bench;
mod cli;
mod cli_run;
mod compress;
mod dimensions;
mod engine;
mod fuzz;
mod growth;
mod init;
mod lab;
mod observe_rdf;
mod observe_transport;
mod physics;
mod sweep;
