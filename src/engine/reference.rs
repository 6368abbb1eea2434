//! The slow exact reference: after every event, every pair and every wall is predicted
//! again from scratch (O(N²) per event) and the earliest event in the same total order is
//! applied. No queue, no cells, no invalidation — nothing to get wrong. Tests run it beside
//! [`Simulation`](super::Simulation) on small systems and require the same sequence of events,
//! bit for bit.
//!
//! Between collisions the minimum image of a pair can change. The fast engine predicts a
//! pair only while both are inside their skins, where their separation stays below `L/2`
//! (the image cannot switch before they have rebuilt their lists); the reference instead never looks further ahead than
//! `(L/2 − reach)/(2·v_max)` — less than the time any pair needs to switch image and then
//! touch — and predicts again from there when nothing happens sooner.

use super::collision::Restitution;
use super::events::{Event, EventKind, predict_pair, predict_wall, resolve_pair_event, resolve_wall_event, short_axes};
use super::geometry::Boundary;
use super::geometry::{Particle, SimBox};

/// A collision the reference engine processed: `(time, i, j)` for pairs, `(time, i, i)`
/// for walls.
pub type Collision = (f64, usize, usize);

enum Lookahead {
    Event(Event),
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
                Lookahead::Event(e) => return Some(self.apply(e)),
                Lookahead::Nothing => return None,
                Lookahead::Until(t) => self.time = t,
            }
        }
    }

    fn next_event(&self) -> Lookahead {
        let reach = 2.0 * self.particles.iter().map(|p| p.radius).fold(0.0, f64::max);
        let short = short_axes(&self.sim_box, reach);
        let vmax = self.particles.iter().map(|p| p.velocity.norm()).fold(0.0, f64::max);
        let horizon = (0..D)
            .filter(|&a| self.sim_box.boundary[a] == Boundary::Periodic)
            .map(|a| self.time + (self.sim_box.lengths[a] / 2.0 - reach) / (2.0 * vmax))
            .fold(f64::INFINITY, f64::min);
        let mut best: Option<Event> = None;
        let mut consider = |e: Event| {
            if best.is_none_or(|b| e.order(&b).is_lt()) {
                best = Some(e);
            }
        };
        let n = self.particles.len();
        for i in 0..n {
            let p = &self.particles[i];
            for j in i + 1..n {
                let q = &self.particles[j];
                if let Some(t) = predict_pair(p, q, &self.sim_box, self.time, &short) {
                    let kind = EventKind::Pair { j, j_events: q.events };
                    consider(Event { time: t.max(self.time), i, i_events: p.events, kind });
                }
            }
            if let Some((t, axis, upper)) = predict_wall(p, &self.sim_box) {
                consider(Event {
                    time: t.max(self.time),
                    i,
                    i_events: p.events,
                    kind: EventKind::Wall { axis, upper },
                });
            }
        }
        match best {
            Some(e) if e.time <= horizon => Lookahead::Event(e),
            _ if horizon.is_finite() => Lookahead::Until(horizon),
            Some(e) => Lookahead::Event(e),
            None => Lookahead::Nothing,
        }
    }

    fn apply(&mut self, e: Event) -> Collision {
        self.time = e.time;
        let t = e.time;
        match e.kind {
            EventKind::Pair { j, .. } => {
                resolve_pair_event(&mut self.particles, e.i, j, &self.sim_box, t, Restitution::ELASTIC);
                (t, e.i, j)
            }
            EventKind::Wall { axis, upper } => {
                resolve_wall_event(&mut self.particles[e.i], axis, upper, t);
                (t, e.i, e.i)
            }
            EventKind::Rebuild | EventKind::Sample => unreachable!("the reference predicts only collisions"),
        }
    }
}
