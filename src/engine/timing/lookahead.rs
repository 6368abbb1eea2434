//! The lookahead: while one event is processed, the data of the next is loaded.
//!
//! At large N every event touches a few particles anywhere in memory, so a step waits on
//! memory more than it computes. The next event is guessed from the queue (the earliest
//! event of everyone but the pair being processed, [`EventQueue::guess_next`]) — right almost
//! always, and a wrong guess costs only time — and its data is asked for in three stages, each
//! a few hundred nanoseconds ahead of its use, so that no stage waits for the one before:
//!
//! 1. before the collision is resolved: the next owner's record (both lines of a sphere's:
//!    the second holds the event count), pending event, and list and centre (or cell
//!    coordinates);
//! 2. between the two predictions that follow: the first lines of the records on its list
//!    (or the heads of the cells around it), its partner's whole record (the next step first
//!    reads its event count, to tell whether the event is live), list and centre (or cell
//!    coordinates), and the lowest levels of both queue paths — or, when its event is leaving
//!    its skin, the rows of its old neighbours and the heads of the cells around its new
//!    centre;
//! 3. after the predictions, when those have arrived: the records on the partner's list (or
//!    the first members of the cells around the owner, or around the new centre).
//!
//! Within the step, between a collision's brackets and its candidates' exact times, the line
//! holding each candidate's event count is asked for too
//! ([`Timing::candidates`](super::Timing::candidates)): a sphere's record spans two lines,
//! and asking for every neighbour's second line in stage two measured slower than asking
//! for the one or two a search turns out to need.
//!
//! When the event being processed is a particle leaving its skin, the centres of everyone in
//! the cells around its new centre are asked for before the rebuild ([`scanned`]): stage
//! three has brought only each cell's first member, and the rebuild's scan, which computes a
//! distance per member as it walks the cells, keeps too few of the others' loads in flight
//! at once (at large N, waiting on them was most of its time).
//!
//! The stages pay only once the engine's state has left the level-2 cache ([`pays`]): finding
//! the next event and issuing the hints costs instructions that only misses of that cache
//! repay.

use super::Reading;
use super::cache::level2_bytes;
use super::prefetch::{prefetch, prefetch_address};
use crate::engine::geometry::Particle;
use crate::engine::neighbours::cells::Around;
use crate::engine::queue::Reads;
use crate::engine::sources::EventKind;

/// What stage two found for stage three: the next event's owner and partner, and the cells a
/// rebuild of the owner will scan.
#[derive(Debug)]
pub struct Ahead {
    next: usize,
    partner: Option<usize>,
    rebuild: Option<Around>,
}

/// Whether the lookahead pays for `n` particles: from [`starts_at`] the level-2 cache's size.
pub(super) fn pays(n: usize) -> bool {
    n >= starts_at(level2_bytes())
}

/// The fewest particles for which the lookahead pays with a level-2 cache of `l2` bytes
/// (1 MiB when unknown): 3·2¹³ per MiB, about 3.5 bytes of engine state per byte of cache —
/// the crossover measured on machines with 1 and 2 MiB of level-2 cache
/// (`benches/HISTORY.md`).
fn starts_at(l2: Option<usize>) -> usize {
    const PER_MIB: usize = 3 << 13;
    let l2 = l2.unwrap_or(1 << 20);
    (PER_MIB as u128 * l2 as u128 / (1 << 20) as u128).clamp(1, usize::MAX as u128) as usize
}

/// Particle `i`'s list row and centre, or its cell coordinates.
#[inline(always)]
fn row<const D: usize>(at: &Reading<'_, D>, i: usize) {
    match at.neighbours.row(i) {
        Some(row) => {
            for block in row.blocks() {
                prefetch(block);
            }
            prefetch(&at.neighbours.centres()[i]);
        }
        None => {
            let (coord, wrapped) = at.neighbours.cells().coord_refs(i);
            prefetch(coord);
            prefetch(wrapped);
        }
    }
}

/// Without the lookahead: the rows of the two partners of a collision, read right after it
/// is resolved.
#[inline(always)]
pub(super) fn own_rows<const D: usize>(at: &Reading<'_, D>, a: usize, b: usize) {
    row(at, a);
    row(at, b);
}

/// Without the lookahead, before particle `a` leaves its skin: the rows of its old
/// neighbours, which its rebuild leaves after scanning the cells around its new centre (the
/// scan takes long enough for them to arrive).
#[inline(always)]
pub(super) fn old_rows<const D: usize>(at: &Reading<'_, D>, a: usize) {
    if let Some(row) = at.neighbours.row(a) {
        row.for_each_member(|j| prefetch(&at.neighbours.row(j).expect("lists").blocks()[0]));
    }
}

/// With the lookahead, before particle `a` leaves its skin at `t`: the centres of everyone in
/// the cells around its new centre, which the rebuild's scan measures against. The scan
/// walks the cells' lists and computes a distance per member, so few of its loads are in
/// flight at once; walked here with nothing but the hints, they all are.
#[inline(always)]
pub(super) fn scanned<const D: usize>(at: &Reading<'_, D>, a: usize, t: f64) {
    if at.neighbours.row(a).is_none() {
        return;
    }
    let cells = at.neighbours.cells();
    let around = cells.around(&cells.locate(&at.particles[a].position_at(t)));
    let centres = at.neighbours.centres();
    cells.for_each_member_side_by_side(around.as_slice(), |j| prefetch(&centres[j as usize]));
}

/// Particle `i`'s whole record: the line the motion and the search read, and the one holding
/// the event count — which the next step reads first (whether the pair's event is still
/// live) and the resolution writes (the next line for spheres; the same line for disks,
/// asked for once).
#[inline(always)]
fn record<const D: usize>(at: &Reading<'_, D>, i: usize) {
    prefetch(&at.particles[i]);
    event_count(at, i);
}

/// Whether a particle's record spans two cache lines, its event count on the second (spheres).
pub(super) const fn two_lines<const D: usize>() -> bool {
    size_of::<Particle<D>>() > 64
}

/// The second line of particle `i`'s record, which holds its event count (nothing where the
/// record is one line).
#[inline(always)]
pub(super) fn event_count<const D: usize>(at: &Reading<'_, D>, i: usize) {
    if two_lines::<D>() {
        prefetch(&at.particles[i].events);
    }
}

/// The records of the particles `near`: the line the search reads (position, velocity,
/// time and radius), and the one holding the event count, which a candidate's event records
/// (the same line for disks, the next for spheres).
#[inline(always)]
pub(super) fn records<const D: usize>(at: &Reading<'_, D>, near: &[u32]) {
    for &j in near {
        record(at, j as usize);
    }
}

/// Stage one (see the module docs): the guess of the next event after `a` and `b`'s, with
/// its record, pending event and row on their way.
pub(super) fn first_stage<const D: usize>(at: &Reading<'_, D>, a: usize, b: usize) -> usize {
    let next = at.queue.guess_next(a, b);
    record(at, next);
    at.queue.footprint(next, Reads::Slot, prefetch_address);
    row(at, next);
    next
}

/// The records on `i`'s list, or the heads of the cells around it.
#[inline(always)]
fn neighbourhood<const D: usize>(at: &Reading<'_, D>, i: usize) {
    let cells = at.neighbours.cells();
    match at.neighbours.row(i) {
        None => {
            for &c in cells.around(&cells.wrapped(i)).as_slice() {
                prefetch(cells.head(c));
            }
        }
        Some(row) => row.for_each_member(|j| prefetch(&at.particles[j])),
    }
}

/// Stage two (see the module docs).
pub(super) fn second_stage<const D: usize>(at: &Reading<'_, D>, next: usize) -> Ahead {
    neighbourhood(at, next);
    at.queue.footprint(next, Reads::Path, prefetch_address);
    let mut ahead = Ahead { next, partner: None, rebuild: None };
    let event = at.queue.get(next);
    match event.kind {
        EventKind::Pair { partner, .. } => {
            let partner = partner as usize;
            record(at, partner);
            row(at, partner);
            at.queue.footprint(partner, Reads::Path, prefetch_address);
            ahead.partner = Some(partner);
        }
        EventKind::Rebuild => {
            if let Some(row) = at.neighbours.row(next) {
                // The rows it leaves, and the cells around where its new centre will be.
                row.for_each_member(|j| prefetch(&at.neighbours.row(j).expect("lists").blocks()[0]));
                let cells = at.neighbours.cells();
                let centre = at.particles[next].position_at(event.time);
                let around = cells.around(&cells.locate(&centre));
                for &c in around.as_slice() {
                    prefetch(cells.head(c));
                }
                ahead.rebuild = Some(around);
            }
        }
        _ => {}
    }
    ahead
}

/// Stage three (see the module docs).
pub(super) fn third_stage<const D: usize>(at: &Reading<'_, D>, ahead: &Ahead) {
    let cells = at.neighbours.cells();
    let first_members = |around: &Around, centres: bool| {
        for &c in around.as_slice() {
            if let Some((j, link)) = cells.first_member(c) {
                prefetch(link);
                if centres {
                    prefetch(&at.neighbours.centres()[j]);
                } else {
                    prefetch(&at.particles[j]);
                }
            }
        }
    };
    if at.neighbours.row(ahead.next).is_none() {
        first_members(&cells.around(&cells.wrapped(ahead.next)), false);
    }
    if let Some(partner) = ahead.partner {
        neighbourhood(at, partner);
    }
    if let Some(around) = &ahead.rebuild {
        first_members(around, true);
    }
}

#[cfg(test)]
mod tests {
    use super::starts_at;

    /// The lookahead starts where the engine's state leaves the level-2 cache: at the
    /// measured crossovers of both machines it ran on.
    #[test]
    fn the_lookahead_starts_with_the_cache() {
        assert_eq!(starts_at(Some(1 << 20)), 3 << 13);
        assert_eq!(starts_at(Some(2 << 20)), 3 << 14);
        assert_eq!(starts_at(None), 3 << 13);
        assert_eq!(starts_at(Some(256 << 10)), 3 << 11);
        assert_eq!(starts_at(Some(1)), 1);
        assert!(starts_at(Some(usize::MAX)) > 1 << 40);
    }
}
