//! The event queue: one [`Event`] event per particle, earliest first, in one of two
//! structures with the same answers ([`EventQueue`]):
//!
//! * a **calendar** of time buckets ([`calendar`]): replacing an event unlinks it from a
//!   short list and links it into another, a few dozen instructions; used while the engine's
//!   state fits the caches (below [`CALENDAR_BELOW`] particles);
//! * a 4-ary **tournament tree** ([`tree`]): replacing an event walks ⌈log₄ N⌉ levels to the
//!   root, each one cache line, and the path depends only on the particle — so the engine's
//!   lookahead can prefetch it. The calendar's lists are found from the new event's time,
//!   which is not known before the prediction, so at large N every update misses the cache.
//!
//! Every particle owns exactly one slot, so neither structure grows nor holds stale copies
//! (a binary heap of every prediction held about five stale events per collision at packing
//! fraction 0.65 and spent most of its time popping them). The order is the engine's total
//! order ([`Event::before`]): by time, then by kind, then by particles and axes — so the
//! earliest event never depends on how it was reached, nor on the structure.
//!
//! The calendar is the faster of the two while the engine's state fits the caches; from
//! [`CALENDAR_BELOW`] particles on, memory latency rules and the tree's prefetchable paths
//! win (the measurements are in `benches/HISTORY.md`).

use super::arrays::{Plain, Store};
use super::sources::{Event, EventKind};

pub mod calendar;
pub mod tree;

pub use calendar::Calendar;
pub use tree::Tree;

/// The calendar is used below this many particles, the tree from it on: about 6 MB of
/// engine state, past which memory latency rules and the tree's prefetchable paths win.
pub const CALENDAR_BELOW: usize = 3 << 14;

/// Which structure an [`EventQueue`] uses.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum QueueKind {
    /// Time buckets (`calendar.rs`).
    Calendar,
    /// A tournament tree (`tree.rs`).
    Tree,
}

impl QueueKind {
    /// The structure for `n` particles (see [`CALENDAR_BELOW`]).
    pub fn for_particles(n: usize) -> QueueKind {
        if n < CALENDAR_BELOW { QueueKind::Calendar } else { QueueKind::Tree }
    }
}

/// An [`Event`] packed into 16 bytes: its time and the two words of [`EventKind::pack`].
#[derive(Clone, Copy, Debug)]
#[repr(C)]
pub(super) struct Slot {
    pub(super) time: f64,
    who: u32,
    what: u32,
}

impl Slot {
    #[inline(always)]
    pub(super) fn pack(e: Event) -> Slot {
        let (who, what) = e.kind.pack();
        Slot { time: e.time, who, what }
    }

    #[inline(always)]
    pub(super) fn unpack(self) -> Event {
        Event { time: self.time, kind: EventKind::unpack(self.who, self.what) }
    }
}

/// Which of a particle's places in the queue [`EventQueue::footprint`] names.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Reads {
    /// Its slot (and the calendar's link).
    Slot,
    /// What replacing its event walks first.
    Path,
}

/// One pending event per particle, earliest first: a calendar or a tournament tree.
#[derive(Clone, Debug)]
pub enum EventQueue {
    /// Time buckets.
    Calendar(Calendar),
    /// A tournament tree.
    Tree(Tree),
}

impl EventQueue {
    /// A queue over `pending` (one event per particle, at most [`MAX_PARTICLES`]).
    pub fn new(pending: Vec<Event>, kind: QueueKind) -> Self {
        EventQueue::new_in(pending, kind, &Plain)
    }

    /// [`new`](Self::new), the tree's arrays built in `store` (the calendar is used only
    /// while the engine fits the caches, in ordinary vectors).
    pub(crate) fn new_in(pending: Vec<Event>, kind: QueueKind, store: &impl Store) -> Self {
        match kind {
            QueueKind::Calendar => EventQueue::Calendar(Calendar::new(pending)),
            QueueKind::Tree => EventQueue::Tree(Tree::new(pending, store)),
        }
    }

    /// A queue of `n` particles with nothing pending, the tree's arrays built in `store`.
    pub(crate) fn nothing_in(n: usize, kind: QueueKind, store: &impl Store) -> Self {
        match kind {
            QueueKind::Calendar => EventQueue::Calendar(Calendar::nothing(n)),
            QueueKind::Tree => EventQueue::Tree(Tree::nothing(n, store)),
        }
    }

    /// Which structure this is.
    pub fn kind(&self) -> QueueKind {
        match self {
            EventQueue::Calendar(_) => QueueKind::Calendar,
            EventQueue::Tree(_) => QueueKind::Tree,
        }
    }

    /// The pending events, by owner.
    pub fn pending(&self) -> Vec<Event> {
        match self {
            EventQueue::Calendar(q) => q.pending(),
            EventQueue::Tree(q) => q.pending(),
        }
    }

    /// Particle `owner`'s pending event.
    #[inline]
    pub fn get(&self, owner: usize) -> Event {
        match self {
            EventQueue::Calendar(q) => q.get(owner),
            EventQueue::Tree(q) => q.get(owner),
        }
    }

    /// The owner of the earliest event, and the event (`&mut`: the calendar moves its cursor).
    #[inline]
    pub fn first(&mut self) -> (usize, Event) {
        match self {
            EventQueue::Calendar(q) => q.first(),
            EventQueue::Tree(q) => q.first(),
        }
    }

    /// Replaces particle `owner`'s pending event.
    #[inline]
    pub fn set(&mut self, owner: usize, event: Event) {
        match self {
            EventQueue::Calendar(q) => q.set(owner, event),
            EventQueue::Tree(q) => q.set(owner, event),
        }
    }

    /// The owner of the earliest event among all particles except `a` and `b`, ties aside (a
    /// guess at the next event once `a` and `b` have collided, for prefetching).
    #[inline]
    pub fn runner_up(&self, a: usize, b: usize) -> usize {
        match self {
            EventQueue::Calendar(q) => q.runner_up(a, b),
            EventQueue::Tree(q) => q.runner_up(a, b),
        }
    }

    /// A guess at the next event once `a` and `b` have collided, for the lookahead: the
    /// calendar's [`runner_up`](Self::runner_up); the tree's leaves out the particles near
    /// `a` and `b` in the tree ([`Tree::guess_next`], whose walk is then shorter and stays
    /// in cache). Any answer is safe: it only decides what is prefetched.
    #[inline]
    pub fn guess_next(&self, a: usize, b: usize) -> usize {
        match self {
            EventQueue::Calendar(q) => q.runner_up(a, b),
            EventQueue::Tree(q) => q.guess_next(a, b),
        }
    }

    /// Where the memory is that reading `owner`'s event ([`Reads::Slot`]) or replacing it
    /// ([`Reads::Path`]: the lowest levels of its tree path, or its bucket's head) touches
    /// first — for the timing room to prefetch: `touch` is given each place.
    #[inline]
    pub(crate) fn footprint(&self, owner: usize, reads: Reads, touch: impl FnMut(*const u8)) {
        match self {
            EventQueue::Calendar(q) => q.footprint(owner, reads, touch),
            EventQueue::Tree(q) => q.footprint(owner, reads, touch),
        }
    }

    /// After every event has been replaced (the first predictions): the calendar chooses its
    /// bucket width for the new events (it would otherwise notice only after a thousand long
    /// searches); the tree has nothing to do.
    pub fn refit(&mut self) {
        if let EventQueue::Calendar(q) = self {
            q.rebuild();
        }
    }

    /// Heap bytes held (capacities).
    pub fn memory_bytes(&self) -> usize {
        match self {
            EventQueue::Calendar(q) => q.memory_bytes(),
            EventQueue::Tree(q) => q.memory_bytes(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const KINDS: [QueueKind; 2] = [QueueKind::Calendar, QueueKind::Tree];
    use crate::engine::sources::{EventKind, MAX_PARTICLES};
    use rand::rngs::Xoshiro256PlusPlus;
    use rand::{RngExt, SeedableRng};

    fn wall(time: f64) -> Event {
        Event { time, kind: EventKind::Wall { axis: 0, upper: true } }
    }

    /// Every kind of event comes back out of its 16-byte slot as it went in, at the
    /// extremes of every field.
    #[test]
    fn slots_keep_every_event() {
        let largest = MAX_PARTICLES as u32 - 1;
        let mut kinds = vec![EventKind::Nothing, EventKind::Rebuild];
        for axis in [0u8, 1, 2] {
            for flag in [false, true] {
                kinds.push(EventKind::Wall { axis, upper: flag });
            }
        }
        for partner in [0, 1, largest] {
            for partner_events in [0, 1, u32::MAX] {
                kinds.push(EventKind::Pair { partner, partner_events });
            }
        }
        for kind in kinds {
            for time in [0.0, -0.0, 1.5, f64::MIN_POSITIVE, f64::INFINITY] {
                let e = Event { time, kind };
                let back = Slot::pack(e).unpack();
                assert_eq!((back.time.to_bits(), back.kind), (time.to_bits(), kind));
            }
        }
    }

    /// Against a linear scan, after every one of many random replacements, for sizes that
    /// are and are not powers of two; ties are broken by the owner.
    #[test]
    fn first_is_the_minimum_in_the_total_order() {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(5);
        for (n, kind) in [1usize, 2, 3, 4, 5, 6, 7, 8, 13, 100].into_iter().flat_map(|n| KINDS.map(|k| (n, k))) {
            let mut queue = EventQueue::new((0..n).map(|_| Event::NOTHING).collect(), kind);
            for _ in 0..2000 {
                let owner = rng.random_range(0..n);
                // Few distinct times, so that ties are common; sometimes nothing.
                let r: u32 = rng.random_range(0..9);
                let event = if r == 8 { Event::NOTHING } else { wall(r as f64) };
                queue.set(owner, event);
                let (got, _) = queue.first();
                let want = (0..n)
                    .min_by(|&a, &b| {
                        let (pa, pb) = (queue.get(a), queue.get(b));
                        pa.time.total_cmp(&pb.time).then(pa.key(a as u32).cmp(&pb.key(b as u32)))
                    })
                    .unwrap();
                assert_eq!(got, want, "n = {n}, {kind:?}");
            }
        }
    }

    /// The earliest event by a linear scan in the total order.
    fn earliest(queue: &EventQueue, n: usize) -> usize {
        (0..n)
            .min_by(|&a, &b| {
                let (pa, pb) = (queue.get(a), queue.get(b));
                pa.time.total_cmp(&pb.time).then(pa.key(a as u32).cmp(&pb.key(b as u32)))
            })
            .unwrap()
    }

    /// A simulation's pattern of use, against a linear scan after every step: the earliest
    /// event is taken and replaced by a later one (sometimes far later, sometimes at +∞,
    /// sometimes at the same time — a tie), and now and then another particle's event is
    /// moved earlier than the earliest (a prediction from a clock behind it), all over long
    /// enough for the calendar to choose its width again several times — and across a jump
    /// of the time scale by 10⁶ (the width fitted before then puts every event in one
    /// bucket), and a stretch with a single pending event.
    #[test]
    fn the_structures_agree_with_a_scan_through_a_run() {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(17);
        for kind in KINDS {
            for n in [1usize, 2, 50, 300] {
                let mut queue = EventQueue::new((0..n).map(|k| wall(k as f64 * 0.01)).collect(), kind);
                let mut scale = 0.01;
                for step in 0..20 * n + 3000 {
                    if step == 10 * n + 1500 {
                        scale *= 1e6;
                    }
                    let (owner, first) = queue.first();
                    assert_eq!(owner, earliest(&queue, n), "{kind:?}, n = {n}, step {step}");
                    if first.time == f64::INFINITY {
                        // Everything is at +∞: start again from the last finite time.
                        for k in 0..n {
                            queue.set(k, wall(scale * k as f64));
                        }
                        continue;
                    }
                    let r: u32 = rng.random_range(0..100);
                    let t = match r {
                        0 => f64::INFINITY,
                        1..=3 => first.time + scale * 1e4 * rng.random_range(0.0..1.0),
                        4..=9 => first.time,
                        _ => first.time + scale * rng.random_range(0.0..2.0),
                    };
                    queue.set(owner, wall(t));
                    if r % 10 == 7 {
                        let other = rng.random_range(0..n);
                        let back = (first.time - scale * rng.random_range(0.0..0.5)).max(0.0);
                        queue.set(other, wall(back));
                    }
                    if n > 2 && step % 997 == 0 {
                        // A stretch where one particle is pending and everyone else is not.
                        for k in 1..n {
                            queue.set(k, Event::NOTHING);
                        }
                    }
                }
            }
        }
    }

    /// The two owners of one pair event (each holding the pair, at the same time) have the
    /// same key; the tree then takes the one in the left subtree, as a tournament of pairs
    /// in which the left one wins ties — at every level, whether two, three or four children
    /// tie (some at `+∞`), and whatever else is pending (checked against that tournament
    /// played out over the tree's positions). Which owner comes first decides which partner
    /// a step resolves from, so the tie must fall the same way in every build.
    #[test]
    fn the_tree_breaks_equal_keys_to_the_left() {
        let pair = |time: f64, partner: usize| Event {
            time,
            kind: EventKind::Pair { partner: partner as u32, partner_events: 0 },
        };
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(23);
        let mut lower_lost = 0;
        for n in [4usize, 5, 16, 17, 64, 300] {
            let mut queue = EventQueue::new((0..n).map(|_| Event::NOTHING).collect(), QueueKind::Tree);
            let EventQueue::Tree(tree) = &queue else { unreachable!() };
            let m = tree.internal_nodes();
            for _ in 0..(60_000 / n).max(300) {
                // A background of events at +∞ and at 3, 4 and 5: many share a time.
                for k in 0..n {
                    let r: u32 = rng.random_range(0..4);
                    queue.set(k, if r == 0 { Event::NOTHING } else { wall(2.0 + r as f64) });
                }
                let (p, q) = (rng.random_range(0..n), rng.random_range(0..n));
                if p == q {
                    continue;
                }
                // At t = 3 walls share the time, but a pair ranks before them.
                let t = if rng.random_range(0..2) == 0 { 1.0 } else { 3.0 };
                queue.set(q, pair(t, p));
                queue.set(p, pair(t, q));
                // The tournament over positions: node `k`'s children are `4k + 1 … 4k + 4`,
                // slot `s` is position `m + s` (those past the particles hold nothing).
                fn play(queue: &EventQueue, m: usize, n: usize, k: usize) -> (usize, Event) {
                    if k >= m {
                        let s = k - m;
                        return (s, if s < n { queue.get(s) } else { Event::NOTHING });
                    }
                    let mut best = play(queue, m, n, 4 * k + 1);
                    for c in 4 * k + 2..4 * k + 5 {
                        let other = play(queue, m, n, c);
                        if other.1.before(other.0 as u32, &best.1, best.0 as u32) {
                            best = other;
                        }
                    }
                    best
                }
                let (want, _) = if m == 0 { (0, Event::NOTHING) } else { play(&queue, m, n, 0) };
                let (first, event) = queue.first();
                assert_eq!((first, event.time), (want, t), "n = {n}, pair {p}, {q}");
                assert!(first == p || first == q, "n = {n}, pair {p}, {q}");
                lower_lost += (first != p.min(q)) as usize;
            }
        }
        // The left subtree is not always the lower slot (slots lie on two levels).
        assert!(lower_lost > 0);
    }

    /// Against a linear scan: the tree's `guess_next(a, b)` is at least as early as every
    /// particle outside the subtrees of `a` and `b` that it leaves out (`guess_levels`
    /// levels up, never above the top three levels), and where neither subtree holds the
    /// other (they can be one level apart, the slots lying on two levels) it is the earliest
    /// of those, outside both.
    #[test]
    fn the_tree_guesses_the_earliest_outside_the_pair_s_subtrees() {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(12);
        let mut exact = 0;
        for n in [300usize, 1000, 1100, 5000, 20_000] {
            let skip = tree::guess_levels(n);
            assert!(skip >= 1, "n = {n}");
            let mut queue = EventQueue::new((0..n).map(|_| Event::NOTHING).collect(), QueueKind::Tree);
            for k in 0..n {
                queue.set(k, wall(rng.random_range(0.0..1.0)));
            }
            let EventQueue::Tree(tree) = &queue else { unreachable!() };
            let m = tree.internal_nodes();
            let up = |k: usize| (0..skip).fold(k, |k, _| if k >= tree::TOP { (k - 1) / 4 } else { k });
            // Whether tree position `k` lies under node `top`.
            let under = |mut k: usize, top: usize| loop {
                if k == top {
                    return true;
                }
                if k < top || k == 0 {
                    return false;
                }
                k = (k - 1) / 4;
            };
            for _ in 0..2000 {
                let owner = rng.random_range(0..n);
                queue.set(owner, wall(rng.random_range(0.0..1.0)));
                let EventQueue::Tree(tree) = &queue else { unreachable!() };
                let (a, b) = (rng.random_range(0..n), rng.random_range(0..n));
                let (x, y) = (up(m + a), up(m + b));
                let outside = |k: usize| !under(m + k, x) && !under(m + k, y);
                let want = (0..n).filter(|&k| outside(k)).map(|k| queue.get(k).time).fold(f64::INFINITY, f64::min);
                let got = tree.guess_next(a, b);
                assert!(queue.get(got).time <= want, "n = {n}, {a}, {b} → {got}");
                if !under(x, y) && !under(y, x) {
                    exact += 1;
                    assert!(outside(got), "n = {n}, {a}, {b} → {got}");
                    assert_eq!(queue.get(got).time.to_bits(), want.to_bits(), "n = {n}, {a}, {b}");
                }
            }
        }
        assert!(exact > 9000, "{exact}");
    }

    /// Against a linear scan: the time of `runner_up(a, b)` is the earliest time among
    /// all particles but `a` and `b`, for paths that meet low, high and not until the root.
    #[test]
    fn runner_up_is_the_earliest_of_the_others() {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(11);
        for (n, kind) in [3usize, 4, 5, 6, 7, 13, 100, 1000].into_iter().flat_map(|n| KINDS.map(|k| (n, k))) {
            let mut queue = EventQueue::new((0..n).map(|_| Event::NOTHING).collect(), kind);
            for _ in 0..2000 {
                let owner = rng.random_range(0..n);
                queue.set(owner, wall(rng.random_range(0.0..1.0)));
                let (a, b) = (rng.random_range(0..n), rng.random_range(0..n));
                let got = queue.runner_up(a, b);
                let want =
                    (0..n).filter(|&k| k != a && k != b).map(|k| queue.get(k).time).fold(f64::INFINITY, f64::min);
                // With nobody else pending, any answer will do (there is nothing to prefetch).
                if want < f64::INFINITY {
                    assert!(got != a && got != b, "n = {n}, {kind:?}, {a}, {b} → {got}");
                    assert_eq!(queue.get(got).time.to_bits(), want.to_bits(), "n = {n}, {kind:?}, {a}, {b}");
                }
            }
        }
    }
}
