//! What the observables cost at their default sampling rates: 10⁴ disks at η = 0.3 and 10⁴
//! spheres at 0.45 (periodic, the benchmark report's starts, warmed up). For each observable,
//! `observers/<name>` times its sample at each due instant (the events between them run
//! untimed, as a run runs them) and `observers/engine_<name>` the events of one sampling
//! interval: the first over the second is the observable's cost against the engine's time at
//! its default rate (docs/configuration.md's figures: `cargo bench --bench observers`).

use collide::engine::Simulation;
use collide::observe::{Observable, Selection};
use criterion::{Criterion, criterion_group, criterion_main};
use std::time::{Duration, Instant};

fn warmed_up<const D: usize>(n: usize, eta: f64) -> Simulation<D> {
    let (particles, sim_box) = collide::bench::state::initial_state::<D>(n, eta, 1).unwrap();
    let mut sim = Simulation::new(particles, sim_box).unwrap();
    while sim.counts().pair < collide::bench::WARMUP * n as u64 {
        sim.step().unwrap();
    }
    sim
}

/// `iters` sampling intervals of `observable`: the events up to its next due instant (not
/// timed), then its sample (timed).
fn samples<const D: usize>(sim: &mut Simulation<D>, observable: &mut Observable, iters: u64) -> Duration {
    let mut total = Duration::ZERO;
    for _ in 0..iters {
        let due = observable.due().expect("samples at its own instants");
        while sim.quiet_until() < due {
            sim.step().unwrap();
        }
        let start = Instant::now();
        observable.sample(sim, due);
        total += start.elapsed();
    }
    total
}

fn selections() -> Vec<(&'static str, Selection)> {
    let table = |name: &str| -> Selection { toml::from_str(&format!("[{name}]\n")).unwrap() };
    ["rdf", "msd", "vacf", "sk", "bond_order"].into_iter().map(|n| (n, table(n))).collect()
}

fn observers<const D: usize>(c: &mut Criterion, label: &str, eta: f64) {
    let mut group = c.benchmark_group(format!("observers/{label}"));
    let mut sim = warmed_up::<D>(10_000, eta);
    for (name, selection) in selections() {
        if D == 3 && name == "bond_order" {
            continue;
        }
        let mut observable = selection.start(&sim).remove(0);
        group.bench_function(name, |b| b.iter_custom(|iters| samples(&mut sim, &mut observable, iters)));
        let mut observable = selection.start(&sim).remove(0);
        group.bench_function(format!("engine_{name}"), |b| {
            b.iter_custom(|iters| {
                // The engine alone over the same stretches: time only the events.
                let mut total = Duration::ZERO;
                for _ in 0..iters {
                    let due = observable.due().expect("samples at its own instants");
                    let start = Instant::now();
                    while sim.quiet_until() < due {
                        sim.step().unwrap();
                    }
                    total += start.elapsed();
                    observable.sample(&sim, due);
                }
                total
            })
        });
    }
    group.finish();
}

fn all(c: &mut Criterion) {
    observers::<2>(c, "disks_eta0.3", 0.3);
    observers::<3>(c, "spheres_eta0.45", 0.45);
}

fn config() -> Criterion {
    Criterion::default().warm_up_time(Duration::from_secs(1)).measurement_time(Duration::from_secs(4)).sample_size(10)
}

criterion_group! { name = benches; config = config(); targets = all }
criterion_main!(benches);
