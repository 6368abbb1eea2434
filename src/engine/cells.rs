//! The cell grid: cells at least one contact distance wide, so that every possible
//! collision partner of a particle is in its own or an adjacent cell.
//!
//! Each particle carries an *unwrapped* integer cell coordinate per axis; along periodic
//! axes it keeps counting past the box (that is how images are tracked without shifting
//! positions). The wrapped coordinate selects the cell list.

use super::geometry::{Boundary, SimBox};
use nalgebra::SVector;

/// Cell lists over the box.
#[derive(Clone, Debug)]
pub struct Cells<const D: usize> {
    counts: [usize; D],
    widths: SVector<f64, D>,
    boundary: [Boundary; D],
    lists: Vec<Vec<usize>>,
    /// Unwrapped cell coordinate of each particle.
    coords: Vec<[i64; D]>,
    /// Index of each particle within its cell list.
    slot: Vec<usize>,
}

/// Relative slack on the cell width: a particle may sit a few ulps outside its cell (its
/// crossing time is rounded), and must still be found by its neighbours' search.
const WIDTH_SLACK: f64 = 1e-9;

impl<const D: usize> Cells<D> {
    /// A grid with cells at least `reach·(1 + 10⁻⁹)` wide, `reach` the largest contact
    /// distance, holding the given positions.
    pub fn new(sim_box: &SimBox<D>, reach: f64, positions: impl Iterator<Item = SVector<f64, D>>) -> Self {
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
            lists: vec![Vec::new(); total],
            coords: Vec::new(),
            slot: Vec::new(),
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
            cells.slot.push(0);
            cells.insert(i);
        }
        cells
    }

    /// Rebuilds a grid from stored unwrapped coordinates (checkpoints).
    pub fn from_coords(sim_box: &SimBox<D>, reach: f64, coords: Vec<[i64; D]>) -> Self {
        let mut cells = Cells::new(sim_box, reach, std::iter::empty());
        cells.slot = vec![0; coords.len()];
        cells.coords = coords;
        for i in 0..cells.coords.len() {
            cells.insert(i);
        }
        cells
    }

    /// Heap bytes held (capacities, not lengths).
    pub fn memory_bytes(&self) -> usize {
        use std::mem::size_of;
        self.lists.capacity() * size_of::<Vec<usize>>()
            + self.lists.iter().map(|l| l.capacity() * size_of::<usize>()).sum::<usize>()
            + self.coords.capacity() * size_of::<[i64; D]>()
            + self.slot.capacity() * size_of::<usize>()
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
        self.slot[i] = self.lists[c].len();
        self.lists[c].push(i);
    }

    fn remove(&mut self, i: usize) {
        let c = self.wrap(&self.coords[i]);
        let s = self.slot[i];
        self.lists[c].swap_remove(s);
        if let Some(&moved) = self.lists[c].get(s) {
            self.slot[moved] = s;
        }
    }

    /// Moves particle `i` one cell along `axis`, up or down.
    pub fn shift(&mut self, i: usize, axis: usize, up: bool) {
        self.remove(i);
        self.coords[i][axis] += if up { 1 } else { -1 };
        self.insert(i);
    }

    /// The time from `t0` at which a particle at `x` (at `t0`) moving with `v` leaves cell
    /// `m` — `(Δt, axis, up)` — or `None` if it never does (at rest, or only walls ahead).
    pub fn next_crossing(&self, m: &[i64; D], x: &SVector<f64, D>, v: &SVector<f64, D>) -> Option<(f64, usize, bool)> {
        let mut best: Option<(f64, usize, bool)> = None;
        for a in 0..D {
            let up = v[a] > 0.0;
            if v[a] == 0.0 {
                continue;
            }
            if self.boundary[a] == Boundary::Wall && ((up && m[a] + 1 >= self.counts[a] as i64) || (!up && m[a] <= 0)) {
                continue;
            }
            let edge = if up { m[a] + 1 } else { m[a] } as f64 * self.widths[a];
            let dt = ((edge - x[a]) / v[a]).max(0.0);
            if best.is_none_or(|(b, _, _)| dt < b) {
                best = Some((dt, a, up));
            }
        }
        best
    }

    /// The distinct cells adjacent to (and including) particle `i`'s cell, each listed once
    /// even when an axis has fewer than three cells.
    pub fn neighbours(&self, i: usize) -> impl Iterator<Item = usize> + '_ {
        let m = self.coords[i];
        let mut found: Vec<usize> = Vec::with_capacity(3usize.pow(D as u32));
        let mut offset = [-1i64; D];
        loop {
            let mut n = m;
            let mut inside = true;
            for a in 0..D {
                n[a] += offset[a];
                if self.boundary[a] == Boundary::Wall && !(0..self.counts[a] as i64).contains(&n[a]) {
                    inside = false;
                }
            }
            if inside {
                let c = self.wrap(&n);
                if !found.contains(&c) {
                    found.push(c);
                }
            }
            // Next offset in {−1, 0, 1}^D.
            let mut a = 0;
            while a < D && offset[a] == 1 {
                offset[a] = -1;
                a += 1;
            }
            if a == D {
                break;
            }
            offset[a] += 1;
        }
        found.into_iter().flat_map(move |c| self.lists[c].iter().copied())
    }
}
