//! The event queue: one [`Pending`] event per particle in a tournament tree.
//!
//! Every particle owns exactly one slot, so the queue never grows and never holds stale
//! copies (a binary heap of every prediction held about five stale events per collision at
//! packing fraction 0.65 and spent most of its time popping them). The tree is the
//! complete binary tree over the `n` slots laid out as an array: internal node `k` has
//! children `2k + 1` and `2k + 2`, and slot `p` is leaf `n − 1 + p`, so any `n` works and
//! the internal nodes take exactly `n − 1` entries. Each internal node keeps the time and
//! owner of the earliest event below it, so replacing one particle's event walks one path
//! of ⌈log₂ n⌉ nodes with a comparison per level and no branch on the tree's shape.
//!
//! The order is the engine's total order ([`Pending::before`]): by time, then by kind, then
//! by particles and axes — so the earliest event never depends on how it was reached.

use super::events::Pending;

/// Earliest event below an internal node.
#[derive(Clone, Copy, Debug)]
struct Node {
    time: f64,
    owner: u32,
}

/// One pending event per particle, earliest first.
#[derive(Clone, Debug)]
pub struct EventQueue {
    pending: Vec<Pending>,
    nodes: Vec<Node>,
}

impl EventQueue {
    /// A queue over `pending` (one event per particle, `pending.len() < u32::MAX`).
    pub fn new(pending: Vec<Pending>) -> Self {
        assert!(!pending.is_empty() && pending.len() < u32::MAX as usize, "1 ≤ n < 2³² − 1 particles");
        let n = pending.len();
        let mut queue = EventQueue { nodes: vec![Node { time: f64::INFINITY, owner: 0 }; n - 1], pending };
        for k in (0..n - 1).rev() {
            let (a, b) = (queue.winner(2 * k + 1), queue.winner(2 * k + 2));
            queue.nodes[k] = queue.earlier(a, b);
        }
        queue
    }

    /// The pending events, by owner.
    pub fn pending(&self) -> &[Pending] {
        &self.pending
    }

    /// Particle `owner`'s pending event.
    #[inline]
    pub fn get(&self, owner: usize) -> &Pending {
        &self.pending[owner]
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
        self.pending[owner] = event;
        let leaves = self.nodes.len();
        let mut best = Node { time: event.time, owner: owner as u32 };
        let mut k = leaves + owner;
        while k > 0 {
            // Left children have odd positions, right children even ones.
            let sibling = self.winner(if k % 2 == 1 { k + 1 } else { k - 1 });
            best = self.earlier(best, sibling);
            k = (k - 1) / 2;
            let old = self.nodes[k];
            // Another particle still wins here, at the same time: nothing above changes.
            if old.owner == best.owner && old.owner != owner as u32 && old.time == best.time {
                return;
            }
            self.nodes[k] = best;
        }
    }

    /// Heap bytes held (capacities).
    pub fn memory_bytes(&self) -> usize {
        self.pending.capacity() * size_of::<Pending>() + self.nodes.capacity() * size_of::<Node>()
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
        if b_first { b } else { a }
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
        for n in [1usize, 2, 3, 5, 8, 13, 100] {
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
}
