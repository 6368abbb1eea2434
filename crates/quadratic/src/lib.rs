//! Verified real roots of `a·x² + b·x + c = 0` and exact contact times of moving balls, in f64.
//!
//! # Overview
//!
//! * [`solve`] returns every real root of a quadratic with finite f64 coefficients as a
//!   [`Roots`] (none, one, two ascending, or all x). The root count is exact and every
//!   root is within one ulp of the exact root of the f64-valued coefficients.
//! * [`contact_time`] returns when two [`Ball`]s (disks in 2D, spheres in 3D; any `D`)
//!   first touch while approaching, as a [`Contact`] (never — and why —, now, or at `t`).
//!   The never/now/at classification is exact for the f64 inputs and `t` is within one
//!   ulp of the exact contact time of those inputs — not of rounded `a`, `b`, `c`.
//! * [`contact_time_growing`] does the same for balls whose radii grow linearly in time
//!   (`R + g·t`, Lubachevsky–Stillinger compression), where growth can outrun the motion;
//!   with no growth it is [`contact_time`], bit for bit.
//! * [`contact_bracket`] and [`contact_time_within`] serve a search for the earliest of many
//!   contacts: a certified interval for the time (or "later than the horizon") from the f64
//!   filter alone, so that only the one or two candidates that can come first pay for the
//!   double-double root. [`contact_brackets`] does the same for a batch of pairs held in
//!   [`BallLanes`] (structure of arrays), branch-free, so that the pairs share vector registers;
//!   [`contact_brackets_from_origin`] the same, bit for bit, when every first ball sits at the
//!   origin (an engine's frame of the particle it predicts), with a few operations less a lane;
//!   [`contact_clear_until_from_origin`] screens such a batch for the lanes certainly clear of
//!   a horizon (receding, or meeting later), so that a search can skip a chunk of them.
//! * [`narrow_contact`] pins a contact time to two adjacent doubles from a guess (one
//!   compensated, certified evaluation of the gap function), and [`Narrowed::time`] tells
//!   which — for a caller that needs `t₀ + t` exactly when a bracket leaves two candidates.
//! * [`exact`] holds the error-free building blocks (TwoSum, FMA TwoProd, Shewchuk
//!   expansions, double-double); [`hex`] reads and writes C99 hex floats; [`textbook`]
//!   is the seed's naive formula, kept only for comparison.
//!
//! Data flows one way: f64 inputs → exact differences (TwoSum) → certified f64 /
//! double-double evaluation, or exact expansions when a bound cannot decide → one rounding.
//! Nothing allocates except the rare exact path. No dependencies, no `unsafe`.
//!
//! The crate's `README.md` is the edge-case reference: one row per hard case with the
//! textbook answer, this crate's answer and the exact one.
//!
//! # Example
//!
//! ```
//! use quadratic::{contact_time, solve, Ball, Contact, Roots};
//!
//! // Cancellation: the textbook formula returns 0 for the small root of x² − 1e9·x + 1.
//! assert_eq!(solve(1.0, -1e9, 1.0), Ok(Roots::Two(1e-9, 1e9)));
//!
//! // Two unit disks 1e9 apart at large coordinates, head on: exact differences, exact time.
//! let p = Ball { position: [1e9, 0.0], velocity: [0.5, 0.0], radius: 0.5 };
//! let q = Ball { position: [2e9 + 1.0, 0.0], velocity: [-0.5, 0.0], radius: 0.5 };
//! assert_eq!(contact_time(&p, &q), Ok(Contact::At(1e9)));
//! ```
#![forbid(unsafe_code)]
#![warn(missing_docs)]

pub mod contact;
pub mod exact;
pub mod growing;
pub mod hex;
pub mod reference;
pub mod roots;
pub mod textbook;

#[doc(hidden)]
pub use contact::contact_time_exact_path;
pub use contact::{
    Ball, BallLanes, Bracket, Contact, ContactError, Field, Miss, Narrowed, contact_bracket, contact_brackets,
    contact_brackets_from_origin, contact_clear_until_from_origin, contact_time, contact_time_unchecked,
    contact_time_within, narrow_contact,
};
#[doc(hidden)]
pub use growing::contact_time_growing_exact_path;
pub use growing::{contact_time_growing, contact_time_growing_unchecked};
pub use roots::{Coefficient, Roots, SolveError, solve};

/// Uniform numbers in [0, 1) from xorshift64* with a fixed seed: the unit tests' families,
/// the same on every machine.
#[cfg(test)]
pub(crate) fn uniform_stream(seed: u64) -> impl FnMut() -> f64 {
    let mut state = seed;
    move || {
        state ^= state >> 12;
        state ^= state << 25;
        state ^= state >> 27;
        (state.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11) as f64 / (1u64 << 53) as f64
    }
}
