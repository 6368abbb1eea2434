//! What makes a valid start: the particles, the box, and the errors that say what is wrong
//! with them.

use super::geometry::{Boundary, Particle, SimBox};
use super::sources::MAX_PARTICLES;
use serde::{Deserialize, Serialize};
use std::fmt;

/// Why a set of particles and a box cannot be simulated.
#[non_exhaustive]
#[derive(Clone, Debug, PartialEq)]
pub enum SetupError {
    /// No particles.
    Empty,
    /// A non-finite or non-positive radius or mass, or a non-finite coordinate.
    BadParticle {
        /// Which particle.
        index: usize,
        /// Which field.
        field: &'static str,
        /// Its value.
        value: f64,
    },
    /// A box edge too short for the largest contact distance.
    BoxTooSmall {
        /// The axis.
        axis: usize,
        /// Its length.
        length: f64,
        /// The smallest length allowed (between walls, the edge must be longer).
        minimum: f64,
        /// Whether the axis has walls.
        walls: bool,
    },
    /// A particle outside the walls.
    OutsideBox {
        /// Which particle.
        index: usize,
        /// Along which axis.
        axis: usize,
        /// Its coordinate.
        coordinate: f64,
    },
    /// More particles than the engine indexes (32-bit indices).
    TooMany {
        /// How many were given.
        n: usize,
    },
    /// A saved state that does not fit together.
    BadState {
        /// What is wrong.
        what: String,
    },
    /// Two particles overlap.
    Overlap {
        /// Lower index.
        i: usize,
        /// Higher index.
        j: usize,
        /// Overlap as a fraction of their contact distance.
        fraction: f64,
    },
    /// A growth (compression) that cannot start: a bad schedule, or one already under way.
    Growth {
        /// What is wrong.
        what: String,
    },
}

impl fmt::Display for SetupError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SetupError::Empty => write!(f, "there are no particles"),
            SetupError::BadParticle { index, field, value } => {
                write!(
                    f,
                    "particle {index}: {field} = {value} (must be finite{})",
                    if matches!(*field, "radius" | "mass") { " and > 0" } else { "" }
                )
            }
            SetupError::BoxTooSmall { axis, length, minimum, walls: false } => {
                write!(
                    f,
                    "box edge {axis} = {length} is too short: a periodic edge must be at least {minimum} (two largest contact distances, so that a disk meets one image of another)"
                )
            }
            SetupError::BoxTooSmall { axis, length, minimum, walls: true } => {
                write!(
                    f,
                    "box edge {axis} = {length} is too short: between walls it must be longer than the largest diameter {minimum}"
                )
            }
            SetupError::OutsideBox { index, axis, coordinate } => {
                write!(f, "particle {index} is outside the walls along axis {axis} (coordinate {coordinate})")
            }
            SetupError::TooMany { n } => {
                write!(f, "{n} particles: the engine handles at most {}", MAX_PARTICLES)
            }
            SetupError::BadState { what } => write!(f, "inconsistent saved state: {what}"),
            SetupError::Overlap { i, j, fraction } => {
                write!(f, "particles {i} and {j} overlap by {:.3e} of their contact distance", fraction)
            }
            SetupError::Growth { what } => write!(f, "cannot grow the particles: {what}"),
        }
    }
}

impl std::error::Error for SetupError {}

/// The largest overlap found by [`Simulation::check_overlaps`](super::Simulation::check_overlaps).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct OverlapAudit {
    /// Largest overlap as a fraction of the contact distance (pairs) or the diameter
    /// (walls); 0 when nothing overlaps.
    pub fraction: f64,
    /// The pair (or `(i, i)` for a wall) where it occurs.
    pub at: Option<(usize, usize)>,
}

/// The largest overlap a saved state may hold (a fraction of the contact distance): a run's
/// contacts are exact to rounding, so overlaps of some 10⁻¹³ occur, far below this; anything
/// more was not written by a run.
pub const RESTORE_OVERLAP: f64 = 1e-9;

/// Checks particles and box; returns the largest contact distance (the cell "reach").
pub(crate) fn validate<const D: usize>(particles: &[Particle<D>], sim_box: &SimBox<D>) -> Result<f64, SetupError> {
    if particles.is_empty() {
        return Err(SetupError::Empty);
    }
    if particles.len() > MAX_PARTICLES {
        return Err(SetupError::TooMany { n: particles.len() });
    }
    let mut rmax: f64 = 0.0;
    for (index, p) in particles.iter().enumerate() {
        for (field, value) in [("radius", p.radius), ("mass", p.mass)] {
            if !(value.is_finite() && value > 0.0) {
                return Err(SetupError::BadParticle { index, field, value });
            }
        }
        for (field, values) in [("position", p.position.as_slice()), ("velocity", p.velocity.as_slice())] {
            if let Some(&value) = values.iter().find(|x| !x.is_finite()) {
                return Err(SetupError::BadParticle { index, field, value });
            }
        }
        if !p.time.is_finite() {
            return Err(SetupError::BadParticle { index, field: "time", value: p.time });
        }
        // The energy must be a number: m|v|² overflowing makes every temperature and
        // pressure infinite (and such a speed crosses the box in less than the clock's
        // resolution).
        let energy = p.kinetic_energy();
        if !energy.is_finite() {
            return Err(SetupError::BadParticle { index, field: "kinetic energy", value: energy });
        }
        rmax = rmax.max(p.radius);
    }
    let reach = 2.0 * rmax;
    check_box(sim_box, reach)?;
    Ok(reach)
}

/// Checks that a box can hold particles of contact distance up to `reach` (twice the
/// largest radius): every edge finite, a periodic edge at least `2·reach` (minimum image:
/// a particle then meets at most one image of another), an edge between walls longer than
/// `reach` (a particle exactly as wide as the gap touches both walls at once and bounces
/// between them without the clock moving).
pub fn check_box<const D: usize>(sim_box: &SimBox<D>, reach: f64) -> Result<(), SetupError> {
    for a in 0..D {
        let length = sim_box.lengths[a];
        let walls = sim_box.boundary[a] == Boundary::Wall;
        let (fits, minimum) = if walls { (length > reach, reach) } else { (length >= 2.0 * reach, 2.0 * reach) };
        if !(length.is_finite() && fits) {
            return Err(SetupError::BoxTooSmall { axis: a, length, minimum, walls });
        }
    }
    Ok(())
}
