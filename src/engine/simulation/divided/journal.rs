//! A side's undo records: what each item it takes (an event or a re-prediction marker of
//! its own) and each batch of changes it applies would have to give back, recorded before
//! it is changed, so that the side can be taken back to any item's start exactly — the
//! groundwork of an engine that resolves each side's events ahead of what the other side
//! has told it and undoes them when a change arrives that they should have read.
//!
//! # What is recorded
//!
//! | record | when | restores |
//! |---|---|---|
//! | `Item` | before each item or batch | the clock, the event counts, the changes told |
//! | `State` | a particle an event or a change moves | its position, velocity, time, counter |
//! | `Pending` | a particle predicted again | its pending event |
//! | `Anchor` | a neighbourhood update | its anchor, and so its side |
//! | `Everyone` | every particle predicted again | every pending event |
//!
//! and the neighbourhood records its own ([`Neighbours::record`](crate::engine::neighbours::Neighbours)):
//! centres, rows and cell moves. What is recorded is chosen before the item from what its
//! event involves (the pair, or the particle alone, which are all it changes and all it
//! predicts again) or from the batch's changes, so the engine's own paths carry no
//! recording; an event counter about to wrap (every particle predicted again) records
//! every pending event.
//!
//! Undoing takes the records back latest first ([`Simulation::undo_to`]); a particle's
//! records at two items are both taken back, so the earlier one wins. The side's queue
//! takes back each event it held (its structure may differ, never the order it gives), and
//! the tests replay the undone events after an undo and compare them bit for bit with the
//! first time.

// Taken back by the tests today, and by the two-thread schedule that keeps the order of
// time once it lands.
#![cfg_attr(not(test), allow(dead_code))]

use super::super::Simulation;
use super::{Moved, Side};
use crate::engine::sources::{Event, EventCounts, EventKind};

/// One thing as it was before an item changed it.
#[derive(Clone, Debug)]
pub(crate) enum Record<const D: usize> {
    /// The start of an item: the clock, the counts, and the changes told so far.
    Item { time: f64, counts: EventCounts, told: u64 },
    /// Particle `k`'s state (what an event can change of it).
    State { k: u32, state: Moved<D> },
    /// Particle `k`'s pending event.
    Pending { k: u32, event: Event },
    /// Particle `k`'s anchor.
    Anchor { k: u32, x: f64 },
    /// Every particle's pending event.
    Everyone(Vec<Event>),
}

/// Where a side's records stood: the side's and its neighbourhood's.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Mark {
    records: usize,
    neighbourhood: usize,
}

impl Mark {
    /// This mark once the records before `forgotten` are forgotten.
    pub(crate) fn after_forgetting(self, forgotten: Mark) -> Mark {
        Mark { records: self.records - forgotten.records, neighbourhood: self.neighbourhood - forgotten.neighbourhood }
    }
}

impl<const D: usize> Simulation<D> {
    /// Starts (or stops and forgets) recording what each item changes.
    pub(crate) fn record(&mut self, on: bool) {
        self.region.as_deref_mut().expect("divided").journal = on.then(Vec::new);
        self.neighbours.record(on);
    }

    /// Where the records stand now: a mark to [`undo_to`](Self::undo_to).
    pub(crate) fn mark(&self) -> Mark {
        let journal = self.region.as_deref().expect("divided").journal.as_ref();
        Mark { records: journal.map_or(0, Vec::len), neighbourhood: self.neighbours.recorded() }
    }

    /// Whether this side records.
    #[inline]
    fn recording(&self) -> bool {
        self.region.as_deref().is_some_and(|r| r.journal.is_some())
    }

    #[inline]
    fn note(&mut self, record: Record<D>) {
        self.region.as_deref_mut().expect("divided").journal.as_mut().expect("recording").push(record);
    }

    /// Records the start of an item.
    fn note_item(&mut self) {
        let told = self.region.as_deref().expect("divided").told;
        self.note(Record::Item { time: self.time, counts: self.counts, told });
    }

    /// Records particle `k`'s state and pending event, and with `anchor` its anchor.
    fn note_particle(&mut self, k: usize, anchor: bool) {
        self.note(Record::State { k: k as u32, state: Moved::of(&self.particles[k]) });
        self.note(Record::Pending { k: k as u32, event: self.queue.get(k) });
        if anchor {
            let x = self.region.as_deref().expect("divided").anchor[k];
            self.note(Record::Anchor { k: k as u32, x });
        }
    }

    /// Records every pending event.
    fn note_everyone(&mut self) {
        let pending = self.queue.pending();
        self.note(Record::Everyone(pending));
    }

    /// Takes the earliest item, `owner`'s `next` (the queue's first), as
    /// [`take`](Simulation::take) does, recording first what it will change when recording.
    pub(super) fn take_noted(&mut self, owner: usize, next: Event) -> super::super::Taken<D> {
        if self.recording() {
            self.note_next(owner, next);
        }
        self.take_first(owner, next)
    }

    /// Records what the earliest item, `owner`'s `next`, will change.
    fn note_next(&mut self, owner: usize, next: Event) {
        self.note_item();
        if next.kind == EventKind::Nothing {
            return;
        }
        if !next.is_live(&self.particles) {
            // A marker: its owner is predicted again, nothing moves.
            self.note(Record::Pending { k: owner as u32, event: next });
            return;
        }
        let (Some(a), b) = next.involved(owner) else { unreachable!("an event of a particle") };
        let rebuild = next.kind == EventKind::Rebuild;
        self.note_particle(a, rebuild);
        if let Some(b) = b {
            self.note_particle(b, false);
        }
        // A counter about to wrap to 0 has every particle predicted again.
        if [Some(a), b].into_iter().flatten().any(|k| self.particles[k].events == u32::MAX) {
            self.note_everyone();
        }
    }

    /// Records what applying the other side's `changes` will change.
    pub(super) fn note_batch(&mut self, changes: &[super::Change<D>]) {
        if !self.recording() {
            return;
        }
        self.note_item();
        for change in changes {
            match change.what {
                super::What::Course { k, .. } => self.note_particle(k as usize, false),
                super::What::Neighbourhood { k, .. } => self.note_particle(k as usize, true),
                super::What::Members { .. } | super::What::Item { .. } => {}
                super::What::Everyone => self.note_everyone(),
            }
        }
    }

    /// Takes this side back to where [`mark`](Self::mark) gave `mark`: every record since,
    /// latest first.
    pub(crate) fn undo_to(&mut self, mark: Mark) {
        let region = self.region.as_deref_mut().expect("divided");
        let mut journal = region.journal.take().expect("recording");
        for record in journal.drain(mark.records..).rev() {
            match record {
                Record::Item { time, counts, told } => {
                    self.time = time;
                    self.counts = counts;
                    self.region.as_deref_mut().expect("divided").told = told;
                }
                Record::State { k, state } => state.set(&mut self.particles[k as usize]),
                Record::Pending { k, event } => self.queue.set(k as usize, event),
                Record::Anchor { k, x } => {
                    // As it was, not wrapped again: an anchor can be `L₀` itself (a position
                    // just below 0, wrapped, rounds up to it), which wrapping would make 0,
                    // on the other side.
                    let region = self.region.as_deref_mut().expect("divided");
                    region.anchor[k as usize] = x;
                    region.owner[k as usize] = Side::of(x, region.half);
                }
                Record::Everyone(pending) => {
                    for (k, event) in pending.into_iter().enumerate() {
                        self.queue.set(k, event);
                    }
                }
            }
        }
        self.neighbours.undo_to(mark.neighbourhood);
        self.region.as_deref_mut().expect("divided").journal = Some(journal);
    }

    /// Forgets the records before `mark`, which can no longer be undone: every mark given
    /// since is moved back by as many ([`Mark::after_forgetting`]).
    pub(crate) fn forget(&mut self, mark: Mark) {
        let region = self.region.as_deref_mut().expect("divided");
        region.journal.as_mut().expect("recording").drain(..mark.records);
        self.neighbours.forget(mark.neighbourhood);
    }

    /// How many records this side holds (its own and its neighbourhood's).
    pub(crate) fn records(&self) -> usize {
        let mark = self.mark();
        mark.records + mark.neighbourhood
    }
}
