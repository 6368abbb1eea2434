//! The collision kernels against the seed's textbook formula.
//!
//! * `contact/realistic`: every pair closer than 2.5σ in a dense hard-disk fluid
//!   (η = 0.65, jittered triangular lattice, Maxwell velocities) — what an event-driven code
//!   predicts all day. Mix: about half receding, the rest hits or misses.
//! * `contact/hard`: near-contact gaps of a few ulps, grazing at 10⁶σ, neighbours at 10⁹.
//! * `contact/growing`: the realistic pairs with every radius growing at 0.1 of itself per
//!   unit time (what a compression predicts).
//! * `roots/realistic` and `roots/hard`: random moderate coefficients; near-double roots and
//!   extreme scales.
//! * `contact/pin`: the contacts among the realistic pairs; `narrow` is
//!   `quadratic::narrow_contact` from the middle of each bracket (one ulp), `narrow-and-time`
//!   also settles which of the two doubles (what the engine does when a bracket's ends round
//!   to two absolute times), `robust` the exact root it replaces.
//!
//! `robust` is `quadratic::contact_time` / `quadratic::solve`, `textbook` the seed's formula,
//! `exact-path` the expansion fallback alone (what every pair would cost without the filter),
//! `bracket` the certified interval `quadratic::contact_bracket` that the engine computes for
//! every neighbour before it evaluates exactly the one or two pairs that can come first,
//! `brackets-8` the same intervals from the branch-free batch kernel
//! `quadratic::contact_brackets`, eight pairs per call (what the engine runs).
//!
//! Reported per batch; divide by the batch size (printed as throughput) for the cost per call.

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use quadratic::{
    Ball, BallLanes, Bracket, contact_bracket, contact_brackets, contact_time, contact_time_exact_path,
    contact_time_growing, contact_time_growing_exact_path, narrow_contact, solve, textbook,
};
use rand::rngs::Xoshiro256PlusPlus;
use rand::{RngExt, SeedableRng};
use rand_distr::{Distribution, StandardNormal};
use std::hint::black_box;
use std::time::Duration;

type Pair = (Ball<2>, Ball<2>);

/// All pairs within 2.5σ of a jittered triangular lattice at packing fraction η, σ = 1.
fn dense_fluid_pairs(eta: f64, side: usize, seed: u64) -> Vec<Pair> {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    // Triangular lattice: area per disk (√3/2)·a² = π/(4η).
    let a = (std::f64::consts::PI / (2.0 * 3f64.sqrt() * eta)).sqrt();
    let jitter = (a - 1.0) / 2.0;
    let mut disks = Vec::new();
    for row in 0..side {
        for col in 0..side {
            let x = (col as f64 + 0.5 * (row % 2) as f64) * a + 10.0;
            let y = row as f64 * a * 3f64.sqrt() / 2.0 + 10.0;
            let (dx, dy): (f64, f64) = (rng.random_range(-jitter..jitter), rng.random_range(-jitter..jitter));
            let v = [StandardNormal.sample(&mut rng), StandardNormal.sample(&mut rng)];
            disks.push(Ball { position: [x + dx * 0.7, y + dy * 0.7], velocity: v, radius: 0.5 });
        }
    }
    let mut pairs = Vec::new();
    for i in 0..disks.len() {
        for j in i + 1..disks.len() {
            let (p, q) = (disks[i].position, disks[j].position);
            if (p[0] - q[0]).hypot(p[1] - q[1]) < 2.5 {
                pairs.push((disks[i], disks[j]));
            }
        }
    }
    pairs
}

fn hard_pairs(n: usize, seed: u64) -> Vec<Pair> {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    let ball = |position, velocity| Ball { position, velocity, radius: 0.5 };
    (0..n)
        .map(|i| {
            let th: f64 = rng.random_range(0.0..std::f64::consts::TAU);
            let k: i64 = rng.random_range(-4..=4);
            let nudge = |x: f64| f64::from_bits((x.to_bits() as i64 + k) as u64);
            match i % 3 {
                // Gap or overlap of a few ulps, approaching at a random angle.
                0 => {
                    (ball([0.0, 0.0], [0.0, 0.0]), ball([nudge(th.cos()), th.sin()], [-th.sin().abs() - 0.1, th.cos()]))
                }
                // Grazing at 10⁶ diameters, impact parameter σ ± a few ulps.
                1 => (ball([0.0, 0.0], [0.0, 0.0]), ball([1e6, nudge(1.0)], [-1.0, 0.0])),
                // Neighbours at 10⁹.
                _ => {
                    let base = [1e9 * th.cos(), 1e9 * th.sin()];
                    (ball(base, [0.0, 0.0]), ball([base[0] + 1.5, base[1] + 0.3], [-1.0, 0.1]))
                }
            }
        })
        .collect()
}

fn contact(c: &mut Criterion) {
    let realistic = dense_fluid_pairs(0.65, 40, 1);
    let hard = hard_pairs(3000, 2);
    for (name, pairs) in [("contact/realistic", &realistic), ("contact/hard", &hard)] {
        let mut group = c.benchmark_group(name);
        group.throughput(Throughput::Elements(pairs.len() as u64));
        group.bench_function("robust", |b| {
            b.iter(|| {
                let mut n = 0.0;
                for (p, q) in pairs.iter() {
                    n += contact_time(black_box(p), black_box(q)).unwrap().time().unwrap_or(-1.0);
                }
                n
            })
        });
        group.bench_function("textbook", |b| {
            b.iter(|| {
                let mut n = 0.0;
                for (p, q) in pairs.iter() {
                    n += textbook::contact_time(black_box(p), black_box(q)).time().unwrap_or(-1.0);
                }
                n
            })
        });
        group.bench_function("bracket", |b| {
            b.iter(|| {
                let mut n = 0.0;
                for (p, q) in pairs.iter() {
                    n += match contact_bracket(black_box(p), black_box(q), f64::INFINITY) {
                        Bracket::Between { lo, .. } => lo,
                        Bracket::Known(c) => c.time().unwrap_or(-1.0),
                        Bracket::Beyond => -2.0,
                    };
                }
                n
            })
        });
        // The pairs in lanes of eight (the last lanes padded with copies of the first pair).
        let lanes: Vec<(BallLanes<2, 8>, BallLanes<2, 8>)> = pairs
            .chunks(8)
            .map(|chunk| {
                let (mut first, mut second) = (BallLanes::default(), BallLanes::default());
                for k in 0..8 {
                    let (p, q) = chunk.get(k).unwrap_or(&chunk[0]);
                    first.set(k, p);
                    second.set(k, q);
                }
                (first, second)
            })
            .collect();
        group.bench_function("brackets-8", |b| {
            b.iter(|| {
                let mut n = 0.0;
                for (first, second) in &lanes {
                    let (mut lo, mut hi) = ([0.0; 8], [0.0; 8]);
                    contact_brackets(black_box(first), black_box(second), &mut lo, &mut hi);
                    n += lo.iter().sum::<f64>();
                }
                n
            })
        });
        group.bench_function("exact-path", |b| {
            b.iter(|| {
                let mut n = 0.0;
                for (p, q) in pairs.iter() {
                    n += contact_time_exact_path(black_box(p), black_box(q)).time().unwrap_or(-1.0);
                }
                n
            })
        });
        group.finish();
    }
    // What the engine does with a candidate whose bracket's ends round to two absolute times:
    // the contacts among the realistic pairs, pinned to one ulp from the middle of their
    // brackets (and settled exactly), against the exact root.
    let contacts: Vec<(Ball<2>, Ball<2>, f64)> = realistic
        .iter()
        .filter_map(|(p, q)| match contact_bracket(p, q, f64::INFINITY) {
            Bracket::Between { lo, hi } => Some((*p, *q, lo + 0.5 * (hi - lo))),
            _ => None,
        })
        .collect();
    let mut group = c.benchmark_group("contact/pin");
    group.throughput(Throughput::Elements(contacts.len() as u64));
    group.bench_function("narrow", |b| {
        b.iter(|| {
            let mut n = 0.0;
            for (p, q, guess) in &contacts {
                n += narrow_contact(black_box(p), black_box(q), *guess).map_or(-1.0, |n| n.lo());
            }
            n
        })
    });
    group.bench_function("narrow-and-time", |b| {
        b.iter(|| {
            let mut n = 0.0;
            for (p, q, guess) in &contacts {
                n += narrow_contact(black_box(p), black_box(q), *guess).and_then(|n| n.time()).unwrap_or(-1.0);
            }
            n
        })
    });
    group.bench_function("robust", |b| {
        b.iter(|| {
            let mut n = 0.0;
            for (p, q, _) in &contacts {
                n += contact_time(black_box(p), black_box(q)).unwrap().time().unwrap_or(-1.0);
            }
            n
        })
    });
    group.finish();
}

/// `contact/growing`: the realistic pairs again, every radius growing at `rate` of itself per
/// unit time (a compression's neighbours), through `quadratic::contact_time_growing` (its
/// filter), its exact path alone, and the textbook growing formula.
fn growing(c: &mut Criterion) {
    let realistic = dense_fluid_pairs(0.65, 40, 1);
    let mut group = c.benchmark_group("contact/growing");
    group.throughput(Throughput::Elements(realistic.len() as u64));
    let rates = |p: &Ball<2>, q: &Ball<2>| [0.1 * p.radius, 0.1 * q.radius];
    group.bench_function("robust", |b| {
        b.iter(|| {
            let mut n = 0.0;
            for (p, q) in realistic.iter() {
                let g = rates(p, q);
                n += contact_time_growing(black_box(p), black_box(q), g).unwrap().time().unwrap_or(-1.0);
            }
            n
        })
    });
    group.bench_function("exact-path", |b| {
        b.iter(|| {
            let mut n = 0.0;
            for (p, q) in realistic.iter() {
                let g = rates(p, q);
                n += contact_time_growing_exact_path(black_box(p), black_box(q), g).time().unwrap_or(-1.0);
            }
            n
        })
    });
    group.bench_function("textbook", |b| {
        b.iter(|| {
            let mut n = 0.0;
            for (p, q) in realistic.iter() {
                let g = rates(p, q);
                n += textbook::contact_time_growing(black_box(p), black_box(q), g).time().unwrap_or(-1.0);
            }
            n
        })
    });
    group.finish();
}

fn roots(c: &mut Criterion) {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(3);
    let realistic: Vec<(f64, f64, f64)> = (0..3000)
        .map(|_| (rng.random_range(0.1..10.0), rng.random_range(-10.0..10.0), rng.random_range(-10.0..10.0)))
        .collect();
    let hard: Vec<(f64, f64, f64)> = (0..3000)
        .map(|i| {
            let a: f64 = rng.random_range(1.0..2.0);
            let b: f64 = rng.random_range(1.0..2.0);
            match i % 3 {
                0 => (a, b, f64::from_bits((b * b / (4.0 * a)).to_bits() + (i % 5) as u64)), // near-double
                1 => (a * 1e300, b * 1e300, -a * 1e300),                                     // overflowing b²
                _ => (a * 1e-300, b, a * 1e-300),                                            // b² ≫ |4ac|
            }
        })
        .collect();
    for (name, cases) in [("roots/realistic", &realistic), ("roots/hard", &hard)] {
        let mut group = c.benchmark_group(name);
        group.throughput(Throughput::Elements(cases.len() as u64));
        group.bench_function("robust", |b| {
            b.iter(|| cases.iter().map(|&(a, b, c)| solve(black_box(a), b, c).unwrap().as_vec().len()).sum::<usize>())
        });
        group.bench_function("textbook", |b| {
            b.iter(|| cases.iter().map(|&(a, b, c)| textbook::solve(black_box(a), b, c).as_vec().len()).sum::<usize>())
        });
        group.finish();
    }
}

fn config() -> Criterion {
    // Short, many-sample runs: the machine is shared and noisy, medians are what we report.
    Criterion::default().warm_up_time(Duration::from_secs(1)).measurement_time(Duration::from_secs(3)).sample_size(40)
}

criterion_group! { name = benches; config = config(); targets = contact, growing, roots }
criterion_main!(benches);
