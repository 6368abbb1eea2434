//! The box divided between two slabs across the first axis: [`Divided`], two
//! [`Simulation`]s that each resolve the events of their own particles and tell each other
//! what changed — the engine's layout for two cores, here run by one thread in the global
//! order of events, so that it gives the whole box's events bit for bit.
//!
//! # The division
//!
//! A particle belongs to the slab (`x < L₀/2`, the lower; else the upper) that held it at its
//! last neighbourhood update — the centre of its list, or where it entered its cell — so it
//! changes side only at an event of its own. Each side keeps a replica of every particle,
//! the whole neighbourhood and a queue in which only its own particles hold events (the
//! others [`Event::NOTHING`]). A side resolves its own particles' events exactly as the
//! whole box's engine does: a collision with the other side's particle changes both in its
//! replica, and it predicts again only its own.
//!
//! # What the sides tell each other
//!
//! After each event the side that resolved it sends a change per particle it changed:
//! its new state and the partner its prediction skips (the whole box's engine predicts the
//! lower particle of a pair skipping the higher, the higher skipping none), a neighbourhood
//! update (with lists, with the members the rebuild found, which the other side takes
//! instead of scanning again), or every particle predicted again (an event counter
//! wrapped). The other side
//! applies all of an event's changes, then predicts those of its own particles among them
//! with the skips given — at the event's time, as the whole box's engine does. A particle
//! whose neighbourhood update takes it into the other slab is given away: its slot emptied
//! on one side, predicted on the other.
//!
//! [`Divided::step`] takes the side whose earliest item (event or re-prediction marker)
//! comes first in the [total order](crate::engine::sources#the-total-order) and delivers its
//! changes before the next item, so every prediction reads the states the whole box's engine
//! reads: the same events, the same markers, the same counts. Every change is sent, so the
//! replicas stay equal; what a side needs of the other's is the particles near the border.
//!
//! [`Divided::run_unordered`] runs the two sides at once in two threads, each applying the
//! other's changes when they arrive: not a simulation, but what the division costs and
//! keeps on two cores with nothing spent on the order of time ([`Unordered`]) — free, or
//! each side held within a [`Lead`] of the other — and how often a change arrives late
//! enough to meet something its receiver has read since, which an engine that keeps the
//! order would have to undo.
//!
//! # Example
//!
//! ```
//! use collide::engine::{Divided, Simulation};
//!
//! let (particles, sim_box) =
//!     collide::bench::state::initial_state::<3>(500, 0.4, 3).expect("a start");
//! let mut whole = Simulation::new(particles.clone(), sim_box.clone()).expect("valid");
//! let mut divided = Divided::new(particles, sim_box).expect("valid");
//! for _ in 0..2000 {
//!     assert_eq!(whole.step(), divided.step());
//! }
//! assert_eq!(whole.counts(), divided.counts());
//! ```

use super::{Simulation, Taken};
use crate::engine::geometry::{Boundary, Particle, SimBox};
use crate::engine::neighbours::Neighbours;
use crate::engine::params::EngineParams;
use crate::engine::setup::SetupError;
use crate::engine::sources::{Event, EventCounts, Outcome};
use nalgebra::SVector;

/// One side's view of the division: its slab, every particle's side and what it has still
/// to tell the other side.
#[derive(Clone, Debug)]
pub(crate) struct Region<const D: usize> {
    side: Side,
    /// Each particle's side.
    owner: Vec<Side>,
    /// Each particle's anchor: the first coordinate of where it last updated its
    /// neighbourhood (wrapped into the box), which says its side and whether it is near.
    anchor: Vec<f64>,
    /// Where the slabs meet on the first axis, `L₀/2` (and at 0 ≡ `L₀` when periodic).
    half: f64,
    periodic: bool,
    /// How far from a border an anchor is *near*: within the reach of the other side's
    /// reads (the neighbourhood's `read_reach`).
    zone: f64,
    /// The changes of the last event, not yet delivered.
    outbox: Vec<Change<D>>,
    /// Changes told so far (a list's members counted with its `Neighbourhood` change).
    told: u64,
    /// What each item changed, when recording ([`journal`]).
    journal: Option<Vec<journal::Record<D>>>,
}

/// A slab.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Side {
    /// `0 ≤ x < L₀/2`.
    Lower,
    /// `L₀/2 ≤ x < L₀`.
    Upper,
}

impl Side {
    /// The slab holding first coordinate `x` (already wrapped into the box).
    fn of(x: f64, half: f64) -> Side {
        if x < half { Side::Lower } else { Side::Upper }
    }
}

/// What an event can change of a particle's record: where it is, its velocity, its own
/// time and its event counter. Its radius, mass and species never change in a divided box
/// (which does not grow), and every side holds them from the start: a change or an undo
/// record carries these alone, half of a sphere's padded record.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Moved<const D: usize> {
    position: SVector<f64, D>,
    velocity: SVector<f64, D>,
    time: f64,
    events: u32,
}

impl<const D: usize> Moved<D> {
    fn of(p: &Particle<D>) -> Self {
        Moved { position: p.position, velocity: p.velocity, time: p.time, events: p.events }
    }

    fn set(&self, p: &mut Particle<D>) {
        p.position = self.position;
        p.velocity = self.velocity;
        p.time = self.time;
        p.events = self.events;
    }
}

/// What one side tells the other after an event of its own.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Change<const D: usize> {
    /// The event's time.
    time: f64,
    what: What<D>,
}

#[derive(Clone, Copy, Debug)]
enum What<const D: usize> {
    /// Particle `k` changed course: its new state; predicted again skipping `skip` (itself:
    /// skipping none).
    Course { k: u32, state: Moved<D>, skip: u32 },
    /// Particle `k`'s neighbourhood was updated (its list built again around it, or it
    /// moved to the next cell); its state, which the other side may not have.
    Neighbourhood { k: u32, state: Moved<D> },
    /// With lists, after a `Neighbourhood` change: up to [`CHUNK`] more of the particles
    /// within range of its particle's new centre (its list as the rebuild found it), which
    /// the receiver takes instead of scanning its replica, whose centres far from the
    /// border are out of date.
    Members { chunk: [u32; CHUNK], len: u8 },
    /// Every particle was predicted again (an event counter wrapped to 0).
    Everyone,
    /// The first change of a batch of the ordered schedule's: `owner`'s `event`, the key
    /// that places the batch in the order (`ordered`; not counted as told).
    Item { owner: u32, event: Event },
}

/// The particles whose state a batch of changes sets.
fn changed<const D: usize>(batch: &[Change<D>]) -> impl Iterator<Item = usize> + '_ {
    batch.iter().filter_map(|c| match c.what {
        What::Course { k, .. } | What::Neighbourhood { k, .. } => Some(k as usize),
        What::Members { .. } | What::Everyone | What::Item { .. } => None,
    })
}

/// How many list members one [`What::Members`] carries: as many as fit in the room a
/// state takes, so that the change is no larger.
const CHUNK: usize = 16;

impl<const D: usize> Region<D> {
    fn new(side: Side, sim_box: &SimBox<D>, anchors: Vec<f64>, zone: f64) -> Self {
        let half = 0.5 * sim_box.lengths[0];
        let anchor: Vec<f64> = anchors.into_iter().map(|x| x.rem_euclid(2.0 * half)).collect();
        Region {
            side,
            owner: anchor.iter().map(|&x| Side::of(x, half)).collect(),
            anchor,
            half,
            periodic: sim_box.boundary[0] == Boundary::Periodic,
            zone,
            outbox: Vec::new(),
            told: 0,
            journal: None,
        }
    }

    /// Whether particle `k`'s anchor is near a border: the other side may read its state.
    fn near(&self, k: usize) -> bool {
        let x = self.anchor[k];
        let to_border =
            if self.periodic { (x - self.half).abs().min(x).min(2.0 * self.half - x) } else { (x - self.half).abs() };
        to_border < self.zone
    }

    /// Moves particle `k`'s anchor to `x` (where it updated its neighbourhood): its side
    /// now, which it takes.
    fn anchor_at(&mut self, k: usize, x: f64) -> Side {
        self.anchor[k] = x.rem_euclid(2.0 * self.half);
        self.owner[k] = Side::of(self.anchor[k], self.half);
        self.owner[k]
    }

    /// The side an anchor at first coordinate `x` would take (as [`anchor_at`](Self::anchor_at)).
    fn side_at(&self, x: f64) -> Side {
        Side::of(x.rem_euclid(2.0 * self.half), self.half)
    }
}

/// What a side holds of a particle of the other side that is not near: nothing it may read.
/// Its motion is not a number, so that a read shows at once (the tests fail within a few
/// thousand events when the zone is made narrower than the reads reach). Its counter is
/// the last one known with the top bit flipped, so that an event of this side with it as
/// partner is a re-prediction marker — as it is in the whole box: a live pair event's
/// partner stays near on its way to the contact, so one that got far changed course on the
/// way, where it was near and this side was told. The flip only makes sure.
fn poisoned<const D: usize>(p: &mut Particle<D>) {
    p.position.fill(f64::NAN);
    p.velocity.fill(f64::NAN);
    p.events ^= 1 << 31;
}

impl<const D: usize> Simulation<D> {
    /// Whether particle `k` is this side's (always, for the whole box).
    #[inline(always)]
    pub(super) fn owns(&self, k: usize) -> bool {
        self.region.as_ref().is_none_or(|r| r.owner[k] == r.side)
    }

    /// Particle `k` updated its neighbourhood now: its anchor moves where it is, and the
    /// side it takes is returned.
    fn anchor_now(&mut self, k: usize) -> Side {
        let x = self.particles[k].position_at(self.time)[0];
        self.region.as_deref_mut().expect("divided").anchor_at(k, x)
    }

    /// Queues a change for the other side.
    fn tell(&mut self, what: What<D>) {
        let time = self.time;
        let region = self.region.as_deref_mut().expect("divided");
        region.told += 1;
        region.outbox.push(Change { time, what });
    }

    /// Tells particle `k`'s new course, predicted again skipping `skip`, if the other side
    /// holds it: its own, or this side's near a border.
    fn tell_course(&mut self, k: usize, skip: usize) {
        let region = self.region.as_deref().expect("divided");
        if region.owner[k] != region.side || region.near(k) {
            self.tell(What::Course { k: k as u32, state: Moved::of(&self.particles[k]), skip: skip as u32 });
        }
    }

    /// Tells the other side what an event of this side changed (nothing, for the whole box).
    pub(super) fn tell_changes(&mut self, outcome: &Outcome<D>) {
        if self.region.is_none() {
            return;
        }
        match *outcome {
            Outcome::Pair { i, j, .. } => {
                self.tell_course(i, j);
                self.tell_course(j, j);
            }
            Outcome::Wall { i, .. } => self.tell_course(i, i),
            // Told where the anchor is known, before and after (`predict_divided`).
            Outcome::Rebuild { .. } => {}
            Outcome::Sample | Outcome::GrowthEnd => unreachable!("a divided box neither samples nor grows"),
        }
    }

    /// After an event of this side: tells the other side what changed and predicts this
    /// side's particles again (a particle that left the slab is given away).
    pub(super) fn predict_divided(&mut self, outcome: &Outcome<D>, guess: Option<usize>) {
        self.tell_changes(outcome);
        match *outcome {
            Outcome::Pair { i, j, .. } => match (self.owns(i), self.owns(j)) {
                (true, true) => self.predict_partners(i, j, guess),
                (true, false) => self.predict_skipping(i, j),
                (false, true) => self.predict_skipping(j, j),
                (false, false) => unreachable!("a side resolves only its own particles' events"),
            },
            Outcome::Wall { i, .. } => self.predict_one(i, guess),
            Outcome::Rebuild { i } => {
                let was_near = self.region.as_deref().expect("divided").near(i);
                let side = self.anchor_now(i);
                let near = self.region.as_deref().expect("divided").near(i);
                // The grid moves a particle one cell from where the replica has it: every move
                // is told. A list is centred where the particle is: only near ones are.
                if was_near || near || !self.neighbours.listed() {
                    self.tell(What::Neighbourhood { k: i as u32, state: Moved::of(&self.particles[i]) });
                    self.tell_members();
                }
                if side == self.region.as_deref().expect("divided").side {
                    self.predict_one(i, guess);
                } else {
                    self.queue.set(i, Event::NOTHING);
                }
            }
            Outcome::Sample | Outcome::GrowthEnd => unreachable!("a divided box neither samples nor grows"),
        }
    }

    /// Tells the other side whom the list just rebuilt holds (nothing, following the
    /// particles).
    fn tell_members(&mut self) {
        let region = self.region.as_deref_mut().expect("divided");
        let time = self.time;
        for members in self.neighbours.found().chunks(CHUNK) {
            let mut chunk = [0; CHUNK];
            chunk[..members.len()].copy_from_slice(members);
            region.outbox.push(Change { time, what: What::Members { chunk, len: members.len() as u8 } });
        }
    }

    /// Tells the other side that every particle was predicted again.
    pub(super) fn tell_everyone(&mut self) {
        if self.region.is_some() {
            self.tell(What::Everyone);
        }
    }

    /// Predicts particle `i` again, skipping `skip` (itself: none).
    fn predict_skipping(&mut self, i: usize, skip: usize) {
        let mut near = [0u32; crate::engine::search::NEAR];
        let gathered = self.search.gather(&self.neighbours, i, skip, &mut near);
        self.predict_among(i, skip, &near, gathered);
    }

    /// Applies the other side's changes of one event: every state first, then the
    /// predictions of this side's particles among them (and of a particle that entered the
    /// slab).
    fn receive(&mut self, changes: &[Change<D>]) {
        let Some(first) = changes.first() else { return };
        self.note_batch(changes);
        self.time = first.time;
        for (at, change) in changes.iter().enumerate() {
            match change.what {
                What::Course { k, ref state, .. } => state.set(&mut self.particles[k as usize]),
                What::Neighbourhood { k, ref state } => {
                    let k = k as usize;
                    state.set(&mut self.particles[k]);
                    // With lists, the members the rebuild found follow the update.
                    let members = changes[at + 1..].iter().map_while(|c| match c.what {
                        What::Members { ref chunk, len } => Some(&chunk[..len as usize]),
                        _ => None,
                    });
                    let members = members.flatten().copied();
                    // Only this side's rows take the change (it never reads the others'),
                    // and, when the particle comes into this slab, its new neighbours'.
                    let region = self.region.as_deref().expect("divided");
                    let joins = region.side_at(self.particles[k].position_at(self.time)[0]) == region.side;
                    let mine = |j: usize| region.owner[j] == region.side;
                    self.neighbours.rebuild_told(k, &self.particles[k], self.time, members, mine, joins);
                }
                What::Members { .. } | What::Everyone | What::Item { .. } => {}
            }
        }
        for change in changes {
            match change.what {
                What::Course { k, skip, .. } => {
                    if self.owns(k as usize) {
                        self.predict_skipping(k as usize, skip as usize);
                    }
                }
                What::Neighbourhood { k, .. } => {
                    let k = k as usize;
                    let side = self.anchor_now(k);
                    let region = self.region.as_deref().expect("divided");
                    if side == region.side {
                        self.predict_skipping(k, k);
                    } else if !region.near(k) {
                        poisoned(&mut self.particles[k]);
                    }
                }
                What::Members { .. } | What::Item { .. } => {}
                What::Everyone => self.predict_everyone(),
            }
        }
    }

    /// One side of [`Divided::run_unordered`]: resolves `per_side` events of its own (until
    /// it has none, or the other side has resolved as many), sending each event's changes
    /// to `out` and applying what `inbox` holds after each item, and never taking an item
    /// more than `lead` allows beyond the other side's next (each side's published in
    /// `pace`).
    fn run_side(
        &mut self,
        per_side: u64,
        out: &mailbox::Mailbox<Change<D>>,
        inbox: &mailbox::Mailbox<Change<D>>,
        pace: &Pace,
        lead: Lead,
    ) -> SideRun {
        use std::sync::atomic::Ordering;
        let me = self.region.as_deref().expect("divided").side as usize;
        let clock = std::time::Instant::now();
        let mut run = SideRun::default();
        let mut watch = Watch::new(self.particles.len(), self.neighbours.cell_count());
        let mut batches = mailbox::Batches::default();
        // The other side's next item as last read: read again only when this side's would
        // be beyond it by more than the lead, so that the line it sits on seldom moves.
        let mut theirs = f64::NEG_INFINITY;
        let next = &pace.next;
        run.stop = Stop::Reached;
        // Consecutive events at one time so far.
        let mut chain = 0;
        while run.events < per_side {
            if pace.stop.load(Ordering::Relaxed) {
                run.stop = Stop::Halted;
                break;
            }
            let (owner, item) = self.earliest();
            next[me].0.store(item.time.to_bits(), Ordering::Release);
            if let Lead::Within(ahead) = lead
                && item.time > theirs + ahead
            {
                theirs = f64::from_bits(next[1 - me].0.load(Ordering::Acquire));
                if item.time > theirs + ahead {
                    run.held_back += 1;
                    self.deliver(inbox, &mut batches, &mut run, &mut watch);
                    std::hint::spin_loop();
                    continue;
                }
            }
            match self.take_noted(owner as usize, item) {
                Taken::Event(outcome) => {
                    run.events += 1;
                    chain = if watch.history.last() == Some(&self.time) { chain + 1 } else { 1 };
                    run.stall = run.stall.max(chain);
                    watch.history.push(self.time);
                    let (a, b) = match outcome {
                        Outcome::Pair { i, j, .. } => (i, j),
                        Outcome::Wall { i, .. } | Outcome::Rebuild { i } => (i, i),
                        Outcome::Sample | Outcome::GrowthEnd => unreachable!("a divided box neither samples"),
                    };
                    watch.stamp(&self.neighbours, a, self.time);
                    watch.stamp(&self.neighbours, b, self.time);
                }
                Taken::Bookkeeping => watch.stamp(&self.neighbours, owner as usize, self.time),
                Taken::End => {
                    run.stop = Stop::RanOut;
                    break;
                }
            }
            let region = self.region.as_deref_mut().expect("divided");
            out.send(&region.outbox);
            region.outbox.clear();
            self.deliver(inbox, &mut batches, &mut run, &mut watch);
        }
        // The other side stops too (alone, it would run on against this side's particles
        // frozen where they were) and no longer waits for this one.
        pace.stop.store(true, Ordering::Relaxed);
        next[me].0.store(f64::INFINITY.to_bits(), Ordering::Release);
        run.seconds = clock.elapsed().as_secs_f64();
        run.clock = watch.history.last().copied().unwrap_or(self.time);
        run
    }

    /// Applies every batch of changes waiting in `inbox` (taken into `batches`), counting
    /// in `run` how they arrived: how many, how many in this side's past, and of those how
    /// many change a particle that `watch` says was read since (and what undoing back to
    /// them would take).
    fn deliver(
        &mut self,
        inbox: &mailbox::Mailbox<Change<D>>,
        batches: &mut mailbox::Batches<Change<D>>,
        run: &mut SideRun,
        watch: &mut Watch,
    ) {
        if !inbox.take(batches) {
            return;
        }
        for batch in batches.each() {
            run.received += 1;
            let t = batch[0].time;
            let mut quiet = false;
            if t < self.time {
                run.late += 1;
                if changed(batch).any(|k| watch.read_since(&self.neighbours, k, t)) {
                    run.conflicts += 1;
                    // Times in the order resolved, which is the order of time but where a
                    // late batch's predictions came due in this side's past.
                    run.undone += (watch.history.len() - watch.history.partition_point(|&h| h <= t)) as u64;
                } else {
                    quiet = true;
                }
            }
            self.receive(batch);
            if quiet && watch.history.last().is_some_and(|&last| self.earliest().1.time < last) {
                run.overtaken += 1;
            }
            for k in changed(batch) {
                watch.stamp(&self.neighbours, k, t);
            }
        }
    }

    /// How many of this side's own particles have a position or velocity that is not a
    /// number.
    fn not_numbers(&self) -> usize {
        let finite = |p: &Particle<D>| p.position.iter().chain(p.velocity.iter()).all(|x| x.is_finite());
        (0..self.particles.len()).filter(|&k| self.owns(k) && !finite(&self.particles[k])).count()
    }

    /// How many particles this side holds for its own.
    fn held(&self) -> usize {
        (0..self.particles.len()).filter(|&k| self.owns(k)).count()
    }

    /// The earliest item of this side's queue: its owner and the event.
    fn earliest(&mut self) -> (u32, Event) {
        let (owner, event) = self.queue.first();
        (owner as u32, event)
    }
}

/// What [`Divided::run_unordered`] measured: each side's events and thread time, and how
/// the changes it received arrived.
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub struct Unordered {
    /// Why each side stopped, the lower side's first: the first to resolve the events asked
    /// for stops the other.
    pub stops: [Stop; 2],
    /// The time of each side's last event, the lower side's first.
    pub clocks: [f64; 2],
    /// Events each side resolved (re-prediction markers not counted), the lower side's first.
    pub events: [u64; 2],
    /// Each side's thread's time from the start to its last event, in seconds.
    pub seconds: [f64; 2],
    /// Batches of changes (one per event of the other side that changed anything it holds)
    /// each side received while it ran.
    pub received: [u64; 2],
    /// How many of those arrived in the receiver's past: the event that sent them was
    /// earlier than the receiver's clock. An engine that keeps the order of time has to
    /// undo (or to have waited for) what it did since, when it read what they change.
    pub late: [u64; 2],
    /// How many of its own particles each side holds with a position or velocity that is
    /// not a number at the end: what reading in the wrong order can do to the replicas (a
    /// measurement with any is void). Ran out of events: `events` says so.
    pub not_numbers: [usize; 2],
    /// Particles that neither side holds for its own at the end (each side's view, after
    /// each has applied what the other sent once it had stopped): their events were lost
    /// during the run.
    pub disowned: usize,
    /// How many particles each side holds for its own at the end.
    pub held: [usize; 2],
    /// How many of the late batches each side received change a particle it read after the
    /// batch's time: one of its own events' particles, a particle it predicted, or one whose
    /// searches read it (a change it applied from an earlier batch counts as read at that
    /// batch's time). An engine that keeps the order of time has to undo its events back to
    /// such a batch; a late batch that changes nothing read since can be applied as it comes.
    pub conflicts: [u64; 2],
    /// The side's own events later than each conflicting batch, summed: the events an
    /// engine that keeps the order would undo and resolve again (cascades not counted).
    pub undone: [u64; 2],
    /// How many of the late batches each side received met no read, but predicted an event
    /// of its own earlier than its last: applied as they come, they put an event into the
    /// receiver's past, which an engine that keeps the order has to resolve there (nothing
    /// since has read its particles, or the batch would have met a read; but what the event
    /// changes may) or undo back to.
    pub overtaken: [u64; 2],
    /// How often each side stood waiting because its next item lay beyond the lead.
    pub held_back: [u64; 2],
    /// The longest chain of each side's consecutive events at one time. The whole box's
    /// events at one time are rare and few; here a collision across the border that both
    /// sides resolved (each before it heard of the other's) makes two, and particles left
    /// overlapping by the disorder a chain that stops the clock (a measurement with one is
    /// void).
    pub stall: [u64; 2],
}

/// How far ahead of the other side a side of [`Divided::run_unordered`] may run, in the
/// time of the simulation.
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub enum Lead {
    /// As far as it goes: each side resolves its events at its own pace.
    Free,
    /// No item later than this long after the other side's next: a side that would go
    /// further waits, applying what arrives. Two sides can never both wait (each waits
    /// only for an item earlier than its own by the lead).
    Within(f64),
}

/// A side's next item's time (its bits) on a cache line of its own, which the other side
/// reads.
#[repr(align(128))]
struct Line(std::sync::atomic::AtomicU64);

/// What the sides of [`Divided::run_unordered`] share besides their changes: each side's
/// next item's time, and whether one has stopped.
struct Pace {
    next: [Line; 2],
    stop: std::sync::atomic::AtomicBool,
}

/// Why a side of [`Divided::run_unordered`] stopped.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[non_exhaustive]
pub enum Stop {
    /// It resolved the events asked for.
    #[default]
    Reached,
    /// The other side had resolved them first (or ran out).
    Halted,
    /// It had no event left: every particle of its own had gone to the other side.
    RanOut,
}

/// What one side of [`Divided::run_unordered`] counted.
#[derive(Clone, Copy, Debug, Default)]
struct SideRun {
    stop: Stop,
    clock: f64,
    events: u64,
    seconds: f64,
    received: u64,
    late: u64,
    conflicts: u64,
    undone: u64,
    held_back: u64,
    stall: u64,
    overtaken: u64,
}

/// What a side of [`Divided::run_unordered`] has read: for each particle the latest time
/// at which an item of this side read it (its events' particles, whose predictions read
/// their neighbours) or a change was applied to it, the same for each cell of the grid
/// (the latest of its particles', when they were stamped: a filter), and the times of the
/// side's events.
struct Watch {
    particles: Vec<f64>,
    cells: Vec<f64>,
    history: Vec<f64>,
}

impl Watch {
    fn new(particles: usize, cells: usize) -> Self {
        Watch {
            particles: vec![f64::NEG_INFINITY; particles],
            cells: vec![f64::NEG_INFINITY; cells],
            history: Vec::new(),
        }
    }

    /// Particle `k` was read at `t` (where the neighbourhood has it now).
    fn stamp<const D: usize>(&mut self, neighbours: &Neighbours<D>, k: usize, t: f64) {
        self.particles[k] = self.particles[k].max(t);
        let c = neighbours.cell_index(k);
        self.cells[c] = self.cells[c].max(t);
    }

    /// Whether `k`, or a particle whose searches read `k`, was read after `t`. Every reader
    /// of `k` has its cell next to `k`'s, and a particle's present cell was stamped when it
    /// was (it moves cell only at a stamp of its own), so only the cells around `k`'s
    /// stamped after `t` are looked into.
    fn read_since<const D: usize>(&self, neighbours: &Neighbours<D>, k: usize, t: f64) -> bool {
        self.read_from(neighbours, k, t.next_up())
    }

    /// Whether `k`, or a particle whose searches read `k`, was read at or after `t`
    /// ([`read_since`](Self::read_since), with a read at `t` itself counted).
    fn read_from<const D: usize>(&self, neighbours: &Neighbours<D>, k: usize, t: f64) -> bool {
        if self.particles[k] >= t {
            return true;
        }
        neighbours.cells_around(k).as_slice().iter().any(|&c| {
            self.cells[c as usize] >= t
                && neighbours
                    .cells()
                    .members(c)
                    .any(|i| self.particles[i as usize] >= t && neighbours.searches(i as usize, k))
        })
    }

    /// Takes every read later than `t` back to `t` (reads undone: still counted, as if at
    /// `t`, which no later change comes before).
    fn clamp(&mut self, t: f64) {
        self.particles.iter_mut().chain(self.cells.iter_mut()).for_each(|x| *x = x.min(t));
    }
}

impl Unordered {
    /// Events per second of both sides together: all their events over the slower side's
    /// time.
    pub fn rate(&self) -> f64 {
        (self.events[0] + self.events[1]) as f64 / self.seconds[0].max(self.seconds[1])
    }
}

/// The box divided between two slabs, run in one thread in the global order of events:
/// the same events as [`Simulation`], bit for bit (see the [module](self)).
#[derive(Clone, Debug)]
pub struct Divided<const D: usize> {
    sides: [Simulation<D>; 2],
    /// The changes in delivery (kept to reuse the allocation).
    mail: Vec<Change<D>>,
}

impl<const D: usize> Divided<D> {
    /// Validates the particles and the box (as [`Simulation::new`]) and divides them.
    pub fn new(particles: Vec<Particle<D>>, sim_box: SimBox<D>) -> Result<Self, SetupError> {
        Self::with_params(particles, sim_box, EngineParams::default())
    }

    /// [`new`](Self::new) with the engine's tunables chosen (each side takes them).
    pub fn with_params(
        particles: Vec<Particle<D>>,
        sim_box: SimBox<D>,
        params: EngineParams,
    ) -> Result<Self, SetupError> {
        Self::from_simulation(Simulation::with_params(particles, sim_box, params)?)
    }

    /// A running simulation divided from where it stands: its particles, box, clock and
    /// tunables, every particle predicted again (the same events from here on — predictions
    /// are exact — though not the same re-prediction markers), the counts from zero. A state
    /// taken mid-run can hold pairs in contact overlapping by rounding, which [`new`](Self::new)
    /// refuses; here they are the engine's own. A simulation that samples or grows is refused
    /// ([`SetupError::BadState`]): a divided box does neither.
    pub fn from_simulation(mut whole: Simulation<D>) -> Result<Self, SetupError> {
        if whole.growth.is_some() || whole.holds_until.is_some() || whole.sampling.predict().is_some() {
            return Err(SetupError::BadState { what: "a simulation that samples or grows cannot be divided".into() });
        }
        whole.counts = EventCounts::default();
        let time = whole.time;
        let anchors = || whole.particles.iter().map(|p| p.position_at(time)[0]).collect();
        let zone = whole.neighbours.read_reach(0);
        let side = |side: Side| {
            let mut sim = whole.clone();
            let region = Region::new(side, &sim.sim_box, anchors(), zone);
            for (k, p) in sim.particles.iter_mut().enumerate() {
                if region.owner[k] != side && !region.near(k) {
                    poisoned(p);
                }
            }
            sim.region = Some(Box::new(region));
            sim.predict_everyone();
            sim
        };
        Ok(Divided { sides: [side(Side::Lower), side(Side::Upper)], mail: Vec::new() })
    }

    /// Processes the next event and reports it; `None` when nothing can happen any more.
    pub fn step(&mut self) -> Option<Outcome<D>> {
        loop {
            let ([a, b], [first_a, first_b]) = {
                let (a, ea) = self.sides[0].earliest();
                let (b, eb) = self.sides[1].earliest();
                ([a, b], [ea, eb])
            };
            let s = first_b.before(b, &first_a, a) as usize;
            let taken = self.sides[s].take_noted([a, b][s] as usize, [first_a, first_b][s]);
            let region = self.sides[s].region.as_deref_mut().expect("divided");
            std::mem::swap(&mut self.mail, &mut region.outbox);
            self.sides[1 - s].receive(&self.mail);
            self.mail.clear();
            match taken {
                Taken::Event(outcome) => return Some(outcome),
                Taken::Bookkeeping => continue,
                Taken::End => return None,
            }
        }
    }

    /// Starts (or stops and forgets) recording on both sides what each item changes, so
    /// that the divided box can be taken back ([`undo_to`](Self::undo_to)).
    #[cfg_attr(not(test), allow(dead_code))]
    pub(crate) fn record(&mut self, on: bool) {
        self.sides.iter_mut().for_each(|s| s.record(on));
    }

    /// Where both sides' records stand now.
    #[cfg_attr(not(test), allow(dead_code))]
    pub(crate) fn mark(&self) -> [journal::Mark; 2] {
        self.sides.each_ref().map(|s| s.mark())
    }

    /// Takes both sides back to where [`mark`](Self::mark) gave `mark`.
    #[cfg_attr(not(test), allow(dead_code))]
    pub(crate) fn undo_to(&mut self, mark: [journal::Mark; 2]) {
        for (side, mark) in self.sides.iter_mut().zip(mark) {
            side.undo_to(mark);
        }
    }

    /// The clock: the time of the last event.
    pub fn time(&self) -> f64 {
        self.sides[0].time.max(self.sides[1].time)
    }

    /// The particles, each from its side.
    pub fn particles(&self) -> Vec<Particle<D>> {
        let owner = &self.sides[0].region.as_deref().expect("divided").owner;
        owner.iter().enumerate().map(|(k, s)| self.sides[*s as usize].particles[k].clone()).collect()
    }

    /// How many particles each side holds now, lower then upper.
    pub fn sides(&self) -> [usize; 2] {
        let owner = &self.sides[0].region.as_deref().expect("divided").owner;
        let upper = owner.iter().filter(|&&s| s == Side::Upper).count();
        [owner.len() - upper, upper]
    }

    /// The engine's heap, both sides' (each holds a replica of every record).
    pub fn memory_bytes(&self) -> usize {
        self.sides.iter().map(Simulation::memory_bytes).sum()
    }

    /// How many particles are crowded (see [`Simulation::crowded`]), each counted by the
    /// side that owns it; none with the grid.
    pub fn crowded(&self) -> usize {
        let crowded =
            |s: &Simulation<D>| (0..s.particles.len()).filter(|&k| s.owns(k) && s.neighbours.is_crowded(k)).count();
        if self.lists() { self.sides.iter().map(crowded).sum() } else { 0 }
    }

    /// Whether neighbour lists are in use (else the grid).
    pub fn lists(&self) -> bool {
        self.sides[0].lists()
    }

    /// Events so far, both sides'.
    pub fn counts(&self) -> EventCounts {
        let [a, b] = [self.sides[0].counts, self.sides[1].counts];
        EventCounts {
            pair: a.pair + b.pair,
            wall: a.wall + b.wall,
            rebuild: a.rebuild + b.rebuild,
            sample: a.sample + b.sample,
            stale: a.stale + b.stale,
        }
    }

    /// Whether the two sides agree on every particle's side, and on the anchor and state of
    /// every particle near a border, and each takes every other particle of the other's to
    /// be far (a check for tests).
    pub fn replicas_agree(&self) -> bool {
        let regions = self.sides.each_ref().map(|s| s.region.as_deref().expect("divided"));
        (0..self.sides[0].particles.len()).all(|k| {
            let owner = regions[0].owner[k] as usize;
            let (mine, theirs) = (regions[owner], regions[1 - owner]);
            mine.owner[k] == theirs.owner[k]
                && if mine.near(k) {
                    mine.anchor[k] == theirs.anchor[k]
                        && self.sides[owner].particles[k] == self.sides[1 - owner].particles[k]
                } else {
                    !theirs.near(k)
                }
        })
    }

    /// The changes the sides have told each other so far.
    pub fn told(&self) -> u64 {
        self.sides.iter().map(|s| s.region.as_deref().expect("divided").told).sum()
    }

    /// How many of the other side's particles each side holds the state of (those near a
    /// border), the lower side's count first.
    pub fn known(&self) -> [usize; 2] {
        self.sides.each_ref().map(|s| {
            let region = s.region.as_deref().expect("divided");
            (0..s.particles.len()).filter(|&k| region.owner[k] != region.side && region.near(k)).count()
        })
    }

    /// Runs both sides at once, each in its own thread, until one has resolved `per_side`
    /// events (or has none left), each applying the other's changes when they arrive instead
    /// of in the order of time and none going further ahead of the other than `lead` allows:
    /// a measurement of what the division costs and keeps on two cores with nothing spent on
    /// keeping the order — an upper bound on an engine that keeps it — and of what such an
    /// engine would undo ([`Unordered::conflicts`]). Not a simulation: the sides' replicas no
    /// longer agree, and the events are not the whole box's, so the divided box is consumed.
    pub fn run_unordered(self, per_side: u64, lead: Lead) -> Unordered {
        use std::sync::atomic::AtomicU64;
        let [mut lower, mut upper] = self.sides;
        let mailboxes = [mailbox::Mailbox::default(), mailbox::Mailbox::default()];
        let [to_lower, to_upper] = &mailboxes;
        let pace = Pace {
            next: [Line(AtomicU64::new(0)), Line(AtomicU64::new(0))],
            stop: std::sync::atomic::AtomicBool::new(false),
        };
        let [a, b] = std::thread::scope(|scope| {
            let thread = scope.spawn(|| lower.run_side(per_side, to_upper, to_lower, &pace, lead));
            let here = upper.run_side(per_side, to_lower, to_upper, &pace, lead);
            [thread.join().expect("the lower side's thread"), here]
        });
        // What a side sent after the other had stopped (a particle given away, say) is
        // applied now, so that the end state counts only what the disorder did.
        let mut batches = mailbox::Batches::default();
        let mut watch = Watch::new(lower.particles.len(), lower.neighbours.cell_count());
        lower.deliver(to_lower, &mut batches, &mut SideRun::default(), &mut watch);
        upper.deliver(to_upper, &mut batches, &mut SideRun::default(), &mut watch);
        Unordered {
            stops: [a.stop, b.stop],
            clocks: [a.clock, b.clock],
            events: [a.events, b.events],
            seconds: [a.seconds, b.seconds],
            received: [a.received, b.received],
            late: [a.late, b.late],
            conflicts: [a.conflicts, b.conflicts],
            undone: [a.undone, b.undone],
            overtaken: [a.overtaken, b.overtaken],
            held_back: [a.held_back, b.held_back],
            stall: [a.stall, b.stall],
            not_numbers: [lower.not_numbers(), upper.not_numbers()],
            disowned: (0..lower.particles.len()).filter(|&k| !lower.owns(k) && !upper.owns(k)).count(),
            held: [lower.held(), upper.held()],
        }
    }
}

mod journal;
mod mailbox;
mod ordered;
pub use ordered::Ordered;
#[cfg(test)]
mod tests;
