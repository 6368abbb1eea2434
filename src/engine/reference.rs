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
//!
//! It grows too ([`ReferenceSimulation::grow`]): the same growing predictions, the same
//! collision rule, the thermostat after the same collisions and the end of the growth at the
//! same instant (all from [`sources`]), so a compression is checked bit for bit as well.

use super::collision::Restitution;
use super::geometry::{Boundary, Particle, SimBox};
use super::motion::Radii;
use super::sources::growth::{AfterCollision, Growth, GrowthError};
use super::sources::{self, Event, EventKind, Outcome, pair};

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
    /// A compression under way, if any.
    pub growth: Option<Growth>,
}

impl<const D: usize> ReferenceSimulation<D> {
    /// Starts from the given state (assumed valid: build a `Simulation` first to check it).
    pub fn new(particles: Vec<Particle<D>>, sim_box: SimBox<D>) -> Self {
        let time = particles.iter().map(|p| p.time).fold(f64::NEG_INFINITY, f64::max);
        ReferenceSimulation { particles, sim_box, time, growth: None }
    }

    /// Starts a compression now, as [`Simulation::grow`](super::Simulation::grow) does.
    pub fn grow(&mut self, rate: f64, until: f64, kt: f64, every: u64) -> Result<(), GrowthError> {
        self.growth = Some(Growth::new(rate, self.time, until, kt, every)?);
        Ok(())
    }

    fn radii(&self) -> Radii {
        self.growth.as_ref().map_or(Radii::Fixed, Growth::radii)
    }

    /// Finds and applies the next collision; `None` if there is none.
    pub fn step(&mut self) -> Option<Collision> {
        loop {
            match self.next_event() {
                Lookahead::Event(owner, e) => {
                    if let Some(collision) = self.apply(owner, e) {
                        return Some(collision);
                    }
                }
                Lookahead::Nothing => return None,
                Lookahead::Until(t) => self.time = t,
            }
        }
    }

    fn next_event(&self) -> Lookahead {
        let radii = self.radii();
        let reach = 2.0
            * match &self.growth {
                Some(g) => g.final_radius(&self.particles),
                None => self.particles.iter().map(|p| p.radius).fold(0.0, f64::max),
            };
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
                if let Some(t) = pair::predict(p, q, &self.sim_box, self.time, &short, radii) {
                    let kind = EventKind::Pair { partner: j as u32, partner_events: q.events };
                    consider(i, Event { time: t.max(self.time), kind });
                }
            }
            // Every other source of a particle alone (the reference keeps no neighbourhood).
            sources::predict_alone(p, i, &self.sim_box, None, self.time, radii, |e| consider(i, e));
        }
        // The end of a growth, a global event (owner `u32::MAX`, as the engine keys it).
        if let Some(g) = &self.growth {
            consider(u32::MAX as usize, Event { time: g.predict(), kind: EventKind::GrowthEnd });
        }
        match best {
            Some((owner, e)) if e.time <= horizon => Lookahead::Event(owner, e),
            _ if horizon.is_finite() => Lookahead::Until(horizon),
            Some((owner, e)) => Lookahead::Event(owner, e),
            None => Lookahead::Nothing,
        }
    }

    /// Applies the event; a collision is reported, the end of a growth is not.
    fn apply(&mut self, owner: usize, e: Event) -> Option<Collision> {
        self.time = e.time;
        if e.kind == EventKind::GrowthEnd {
            if let Some(growth) = self.growth.take() {
                growth.resolve(&mut self.particles, e.time);
            }
            return None;
        }
        let radii = self.radii();
        let outcome =
            sources::resolve(&mut self.particles, &self.sim_box, None, Restitution::ELASTIC, radii, owner, &e);
        let dof = self.sim_box.degrees_of_freedom(self.particles.len());
        if let (Some(growth), Outcome::Pair { .. }) = (&mut self.growth, &outcome)
            && growth.after_collision(&mut self.particles, e.time, dof) == AfterCollision::Stalled
        {
            growth.resolve(&mut self.particles, e.time);
            self.growth = None;
        }
        let Some((i, j)) = outcome.collided() else {
            unreachable!("the reference predicts only events that move particles, not {outcome}")
        };
        Some((e.time, i, j))
    }
}
