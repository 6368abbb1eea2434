//! The cell grid: cells at least one contact distance wide, so that every possible
//! collision partner of a particle is in its own or an adjacent cell.
//!
//! Each particle carries an *unwrapped* integer cell coordinate per axis; along periodic
//! axes it keeps counting past the box (that is how images are tracked without shifting
//! positions). The wrapped coordinate selects the cell list.

use super::geometry::{Boundary, SimBox};
use nalgebra::SVector;

/// No particle / end of a cell list.
const NONE: u32 = u32::MAX;

/// Cell lists over the box, as intrusive singly linked lists: one head per cell and a `next`
/// link per particle. Nothing allocates after construction, and the grid costs 4 bytes per
/// particle plus 4 per cell — where a `Vec` per cell cost 24 bytes of header per cell and a
/// heap block each (measured: 420–570 bytes per particle for the whole engine before).
/// Removing a particle walks its cell's list, which holds about one particle (cells are one
/// contact distance wide), so a back link would cost more memory than it saves time.
#[derive(Clone, Debug)]
pub struct Cells<const D: usize> {
    counts: [usize; D],
    widths: SVector<f64, D>,
    boundary: [Boundary; D],
    /// Flat-index stride of each axis (axis 0 fastest).
    strides: [usize; D],
    head: Vec<u32>,
    next: Vec<u32>,
    /// Unwrapped cell coordinate of each particle.
    coords: Vec<[i64; D]>,
    /// The same, wrapped into the grid (`coords` modulo `counts`): the cells around a
    /// particle are then found without a division (two per call cost more than the rest of
    /// [`Cells::gather`]'s cell arithmetic; 8 bytes per particle in 2D).
    wrapped: Vec<[u32; D]>,
}

/// Relative slack on the cell width: a particle may sit a few ulps outside its cell (its
/// crossing time is rounded), and must still be found by its neighbours' search.
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
            let (ny, nz) = (if D > 1 { 3 } else { 1 }, if D > 2 { 3 } else { 1 });
            for &z in &o[2][..nz] {
                for &y in &o[1][..ny] {
                    for &x in &o[0] {
                        f(x + y + z);
                    }
                }
            }
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
}

impl<const D: usize> Cells<D> {
    /// A grid with cells at least `reach·(1 + 10⁻⁹)` wide, `reach` the largest contact
    /// distance, holding the given positions.
    pub fn new(sim_box: &SimBox<D>, reach: f64, positions: impl Iterator<Item = SVector<f64, D>>) -> Self {
        const { assert!(D >= 1 && D <= 3, "the cell grid supports 1 to 3 dimensions") };
        let mut counts = [1usize; D];
        let mut widths = SVector::zeros();
        for a in 0..D {
            let n = (sim_box.lengths[a] / (reach * (1.0 + WIDTH_SLACK))).floor().max(1.0);
            counts[a] = n as usize;
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
            boundary: sim_box.boundary,
            head: vec![NONE; total],
            next: Vec::new(),
            coords: Vec::new(),
            wrapped: Vec::new(),
        };
        for (i, r) in positions.enumerate() {
            let mut m = [0i64; D];
            for a in 0..D {
                let raw = (r[a] / widths[a]).floor() as i64;
                m[a] = match cells.boundary[a] {
                    Boundary::Periodic => raw,
                    Boundary::Wall => raw.clamp(0, counts[a] as i64 - 1),
                };
            }
            cells.coords.push(m);
            cells.wrapped.push(cells.wrap_axes(&m));
            cells.next.push(NONE);
            cells.insert(i);
        }
        // The sentinel link past the last particle (see `gather`).
        cells.next.push(NONE);
        cells.coords.shrink_to_fit();
        cells.wrapped.shrink_to_fit();
        cells.next.shrink_to_fit();
        cells
    }

    /// Rebuilds a grid from stored unwrapped coordinates (checkpoints).
    pub fn from_coords(sim_box: &SimBox<D>, reach: f64, coords: Vec<[i64; D]>) -> Self {
        let mut cells = Cells::new(sim_box, reach, std::iter::empty());
        cells.next = vec![NONE; coords.len() + 1];
        cells.wrapped = coords.iter().map(|m| cells.wrap_axes(m)).collect();
        cells.coords = coords;
        for i in 0..cells.coords.len() {
            cells.insert(i);
        }
        cells
    }

    /// Heap bytes held (capacities, not lengths).
    pub fn memory_bytes(&self) -> usize {
        use std::mem::size_of;
        (self.head.capacity() + self.next.capacity()) * size_of::<u32>()
            + self.coords.capacity() * size_of::<[i64; D]>()
            + self.wrapped.capacity() * size_of::<[u32; D]>()
    }

    /// Cells per axis.
    pub fn counts(&self) -> [usize; D] {
        self.counts
    }

    /// The unwrapped cell coordinate of particle `i`.
    pub fn coord(&self, i: usize) -> [i64; D] {
        self.coords[i]
    }

    /// All unwrapped coordinates (for checkpoints).
    pub fn coords(&self) -> &[[i64; D]] {
        &self.coords
    }

    /// An unwrapped coordinate wrapped into the grid, axis by axis.
    fn wrap_axes(&self, m: &[i64; D]) -> [u32; D] {
        std::array::from_fn(|a| m[a].rem_euclid(self.counts[a] as i64) as u32)
    }

    /// The flat index of particle `i`'s cell.
    fn flat(&self, i: usize) -> usize {
        (0..D).map(|a| self.wrapped[i][a] as usize * self.strides[a]).sum()
    }

    fn insert(&mut self, i: usize) {
        let c = self.flat(i);
        self.next[i] = self.head[c];
        self.head[c] = i as u32;
    }

    fn remove(&mut self, i: usize) {
        let c = self.flat(i);
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

    /// Moves particle `i` one cell along `axis`, up or down.
    pub fn shift(&mut self, i: usize, axis: usize, up: bool) {
        self.remove(i);
        self.coords[i][axis] += if up { 1 } else { -1 };
        let (n, w) = (self.counts[axis] as u32, self.wrapped[i][axis]);
        self.wrapped[i][axis] = match up {
            true if w + 1 == n => 0,
            true => w + 1,
            false if w == 0 => n - 1,
            false => w - 1,
        };
        self.insert(i);
    }

    /// The time from `t0` at which a particle at `x` (at `t0`) moving with `v` leaves cell
    /// `m` — `(Δt, axis, up)` — or `None` if it never does (at rest, or only walls ahead).
    ///
    /// Which axis is crossed first, and in which direction, is a coin toss for the branch
    /// predictor, so both are chosen by selects, not branches.
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
            let dt = ((edge - x[a]) / v[a]).max(0.0);
            // The first axis, or an earlier crossing than the best so far (ties: lower axis).
            let better = dt < best_dt || best_axis == usize::MAX;
            best_dt = best_dt.min(dt);
            best_axis = std::hint::select_unpredictable(better, a, best_axis);
            best_up = std::hint::select_unpredictable(better, up, best_up);
        }
        (best_axis != usize::MAX).then_some((best_dt, best_axis, best_up))
    }

    /// The distinct cells adjacent to (and including) particle `i`'s cell, each listed once
    /// even when an axis has fewer than three cells; no allocation. The order is the flat
    /// index order of a 3^D block: axis 0 fastest.
    pub fn around(&self, i: usize) -> Around {
        let mut around = Around { cells: [0; 27], len: 0 };
        self.stencil(i).for_each::<D>(
            #[inline(always)]
            |c| {
                around.cells[around.len] = c as u32;
                around.len += 1;
            },
        );
        around
    }

    /// Particle `i`'s [`Stencil`]. Away from the walls every axis with three cells or more
    /// gives m − 1, m, m + 1, wrapped by comparison (this and the unrolled loops replaced a
    /// general construction that cost about 350 instructions a call; callgrind, N = 10⁴,
    /// η = 0.65); next to a wall, or with fewer than three cells (which wrap onto each
    /// other), the distinct ones are listed one by one.
    #[inline(always)]
    fn stencil(&self, i: usize) -> Stencil {
        let w = self.wrapped[i];
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

    /// Prefetches particle `i`'s cell coordinate.
    #[inline]
    pub fn prefetch_coord(&self, i: usize) {
        super::prefetch::prefetch(&self.coords[i]);
    }

    /// Prefetches the heads of the cells `around` (from [`Cells::around`]).
    #[inline]
    pub fn prefetch_heads(&self, around: &Around) {
        for &c in around.as_slice() {
            super::prefetch::prefetch(&self.head[c as usize]);
        }
    }

    /// Prefetches the first member of each of the cells `around`, from `records` (one per
    /// particle), and its link (the heads should already be in cache).
    #[inline]
    pub fn prefetch_members<T>(&self, around: &Around, records: &[T]) {
        for &c in around.as_slice() {
            let j = self.head[c as usize];
            if j != NONE {
                super::prefetch::prefetch(&self.next[j as usize]);
                super::prefetch::prefetch(&records[j as usize]);
            }
        }
    }

    /// The particles in cell `c` (a flat index from [`Cells::around`]).
    #[inline]
    pub fn members(&self, c: u32) -> Members<'_> {
        Members { next: &self.next, at: self.head[c as usize] }
    }

    /// Writes the particles in the cells around particle `i`, except `i` and `skip`, into
    /// `out` and returns how many — or `None` when they do not fit (`out.len()` or more).
    ///
    /// The first two members of each cell are taken without branches: a cell one contact
    /// distance wide seldom holds more, and how many it holds is a coin toss for the branch
    /// predictor (a loop per cell cost about 2 mispredictions per gather; callgrind's branch
    /// simulation, N = 10⁴, η = 0.65). The end of a list, `NONE`, reads the sentinel link
    /// past the last particle, which is `NONE` again, and is not counted. Every write goes to
    /// `out[min(len, last)]`, with no early exit: once `len` reaches `out.len()` the entries
    /// are no longer trusted and the answer is `None`, but until then no write is clamped.
    #[inline]
    pub fn gather(&self, i: usize, skip: usize, out: &mut [u32]) -> Option<usize> {
        let sentinel = self.next.len() - 1;
        let last = out.len().checked_sub(1)?;
        let mut len = 0;
        // The closure is inlined into each of the unrolled cells (a call per cell cost more
        // than the members it gathers).
        self.stencil(i).for_each::<D>(
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

    /// Every particle in the cells around particle `i` (itself included).
    pub fn neighbours(&self, i: usize) -> impl Iterator<Item = usize> + '_ {
        let around = self.around(i);
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
    fn around_by_definition<const D: usize>(cells: &Cells<D>, m: &[i64; D]) -> Vec<u32> {
        let mut out = Vec::new();
        for code in 0..3usize.pow(D as u32) {
            let mut flat = 0;
            let mut inside = true;
            for a in 0..D {
                let y = m[a] + (code / 3usize.pow(a as u32) % 3) as i64 - 1;
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

    /// Random walks of particles through grids of 1 to 5 cells per axis, periodic and
    /// walled, in 2D and 3D: after every shift, each particle's cells around (`around`, the
    /// stencil's fast and slow paths) are those of the definition, and `gather` returns
    /// exactly the members of those cells but `i` and `skip`.
    fn walk<const D: usize>(seed: u64) {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
        let mut boxes = 0;
        while boxes < 60 {
            let counts: [usize; D] = std::array::from_fn(|_| rng.random_range(1..=5));
            let boundary: [Boundary; D] =
                std::array::from_fn(|_| if rng.random_range(0..2) == 0 { Boundary::Periodic } else { Boundary::Wall });
            let lengths = SVector::<f64, D>::from_fn(|a, _| counts[a] as f64 + 0.5);
            let sim_box = SimBox { lengths, boundary };
            let n = 12;
            let positions: Vec<_> =
                (0..n).map(|_| SVector::<f64, D>::from_fn(|a, _| rng.random_range(0.0..lengths[a]))).collect();
            let mut cells = Cells::new(&sim_box, 1.0, positions.into_iter());
            assert_eq!(cells.counts, counts);
            boxes += 1;
            for _ in 0..200 {
                let i = rng.random_range(0..n);
                let axis = rng.random_range(0..D);
                let up = rng.random_range(0..2) == 0;
                let m = cells.coords[i][axis];
                let blocked =
                    boundary[axis] == Boundary::Wall && if up { m + 1 >= counts[axis] as i64 } else { m <= 0 };
                if !blocked {
                    cells.shift(i, axis, up);
                }
                for k in 0..n {
                    assert_eq!(cells.wrapped[k], cells.wrap_axes(&cells.coords[k]));
                    let mut got = cells.around(k).as_slice().to_vec();
                    got.sort_unstable();
                    let expected = around_by_definition(&cells, &cells.coords[k]);
                    assert_eq!(got, expected, "counts {counts:?}, {boundary:?}, coord {:?}", cells.coords[k]);
                    let skip = (k + 1) % n;
                    let mut out = [0u32; 64];
                    let len = cells.gather(k, skip, &mut out).expect("room for 12");
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

    /// A gather that does not fit says so instead of writing past `out` or dropping members.
    #[test]
    fn gather_reports_when_the_members_do_not_fit() {
        let sim_box = SimBox { lengths: SVector::from([10.5, 10.5]), boundary: [Boundary::Periodic; 2] };
        let positions = (0..40).map(|k| SVector::from([5.2 + 0.01 * k as f64, 5.3]));
        let cells = Cells::new(&sim_box, 1.0, positions);
        let mut out = [0u32; 40];
        assert_eq!(cells.gather(0, 0, &mut out), Some(39));
        let mut small = [0u32; 39];
        assert_eq!(cells.gather(0, 0, &mut small), None);
        let mut tiny = [0u32; 38];
        assert_eq!(cells.gather(0, 0, &mut tiny), None);
    }
}
