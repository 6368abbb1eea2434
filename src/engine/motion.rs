//! The motion law between events: free flight.
//!
//! A particle last updated at `t₀` at `r₀` with velocity `v` is at
//!
//! `r(t) = r₀ + v·(t − t₀)`
//!
//! and its velocity stays `v` until an event changes it. Every place in the engine that asks
//! where a particle is, or when it reaches a plane, asks here — the particle records
//! ([`Particle::position_at`](super::Particle::position_at)), the pair search's lanes, the
//! neighbourhood's exit times, the cell crossings, the walls. A force field (gravity) would
//! change these functions and nothing else of the engine's arithmetic (the contact kernel
//! sees relative motion, which a uniform field leaves linear).
//!
//! Each function is one product and one sum (or one difference and one quotient), so the
//! same state gives the same bits wherever it is asked.

use nalgebra::SVector;

/// A coordinate `dt` after it was `x`, moving at `v`: `x + v·dt`.
#[inline(always)]
pub fn coordinate(x: f64, v: f64, dt: f64) -> f64 {
    x + v * dt
}

/// A position `dt` after it was `x`, moving at `v`: `x + v·dt`, component by component.
#[inline(always)]
pub fn position<const D: usize>(x: &SVector<f64, D>, v: &SVector<f64, D>, dt: f64) -> SVector<f64, D> {
    x + v * dt
}

/// How long a coordinate at `x`, moving at `v ≠ 0`, takes to reach `plane`: `(plane − x)/v`
/// (negative when the plane is behind).
#[inline(always)]
pub fn time_to(x: f64, v: f64, plane: f64) -> f64 {
    (plane - x) / v
}

/// How the radii change in time: the second half of the motion law.
///
/// `Fixed` is every run but a compression. `Growing` is Lubachevsky–Stillinger compression
/// with every radius growing in proportion: a particle whose `radius` field is `R` (its
/// radius at `origin`) has at time `t`
///
/// `R(t) = R + g·(t − origin)`, with `g = rate·R`,
///
/// computed by [`radius`](Self::radius) and [`speed`](Self::speed) alone, so that every
/// engine and every source gets the same bits for the same particle and time. The packing
/// fraction then grows as `φ(t) = φ(origin)·(1 + rate·(t − origin))^d`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum Radii {
    /// Radii never change.
    #[default]
    Fixed,
    /// Every radius grows at `rate` times its value at `origin`, per unit time.
    Growing {
        /// Relative growth rate (per unit time, > 0).
        rate: f64,
        /// When the particles' `radius` fields hold.
        origin: f64,
    },
}

impl Radii {
    /// The radius at time `t` of a particle whose `radius` field is `r`.
    #[inline(always)]
    pub fn radius(&self, r: f64, t: f64) -> f64 {
        match *self {
            Radii::Fixed => r,
            Radii::Growing { rate, origin } => r + (rate * r) * (t - origin),
        }
    }

    /// The growth speed `dR/dt` of a particle whose `radius` field is `r` (0 when fixed).
    #[inline(always)]
    pub fn speed(&self, r: f64) -> f64 {
        match *self {
            Radii::Fixed => 0.0,
            Radii::Growing { rate, .. } => rate * r,
        }
    }

    /// Whether the radii grow.
    #[inline(always)]
    pub fn growing(&self) -> bool {
        matches!(self, Radii::Growing { .. })
    }
}
