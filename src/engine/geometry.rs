//! Particles and the box: state, boundaries and the minimum-image convention.

use super::motion;
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

    /// Degrees of freedom of the kinetic energy of `n` particles in this box: `d·n` less one
    /// per periodic axis (the total momentum along a periodic axis is conserved, and zeroed
    /// by the initial state).
    pub fn degrees_of_freedom(&self, n: usize) -> f64 {
        (D * n - self.periodic_axes()) as f64
    }

    /// The image shift to add to `d = r_j − r_i` so that each periodic component lies in
    /// `[−L/2, L/2]` (minimum image); zero along walled axes. Always `count·L` for the
    /// integer counts of [`minimum_image_count`](Self::minimum_image_count).
    pub fn minimum_image_shift(&self, d: &SVector<f64, D>) -> SVector<f64, D> {
        self.minimum_image_count(d).component_mul(&self.lengths)
    }

    /// The number of box lengths (an integer, as f64) to add along each axis for the
    /// minimum image of `d`; zero along walled axes. It is `−round(d/L)` to the last bit
    /// (the sign of a zero included).
    ///
    /// Nearly every call asks about two neighbours, whose separation is far from `L/2` and
    /// `3L/2`; there the answer follows from comparisons, without a division on the critical
    /// path of every pair prediction: `|d| < fl(0.49·L)` gives `|fl(d/L)| ≤ 0.49(1 + u)² < ½`,
    /// a zero with the sign of `d`; and `fl(0.51·L) < |d| < fl(1.49·L)` gives
    /// `½ < |fl(d/L)| < 3/2`, one with the sign of `d`.
    pub fn minimum_image_count(&self, d: &SVector<f64, D>) -> SVector<f64, D> {
        let mut count = SVector::zeros();
        for a in 0..D {
            if self.boundary[a] == Boundary::Periodic {
                count[a] = image_count(d[a], self.lengths[a]);
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

/// `−round(x/l)` for `l > 0` (see [`SimBox::minimum_image_count`]).
pub(crate) fn image_count(x: f64, l: f64) -> f64 {
    match image_count_by_comparison(x, l) {
        (count, true) => count,
        _ => -(x / l).round(),
    }
}

/// [`image_count`] where comparisons decide it, as selects (so that vector lanes can use it):
/// `|x| < fl(0.49·l)` gives 0 and `fl(0.51·l) < |x| < fl(1.49·l)` gives 1, with the sign of
/// `−x`; the flag says whether one of them held — if not, `|x|` is near `l/2` or beyond
/// `3l/2`, and the count takes the division.
#[inline(always)]
pub(crate) fn image_count_by_comparison(x: f64, l: f64) -> (f64, bool) {
    let ax = x.abs();
    let small = ax < 0.49 * l;
    let one = ax > 0.51 * l && ax < 1.49 * l;
    let count = if small { -(0.0f64.copysign(x)) } else { -(1.0f64.copysign(x)) };
    (count, small | one)
}

/// One hard disk (sphere): its state at its own last-update time.
///
/// Positions are stored *unwrapped* at time `time` and advanced lazily: the position at any
/// `t` is `position + velocity·(t − time)`. Periodic images are tracked by the cell grid,
/// so a position is never shifted by a box length (which would round).
///
/// In 2D a record is 64 bytes and aligned to 64: exactly one cache line, so that reading a
/// neighbour costs one line (a record that straddles two lines costs two misses at large N).
/// In 3D it takes two lines (80 bytes, padded to 128).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[repr(C, align(64))]
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
    pub species: u32,
    /// Event counter: incremented (modulo 2³²) whenever the velocity changes; an event
    /// predicted with another count is stale. A counter that wraps to 0 makes the
    /// [`Simulation`](super::Simulation) predict every particle again, so that no pending
    /// event can outlive 2³² changes of its partner and take it for a live one.
    pub events: u32,
}

// One cache line per disk (see `Particle`).
const _: () = assert!(size_of::<Particle<2>>() == 64);

impl<const D: usize> Particle<D> {
    /// Position at time `t` (the [motion law](super::motion)).
    #[inline]
    pub fn position_at(&self, t: f64) -> SVector<f64, D> {
        motion::position(&self.position, &self.velocity, t - self.time)
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

#[cfg(test)]
mod tests {
    use super::image_count;
    use rand::rngs::Xoshiro256PlusPlus;
    use rand::{RngExt, SeedableRng};

    /// The comparisons give `−round(x/l)` bit for bit: at and one or two ulps around every
    /// threshold (0.49, ½, 0.51, 1.49, 3/2 box lengths), at zeros of both signs, and at many
    /// pseudo-random separations, for box lengths of many magnitudes.
    #[test]
    fn image_count_is_minus_round_of_the_quotient() {
        let step = |x: f64, k: i64| f64::from_bits((x.to_bits() as i64 + k) as u64);
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(11);
        let mut checked = 0;
        for &l in &[1.0, 3.0, 7.3, 40.0, 109.87, 1e-300, 1e300, 0.1 + 0.2] {
            let mut xs = vec![0.0, -0.0, l, -l];
            for f in [0.49, 0.5, 0.51, 1.49, 1.5, 2.5] {
                let t = f * l;
                for k in -3..=3 {
                    xs.push(step(t, k));
                    xs.push(-step(t, k));
                }
            }
            for _ in 0..20_000 {
                let x: f64 = rng.random_range(-2.0..2.0) * l;
                xs.push(x);
            }
            for x in xs {
                let want = -(x / l).round();
                assert_eq!(image_count(x, l).to_bits(), want.to_bits(), "x = {x:e}, l = {l:e}");
                checked += 1;
            }
        }
        assert!(checked > 100_000);
    }
}
