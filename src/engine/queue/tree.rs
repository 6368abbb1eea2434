//! The tournament tree: one [`Event`] event per particle in a 4-ary tree of winners.
//!
//! Every particle owns exactly one slot, so the queue never grows and never holds stale
//! copies (a binary heap of every prediction held about five stale events per collision at
//! packing fraction 0.65 and spent most of its time popping them). The tree is the
//! complete 4-ary tree over the slots laid out as an array: internal node `k` has children
//! `4k + 1 … 4k + 4`, and slot `p` is leaf `m + p`, where `m` is the number of internal
//! nodes. The slots are padded with at most two empty ones so that every internal node has
//! four children, which makes `m = (slots − 1)/3` — about N/3 nodes of 16 bytes. Each
//! internal node keeps the time and owner of the earliest event below it, so replacing one
//! particle's event walks one path of ⌈log₄ N⌉ nodes, taking the earliest of the four
//! children of each node on it by their smallest time (the full key only on a tie). Against
//! a binary tree, an update costs about the same and the tree takes a third of the memory
//! (N/3 nodes instead of N).
//! The four children of a node share one cache line (see [`Tree`]): 16 bytes per
//! particle for the events and about 5 for the nodes.
//!
//! The order is the engine's total order ([`Event::before`]): by time, then by kind, then
//! by particles and axes — so the earliest event never depends on how it was reached.

use super::Reads;
use super::Slot;
use crate::engine::arrays::Store;
use crate::engine::sources::{Event, MAX_PARTICLES};

/// Children per internal node.
const ARITY: usize = 4;

/// Earliest event below an internal node.
#[derive(Clone, Copy, Debug)]
struct Node {
    time: f64,
    owner: u32,
}

const NO_NODE: Node = Node { time: f64::INFINITY, owner: 0 };

/// Four sibling nodes, one cache line.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
struct Quad([Node; ARITY]);

/// Four sibling slots, one cache line.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
struct Group([Slot; ARITY]);

/// One pending event per particle, earliest first.
///
/// Every level of the walk from a slot to the root reads the four children of one node, and
/// they fill one cache line: the internal nodes are stored four siblings to a `Quad` (the
/// root apart), the slots four siblings to a `Group` (packed to 16 bytes, and shifted so
/// that siblings share a group). With 24-byte events and 16-byte nodes in plain arrays the
/// four children straddled two lines at every level.
#[derive(Clone, Debug)]
pub struct Tree {
    /// The slots: particle `p`'s is number `p + shift` (the padding after the particles
    /// holds nothing).
    groups: Vec<Group>,
    shift: usize,
    /// Particles (the unpadded slots).
    n: usize,
    /// Internal nodes, the root included: tree position `k < m` is a node, `m + p` slot `p`.
    m: usize,
    root: Node,
    /// Internal nodes `1 … m − 1`: node `x` is `quads[(x − 1)/4][(x − 1) % 4]`, so that the
    /// children of node `k` are `quads[k]`.
    quads: Vec<Quad>,
    /// Levels above the slots at which [`guess_next`](Self::guess_next) starts its walk
    /// ([`guess_levels`]).
    skip: usize,
}

/// The levels [`Tree::guess_next`] leaves out for `n` particles: the most whose subtrees
/// (4^s slots) hold at most a 64th of the particles — 5 at N = 10⁵, 6 at 10⁶, 0 below 256.
pub(super) fn guess_levels(n: usize) -> usize {
    let mut s = 0;
    while ARITY.pow(s as u32 + 1) * 64 <= n {
        s += 1;
    }
    s
}

/// Tree positions of the top three levels (1 + 4 + 16): the guess's walk never starts
/// above them, so that it always searches most of the tree.
pub(super) const TOP: usize = 21;

impl Tree {
    /// A queue over `pending` (one event per particle, at most [`MAX_PARTICLES`]), its arrays
    /// built in `store`.
    pub(crate) fn new(pending: Vec<Event>, store: &impl Store) -> Self {
        let mut queue = Tree::nothing(pending.len(), store);
        for (p, e) in pending.into_iter().enumerate() {
            *queue.slot_mut(p) = Slot::pack(e);
        }
        queue.build_nodes();
        queue
    }

    /// A queue of `n` particles with nothing pending (no temporary list of events: at
    /// N = 10⁶ one cost 24 MB of peak memory).
    pub(crate) fn nothing(n: usize, store: &impl Store) -> Self {
        assert!(n >= 1 && n <= MAX_PARTICLES, "1 ≤ n ≤ 2³² − 6 particles");
        let mut slots = n;
        while (slots - 1) % (ARITY - 1) != 0 {
            slots += 1;
        }
        let m = (slots - 1) / (ARITY - 1);
        // The children of node k begin at tree position 4k + 1, slot 4k + 1 − m.
        let shift = (m + ARITY - 1) % ARITY;
        let empty = Group([Slot::pack(Event::NOTHING); ARITY]);
        let mut queue = Tree {
            groups: store.filled((slots + shift).div_ceil(ARITY), empty),
            shift,
            n,
            m,
            root: NO_NODE,
            quads: store.filled(m.saturating_sub(1).div_ceil(ARITY), Quad([NO_NODE; ARITY])),
            skip: guess_levels(n),
        };
        // Built even though every time is +∞: the winners of those ties are decided by the
        // full key, as everywhere else.
        queue.build_nodes();
        queue
    }

    /// Every internal node's winner, bottom up.
    fn build_nodes(&mut self) {
        for k in (0..self.m).rev() {
            let best = self.children_winner(k);
            *self.node_mut(k) = best;
        }
    }

    #[inline(always)]
    fn slot(&self, p: usize) -> &Slot {
        let x = p + self.shift;
        &self.groups[x / ARITY].0[x % ARITY]
    }

    #[inline(always)]
    fn slot_mut(&mut self, p: usize) -> &mut Slot {
        let x = p + self.shift;
        &mut self.groups[x / ARITY].0[x % ARITY]
    }

    /// Internal node `k < m`.
    #[inline(always)]
    fn node(&self, k: usize) -> Node {
        if k == 0 { self.root } else { self.quads[(k - 1) / ARITY].0[(k - 1) % ARITY] }
    }

    /// Internal node `k < m`, to replace.
    #[inline(always)]
    fn node_mut(&mut self, k: usize) -> &mut Node {
        if k == 0 { &mut self.root } else { &mut self.quads[(k - 1) / ARITY].0[(k - 1) % ARITY] }
    }

    /// The pending events, by owner.
    pub fn pending(&self) -> Vec<Event> {
        (0..self.n).map(|p| self.get(p)).collect()
    }

    /// Particle `owner`'s pending event.
    #[inline]
    pub fn get(&self, owner: usize) -> Event {
        assert!(owner < self.n, "particle {owner} of {}", self.n);
        self.slot(owner).unpack()
    }

    /// The owner of the earliest event, and the event.
    #[inline]
    pub fn first(&self) -> (usize, Event) {
        let owner = if self.m == 0 { 0 } else { self.root.owner as usize };
        (owner, self.slot(owner).unpack())
    }

    /// Replaces particle `owner`'s pending event.
    #[inline]
    pub fn set(&mut self, owner: usize, event: Event) {
        assert!(owner < self.n, "particle {owner} of {}", self.n);
        *self.slot_mut(owner) = Slot::pack(event);
        let mut k = self.m + owner;
        while k > 0 {
            k = (k - 1) / ARITY;
            let best = self.children_winner(k);
            let node = self.node_mut(k);
            // Another particle still wins here, at the same time: nothing above changes.
            if node.owner == best.owner && node.owner != owner as u32 && node.time == best.time {
                return;
            }
            *node = best;
        }
    }

    /// The owner of the earliest event among all particles except `a` and `b`, ties aside:
    /// the earliest of the winners beside both leaves' paths.
    #[inline]
    pub fn runner_up(&self, a: usize, b: usize) -> usize {
        self.earliest_beside(a, b, 0)
    }

    /// A guess at the next event once `a` and `b` have collided, for the lookahead: the
    /// owner of the earliest event outside the two subtrees that hold `a` and `b`
    /// `guess_levels` levels up (4^s slots each, at most a 64th of the particles).
    ///
    /// Why not [`runner_up`](Self::runner_up): its walk starts at the slots, and the lowest
    /// levels of both paths are the ones out of cache (the upper levels are shared by every
    /// walk). Leaving out two small subtrees makes the guess wrong now and then (when the
    /// next event's owner is near the pair in the tree), but shortens the walk to the levels
    /// that stay in cache; the trade was measured over `s` (`benches/HISTORY.md`). A wrong
    /// guess costs only time: the results are the same bit for bit.
    #[inline]
    pub fn guess_next(&self, a: usize, b: usize) -> usize {
        self.earliest_beside(a, b, self.skip)
    }

    /// The earliest winner beside both paths from `skip` levels above the slots of `a` and
    /// `b` (never from the top three levels) to the root.
    #[inline(always)]
    fn earliest_beside(&self, a: usize, b: usize, skip: usize) -> usize {
        let m = self.m;
        let (mut best_time, mut best_owner) = (f64::INFINITY, a as u32);
        let (mut x, mut y) = (m + a, m + b);
        for _ in 0..skip {
            x = if x >= TOP { (x - 1) / ARITY } else { x };
            y = if y >= TOP { (y - 1) / ARITY } else { y };
        }
        while (x | y) != 0 {
            let parent = (x.max(y) - 1) / ARITY;
            let c = ARITY * parent + 1;
            let four = self.children(parent);
            for (ch, Node { time, owner }) in (c..c + ARITY).zip(four) {
                let time = if ch == x || ch == y { f64::INFINITY } else { time };
                best_owner = std::hint::select_unpredictable(time < best_time, owner, best_owner);
                best_time = best_time.min(time);
            }
            x = if x > 0 && (x - 1) / ARITY == parent { parent } else { x };
            y = if y > 0 && (y - 1) / ARITY == parent { parent } else { y };
        }
        best_owner as usize
    }

    /// Where reading `owner`'s event (its slot) or replacing it (the lowest levels of the path
    /// above its slot, one line per level: the upper levels stay in cache) touches first (see
    /// [`EventQueue::footprint`](super::EventQueue::footprint)).
    #[inline]
    pub(crate) fn footprint(&self, owner: usize, reads: Reads, mut touch: impl FnMut(*const u8)) {
        if reads == Reads::Slot {
            touch((self.slot(owner) as *const Slot).cast());
            return;
        }
        let m = self.m;
        let mut k = m + owner;
        for _ in 0..4 {
            if k == 0 {
                return;
            }
            k = (k - 1) / ARITY;
            let c = ARITY * k + 1;
            if c >= m {
                touch((&self.groups[(c - m + self.shift) / ARITY] as *const Group).cast());
            } else if let Some(quad) = self.quads.get(k) {
                touch((quad as *const Quad).cast());
            }
        }
    }

    /// Internal nodes, the root included (tree position `m + p` is slot `p`).
    #[cfg(test)]
    pub(super) fn internal_nodes(&self) -> usize {
        self.m
    }

    /// Heap bytes held (capacities).
    pub fn memory_bytes(&self) -> usize {
        self.groups.capacity() * size_of::<Group>() + self.quads.capacity() * size_of::<Quad>()
    }

    /// The earliest event below internal node `k`, from its four children ([`earliest_of`]).
    ///
    /// The cases of [`children`](Self::children), each taking the winner's owner where it
    /// is (a slot's from its lane, a node's from the line): through `children`' array the
    /// four nodes went to the stack and back, which counted more instructions a replacement
    /// (`benches/HISTORY.md`).
    #[inline(always)]
    fn children_winner(&self, k: usize) -> Node {
        let c = ARITY * k + 1;
        let m = self.m;
        if c >= m {
            let first = c - m;
            let g = &self.groups[(first + self.shift) / ARITY].0;
            match earliest_of([g[0].time, g[1].time, g[2].time, g[3].time]) {
                Ok((time, lane)) => Node { time, owner: (first + lane) as u32 },
                Err(tied) => {
                    let leaf = |o: usize| Node { time: g[o].time, owner: (first + o) as u32 };
                    self.tie_among([leaf(0), leaf(1), leaf(2), leaf(3)], tied)
                }
            }
        } else if c + ARITY <= m {
            let q = &self.quads[k].0;
            match earliest_of([q[0].time, q[1].time, q[2].time, q[3].time]) {
                Ok((time, lane)) => Node { time, owner: q[lane].owner },
                Err(tied) => self.tie_among(*q, tied),
            }
        } else {
            let q = self.children(k);
            match earliest_of(q.map(|n| n.time)) {
                Ok((time, lane)) => Node { time, owner: q[lane].owner },
                Err(tied) => self.tie_among(q, tied),
            }
        }
    }

    /// The four children of internal node `k`. They are all slots (the level above the
    /// slots) or all internal nodes, except under at most one node; the two common cases read
    /// them as one line each.
    #[inline(always)]
    fn children(&self, k: usize) -> [Node; ARITY] {
        let c = ARITY * k + 1;
        let m = self.m;
        if c >= m {
            let first = c - m;
            let g = &self.groups[(first + self.shift) / ARITY].0;
            core::array::from_fn(|o| Node { time: g[o].time, owner: (first + o) as u32 })
        } else if c + ARITY <= m {
            self.quads[k].0
        } else {
            core::array::from_fn(|o| self.winner(c + o))
        }
    }

    /// The earliest event below tree position `k` (a node or a slot).
    #[inline(always)]
    fn winner(&self, k: usize) -> Node {
        if k >= self.m {
            let owner = k - self.m;
            Node { time: self.slot(owner).time, owner: owner as u32 }
        } else {
            self.node(k)
        }
    }

    /// The earliest of the four nodes whose lanes are set in `tied` (at least two, sharing
    /// the smallest time), by the full key; among equal keys (the two owners of one pair
    /// event) the lowest lane — as a tournament of pairs in which the left one wins ties.
    #[cold]
    #[inline(never)]
    fn tie_among(&self, four: [Node; ARITY], tied: u32) -> Node {
        let mut lanes = (0..ARITY).filter(|&k| tied & (1 << k) != 0);
        let mut best = four[lanes.next().expect("two tied lanes")];
        for k in lanes {
            if self.tie_b_first(best, four[k]) {
                best = four[k];
            }
        }
        best
    }

    #[cold]
    #[inline(never)]
    fn tie_b_first(&self, a: Node, b: Node) -> bool {
        let key = |x: Node| self.slot(x.owner as usize).unpack().key(x.owner);
        key(b) < key(a)
    }
}

/// The smallest of four times and its lane; or, when two or more lanes hold it, those lanes
/// as a bit mask (`Err`), for the full key to decide — the two owners of one pair event
/// meeting in a node, or children with nothing pending (`+∞`). Each lane is compared once,
/// with the minimum, and the one branch is on a tie, where a tournament of pairs compared
/// each pair twice, for a tie and for the order (a replacement's walk up the tree takes a
/// sixth fewer instructions, `benches/HISTORY.md`). Times are never NaN.
#[inline(always)]
fn earliest_of(t: [f64; ARITY]) -> Result<(f64, usize), u32> {
    let low = smaller(smaller(t[0], t[1]), smaller(t[2], t[3]));
    let tied =
        (t[0] == low) as u32 | ((t[1] == low) as u32) << 1 | ((t[2] == low) as u32) << 2 | ((t[3] == low) as u32) << 3;
    if tied & (tied - 1) == 0 { Ok((low, tied.trailing_zeros() as usize)) } else { Err(tied) }
}

/// The smaller of two times that are not NaN: one instruction (`f64::min` also orders NaN).
#[inline(always)]
fn smaller(a: f64, b: f64) -> f64 {
    if a < b { a } else { b }
}
