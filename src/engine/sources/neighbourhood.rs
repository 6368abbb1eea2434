//! The neighbourhood: bookkeeping events that keep every particle's list of candidate
//! partners complete (`engine/neighbours/`).
//!
//! With the cell grid that follows the particles, a particle's candidates are the members of
//! the cells around its own, so leaving its cell is an event; with neighbour lists, a
//! particle's list holds everyone within its range while it stays inside its skin, so
//! leaving the skin is an event. *Predict* (pure): when that happens. *Resolve* (mutating):
//! the particle moves to the next cell, or its list is built again around where it is. No
//! velocity changes, so observers see only a count.

use crate::engine::geometry::Particle;
use crate::engine::neighbours::Neighbours;

/// When particle `p` (number `i`) next leaves its cell or skin, as an absolute time no
/// earlier than `now`; `None` if it never does (at rest, or only walls ahead).
#[inline]
pub fn predict<const D: usize>(neighbours: &Neighbours<D>, i: usize, p: &Particle<D>, now: f64) -> Option<f64> {
    neighbours.exit_time(i, p, now)
}

/// Particle `p` (number `i`) has reached the time `t` of its prediction: its cell or its
/// list is brought up to date.
#[inline]
pub fn resolve<const D: usize>(neighbours: &mut Neighbours<D>, i: usize, p: &Particle<D>, t: f64) {
    neighbours.rebuild(i, p, t);
}
