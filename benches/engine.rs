//! Steady-state collisions per second of the engine (setup and warm-up excluded): N = 10³,
//! 10⁴, 10⁵ disks at packing fractions 0.3 and 0.65 (`engine/collisions`) and spheres at 0.3
//! and 0.45 (`engine/collisions_3d`), periodic box, from the benchmark report's lattice
//! starts. Each iteration processes events until one more pair collision has happened, so
//! criterion's throughput is in collisions per second.
//!
//! `engine/floor` times the hardware's floor (`collide::bench::floor`: two particles moved,
//! bounced and re-predicted against fixed neighbours — eight disks, or sixteen spheres — no
//! queue) at N = 10⁴ and 10⁵, disks at η = 0.65 and spheres at 0.45, per collision, without
//! and with its lookahead: what the engine's rate is a fraction of.
//!
//! `engine/parts` times pieces of one collision's work at N = 10⁴, η = 0.65, to show where
//! the time goes: `bracket_pair` over every pair of a warmed-up state closer than 1.8σ (per
//! pair); `bracket_neighbours`, the batch version the engine runs, over every particle's
//! cell neighbours (per particle, i.e. per prediction); a search's short last chunk, each
//! particle's first four neighbours, bracketed at the full width and at half of it
//! (`chunk_of_four`, per particle); and replacing the earliest event of
//! a queue of 10⁴ by a later one, with either structure (per update, as after every
//! collision; in the tree the root owner's is the longest walk).

use collide::bench::floor::Floor;
use collide::engine::init::{Placement, Species, Velocities, box_for_packing_fraction, initial_particles};
use collide::engine::internals::{
    EventQueue, HALF, LANES, Lanes, PairBracket, QueueKind, bracket_half, bracket_neighbours, bracket_pair,
    pair_positions,
};
use collide::engine::{Boundary, Particle, Radii, SimBox, Simulation};
use collide::engine::{Event, EventKind};
use criterion::measurement::WallTime;
use criterion::{BenchmarkGroup, BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use rand::rngs::Xoshiro256PlusPlus;
use rand::{RngExt, SeedableRng};
use std::hint::black_box;
use std::time::{Duration, Instant};

fn warmed_up(n: usize, eta: f64) -> Simulation<2> {
    let species = vec![Species { count: n, radius: 0.5, mass: 1.0 }];
    let sim_box = box_for_packing_fraction(&species, eta, [Boundary::Periodic; 2], Placement::Triangular, None);
    let particles = initial_particles(&species, &sim_box, Placement::Triangular, Velocities::Maxwell, 1.0, 1).unwrap();
    relaxed(Simulation::new(particles, sim_box).unwrap(), n)
}

/// Spheres from the benchmark report's start (`collide::bench::state::initial_state`).
fn warmed_up_3d(n: usize, eta: f64) -> Simulation<3> {
    let (particles, sim_box) = collide::bench::state::initial_state::<3>(n, eta, 1).unwrap();
    relaxed(Simulation::new(particles, sim_box).unwrap(), n)
}

fn relaxed<const D: usize>(mut sim: Simulation<D>, n: usize) -> Simulation<D> {
    // As `collide bench` does: the lattice relaxes (see `collide::bench::WARMUP`) — when
    // timing. Criterion's `--test` runs each bench once as a smoke test (CI does), which
    // times nothing: the lattice start serves, and the 10⁵-particle states do not spend
    // half a minute relaxing for one iteration.
    if std::env::args().any(|arg| arg == "--test") {
        return sim;
    }
    while sim.counts().pair < collide::bench::WARMUP * n as u64 {
        sim.step().unwrap();
    }
    sim
}

/// Iterations of one more pair collision each.
fn collisions<const D: usize>(sim: &mut Simulation<D>, iters: u64) -> Duration {
    let start = Instant::now();
    let target = sim.counts().pair + iters;
    while sim.counts().pair < target {
        sim.step().unwrap();
    }
    start.elapsed()
}

fn engine(c: &mut Criterion) {
    let mut group = c.benchmark_group("engine/collisions");
    group.throughput(Throughput::Elements(1));
    // Each state is made when its bench first runs: a filtered run (`cargo bench --bench
    // engine -- 3d/chunk_of_four`) does not wait for the states of the benches it skips.
    for n in [1_000, 10_000, 100_000] {
        for eta in [0.3, 0.65] {
            let mut sim = None;
            group.bench_function(BenchmarkId::new(format!("eta={eta}"), n), |b| {
                let sim = sim.get_or_insert_with(|| warmed_up(n, eta));
                b.iter_custom(|iters| collisions(sim, iters))
            });
        }
    }
    group.finish();
    let mut group = c.benchmark_group("engine/collisions_3d");
    group.throughput(Throughput::Elements(1));
    for n in [1_000, 10_000, 100_000] {
        for eta in [0.3, 0.45] {
            let mut sim = None;
            group.bench_function(BenchmarkId::new(format!("eta={eta}"), n), |b| {
                let sim = sim.get_or_insert_with(|| warmed_up_3d(n, eta));
                b.iter_custom(|iters| collisions(sim, iters))
            });
        }
    }
    group.finish();
}

/// The hardware's floor (`collide::bench::floor`) at η = 0.65: per collision, for the
/// engine's rate as a fraction of it.
/// `iters` steps of the floor, timed.
fn floor_steps<const D: usize>(
    floor: &mut Floor<D>,
    rng: &mut Xoshiro256PlusPlus,
    iters: u64,
    lookahead: bool,
) -> Duration {
    let start = Instant::now();
    floor.run(rng, iters, lookahead);
    start.elapsed()
}

fn floor(c: &mut Criterion) {
    let mut group = c.benchmark_group("engine/floor");
    group.throughput(Throughput::Elements(1));
    for n in [10_000, 100_000] {
        // Both loops, as `collide bench` times them (it reports the faster).
        for lookahead in [false, true] {
            let loop_name = if lookahead { "lookahead" } else { "plain" };
            let mut rng = Xoshiro256PlusPlus::seed_from_u64(2);
            let mut disks = None;
            group.bench_function(BenchmarkId::new(format!("eta=0.65/{loop_name}"), n), |b| {
                let disks = disks.get_or_insert_with(|| Floor::<2>::new(n, 0.65, 1).unwrap());
                b.iter_custom(|iters| floor_steps(disks, &mut rng, iters, lookahead))
            });
            let mut spheres = None;
            group.bench_function(BenchmarkId::new(format!("3d/eta=0.45/{loop_name}"), n), |b| {
                let spheres = spheres.get_or_insert_with(|| Floor::<3>::new(n, 0.45, 1).unwrap());
                b.iter_custom(|iters| floor_steps(spheres, &mut rng, iters, lookahead))
            });
        }
    }
    group.finish();
}

fn parts(c: &mut Criterion) {
    let mut group = c.benchmark_group("engine/parts");
    let sim = warmed_up(10_000, 0.65);
    let (ps, sim_box, now) = (sim.particles(), sim.sim_box(), sim.time());
    let mut pairs = Vec::new();
    for i in 0..ps.len() {
        for j in i + 1..ps.len() {
            let (a, b) = pair_positions(&ps[i], &ps[j], sim_box, now);
            if (b - a).norm() < 1.8 {
                pairs.push((i, j));
            }
        }
    }
    group.throughput(Throughput::Elements(pairs.len() as u64));
    group.bench_function("bracket_pair", |b| {
        b.iter(|| {
            let mut n = 0.0;
            for &(i, j) in &pairs {
                if let PairBracket::Between { lo, .. } =
                    bracket_pair(&ps[i], &ps[j], sim_box, black_box(now), &[false; 2], f64::INFINITY, Radii::Fixed)
                {
                    n += lo;
                }
            }
            n
        })
    });
    // Each particle's neighbours within 1.8σ (the pairs above), in chunks of LANES.
    let mut near: Vec<Vec<u32>> = vec![Vec::new(); ps.len()];
    for &(i, j) in &pairs {
        near[i].push(j as u32);
        near[j].push(i as u32);
    }
    group.throughput(Throughput::Elements(ps.len() as u64));
    group.bench_function("bracket_neighbours", |b| {
        b.iter(|| {
            let mut n = 0.0;
            for (i, js) in near.iter().enumerate() {
                for chunk in js.chunks(LANES) {
                    let (mut lo, mut hi) = ([0.0; LANES], [0.0; LANES]);
                    let mut js = [i as u32; LANES];
                    js[..chunk.len()].copy_from_slice(chunk);
                    let mut lanes = Lanes::default();
                    bracket_neighbours(ps, i, &js, chunk.len(), sim_box, black_box(now), &mut lo, &mut hi, &mut lanes);
                    n += hi[0];
                }
            }
            n
        })
    });
    chunks_of_four(&mut group, ps, sim_box, now, &near, "");
    let spheres = warmed_up_3d(4000, 0.45);
    let (ps, sim_box, now) = (spheres.particles(), spheres.sim_box(), spheres.time());
    let mut near: Vec<Vec<u32>> = vec![Vec::new(); ps.len()];
    for i in 0..ps.len() {
        for j in i + 1..ps.len() {
            let (a, b) = pair_positions(&ps[i], &ps[j], sim_box, now);
            // About the twelve neighbours of a sphere's list at η = 0.45.
            if (b - a).norm() < 1.55 {
                near[i].push(j as u32);
                near[j].push(i as u32);
            }
        }
    }
    chunks_of_four(&mut group, ps, sim_box, now, &near, "3d/");
    // A queue of 10⁴ events; each update moves the earliest one later by a pseudo-random step.
    let wall = |time| Event { time, kind: EventKind::Wall { axis: 0, upper: true } };
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(3);
    let mut next = move || rng.random_range(0.0..100_000.0f64).floor();
    let start: Vec<Event> = (0..10_000).map(|_| wall(next())).collect();
    group.throughput(Throughput::Elements(1));
    for (name, kind) in [("queue_set_first/tree", QueueKind::Tree), ("queue_set_first/calendar", QueueKind::Calendar)] {
        let mut queue = EventQueue::new(start.clone(), kind);
        group.bench_function(name, |b| {
            b.iter(|| {
                let (owner, first) = queue.first();
                let t = first.time + next();
                queue.set(owner, wall(t));
            })
        });
    }
    group.finish();
}

/// A search's short last chunk: each particle's first HALF neighbours, at the full width
/// and at half of it (what the engine does where vectors hold four f64) — unscreened
/// (bound +∞), and screened against the smallest upper end over all the particle's
/// neighbours (the bound a search has reached by its last chunk, or below it).
fn chunks_of_four<const D: usize>(
    group: &mut BenchmarkGroup<'_, WallTime>,
    ps: &[Particle<D>],
    sim_box: &SimBox<D>,
    now: f64,
    near: &[Vec<u32>],
    prefix: &str,
) {
    let reached: Vec<f64> = near
        .iter()
        .enumerate()
        .map(|(i, js)| {
            let mut bound = f64::INFINITY;
            for chunk in js.chunks(LANES) {
                let (mut lo, mut hi) = ([0.0; LANES], [0.0; LANES]);
                let mut full = [i as u32; LANES];
                full[..chunk.len()].copy_from_slice(chunk);
                let m = bracket_neighbours(
                    ps,
                    i,
                    &full,
                    chunk.len(),
                    sim_box,
                    now,
                    &mut lo,
                    &mut hi,
                    &mut Lanes::default(),
                );
                bound = bound.min(m);
            }
            bound
        })
        .collect();
    let unbounded = vec![f64::INFINITY; ps.len()];
    for (name, half, bounds) in [
        ("chunk_of_four/full_width", false, &unbounded),
        ("chunk_of_four/half_width", true, &unbounded),
        ("chunk_of_four/half_width_screened", true, &reached),
    ] {
        group.bench_function(format!("{prefix}{name}"), |b| {
            b.iter(|| {
                let mut n = 0.0;
                for (i, js) in near.iter().enumerate() {
                    let len = js.len().min(HALF);
                    let (mut lo, mut hi) = ([0.0; LANES], [0.0; LANES]);
                    let mut full = [i as u32; LANES];
                    full[..len].copy_from_slice(&js[..len]);
                    let mut lanes = Lanes::default();
                    let m = if half {
                        let short = full[..HALF].try_into().expect("HALF wide");
                        let bound = black_box(bounds[i]);
                        bracket_half(ps, i, short, len, sim_box, black_box(now), bound, &mut lo, &mut hi, &mut lanes)
                    } else {
                        bracket_neighbours(ps, i, &full, len, sim_box, black_box(now), &mut lo, &mut hi, &mut lanes)
                    };
                    n += m;
                }
                n
            })
        });
    }
}

fn config() -> Criterion {
    Criterion::default().warm_up_time(Duration::from_secs(1)).measurement_time(Duration::from_secs(3)).sample_size(20)
}

criterion_group! { name = benches; config = config(); targets = engine, floor, parts }
criterion_main!(benches);
