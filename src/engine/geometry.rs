//! Particles and the box: state, boundaries and the minimum-image convention.

use nalgebra::SVector;
use serde::{Deserialize, Serialize};

/// What happens at the two ends of one axis of the box.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Boundary {
    /// The axis wraps around (minimum-image convention).
    Periodic,
    /// Hard, elastic walls at 0 and L.
    Wall,
}

/// An axis-aligned box `[0, L₁) × … × [0, L_D)` with a boundary per axis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SimBox<const D: usize> {
    /// Edge lengths.
    pub lengths: SVector<f64, D>,
    /// Boundary per axis.
    pub boundary: [Boundary; D],
}

impl<const D: usize> SimBox<D> {
    /// The volume (area in 2D).
    pub fn volume(&self) -> f64 {
        self.lengths.iter().product()
    }

    /// Number of periodic axes (each conserves one component of the total momentum).
    pub fn periodic_axes(&self) -> usize {
        self.boundary.iter().filter(|b| **b == Boundary::Periodic).count()
    }

    /// The image shift to add to `d = r_j − r_i` so that each periodic component lies in
    /// `[−L/2, L/2]` (minimum image); zero along walled axes. Always `count·L` for the
    /// integer counts of [`minimum_image_count`](Self::minimum_image_count).
    pub fn minimum_image_shift(&self, d: &SVector<f64, D>) -> SVector<f64, D> {
        self.minimum_image_count(d).component_mul(&self.lengths)
    }

    /// The number of box lengths (an integer, as f64) to add along each axis for the
    /// minimum image of `d`; zero along walled axes.
    pub fn minimum_image_count(&self, d: &SVector<f64, D>) -> SVector<f64, D> {
        let mut count = SVector::zeros();
        for a in 0..D {
            if self.boundary[a] == Boundary::Periodic {
                count[a] = -(d[a] / self.lengths[a]).round();
            }
        }
        count
    }

    /// The accessible volume for centres of disks of diameter `sigma`: `L − σ` along walled
    /// axes, `L` along periodic ones.
    pub fn accessible_volume(&self, sigma: f64) -> f64 {
        (0..D).map(|a| self.accessible_length(a, sigma)).product()
    }

    /// `L − σ` along a walled axis, `L` along a periodic one.
    pub fn accessible_length(&self, axis: usize, sigma: f64) -> f64 {
        match self.boundary[axis] {
            Boundary::Periodic => self.lengths[axis],
            Boundary::Wall => self.lengths[axis] - sigma,
        }
    }
}

/// One hard disk (sphere): its state at its own last-update time.
///
/// Positions are stored *unwrapped* at time `time` and advanced lazily: the position at any
/// `t` is `position + velocity·(t − time)`. Periodic images are tracked by the cell grid,
/// so a position is never shifted by a box length (which would round).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Particle<const D: usize> {
    /// Position at `time`.
    pub position: SVector<f64, D>,
    /// Velocity (constant between events).
    pub velocity: SVector<f64, D>,
    /// The time at which `position` holds.
    pub time: f64,
    /// Radius (> 0).
    pub radius: f64,
    /// Mass (> 0).
    pub mass: f64,
    /// Species index (into the configuration's species list).
    pub species: usize,
    /// Event counter: incremented whenever the velocity changes; an event predicted with an
    /// older count is stale.
    pub events: u64,
}

impl<const D: usize> Particle<D> {
    /// Position at time `t`.
    #[inline]
    pub fn position_at(&self, t: f64) -> SVector<f64, D> {
        self.position + self.velocity * (t - self.time)
    }

    /// Moves the stored state to time `t`.
    #[inline]
    pub fn advance(&mut self, t: f64) {
        self.position = self.position_at(t);
        self.time = t;
    }

    /// Kinetic energy ½m|v|².
    pub fn kinetic_energy(&self) -> f64 {
        0.5 * self.mass * self.velocity.norm_squared()
    }
}
