//! The event queue: one [`Pending`] event per particle in a 4-ary tournament tree.
//!
//! Every particle owns exactly one slot, so the queue never grows and never holds stale
//! copies (a binary heap of every prediction held about five stale events per collision at
//! packing fraction 0.65 and spent most of its time popping them). The tree is the
//! complete 4-ary tree over the slots laid out as an array: internal node `k` has children
//! `4k + 1 … 4k + 4`, and slot `p` is leaf `m + p`, where `m` is the number of internal
//! nodes. The slots are padded with at most two empty ones so that every internal node has
//! four children, which makes `m = (slots − 1)/3` — about N/3 nodes of 16 bytes. Each
//! internal node keeps the time and owner of the earliest event below it, so replacing one
//! particle's event walks one path of ⌈log₄ N⌉ nodes, comparing the four children of each
//! node on it as two independent pairs. Against the binary tree it replaced, an update of
//! the root's owner costs the same (63 ns in `engine/parts/queue_set_root`, three
//! interleaved runs each), the tree takes a third of the memory (N/3 nodes instead of N),
//! and the whole engine measured +5 % (median of five interleaved runs, within the noise).
//!
//! The order is the engine's total order ([`Pending::before`]): by time, then by kind, then
//! by particles and axes — so the earliest event never depends on how it was reached.

use super::events::Pending;

/// Children per internal node.
const ARITY: usize = 4;

/// Earliest event below an internal node.
#[derive(Clone, Copy, Debug)]
struct Node {
    time: f64,
    owner: u32,
}

/// One pending event per particle, earliest first.
#[derive(Clone, Debug)]
pub struct EventQueue {
    /// One slot per particle, then up to two empty ones (padding).
    pending: Vec<Pending>,
    /// Particles (the unpadded slots).
    n: usize,
    nodes: Vec<Node>,
}

impl EventQueue {
    /// A queue over `pending` (one event per particle, `pending.len() < u32::MAX − 2`).
    pub fn new(mut pending: Vec<Pending>) -> Self {
        let n = pending.len();
        assert!(n >= 1 && n < u32::MAX as usize - 2, "1 ≤ n < 2³² − 3 particles");
        while (pending.len() - 1) % (ARITY - 1) != 0 {
            pending.push(Pending::NOTHING);
        }
        pending.shrink_to_fit();
        let m = (pending.len() - 1) / (ARITY - 1);
        let mut queue = EventQueue { nodes: vec![Node { time: f64::INFINITY, owner: 0 }; m], pending, n };
        for k in (0..m).rev() {
            queue.nodes[k] = queue.children_winner(k);
        }
        queue
    }

    /// The pending events, by owner.
    pub fn pending(&self) -> &[Pending] {
        &self.pending[..self.n]
    }

    /// Particle `owner`'s pending event.
    #[inline]
    pub fn get(&self, owner: usize) -> &Pending {
        &self.pending[..self.n][owner]
    }

    /// The owner of the earliest event, and the event.
    #[inline]
    pub fn first(&self) -> (usize, &Pending) {
        let owner = self.nodes.first().map_or(0, |n| n.owner as usize);
        (owner, &self.pending[owner])
    }

    /// Replaces particle `owner`'s pending event.
    #[inline]
    pub fn set(&mut self, owner: usize, event: Pending) {
        self.pending[..self.n][owner] = event;
        let mut k = self.nodes.len() + owner;
        while k > 0 {
            k = (k - 1) / ARITY;
            let best = self.children_winner(k);
            let old = self.nodes[k];
            // Another particle still wins here, at the same time: nothing above changes.
            if old.owner == best.owner && old.owner != owner as u32 && old.time == best.time {
                return;
            }
            self.nodes[k] = best;
        }
    }

    /// The owner of the earliest event among all particles except `a` and `b`, ties aside
    /// (a guess at the next event once `a` and `b` have collided, for prefetching): the
    /// earliest of the winners beside both leaves' paths.
    #[inline]
    pub fn runner_up(&self, a: usize, b: usize) -> usize {
        let m = self.nodes.len();
        let (mut best_time, mut best_owner) = (f64::INFINITY, a as u32);
        let (mut x, mut y) = (m + a, m + b);
        while (x | y) != 0 {
            let parent = (x.max(y) - 1) / ARITY;
            let c = ARITY * parent + 1;
            for ch in c..c + ARITY {
                let (time, owner) = if ch >= m {
                    (self.pending[ch - m].time, (ch - m) as u32)
                } else {
                    (self.nodes[ch].time, self.nodes[ch].owner)
                };
                let time = if ch == x || ch == y { f64::INFINITY } else { time };
                best_owner = std::hint::select_unpredictable(time < best_time, owner, best_owner);
                best_time = best_time.min(time);
            }
            x = if x > 0 && (x - 1) / ARITY == parent { parent } else { x };
            y = if y > 0 && (y - 1) / ARITY == parent { parent } else { y };
        }
        best_owner as usize
    }

    /// Prefetches the lowest levels of the path above `owner`'s slot (the upper levels stay
    /// in cache).
    #[inline]
    pub fn prefetch_path(&self, owner: usize) {
        let m = self.nodes.len();
        let mut k = m + owner;
        for _ in 0..4 {
            if k == 0 {
                return;
            }
            k = (k - 1) / ARITY;
            let c = ARITY * k + 1;
            if c >= m {
                super::prefetch::prefetch(&self.pending[c - m]);
                super::prefetch::prefetch(&self.pending[c - m + ARITY - 1]);
            } else {
                super::prefetch::prefetch(&self.nodes[c]);
                super::prefetch::prefetch(&self.nodes[(c + ARITY - 1).min(m - 1)]);
            }
        }
    }

    /// Heap bytes held (capacities).
    pub fn memory_bytes(&self) -> usize {
        self.pending.capacity() * size_of::<Pending>() + self.nodes.capacity() * size_of::<Node>()
    }

    /// The earliest event below internal node `k`, from its four children: two independent
    /// pairs, then their winners.
    ///
    /// The four children are all leaves (the level above the slots) or all internal nodes,
    /// except under at most one node; the two common cases read them as one slice each.
    #[inline(always)]
    fn children_winner(&self, k: usize) -> Node {
        let c = ARITY * k + 1;
        let m = self.nodes.len();
        let [w, x, y, z] = if c >= m {
            let first = c - m;
            let s = &self.pending[first..first + ARITY];
            let leaf = |o: usize| Node { time: s[o].time, owner: (first + o) as u32 };
            [leaf(0), leaf(1), leaf(2), leaf(3)]
        } else if c + ARITY <= m {
            let s = &self.nodes[c..c + ARITY];
            [s[0], s[1], s[2], s[3]]
        } else {
            [self.winner(c), self.winner(c + 1), self.winner(c + 2), self.winner(c + 3)]
        };
        let (a, b) = (self.earlier(w, x), self.earlier(y, z));
        self.earlier(a, b)
    }

    /// The earliest event below tree position `k` (a node or a leaf).
    #[inline(always)]
    fn winner(&self, k: usize) -> Node {
        let leaves = self.nodes.len();
        if k >= leaves {
            let owner = k - leaves;
            Node { time: self.pending[owner].time, owner: owner as u32 }
        } else {
            self.nodes[k]
        }
    }

    /// The earlier of two nodes. Which one wins is a coin toss for the branch predictor, so
    /// the choice is a select; equal times (rare) take the branch to the full key.
    #[inline(always)]
    fn earlier(&self, a: Node, b: Node) -> Node {
        let b_first = if a.time == b.time { self.tie_b_first(a, b) } else { b.time < a.time };
        // The winner's time is the smaller one (equal times are equal as f64, whichever wins
        // the tie), so no branch picks it: written as an `if`, the compiler branched on it
        // (it has no conditional move for an f64), and those branches were a third of the
        // engine's mispredictions (callgrind's branch simulation at N = 10⁴, η = 0.65).
        Node { time: a.time.min(b.time), owner: std::hint::select_unpredictable(b_first, b.owner, a.owner) }
    }

    #[cold]
    #[inline(never)]
    fn tie_b_first(&self, a: Node, b: Node) -> bool {
        self.pending[b.owner as usize].key(b.owner) < self.pending[a.owner as usize].key(a.owner)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::events::PendingKind;
    use rand::rngs::Xoshiro256PlusPlus;
    use rand::{RngExt, SeedableRng};

    fn wall(time: f64) -> Pending {
        Pending { time, kind: PendingKind::Wall { axis: 0, upper: true } }
    }

    /// Against a linear scan, after every one of many random replacements, for sizes that
    /// are and are not powers of two; ties are broken by the owner.
    #[test]
    fn first_is_the_minimum_in_the_total_order() {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(5);
        for n in [1usize, 2, 3, 4, 5, 6, 7, 8, 13, 100] {
            let mut queue = EventQueue::new((0..n).map(|_| Pending::NOTHING).collect());
            for _ in 0..2000 {
                let owner = rng.random_range(0..n);
                // Few distinct times, so that ties are common; sometimes nothing.
                let r: u32 = rng.random_range(0..9);
                let event = if r == 8 { Pending::NOTHING } else { wall(r as f64) };
                queue.set(owner, event);
                let (got, _) = queue.first();
                let want = (0..n)
                    .min_by(|&a, &b| {
                        let (pa, pb) = (queue.get(a), queue.get(b));
                        pa.time.total_cmp(&pb.time).then(pa.key(a as u32).cmp(&pb.key(b as u32)))
                    })
                    .unwrap();
                assert_eq!(got, want, "n = {n}");
            }
        }
    }

    /// Against a linear scan: the time of `runner_up(a, b)` is the earliest time among
    /// all particles but `a` and `b`, for paths that meet low, high and not until the root.
    #[test]
    fn runner_up_is_the_earliest_of_the_others() {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(11);
        for n in [3usize, 4, 5, 6, 7, 13, 100, 1000] {
            let mut queue = EventQueue::new((0..n).map(|_| Pending::NOTHING).collect());
            for _ in 0..2000 {
                let owner = rng.random_range(0..n);
                queue.set(owner, wall(rng.random_range(0.0..1.0)));
                let (a, b) = (rng.random_range(0..n), rng.random_range(0..n));
                let got = queue.runner_up(a, b);
                let want =
                    (0..n).filter(|&k| k != a && k != b).map(|k| queue.get(k).time).fold(f64::INFINITY, f64::min);
                // With nobody else pending, any answer will do (there is nothing to prefetch).
                if want < f64::INFINITY {
                    assert!(got != a && got != b, "n = {n}, {a}, {b} → {got}");
                    assert_eq!(queue.get(got).time.to_bits(), want.to_bits(), "n = {n}, {a}, {b}");
                }
            }
        }
    }
}
