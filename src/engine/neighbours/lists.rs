//! Neighbour lists: one fixed-size row per particle, and when lists are kept and how wide
//! their skin is ([`skin_for`]). The bookkeeping that keeps the rows true — centres, rebuilds,
//! exit times — is [`Neighbours`](super::Neighbours)'.

use super::Neighbourhood;
use crate::engine::geometry::{Boundary, SimBox};

/// The entries of one row of a list (one 32-byte block, read by the batch kernel eight lanes
/// at a time).
pub const CAPACITY: usize = 8;

/// Rows a particle's list spans: one in 2D, two in 3D (a dense sphere fluid has about twice
/// the neighbours in range of a disk fluid; three rows, with a range holding 14 to 18, were
/// slower at η = 0.45: `benches/HISTORY.md`).
pub const fn rows_for(dimension: usize) -> usize {
    if dimension >= 3 { 2 } else { 1 }
}

/// The most rows any dimension's lists span.
pub(crate) const MAX_ROWS: usize = rows_for(3);

/// An unused entry (lists are packed at the front).
pub(crate) const NONE: u32 = u32::MAX;

/// The first entry of a crowded particle's list.
pub(crate) const CROWDED: u32 = u32::MAX - 1;

/// One row of a list: `CAPACITY` entries. A particle's list is its `rows_for(D)` consecutive
/// rows ([`Rows`]).
#[derive(Clone, Copy, Debug)]
#[repr(C, align(32))]
pub(crate) struct List([u32; CAPACITY]);

impl List {
    pub(crate) const EMPTY: List = List([NONE; CAPACITY]);

    /// The row's entries.
    #[inline(always)]
    pub(crate) fn entries(&self) -> &[u32; CAPACITY] {
        &self.0
    }
}

/// One particle's list, its rows: its neighbours, `NONE` after the last; `CROWDED` first for
/// a crowded particle.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Rows<'a>(pub(crate) &'a [List]);

impl<'a> Rows<'a> {
    /// Whether the particle has more neighbours in range than its rows hold (it then searches
    /// the grid of centres instead).
    #[inline]
    pub(crate) fn crowded(&self) -> bool {
        crowded(self.0)
    }

    /// The entries, members first (`NONE` after the last; `CROWDED` first when crowded).
    #[inline]
    pub(crate) fn entries(self) -> impl Iterator<Item = u32> + 'a {
        self.0.iter().flat_map(|row| row.0)
    }

    /// The members (none when crowded).
    #[inline]
    pub(crate) fn members(self) -> impl Iterator<Item = usize> + 'a {
        let skip = if self.crowded() { self.0.len() * CAPACITY } else { 0 };
        self.entries().skip(skip).take_while(|&j| j != NONE).map(|j| j as usize)
    }

    /// Calls `f` with each member, in order (none when crowded): the loops of
    /// [`members`](Self::members) written out, for the prefetches of the timing room.
    #[inline(always)]
    pub(crate) fn for_each_member(self, mut f: impl FnMut(usize)) {
        if self.crowded() {
            return;
        }
        for row in self.0 {
            for &j in &row.0 {
                if j == NONE {
                    return;
                }
                f(j as usize);
            }
        }
    }

    /// The rows, for prefetching.
    #[inline]
    pub(crate) fn blocks(self) -> &'a [List] {
        self.0
    }
}

/// Entry `k` of rows `rows`.
#[inline(always)]
fn at(rows: &mut [List], k: usize) -> &mut u32 {
    &mut rows[k / CAPACITY].0[k % CAPACITY]
}

/// Whether `rows` are crowded.
#[inline(always)]
pub(crate) fn crowded(rows: &[List]) -> bool {
    rows[0].0[0] == CROWDED
}

/// Takes `i` out of `rows`, moving the last entry into its place (no-op if crowded or absent).
#[inline]
pub(crate) fn drop(rows: &mut [List], i: u32) {
    if crowded(rows) {
        return;
    }
    // Members first, then `NONE`s: count the members and find `i` without branches.
    let full = rows.len() * CAPACITY;
    let (mut len, mut found) = (0, full);
    for (k, j) in rows.iter().flat_map(|row| row.0).enumerate() {
        len += (j != NONE) as usize;
        found = if j == i { k } else { found };
    }
    if found < full {
        *at(rows, found) = *at(rows, len - 1);
        *at(rows, len - 1) = NONE;
    }
}

/// Puts `i` into `rows`; full rows become crowded.
#[inline]
pub(crate) fn add(rows: &mut [List], i: u32) {
    if crowded(rows) {
        return;
    }
    let len = rows.iter().flat_map(|row| row.0).filter(|&j| j != NONE).count();
    if len == rows.len() * CAPACITY {
        set_crowded(rows);
    } else {
        *at(rows, len) = i;
    }
}

/// Rows holding `members`, or crowded ones if they do not fit.
#[inline]
pub(crate) fn fill(rows: &mut [List], members: &[u32]) {
    if members.len() > rows.len() * CAPACITY {
        set_crowded(rows);
        return;
    }
    rows.fill(List::EMPTY);
    for (k, &j) in members.iter().enumerate() {
        *at(rows, k) = j;
    }
}

/// The first entries of `entries` in a block as wide as the widest list, `NONE` after them:
/// whether a particle is among them is then one vector compare.
#[inline(always)]
pub(crate) fn block(entries: impl IntoIterator<Item = u32>) -> [u32; MAX_ROWS * CAPACITY] {
    let mut block = [NONE; MAX_ROWS * CAPACITY];
    for (slot, j) in block.iter_mut().zip(entries) {
        *slot = j;
    }
    block
}

/// Marks `rows` crowded.
pub(crate) fn set_crowded(rows: &mut [List]) {
    rows.fill(List::EMPTY);
    rows[0].0[0] = CROWDED;
}

/// Lists are kept (by [`Neighbourhood::Auto`]) from this packing fraction on,
/// `n·π(reach/2)²` with `n` the number density, at every N. Lists save the walk through the
/// cell lists around a particle (and, at large N, most of the cache misses around a
/// collision); at lower densities a particle leaves its skin so often that the rebuilds cost
/// more. The crossover was measured with alternating runs of both neighbourhoods over N and
/// η (`benches/HISTORY.md`).
pub const LISTS_FROM: f64 = 0.63;

/// The mean number of particles the list range is sized to hold, `n·πR²`: a longer range
/// means fewer rebuilds but longer rows and more crowded particles (which search the grid
/// instead); this one makes the skin about 0.8 of a contact distance at η = 0.65, the
/// fastest of the skins measured (`benches/HISTORY.md`).
pub const RANGE_HOLDS: f64 = 8.4;

/// Spheres: lists are kept (by [`Neighbourhood::Auto`]) from this packing fraction on,
/// `n·(π/6)·reach³`. Measured with alternating runs of both neighbourhoods at N = 10⁴
/// (`benches/HISTORY.md`): the grid is ahead at η = 0.3, even at 0.35, lists ahead by a tenth
/// at 0.4 and a quarter at 0.45.
pub const LISTS_FROM_3D: f64 = 0.38;

/// Spheres: the mean number of particles the list range is sized to hold, `n·(4π/3)·R³`
/// (two rows hold 16; the fluid's first shell crowds the range beyond its mean, and a
/// particle with more than 16 searches the grid). Of 8, 10, 12 and 14 measured at η = 0.45,
/// 12 was the fastest (a skin of about 0.55 of a contact distance there).
pub const RANGE_HOLDS_3D: f64 = 12.0;

/// The skin for lists, or `None` for the grid that follows the particles: with no short
/// periodic axis (`allow`), and for [`Neighbourhood::Auto`] from [`LISTS_FROM`]
/// ([`LISTS_FROM_3D`] for spheres) on, unless the range would crowd (below). The skin makes the range hold [`RANGE_HOLDS`]
/// ([`RANGE_HOLDS_3D`]) particles, within `[reach/4, reach]`, and short enough that a range
/// plus a skin stays under half of every periodic box length (one image of a pair in range).
pub(crate) fn skin_for<const D: usize>(
    sim_box: &SimBox<D>,
    reach: f64,
    n: usize,
    allow: bool,
    choice: Neighbourhood,
) -> Option<f64> {
    use std::f64::consts::PI;
    let density = n as f64 / sim_box.volume();
    let (eta, from) = match D {
        2 => (density * PI * 0.25 * reach * reach, LISTS_FROM),
        _ => (density * PI / 6.0 * reach * reach * reach, LISTS_FROM_3D),
    };
    let range = match D {
        2 => (RANGE_HOLDS / (PI * density)).sqrt(),
        _ => (RANGE_HOLDS_3D / (4.0 / 3.0 * PI * density)).cbrt(),
    };
    // Where the range that holds RANGE_HOLDS particles is shorter than the smallest skin
    // allows, a range would hold far more than a row: a size-asymmetric mixture (the reach
    // is the large pair's, the density the small particles'), whose particles would all be
    // crowded and search the grid after paying for the lists' upkeep. Never for equal
    // particles: that takes η above 1.3 in 2D.
    let crowds = range < 1.25 * reach;
    let wanted = match choice {
        Neighbourhood::Auto => eta >= from && !crowds,
        Neighbourhood::Grid => false,
        Neighbourhood::Lists => true,
    };
    if !(D == 2 || D == 3) || !allow || !wanted {
        return None;
    }
    let mut skin = (range - reach).clamp(0.25 * reach, reach);
    for a in 0..D {
        if sim_box.boundary[a] == Boundary::Periodic {
            skin = skin.min(0.45 * (0.5 * sim_box.lengths[a] - reach));
        }
    }
    Some(skin)
}
