//! The slow exact reference: after every event, every pair and every particle's other
//! sources (its walls) are predicted again from scratch (O(N²) per event), with the same
//! pure predictions and in the same total order as the engine
//! ([`super::sources`]), and the earliest is resolved. No queue, no cells, no
//! invalidation — nothing to get wrong. Tests run it beside
//! [`Simulation`](super::Simulation) on small systems and require the same sequence of events,
//! bit for bit.
//!
//! Between collisions the minimum image of a pair can change. The fast engine predicts a
//! pair only while both are inside their skins, where their separation stays below `L/2`
//! (the image cannot switch before they have rebuilt their lists); the reference instead
//! never looks further ahead than `(L/2 − reach)/(2·v_max)` — less than the time any pair needs to switch image and then
//! touch — and predicts again from there when nothing happens sooner.

use super::collision::Restitution;
use super::geometry::{Boundary, Particle, SimBox};
use super::sources::{self, Event, EventKind, pair};

/// A collision the reference engine processed: `(time, i, j)` for pairs, `(time, i, i)`
/// for walls.
pub type Collision = (f64, usize, usize);

enum Lookahead {
    /// The owner and its event.
    Event(usize, Event),
    Until(f64),
    Nothing,
}

/// Brute-force event-driven dynamics.
#[derive(Clone, Debug)]
pub struct ReferenceSimulation<const D: usize> {
    /// The particles (each at its own update time).
    pub particles: Vec<Particle<D>>,
    /// The box.
    pub sim_box: SimBox<D>,
    /// The clock.
    pub time: f64,
}

impl<const D: usize> ReferenceSimulation<D> {
    /// Starts from the given state (assumed valid: build a `Simulation` first to check it).
    pub fn new(particles: Vec<Particle<D>>, sim_box: SimBox<D>) -> Self {
        let time = particles.iter().map(|p| p.time).fold(f64::NEG_INFINITY, f64::max);
        ReferenceSimulation { particles, sim_box, time }
    }

    /// Finds and applies the next collision; `None` if there is none.
    pub fn step(&mut self) -> Option<Collision> {
        loop {
            match self.next_event() {
                Lookahead::Event(owner, e) => return Some(self.apply(owner, e)),
                Lookahead::Nothing => return None,
                Lookahead::Until(t) => self.time = t,
            }
        }
    }

    fn next_event(&self) -> Lookahead {
        let reach = 2.0 * self.particles.iter().map(|p| p.radius).fold(0.0, f64::max);
        let short = pair::short_axes(&self.sim_box, reach);
        let vmax = self.particles.iter().map(|p| p.velocity.norm()).fold(0.0, f64::max);
        let horizon = (0..D)
            .filter(|&a| self.sim_box.boundary[a] == Boundary::Periodic)
            .map(|a| self.time + (self.sim_box.lengths[a] / 2.0 - reach) / (2.0 * vmax))
            .fold(f64::INFINITY, f64::min);
        let mut best: Option<(usize, Event)> = None;
        let mut consider = |owner: usize, e: Event| {
            if best.is_none_or(|(o, b)| e.before(owner as u32, &b, o as u32)) {
                best = Some((owner, e));
            }
        };
        let n = self.particles.len();
        for i in 0..n {
            let p = &self.particles[i];
            for j in i + 1..n {
                let q = &self.particles[j];
                if let Some(t) = pair::predict(p, q, &self.sim_box, self.time, &short) {
                    let kind = EventKind::Pair { partner: j as u32, partner_events: q.events };
                    consider(i, Event { time: t.max(self.time), kind });
                }
            }
            // Every other source of a particle alone (the reference keeps no neighbourhood).
            sources::predict_alone(p, i, &self.sim_box, None, self.time, |e| consider(i, e));
        }
        match best {
            Some((owner, e)) if e.time <= horizon => Lookahead::Event(owner, e),
            _ if horizon.is_finite() => Lookahead::Until(horizon),
            Some((owner, e)) => Lookahead::Event(owner, e),
            None => Lookahead::Nothing,
        }
    }

    fn apply(&mut self, owner: usize, e: Event) -> Collision {
        self.time = e.time;
        let outcome = sources::resolve(&mut self.particles, &self.sim_box, None, Restitution::ELASTIC, owner, &e);
        let Some((i, j)) = outcome.collided() else {
            unreachable!("the reference predicts only events that move particles, not {outcome}")
        };
        (e.time, i, j)
    }
}
