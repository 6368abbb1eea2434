//! The event loop: one [`Simulation`] owns the particles, the event queue, the cell grid,
//! the box and the clock.
//!
//! `step()` pops the earliest *valid* event (an event is stale when a particle it involves
//! has changed velocity since it was predicted — per-particle event counters), advances
//! the particles it involves to the event time, resolves it, re-predicts what changed, and
//! returns an [`Outcome`] describing what happened, for the observers.

use super::cells::Cells;
use super::collision::{Impulse, Restitution};
use super::events::{
    Event, EventKind, Queued, pair_positions, predict_pair, predict_wall, resolve_pair_event, resolve_wall_event,
    short_axes,
};
use super::geometry::{Boundary, Particle, SimBox};
use nalgebra::SVector;
use serde::{Deserialize, Serialize};
use std::collections::BinaryHeap;
use std::fmt;

/// What one step did.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Outcome<const D: usize> {
    /// Particles `i < j` collided; `impulse.on_second` is `j`'s momentum change.
    Pair {
        /// Lower index.
        i: usize,
        /// Higher index.
        j: usize,
        /// The impulse and the contact vector (minimum image).
        impulse: Impulse<D>,
    },
    /// Particle `i` bounced off a wall, receiving momentum `impulse` along `axis`.
    Wall {
        /// The particle.
        i: usize,
        /// Axis of the wall.
        axis: usize,
        /// Upper or lower wall.
        upper: bool,
        /// |Δp| = 2m|v⊥|.
        impulse: f64,
    },
    /// A particle changed cell (bookkeeping only).
    Cell,
    /// A scheduled sampling time was reached.
    Sample,
}

/// Counts of processed events by kind, and of stale events discarded.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct EventCounts {
    /// Pair collisions.
    pub pair: u64,
    /// Wall collisions.
    pub wall: u64,
    /// Cell crossings.
    pub cell: u64,
    /// Sampling events.
    pub sample: u64,
    /// Stale events discarded (popped, or dropped when the queue is compacted).
    pub stale: u64,
}

impl EventCounts {
    /// The events counted since `earlier` (a snapshot of the same counter).
    pub fn since(&self, earlier: &EventCounts) -> EventCounts {
        EventCounts {
            pair: self.pair - earlier.pair,
            wall: self.wall - earlier.wall,
            cell: self.cell - earlier.cell,
            sample: self.sample - earlier.sample,
            stale: self.stale - earlier.stale,
        }
    }

    /// Every processed event (stale ones excluded).
    pub fn total(&self) -> u64 {
        self.pair + self.wall + self.cell + self.sample
    }
}

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
        /// The smallest length allowed.
        minimum: f64,
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
    /// Two particles overlap.
    Overlap {
        /// Lower index.
        i: usize,
        /// Higher index.
        j: usize,
        /// Overlap as a fraction of their contact distance.
        fraction: f64,
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
                    if *field == "position" { "" } else { " and > 0" }
                )
            }
            SetupError::BoxTooSmall { axis, length, minimum } => {
                write!(
                    f,
                    "box edge {axis} = {length} is too short: it must be at least {minimum} (two contact distances when periodic, one diameter between walls)"
                )
            }
            SetupError::OutsideBox { index, axis, coordinate } => {
                write!(f, "particle {index} is outside the walls along axis {axis} (coordinate {coordinate})")
            }
            SetupError::Overlap { i, j, fraction } => {
                write!(f, "particles {i} and {j} overlap by {:.3e} of their contact distance", fraction)
            }
        }
    }
}

impl std::error::Error for SetupError {}

/// The largest overlap found by [`Simulation::check_overlaps`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct OverlapAudit {
    /// Largest overlap as a fraction of the contact distance (pairs) or the diameter
    /// (walls); 0 when nothing overlaps.
    pub fraction: f64,
    /// The pair (or `(i, i)` for a wall) where it occurs.
    pub at: Option<(usize, usize)>,
}

/// An event-driven simulation of hard disks (`D = 2`) or spheres.
#[derive(Clone, Debug)]
pub struct Simulation<const D: usize> {
    particles: Vec<Particle<D>>,
    sim_box: SimBox<D>,
    cells: Cells<D>,
    queue: BinaryHeap<Queued>,
    time: f64,
    short: [bool; D],
    restitution: Restitution,
    counts: EventCounts,
    sampling: Option<f64>,
    compact_at: usize,
}

/// The saved state of a [`Simulation`]: enough to continue bit-identically.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct SimulationState<const D: usize> {
    /// Particles.
    pub particles: Vec<Particle<D>>,
    /// Unwrapped cell coordinates, one list per particle.
    pub cells: Vec<Vec<i64>>,
    /// Every queued event (stale ones included).
    pub queue: Vec<Event>,
    /// The clock.
    pub time: f64,
    /// Event counts so far.
    pub counts: EventCounts,
    /// Sampling interval, if sampling.
    pub sampling: Option<f64>,
    /// Queue length that triggers the next compaction.
    pub compact_at: usize,
}

impl<const D: usize> Simulation<D> {
    /// Validates the particles and the box and predicts every first event.
    pub fn new(particles: Vec<Particle<D>>, sim_box: SimBox<D>) -> Result<Self, SetupError> {
        let reach = validate(&particles, &sim_box)?;
        let cells = Cells::new(&sim_box, reach, particles.iter().map(|p| p.position_at(p.time)));
        let time = particles.iter().map(|p| p.time).fold(f64::NEG_INFINITY, f64::max);
        let mut sim = Simulation {
            particles,
            short: short_axes(&sim_box, reach),
            sim_box,
            cells,
            queue: BinaryHeap::new(),
            time,
            restitution: Restitution::ELASTIC,
            counts: EventCounts::default(),
            sampling: None,
            compact_at: 0,
        };
        sim.compact_at = 4 * sim.particles.len() + 1024;
        if let Some(audit) = sim.overlap_beyond(0.0) {
            let (i, j) = audit.at.expect("an overlap has a place");
            if i == j {
                let p = &sim.particles[i];
                let axis = (0..D).find(|&a| {
                    sim.sim_box.boundary[a] == Boundary::Wall && {
                        let x = p.position[a];
                        x < p.radius || x > sim.sim_box.lengths[a] - p.radius
                    }
                });
                return Err(SetupError::OutsideBox {
                    index: i,
                    axis: axis.unwrap_or(0),
                    coordinate: p.position[axis.unwrap_or(0)],
                });
            }
            return Err(SetupError::Overlap { i, j, fraction: audit.fraction });
        }
        for i in 0..sim.particles.len() {
            sim.predict(i, None);
        }
        Ok(sim)
    }

    /// Restores a saved state (see [`Simulation::state`]).
    pub fn restore(state: SimulationState<D>, sim_box: SimBox<D>) -> Result<Self, SetupError> {
        let reach = validate(&state.particles, &sim_box)?;
        let coords = state
            .cells
            .iter()
            .map(|c| {
                let mut m = [0i64; D];
                m.copy_from_slice(c);
                m
            })
            .collect();
        Ok(Simulation {
            cells: Cells::from_coords(&sim_box, reach, coords),
            particles: state.particles,
            short: short_axes(&sim_box, reach),
            sim_box,
            queue: state.queue.into_iter().map(Queued).collect(),
            time: state.time,
            restitution: Restitution::ELASTIC,
            counts: state.counts,
            sampling: state.sampling,
            compact_at: state.compact_at,
        })
    }

    /// The complete state, for checkpoints.
    pub fn state(&self) -> SimulationState<D> {
        let mut queue: Vec<Event> = self.queue.iter().map(|q| q.0).collect();
        queue.sort_by(|a, b| a.order(b));
        SimulationState {
            particles: self.particles.clone(),
            cells: self.cells.coords().iter().map(|m| m.to_vec()).collect(),
            queue,
            time: self.time,
            counts: self.counts,
            sampling: self.sampling,
            compact_at: self.compact_at,
        }
    }

    /// Schedules sampling events every `interval`, the first at `now + interval`.
    pub fn sample_every(&mut self, interval: f64) {
        self.sampling = Some(interval);
        self.push(Event { time: self.time + interval, i: usize::MAX, i_events: 0, kind: EventKind::Sample });
    }

    /// The clock.
    pub fn time(&self) -> f64 {
        self.time
    }

    /// The particles (each at its own update time; see [`Particle::position_at`]).
    pub fn particles(&self) -> &[Particle<D>] {
        &self.particles
    }

    /// The box.
    pub fn sim_box(&self) -> &SimBox<D> {
        &self.sim_box
    }

    /// Processed events by kind.
    pub fn counts(&self) -> EventCounts {
        self.counts
    }

    /// Heap bytes held by the particles, the queue and the cells (capacities).
    pub fn memory_bytes(&self) -> usize {
        use std::mem::size_of;
        self.particles.capacity() * size_of::<Particle<D>>()
            + self.queue.capacity() * size_of::<Queued>()
            + self.cells.memory_bytes()
    }

    /// Events waiting in the queue (stale ones included).
    pub fn queue_len(&self) -> usize {
        self.queue.len()
    }

    /// Cells per axis.
    pub fn cell_counts(&self) -> [usize; D] {
        self.cells.counts()
    }

    /// Total kinetic energy.
    pub fn kinetic_energy(&self) -> f64 {
        self.particles.iter().map(Particle::kinetic_energy).sum()
    }

    /// Total momentum.
    pub fn momentum(&self) -> SVector<f64, D> {
        self.particles.iter().map(|p| p.velocity * p.mass).sum()
    }

    /// Degrees of freedom of the kinetic energy: `d·N` less one per periodic axis (the total
    /// momentum along a periodic axis is conserved, and zeroed by the initial state).
    pub fn degrees_of_freedom(&self) -> f64 {
        (D * self.particles.len() - self.sim_box.periodic_axes()) as f64
    }

    /// kT = 2K / (degrees of freedom).
    pub fn kt(&self) -> f64 {
        2.0 * self.kinetic_energy() / self.degrees_of_freedom()
    }

    /// Positions of all particles at the current time, wrapped into the box.
    pub fn wrapped_positions(&self) -> Vec<SVector<f64, D>> {
        self.particles
            .iter()
            .map(|p| {
                let mut r = p.position_at(self.time);
                for a in 0..D {
                    if self.sim_box.boundary[a] == Boundary::Periodic {
                        r[a] = r[a].rem_euclid(self.sim_box.lengths[a]);
                    }
                }
                r
            })
            .collect()
    }

    /// Audits the current state: the largest overlap between two particles (as a fraction of
    /// their contact distance) or of a particle beyond a wall (as a fraction of its diameter).
    pub fn check_overlaps(&self) -> OverlapAudit {
        self.overlap_beyond(f64::NEG_INFINITY).unwrap_or_default()
    }

    /// The largest overlap if it exceeds `threshold` (a fraction).
    fn overlap_beyond(&self, threshold: f64) -> Option<OverlapAudit> {
        let mut worst = OverlapAudit { fraction: threshold.max(0.0), at: None };
        let t = self.time;
        for (i, p) in self.particles.iter().enumerate() {
            for j in self.cells.neighbours(i).filter(|&j| j > i) {
                let q = &self.particles[j];
                let (ri, rj) = pair_positions(p, q, &self.sim_box, t);
                let sigma = p.radius + q.radius;
                let fraction = (sigma - (rj - ri).norm()) / sigma;
                if fraction > worst.fraction {
                    worst = OverlapAudit { fraction, at: Some((i, j)) };
                }
            }
            let r = p.position_at(t);
            for a in 0..D {
                if self.sim_box.boundary[a] == Boundary::Wall {
                    let beyond = (p.radius - r[a]).max(r[a] - (self.sim_box.lengths[a] - p.radius));
                    let fraction = beyond / (2.0 * p.radius);
                    if fraction > worst.fraction {
                        worst = OverlapAudit { fraction, at: Some((i, i)) };
                    }
                }
            }
        }
        worst.at.map(|_| worst)
    }

    fn push(&mut self, event: Event) {
        self.queue.push(Queued(event));
    }

    /// Drops the stale events once the queue has doubled since the last compaction (and
    /// holds more than 4N entries). Stale events would be skipped when popped anyway, so the
    /// sequence of events is unchanged; what changes is the size of the heap every pop walks
    /// (measured: 7.8 → 2.2 µs per collision at N = 10⁴, η = 0.65). Each compaction costs
    /// O(queue) and comes after as many pushes, so the cost per push stays O(1). The
    /// threshold is part of the saved state, so resumed runs stay bit-identical.
    fn compact_if_large(&mut self) {
        if self.queue.len() > self.compact_at {
            let before = self.queue.len();
            self.queue.retain(|Queued(e)| e.is_valid(&self.particles));
            self.counts.stale += (before - self.queue.len()) as u64;
            self.compact_at = (2 * self.queue.len()).max(4 * self.particles.len() + 1024);
        }
    }

    /// Predicts every event of particle `i` (pairs with its neighbours, a wall, its next cell
    /// crossing) and queues them. `except` skips one partner (just resolved with `i`).
    fn predict(&mut self, i: usize, except: Option<usize>) {
        let p = &self.particles[i];
        let mut found: Vec<Event> = Vec::new();
        for j in self.cells.neighbours(i) {
            if j == i || Some(j) == except {
                continue;
            }
            let (lo, hi) = if i < j { (i, j) } else { (j, i) };
            let (a, b) = (&self.particles[lo], &self.particles[hi]);
            if let Some(t) = predict_pair(a, b, &self.sim_box, self.time, &self.short) {
                found.push(Event {
                    time: t.max(self.time),
                    i: lo,
                    i_events: a.events,
                    kind: EventKind::Pair { j: hi, j_events: b.events },
                });
            }
        }
        if let Some((t, axis, upper)) = predict_wall(p, &self.sim_box) {
            found.push(Event { time: t.max(self.time), i, i_events: p.events, kind: EventKind::Wall { axis, upper } });
        }
        let m = self.cells.coord(i);
        if let Some((dt, axis, up)) = self.cells.next_crossing(&m, &p.position, &p.velocity) {
            let t = (p.time + dt).max(self.time);
            found.push(Event { time: t, i, i_events: p.events, kind: EventKind::Cell { axis, up } });
        }
        for e in found {
            self.push(e);
        }
    }

    /// Processes the next valid event and reports it; `None` when nothing can happen any
    /// more (no event left in the queue).
    pub fn step(&mut self) -> Option<Outcome<D>> {
        self.compact_if_large();
        loop {
            let Queued(e) = self.queue.pop()?;
            if !e.is_valid(&self.particles) {
                self.counts.stale += 1;
                continue;
            }
            self.time = e.time;
            return Some(self.resolve(e));
        }
    }

    /// Applies a valid event at `self.time` and re-predicts.
    fn resolve(&mut self, e: Event) -> Outcome<D> {
        let t = self.time;
        match e.kind {
            EventKind::Pair { j, .. } => {
                self.counts.pair += 1;
                let i = e.i;
                let impulse = resolve_pair_event(&mut self.particles, i, j, &self.sim_box, t, self.restitution);
                self.predict(i, Some(j));
                self.predict(j, None);
                Outcome::Pair { i, j, impulse }
            }
            EventKind::Wall { axis, upper } => {
                self.counts.wall += 1;
                let impulse = resolve_wall_event(&mut self.particles[e.i], axis, upper, t);
                self.predict(e.i, None);
                Outcome::Wall { i: e.i, axis, upper, impulse }
            }
            EventKind::Cell { axis, up } => {
                self.counts.cell += 1;
                self.cells.shift(e.i, axis, up);
                // Same counter: the pending pair and wall events of e.i stay valid; predict the
                // new neighbours and the next crossing (duplicates become stale harmlessly).
                self.predict(e.i, None);
                Outcome::Cell
            }
            EventKind::Sample => {
                self.counts.sample += 1;
                // An interval below the resolution of the clock (t + dt = t) would sample at
                // the same instant forever: sampling stops instead.
                if let Some(dt) = self.sampling
                    && t + dt > t
                {
                    self.push(Event { time: t + dt, i: usize::MAX, i_events: 0, kind: EventKind::Sample });
                }
                Outcome::Sample
            }
        }
    }
}

/// Checks particles and box; returns the largest contact distance (the cell "reach").
fn validate<const D: usize>(particles: &[Particle<D>], sim_box: &SimBox<D>) -> Result<f64, SetupError> {
    if particles.is_empty() {
        return Err(SetupError::Empty);
    }
    let mut rmax: f64 = 0.0;
    for (index, p) in particles.iter().enumerate() {
        for (field, value) in [("radius", p.radius), ("mass", p.mass)] {
            if !(value.is_finite() && value > 0.0) {
                return Err(SetupError::BadParticle { index, field, value });
            }
        }
        for x in p.position.iter().chain(p.velocity.iter()).chain([p.time].iter()) {
            if !x.is_finite() {
                return Err(SetupError::BadParticle { index, field: "position", value: *x });
            }
        }
        rmax = rmax.max(p.radius);
    }
    let reach = 2.0 * rmax;
    for a in 0..D {
        let minimum = match sim_box.boundary[a] {
            // Minimum image needs L > 2·reach: a disk then meets at most one image of another.
            Boundary::Periodic => 2.0 * reach,
            Boundary::Wall => reach,
        };
        let length = sim_box.lengths[a];
        if !(length.is_finite() && length >= minimum) {
            return Err(SetupError::BoxTooSmall { axis: a, length, minimum });
        }
    }
    Ok(reach)
}
