//! Growth: Lubachevsky–Stillinger compression, as a global event source and a thermostat.
//!
//! While a [`Growth`] is under way every radius grows in proportion, `R(t) = R + rate·R·(t −
//! origin)` (the motion law's [`Radii::Growing`]): pair and wall predictions use the growing
//! kernel, and the collision rule reverses the gap's closing speed, which injects energy.
//!
//! *Predict* (pure): the end of the growth, `until` — a global event, kept beside the queue
//! like sampling and ordered after it among simultaneous events. *Resolve* (mutating): every
//! particle is advanced to `until` and its `radius` set to its grown value; from then on the
//! radii are fixed. The packing fraction at the end is `φ(origin)·(1 + rate·(until −
//! origin))^d`.
//!
//! The thermostat: after every `every`-th pair collision of the growth, every particle is
//! advanced to the collision's time and all velocities are scaled by one factor so that
//! `kT = 2K/f` (`f` the degrees of freedom) is the target again. It is part of that
//! collision's resolution in both engines, so the fast engine and the reference rescale at
//! the same instants, by the same factor, to the bit.
//!
//! The stall guard: a packing compressed to its jamming density has a diverging collision
//! rate — the collision times converge, and in f64 they end up equal, every collision at the
//! same instant. Growth cannot continue (no time passes), so after
//! [`stall_limit`]`(N)` consecutive pair collisions at one instant the growth ends there
//! ([`Ending::Stalled`]), in both engines alike: a target beyond jamming ends in a jammed
//! packing, never in a hang.

use crate::engine::geometry::Particle;
use crate::engine::motion::Radii;
use serde::{Deserialize, Serialize};
use std::fmt;

/// A compression in progress: its schedule and its thermostat.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Growth {
    /// Relative growth rate: `dRᵢ/dt = rate·Rᵢ(origin)` (> 0).
    pub rate: f64,
    /// When the particles' `radius` fields hold.
    pub origin: f64,
    /// When the growth ends (finite, after `origin`).
    pub until: f64,
    /// The thermostat's target `kT` (> 0).
    pub kt: f64,
    /// Pair collisions between rescalings of the velocities (≥ 1).
    pub every: u64,
    /// Pair collisions since `origin`.
    pub collisions: u64,
    /// The time of the last pair collision of the growth.
    #[serde(default)]
    pub last: f64,
    /// Consecutive pair collisions at `last` (the stall guard).
    #[serde(default)]
    pub same_time: u64,
}

/// Why a growth ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Ending {
    /// At its `until`: the target was reached.
    Reached,
    /// The clock stalled (see the module docs): the packing jammed before `until`.
    Stalled,
    /// Ended early by the caller ([`Simulation::end_growth`](crate::engine::Simulation::end_growth)).
    Stopped,
}

/// What one pair collision did to a growth.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AfterCollision {
    /// Nothing beyond counting it.
    Counted,
    /// The thermostat rescaled every velocity (every particle moved).
    Rescaled,
    /// The clock has stalled: the growth must end now.
    Stalled,
}

/// Consecutive pair collisions at one instant after which a growth of `n` particles has
/// stalled: far more than any configuration's simultaneous contacts (a lattice start touches
/// each pair once), far fewer than a hang.
pub fn stall_limit(n: usize) -> u64 {
    16 * n as u64 + 1024
}

/// Why a growth was refused.
#[non_exhaustive]
#[derive(Clone, Debug, PartialEq)]
pub enum GrowthError {
    /// A field outside what is allowed.
    Field {
        /// The field.
        field: &'static str,
        /// Its value.
        value: f64,
        /// What is allowed.
        allowed: &'static str,
    },
}

impl fmt::Display for GrowthError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            GrowthError::Field { field, value, allowed } => {
                write!(f, "growth {field} = {value} is not allowed: it must be {allowed}")
            }
        }
    }
}

impl std::error::Error for GrowthError {}

impl Growth {
    /// A growth from `origin` to `until` at relative `rate`, rescaling to `kt` every `every`
    /// pair collisions; validated.
    pub fn new(rate: f64, origin: f64, until: f64, kt: f64, every: u64) -> Result<Growth, GrowthError> {
        let bad = |field, value, allowed| Err(GrowthError::Field { field, value, allowed });
        if !(rate.is_finite() && rate > 0.0) {
            return bad("rate", rate, "finite and > 0");
        }
        if !origin.is_finite() {
            return bad("origin", origin, "finite");
        }
        if !(until.is_finite() && until > origin) {
            return bad("until", until, "finite and after the origin");
        }
        if !(kt.is_finite() && kt > 0.0) {
            return bad("kT", kt, "finite and > 0");
        }
        if every == 0 {
            return bad("thermostat interval", 0.0, "at least one collision");
        }
        Ok(Growth { rate, origin, until, kt, every, collisions: 0, last: origin, same_time: 0 })
    }

    /// The motion law's radii while this growth lasts.
    #[inline]
    pub fn radii(&self) -> Radii {
        Radii::Growing { rate: self.rate, origin: self.origin }
    }

    /// The largest radius the particles reach (at `until`).
    pub fn final_radius<const D: usize>(&self, particles: &[Particle<D>]) -> f64 {
        self.largest_radius(particles, self.until)
    }

    /// The largest radius at time `t` (by the motion law: the same bits as every
    /// prediction, and never smaller at a later time, each operation being monotone).
    pub fn largest_radius<const D: usize>(&self, particles: &[Particle<D>], t: f64) -> f64 {
        let radii = self.radii();
        particles.iter().map(|p| radii.radius(p.radius, t)).fold(0.0, f64::max)
    }

    /// When every radius will be `factor` (> 1) times what it is at `now`: the time `t`
    /// with `1 + rate·(t − origin) = factor·(1 + rate·(now − origin))`, or `until` if that
    /// comes first (or if rounding leaves `t` no later than `now`).
    pub fn grown_by(&self, now: f64, factor: f64) -> f64 {
        let t = self.origin + (factor * (1.0 + self.rate * (now - self.origin)) - 1.0) / self.rate;
        if t > now && t < self.until { t } else { self.until }
    }

    /// The end of the growth (the global event's time).
    #[inline]
    pub fn predict(&self) -> f64 {
        self.until
    }

    /// Ends the growth at `t` (its `until`, or earlier): every particle advanced there, its
    /// radius set to the grown value, its counter advanced (every pending prediction is
    /// stale).
    pub fn resolve<const D: usize>(&self, particles: &mut [Particle<D>], t: f64) {
        let radii = self.radii();
        for p in particles.iter_mut() {
            p.advance(t);
            p.radius = radii.radius(p.radius, t);
            p.events = p.events.wrapping_add(1);
        }
    }

    /// Counts one pair collision at time `t`: reports a stalled clock, or on every
    /// `every`-th collision rescales the velocities to the target `kT` (see the module
    /// docs); `dof` is the number of degrees of freedom.
    pub fn after_collision<const D: usize>(
        &mut self,
        particles: &mut [Particle<D>],
        t: f64,
        dof: f64,
    ) -> AfterCollision {
        self.collisions += 1;
        if t == self.last {
            self.same_time += 1;
        } else {
            (self.last, self.same_time) = (t, 0);
        }
        if self.same_time >= stall_limit(particles.len()) {
            return AfterCollision::Stalled;
        }
        if !self.collisions.is_multiple_of(self.every) {
            return AfterCollision::Counted;
        }
        rescale(particles, t, self.kt, dof);
        AfterCollision::Rescaled
    }
}

/// Advances every particle to `t` and scales all velocities by `√(kt/kT)`, where
/// `kT = 2K/dof` sums the kinetic energies in index order; every counter advances. Particles
/// at rest (no energy) are left so.
pub fn rescale<const D: usize>(particles: &mut [Particle<D>], t: f64, kt: f64, dof: f64) {
    let energy: f64 = particles.iter().map(Particle::kinetic_energy).sum();
    let now = 2.0 * energy / dof;
    let factor = if now > 0.0 { (kt / now).sqrt() } else { 1.0 };
    for p in particles.iter_mut() {
        p.advance(t);
        p.velocity *= factor;
        p.events = p.events.wrapping_add(1);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::SVector;

    fn particle(x: f64, v: f64, r: f64) -> Particle<2> {
        Particle {
            position: SVector::from([x, 0.0]),
            velocity: SVector::from([v, 0.0]),
            time: 0.0,
            radius: r,
            mass: 1.0,
            species: 0,
            events: 0,
        }
    }

    #[test]
    fn growth_is_validated_field_by_field() {
        assert!(Growth::new(0.1, 0.0, 1.0, 1.0, 10).is_ok());
        let message = |g: Result<Growth, GrowthError>| g.unwrap_err().to_string();
        assert_eq!(
            message(Growth::new(0.0, 0.0, 1.0, 1.0, 1)),
            "growth rate = 0 is not allowed: it must be finite and > 0"
        );
        assert!(message(Growth::new(0.1, 0.0, 0.0, 1.0, 1)).contains("until = 0"));
        assert!(message(Growth::new(0.1, 0.0, f64::INFINITY, 1.0, 1)).contains("until = inf"));
        assert!(message(Growth::new(0.1, 0.0, 1.0, -1.0, 1)).contains("kT = -1"));
        assert!(message(Growth::new(0.1, 0.0, 1.0, 1.0, 0)).contains("at least one collision"));
    }

    /// The end freezes each radius at `R·(1 + rate·(until − origin))` and moves everyone to
    /// `until`; the thermostat fires on every `every`-th collision and restores kT exactly
    /// (to rounding).
    #[test]
    fn the_end_freezes_the_radii_and_the_thermostat_restores_kt() {
        let mut ps = vec![particle(0.0, 1.0, 0.5), particle(3.0, -2.0, 0.25)];
        let g = Growth::new(0.5, 1.0, 3.0, 1.0, 2).unwrap();
        assert_eq!(g.final_radius(&ps), 1.0);
        g.resolve(&mut ps, g.until);
        assert_eq!((ps[0].radius, ps[1].radius), (1.0, 0.5));
        assert_eq!((ps[0].time, ps[0].position[0], ps[1].position[0]), (3.0, 3.0, -3.0));
        assert_eq!(ps[0].events, 1);
        let mut g = Growth::new(0.5, 3.0, 4.0, 2.0, 2).unwrap();
        assert_eq!(g.after_collision(&mut ps, 3.5, 2.0), AfterCollision::Counted);
        assert_eq!(g.after_collision(&mut ps, 3.5, 2.0), AfterCollision::Rescaled);
        let kt = ps.iter().map(Particle::kinetic_energy).sum::<f64>() * 2.0 / 2.0;
        assert!((kt - 2.0).abs() <= 4.0 * f64::EPSILON, "{kt}");
        assert_eq!(ps[1].time, 3.5);
        // The stall guard: the limit's worth of collisions at one instant, not one fewer.
        let mut g = Growth::new(0.5, 3.5, 4.0, 2.0, u64::MAX).unwrap();
        assert_eq!(g.after_collision(&mut ps, 3.6, 2.0), AfterCollision::Counted);
        for _ in 1..stall_limit(2) {
            assert_eq!(g.after_collision(&mut ps, 3.6, 2.0), AfterCollision::Counted);
        }
        assert_eq!(g.after_collision(&mut ps, 3.6, 2.0), AfterCollision::Stalled);
        assert_eq!(g.after_collision(&mut ps, 3.7, 2.0), AfterCollision::Counted, "time moved on");
    }
}
