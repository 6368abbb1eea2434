//! Random sequential placement, in any dimension: each particle at a uniformly random
//! accessible position, rejected if it overlaps one already placed (minimum image), up to
//! [`TRIES`] tries per particle; the largest first, so that a few large particles among many
//! small ones find room before the small ones fill the box.
//!
//! Placed disks are kept in cell grids, one per *size class* (radii within a factor of two:
//! the same binary exponent), each with cells at least one class diameter wide. A candidate
//! of radius `r` can only overlap disks of a class of largest radius `r_c` within `r + r_c`,
//! so it looks at `⌈(r + r_c)/w⌉ + 1` cells each way in that class's grid, `w` the cell
//! width: O(1) work per try at any density, and expected O(N) for the whole placement (a
//! search over every placed disk is O(N²)). The test for overlap is the one of the plain
//! search, evaluated for the same
//! pairs that could fail it, and the random numbers are drawn in the same order, so the
//! placement is exactly what a search over every placed disk would give.

use super::{InitError, Species};
use crate::engine::geometry::{Boundary, SimBox};
use nalgebra::SVector;
use rand::RngExt;
use rand::rngs::Xoshiro256PlusPlus;

/// Tries per disk before giving up.
pub(super) const TRIES: usize = 10_000;

/// A cell grid of the disks of one size class, as lists threaded through the placed disks.
struct Grid<const D: usize> {
    /// The binary exponent of the class's radii.
    class: u64,
    /// The largest radius in the class.
    radius: f64,
    /// Cells per axis.
    counts: [usize; D],
    /// Cell widths.
    widths: [f64; D],
    /// First member of each cell (`NONE`: empty).
    heads: Vec<u32>,
}

const NONE: u32 = u32::MAX;

fn class_of(radius: f64) -> u64 {
    radius.to_bits() >> 52
}

impl<const D: usize> Grid<D> {
    /// A grid for `count` disks of largest radius `radius`, with cells at least a diameter
    /// wide and at most about four per disk (a few tiny disks in a large box need no
    /// billions of cells).
    fn new(class: u64, radius: f64, count: usize, sim_box: &SimBox<D>) -> Grid<D> {
        let cap = (4 * count + 16) as f64;
        let fit: [f64; D] = std::array::from_fn(|a| (sim_box.lengths[a] / (2.0 * radius)).floor().clamp(1.0, 1e9));
        let excess = fit.iter().product::<f64>() / cap;
        let shrink = match (excess > 1.0, D) {
            (false, _) => 1.0,
            (true, 2) => excess.sqrt(),
            (true, _) => excess.powf(1.0 / D as f64),
        };
        let counts: [usize; D] = std::array::from_fn(|a| ((fit[a] / shrink).floor() as usize).max(1));
        let widths = std::array::from_fn(|a| sim_box.lengths[a] / counts[a] as f64);
        Grid { class, radius, counts, widths, heads: vec![NONE; counts.iter().product()] }
    }

    /// The flat index of the cell with coordinates `c` (axis 0 fastest).
    fn flat(&self, c: &[usize; D]) -> usize {
        let mut index = 0;
        for a in (0..D).rev() {
            index = index * self.counts[a] + c[a];
        }
        index
    }

    fn cell(&self, x: &SVector<f64, D>, axis: usize) -> usize {
        let m = (x[axis] / self.widths[axis]).floor();
        (m.max(0.0) as usize).min(self.counts[axis] - 1)
    }

    /// The cell indices along `axis` within `reach` cells of `m`, as `start..end` taken
    /// modulo the count: each once, wrapped along a periodic axis, cut at the walls.
    fn span(&self, m: usize, reach: usize, axis: usize, boundary: Boundary) -> (usize, usize) {
        let n = self.counts[axis];
        if 2 * reach + 1 >= n {
            (0, n)
        } else {
            match boundary {
                Boundary::Periodic => (m + n - reach, m + n + reach + 1),
                Boundary::Wall => (m.saturating_sub(reach), (m + reach + 1).min(n)),
            }
        }
    }
}

/// The placement state: every disk placed so far, and the grids that index them.
struct Placed<'a, const D: usize> {
    sim_box: &'a SimBox<D>,
    disks: Vec<(SVector<f64, D>, f64)>,
    next: Vec<u32>,
    grids: Vec<Grid<D>>,
    /// Pairs tested for overlap so far (the work the grids save is counted by a test).
    tested: u64,
}

impl<const D: usize> Placed<'_, D> {
    /// Whether a disk of radius `r` at `x` overlaps none placed: `|d| ≥ r + s` for the
    /// minimum image `d` of every placed disk (radius `s`) near enough to fail it.
    fn clear(&mut self, x: &SVector<f64, D>, r: f64) -> bool {
        for grid in &self.grids {
            let reach = |a: usize| (((r + grid.radius) / grid.widths[a]).ceil().min(1e9) as usize).saturating_add(1);
            let spans: [(usize, usize); D] =
                std::array::from_fn(|a| grid.span(grid.cell(x, a), reach(a), a, self.sim_box.boundary[a]));
            // Every cell of the block, axis 0 fastest.
            let mut at: [usize; D] = std::array::from_fn(|a| spans[a].0);
            'cells: loop {
                let c: [usize; D] = std::array::from_fn(|a| at[a] % grid.counts[a]);
                let mut k = grid.heads[grid.flat(&c)];
                while k != NONE {
                    self.tested += 1;
                    let (y, s) = &self.disks[k as usize];
                    let d = y - x;
                    let d = d + self.sim_box.minimum_image_shift(&d);
                    if d.norm() < r + s {
                        return false;
                    }
                    k = self.next[k as usize];
                }
                for a in 0..D {
                    at[a] += 1;
                    if at[a] < spans[a].1 {
                        continue 'cells;
                    }
                    at[a] = spans[a].0;
                }
                break;
            }
        }
        true
    }

    fn add(&mut self, x: SVector<f64, D>, r: f64) {
        let grid = self.grids.iter_mut().find(|g| g.class == class_of(r)).expect("a grid for every class");
        let cell = grid.flat(&std::array::from_fn(|a| grid.cell(&x, a)));
        self.next.push(grid.heads[cell]);
        grid.heads[cell] = self.disks.len() as u32;
        self.disks.push((x, r));
    }
}

/// Positions for disks of species `kinds[i]`, largest first (ties in the given order).
pub(super) fn positions<const D: usize>(
    kinds: &[usize],
    species: &[Species],
    sim_box: &SimBox<D>,
    rng: &mut Xoshiro256PlusPlus,
) -> Result<Vec<SVector<f64, D>>, InitError> {
    place(kinds, species, sim_box, rng).map(|(at, _)| at)
}

/// [`positions`], and how many pairs were tested for overlap.
fn place<const D: usize>(
    kinds: &[usize],
    species: &[Species],
    sim_box: &SimBox<D>,
    rng: &mut Xoshiro256PlusPlus,
) -> Result<(Vec<SVector<f64, D>>, u64), InitError> {
    let mut order: Vec<usize> = (0..kinds.len()).collect();
    order.sort_by(|&a, &b| species[kinds[b]].radius.total_cmp(&species[kinds[a]].radius));
    // The size classes: (binary exponent, largest radius, disks).
    let mut classes: Vec<(u64, f64, usize)> = Vec::new();
    for s in species {
        let class = class_of(s.radius);
        match classes.iter_mut().find(|c| c.0 == class) {
            Some(c) => (c.1, c.2) = (c.1.max(s.radius), c.2 + s.count),
            None => classes.push((class, s.radius, s.count)),
        }
    }
    let grids = classes.into_iter().map(|(class, radius, count)| Grid::new(class, radius, count, sim_box)).collect();
    let mut placed = Placed { sim_box, disks: Vec::with_capacity(kinds.len()), next: Vec::new(), grids, tested: 0 };
    let mut at = vec![SVector::<f64, D>::zeros(); kinds.len()];
    for &i in &order {
        let k = kinds[i];
        let r = species[k].radius;
        let mut found = None;
        for _ in 0..TRIES {
            let mut x = SVector::<f64, D>::zeros();
            for a in 0..D {
                let (lo, hi) = match sim_box.boundary[a] {
                    Boundary::Periodic => (0.0, sim_box.lengths[a]),
                    Boundary::Wall => (r, sim_box.lengths[a] - r),
                };
                x[a] = if hi > lo { rng.random_range(lo..hi) } else { lo };
            }
            if placed.clear(&x, r) {
                found = Some(x);
                break;
            }
        }
        let Some(x) = found else {
            let volume: f64 = placed.disks.iter().map(|&(_, s)| super::ball_volume::<D>(s)).sum();
            return Err(InitError::CannotPlace {
                dimension: D,
                placed: placed.disks.len(),
                requested: kinds.len(),
                species: k,
                radius: r,
                reached: volume / sim_box.volume(),
                requested_eta: super::particle_volume::<D>(species) / sim_box.volume(),
                lattice_fits_up_to: super::lattice_limit::<D>(species),
            });
        };
        placed.add(x, r);
        at[i] = x;
    }
    Ok((at, placed.tested))
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector2;
    use rand::SeedableRng;

    /// The work per disk does not grow with N: at η = 0.3 the pairs tested per disk placed
    /// stay within 10 % from 10⁴ to 4·10⁴ disks (a search over every placed disk tests
    /// N/2 per disk on average: 5 000 to 20 000), and they are a few dozen — for one size
    /// and for a mixture of radii 30 apart.
    #[test]
    fn placement_tests_a_bounded_number_of_pairs_per_disk() {
        let per_disk = |n: usize, mixture: bool| {
            let species = if mixture {
                vec![Species { count: n / 100, radius: 3.0, mass: 1.0 }, Species { count: n, radius: 0.1, mass: 1.0 }]
            } else {
                vec![Species { count: n, radius: 0.5, mass: 1.0 }]
            };
            let area = super::super::particle_volume::<2>(&species) / if mixture { 0.1 } else { 0.3 };
            let l = area.sqrt();
            let sim_box = SimBox { lengths: Vector2::new(l, l), boundary: [Boundary::Periodic; 2] };
            let kinds: Vec<usize> =
                species.iter().enumerate().flat_map(|(k, s)| std::iter::repeat_n(k, s.count)).collect();
            let mut rng = Xoshiro256PlusPlus::seed_from_u64(5);
            let (_, tested) = place(&kinds, &species, &sim_box, &mut rng).expect("dilute");
            tested as f64 / kinds.len() as f64
        };
        for mixture in [false, true] {
            let (small, large) = (per_disk(10_000, mixture), per_disk(40_000, mixture));
            assert!(large < 1.1 * small && large < 100.0, "mixture {mixture}: {small} then {large} pairs per disk");
        }
    }

    /// The grid search gives the positions of the search over every placed disk, bit for
    /// bit, in periodic and walled boxes, for one species and for a mixture.
    #[test]
    fn the_grid_places_as_the_plain_search_does() {
        for boundary in [[Boundary::Periodic; 2], [Boundary::Wall, Boundary::Periodic]] {
            for species in [
                vec![Species { count: 300, radius: 0.5, mass: 1.0 }],
                vec![Species { count: 5, radius: 2.0, mass: 1.0 }, Species { count: 300, radius: 0.2, mass: 1.0 }],
            ] {
                let sim_box = SimBox { lengths: Vector2::new(30.0, 24.0), boundary };
                let kinds: Vec<usize> =
                    species.iter().enumerate().flat_map(|(k, s)| std::iter::repeat_n(k, s.count)).collect();
                let mut rng = Xoshiro256PlusPlus::seed_from_u64(11);
                let fast = positions(&kinds, &species, &sim_box, &mut rng).expect("dilute");
                // The plain search, in the same order.
                let mut rng = Xoshiro256PlusPlus::seed_from_u64(11);
                let mut order: Vec<usize> = (0..kinds.len()).collect();
                order.sort_by(|&a, &b| species[kinds[b]].radius.total_cmp(&species[kinds[a]].radius));
                let mut done: Vec<(SVector<f64, 2>, f64)> = Vec::new();
                let mut slow = vec![SVector::zeros(); kinds.len()];
                for &i in &order {
                    let r = species[kinds[i]].radius;
                    loop {
                        let mut x = SVector::<f64, 2>::zeros();
                        for a in 0..2 {
                            let (lo, hi) = match boundary[a] {
                                Boundary::Periodic => (0.0, sim_box.lengths[a]),
                                Boundary::Wall => (r, sim_box.lengths[a] - r),
                            };
                            x[a] = rng.random_range(lo..hi);
                        }
                        if done.iter().all(|(y, s)| {
                            let d = y - x;
                            (d + sim_box.minimum_image_shift(&d)).norm() >= r + s
                        }) {
                            done.push((x, r));
                            slow[i] = x;
                            break;
                        }
                    }
                }
                assert_eq!(fast, slow, "{boundary:?}, {} species", species.len());
            }
        }
    }
}
