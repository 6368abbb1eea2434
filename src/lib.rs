//! # collide
//!
//! Event-driven molecular dynamics of hard disks and spheres, built on collision numerics
//! that are verified rather than hoped for.
//!
//! ## Brief overview
//!
//! The main types, in the order data flows through them:
//!
//! * A [`Simulation`](engine::Simulation) holds the particles in a box and processes one
//!   event at a time ([`step`](engine::Simulation::step)): the earliest of every particle's
//!   predicted events — a pair collision, a wall, a neighbourhood update, a sample — is
//!   resolved by its [source](engine::sources) and reported as an
//!   [`Outcome`](engine::Outcome). Contact times come from the workspace crate
//!   [`quadratic`] (exact never/now/at classification, times within one ulp).
//! * An [`Observer`](observe::Observer) is fed every outcome with the simulation as the
//!   event left it, and keeps what it measures: [`Thermo`](observe::Thermo) the temperature
//!   and the pressures, the registered observables what a configuration names
//!   ([`observe::Selection`]), an experiment's own observers whatever it needs.
//! * A [`Run`](run::Run) owns the loop: from a [`Config`](run::Config) it builds the initial
//!   state, equilibrates, and runs the production, feeding its observers and a
//!   [`Sink`](run::Sink) (the files of `collide run`; every observer is one); it reports a
//!   [`Summary`](run::Summary) and saves [`Checkpoint`](run::Checkpoint)s that continue it
//!   bit-identically.
//! * A [`sweep`] is many runs of one configuration with values varied, each task a run
//!   directory of its own, run in parallel processes or as a scheduler's job array, and
//!   collected into one table.
//! * The [`lab`] turns runs into checks against the formulas of [`theory`]; [`bench`](mod@bench) times
//!   the engine beside the hardware's floor; [`query`] answers the numerical questions of
//!   `collide roots` and `collide contact-time` line by line.
//!
//! Each arrow runs one way: the engine knows no files, the observers know no runs, the
//! kernel knows no particles, and nothing below `main.rs` draws to a terminal.
//!
//! ## Example
//!
//! A dilute gas of hard disks, with an observer of our own beside the run's:
//!
//! ```
//! use collide::engine::{Outcome, Simulation};
//! use collide::observe::Observer;
//! use collide::run::{Config, Run};
//!
//! let config = Config::parse(
//!     r#"
//!     seed = 1
//!     [box]
//!     packing_fraction = 0.3
//!     boundary = "periodic"
//!     [[species]]
//!     count = 400
//!     radius = 0.5
//!     mass = 1.0
//!     [equilibration]
//!     collisions = 20000
//!     [run]
//!     collisions = 100000
//!     "#,
//!     "example",
//! )?;
//! let mut run = Run::<2>::new(config)?;
//!
//! /// Counts the pair collisions of the production.
//! struct Collisions(u64);
//! impl Observer<2> for Collisions {
//!     fn observe(&mut self, _: &Simulation<2>, outcome: &Outcome<2>) {
//!         if let Outcome::Pair { .. } = outcome {
//!             self.0 += 1;
//!         }
//!     }
//! }
//! let mut seen = Collisions(0);
//! let Ok(_) = run.complete(&mut seen);
//!
//! let summary = run.summary();
//! assert_eq!(seen.0, summary.collisions);
//! // Henderson's equation of state, to a few per cent at this size and length.
//! let z = summary.compressibility;
//! assert!((z / collide::theory::z_henderson(0.3) - 1.0).abs() < 0.03, "Z = {z}");
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
// Denied, not forbidden: the two exceptions are the cache hint in
// `engine/timing/prefetch.rs` (a prefetch never faults and changes no state, but Rust's
// intrinsic takes a raw pointer) and the request for huge pages in
// `engine/timing/pages.rs` (it changes no contents either).
#![deny(unsafe_code)]
#![warn(missing_docs)]

pub mod bench;
pub mod engine;
pub mod lab;
pub mod observe;
pub mod query;
pub mod run;
pub mod sweep;
pub mod text;
pub mod theory;

pub use quadratic;
