//! The event loop: one [`Simulation`] owns the particles, the box, the neighbourhood, the
//! event queue and the clock.
//!
//! Each particle has exactly one pending event — the earliest of every
//! [source](super::sources)'s prediction for it: its collisions with its neighbours, its next
//! wall, its next neighbourhood update — held in the [`EventQueue`]; sampling is a global
//! event kept beside it. [`Simulation::step`] takes the earliest in the total order. A pair
//! event whose partner has changed velocity since it was predicted (per-particle event
//! counters) is a re-prediction marker: its owner is predicted again and nothing happens.
//! Otherwise the event is resolved by its source, the particles it involved are predicted
//! again, and the [`Outcome`] is returned for the observers.
//!
//! Why this finds every collision: each pair is *covered* by the pending event of one of
//! its particles, whose time is no later than the pair's contact. Predicting a particle
//! covers all its pairs (it takes the minimum over them); a pair stays covered when the
//! covering event turns into a marker, because the marker's time is still no later than
//! the pair's contact and coming up re-covers it. The brute-force
//! [`ReferenceSimulation`](super::ReferenceSimulation) checks this bit for bit.
//!
//! The speed machinery (prefetching the next event's data, huge pages) lives behind
//! the timing room (`engine/timing/`); it is told where a step is and reads, never writes.

use super::arrays::Store;
use super::collision::Restitution;
use super::geometry::{Boundary, Particle, SimBox};
use super::motion::Radii;
use super::neighbours::{GROWTH_STRETCH, Neighbourhood, Neighbours, Saved};
use super::params::EngineParams;
use super::queue::{EventQueue, QueueKind};
use super::search::{NEAR, Search};
use super::setup::{OverlapAudit, RESTORE_OVERLAP, SetupError, check_box, validate};
use super::sources::growth::{AfterCollision, Ending, Growth};
use super::sources::sample::Sampling;
use super::sources::{self, Event, EventCounts, EventKind, Outcome, pair, wall};
use super::timing::{Reading, Timing};
use nalgebra::SVector;
use serde::{Deserialize, Serialize};

/// An event-driven simulation of hard disks (`D = 2`) or spheres (`D = 3`).
#[derive(Clone, Debug)]
pub struct Simulation<const D: usize> {
    particles: Vec<Particle<D>>,
    sim_box: SimBox<D>,
    neighbours: Neighbours<D>,
    /// What was asked for; `neighbours`, `queue` and `timing` say what it resolved to.
    params: EngineParams,
    queue: EventQueue,
    time: f64,
    /// Periodic axes too short for one image per pair ([`pair::short_axes`]).
    short: [bool; D],
    restitution: Restitution,
    counts: EventCounts,
    sampling: Sampling,
    /// A compression under way, if any.
    growth: Option<Growth>,
    /// How the last growth ended (none yet: `None`).
    ending: Option<Ending>,
    /// While growing: until when the neighbourhood holds the radii (the end of its present
    /// stretch, [`GROWTH_STRETCH`]; the growth's `until` for the last one).
    holds_until: Option<f64>,
    search: Search<D>,
    timing: Timing,
    /// When the box is divided between two slabs ([`divided`]): this one's side, who owns
    /// each particle, and what it tells the other side. `None`: the whole box.
    region: Option<Box<divided::Region<D>>>,
}

/// The saved state of a [`Simulation`]: enough to continue bit-identically.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct SimulationState<const D: usize> {
    /// Particles.
    pub particles: Vec<Particle<D>>,
    /// Unwrapped cell coordinates, one list per particle, when the grid follows the
    /// particles (else empty).
    #[serde(default)]
    pub cells: Vec<Vec<i64>>,
    /// Neighbour-list centres (unwrapped positions), one per particle, with lists (else
    /// empty).
    #[serde(default)]
    pub centres: Vec<Vec<f64>>,
    /// With lists: the crowded particles (more neighbours in range than a list holds, when
    /// their list was last built), in increasing order.
    #[serde(default)]
    pub crowded: Vec<u32>,
    /// The neighbourhood asked for.
    #[serde(default)]
    pub neighbourhood: Neighbourhood,
    /// Each particle's pending event (re-prediction markers included).
    pub pending: Vec<Event>,
    /// The clock.
    pub time: f64,
    /// Event counts so far.
    pub counts: EventCounts,
    /// Sampling interval, if sampling.
    pub sampling: Option<f64>,
    /// The next sampling instant, if sampling.
    pub next_sample: Option<f64>,
    /// A compression under way (absent when none).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub growth: Option<Growth>,
    /// During a compression: until when the neighbourhood holds the radii (absent: until the
    /// growth's end, with the cell grid).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub neighbourhood_until: Option<f64>,
}

impl<const D: usize> Simulation<D> {
    /// Validates the particles and the box and predicts every first event, with the engine's
    /// automatic choices ([`EngineParams::default`]).
    pub fn new(particles: Vec<Particle<D>>, sim_box: SimBox<D>) -> Result<Self, SetupError> {
        Self::with_params(particles, sim_box, EngineParams::default())
    }

    /// [`new`](Self::new) with the neighbourhood chosen.
    pub fn with_neighbourhood(
        particles: Vec<Particle<D>>,
        sim_box: SimBox<D>,
        neighbourhood: Neighbourhood,
    ) -> Result<Self, SetupError> {
        Self::with_params(particles, sim_box, EngineParams::with_neighbourhood(neighbourhood))
    }

    /// [`new`](Self::new) with the engine's tunables chosen: the events are the same bit for
    /// bit whatever they are (only the bookkeeping events and the speed differ).
    pub fn with_params(
        particles: Vec<Particle<D>>,
        sim_box: SimBox<D>,
        params: EngineParams,
    ) -> Result<Self, SetupError> {
        let reach = validate(&particles, &sim_box)?;
        let n = particles.len();
        let time = particles.iter().map(|p| p.time).fold(f64::NEG_INFINITY, f64::max);
        let short = pair::short_axes(&sim_box, reach);
        let batch = !short.contains(&true);
        let timing = Timing::new(&params, n);
        // The particles move into the timing room's store first, while nothing else is
        // allocated (the move holds both copies for a moment); the rest is built there.
        let store = timing.store();
        let particles = store.moved(particles);
        let neighbours = Neighbours::new(&sim_box, reach, &particles, time, batch, params.neighbourhood, &store);
        let queue = EventQueue::nothing_in(n, queue_kind(&params, n), &store);
        let mut sim = Simulation {
            queue,
            particles,
            short,
            sim_box,
            neighbours,
            params,
            time,
            restitution: Restitution::ELASTIC,
            counts: EventCounts::default(),
            sampling: Sampling::default(),
            growth: None,
            ending: None,
            holds_until: None,
            search: Search::new(batch),
            timing,
            region: None,
        };
        sim.refuse_overlaps(0.0)?;
        sim.predict_everyone();
        Ok(sim)
    }

    /// Starts a compression now: every radius grows at `rate` times its present value per
    /// unit time until `until` (Lubachevsky–Stillinger; see
    /// [`sources::growth`]), the velocities rescaled to `kt` every
    /// `every` pair collisions. The packing fraction at `until` is
    /// `φ(now)·(1 + rate·(until − now))^d`.
    ///
    /// The box must hold the final radii (a periodic edge at least two final diameters, an
    /// edge between walls longer than one). While the radii grow, the neighbourhood adapts:
    /// it is built for radii [`GROWTH_STRETCH`] times the present ones and rebuilt when they
    /// get there (lists or the grid, as without growth), and pairs are searched one at a
    /// time with the growing kernel. At `until` the step reports [`Outcome::GrowthEnd`] and
    /// the engine goes back to its usual neighbourhood.
    pub fn grow(&mut self, rate: f64, until: f64, kt: f64, every: u64) -> Result<(), SetupError> {
        if self.growth.is_some() {
            return Err(SetupError::Growth { what: "a growth is already under way".into() });
        }
        let growth =
            Growth::new(rate, self.time, until, kt, every).map_err(|e| SetupError::Growth { what: e.to_string() })?;
        check_box(&self.sim_box, 2.0 * growth.final_radius(&self.particles))?;
        self.growth = Some(growth);
        self.arrange_neighbourhood();
        self.predict_everyone();
        Ok(())
    }

    /// [`grow`](Self::grow) until the packing fraction reaches `target`: the growth ends at
    /// `now + ((target/φ)^(1/d) − 1)/rate`, `φ` the packing fraction now.
    pub fn grow_to(&mut self, target: f64, rate: f64, kt: f64, every: u64) -> Result<(), SetupError> {
        let now = self.packing_fraction();
        if !(target.is_finite() && target > now) {
            return Err(SetupError::Growth {
                what: format!("the target packing fraction {target} must exceed the present one, {now}"),
            });
        }
        let until = self.time + ((target / now).powf(1.0 / D as f64) - 1.0) / rate;
        self.grow(rate, until, kt, every)
    }

    /// The compression under way, if any.
    pub fn growth(&self) -> Option<&Growth> {
        self.growth.as_ref()
    }

    /// How the last growth ended, once one has (not kept in checkpoints).
    pub fn growth_ending(&self) -> Option<Ending> {
        self.ending
    }

    /// Ends the growth under way now ([`Ending::Stopped`]): the radii are frozen at their
    /// present values. Nothing happens without one.
    pub fn end_growth(&mut self) {
        self.finish_growth(self.time, Ending::Stopped);
    }

    /// Freezes the radii at `t` (the clock) and goes back to the usual neighbourhood.
    fn finish_growth(&mut self, t: f64, ending: Ending) {
        let Some(growth) = self.growth.take() else { return };
        self.time = t;
        growth.resolve(&mut self.particles, t);
        self.ending = Some(ending);
        self.arrange_neighbourhood();
        self.predict_everyone();
    }

    /// The radii as they change in time (the motion law's second half).
    #[inline(always)]
    pub fn radii(&self) -> Radii {
        self.growth.as_ref().map_or(Radii::Fixed, Growth::radii)
    }

    /// Particle `i`'s radius now (its `radius` field unless a growth is under way).
    pub fn radius(&self, i: usize) -> f64 {
        self.radii().radius(self.particles[i].radius, self.time)
    }

    /// The packing fraction now: the particles' volume (at their present radii) over the
    /// box's.
    pub fn packing_fraction(&self) -> f64 {
        let radii = self.radii();
        let volume: f64 =
            self.particles.iter().map(|p| super::init::ball_volume::<D>(radii.radius(p.radius, self.time))).sum();
        volume / self.sim_box.volume()
    }

    /// The neighbourhood, the short axes and the search for the present radii, what the
    /// parameters ask for: while growing, built for the radii at the end of the next stretch
    /// (until they are [`GROWTH_STRETCH`] times the present ones), with the scalar search.
    /// The pending events must be predicted again afterwards.
    fn arrange_neighbourhood(&mut self) {
        let (reach, growing) = match &self.growth {
            Some(g) => {
                let end = g.grown_by(self.time, GROWTH_STRETCH);
                self.holds_until = Some(end);
                (2.0 * g.largest_radius(&self.particles, end), true)
            }
            None => {
                self.holds_until = None;
                (2.0 * self.particles.iter().map(|p| p.radius).fold(0.0, f64::max), false)
            }
        };
        self.short = pair::short_axes(&self.sim_box, reach);
        let lists = !self.short.contains(&true);
        let batch = lists && !growing;
        let store = self.timing.store();
        let (sim_box, time, choice) = (&self.sim_box, self.time, self.params.neighbourhood);
        self.neighbours = Neighbours::new(sim_box, reach, &self.particles, time, lists, choice, &store);
        self.search = Search::new(batch);
    }

    /// Restores a saved state (see [`Simulation::state`]), with the engine's automatic
    /// choices but the neighbourhood it was saved with.
    pub fn restore(state: SimulationState<D>, sim_box: SimBox<D>) -> Result<Self, SetupError> {
        let mut reach = validate(&state.particles, &sim_box)?;
        // A growth saved without the end of its stretch kept the grid for the final radii.
        let mut lists_allowed = true;
        let mut holds_until = None;
        if let Some(g) = &state.growth {
            let holds = state.neighbourhood_until.unwrap_or(g.until);
            let fine = Growth::new(g.rate, g.origin, g.until, g.kt, g.every).is_ok()
                && g.origin <= state.time
                && state.time <= holds
                && holds <= g.until
                && (state.neighbourhood_until.is_some() || state.centres.is_empty());
            if !fine {
                return Err(SetupError::BadState {
                    what: format!("growth {g:?} with the neighbourhood until {holds} and the clock at {}", state.time),
                });
            }
            check_box(&sim_box, 2.0 * g.final_radius(&state.particles))?;
            reach = 2.0 * g.largest_radius(&state.particles, holds);
            lists_allowed = state.neighbourhood_until.is_some();
            holds_until = Some(holds);
        } else if state.neighbourhood_until.is_some() {
            return Err(SetupError::BadState { what: "a neighbourhood stretch without a growth".into() });
        }
        let n = state.particles.len();
        let bad = |what: String| Err(SetupError::BadState { what });
        if state.cells.iter().any(|c| c.len() != D) || state.centres.iter().any(|c| c.len() != D) {
            return bad(format!("cell coordinates and list centres have {D} components"));
        }
        if state.pending.len() != n {
            return bad(format!("{} pending events for {n} particles", state.pending.len()));
        }
        if !state.time.is_finite() {
            return bad(format!("the clock is {}", state.time));
        }
        if let Some((i, p)) = state.particles.iter().enumerate().find(|(_, p)| p.time > state.time) {
            return bad(format!("particle {i} was last updated at {}, after the clock ({})", p.time, state.time));
        }
        for (owner, p) in state.pending.iter().enumerate() {
            let fine = p.kind.fits(owner, n, &sim_box);
            // Every pending event is predicted no earlier than the clock at its prediction,
            // and the clock is the time of the earliest: none is ever in the past.
            if !fine || p.time.is_nan() || p.time < state.time {
                return bad(format!("pending event {owner} is {p:?} (the clock is at {})", state.time));
            }
        }
        let sampling = match (state.sampling, state.next_sample) {
            (None, None) => Sampling::default(),
            (Some(dt), Some(next)) if dt.is_finite() && dt > 0.0 && next >= state.time && next.is_finite() => {
                Sampling { interval: Some(dt), next: Some(next) }
            }
            (sampling, next) => {
                return bad(format!("sampling every {sampling:?}, next at {next:?}, with the clock at {}", state.time));
            }
        };
        let saved = if state.centres.is_empty() {
            if !state.crowded.is_empty() {
                return bad("crowded particles without neighbour lists".into());
            }
            Saved::Cells(state.cells.iter().map(|c| std::array::from_fn(|a| c[a])).collect())
        } else {
            Saved::Centres(state.centres.iter().map(|c| SVector::from_column_slice(c)).collect(), state.crowded)
        };
        let short = pair::short_axes(&sim_box, reach);
        let lists = !short.contains(&true) && lists_allowed;
        let batch = lists && state.growth.is_none();
        let params = EngineParams::with_neighbourhood(state.neighbourhood);
        let timing = Timing::new(&params, n);
        let store = timing.store();
        let particles = store.moved(state.particles);
        let neighbours = match Neighbours::restore(&sim_box, reach, n, lists, state.neighbourhood, saved, &store) {
            Ok(neighbours) => neighbours,
            Err(what) => return bad(what),
        };
        for (i, p) in particles.iter().enumerate() {
            if !neighbours.inside(i, p, state.time) {
                return bad(match neighbours.listed() {
                    true => format!(
                        "particle {i} is outside its skin (centre {:?}) at time {}",
                        state.centres[i], state.time
                    ),
                    false => format!("particle {i} is not in its cell {:?} at time {}", state.cells[i], state.time),
                });
            }
        }
        let queue = EventQueue::new_in(state.pending, queue_kind(&params, n), &store);
        let sim = Simulation {
            neighbours,
            params,
            particles,
            search: Search::new(batch),
            timing,
            region: None,
            short,
            sim_box,
            queue,
            time: state.time,
            restitution: Restitution::ELASTIC,
            counts: state.counts,
            sampling,
            growth: state.growth,
            ending: None,
            holds_until,
        };
        sim.refuse_overlaps(RESTORE_OVERLAP)?;
        sim.check_pending().map_err(|what| SetupError::BadState { what })?;
        Ok(sim)
    }

    /// Checks that the pending events are what a run leaves: every live event is the
    /// prediction its state gives (pairs and walls to the bit, a neighbourhood update to
    /// rounding), and every event that can happen is covered — no particle's pending event
    /// is later than its next wall or update, and every pair that will touch has one of its
    /// two pending events no later than the contact. Re-prediction markers may be anything
    /// after the clock. A state that fails would miss collisions, or make disks collide
    /// apart.
    fn check_pending(&self) -> Result<(), String> {
        let now = self.time;
        let radii = self.radii();
        // An update's time depends on the clock it was predicted at, by rounding; the exit
        // radius is 2⁻²⁰ of the skin inside it, far more than this.
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-12 * a.abs().max(b.abs()).max(1.0);
        for i in 0..self.particles.len() {
            let p = &self.particles[i];
            let e = self.queue.get(i);
            let wall = wall::predict(p, &self.sim_box, radii).map(|(t, axis, upper)| (t.max(now), axis, upper));
            let exit = sources::neighbourhood::predict(&self.neighbours, i, p, now).map(|t| t.max(now));
            let fine = match e.kind {
                EventKind::Pair { partner, .. } if e.is_live(&self.particles) => {
                    let q = &self.particles[partner as usize];
                    pair::predict(p, q, &self.sim_box, now, &self.short, radii).map(|t| t.max(now)) == Some(e.time)
                }
                EventKind::Wall { axis, upper } => wall == Some((e.time, axis as usize, upper)),
                EventKind::Rebuild => exit.is_some_and(|x| close(x, e.time)),
                _ => true,
            };
            if !fine {
                return Err(format!("pending event {i} ({:?} at {}) is not what its state predicts", e.kind, e.time));
            }
            let late_for_wall = wall.is_some_and(|(t, ..)| e.time > t);
            let late_for_update = exit.is_some_and(|x| e.time > x && !close(x, e.time));
            if late_for_wall || late_for_update {
                return Err(format!(
                    "particle {i}'s pending event at {} is later than its next wall or update",
                    e.time
                ));
            }
            for j in self.neighbours.candidates(i).filter(|&j| j > i) {
                let q = &self.particles[j];
                if let Some(t) = pair::predict(p, q, &self.sim_box, now, &self.short, radii).map(|t| t.max(now))
                    && e.time.min(self.queue.get(j).time) > t
                {
                    return Err(format!(
                        "particles {i} and {j} touch at {t}, and neither has an event pending by then"
                    ));
                }
            }
        }
        Ok(())
    }

    /// The complete state, for checkpoints.
    pub fn state(&self) -> SimulationState<D> {
        let (cells, centres, crowded) = match self.neighbours.save() {
            Saved::Cells(coords) => (coords.iter().map(|m| m.to_vec()).collect(), Vec::new(), Vec::new()),
            Saved::Centres(centres, crowded) => {
                (Vec::new(), centres.iter().map(|c| c.as_slice().to_vec()).collect(), crowded)
            }
        };
        SimulationState {
            particles: self.particles.clone(),
            cells,
            centres,
            crowded,
            neighbourhood: self.params.neighbourhood,
            pending: self.queue.pending(),
            time: self.time,
            counts: self.counts,
            sampling: self.sampling.interval,
            next_sample: self.sampling.next,
            growth: self.growth,
            neighbourhood_until: self.holds_until,
        }
    }

    /// Schedules sampling events every `interval`, the first at `now + interval`.
    pub fn sample_every(&mut self, interval: f64) {
        self.sampling = Sampling::every(self.time, interval);
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

    /// The tunables asked for (see [`lists`](Self::lists) for what the neighbourhood
    /// resolved to).
    pub fn params(&self) -> EngineParams {
        self.params
    }

    /// Heap bytes held by the particles, the queue and the neighbour lists with their grid
    /// (capacities).
    pub fn memory_bytes(&self) -> usize {
        self.particles.capacity() * size_of::<Particle<D>>()
            + self.queue.memory_bytes()
            + self.neighbours.memory_bytes()
    }

    /// Cells per axis of the grid of list centres.
    pub fn cell_counts(&self) -> [usize; D] {
        self.neighbours.cell_counts()
    }

    /// Whether neighbour lists are in use (else the grid follows the particles).
    pub fn lists(&self) -> bool {
        self.neighbours.listed()
    }

    /// How many particles are crowded (more neighbours in range than a list holds: they
    /// search the grid instead).
    pub fn crowded(&self) -> usize {
        self.neighbours.crowded()
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
        self.sim_box.degrees_of_freedom(self.particles.len())
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

    /// Every pair whose gap `|rⱼ − rᵢ| − (Rᵢ + Rⱼ)` (minimum image, present radii) is at most
    /// `tolerance` times its contact distance, as `(i, j, gap / contact distance)` with
    /// `i < j`, in increasing order of `i` then of `j`'s place among `i`'s neighbours; and
    /// every particle within `tolerance` of its own diameter of a wall, as `(i, axis, upper,
    /// gap / diameter)`. For contact networks (`observe::contacts`); `tolerance` must be small
    /// enough that such pairs are neighbours (below about 1).
    #[allow(clippy::type_complexity)]
    pub fn near_contacts(&self, tolerance: f64) -> (Vec<(usize, usize, f64)>, Vec<(usize, usize, bool, f64)>) {
        let (t, radii) = (self.time, self.radii());
        let (mut pairs, mut walls) = (Vec::new(), Vec::new());
        for (i, p) in self.particles.iter().enumerate() {
            let ri = radii.radius(p.radius, t);
            for j in self.neighbours.candidates(i).filter(|&j| j > i) {
                let q = &self.particles[j];
                let (a, b) = pair::positions(p, q, &self.sim_box, t);
                let sigma = ri + radii.radius(q.radius, t);
                let gap = ((b - a).norm() - sigma) / sigma;
                if gap <= tolerance {
                    pairs.push((i, j, gap));
                }
            }
            let r = p.position_at(t);
            for a in 0..D {
                if self.sim_box.boundary[a] == Boundary::Wall {
                    for (upper, gap) in [(false, r[a] - ri), (true, self.sim_box.lengths[a] - ri - r[a])] {
                        if gap / (2.0 * ri) <= tolerance {
                            walls.push((i, a, upper, gap / (2.0 * ri)));
                        }
                    }
                }
            }
        }
        pairs.sort_by_key(|&(i, j, _)| (i, j));
        (pairs, walls)
    }

    /// Audits the current state: the largest overlap between two particles (as a fraction of
    /// their contact distance) or of a particle beyond a wall (as a fraction of its diameter).
    pub fn check_overlaps(&self) -> OverlapAudit {
        self.overlap_beyond(f64::NEG_INFINITY).unwrap_or_default()
    }

    /// An error for the largest overlap beyond `threshold` (a fraction of the contact
    /// distance, or of the diameter beyond a wall), if there is one.
    fn refuse_overlaps(&self, threshold: f64) -> Result<(), SetupError> {
        let Some(audit) = self.overlap_beyond(threshold) else { return Ok(()) };
        let (i, j) = audit.at.expect("an overlap has a place");
        if i != j {
            return Err(SetupError::Overlap { i, j, fraction: audit.fraction });
        }
        let p = &self.particles[i];
        let r = p.position_at(self.time);
        let radius = self.radius(i);
        let axis = (0..D)
            .find(|&a| {
                self.sim_box.boundary[a] == Boundary::Wall && (r[a] < radius || r[a] > self.sim_box.lengths[a] - radius)
            })
            .unwrap_or(0);
        Err(SetupError::OutsideBox { index: i, axis, coordinate: r[axis] })
    }

    /// The largest overlap if it exceeds `threshold` (a fraction).
    fn overlap_beyond(&self, threshold: f64) -> Option<OverlapAudit> {
        let mut worst = OverlapAudit { fraction: threshold.max(0.0), at: None };
        let t = self.time;
        let radius = |p: &Particle<D>| self.radii().radius(p.radius, t);
        for (i, p) in self.particles.iter().enumerate() {
            for j in self.neighbours.candidates(i).filter(|&j| j > i) {
                let q = &self.particles[j];
                let (ri, rj) = pair::positions(p, q, &self.sim_box, t);
                let sigma = radius(p) + radius(q);
                let fraction = (sigma - (rj - ri).norm()) / sigma;
                if fraction > worst.fraction {
                    worst = OverlapAudit { fraction, at: Some((i, j)) };
                }
            }
            let r = p.position_at(t);
            let radius = radius(p);
            for a in 0..D {
                if self.sim_box.boundary[a] == Boundary::Wall {
                    let beyond = (radius - r[a]).max(r[a] - (self.sim_box.lengths[a] - radius));
                    let fraction = beyond / (2.0 * radius);
                    if fraction > worst.fraction {
                        worst = OverlapAudit { fraction, at: Some((i, i)) };
                    }
                }
            }
        }
        worst.at.map(|_| worst)
    }

    /// What the timing room may read.
    #[inline(always)]
    fn reading(&self) -> Reading<'_, D> {
        Reading { particles: &self.particles, queue: &self.queue, neighbours: &self.neighbours }
    }

    /// A time before which no particle changes course: the earliest pending event's (a
    /// stale marker's included, which only makes it earlier), the growth's end, the
    /// neighbourhood's next rebuild while growing. Every particle is in free flight from its
    /// last update to this time, so its position and velocity there are known: an observer
    /// that samples at instants of its own samples at those up to this time before the next
    /// [`step`](Self::step).
    pub fn quiet_until(&mut self) -> f64 {
        let (_, next) = self.queue.first();
        let end = self.growth.map_or(f64::INFINITY, |g| g.predict());
        next.time.min(end).min(self.holds_until.unwrap_or(f64::INFINITY))
    }

    /// Processes the next event and reports it; `None` when nothing can happen any more.
    pub fn step(&mut self) -> Option<Outcome<D>> {
        loop {
            match self.take() {
                Taken::Event(outcome) => return Some(outcome),
                Taken::Bookkeeping => continue,
                Taken::End => return None,
            }
        }
    }

    /// Takes the earliest item — an event, a re-prediction marker, a rebuild of the
    /// neighbourhood while growing — and deals with it.
    #[inline(always)]
    fn take(&mut self) -> Taken<D> {
        let (owner, next) = self.queue.first();
        self.take_first(owner, next)
    }

    /// [`take`](Self::take) with the queue's first item (`owner`'s `next`) known already.
    #[inline(always)]
    fn take_first(&mut self, owner: usize, next: Event) -> Taken<D> {
        let end = self.growth.map(|g| Event { time: g.predict(), kind: EventKind::GrowthEnd });
        let ends_first = end.is_some_and(|end| end.before(u32::MAX, &next, owner as u32));
        if let Some(time) = self.sampling.predict()
            && (Event { time, kind: EventKind::Sample }).before(u32::MAX, &next, owner as u32)
            && end.is_none_or(|end| (Event { time, kind: EventKind::Sample }).before(u32::MAX, &end, u32::MAX))
        {
            self.time = time;
            self.sampling.resolve(time);
            self.counts.record(&Outcome::<D>::Sample);
            return Taken::Event(Outcome::Sample);
        }
        if ends_first && let Some(growth) = &self.growth {
            self.finish_growth(growth.predict(), Ending::Reached);
            return Taken::Event(Outcome::GrowthEnd);
        }
        if let Some(t) = self.holds_until
            && end.is_some_and(|end| t < end.time)
            && t <= next.time
            && self.sampling.predict().is_none_or(|sample| t <= sample)
        {
            // The radii have grown as far as the neighbourhood holds: rebuilt for the next
            // stretch. No particle changes, so no event is reported; the pending events
            // are predicted again against the new neighbourhood (the same events).
            self.time = t;
            self.arrange_neighbourhood();
            self.predict_everyone();
            return Taken::Bookkeeping;
        }
        if next.kind == EventKind::Nothing {
            return Taken::End;
        }
        if !next.is_live(&self.particles) {
            // The partner changed course: a marker. Predict the owner again, from the
            // clock of the last real event (the marker is no event).
            self.counts.stale += 1;
            let guess = self.timing.begin(&self.reading(), owner, None);
            self.predict_one(owner, guess);
            return Taken::Bookkeeping;
        }
        self.time = next.time;
        let (Some(a), b) = next.involved(owner) else { unreachable!("an event of a particle") };
        let guess = self.timing.begin(&self.reading(), a, b);
        if next.kind == EventKind::Rebuild {
            self.timing.leaving(&self.reading(), a, next.time);
        }
        let radii = self.radii();
        let outcome = sources::resolve(
            &mut self.particles,
            &self.sim_box,
            Some(&mut self.neighbours),
            self.restitution,
            radii,
            owner,
            &next,
        );
        self.counts.record(&outcome);
        let after = match (&mut self.growth, &outcome) {
            (Some(growth), Outcome::Pair { .. }) => {
                let dof = self.sim_box.degrees_of_freedom(self.particles.len());
                growth.after_collision(&mut self.particles, next.time, dof)
            }
            _ => AfterCollision::Counted,
        };
        if after == AfterCollision::Stalled {
            self.finish_growth(next.time, Ending::Stalled);
        } else if after == AfterCollision::Rescaled || self.wrapped(&outcome) {
            self.tell_changes(&outcome);
            self.predict_everyone();
            self.tell_everyone();
        } else if self.region.is_some() {
            self.predict_divided(&outcome, guess);
        } else if let Some(b) = b {
            self.predict_partners(a, b, guess);
        } else {
            self.predict_one(a, guess);
        }
        Taken::Event(outcome)
    }

    /// Whether the event counter of a particle the event moved wrapped to 0 (once per 2³²
    /// velocity changes of one particle). A pending event records its partner's count at
    /// prediction; were it to survive until the partner had changed course a multiple of
    /// 2³² times, the counts would match and a stale event would be taken for a live one.
    /// [`predict_everyone`](Self::predict_everyone) then records the current counts, so that
    /// no prediction spans a wrap. The collisions are the same either way (predictions are
    /// exact); only re-prediction markers go.
    #[inline]
    fn wrapped(&self, outcome: &Outcome<D>) -> bool {
        outcome.collided().is_some_and(|(i, j)| self.particles[i].events == 0 || self.particles[j].events == 0)
    }

    /// Predicts particle `i`'s earliest event — from every source that concerns it alone, and
    /// its collisions with its neighbours ([`Search`]) — and makes it `i`'s pending event.
    /// `skip` is a partner not to search (just resolved with `i`: the partner's own
    /// prediction covers the pair), or `i` itself. `near[..n]` are its gathered neighbours
    /// (`gathered = Some(n)`), or the search takes them one at a time (`None`).
    #[inline]
    fn predict_among(&mut self, i: usize, skip: usize, near: &[u32; NEAR], gathered: Option<usize>) {
        let now = self.time;
        let radii = self.radii();
        let mut best = self.alone(i);
        let search = &mut self.search;
        search.earliest(
            &self.particles,
            &self.sim_box,
            &self.short,
            &self.neighbours,
            now,
            i,
            skip,
            near,
            gathered,
            radii,
            &mut best,
        );
        self.queue.set(i, best);
    }

    /// Particle `i`'s earliest event from the sources that concern it alone (a wall, its
    /// skin or cell), or [`Event::NOTHING`].
    #[inline(always)]
    fn alone(&self, i: usize) -> Event {
        let owner = i as u32;
        let mut best = Event::NOTHING;
        sources::predict_alone(
            &self.particles[i],
            i,
            &self.sim_box,
            Some(&self.neighbours),
            self.time,
            self.radii(),
            |e| {
                if e.before(owner, &best, owner) {
                    best = e;
                }
            },
        );
        best
    }

    /// Predicts particle `i` again (see [`predict_among`](Self::predict_among)).
    fn predict(&mut self, i: usize) {
        let mut near = [0u32; NEAR];
        let gathered = self.search.gather(&self.neighbours, i, i, &mut near);
        self.predict_among(i, i, &near, gathered);
    }

    /// Predicts particle `i` again after an event of its own, with the timing room's stages
    /// around it (`guess`: the next event's owner, from [`Timing::begin`]).
    fn predict_one(&mut self, i: usize, guess: Option<usize>) {
        let mut near = [0u32; NEAR];
        let gathered = self.search.gather(&self.neighbours, i, i, &mut near);
        if let Some(n) = gathered {
            self.timing.searching(&self.reading(), &near[..n]);
        }
        let ahead = self.timing.middle(&self.reading(), guess);
        self.predict_among(i, i, &near, gathered);
        self.timing.end(&self.reading(), ahead.as_ref());
    }

    /// Predicts both partners of a collision again, `i` skipping `j`. Both neighbour lists
    /// are copied before either particle is searched, so that the loads of the two rows (and,
    /// for a crowded particle, the walk of its cells) overlap. When the batch takes both,
    /// they are searched side by side ([`Search::bracket_both`]: at N = 10⁴ a tenth faster in
    /// both dimensions with the two changes below, `benches/HISTORY.md`), the timing room's
    /// second stage between the brackets and the exact times; otherwise one after the other,
    /// the second stage between them. The third stage comes after both, each some hundreds
    /// of nanoseconds ahead of its use.
    fn predict_partners(&mut self, i: usize, j: usize, guess: Option<usize>) {
        let (mut near_i, mut near_j) = ([0u32; NEAR], [0u32; NEAR]);
        let gathered_i = self.search.gather(&self.neighbours, i, j, &mut near_i);
        let gathered_j = self.search.gather(&self.neighbours, j, j, &mut near_j);
        let (Some(n_i), Some(n_j)) = (gathered_i, gathered_j) else {
            self.predict_among(i, j, &near_i, gathered_i);
            let ahead = self.timing.middle(&self.reading(), guess);
            self.predict_among(j, j, &near_j, gathered_j);
            self.timing.end(&self.reading(), ahead.as_ref());
            return;
        };
        // Both by the batch: searched side by side (`Search::bracket_both`), the timing
        // room's second stage between the brackets and the candidates' exact times.
        self.timing.searching(&self.reading(), &near_i[..n_i]);
        self.timing.searching(&self.reading(), &near_j[..n_j]);
        let (mut best_i, mut best_j) = (self.alone(i), self.alone(j));
        let (near, gathered) = ([&near_i, &near_j], [n_i, n_j]);
        let bounds = self.search.bracket_both(
            &self.particles,
            &self.sim_box,
            self.time,
            [i, j],
            near,
            gathered,
            [&best_i, &best_j],
        );
        self.timing.candidates(&self.reading(), &self.search, near, gathered, bounds);
        let ahead = self.timing.middle(&self.reading(), guess);
        self.search.settle_both(&self.particles, self.time, [i, j], near, gathered, bounds, [&mut best_i, &mut best_j]);
        self.queue.set(i, best_i);
        self.queue.set(j, best_j);
        self.timing.end(&self.reading(), ahead.as_ref());
    }

    /// Predicts every particle: at the start, and again after an event counter wrapped to 0
    /// (see [`wrapped`](Self::wrapped)).
    #[cold]
    #[inline(never)]
    fn predict_everyone(&mut self) {
        for k in 0..self.particles.len() {
            if self.owns(k) {
                self.predict(k);
            } else {
                self.queue.set(k, Event::NOTHING);
            }
        }
        self.queue.refit();
    }
}

/// What one item of the queue came to ([`Simulation::take`]).
enum Taken<const D: usize> {
    /// An event, resolved.
    Event(Outcome<D>),
    /// Bookkeeping that no observer sees: a re-prediction marker, the neighbourhood rebuilt
    /// while growing.
    Bookkeeping,
    /// Nothing can happen any more.
    End,
}

/// The queue structure `params` ask for with `n` particles.
fn queue_kind(params: &EngineParams, n: usize) -> QueueKind {
    match params.queue {
        super::params::QueueChoice::Auto => QueueKind::for_particles(n),
        super::params::QueueChoice::Calendar => QueueKind::Calendar,
        super::params::QueueChoice::Tree => QueueKind::Tree,
    }
}

pub mod divided;
#[cfg(test)]
mod tests;
