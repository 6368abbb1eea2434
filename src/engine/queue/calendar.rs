//! The calendar: one [`Event`] event per particle, threaded through buckets of time.
//!
//! The slots are threaded through a *calendar* (Brown 1988; as used for event-driven dynamics by Paul, J. Comput.
//! Phys. 221, 615 (2007), and Smallenburg 2022): time is cut into buckets of width `w`, an
//! event at time `t` belongs to bucket `k = ⌊t/w⌋`, and bucket `k` is kept, unsorted, in the
//! singly linked list `k mod B` (`B` a power of two, so a list also holds the rare events a
//! multiple of `B·w` later, which the search skips). Replacing an event unlinks it from its
//! list (a walk of about two entries) and links the new one in front: a few dozen
//! instructions, where the [tournament tree](super::tree) walks ⌈log₄ N⌉ levels to the root.
//!
//! The earliest event is found in the first bucket, from a cursor `current`, that holds an
//! event of its own index: bucket indices are a monotone function of time (a product and a
//! truncation, both monotone), so every event there comes no later than any event of a later
//! bucket, and events at equal times share a bucket. Within it the engine's total order
//! decides ([`Event::before`]: by time, then by kind, then by particles and axes), exactly
//! as everywhere else, so the earliest event never depends on how it was reached — nor on
//! `w`, which only sets how many events a bucket holds. `w` is chosen from the pending events
//! (about one per bucket at the front of the calendar: searches then visit about four list
//! entries and empty buckets; widths from half to four times this cost about the same) when the queue is built,
//! again every `4N` searches, and as soon as the searches grow long; an event earlier than the cursor (a prediction made from a clock
//! behind the last event, after a re-prediction marker) moves the cursor back; after a whole
//! round of `B` empty buckets the cursor jumps to the earliest bucket directly.
//! Events at `+∞` are kept out of the lists and found by a scan once nothing else is left.
//!
//! Memory: 16 bytes per slot, 4 per link and 4 per bucket (`B` = N rounded up to a power of
//! two): 24–28 bytes per particle.

use super::Reads;
use super::Slot;
use crate::engine::sources::{Event, MAX_PARTICLES};

/// End of a bucket list.
const NONE: u32 = u32::MAX;

/// Searches between checks of the calendar's load (see [`Calendar::first`]).
const CHECK_EVERY: usize = 1024;

/// The most bucket entries and empty buckets a search may visit on average before the
/// width is chosen again (about 3 when it fits the events).
const MOST_WORK: usize = 16;

/// One pending event per particle, earliest first (see the module documentation).
#[derive(Clone, Debug)]
pub struct Calendar {
    /// Particle `p`'s pending event.
    slots: Vec<Slot>,
    /// The next particle in `p`'s bucket list (`NONE` at the end, and for events at `+∞`).
    next: Vec<u32>,
    /// The first particle of each bucket list.
    heads: Vec<u32>,
    /// `B − 1`.
    mask: u64,
    /// `1/w`.
    inverse: f64,
    /// No linked event has a bucket index below this.
    current: u64,
    /// Events linked (finite times).
    linked: usize,
    /// Searches since `w` was last chosen.
    searches: usize,
    /// Bucket entries and empty buckets visited by those searches.
    work: usize,
}

impl Calendar {
    /// A queue over `pending` (one event per particle, at most [`MAX_PARTICLES`]).
    pub fn new(pending: Vec<Event>) -> Self {
        let mut queue = Calendar::nothing(pending.len());
        for (p, e) in pending.into_iter().enumerate() {
            queue.slots[p] = Slot::pack(e);
        }
        queue.rebuild();
        queue
    }

    /// A queue of `n` particles with nothing pending.
    pub fn nothing(n: usize) -> Self {
        assert!((1..=MAX_PARTICLES).contains(&n), "1 ≤ n ≤ 2³² − 6 particles");
        let buckets = n.next_power_of_two();
        Calendar {
            slots: vec![Slot::pack(Event::NOTHING); n],
            next: vec![NONE; n],
            heads: vec![NONE; buckets],
            mask: buckets as u64 - 1,
            inverse: 1.0,
            current: 0,
            linked: 0,
            searches: 0,
            work: 0,
        }
    }

    /// The bucket index of time `t` (finite): monotone in `t` (negative times give 0; the
    /// conversion through `i64` is one instruction on every x86-64, and saturates past 2⁶³).
    #[inline(always)]
    fn index(&self, t: f64) -> u64 {
        (t * self.inverse).max(0.0) as i64 as u64
    }

    /// Chooses `w` from the pending events and links them all again: the mean lead of the
    /// finite times over the earliest, spread over as many buckets as there are events, puts
    /// about one in each bucket at the front (where the lead is small and the events dense).
    pub fn rebuild(&mut self) {
        let finite = || self.slots.iter().map(|s| s.time).filter(|t| t.is_finite());
        let (count, earliest) = finite().fold((0usize, f64::INFINITY), |(c, m), t| (c + 1, m.min(t)));
        if count > 0 {
            let lead = finite().map(|t| t - earliest).sum::<f64>() / count as f64;
            let width = lead / count as f64;
            // A width that is zero, subnormal or not finite (one event, or all at one time)
            // would make indices overflow or divide by nothing: any width is correct, so fall
            // back to one that keeps `earliest/w` in range.
            let fallback = earliest.abs().max(1.0) * 2f64.powi(-40);
            let width = if width.is_normal() && width > fallback { width } else { fallback };
            self.inverse = 1.0 / width;
        }
        self.heads.fill(NONE);
        self.next.fill(NONE);
        self.linked = 0;
        self.current = u64::MAX;
        for p in 0..self.slots.len() {
            let t = self.slots[p].time;
            if t < f64::INFINITY {
                self.link(p, t);
            }
        }
        if self.linked == 0 {
            self.current = 0;
        }
        self.searches = 0;
        self.work = 0;
    }

    /// Links particle `p` (event at the finite time `t`) into its bucket.
    #[inline(always)]
    fn link(&mut self, p: usize, t: f64) {
        let k = self.index(t);
        let b = (k & self.mask) as usize;
        self.next[p] = self.heads[b];
        self.heads[b] = p as u32;
        self.current = self.current.min(k);
        self.linked += 1;
    }

    /// Unlinks particle `p` (event at the finite time `t`) from its bucket.
    #[inline(always)]
    fn unlink(&mut self, p: usize, t: f64) {
        let b = (self.index(t) & self.mask) as usize;
        let after = self.next[p];
        if self.heads[b] == p as u32 {
            self.heads[b] = after;
        } else {
            let mut k = self.heads[b] as usize;
            while self.next[k] != p as u32 {
                k = self.next[k] as usize;
            }
            self.next[k] = after;
        }
        self.linked -= 1;
    }

    /// The pending events, by owner.
    pub fn pending(&self) -> Vec<Event> {
        self.slots.iter().map(|s| s.unpack()).collect()
    }

    /// Particle `owner`'s pending event.
    #[inline]
    pub fn get(&self, owner: usize) -> Event {
        self.slots[owner].unpack()
    }

    /// Whether `a`'s event comes before `b`'s in the engine's total order.
    #[inline(always)]
    fn before(&self, a: u32, b: u32) -> bool {
        let (x, y) = (&self.slots[a as usize], &self.slots[b as usize]);
        if x.time == y.time { self.tie_first(a, b) } else { x.time < y.time }
    }

    #[cold]
    #[inline(never)]
    fn tie_first(&self, a: u32, b: u32) -> bool {
        let key = |p: u32| self.slots[p as usize].unpack().key(p);
        key(a) < key(b)
    }

    /// The earliest event of bucket `k` among its own (index `k`), but `a` and `b`; and how
    /// many entries its list held.
    #[inline(always)]
    fn earliest_in(&self, k: u64, a: u32, b: u32) -> (Option<u32>, usize) {
        let mut best: Option<u32> = None;
        let mut visited = 0;
        let mut p = self.heads[(k & self.mask) as usize];
        while p != NONE {
            visited += 1;
            let s = &self.slots[p as usize];
            if self.index(s.time) == k && p != a && p != b && best.is_none_or(|q| self.before(p, q)) {
                best = Some(p);
            }
            p = self.next[p as usize];
        }
        (best, visited)
    }

    /// The smallest bucket index of a linked event (a scan of every slot).
    #[cold]
    fn earliest_index(&self) -> u64 {
        self.slots.iter().filter(|s| s.time < f64::INFINITY).map(|s| self.index(s.time)).min().unwrap_or(0)
    }

    /// The owner of the earliest event, and the event. Moves the cursor past empty buckets
    /// (hence `&mut`). Chooses the bucket width again every `4N` searches, and as soon as
    /// the searches of the last `CHECK_EVERY` visited more than `MOST_WORK` entries and
    /// empty buckets each on average (a width chosen for other events: at the start, or
    /// after the temperature changed).
    #[inline]
    pub fn first(&mut self) -> (usize, Event) {
        self.searches += 1;
        if self.searches > 4 * self.slots.len()
            || (self.searches.is_multiple_of(CHECK_EVERY) && self.work > MOST_WORK * CHECK_EVERY)
        {
            self.rebuild();
        } else if self.searches.is_multiple_of(CHECK_EVERY) {
            self.work = 0;
        }
        if self.linked == 0 {
            return self.first_at_infinity();
        }
        let mut empty = 0;
        loop {
            let (best, visited) = self.earliest_in(self.current, NONE, NONE);
            self.work += visited + 1;
            if let Some(p) = best {
                return (p as usize, self.slots[p as usize].unpack());
            }
            self.current += 1;
            empty += 1;
            if empty > self.mask {
                self.current = self.earliest_index();
                empty = 0;
            }
        }
    }

    /// [`first`](Self::first) when every event is at `+∞`: the earliest by the total order.
    #[cold]
    fn first_at_infinity(&self) -> (usize, Event) {
        let mut best = 0u32;
        for p in 1..self.slots.len() as u32 {
            if self.before(p, best) {
                best = p;
            }
        }
        (best as usize, self.slots[best as usize].unpack())
    }

    /// Replaces particle `owner`'s pending event.
    #[inline]
    pub fn set(&mut self, owner: usize, event: Event) {
        let old = self.slots[owner].time;
        if old < f64::INFINITY {
            self.unlink(owner, old);
        }
        self.slots[owner] = Slot::pack(event);
        if event.time < f64::INFINITY {
            self.link(owner, event.time);
        }
    }

    /// The owner of the earliest event among all particles except `a` and `b`, ties aside
    /// (a guess at the next event once `a` and `b` have collided, for prefetching): the
    /// first bucket from the cursor with another event of its own.
    #[inline]
    pub fn runner_up(&self, a: usize, b: usize) -> usize {
        let (a32, b32) = (a as u32, b as u32);
        let mut k = self.current;
        for _ in 0..=self.mask {
            if let (Some(p), _) = self.earliest_in(k, a32, b32) {
                return p as usize;
            }
            k += 1;
        }
        // Nothing within a round of buckets: the earliest of the rest by a scan (`a` when
        // nobody else has an event).
        (0..self.slots.len())
            .filter(|&p| p != a && p != b && self.slots[p].time < f64::INFINITY)
            .min_by(|&x, &y| self.slots[x].time.total_cmp(&self.slots[y].time))
            .unwrap_or(a)
    }

    /// Where reading `owner`'s event (its slot and link) or replacing it (the head of its
    /// bucket; its slot should have arrived) touches first (see
    /// [`EventQueue::footprint`](super::EventQueue::footprint)).
    #[inline]
    pub(crate) fn footprint(&self, owner: usize, reads: Reads, mut touch: impl FnMut(*const u8)) {
        match reads {
            Reads::Slot => {
                touch((&self.slots[owner] as *const Slot).cast());
                touch((&self.next[owner] as *const u32).cast());
            }
            Reads::Path => {
                let t = self.slots[owner].time;
                if t < f64::INFINITY {
                    touch((&self.heads[(self.index(t) & self.mask) as usize] as *const u32).cast());
                }
            }
        }
    }

    /// Heap bytes held (capacities).
    pub fn memory_bytes(&self) -> usize {
        self.slots.capacity() * size_of::<Slot>()
            + self.next.capacity() * size_of::<u32>()
            + self.heads.capacity() * size_of::<u32>()
    }
}
