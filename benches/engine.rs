//! Steady-state collisions per second of the engine (setup and warm-up excluded): N = 10³,
//! 10⁴, 10⁵ disks at packing fractions 0.3 and 0.65, periodic box. Each iteration processes
//! events until one more pair collision has happened, so criterion's throughput is in
//! collisions per second.

use collide::engine::init::{Placement, Species, Velocities, box_for_packing_fraction, initial_particles};
use collide::engine::{Boundary, Simulation};
use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use std::time::{Duration, Instant};

fn warmed_up(n: usize, eta: f64) -> Simulation<2> {
    let species = vec![Species { count: n, radius: 0.5, mass: 1.0 }];
    let sim_box = box_for_packing_fraction(&species, eta, [Boundary::Periodic; 2], Placement::Triangular, 1.0);
    let particles = initial_particles(&species, &sim_box, Placement::Triangular, Velocities::Maxwell, 1.0, 1).unwrap();
    let mut sim = Simulation::new(particles, sim_box).unwrap();
    // Two collisions per particle: the lattice melts and the queue reaches its working size.
    while sim.counts().pair < 2 * n as u64 {
        sim.step().unwrap();
    }
    sim
}

fn engine(c: &mut Criterion) {
    let mut group = c.benchmark_group("engine/collisions");
    group.throughput(Throughput::Elements(1));
    for n in [1_000, 10_000, 100_000] {
        for eta in [0.3, 0.65] {
            let mut sim = warmed_up(n, eta);
            group.bench_function(BenchmarkId::new(format!("eta={eta}"), n), |b| {
                b.iter_custom(|iters| {
                    let start = Instant::now();
                    let target = sim.counts().pair + iters;
                    while sim.counts().pair < target {
                        sim.step().unwrap();
                    }
                    start.elapsed()
                })
            });
        }
    }
    group.finish();
}

fn config() -> Criterion {
    Criterion::default().warm_up_time(Duration::from_secs(1)).measurement_time(Duration::from_secs(3)).sample_size(20)
}

criterion_group! { name = benches; config = config(); targets = engine }
criterion_main!(benches);
