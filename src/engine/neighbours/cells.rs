//! The cell grid, in one of two roles (see [`Neighbours`](super::Neighbours)):
//!
//! * **Following** the particles ([`Cells::follow`]): cells at least one contact distance
//!   wide, each particle in the cell of its current position, so that every possible partner
//!   is in its own or an adjacent cell. Each particle carries an *unwrapped* integer cell
//!   coordinate per axis (along periodic axes it keeps counting past the box, which is how
//!   its crossing times are computed from unwrapped positions), and the wrapped one that
//!   selects the cell list. Leaving a cell is an event ([`Cells::next_crossing`],
//!   [`Cells::shift`]).
//! * Holding neighbour-list **centres** ([`Cells::new`]): cells at least one list range wide,
//!   each particle in the cell of its centre, which moves only when the particle leaves its
//!   skin. No coordinate is stored: [`Cells::locate`] finds it from the centre.

use crate::engine::arrays::Store;
use crate::engine::geometry::{Boundary, SimBox};
use crate::engine::motion;
use nalgebra::SVector;

/// No particle / end of a cell list.
const NONE: u32 = u32::MAX;

/// A cell's coordinate, wrapped into the grid (axis by axis).
pub type Coord<const D: usize> = [u32; D];

/// Cell lists over the box, as intrusive singly linked lists: one head per cell and a `next`
/// link per particle. Nothing allocates after construction, and the grid costs 4 bytes per
/// particle plus 4 per cell (a `Vec` per cell would cost 24 bytes of header per cell and a
/// heap block each).
/// Removing a particle walks its cell's list, which holds about one particle, so a back
/// link would cost more memory than it saves time. Which cell a particle is in is not
/// stored: the caller locates it from the particle's centre (the same function of the same
/// number, so insertion and removal agree).
#[derive(Clone, Debug)]
pub struct Cells<const D: usize> {
    counts: [usize; D],
    widths: SVector<f64, D>,
    /// `1 / width` per axis: locating a centre multiplies (the cell boundaries then sit
    /// within an ulp of multiples of the width, which [`WIDTH_SLACK`] absorbs).
    inverse: SVector<f64, D>,
    boundary: [Boundary; D],
    /// Flat-index stride of each axis (axis 0 fastest).
    strides: [usize; D],
    head: Vec<u32>,
    next: Vec<u32>,
    /// Following: the unwrapped cell coordinate of each particle (else empty).
    coords: Vec<[i64; D]>,
    /// Following: the same, wrapped into the grid (`coords` modulo `counts`; else empty). The
    /// cells around a particle are then found without a division (a division per axis would
    /// cost more than the rest of [`Cells::gather`]'s cell arithmetic).
    wrapped: Vec<Coord<D>>,
}

/// Relative slack on the cell width: a centre a few ulps from a cell boundary may be located
/// on either side of it, and must still be found by its neighbours' search.
const WIDTH_SLACK: f64 = 1e-9;

/// The distinct cells around one cell (at most 3^D, D ≤ 3), as flat cell indices.
#[derive(Clone, Copy, Debug)]
pub struct Around {
    cells: [u32; 27],
    len: usize,
}

impl Around {
    /// The cell indices.
    pub fn as_slice(&self) -> &[u32] {
        &self.cells[..self.len]
    }
}

/// The cells around one cell, axis by axis: the distinct wrapped coordinates among m − 1,
/// m, m + 1 (inside the walls), each multiplied by its axis' stride; a cell's flat index is
/// the sum of one offset per axis. Axes past `D` hold the single offset 0, so that one
/// triple loop serves every `D ≤ 3`.
#[derive(Clone, Copy, Debug)]
struct Stencil {
    offsets: [[usize; 3]; 3],
    lens: [usize; 3],
    /// Three distinct offsets on every axis (the cell is away from the walls and every
    /// axis has three cells or more): the loops then have constant bounds and unroll.
    full: bool,
}

impl Stencil {
    /// Calls `f` with the flat index of each cell, axis 0 fastest.
    #[inline(always)]
    fn for_each<const D: usize>(&self, mut f: impl FnMut(usize)) {
        let o = &self.offsets;
        if self.full {
            self.for_each_full::<D>(|_, c| f(c));
        } else {
            for &z in &o[2][..self.lens[2]] {
                for &y in &o[1][..self.lens[1]] {
                    for &x in &o[0][..self.lens[0]] {
                        f(x + y + z);
                    }
                }
            }
        }
    }

    /// The full stencil's cells (see [`for_each`](Self::for_each)): `f` gets each cell's
    /// place on every axis (0 below, 1 at, 2 above the cell around which it is) and its flat
    /// index, axis 0 fastest. The loops have constant bounds and unroll.
    #[inline(always)]
    fn for_each_full<const D: usize>(&self, mut f: impl FnMut([usize; 3], usize)) {
        let o = &self.offsets;
        let (ny, nz) = (if D > 1 { 3 } else { 1 }, if D > 2 { 3 } else { 1 });
        for (kz, &z) in o[2][..nz].iter().enumerate() {
            for (ky, &y) in o[1][..ny].iter().enumerate() {
                for (kx, &x) in o[0].iter().enumerate() {
                    f([kx, ky, kz], x + y + z);
                }
            }
        }
    }
}

impl<const D: usize> Cells<D> {
    /// A grid with cells at least `width·(1 + 10⁻⁹)` wide, holding particle `k` at the `k`-th
    /// of `centres`.
    pub fn new(sim_box: &SimBox<D>, width: f64, centres: impl Iterator<Item = SVector<f64, D>>) -> Self {
        const { assert!(D >= 1 && D <= 3, "the cell grid supports 1 to 3 dimensions") };
        let mut counts = [1usize; D];
        let mut inverse = SVector::zeros();
        let mut widths = SVector::zeros();
        for a in 0..D {
            let n = (sim_box.lengths[a] / (width * (1.0 + WIDTH_SLACK))).floor().max(1.0);
            counts[a] = n as usize;
            inverse[a] = n / sim_box.lengths[a];
            widths[a] = sim_box.lengths[a] / n;
        }
        let total = counts.iter().product();
        let mut strides = [1usize; D];
        for a in 1..D {
            strides[a] = strides[a - 1] * counts[a - 1];
        }
        let mut cells = Cells {
            counts,
            strides,
            widths,
            inverse,
            boundary: sim_box.boundary,
            head: vec![NONE; total],
            next: Vec::new(),
            coords: Vec::new(),
            wrapped: Vec::new(),
        };
        for (i, c) in centres.enumerate() {
            cells.next.push(NONE);
            let m = cells.locate(&c);
            cells.insert(i, &m);
        }
        // The sentinel link past the last particle (see `gather`).
        cells.next.push(NONE);
        cells.next.shrink_to_fit();
        cells
    }

    /// A grid following the particles at `positions` (unwrapped), with cells at least
    /// `width·(1 + 10⁻⁹)` wide; its links built in `store`.
    pub(crate) fn follow(
        sim_box: &SimBox<D>,
        width: f64,
        positions: impl Iterator<Item = SVector<f64, D>>,
        store: &impl Store,
    ) -> Self {
        let cells = Cells::new(sim_box, width, std::iter::empty());
        let coords = positions
            .map(|r| {
                std::array::from_fn(|a| {
                    let raw = (r[a] / cells.widths[a]).floor() as i64;
                    match cells.boundary[a] {
                        Boundary::Periodic => raw,
                        Boundary::Wall => raw.clamp(0, cells.counts[a] as i64 - 1),
                    }
                })
            })
            .collect();
        cells.with_coords(coords, store)
    }

    /// A grid following particles with the given unwrapped coordinates (checkpoints).
    pub(crate) fn from_coords(sim_box: &SimBox<D>, width: f64, coords: Vec<[i64; D]>, store: &impl Store) -> Self {
        Cells::new(sim_box, width, std::iter::empty()).with_coords(coords, store)
    }

    fn with_coords(mut self, mut coords: Vec<[i64; D]>, store: &impl Store) -> Self {
        coords.shrink_to_fit();
        self.next = store.filled(coords.len() + 1, NONE);
        self.wrapped = coords.iter().map(|m| self.wrap_axes(m)).collect();
        self.coords = coords;
        for i in 0..self.coords.len() {
            let m = self.wrapped[i];
            self.insert(i, &m);
        }
        self
    }

    /// Heap bytes held (capacities, not lengths).
    pub fn memory_bytes(&self) -> usize {
        (self.head.capacity() + self.next.capacity()) * size_of::<u32>()
            + self.coords.capacity() * size_of::<[i64; D]>()
            + self.wrapped.capacity() * size_of::<Coord<D>>()
    }

    /// Following: the unwrapped cell coordinate of particle `i`.
    pub fn coord(&self, i: usize) -> [i64; D] {
        self.coords[i]
    }

    /// Following: all unwrapped coordinates (for checkpoints).
    pub fn coords(&self) -> &[[i64; D]] {
        &self.coords
    }

    /// Following: particle `i`'s cell.
    #[inline]
    pub fn wrapped(&self, i: usize) -> Coord<D> {
        self.wrapped[i]
    }

    /// An unwrapped coordinate wrapped into the grid, axis by axis.
    fn wrap_axes(&self, m: &[i64; D]) -> Coord<D> {
        std::array::from_fn(|a| m[a].rem_euclid(self.counts[a] as i64) as u32)
    }

    /// Following: moves particle `i` one cell along `axis`, up or down.
    pub fn shift(&mut self, i: usize, axis: usize, up: bool) {
        let from = self.wrapped[i];
        self.remove(i, &from);
        self.coords[i][axis] += if up { 1 } else { -1 };
        let (n, w) = (self.counts[axis] as u32, self.wrapped[i][axis]);
        self.wrapped[i][axis] = match up {
            true if w + 1 == n => 0,
            true => w + 1,
            false if w == 0 => n - 1,
            false => w - 1,
        };
        let to = self.wrapped[i];
        self.insert(i, &to);
    }

    /// The time from `t0` at which a particle at `x` (at `t0`) moving with `v` leaves cell
    /// `m` (unwrapped) — `(Δt, axis, up)` — or `None` if it never does (at rest, or only
    /// walls ahead).
    ///
    /// Which axis is crossed first, and in which direction, is a coin toss for the branch
    /// predictor, so both are chosen by selects, not branches.
    #[inline]
    pub fn next_crossing(&self, m: &[i64; D], x: &SVector<f64, D>, v: &SVector<f64, D>) -> Option<(f64, usize, bool)> {
        let (mut best_dt, mut best_axis, mut best_up) = (f64::INFINITY, usize::MAX, false);
        for a in 0..D {
            if v[a] == 0.0 {
                continue;
            }
            let up = v[a] > 0.0;
            if self.boundary[a] == Boundary::Wall
                && std::hint::select_unpredictable(up, m[a] + 1 >= self.counts[a] as i64, m[a] <= 0)
            {
                continue;
            }
            let edge = (m[a] + up as i64) as f64 * self.widths[a];
            let dt = motion::time_to(x[a], v[a], edge).max(0.0);
            // The first axis, or an earlier crossing than the best so far (ties: lower axis).
            let better = dt < best_dt || best_axis == usize::MAX;
            best_dt = best_dt.min(dt);
            best_axis = std::hint::select_unpredictable(better, a, best_axis);
            best_up = std::hint::select_unpredictable(better, up, best_up);
        }
        (best_axis != usize::MAX).then_some((best_dt, best_axis, best_up))
    }

    /// The width of a cell along `axis`.
    pub fn width(&self, axis: usize) -> f64 {
        self.widths[axis]
    }

    /// Cells per axis.
    pub fn counts(&self) -> [usize; D] {
        self.counts
    }

    /// The cell of a centre: `⌊x/w⌋` per axis, wrapped along periodic axes and clamped to
    /// the grid between walls.
    #[inline]
    pub fn locate(&self, x: &SVector<f64, D>) -> Coord<D> {
        std::array::from_fn(|a| {
            let (raw, n) = ((x[a] * self.inverse[a]).floor() as i64, self.counts[a] as i64);
            match self.boundary[a] {
                Boundary::Periodic => raw.rem_euclid(n) as u32,
                Boundary::Wall => raw.clamp(0, n - 1) as u32,
            }
        })
    }

    /// The flat index of cell `m`.
    pub(crate) fn flat(&self, m: &Coord<D>) -> usize {
        (0..D).map(|a| m[a] as usize * self.strides[a]).sum()
    }

    /// Puts particle `i` into cell `m`.
    pub fn insert(&mut self, i: usize, m: &Coord<D>) {
        let c = self.flat(m);
        self.next[i] = self.head[c];
        self.head[c] = i as u32;
    }

    /// Takes particle `i` out of cell `m` (where it must be).
    pub fn remove(&mut self, i: usize, m: &Coord<D>) {
        let c = self.flat(m);
        let after = self.next[i];
        if self.head[c] == i as u32 {
            self.head[c] = after;
            return;
        }
        let mut k = self.head[c];
        while self.next[k as usize] != i as u32 {
            k = self.next[k as usize];
        }
        self.next[k as usize] = after;
    }

    /// The distinct cells adjacent to (and including) cell `m`, each listed once even when
    /// an axis has fewer than three cells; no allocation. The order is the flat index order
    /// of a 3^D block: axis 0 fastest.
    pub fn around(&self, m: &Coord<D>) -> Around {
        let mut around = Around { cells: [0; 27], len: 0 };
        self.stencil(m).for_each::<D>(
            #[inline(always)]
            |c| {
                around.cells[around.len] = c as u32;
                around.len += 1;
            },
        );
        around
    }

    /// [`around`](Self::around) for a point `x` in cell `m` (as [`locate`](Self::locate)
    /// puts it), without the cells that cannot hold a centre within `range` of `x`: a cell
    /// diagonal to `m` whose nearest corner or edge is farther. The cells kept are in
    /// `around`'s order. A rebuild's scan visits every member of these cells; with cells
    /// about a range wide, 7–8 of a sphere's 27 are dropped on average (a centre placed
    /// uniformly in its cell), most of them corners.
    ///
    /// Each axis' gap from `x` to the faces of its own cell is shortened by `10⁻⁹` of a
    /// width (the slack a centre a few ulps over a face is located with, see
    /// [`WIDTH_SLACK`]); a cell is dropped only when the sum of its squared gaps exceeds
    /// `range2`, so that no centre in range is dropped whatever the rounding. Away from
    /// the full stencil (a wall, or fewer than three cells on an axis) every cell is kept.
    #[inline]
    pub fn around_within(&self, m: &Coord<D>, x: &SVector<f64, D>, range2: f64) -> Around {
        let stencil = self.stencil(m);
        if !stencil.full {
            return self.around(m);
        }
        // The squared gaps to the cells below, at and above `m` along each axis.
        let mut gap2 = [[0.0f64; 3]; 3];
        for a in 0..D {
            let w = self.widths[a];
            let low = (x[a] * self.inverse[a]).floor() * w;
            let slack = WIDTH_SLACK * w;
            let below = (x[a] - low - slack).max(0.0);
            let above = (low + w - x[a] - slack).max(0.0);
            gap2[a] = [below * below, 0.0, above * above];
        }
        let mut around = Around { cells: [0; 27], len: 0 };
        stencil.for_each_full::<D>(|[kx, ky, kz], c| {
            // Written always, kept by the count: whether a corner is in reach is a coin toss
            // for the branch predictor.
            around.cells[around.len] = c as u32;
            around.len += (gap2[0][kx] + gap2[1][ky] + gap2[2][kz] <= range2) as usize;
        });
        around
    }

    /// The [`Stencil`] of cell `m`. Away from the walls every axis with three cells or more
    /// gives m − 1, m, m + 1, wrapped by comparison, and the loops over them unroll; next to
    /// a wall, or with fewer than three cells (which wrap onto each other), the distinct ones
    /// are listed one by one.
    #[inline(always)]
    fn stencil(&self, w: &Coord<D>) -> Stencil {
        let mut s = Stencil { offsets: [[0; 3]; 3], lens: [1; 3], full: true };
        for a in 0..D {
            let (n, x, stride) = (self.counts[a], w[a] as usize, self.strides[a]);
            let periodic = self.boundary[a] == Boundary::Periodic;
            if n >= 3 && (periodic || (x > 0 && x + 1 < n)) {
                let below = if x == 0 { n - 1 } else { x - 1 };
                let above = if x + 1 == n { 0 } else { x + 1 };
                s.offsets[a] = [below * stride, x * stride, above * stride];
                s.lens[a] = 3;
            } else {
                s.full = false;
                s.lens[a] = 0;
                for y in [x as i64 - 1, x as i64, x as i64 + 1] {
                    if !periodic && !(0..n as i64).contains(&y) {
                        continue;
                    }
                    let offset = y.rem_euclid(n as i64) as usize * stride;
                    if !s.offsets[a][..s.lens[a]].contains(&offset) {
                        s.offsets[a][s.lens[a]] = offset;
                        s.lens[a] += 1;
                    }
                }
            }
        }
        s
    }

    /// Following: where particle `i`'s cell coordinates are kept (the timing room asks, to
    /// prefetch them).
    #[inline]
    pub(crate) fn coord_refs(&self, i: usize) -> (&[i64; D], &Coord<D>) {
        (&self.coords[i], &self.wrapped[i])
    }

    /// The head of cell `c`'s list (a flat index from [`Cells::around`]).
    #[inline]
    pub(crate) fn head(&self, c: u32) -> &u32 {
        &self.head[c as usize]
    }

    /// The first particle in cell `c` and where its link is kept, if the cell holds one.
    #[inline]
    pub(crate) fn first_member(&self, c: u32) -> Option<(usize, &u32)> {
        let j = self.head[c as usize];
        (j != NONE).then(|| (j as usize, &self.next[j as usize]))
    }

    /// The particles in cell `c` (a flat index from [`Cells::around`]).
    #[inline]
    pub fn members(&self, c: u32) -> Members<'_> {
        Members { next: &self.next, at: self.head[c as usize] }
    }

    /// Calls `f` with every particle in the cells `cells` (flat indices, at most 27, as from
    /// [`Cells::around`]), the cells' lists walked side by side: one link of each list still
    /// unfinished per round. A list is a chain of dependent loads, and walked one after
    /// another the lists of a neighbourhood cost one load latency per member (a cache miss
    /// each, at large N); side by side, the links of one round are independent, and the walk
    /// costs one latency per round — as many as the longest list has members. The order is
    /// round by round, not cell by cell.
    #[inline(always)]
    pub fn for_each_member_side_by_side(&self, cells: &[u32], mut f: impl FnMut(u32)) {
        let mut at = [NONE; 27];
        let mut active = 0;
        for &c in cells {
            let j = self.head[c as usize];
            at[active] = j;
            active += (j != NONE) as usize;
        }
        // Each round visits the unfinished lists' current members and keeps, packed to the
        // front without branches, those whose lists go on.
        while active > 0 {
            let mut kept = 0;
            for k in 0..active {
                let j = at[k];
                f(j);
                let next = self.next[j as usize];
                at[kept] = next;
                kept += (next != NONE) as usize;
            }
            active = kept;
        }
    }

    /// Writes the particles in the cells around cell `m`, except `i` and `skip`, into `out`
    /// and returns how many — or `None` when they do not fit (`out.len()` or more).
    ///
    /// The first two members of each cell are taken without branches: a cell one contact
    /// distance wide seldom holds more, and how many it holds is a coin toss for the branch
    /// predictor (a loop per cell mispredicts its exit). The end of a list, `NONE`, reads the sentinel link
    /// past the last particle, which is `NONE` again, and is not counted. Every write goes to
    /// `out[min(len, last)]`, with no early exit: once `len` reaches `out.len()` the entries
    /// are no longer trusted and the answer is `None`, but until then no write is clamped.
    #[inline]
    pub fn gather(&self, m: &Coord<D>, i: usize, skip: usize, out: &mut [u32]) -> Option<usize> {
        let sentinel = self.next.len() - 1;
        let last = out.len().checked_sub(1)?;
        let mut len = 0;
        // The closure is inlined into each of the unrolled cells (a call per cell would cost
        // more than the members it gathers).
        self.stencil(m).for_each::<D>(
            #[inline(always)]
            |c| {
                let mut j = self.head[c];
                for _ in 0..2 {
                    let k = (j as usize).min(sentinel);
                    out[len.min(last)] = j;
                    len += ((j != NONE) & (k != i) & (k != skip)) as usize;
                    j = self.next[k];
                }
                while j != NONE {
                    if j as usize != i && j as usize != skip {
                        out[len.min(last)] = j;
                        len += 1;
                    }
                    j = self.next[j as usize];
                }
            },
        );
        (len < out.len()).then_some(len)
    }

    /// Every particle in the cells around cell `m`.
    pub fn neighbours(&self, m: Coord<D>) -> impl Iterator<Item = usize> + '_ {
        let around = self.around(&m);
        (0..around.len).flat_map(move |k| self.members(around.cells[k]).map(|j| j as usize))
    }
}

/// Iterator over one cell list.
pub struct Members<'a> {
    next: &'a [u32],
    at: u32,
}

impl Iterator for Members<'_> {
    type Item = u32;
    #[inline]
    fn next(&mut self) -> Option<u32> {
        if self.at == NONE {
            return None;
        }
        let j = self.at;
        self.at = self.next[j as usize];
        Some(j)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::rngs::Xoshiro256PlusPlus;
    use rand::{RngExt, SeedableRng};

    /// The cells around `m` by the definition: every `m + o`, `o ∈ {−1, 0, 1}^D`, inside the
    /// walls, wrapped, each once.
    fn around_by_definition<const D: usize>(cells: &Cells<D>, m: &Coord<D>) -> Vec<u32> {
        let mut out = Vec::new();
        for code in 0..3usize.pow(D as u32) {
            let mut flat = 0;
            let mut inside = true;
            for a in 0..D {
                let y = m[a] as i64 + (code / 3usize.pow(a as u32) % 3) as i64 - 1;
                let n = cells.counts[a] as i64;
                inside &= cells.boundary[a] == Boundary::Periodic || (0..n).contains(&y);
                flat += y.rem_euclid(n) as usize * cells.strides[a];
            }
            if inside && !out.contains(&(flat as u32)) {
                out.push(flat as u32);
            }
        }
        out.sort_unstable();
        out
    }

    /// Random moves of particles through grids of 1 to 5 cells per axis, periodic and
    /// walled, in 2D and 3D, with centres anywhere (periodic ones several boxes away): each
    /// centre is located in the cell that holds it (wrapped), each particle's cells around
    /// (`around`, the stencil's fast and slow paths) are those of the definition, and
    /// `gather` returns exactly the members of those cells but `i` and `skip`.
    fn walk<const D: usize>(seed: u64) {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
        for _ in 0..60 {
            let counts: [usize; D] = std::array::from_fn(|_| rng.random_range(1..=5));
            let boundary: [Boundary; D] =
                std::array::from_fn(|_| if rng.random_range(0..2) == 0 { Boundary::Periodic } else { Boundary::Wall });
            let lengths = SVector::<f64, D>::from_fn(|a, _| counts[a] as f64 + 0.5);
            let sim_box = SimBox { lengths, boundary };
            let centre = |rng: &mut Xoshiro256PlusPlus| {
                SVector::<f64, D>::from_fn(|a, _| match boundary[a] {
                    Boundary::Periodic => rng.random_range(-3.0..4.0) * lengths[a],
                    Boundary::Wall => rng.random_range(0.0..lengths[a]),
                })
            };
            let n = 12;
            let mut centres: Vec<_> = (0..n).map(|_| centre(&mut rng)).collect();
            let mut cells = Cells::new(&sim_box, 1.0, centres.iter().copied());
            assert_eq!(cells.counts, counts);
            for _ in 0..200 {
                let i = rng.random_range(0..n);
                let to = centre(&mut rng);
                cells.remove(i, &cells.locate(&centres[i]));
                cells.insert(i, &cells.locate(&to));
                centres[i] = to;
                for k in 0..n {
                    let m = cells.locate(&centres[k]);
                    for a in 0..D {
                        let w = lengths[a] / counts[a] as f64;
                        let x = centres[k][a].rem_euclid(lengths[a]);
                        assert!(x >= m[a] as f64 * w * (1.0 - 1e-12) && x <= (m[a] + 1) as f64 * w * (1.0 + 1e-12));
                    }
                    assert!(cells.members(cells.flat(&m) as u32).any(|j| j as usize == k));
                    let mut got = cells.around(&m).as_slice().to_vec();
                    got.sort_unstable();
                    let expected = around_by_definition(&cells, &m);
                    assert_eq!(got, expected, "counts {counts:?}, {boundary:?}, cell {m:?}");
                    let skip = (k + 1) % n;
                    let mut out = [0u32; 64];
                    let len = cells.gather(&m, k, skip, &mut out).expect("room for 12");
                    let mut members: Vec<u32> = expected
                        .iter()
                        .flat_map(|&c| cells.members(c))
                        .filter(|&j| j as usize != k && j as usize != skip)
                        .collect();
                    members.sort_unstable();
                    let mut gathered = out[..len].to_vec();
                    gathered.sort_unstable();
                    assert_eq!(gathered, members);
                }
            }
        }
    }

    #[test]
    fn around_and_gather_follow_the_definition_in_2d_and_3d() {
        walk::<2>(1);
        walk::<3>(2);
    }

    /// `around_within` keeps every cell that holds a point within range of the query point
    /// (minimum image), drops only cells of `around`, keeps `around`'s order, and drops
    /// some: query points anywhere and within a few ulps of their cell's faces, probe points
    /// at random and at one part in 10¹² inside the range in random directions, grids of 3
    /// to 7 cells a range (and 10⁻⁹) wide per axis, periodic (some axes walled: the
    /// fallback keeps all), in 2D and 3D.
    fn within_keeps_every_cell_in_range<const D: usize>(seed: u64) {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
        let (mut dropped, mut probes) = (0usize, 0usize);
        for round in 0..80 {
            let range = rng.random_range(0.5..2.0);
            let counts: [usize; D] = std::array::from_fn(|_| rng.random_range(3..=7));
            let boundary: [Boundary; D] = std::array::from_fn(|_| {
                if round % 4 == 3 && rng.random_range(0..2) == 0 { Boundary::Wall } else { Boundary::Periodic }
            });
            let lengths =
                SVector::<f64, D>::from_fn(|a, _| counts[a] as f64 * range * rng.random_range(1.0 + 2e-9..1.3));
            let sim_box = SimBox { lengths, boundary };
            let cells = Cells::new(&sim_box, range, std::iter::empty());
            let range2 = range * range;
            for _ in 0..200 {
                let mut x = SVector::<f64, D>::from_fn(|a, _| rng.random_range(0.0..lengths[a]));
                // Onto a face of its cell, a few ulps either side, on some axes.
                for a in 0..D {
                    if rng.random_range(0..3) == 0 {
                        let w = cells.widths[a];
                        let face = (x[a] / w).round() * w;
                        x[a] = f64::from_bits((face.max(0.0).to_bits() as i64 + rng.random_range(-4..=4)) as u64);
                        x[a] = x[a].clamp(0.0, lengths[a].next_down());
                    }
                }
                let m = cells.locate(&x);
                let all = cells.around(&m);
                let kept = cells.around_within(&m, &x, range2);
                let order: Vec<usize> = kept
                    .as_slice()
                    .iter()
                    .map(|c| all.as_slice().iter().position(|d| d == c).expect("in around"))
                    .collect();
                assert!(order.windows(2).all(|w| w[0] < w[1]), "around's order");
                dropped += all.as_slice().len() - kept.as_slice().len();
                for k in 0..64 {
                    let y = if k % 2 == 0 {
                        SVector::<f64, D>::from_fn(|a, _| rng.random_range(0.0..lengths[a]))
                    } else {
                        let u = SVector::<f64, D>::from_fn(|_, _| rng.random_range(-1.0..1.0));
                        let y = x + u.normalize() * (range * (1.0 - 1e-12));
                        SVector::<f64, D>::from_fn(|a, _| match boundary[a] {
                            Boundary::Periodic => y[a].rem_euclid(lengths[a]),
                            Boundary::Wall => y[a].clamp(0.0, lengths[a].next_down()),
                        })
                    };
                    if super::super::apart2(&sim_box, &x, &y) < range2 {
                        probes += 1;
                        let c = cells.flat(&cells.locate(&y)) as u32;
                        assert!(
                            kept.as_slice().contains(&c),
                            "{y:?} within range of {x:?} in a dropped cell (counts {counts:?}, range {range})"
                        );
                    }
                }
            }
        }
        assert!(dropped > 1000 && probes > 10_000, "{dropped} cells dropped, {probes} probes in range");
    }

    #[test]
    fn within_keeps_every_cell_in_range_in_2d_and_3d() {
        within_keeps_every_cell_in_range::<2>(5);
        within_keeps_every_cell_in_range::<3>(6);
    }

    /// The walk of several cells' lists side by side visits every member of those cells
    /// once (lists of different lengths, empty cells among them), as the walk one cell after
    /// another does.
    #[test]
    fn side_by_side_walk_visits_every_member_once() {
        let sim_box = SimBox { lengths: SVector::from([6.0, 6.0, 6.0]), boundary: [Boundary::Periodic; 3] };
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(3);
        // Crowded near one corner, so that lists range from empty to long.
        let positions: Vec<SVector<f64, 3>> = (0..300)
            .map(|_| SVector::from(std::array::from_fn(|_| rng.random_range(0.0f64..1.0).powi(3) * 6.0)))
            .collect();
        let cells = Cells::new(&sim_box, 1.0, positions.iter().copied());
        let mut lengths = std::collections::BTreeSet::new();
        let n = cells.counts()[0] as u32;
        for x in 0..n {
            for y in 0..n {
                let around = cells.around(&[x, y, (x + y) % n]);
                let mut one_by_one: Vec<u32> = around.as_slice().iter().flat_map(|&c| cells.members(c)).collect();
                let mut side_by_side = Vec::new();
                cells.for_each_member_side_by_side(around.as_slice(), |j| side_by_side.push(j));
                one_by_one.sort_unstable();
                side_by_side.sort_unstable();
                assert_eq!(side_by_side, one_by_one);
                lengths.extend(around.as_slice().iter().map(|&c| cells.members(c).count()));
            }
        }
        assert!(lengths.contains(&0) && lengths.iter().any(|&k| k > 5), "{lengths:?}");
    }

    /// A gather that does not fit says so instead of writing past `out` or dropping members.
    #[test]
    fn gather_reports_when_the_members_do_not_fit() {
        let sim_box = SimBox { lengths: SVector::from([10.5, 10.5]), boundary: [Boundary::Periodic; 2] };
        let positions = (0..40).map(|k| SVector::from([5.2 + 0.01 * k as f64, 5.3]));
        let cells = Cells::new(&sim_box, 1.0, positions);
        let m = cells.locate(&SVector::from([5.2, 5.3]));
        let mut out = [0u32; 40];
        assert_eq!(cells.gather(&m, 0, 0, &mut out), Some(39));
        let mut small = [0u32; 39];
        assert_eq!(cells.gather(&m, 0, 0, &mut small), None);
        let mut tiny = [0u32; 38];
        assert_eq!(cells.gather(&m, 0, 0, &mut tiny), None);
    }
}
