//! # collide
//!
//! Event-driven molecular dynamics of hard disks (and spheres), built on collision numerics
//! that are verified rather than hoped for.
//!
//! ## Overview
//!
//! * [`quadratic`] (a workspace crate, re-exported) answers the two numerical questions of
//!   an event-driven code exactly: the real roots of a quadratic ([`quadratic::solve`]) and
//!   the earliest contact time of two moving balls ([`quadratic::contact_time`]), with exact
//!   never/now/at classification and times within one ulp.
//! * [`engine`] turns a contact into new velocities: [`engine::resolve_pair`] applies the
//!   mass-weighted collision rule along the line of centres and reports the
//!   [`engine::Impulse`] the pressure observers need.
//! * [`io`] reads and writes numbers exactly and serves the JSON-lines query protocol of
//!   `collide roots` and `collide contact-time`.
//!
//! Data flows one way: inputs → contact time (predict, pure) → velocity update (resolve,
//! mutating) → impulse → observables.
//!
//! ## Example
//!
//! ```
//! use collide::engine::{Body, Restitution, resolve_pair};
//! use collide::quadratic::{Ball, Contact, contact_time};
//! use nalgebra::vector;
//!
//! // Predict: two unit disks approaching head on meet at t = 1.
//! let p = Ball { position: [0.0, 0.0], velocity: [1.0, 0.0], radius: 0.5 };
//! let q = Ball { position: [3.0, 0.0], velocity: [-1.0, 0.0], radius: 0.5 };
//! let Ok(Contact::At(t)) = contact_time(&p, &q) else { panic!() };
//! assert_eq!(t, 1.0);
//!
//! // Resolve: move to contact, collide; equal masses exchange velocities.
//! let at = |b: &Ball<2>| vector![b.position[0] + b.velocity[0] * t, b.position[1] + b.velocity[1] * t];
//! let mut a = Body { position: at(&p), velocity: vector![1.0, 0.0], mass: 1.0 };
//! let mut b = Body { position: at(&q), velocity: vector![-1.0, 0.0], mass: 1.0 };
//! let impulse = resolve_pair(&mut a, &mut b, Restitution::ELASTIC);
//! assert_eq!(b.velocity, vector![1.0, 0.0]);
//! assert_eq!(impulse.virial(), 2.0); // σ·|Δp| with σ = 1, |Δp| = 2
//! ```
// Denied, not forbidden: the two exceptions are the cache hint in `engine/prefetch.rs` (a
// prefetch never faults and changes no state, but Rust's intrinsic takes a raw pointer) and
// the request for huge pages in `engine/pages.rs` (it changes no contents either).
#![deny(unsafe_code)]
#![warn(missing_docs)]

pub mod engine;
pub mod io;
pub mod lab;
pub mod observe;
pub mod run;
pub mod theory;

pub use quadratic;
