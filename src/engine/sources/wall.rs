//! Hard walls: when a particle reaches one, and the reflection when it does.
//!
//! Along a walled axis of length `L` a particle of radius `R` moves between `R` and `L − R`.
//! *Predict* (pure): the first of those planes its flight reaches. *Resolve* (mutating): the
//! normal velocity reversed — an impulse `2m|v⊥|` on the wall, which the wall-pressure
//! observers sum.

use crate::engine::geometry::{Boundary, Particle, SimBox};
use crate::engine::motion;

/// The first wall particle `p` hits: `(time, axis, upper)`. A particle already touching or
/// beyond a wall (by round-off) and moving into it hits it now (at its own update time).
pub fn predict<const D: usize>(p: &Particle<D>, sim_box: &SimBox<D>) -> Option<(f64, usize, bool)> {
    let mut best: Option<(f64, usize, bool)> = None;
    for a in 0..D {
        if sim_box.boundary[a] != Boundary::Wall || p.velocity[a] == 0.0 {
            continue;
        }
        let upper = p.velocity[a] > 0.0;
        let contact = if upper { sim_box.lengths[a] - p.radius } else { p.radius };
        let dt = motion::time_to(p.position[a], p.velocity[a], contact).max(0.0);
        if best.is_none_or(|(b, _, _)| dt < b) {
            best = Some((dt, a, upper));
        }
    }
    best.map(|(dt, a, upper)| (p.time + dt, a, upper))
}

/// Resolves particle `p` hitting the `upper` or lower wall of `axis` at time `t`: advanced,
/// the normal velocity reversed if it moves into the wall, the counter incremented. Returns
/// the impulse |Δp| = 2m|v⊥| (0 if it was not moving into the wall).
pub fn resolve<const D: usize>(p: &mut Particle<D>, axis: usize, upper: bool, t: f64) -> f64 {
    p.advance(t);
    let v = p.velocity[axis];
    p.events = p.events.wrapping_add(1);
    if v != 0.0 && (v > 0.0) == upper {
        p.velocity[axis] = -v;
        2.0 * p.mass * v.abs()
    } else {
        0.0
    }
}
