//! The hardware's floor: what one collision costs on this machine when nothing but the
//! arithmetic and the memory traffic of a collision is done.
//!
//! How far an event-driven code is from the machine it runs on is measured by a bare kernel:
//! *move two particles, bounce, re-predict both against neighbour lists padded to the SIMD
//! width; no queue, no list upkeep*. This module is that loop, written from the description,
//! for disks and for spheres (`Floor<D>`), so that the floor can be measured on whatever
//! machine the benchmark report runs on and the engine's rate given as a fraction of it — the
//! figure that travels between hours and machines better than a rate (the published figures
//! are in `docs/benchmarks.md`).
//!
//! One step of the floor ([`Floor::collide`]):
//!
//! 1. a particle `i`, drawn uniformly (so that at large N the records come from anywhere in
//!    memory, as the events of a real run do), and its predicted partner `j`;
//! 2. both moved ballistically to the contact predicted for `i`;
//! 3. the bounce: equal masses, the velocities exchanged along the line of centres
//!    (minimum image) when the pair approaches, by a select, not a branch;
//! 4. both re-predicted against their listed neighbours — [`WIDTH`] in 2D (the eight nearest
//!    disks), `2·WIDTH` in 3D (an fcc crystal's twelve nearest spheres and four more) — with
//!    the textbook formula `t = (−b − √(b² − ac))/a` (`b = Δr·Δv`, `a = |Δv|²`,
//!    `c = |Δr|² − σ²`), each row of eight lanes gathered first and computed as vectors, the
//!    earliest taken without branches.
//!
//! [`Floor::run`] draws the particles [`AHEAD`] steps early and can prefetch their data in
//! three stages (what keeps a code from waiting on memory at large N); [`measure`] takes the
//! faster of the loops with and without that.
//!
//! What it leaves out is everything a correct simulation needs beyond that: an event queue
//! (the pair is drawn, not the earliest), list rebuilds (the lists are the nearest
//! particles of the initial lattice, fixed), stale events, exact times (the formula cancels
//! and misjudges grazing pairs; see `quadratic::textbook`), and any check. The trajectories
//! mean nothing; only the cost does. Records hold position, velocity and time in plain
//! arrays, padded to one 64-byte cache line (as the engine's are: at 40 or 56 bytes, some
//! records would straddle two lines); list rows are 32 bytes each, partners 4 bytes and due
//! times 8.

use super::state::{BenchError, initial_state};
use crate::engine::SimBox;
use crate::engine::internals::pages;
use crate::engine::internals::prefetch;
use rand::rngs::Xoshiro256PlusPlus;
use rand::{RngExt, SeedableRng};
use serde::{Deserialize, Serialize};
use std::time::Instant;

/// Neighbours in one list row: one AVX-512 register of f64 (padded rows, so that every
/// prediction is whole vectors).
pub const WIDTH: usize = 8;

/// Rows of neighbours per particle: one in 2D, two in 3D.
pub const fn rows(dimension: usize) -> usize {
    if dimension >= 3 { 2 } else { 1 }
}

/// How many steps ahead [`Floor::run`] draws the particles, and first prefetches their data.
pub const AHEAD: usize = 16;

/// The floor measured for one configuration.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FloorPoint {
    /// 2 (disks) or 3 (spheres).
    pub dimension: usize,
    /// N.
    pub n_particles: usize,
    /// Packing fraction of the initial lattice.
    pub packing_fraction: f64,
    /// Whether this loop prefetched ([`Floor::run`]).
    pub lookahead: bool,
    /// Timed steps (one collision each).
    pub collisions: u64,
    /// Timed wall-clock seconds.
    pub seconds: f64,
    /// Collisions per second.
    pub collisions_per_second: f64,
    /// Nanoseconds per collision.
    pub ns_per_collision: f64,
}

/// A particle of the floor: where it was at `time`, and how it moves (one cache line).
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(64))]
struct Disk<const D: usize> {
    position: [f64; D],
    velocity: [f64; D],
    time: f64,
}

/// The floor's state: particles, their fixed list rows (`rows(D)` consecutive rows a
/// particle), and each particle's predicted partner and the absolute time of that contact.
pub struct Floor<const D: usize> {
    disks: Vec<Disk<D>>,
    lists: Vec<[u32; WIDTH]>,
    partner: Vec<u32>,
    due: Vec<f64>,
    lengths: [f64; D],
    inverse: [f64; D],
    sigma: f64,
}

impl<const D: usize> Floor<D> {
    /// Rows a particle.
    const ROWS: usize = rows(D);

    /// The floor for N particles of diameter 1 at packing fraction `eta`, from the benchmark
    /// report's initial state (`bench::state::initial_state`: a lattice, Maxwell velocities,
    /// kT = 1, periodic).
    pub fn new(n: usize, eta: f64, seed: u64) -> Result<Floor<D>, BenchError> {
        if n <= Self::ROWS * WIDTH {
            return Err(BenchError::Option {
                flag: "n",
                value: n.to_string(),
                allowed: if D == 2 {
                    "the floor needs more than 8 disks (a full row of neighbours)"
                } else {
                    "the floor needs more than 16 spheres (two full rows of neighbours)"
                },
            });
        }
        let (particles, sim_box) = initial_state::<D>(n, eta, seed)?;
        // In 2 MB pages where large, as the engine's arrays (`engine::pages`).
        let disks: Vec<Disk<D>> = pages::collect(particles.iter().map(|p| Disk {
            position: p.position.into(),
            velocity: p.velocity.into(),
            time: 0.0,
        }));
        let lists = pages::moved(nearest(&disks, &sim_box, false));
        let lengths: [f64; D] = sim_box.lengths.into();
        let mut floor = Floor {
            disks,
            lists,
            partner: pages::filled(n, 0),
            due: pages::filled(n, 0.0),
            lengths,
            inverse: lengths.map(|l| 1.0 / l),
            sigma: 1.0,
        };
        for i in 0..n {
            floor.predict(i);
        }
        Ok(floor)
    }

    /// The separation from particle `a` to the nearest image of particle `b` and their
    /// relative velocity, at the later of their two times (returned too).
    #[inline(always)]
    fn relative(&self, a: &Disk<D>, b: &Disk<D>) -> ([f64; D], [f64; D], f64) {
        let t = a.time.max(b.time);
        let mut dr = [0.0; D];
        let mut dv = [0.0; D];
        for k in 0..D {
            let d = (b.position[k] + b.velocity[k] * (t - b.time)) - (a.position[k] + a.velocity[k] * (t - a.time));
            dr[k] = d - self.lengths[k] * (d * self.inverse[k]).round();
            dv[k] = b.velocity[k] - a.velocity[k];
        }
        (dr, dv, t)
    }

    /// The earliest contact of `a` with the eight neighbours of one row (textbook formula,
    /// all lanes, no branch), as an absolute time, and its lane (the first when none is
    /// ahead).
    #[inline(always)]
    fn row_earliest(&self, a: &Disk<D>, row: &[u32; WIDTH]) -> (f64, usize) {
        // Gathered first, lane by lane, so that the arithmetic below runs on whole vectors
        // (with the loads and their bounds checks inside it, it compiled to one lane at a
        // time, each waiting on its square root and division).
        let mut x = [[0.0; WIDTH]; D];
        let mut v = [[0.0; WIDTH]; D];
        let mut tb = [0.0; WIDTH];
        for k in 0..WIDTH {
            let b = &self.disks[row[k] as usize];
            for d in 0..D {
                x[d][k] = b.position[d];
                v[d][k] = b.velocity[d];
            }
            tb[k] = b.time;
        }
        let mut time = [0.0; WIDTH];
        for k in 0..WIDTH {
            let t0 = a.time.max(tb[k]);
            let (mut bb, mut aa, mut cc) = (0.0, 0.0, -self.sigma * self.sigma);
            for d in 0..D {
                let r = (x[d][k] + v[d][k] * (t0 - tb[k])) - (a.position[d] + a.velocity[d] * (t0 - a.time));
                let r = r - self.lengths[d] * (r * self.inverse[d]).round();
                let g = v[d][k] - a.velocity[d];
                bb += r * g;
                aa += g * g;
                cc += r * r;
            }
            let disc = bb * bb - aa * cc;
            let t = t0 + ((-bb - disc.sqrt()) / aa).max(0.0);
            time[k] = if bb < 0.0 && disc > 0.0 { t } else { f64::INFINITY };
        }
        // Pairwise minimum with its lane, in registers.
        let mut lane: [usize; WIDTH] = core::array::from_fn(|k| k);
        let mut width = WIDTH;
        while width > 1 {
            width /= 2;
            for k in 0..width {
                let right = time[k + width] < time[k];
                time[k] = if right { time[k + width] } else { time[k] };
                lane[k] = if right { lane[k + width] } else { lane[k] };
            }
        }
        (time[0], lane[0])
    }

    /// Particle `i`'s earliest contact with a listed neighbour, as an absolute time: its
    /// partner becomes that neighbour (the first when none is ahead), its due time that
    /// contact's.
    #[inline]
    fn predict(&mut self, i: usize) -> f64 {
        let a = self.disks[i];
        let (mut best, mut partner) = (f64::INFINITY, self.lists[i * Self::ROWS][0]);
        for r in 0..Self::ROWS {
            let row = &self.lists[i * Self::ROWS + r];
            let (t, lane) = self.row_earliest(&a, row);
            let earlier = t < best;
            best = if earlier { t } else { best };
            partner = if earlier { row[lane] } else { partner };
        }
        self.partner[i] = partner;
        self.due[i] = best;
        best
    }

    /// Moves particle `i` to time `t` (backwards too: the floor keeps no common clock).
    #[inline(always)]
    fn advance(&mut self, i: usize, t: f64) {
        let d = &mut self.disks[i];
        for k in 0..D {
            d.position[k] += d.velocity[k] * (t - d.time);
        }
        d.time = t;
    }

    /// The elastic bounce of equal masses along the line of centres, when approaching.
    #[inline]
    fn bounce(&mut self, i: usize, j: usize) {
        let (dr, dv, _) = self.relative(&self.disks[i], &self.disks[j]);
        let (mut b, mut r2) = (0.0, 0.0);
        for k in 0..D {
            b += dr[k] * dv[k];
            r2 += dr[k] * dr[k];
        }
        let scale = if b < 0.0 && r2 > 0.0 { b / r2 } else { 0.0 };
        for k in 0..D {
            self.disks[i].velocity[k] += scale * dr[k];
            self.disks[j].velocity[k] -= scale * dr[k];
        }
    }

    /// One collision: particle `i` and its predicted partner moved to their contact,
    /// bounced and re-predicted. (Without a queue the pairs do not come in time order, so a
    /// particle may be moved back, and particles pass through each other: the state soon
    /// means nothing. The arithmetic is branch-free, so its cost does not depend on it.)
    #[inline]
    pub fn collide(&mut self, i: usize) {
        let j = self.partner[i] as usize;
        // At the predicted contact, or where the later of the two is when none was ahead.
        let due = self.due[i];
        let t = if due < f64::INFINITY { due } else { self.disks[i].time.max(self.disks[j].time) };
        self.advance(i, t);
        self.advance(j, t);
        self.bounce(i, j);
        self.predict(i);
        self.predict(j);
    }

    /// `steps` collisions, the particles drawn from `rng`. With `lookahead`, each
    /// particle's data is asked for before its step comes, in three stages as the engine's
    /// lookahead does (its record, list rows, partner and due time [`AHEAD`] steps before;
    /// its partner's record and rows and its neighbours' records half as many before; its
    /// partner's neighbours a quarter): what keeps a code from waiting on memory at large N.
    /// The particles come in the same order either way, drawn `AHEAD` steps early, and the
    /// prefetches change nothing but the timing.
    pub fn run(&mut self, rng: &mut Xoshiro256PlusPlus, steps: u64, lookahead: bool) {
        let n = self.len();
        let mut ring = [0usize; AHEAD];
        for slot in ring.iter_mut() {
            *slot = rng.random_range(0..n);
        }
        for step in 0..steps {
            // The slot read at this step is refilled with the particle of step + AHEAD; slot
            // k + m (mod AHEAD) holds the particle of step + m.
            let k = step as usize % AHEAD;
            let i = ring[k];
            ring[k] = rng.random_range(0..n);
            if lookahead {
                self.prefetch_first(ring[k]);
                self.prefetch_second(ring[(k + AHEAD / 2) % AHEAD]);
                self.prefetch_third(ring[(k + AHEAD / 4) % AHEAD]);
            }
            self.collide(i);
        }
    }

    /// Particle `i`'s rows.
    #[inline(always)]
    fn rows_of(&self, i: usize) -> &[[u32; WIDTH]] {
        &self.lists[i * Self::ROWS..(i + 1) * Self::ROWS]
    }

    #[inline(always)]
    fn prefetch_first(&self, i: usize) {
        prefetch(&self.disks[i]);
        for row in self.rows_of(i) {
            prefetch(row);
        }
        prefetch(&self.partner[i]);
        prefetch(&self.due[i]);
    }

    #[inline(always)]
    fn prefetch_second(&self, i: usize) {
        let j = self.partner[i] as usize;
        prefetch(&self.disks[j]);
        for row in self.rows_of(j) {
            prefetch(row);
        }
        for &m in self.rows_of(i).iter().flatten() {
            prefetch(&self.disks[m as usize]);
        }
    }

    #[inline(always)]
    fn prefetch_third(&self, i: usize) {
        for &m in self.rows_of(self.partner[i] as usize).iter().flatten() {
            prefetch(&self.disks[m as usize]);
        }
    }

    /// The total momentum and kinetic energy (unit masses).
    pub fn momentum_and_energy(&self) -> ([f64; D], f64) {
        let mut p = [0.0; D];
        let mut e = 0.0;
        for d in &self.disks {
            for k in 0..D {
                p[k] += d.velocity[k];
                e += 0.5 * d.velocity[k] * d.velocity[k];
            }
        }
        (p, e)
    }

    /// The number of particles.
    pub fn len(&self) -> usize {
        self.disks.len()
    }

    /// Always false (a floor has more than a row of particles).
    pub fn is_empty(&self) -> bool {
        self.disks.is_empty()
    }
}

/// The `rows(D)·WIDTH` nearest other particles of each (minimum image; ties by index), found
/// through cubic cells at least as wide as the farthest of them in the lattice (or by
/// comparing every pair: `brute`, or a box too small for 3 cells along an axis).
fn nearest<const D: usize>(disks: &[Disk<D>], sim_box: &SimBox<D>, brute: bool) -> Vec<[u32; WIDTH]> {
    let n = disks.len();
    let rows = rows(D);
    let lengths: [f64; D] = sim_box.lengths.into();
    let volume: f64 = lengths.iter().product();
    // 2D, a triangular lattice of spacing s (area √3/2·s² a disk): the eighth neighbour is at
    // √3·s ≈ 1.86·√(area per disk). 3D: the sixteenth is at most the fcc cube edge
    // (4·volume per sphere)^⅓ ≈ 1.59·∛(volume per sphere), and √2 times the spacing of a
    // simple cubic lattice. Cells of 2.2 (2D) or 2.0 (3D) such lengths hold them in the
    // 3^D cells around.
    let width = if D == 2 { 2.2 } else { 2.0 } * (volume / n as f64).powf(1.0 / D as f64);
    let counts: [usize; D] = lengths.map(|l| ((l / width).floor() as usize).max(1));
    let brute = brute || counts.iter().any(|&c| c < 3);
    let coord = |d: &Disk<D>| -> [usize; D] {
        core::array::from_fn(|k| {
            let x = d.position[k].rem_euclid(lengths[k]);
            ((x / lengths[k] * counts[k] as f64) as usize).min(counts[k] - 1)
        })
    };
    let index = |c: [usize; D]| c.iter().zip(&counts).rev().fold(0, |acc, (&x, &m)| acc * m + x);
    let mut cells: Vec<Vec<u32>> = vec![Vec::new(); counts.iter().product()];
    for (i, d) in disks.iter().enumerate() {
        cells[index(coord(d))].push(i as u32);
    }
    let distance = |a: &Disk<D>, b: &Disk<D>| {
        let mut s = 0.0;
        for k in 0..D {
            let d = b.position[k] - a.position[k];
            let d = d - lengths[k] * (d / lengths[k]).round();
            s += d * d;
        }
        s
    };
    let offsets = 3usize.pow(D as u32);
    let mut lists = Vec::with_capacity(n * rows);
    let mut around: Vec<(f64, u32)> = Vec::new();
    for (i, a) in disks.iter().enumerate() {
        around.clear();
        if brute {
            around.extend((0..n as u32).filter(|&j| j as usize != i).map(|j| (distance(a, &disks[j as usize]), j)));
        } else {
            let c = coord(a);
            for o in 0..offsets {
                // Offset o in base 3: −1, 0, +1 along each axis.
                let cell: [usize; D] = core::array::from_fn(|k| {
                    let step = (o / 3usize.pow(k as u32)) % 3;
                    (c[k] + counts[k] + step - 1) % counts[k]
                });
                for &j in &cells[index(cell)] {
                    if j as usize != i {
                        around.push((distance(a, &disks[j as usize]), j));
                    }
                }
            }
        }
        around.sort_by(|p, q| p.0.total_cmp(&q.0).then(p.1.cmp(&q.1)));
        for r in 0..rows {
            lists.push(core::array::from_fn(|k| around[r * WIDTH + k].1));
        }
    }
    lists
}

/// Measures the floor: `warmup` untimed collisions, then `timed` timed ones, without and
/// with the lookahead ([`Floor::run`]), the same particles drawn by a seeded generator
/// either way. The floor is the faster of the two ([`measure`]; the lookahead pays at
/// large N).
pub fn measure_both<const D: usize>(
    n: usize,
    eta: f64,
    warmup: u64,
    timed: u64,
    seed: u64,
) -> Result<[FloorPoint; 2], BenchError> {
    let one = |lookahead| -> Result<FloorPoint, BenchError> {
        let mut floor = Floor::<D>::new(n, eta, seed)?;
        // The draws get a stream of their own (the initial state used `seed`).
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed ^ u64::from_be_bytes(*b"\0\0\0floor"));
        floor.run(&mut rng, warmup, lookahead);
        let start = Instant::now();
        floor.run(&mut rng, timed, lookahead);
        let seconds = start.elapsed().as_secs_f64();
        std::hint::black_box(&floor.disks);
        Ok(FloorPoint {
            dimension: D,
            n_particles: n,
            packing_fraction: eta,
            lookahead,
            collisions: timed,
            seconds,
            collisions_per_second: timed as f64 / seconds,
            ns_per_collision: seconds * 1e9 / timed as f64,
        })
    };
    Ok([one(false)?, one(true)?])
}

/// The floor: the faster of [`measure_both`]'s two loops.
pub fn measure<const D: usize>(
    n: usize,
    eta: f64,
    warmup: u64,
    timed: u64,
    seed: u64,
) -> Result<FloorPoint, BenchError> {
    let [a, b] = measure_both::<D>(n, eta, warmup, timed, seed)?;
    Ok(if b.seconds < a.seconds { b } else { a })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::Boundary;
    use quadratic::{Ball, Contact, textbook};

    /// The 3^D search must give the brute-force rows exactly, and the rows are the nearest:
    /// fewer than a particle's listed count are closer than its farthest listed.
    fn cells_agree_with_every_pair<const D: usize>(n: usize, eta: f64) {
        let floor = Floor::<D>::new(n, eta, 1).unwrap();
        let sim_box = SimBox { lengths: floor.lengths.into(), boundary: [Boundary::Periodic; D] };
        assert_eq!(floor.lists, nearest(&floor.disks, &sim_box, true));
        let d = |i: usize, j: usize| {
            let (dr, _, _) = floor.relative(&floor.disks[i], &floor.disks[j]);
            dr.iter().map(|x| x * x).sum::<f64>().sqrt()
        };
        let listed = rows(D) * WIDTH;
        for i in (0..n).step_by(97) {
            let far = floor.rows_of(i).iter().flatten().map(|&j| d(i, j as usize)).fold(0.0, f64::max);
            let closer = (0..n).filter(|&j| j != i && d(i, j) < far).count();
            assert!(closer < listed, "particle {i}: {closer} nearer than its farthest listed");
        }
    }

    #[test]
    fn cells_find_the_nearest_disks_as_comparing_every_pair_does() {
        // A box of 30 × 34 cells.
        cells_agree_with_every_pair::<2>(5_000, 0.65);
    }

    #[test]
    fn cells_find_the_nearest_spheres_as_comparing_every_pair_does() {
        // Simple cubic (η ≤ 0.5) and fcc starts, 7³ and more cells.
        cells_agree_with_every_pair::<3>(4_000, 0.45);
        cells_agree_with_every_pair::<3>(4_000, 0.6);
    }

    /// How many of the floor's disks have a listed neighbour ahead, after checking that each
    /// disk's prediction is the textbook's earliest contact over its row.
    fn agree_with_the_textbook<const D: usize>(floor: &mut Floor<D>) -> usize {
        let mut ahead = 0;
        for i in 0..floor.len() {
            let t = floor.predict(i);
            let a = floor.disks[i];
            let ball = |d: &Disk<D>, at: [f64; D]| Ball { position: at, velocity: d.velocity, radius: 0.5 };
            let mut best = (f64::INFINITY, u32::MAX);
            let listed: Vec<u32> = floor.rows_of(i).iter().flatten().copied().collect();
            for j in listed {
                let b = floor.disks[j as usize];
                let (dr, _, t0) = floor.relative(&a, &b);
                let t = match textbook::contact_time(&ball(&a, [0.0; D]), &ball(&b, dr)) {
                    Contact::At(t) => t0 + t,
                    Contact::Now => t0,
                    Contact::Never(_) => f64::INFINITY,
                };
                if t < best.0 {
                    best = (t, j);
                }
            }
            if best.0.is_finite() {
                ahead += 1;
                // The two forms round differently (2b and 4ac against b and ac): some ulps.
                assert!((t - best.0).abs() <= 1e-12 * best.0.abs().max(1.0), "disk {i}: {t} against {}", best.0);
                assert_eq!(floor.partner[i], best.1, "disk {i}");
            } else {
                assert_eq!(t, f64::INFINITY, "disk {i}");
            }
        }
        ahead
    }

    #[test]
    fn predictions_are_the_textbook_contact_times() {
        // The lanes compute the seed's formula (b here is half the seed's): the earliest time
        // over the row is the textbook's, and the partner the neighbour it names — on the
        // lattice with Maxwell velocities, where most disks have a contact ahead, and after
        // the floor has scrambled the state (its dynamics are not a gas: see the module).
        let mut floor = Floor::<2>::new(900, 0.65, 3).unwrap();
        let ahead = agree_with_the_textbook(&mut floor);
        assert!(ahead > 600, "only {ahead} of 900 disks had a contact ahead");
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(9);
        for _ in 0..20_000 {
            floor.collide(rng.random_range(0..900));
        }
        agree_with_the_textbook(&mut floor);
        // Spheres: both rows searched, the partner from either.
        let mut floor = Floor::<3>::new(864, 0.6, 3).unwrap();
        let ahead = agree_with_the_textbook(&mut floor);
        assert!(ahead > 600, "only {ahead} of 864 spheres had a contact ahead");
        for _ in 0..20_000 {
            floor.collide(rng.random_range(0..864));
        }
        agree_with_the_textbook(&mut floor);
    }

    #[test]
    fn the_bounce_conserves_momentum_and_energy_and_reverses_approach() {
        // Equal masses exchanging the normal component: momentum and energy to rounding
        // (10⁴ bounces of speeds of order one, each a few ulps), and the pair recedes after.
        let mut floor = Floor::<2>::new(400, 0.65, 5).unwrap();
        let (p0, e0) = floor.momentum_and_energy();
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(11);
        let mut reversed = 0;
        for _ in 0..10_000 {
            let i = rng.random_range(0..400);
            let j = floor.partner[i] as usize;
            // Both at one time first, as `collide` has them (else Δr moves with the velocities).
            let t = floor.disks[i].time.max(floor.disks[j].time);
            floor.advance(i, t);
            floor.advance(j, t);
            let (dr, before, _) = floor.relative(&floor.disks[i], &floor.disks[j]);
            let approaching = dr[0] * before[0] + dr[1] * before[1] < 0.0;
            floor.bounce(i, j);
            let (dr, after, _) = floor.relative(&floor.disks[i], &floor.disks[j]);
            if approaching {
                // Reversed: Δr·Δv' = −Δr·Δv, to the rounding of the products.
                let b = dr[0] * before[0] + dr[1] * before[1];
                let scale = (dr[0] * before[0]).abs() + (dr[1] * before[1]).abs();
                let b_after = dr[0] * after[0] + dr[1] * after[1];
                assert!((b_after + b).abs() <= 1e-13 * scale, "{i} and {j}: {b} → {b_after}");
                reversed += 1;
            }
            floor.collide(i);
        }
        let (p, e) = floor.momentum_and_energy();
        assert!((p[0] - p0[0]).abs() < 1e-10 && (p[1] - p0[1]).abs() < 1e-10, "{p:?} against {p0:?}");
        assert!((e - e0).abs() < 1e-10 * e0, "{e} against {e0}");
        assert!(reversed > 1000, "only {reversed} approaching pairs");
    }

    #[test]
    fn the_same_seed_gives_the_same_state() {
        let run = || {
            let mut floor = Floor::<2>::new(300, 0.65, 2).unwrap();
            let mut rng = Xoshiro256PlusPlus::seed_from_u64(4);
            for _ in 0..5_000 {
                floor.collide(rng.random_range(0..300));
            }
            floor
                .disks
                .iter()
                .flat_map(|d| [d.position[0], d.position[1], d.velocity[0]])
                .map(f64::to_bits)
                .collect::<Vec<_>>()
        };
        assert_eq!(run(), run());
    }

    #[test]
    fn the_lookahead_changes_nothing_but_the_timing() {
        let run = |lookahead| {
            let mut floor = Floor::<2>::new(2_000, 0.65, 6).unwrap();
            floor.run(&mut Xoshiro256PlusPlus::seed_from_u64(8), 30_000, lookahead);
            (floor.disks, floor.partner)
        };
        let (with, without) = (run(true), run(false));
        assert!(with.0 == without.0 && with.1 == without.1);
        // And the steps happened: the state moved from the lattice.
        assert_ne!(with.0, Floor::<2>::new(2_000, 0.65, 6).unwrap().disks);
    }

    #[test]
    fn too_few_disks_are_refused() {
        assert!(Floor::<2>::new(8, 0.65, 1).is_err());
        assert!(Floor::<3>::new(16, 0.45, 1).is_err());
        assert!(Floor::<3>::new(27, 0.45, 1).is_ok());
    }
}
