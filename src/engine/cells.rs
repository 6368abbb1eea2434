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
    head: Vec<u32>,
    next: Vec<u32>,
    /// Unwrapped cell coordinate of each particle.
    coords: Vec<[i64; D]>,
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
        let mut cells = Cells {
            counts,
            widths,
            boundary: sim_box.boundary,
            head: vec![NONE; total],
            next: Vec::new(),
            coords: Vec::new(),
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
            cells.next.push(NONE);
            cells.insert(i);
        }
        // The sentinel link past the last particle (see `gather`).
        cells.next.push(NONE);
        cells.coords.shrink_to_fit();
        cells.next.shrink_to_fit();
        cells
    }

    /// Rebuilds a grid from stored unwrapped coordinates (checkpoints).
    pub fn from_coords(sim_box: &SimBox<D>, reach: f64, coords: Vec<[i64; D]>) -> Self {
        let mut cells = Cells::new(sim_box, reach, std::iter::empty());
        cells.next = vec![NONE; coords.len() + 1];
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

    fn wrap(&self, m: &[i64; D]) -> usize {
        let mut index = 0;
        for a in (0..D).rev() {
            index = index * self.counts[a] + m[a].rem_euclid(self.counts[a] as i64) as usize;
        }
        index
    }

    fn insert(&mut self, i: usize) {
        let c = self.wrap(&self.coords[i]);
        self.next[i] = self.head[c];
        self.head[c] = i as u32;
    }

    fn remove(&mut self, i: usize) {
        let c = self.wrap(&self.coords[i]);
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
        let m = self.coords[i];
        // Per axis, the distinct wrapped coordinates among m − 1, m, m + 1 (inside the walls),
        // already multiplied by the axis' stride in the flat index. Axes past D get the one
        // offset 0, so one triple loop serves every D ≤ 3 (this replaced a general odometer
        // that cost about 340 instructions a call; callgrind, N = 10⁴, η = 0.65).
        let mut offsets = [[0usize; 3]; 3];
        let mut lens = [1usize; 3];
        let mut stride = 1;
        for a in 0..D {
            let n = self.counts[a] as i64;
            // One division per axis; the neighbours wrap by comparison.
            let centre = m[a].rem_euclid(n);
            let mut len = 0;
            for o in -1..=1 {
                if self.boundary[a] == Boundary::Wall && !(0..n).contains(&(m[a] + o)) {
                    continue;
                }
                let x = centre + o;
                let w = if x < 0 {
                    x + n
                } else if x >= n {
                    x - n
                } else {
                    x
                } as usize
                    * stride;
                // With three cells or more the three are distinct; fewer wrap onto each other.
                if n >= 3 || !offsets[a][..len].contains(&w) {
                    offsets[a][len] = w;
                    len += 1;
                }
            }
            lens[a] = len;
            stride *= self.counts[a];
        }
        let mut around = Around { cells: [0; 27], len: 0 };
        for &z in &offsets[2][..lens[2]] {
            for &y in &offsets[1][..lens[1]] {
                for &x in &offsets[0][..lens[0]] {
                    around.cells[around.len] = (x + y + z) as u32;
                    around.len += 1;
                }
            }
        }
        around
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
    /// `out` and returns how many — or `None` when they may not fit (`out` full before the
    /// last member is looked at).
    ///
    /// The first two members of each cell are taken without branches: a cell one contact
    /// distance wide seldom holds more, and how many it holds is a coin toss for the branch
    /// predictor (a loop per cell cost about 2 mispredictions per gather; callgrind's branch
    /// simulation, N = 10⁴, η = 0.65). The end of a list, `NONE`, reads the sentinel link
    /// past the last particle, which is `NONE` again, and is not counted.
    #[inline]
    pub fn gather(&self, i: usize, skip: usize, out: &mut [u32]) -> Option<usize> {
        let around = self.around(i);
        let sentinel = self.next.len() - 1;
        let mut len = 0;
        for &c in around.as_slice() {
            let mut j = self.head[c as usize];
            for _ in 0..2 {
                let k = (j as usize).min(sentinel);
                *out.get_mut(len)? = j;
                len += ((j != NONE) & (k != i) & (k != skip)) as usize;
                j = self.next[k];
            }
            while j != NONE {
                if j as usize != i && j as usize != skip {
                    *out.get_mut(len)? = j;
                    len += 1;
                }
                j = self.next[j as usize];
            }
        }
        Some(len)
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
