//! The two sides in two threads, in the order of time: [`Divided::run_ordered`] gives the
//! whole box's events bit for bit, each side resolving its own events ahead of what the
//! other has told it and undoing them when a change arrives that they should have read.
//!
//! # The schedule
//!
//! Every item (an event or a re-prediction marker) and every batch of changes has a place
//! in the [total order](crate::engine::sources#the-total-order) ([`Key`]; a batch carries
//! the key of the item that sent it). A side takes its own items in queue order, and before
//! each applies the other side's batches that come before it.
//!
//! A side's own items need not come in the order of their events: a marker re-predicts its
//! owner from the clock of the last event, and the new event may fall before the marker
//! when its partner belongs to the other side (whose queue holds the pair's covering
//! event). The whole box, taking the earlier of the two sides' next items each time, would
//! have taken the other side's event first. An item's place is therefore the *latest key
//! taken on its side so far*, its own or an earlier item's: taking the earlier of two
//! heads merges two sequences exactly as sorting them by their running maxima does, so
//! with these keys a batch comes before an item of the receiver's if and only if the whole
//! box takes it first. Reads are stamped at these keys' times, so that a read by any item
//! placed after a batch is at or after the batch's time. A batch
//! that arrives *late* — before the side's last item — is applied where it arrives when
//! nothing since could have read what it changes:
//!
//! * no particle it changes was read at or after its time (by an item of this side, a
//!   prediction, or an earlier batch), before or after its rows are changed
//!   ([`Watch::read_from`]);
//! * no re-prediction marker taken since found an event earlier than its time. A marker
//!   predicts its owner from the clock of the last event, which the batch would have moved
//!   on, but the clock enters a prediction only as a floor under every candidate's time
//!   (pairs are solved from the later of the two particles' own times, walls and the skin's
//!   exit from the particle's own,
//!   [`exit_time`](crate::engine::neighbours::Neighbours::exit_time); a pair's image is
//!   taken at the clock, the same at any clock for neighbours nearer than half the box): a
//!   result no earlier than the batch's time is the same from either clock, bit for bit;
//! * none of this side's particles it predicts again comes due before the side's last item;
//! * it does not predict every particle again (an event counter wrapped).
//!
//! Otherwise it *conflicts*, and both sides meet (a rendezvous, below) and go back to it:
//! every item and batch after it in the order is undone from the undo records
//! ([`journal`](super::journal)), the batches at or before it that were undone with them
//! (late ones applied above later items) are applied again, and both sides go on from
//! there. Nothing before the earliest conflict is undone, and the batch that conflicted is
//! applied in its place, so every rendezvous moves the committed point forward.
//!
//! Two things keep conflicts rare without deciding anything. A collision across the border
//! is in both sides' queues, and the lower side's copy comes first in the order: the upper
//! side holds its copy back until the lower side's next item comes after it and the
//! batches sent before are taken (the lower copy's batch makes the upper copy a marker;
//! taken first, it would be resolved twice, and undone), while the lower side takes its
//! copy at once (undone in the rare case that an earlier item of the upper side's changes
//! either particle). And a side waits while its next item is more than the [`Lead`] ahead
//! of the other's.
//!
//! # Rendezvous
//!
//! The sides meet when one asks: on a conflict, when its records grow long, and when both
//! have reached the end. Both stop; each applies what has arrived; the earliest conflict
//! posted is gone back to on both sides; each forgets the records of everything before
//! both sides' next items, which no batch can come before any more; they end when neither
//! has an item before the end and nothing conflicted.

use super::super::{Simulation, Taken};
use super::journal::Mark;
use super::{Change, Divided, Lead, Watch, What, changed, mailbox};
use crate::engine::sources::{Event, EventKind};
use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering, fence};

/// A side asks for a rendezvous once it holds this many items and batches to undo.
const MOST_STEPS: usize = 1024;

/// A place in the total order: `owner`'s `event` on `side` (0 the lower). The two sides'
/// copies of one collision across the border have the same event and owner pair: the
/// lower side's comes first, as [`Divided::step`] takes it.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Key {
    event: Event,
    owner: u32,
    side: u8,
}

impl Key {
    fn before(&self, other: &Key) -> bool {
        self.event.before(self.owner, &other.event, other.owner)
            || (!other.event.before(other.owner, &self.event, self.owner) && self.side < other.side)
    }

    fn time(&self) -> f64 {
        self.event.time
    }

    /// The key a batch carries in its first change.
    fn of_batch<const D: usize>(batch: &[Change<D>], side: u8) -> Key {
        match batch[0].what {
            What::Item { owner, event } => Key { event, owner, side },
            _ => unreachable!("every batch opens with its item"),
        }
    }
}

/// What a side shows the other: its next item, the batches it has sent and applied.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Shown {
    key: Key,
    sent: u64,
    applied: u64,
}

/// A side's [`Shown`], on a cache line of its own, written by that side alone and read by
/// the other whole (a sequence count odd while it is written).
#[repr(align(128))]
#[derive(Default)]
struct Shop {
    sequence: AtomicU64,
    time: AtomicU64,
    kind: AtomicU64,
    owner: AtomicU64,
    sent: AtomicU64,
    applied: AtomicU64,
}

impl Shop {
    fn show(&self, shown: Shown) {
        let s = self.sequence.load(Ordering::Relaxed);
        self.sequence.store(s + 1, Ordering::Relaxed);
        fence(Ordering::Release);
        let (who, what) = shown.key.event.kind.pack();
        self.time.store(shown.key.event.time.to_bits(), Ordering::Relaxed);
        self.kind.store(u64::from(who) << 32 | u64::from(what), Ordering::Relaxed);
        self.owner.store(u64::from(shown.key.owner) << 8 | u64::from(shown.key.side), Ordering::Relaxed);
        self.sent.store(shown.sent, Ordering::Relaxed);
        self.applied.store(shown.applied, Ordering::Relaxed);
        self.sequence.store(s + 2, Ordering::Release);
    }

    fn read(&self) -> Shown {
        loop {
            let s = self.sequence.load(Ordering::Acquire);
            if s & 1 == 1 {
                std::hint::spin_loop();
                continue;
            }
            let time = f64::from_bits(self.time.load(Ordering::Relaxed));
            let kind = self.kind.load(Ordering::Relaxed);
            let owner = self.owner.load(Ordering::Relaxed);
            let (sent, applied) = (self.sent.load(Ordering::Relaxed), self.applied.load(Ordering::Relaxed));
            fence(Ordering::Acquire);
            if self.sequence.load(Ordering::Relaxed) == s {
                let kind = EventKind::unpack((kind >> 32) as u32, kind as u32);
                let key = Key { event: Event { time, kind }, owner: (owner >> 8) as u32, side: owner as u8 };
                return Shown { key, sent, applied };
            }
        }
    }
}

/// Where the two threads wait for each other in a rendezvous: each arrival counted, and
/// each thread spinning (then yielding) until the other has arrived as often. A meeting
/// then costs a few hand-overs of one cache line rather than a sleep and a wake-up through
/// the kernel, as a lock and condition variable would.
#[repr(align(128))]
#[derive(Default)]
struct Meeting {
    arrived: AtomicU64,
}

impl Meeting {
    fn wait(&self) {
        let mine = self.arrived.fetch_add(1, Ordering::AcqRel) + 1;
        // Both threads arrive once a meeting: the meeting is over at the next even count.
        let over = mine.next_multiple_of(2);
        let mut turns = 0u32;
        while self.arrived.load(Ordering::Acquire) < over {
            turns += 1;
            if turns.is_multiple_of(64) {
                std::thread::yield_now();
            } else {
                std::hint::spin_loop();
            }
        }
    }
}

/// What the two threads share besides their batches.
struct Shared {
    shops: [Shop; 2],
    /// A rendezvous is asked for.
    want: AtomicBool,
    /// The earliest conflict posted since the last rendezvous.
    cut: Mutex<Option<Key>>,
    barrier: Meeting,
    end: f64,
    lead: Lead,
}

impl Shared {
    fn post(&self, cut: Key) {
        let mut earliest = self.cut.lock().unwrap_or_else(|e| e.into_inner());
        if earliest.is_none_or(|e| cut.before(&e)) {
            *earliest = Some(cut);
        }
        self.want.store(true, Ordering::Release);
    }
}

/// One item or batch a side took, with where its records start.
#[derive(Clone, Copy, Debug)]
struct Step {
    key: Key,
    mark: Mark,
    what: StepWhat,
}

#[derive(Clone, Copy, Debug)]
enum StepWhat {
    /// An item of this side's; for a marker, `Some` of the time its owner's prediction
    /// found; whether it sent a batch.
    Own { marker: Option<f64>, sent: bool },
    /// A batch of the other side's, kept in `inputs[from..to]` to be applied again.
    Input { from: usize, to: usize },
}

/// A side's bookkeeping for the schedule.
struct Book<const D: usize> {
    side: u8,
    steps: Vec<Step>,
    inputs: Vec<Change<D>>,
    /// Batches taken from the mailbox; those from `cursor` on come after the side's next
    /// item.
    pending: mailbox::Batches<Change<D>>,
    cursor: usize,
    watch: Watch,
    /// The last item of this side's taken.
    last: Option<Key>,
    /// This side's next keys ([`next_keys`](Simulation::next_keys)), until it changes.
    next: Option<(Key, Key)>,
    /// What this side last showed: written again only when it changes, so that a side
    /// that waits does not take the line from the other at every turn.
    shown: Option<Shown>,
    sent: u64,
    applied: u64,
    run: SideOrdered,
}

impl<const D: usize> Book<D> {
    /// Shows `key` as this side's next item, with its counts, unless that is shown already.
    fn show(&mut self, shop: &Shop, key: Key) {
        let shown = Shown { key, sent: self.sent, applied: self.applied };
        if self.shown != Some(shown) {
            shop.show(shown);
            self.shown = Some(shown);
        }
    }
}

/// What one side of [`Divided::run_ordered`] counted.
#[derive(Clone, Copy, Debug, Default)]
struct SideOrdered {
    items: u64,
    undone: u64,
    late: u64,
    conflicts: u64,
    rendezvous: u64,
    waits: u64,
    seconds: f64,
}

/// What [`Divided::run_ordered`] counted, the lower side's first in each pair.
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub struct Ordered {
    /// Items (events and re-prediction markers) each side took, those undone and taken
    /// again included.
    pub items: [u64; 2],
    /// Items each side undid.
    pub undone: [u64; 2],
    /// Batches that arrived after an item of the receiver's that comes later.
    pub late: [u64; 2],
    /// Of those, how many conflicted (and were gone back to).
    pub conflicts: [u64; 2],
    /// How many times the sides met.
    pub rendezvous: u64,
    /// How often each side found its next item held back (by the lead, or a collision with
    /// the other side's particle that the other side's next item does not yet follow).
    pub waits: [u64; 2],
    /// Each side's thread's time, in seconds.
    pub seconds: [f64; 2],
}

impl<const D: usize> Divided<D> {
    /// Runs both sides at once, each in its own thread, until neither has an item before
    /// `end`, keeping the order of time (docs/engine.md, "Two threads in the order of time"): afterwards the divided box
    /// holds what the whole box holds after its items before `end`, bit for bit, and [`step`]
    /// goes on from there. `lead` holds a side back while its next item is further ahead of
    /// the other's than it allows.
    ///
    /// [`step`]: Divided::step
    pub fn run_ordered(&mut self, end: f64, lead: Lead) -> Ordered {
        let shared = Shared {
            shops: [Shop::default(), Shop::default()],
            want: AtomicBool::new(false),
            cut: Mutex::new(None),
            barrier: Meeting::default(),
            end,
            lead,
        };
        let mailboxes = [mailbox::Mailbox::default(), mailbox::Mailbox::default()];
        let [to_lower, to_upper] = &mailboxes;
        let [lower, upper] = &mut self.sides;
        let [a, b] = std::thread::scope(|scope| {
            let thread = scope.spawn(|| lower.run_ordered_side(&shared, to_lower, to_upper));
            let here = upper.run_ordered_side(&shared, to_upper, to_lower);
            [thread.join().expect("the lower side's thread"), here]
        });
        Ordered {
            items: [a.items, b.items],
            undone: [a.undone, b.undone],
            late: [a.late, b.late],
            conflicts: [a.conflicts, b.conflicts],
            rendezvous: a.rendezvous,
            waits: [a.waits, b.waits],
            seconds: [a.seconds, b.seconds],
        }
    }
}

impl<const D: usize> Simulation<D> {
    /// One side of [`Divided::run_ordered`]: takes its items before the end and applies
    /// `inbox`'s batches in the order of time, sending its own to `out`.
    fn run_ordered_side(
        &mut self,
        shared: &Shared,
        inbox: &mailbox::Mailbox<Change<D>>,
        out: &mailbox::Mailbox<Change<D>>,
    ) -> SideOrdered {
        let clock = std::time::Instant::now();
        let side = self.region.as_deref().expect("divided").side as u8;
        let me = side as usize;
        let mut book = Book {
            side,
            steps: Vec::new(),
            inputs: Vec::new(),
            pending: mailbox::Batches::default(),
            cursor: 0,
            watch: Watch::new(self.particles.len(), self.neighbours.cell_count()),
            last: None,
            next: None,
            shown: None,
            sent: 0,
            applied: 0,
            run: SideOrdered::default(),
        };
        self.record(true);
        let mut idle = 0u32;
        loop {
            if shared.want.load(Ordering::Acquire) {
                if self.rendezvous(&mut book, shared, inbox) {
                    break;
                }
                continue;
            }
            if let Some(cut) = self.apply_due(&mut book, inbox) {
                shared.post(cut);
                continue;
            }
            let (raw, key) = self.next_keys(&mut book);
            book.show(&shared.shops[me], key);
            if !self.may_take(&raw, &key, &book, shared, inbox) {
                book.run.waits += u64::from(idle == 0);
                idle += 1;
                if idle % 64 == 0 {
                    std::thread::yield_now();
                } else {
                    std::hint::spin_loop();
                }
                continue;
            }
            idle = 0;
            self.take_one(raw, key, &mut book);
            let region = self.region.as_deref_mut().expect("divided");
            if let Some(&Change { time, .. }) = region.outbox.first() {
                // The batch opens with its place in the order: the item's key, which may be
                // an earlier item's (see the module), at the item's time (the receiver's
                // clock is the batch's first change's).
                region.outbox.insert(0, Change { time, what: What::Item { owner: key.owner, event: key.event } });
                out.send(&region.outbox);
                region.outbox.clear();
                book.sent += 1;
                if let Some(Step { what: StepWhat::Own { sent, .. }, .. }) = book.steps.last_mut() {
                    *sent = true;
                }
            }
            if book.steps.len() > MOST_STEPS {
                shared.want.store(true, Ordering::Release);
            }
        }
        self.record(false);
        book.run.seconds = clock.elapsed().as_secs_f64();
        book.run
    }

    /// Whether this side may take its next item (`key`) now: before the end, within the
    /// lead, and, for the upper side's copy of a collision across the border, once the
    /// lower side's copy is taken and its batch applied. At the end, asks for the last rendezvous once both sides are there and
    /// every batch has been applied.
    fn may_take(
        &self,
        raw: &Key,
        key: &Key,
        book: &Book<D>,
        shared: &Shared,
        inbox: &mailbox::Mailbox<Change<D>>,
    ) -> bool {
        let other = || shared.shops[1 - book.side as usize].read();
        if key.time() >= shared.end {
            let theirs = other();
            if theirs.key.time() >= shared.end && theirs.applied == book.sent && theirs.sent == book.applied {
                shared.want.store(true, Ordering::Release);
            }
            return false;
        }
        let across = match raw.event.kind {
            EventKind::Pair { partner, .. } => !self.owns(partner as usize) && raw.event.is_live(&self.particles),
            _ => false,
        };
        if let Lead::Within(ahead) = shared.lead
            && key.time() > other().key.time() + ahead
        {
            return false;
        }
        // The lower side's copy of a collision across the border comes first: the upper side
        // waits until the lower side's next item follows it, and then until every batch
        // sent before that item was shown is taken (the lower copy's among them, which
        // makes this copy a marker): a batch held back as not yet due comes after this
        // item, and so does everything sent after it. The lower side goes on, and undoes
        // its copy should an earlier item of the other side's turn out to change either
        // particle.
        let taken = || book.cursor < book.pending.len() || !inbox.waiting();
        !across || book.side == 0 || (key.before(&other().key) && taken())
    }

    /// The next item's own key and the key that places it in the order: the later of its
    /// own and the last item's (see the module).
    ///
    /// Kept until the side changes: a side that waits would otherwise search its queue at
    /// every turn (and a calendar queue rebuilds itself after so many searches).
    fn next_keys(&mut self, book: &mut Book<D>) -> (Key, Key) {
        if let Some(keys) = book.next {
            return keys;
        }
        let (owner, event) = self.earliest();
        let raw = Key { event, owner, side: book.side };
        let keys = (raw, book.last.filter(|last| raw.before(last)).unwrap_or(raw));
        book.next = Some(keys);
        keys
    }

    /// Takes the next item (`key`), recording it.
    fn take_one(&mut self, raw: Key, key: Key, book: &mut Book<D>) {
        let marker = raw.event.kind != EventKind::Nothing && !raw.event.is_live(&self.particles);
        let mark = self.mark();
        match self.take_noted(raw.owner as usize, raw.event) {
            Taken::Event(outcome) => {
                let (a, b) = match outcome {
                    crate::engine::sources::Outcome::Pair { i, j, .. } => (i, j),
                    crate::engine::sources::Outcome::Wall { i, .. }
                    | crate::engine::sources::Outcome::Rebuild { i } => (i, i),
                    _ => unreachable!("a divided box neither samples nor grows"),
                };
                book.watch.stamp(&self.neighbours, a, key.time());
                book.watch.stamp(&self.neighbours, b, key.time());
            }
            Taken::Bookkeeping => book.watch.stamp(&self.neighbours, raw.owner as usize, key.time()),
            Taken::End => unreachable!("an item before the end"),
        }
        book.run.items += 1;
        let found = marker.then(|| self.queue.get(raw.owner as usize).time);
        book.steps.push(Step { key, mark, what: StepWhat::Own { marker: found, sent: false } });
        book.last = Some(key);
        book.next = None;
    }

    /// Applies the batches that come before this side's next item, taking them from
    /// `inbox` as needed; the first that conflicts is returned.
    fn apply_due(&mut self, book: &mut Book<D>, inbox: &mailbox::Mailbox<Change<D>>) -> Option<Key> {
        loop {
            if book.cursor == book.pending.len() {
                // Taking empties `pending` first, whether anything came or not.
                let came = inbox.take(&mut book.pending);
                book.cursor = 0;
                if !came {
                    return None;
                }
            }
            let key = Key::of_batch(book.pending.get(book.cursor), 1 - book.side);
            if !key.before(&self.next_keys(book).1) {
                return None;
            }
            let batch = book.pending.get(book.cursor);
            book.cursor += 1;
            let from = book.inputs.len();
            book.inputs.extend_from_slice(batch);
            let to = book.inputs.len();
            if let Some(cut) = self.apply_input(book, from, to, true) {
                return Some(cut);
            }
        }
    }

    /// Applies the batch `book.inputs[from..to]`; with `check`, a late one is checked (see
    /// the [module](self)) and returned if it conflicts.
    fn apply_input(&mut self, book: &mut Book<D>, from: usize, to: usize, check: bool) -> Option<Key> {
        let batch = &book.inputs[from..to];
        let key = Key::of_batch(batch, 1 - book.side);
        let t = key.time();
        let late = check && book.last.is_some_and(|last| key.before(&last));
        let mut conflict = false;
        if late {
            book.run.late += 1;
            conflict = batch.iter().any(|c| matches!(c.what, What::Everyone))
                || changed(batch).any(|k| book.watch.read_from(&self.neighbours, k, t))
                || Self::marker_since(&book.steps, &key);
        }
        let mark = self.mark();
        let clock = self.time;
        self.receive(batch);
        book.next = None;
        if late {
            self.time = clock;
            let last = book.last.expect("late");
            conflict = conflict
                || changed(batch).any(|k| book.watch.read_from(&self.neighbours, k, t))
                || changed(batch).any(|k| {
                    self.owns(k) && Key { event: self.queue.get(k), owner: k as u32, side: book.side }.before(&last)
                });
        }
        for k in changed(batch) {
            book.watch.stamp(&self.neighbours, k, t);
        }
        book.steps.push(Step { key, mark, what: StepWhat::Input { from, to } });
        book.applied += 1;
        book.run.conflicts += u64::from(conflict);
        conflict.then_some(key)
    }

    /// Whether a marker taken after `key` found an event earlier than its time (see the
    /// module).
    fn marker_since(steps: &[Step], key: &Key) -> bool {
        for step in steps.iter().rev() {
            if let StepWhat::Own { marker, .. } = step.what {
                if !key.before(&step.key) {
                    return false;
                }
                if marker.is_some_and(|found| found < key.time()) {
                    return true;
                }
            }
        }
        false
    }

    /// Meets the other side (see the [module](self)); whether the run ends.
    fn rendezvous(&mut self, book: &mut Book<D>, shared: &Shared, inbox: &mailbox::Mailbox<Change<D>>) -> bool {
        let me = book.side as usize;
        book.run.rendezvous += 1;
        shared.barrier.wait();
        // Neither side sends now: apply what has arrived.
        while let Some(cut) = self.apply_due(book, inbox) {
            shared.post(cut);
        }
        shared.barrier.wait();
        let cut = *shared.cut.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(cut) = cut {
            self.go_back(book, cut);
            // What is still to apply came from items after the cut, undone.
            book.pending.clear();
            book.cursor = 0;
            inbox.take(&mut book.pending);
            book.pending.clear();
        }
        let key = self.next_keys(book).1;
        book.show(&shared.shops[me], key);
        shared.barrier.wait();
        let theirs = shared.shops[1 - me].read();
        let floor = if key.before(&theirs.key) { key } else { theirs.key };
        self.commit(book, &floor);
        let end = cut.is_none()
            && key.time() >= shared.end
            && theirs.key.time() >= shared.end
            && book.cursor == book.pending.len();
        if me == 0 {
            *shared.cut.lock().unwrap_or_else(|e| e.into_inner()) = None;
            shared.want.store(false, Ordering::Release);
        }
        shared.barrier.wait();
        end
    }

    /// Undoes every item and batch after `cut`, and applies again the batches at or before
    /// it that were undone with them.
    fn go_back(&mut self, book: &mut Book<D>, cut: Key) {
        let Some(p) = book.steps.iter().position(|s| cut.before(&s.key)) else { return };
        self.undo_to(book.steps[p].mark);
        let undone = book.steps.split_off(p);
        for step in &undone {
            match step.what {
                StepWhat::Own { sent, .. } => {
                    book.run.undone += 1;
                    book.sent -= u64::from(sent);
                }
                StepWhat::Input { .. } => book.applied -= 1,
            }
        }
        book.last = book.steps.iter().rev().find(|s| matches!(s.what, StepWhat::Own { .. })).map(|s| s.key);
        book.next = None;
        book.watch.clamp(cut.time());
        for step in undone {
            if let StepWhat::Input { from, to } = step.what
                && !cut.before(&step.key)
            {
                self.apply_input(book, from, to, false);
            }
        }
    }

    /// Forgets the records of every step before `floor`: no batch can come before it now.
    fn commit(&mut self, book: &mut Book<D>, floor: &Key) {
        let q = book.steps.iter().position(|s| !s.key.before(floor)).unwrap_or(book.steps.len());
        let mark = book.steps.get(q).map_or_else(|| self.mark(), |s| s.mark);
        self.forget(mark);
        book.steps.drain(..q);
        let kept = book.steps.iter().filter_map(|s| match s.what {
            StepWhat::Input { from, .. } => Some(from),
            StepWhat::Own { .. } => None,
        });
        let first = kept.min().unwrap_or(book.inputs.len());
        book.inputs.drain(..first);
        for step in &mut book.steps {
            step.mark = step.mark.after_forgetting(mark);
            if let StepWhat::Input { from, to } = &mut step.what {
                *from -= first;
                *to -= first;
            }
        }
    }
}
