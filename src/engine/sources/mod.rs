//! Event sources — what can happen — each a pure *predict* and a mutating *resolve* in a file
//! of its own; the one [`Event`] type and its one total order, shared by the engine and the
//! reference; what a resolved event reports ([`Outcome`]) and how events are counted
//! ([`EventCounts`]).
//!
//! | source | file | predicts | resolves |
//! |---|---|---|---|
//! | pair collisions | [`pair`] | when two particles touch | the collision rule along the line of centres |
//! | hard walls | [`wall`] | when a particle reaches a wall | the normal velocity reversed |
//! | the neighbourhood | [`neighbourhood`] | when a particle leaves its cell or skin | its cell or list brought up to date |
//! | sampling | [`sample`] | the next sampling instant (global) | the clock moves there |
//! | growth (compression) | [`growth`] | the end of the growth (global) | the radii frozen at their grown values |
//!
//! The [`Simulation`](super::Simulation) keeps one pending event per particle — the earliest
//! of every source's prediction for it — and a global one for sampling; the
//! [`ReferenceSimulation`](super::ReferenceSimulation) predicts every source for every
//! particle after each event. Both take the earliest by [`Event::before`], resolve it through
//! `sources::resolve`, and report the [`Outcome`].
//!
//! # The total order
//!
//! By time; at equal times by source (pair < wall < neighbourhood < sample < end of growth <
//! nothing); then
//! by the particles and axes involved (lower particle first, then partner, or axis and
//! direction). No two distinct live events compare equal, so which event comes next never
//! depends on how the events were stored or reached — and the fast engine and the reference
//! agree bit for bit.
//!
//! # Example: predict, then resolve
//!
//! ```
//! use collide::engine::{Body, Restitution, resolve_pair};
//! use collide::quadratic::{Ball, Contact, contact_time};
//! use nalgebra::vector;
//!
//! // Predict: two unit disks approaching head on meet at t = 1.
//! let p = Ball { position: [0.0, 0.0], velocity: [1.0, 0.0], radius: 0.5 };
//! let q = Ball { position: [3.0, 0.0], velocity: [-1.0, 0.0], radius: 0.5 };
//! let Ok(Contact::At(t)) = contact_time(&p, &q) else { panic!() };
//! assert_eq!(t, 1.0);
//!
//! // Resolve: move to contact, collide; equal masses exchange velocities.
//! let at = |b: &Ball<2>| vector![b.position[0] + b.velocity[0] * t, b.position[1] + b.velocity[1] * t];
//! let mut a = Body { position: at(&p), velocity: vector![1.0, 0.0], mass: 1.0 };
//! let mut b = Body { position: at(&q), velocity: vector![-1.0, 0.0], mass: 1.0 };
//! let impulse = resolve_pair(&mut a, &mut b, Restitution::ELASTIC);
//! assert_eq!(b.velocity, vector![1.0, 0.0]);
//! assert_eq!(impulse.virial(), 2.0); // σ·|Δp| with σ = 1, |Δp| = 2
//! ```
//!
//! # Adding a source
//!
//! A file here with its `predict` (a pure function of the states it reads) and its `resolve`
//! (which changes them); then, in this file only: its variant of [`EventKind`] (the variant's
//! place is its place among simultaneous events), its words in the queue's slot
//! (`EventKind::pack`), where a restored one may stand (`EventKind::fits`), its variant of
//! [`Outcome`] with the particles it moved ([`Outcome::collided`]) and of [`EventCounts`], and
//! its line in `predict_alone` and `resolve`. The queue, the engine's step, the reference
//! and the summary take it from there. The thermodynamic observer's match over outcomes is
//! exhaustive on purpose: the compiler asks how the new source's momentum enters the
//! pressure (nothing, for a source that exchanges none with the outside).

pub mod growth;
pub mod neighbourhood;
pub mod pair;
pub mod sample;
pub mod wall;

use super::collision::{Impulse, Restitution};
use super::geometry::{Boundary, Particle, SimBox};
use super::motion::Radii;
use super::neighbours::Neighbours;
use serde::{Deserialize, Serialize};
use std::fmt;

/// The most particles an engine takes: indices are 32-bit, the words at and above
/// `u32::MAX − 4` are the tags of the queue's slot words, and the tournament tree pads the
/// particles with up to two empty slots.
pub const MAX_PARTICLES: usize = u32::MAX as usize - 5;

/// A predicted event of one particle (its *owner*: the engine's queue holds one per
/// particle, the reference keeps the owner beside it), or a global one.
///
/// A pair event stores the partner's event counter at prediction: when the partner has
/// changed velocity since, the event has become a *re-prediction marker* ([`is_live`]) — its
/// time is still a lower bound on every event of the owner that it stood for, so when it
/// comes up the owner is simply predicted again. The owner's own counter is not stored:
/// whenever the owner changes velocity it is predicted again at once.
///
/// [`is_live`]: Event::is_live
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Event {
    /// When (`+∞` for nothing; written `"inf"` in JSON, which has no infinity).
    #[serde(with = "extended_float")]
    pub time: f64,
    /// What.
    pub kind: EventKind,
}

/// What an [`Event`] is about, one variant per source, in the order of the sources among
/// simultaneous events.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum EventKind {
    /// A collision with `partner`, valid while the partner's counter is `partner_events`.
    Pair {
        /// The other particle.
        partner: u32,
        /// Its event counter at prediction.
        partner_events: u32,
    },
    /// The owner hits the `upper` or lower wall of `axis`.
    Wall {
        /// The axis.
        axis: u8,
        /// Upper (at L) or lower (at 0) wall.
        upper: bool,
    },
    /// The owner's neighbourhood is updated: it leaves its skin (its list is rebuilt) or,
    /// with the grid, its cell.
    Rebuild,
    /// A sampling instant (global: no owner).
    Sample,
    /// The end of a growth (global: no owner).
    GrowthEnd,
    /// Nothing will ever happen to the owner (it is at rest and alone).
    Nothing,
}

/// The owner named in the key of a global event.
const GLOBAL: u32 = u32::MAX;

// The words of the queue's slot for the kinds other than pairs: where a pair keeps its
// partner, a tag no particle index reaches (indices stay below MAX_PARTICLES).
const NOTHING_TAG: u32 = u32::MAX;
const WALL_TAG: u32 = u32::MAX - 1;
const REBUILD_TAG: u32 = u32::MAX - 2;
const SAMPLE_TAG: u32 = u32::MAX - 3;
const GROWTH_END_TAG: u32 = u32::MAX - 4;

impl EventKind {
    /// Its place among simultaneous events (the variant's order).
    #[inline(always)]
    fn rank(&self) -> u8 {
        match self {
            EventKind::Pair { .. } => 0,
            EventKind::Wall { .. } => 1,
            EventKind::Rebuild => 2,
            EventKind::Sample => 3,
            EventKind::GrowthEnd => 4,
            EventKind::Nothing => 5,
        }
    }

    /// The kind in two words for the queue's 16-byte slot: a pair is `(partner, partner's
    /// count)`; the other kinds put a tag no particle index reaches where the partner would
    /// be ([`unpack`](Self::unpack) reads them back).
    #[inline(always)]
    pub(crate) fn pack(self) -> (u32, u32) {
        match self {
            EventKind::Pair { partner, partner_events } => {
                debug_assert!((partner as usize) < MAX_PARTICLES);
                (partner, partner_events)
            }
            EventKind::Wall { axis, upper } => (WALL_TAG, axis as u32 | (upper as u32) << 8),
            EventKind::Rebuild => (REBUILD_TAG, 0),
            EventKind::Sample => (SAMPLE_TAG, 0),
            EventKind::GrowthEnd => (GROWTH_END_TAG, 0),
            EventKind::Nothing => (NOTHING_TAG, 0),
        }
    }

    /// The kind [`pack`](Self::pack) wrote as `(who, what)`.
    #[inline(always)]
    pub(crate) fn unpack(who: u32, what: u32) -> EventKind {
        match who {
            NOTHING_TAG => EventKind::Nothing,
            WALL_TAG => EventKind::Wall { axis: what as u8, upper: what >> 8 != 0 },
            REBUILD_TAG => EventKind::Rebuild,
            SAMPLE_TAG => EventKind::Sample,
            GROWTH_END_TAG => EventKind::GrowthEnd,
            partner => EventKind::Pair { partner, partner_events: what },
        }
    }
}

impl Event {
    /// Nothing pending.
    pub const NOTHING: Event = Event { time: f64::INFINITY, kind: EventKind::Nothing };

    /// The tie-break key of `owner`'s event (see [the total order](self#the-total-order)):
    /// source, lower particle, then partner or axis and direction.
    #[inline]
    pub fn key(&self, owner: u32) -> (u8, u32, u32, u8) {
        let rank = self.kind.rank();
        match self.kind {
            EventKind::Pair { partner, .. } => (rank, owner.min(partner), owner.max(partner), 0),
            EventKind::Wall { axis, upper } => (rank, owner, axis as u32, upper as u8),
            EventKind::Sample | EventKind::GrowthEnd => (rank, GLOBAL, 0, 0),
            EventKind::Rebuild | EventKind::Nothing => (rank, owner, 0, 0),
        }
    }

    /// Whether this event (of `owner`) comes before `other` (of `other_owner`) in the total
    /// order.
    #[inline]
    pub fn before(&self, owner: u32, other: &Event, other_owner: u32) -> bool {
        self.time < other.time || (self.time == other.time && self.key(owner) < other.key(other_owner))
    }

    /// Whether the event still stands: a pair whose partner has changed velocity since the
    /// prediction is a re-prediction marker.
    #[inline]
    pub fn is_live<const D: usize>(&self, particles: &[Particle<D>]) -> bool {
        match self.kind {
            EventKind::Pair { partner, partner_events } => particles[partner as usize].events == partner_events,
            _ => true,
        }
    }

    /// The particles `owner`'s event involves, lower first (the second is `None` for a
    /// particle alone, both for a global event).
    #[inline]
    pub fn involved(&self, owner: usize) -> (Option<usize>, Option<usize>) {
        match self.kind {
            EventKind::Pair { partner, .. } => {
                let partner = partner as usize;
                (Some(owner.min(partner)), Some(owner.max(partner)))
            }
            EventKind::Wall { .. } | EventKind::Rebuild => (Some(owner), None),
            EventKind::Sample | EventKind::GrowthEnd | EventKind::Nothing => (None, None),
        }
    }
}

impl EventKind {
    /// Whether this kind can be the pending event of particle `owner` of `n` in `sim_box`
    /// (the check of a restored state): a partner in range and not itself, a wall the box
    /// has. A global event is no particle's.
    pub(crate) fn fits<const D: usize>(&self, owner: usize, n: usize, sim_box: &SimBox<D>) -> bool {
        match *self {
            EventKind::Pair { partner, .. } => (partner as usize) < n && partner as usize != owner,
            EventKind::Wall { axis, .. } => (axis as usize) < D && sim_box.boundary[axis as usize] == Boundary::Wall,
            EventKind::Rebuild | EventKind::Nothing => true,
            EventKind::Sample | EventKind::GrowthEnd => false,
        }
    }
}

/// What one resolved event did (what the observers are fed).
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
    /// Particle `i`'s neighbourhood was updated: it left its skin and its list was rebuilt,
    /// or (with the grid) it crossed into the next cell. Bookkeeping only.
    Rebuild {
        /// The particle.
        i: usize,
    },
    /// A scheduled sampling time was reached.
    Sample,
    /// A growth ended: every radius is now fixed at its grown value (every particle was
    /// advanced to this time; no momentum changed).
    GrowthEnd,
}

impl<const D: usize> Outcome<D> {
    /// The particles whose motion the event changed, as a collision: `(i, j)`, `i < j`, for
    /// a pair, `(i, i)` for a particle alone (a wall); `None` for bookkeeping (a
    /// neighbourhood update, a sample). The reference engine reports its collisions so, and
    /// the engine checks these particles' counters for a wrap.
    #[inline]
    pub fn collided(&self) -> Option<(usize, usize)> {
        match *self {
            Outcome::Pair { i, j, .. } => Some((i, j)),
            Outcome::Wall { i, .. } => Some((i, i)),
            Outcome::Rebuild { .. } | Outcome::Sample | Outcome::GrowthEnd => None,
        }
    }
}

impl<const D: usize> fmt::Display for Outcome<D> {
    /// The event in words, naming its particles (for diagnostics).
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Outcome::Pair { i, j, .. } => write!(f, "a collision of particles {i} and {j}"),
            Outcome::Wall { i, axis, upper, .. } => write!(
                f,
                "a collision of particle {i} with the {} wall of axis {axis}",
                if *upper { "upper" } else { "lower" }
            ),
            Outcome::Rebuild { i } => write!(f, "a neighbourhood update of particle {i}"),
            Outcome::Sample => write!(f, "a sample"),
            Outcome::GrowthEnd => write!(f, "the end of the growth"),
        }
    }
}

/// Counts of processed events by source, and of re-prediction markers (`stale`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct EventCounts {
    /// Pair collisions.
    pub pair: u64,
    /// Wall collisions.
    pub wall: u64,
    /// Neighbourhood updates: list rebuilds (a particle leaving its skin) or, with the grid,
    /// cell crossings.
    pub rebuild: u64,
    /// Sampling events.
    pub sample: u64,
    /// Re-prediction markers processed: pair events whose partner had changed velocity
    /// since they were predicted (nothing happens but a new prediction for the owner).
    pub stale: u64,
}

impl EventCounts {
    /// Counts one resolved event.
    #[inline]
    pub fn record<const D: usize>(&mut self, outcome: &Outcome<D>) {
        match outcome {
            Outcome::Pair { .. } => self.pair += 1,
            Outcome::Wall { .. } => self.wall += 1,
            Outcome::Rebuild { .. } => self.rebuild += 1,
            Outcome::Sample => self.sample += 1,
            // Once per growth: the summary reports growth apart.
            Outcome::GrowthEnd => {}
        }
    }

    /// The events counted since `earlier` (a snapshot of the same counter).
    pub fn since(&self, earlier: &EventCounts) -> EventCounts {
        EventCounts {
            pair: self.pair - earlier.pair,
            wall: self.wall - earlier.wall,
            rebuild: self.rebuild - earlier.rebuild,
            sample: self.sample - earlier.sample,
            stale: self.stale - earlier.stale,
        }
    }

    /// Whether every count is at least `earlier`'s (a later snapshot of the same counter).
    pub fn at_least(&self, earlier: &EventCounts) -> bool {
        self.pair >= earlier.pair
            && self.wall >= earlier.wall
            && self.rebuild >= earlier.rebuild
            && self.sample >= earlier.sample
            && self.stale >= earlier.stale
    }

    /// Every processed event (stale ones excluded).
    pub fn total(&self) -> u64 {
        self.pair + self.wall + self.rebuild + self.sample
    }
}

/// The earliest event of particle `p` (number `i`) from every source that concerns it alone —
/// walls and, where there is one, the neighbourhood — each no earlier than `now`, offered to
/// `consider`. Pair collisions are searched apart: among a particle's neighbours by the
/// engine's search, among every pair by the reference.
#[inline(always)]
pub(crate) fn predict_alone<const D: usize>(
    p: &Particle<D>,
    i: usize,
    sim_box: &SimBox<D>,
    neighbours: Option<&Neighbours<D>>,
    now: f64,
    radii: Radii,
    mut consider: impl FnMut(Event),
) {
    if let Some((t, axis, upper)) = wall::predict(p, sim_box, radii) {
        consider(Event { time: t.max(now), kind: EventKind::Wall { axis: axis as u8, upper } });
    }
    if let Some(t) = neighbours.and_then(|n| neighbourhood::predict(n, i, p, now)) {
        consider(Event { time: t.max(now), kind: EventKind::Rebuild });
    }
}

/// Resolves `owner`'s live event at its time (the clock already there) and reports it.
/// Global events are resolved where they are kept.
#[inline(always)]
pub(crate) fn resolve<const D: usize>(
    particles: &mut [Particle<D>],
    sim_box: &SimBox<D>,
    neighbours: Option<&mut Neighbours<D>>,
    restitution: Restitution,
    radii: Radii,
    owner: usize,
    event: &Event,
) -> Outcome<D> {
    let t = event.time;
    match event.kind {
        EventKind::Pair { partner, .. } => {
            let (i, j) = (owner.min(partner as usize), owner.max(partner as usize));
            let impulse = pair::resolve(particles, i, j, sim_box, t, restitution, radii);
            Outcome::Pair { i, j, impulse }
        }
        EventKind::Wall { axis, upper } => {
            let axis = axis as usize;
            let impulse = wall::resolve(&mut particles[owner], axis, upper, t, radii);
            Outcome::Wall { i: owner, axis, upper, impulse }
        }
        EventKind::Rebuild => {
            let neighbours = neighbours.expect("a neighbourhood event comes from a neighbourhood");
            neighbourhood::resolve(neighbours, owner, &particles[owner], t);
            Outcome::Rebuild { i: owner }
        }
        EventKind::Sample | EventKind::GrowthEnd | EventKind::Nothing => unreachable!("not an event of a particle"),
    }
}

/// An f64 in JSON with its infinities: finite values as numbers, `±∞` as the strings
/// `"inf"` and `"-inf"` (serde_json writes them as `null`, which reads back as no number).
mod extended_float {
    use serde::{Deserialize, Deserializer, Serializer, de};

    pub fn serialize<S: Serializer>(x: &f64, s: S) -> Result<S::Ok, S::Error> {
        match *x {
            f64::INFINITY => s.serialize_str("inf"),
            f64::NEG_INFINITY => s.serialize_str("-inf"),
            x => s.serialize_f64(x),
        }
    }

    // Through a JSON value: serde_json's exact numbers (`arbitrary_precision`) do not pass
    // through serde's untagged enums.
    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
        match serde_json::Value::deserialize(d)? {
            serde_json::Value::Number(n) => n.as_f64().ok_or_else(|| de::Error::custom(format!("{n} is not an f64"))),
            serde_json::Value::String(w) if w == "inf" => Ok(f64::INFINITY),
            serde_json::Value::String(w) if w == "-inf" => Ok(f64::NEG_INFINITY),
            _ => Err(de::Error::custom("expected a number, \"inf\" or \"-inf\"")),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::SVector;

    /// What an event moved is what the event and its outcome say it involves: the
    /// counter-wrap check and the reference read it, so a wrong answer would skip a
    /// re-prediction or report a collision with the wrong particles.
    #[test]
    fn an_outcome_names_the_particles_it_moved() {
        let impulse = Impulse { on_second: SVector::<f64, 2>::zeros(), normal: SVector::zeros() };
        assert_eq!(Outcome::Pair { i: 3, j: 7, impulse }.collided(), Some((3, 7)));
        assert_eq!(Outcome::<2>::Wall { i: 5, axis: 1, upper: false, impulse: 1.0 }.collided(), Some((5, 5)));
        assert_eq!(Outcome::<2>::Rebuild { i: 5 }.collided(), None);
        assert_eq!(Outcome::<2>::Sample.collided(), None);
        assert_eq!(Outcome::<2>::GrowthEnd.collided(), None);
    }

    /// A restored pending event must be one the particle can have.
    #[test]
    fn a_restored_event_fits_its_particle_and_box() {
        let walled =
            SimBox::<2> { lengths: SVector::from([10.0, 10.0]), boundary: [Boundary::Wall, Boundary::Periodic] };
        let pair = |partner| EventKind::Pair { partner, partner_events: 0 };
        assert!(pair(4).fits(3, 5, &walled));
        assert!(!pair(5).fits(3, 5, &walled), "a partner out of range");
        assert!(!pair(3).fits(3, 5, &walled), "a particle is not its own partner");
        assert!(EventKind::Wall { axis: 0, upper: true }.fits(0, 5, &walled));
        assert!(!EventKind::Wall { axis: 1, upper: true }.fits(0, 5, &walled), "a periodic axis has no wall");
        assert!(!EventKind::Wall { axis: 2, upper: true }.fits(0, 5, &walled), "no third axis in 2D");
        assert!(EventKind::Rebuild.fits(0, 5, &walled) && EventKind::Nothing.fits(0, 5, &walled));
        assert!(!EventKind::Sample.fits(0, 5, &walled), "a global event is no particle's");
    }

    /// Every kind of event comes back out of its two words as it went in, at the extremes
    /// of every field.
    #[test]
    fn every_kind_survives_its_packing() {
        let largest = MAX_PARTICLES as u32 - 1;
        let mut kinds = vec![EventKind::Nothing, EventKind::Rebuild, EventKind::Sample, EventKind::GrowthEnd];
        for axis in [0u8, 1, 2] {
            for upper in [false, true] {
                kinds.push(EventKind::Wall { axis, upper });
            }
        }
        for partner in [0, 1, largest] {
            for partner_events in [0, 1, u32::MAX] {
                kinds.push(EventKind::Pair { partner, partner_events });
            }
        }
        for kind in kinds {
            let (who, what) = kind.pack();
            assert_eq!(EventKind::unpack(who, what), kind);
        }
    }

    /// At equal times the sources come in their order, and a global sample after the pair,
    /// wall and neighbourhood events of any particle but before "nothing".
    #[test]
    fn simultaneous_events_follow_the_order_of_the_sources() {
        let at = |kind| Event { time: 1.0, kind };
        let pair = at(EventKind::Pair { partner: 9, partner_events: 0 });
        let wall = at(EventKind::Wall { axis: 0, upper: false });
        let rebuild = at(EventKind::Rebuild);
        let sample = at(EventKind::Sample);
        let end = at(EventKind::GrowthEnd);
        let nothing = Event { time: 1.0, kind: EventKind::Nothing };
        let chain = [(pair, 7), (wall, 0), (rebuild, 0), (sample, 0), (end, 0), (nothing, 0)];
        for w in chain.windows(2) {
            assert!(w[0].0.before(w[0].1, &w[1].0, w[1].1), "{:?} before {:?}", w[0], w[1]);
            assert!(!w[1].0.before(w[1].1, &w[0].0, w[0].1));
        }
        // A pair is keyed by its lower particle, from either owner.
        assert_eq!(pair.key(7), at(EventKind::Pair { partner: 7, partner_events: 3 }).key(9));
        // Earlier always wins.
        let earlier = Event { time: 0.5, kind: EventKind::Nothing };
        assert!(earlier.before(0, &pair, 7));
    }
}
