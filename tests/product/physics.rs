//! Conservation laws, estimator identities and reproducibility of whole runs.
//! Fixed seeds throughout; every tolerance says where it comes from.

use collide::engine::{Boundary, Outcome, Particle, SimBox, Simulation};
use collide::observe::block_error;
use collide::run::{Checkpoint, Config, Discard, Run, Sink, Summary};
use nalgebra::Vector2;
use std::sync::atomic::{AtomicBool, Ordering};

const EPS: f64 = f64::EPSILON;

fn config(text: &str) -> Config {
    Config::parse(text, "test").unwrap()
}

fn run_to_end(mut run: Run<2>) -> (Run<2>, Summary) {
    let Ok(_) = run.complete(&mut Discard);
    assert!(run.done(), "events keep coming");
    // The wall-clock fields are the only ones a rerun may change.
    let summary = reproducible(run.summary());
    (run, summary)
}

/// Equilibrates a run (its production starts, nothing of it is run).
fn equilibrated(config: Config) -> Run<2> {
    let mut run = Run::new(config).unwrap();
    let Ok(_) = run.equilibrate(&mut Discard);
    run
}

fn periodic(n: usize, eta: f64, collisions: u64, seed: u64) -> Config {
    config(&format!(
        "seed = {seed}\n[box]\npacking_fraction = {eta}\nboundary = \"periodic\"\n[[species]]\ncount = {n}\nradius = 0.5\nmass = 1.0\n\
         [init]\nplacement = \"triangular\"\nvelocities = \"maxwell\"\nkT = 1.0\n[equilibration]\ncollisions = 20000\n\
         [run]\ncollisions = {collisions}\nsample_interval = 1.0\n"
    ))
}

/// Over 10⁶ collisions the kinetic energy and the momentum drift only by rounding.
///
/// Each collision rounds the pair's new velocities, changing its energy by at most a few ε
/// of the pair's energy (≤ K); the errors are independent, so the total drifts like a random
/// walk: |ΔK|/K ≤ 4ε·√M is conservative. Likewise |ΔP| ≤ 4ε·√M·Σm|v|. The overlap audit
/// bound: positions of magnitude |r| carry a rounding of ~ε|r| each, so two touching disks
/// can overlap by a few ε·max|r|; 16ε·max|r|/σ covers it.
#[test]
fn energy_momentum_and_overlaps_over_a_million_collisions() {
    let run = equilibrated(periodic(400, 0.5, 1_000_000, 7));
    let (p0, k0) = (run.sim.momentum(), run.sim.kinetic_energy());
    let (run, summary) = run_to_end(run);
    let m = summary.collisions as f64;
    let drift = ((run.sim.kinetic_energy() - k0) / k0).abs();
    eprintln!("10⁶ collisions: |ΔK|/K = {drift:e}, max overlap {:e}", summary.max_overlap.fraction);
    assert!(drift <= 4.0 * EPS * m.sqrt(), "energy drift {drift:e} > {:e}", 4.0 * EPS * m.sqrt());
    let scale: f64 = run.sim.particles().iter().map(|p| p.mass * p.velocity.norm()).sum();
    let dp = (run.sim.momentum() - p0).norm();
    assert!(dp <= 4.0 * EPS * m.sqrt() * scale, "momentum drift {dp:e}");
    let rmax = run.sim.particles().iter().map(|p| p.position_at(run.sim.time()).abs().max()).fold(0.0, f64::max);
    let tolerance = 16.0 * EPS * rmax / 1.0;
    assert!(summary.max_overlap.fraction <= tolerance, "overlap {:e} > {tolerance:e}", summary.max_overlap.fraction);
    assert_eq!(summary.collisions, 1_000_000);
}

/// The same configuration and seed give bit-identical results; another seed does not.
#[test]
fn same_seed_same_bits() {
    let a = run_to_end(equilibrated(periodic(200, 0.6, 50_000, 3)));
    let b = run_to_end(equilibrated(periodic(200, 0.6, 50_000, 3)));
    assert_eq!(a.1, b.1);
    assert_eq!(a.0.sim.particles(), b.0.sim.particles());
    let c = run_to_end(equilibrated(periodic(200, 0.6, 50_000, 4)));
    assert_ne!(a.1.pressure_virial, c.1.pressure_virial);
}

/// A run saved to a checkpoint (through its JSON text) and resumed ends bit-identically to
/// one never interrupted.
#[test]
fn checkpoint_and_resume_equal_an_uninterrupted_run() {
    let config = periodic(150, 0.55, 40_000, 11);
    let (whole, expected) = run_to_end(equilibrated(config.clone()));

    /// Asks the run to stop once production has `at` collisions.
    struct StopAt<'a>(u64, &'a AtomicBool);
    impl Sink<2> for StopAt<'_> {
        type Error = std::convert::Infallible;
        fn event(&mut self, run: &Run<2>, _: &Outcome<2>) -> Result<(), Self::Error> {
            if run.collisions() >= self.0 {
                self.1.store(true, Ordering::Relaxed);
            }
            Ok(())
        }
    }
    let mut first = equilibrated(config);
    let stop = AtomicBool::new(false);
    let Ok(_) = first.advance(&stop, &mut StopAt(17_321, &stop));
    assert_eq!(first.collisions(), 17_321);
    let text = first.checkpoint(0).to_json();
    drop(first);
    let resumed = Run::resume(Checkpoint::<2>::from_json(text.as_bytes()).unwrap()).unwrap();
    let (resumed, got) = run_to_end(resumed);
    assert_eq!(got, expected);
    assert_eq!(resumed.sim.particles(), whole.sim.particles());
    assert_eq!(resumed.sim.time().to_bits(), whole.sim.time().to_bits());
}

fn walled(n: usize, eta: f64, collisions: u64) -> Config {
    config(&format!(
        "seed = 5\n[box]\npacking_fraction = {eta}\nboundary = \"wall\"\n[[species]]\ncount = {n}\nradius = 0.5\nmass = 1.0\n\
         [init]\nplacement = \"square\"\n[equilibration]\ncollisions = 20000\n\
         [run]\ncollisions = {collisions}\nsample_interval = 2.0\nblocks = 20\n"
    ))
}

/// The walled-box virial identity ½(Px + Py)·(Lx − σ)(Ly − σ) = N·kT + (1/(2t))·Σσ|Δp| holds
/// within its statistical error in one run. The difference is computed sample by sample and
/// its error from 20 block averages; 3σ is the tolerance (a true identity fails it with
/// probability 0.3 %; the fixed seed makes the test deterministic). The identity is exact in
/// the time average up to a boundary term O(σ·p/t), far below the statistical error here.
#[test]
fn walled_box_virial_identity() {
    let (run, summary) = run_to_end(equilibrated(walled(300, 0.4, 400_000)));
    let diffs: Vec<f64> = run
        .thermo
        .samples
        .iter()
        .map(|s| {
            let (x, y) = (s.pressure_walls[0].unwrap(), s.pressure_walls[1].unwrap());
            0.25 * (x[0] + x[1] + y[0] + y[1]) - s.pressure_virial
        })
        .collect();
    let (mean, error) = block_error(&diffs, 20);
    eprintln!(
        "walled box: P_virial = {} ± {}, wall − virial = {mean:e} ± {error:e}",
        summary.pressure_virial, summary.pressure_virial_error
    );
    assert!(mean.abs() <= 3.0 * error, "wall − virial = {mean} ± {error}");
    // And the two estimators are not trivially equal: both well above the ideal gas.
    let ideal =
        summary.n_particles as f64 * summary.kT / ((summary.box_lengths[0] - 1.0) * (summary.box_lengths[1] - 1.0));
    assert!(summary.pressure_virial > 1.5 * ideal, "{} vs ideal {ideal}", summary.pressure_virial);
    assert!(error < 0.02 * summary.pressure_virial, "error {error} too large to test anything");
}

/// One disk between walls: the mean wall pressure is exactly kT/((Lx − σ)(Ly − σ)) up to the
/// one partial flight at each end of the run: counting one hit more or less on each axis
/// changes ½(Px + Py) by at most ½·m(|vx|/(Ly − σ) + |vy|/(Lx − σ))/t — the tolerance.
#[test]
fn ideal_gas_limit_with_one_disk() {
    let disk = Particle {
        position: Vector2::new(2.0, 3.0),
        velocity: Vector2::new(0.731, -0.412),
        time: 0.0,
        radius: 0.5,
        mass: 1.3,
        species: 0,
        events: 0,
    };
    let (lx, ly) = (7.0, 5.0);
    let sim_box = SimBox { lengths: Vector2::new(lx, ly), boundary: [Boundary::Wall; 2] };
    let mut sim = Simulation::new(vec![disk.clone()], sim_box).unwrap();
    let mut impulse = [0.0; 2];
    while sim.time() < 20_000.0 {
        if let Outcome::Wall { axis, impulse: j, .. } = sim.step().unwrap() {
            impulse[axis] += j;
        }
    }
    let t = sim.time();
    let (ax, ay) = (lx - 1.0, ly - 1.0);
    let px = impulse[0] / 2.0 / (t * ay);
    let py = impulse[1] / 2.0 / (t * ax);
    let kt = sim.kt(); // one disk between walls: dof = 2, kT = K
    let expected = kt / (ax * ay);
    let m = disk.mass;
    let tolerance = 0.5 * m * (disk.velocity.x.abs() / ay + disk.velocity.y.abs() / ax) / t;
    let got = 0.5 * (px + py);
    assert!((got - expected).abs() <= tolerance, "{got} vs {expected} ± {tolerance}");
}

/// The registered velocity-distribution observable (`[observe.velocities]`): from a start at
/// one speed (a₂ = −½, far from the Maxwellian) to equilibrium, where the last snapshot
/// passes the Maxwellian's tests at their stated levels (KS below its 95 % critical value
/// 1.358/√N; a₂ and the kurtosis within 3 standard errors). It is in the summary by name,
/// kept in checkpoints (a resumed run ends with the same bits), and sees production only.
#[test]
fn the_velocity_observable_relaxes_to_the_maxwellian() {
    use collide::observe::Observable;
    let text = "seed = 5\n[box]\npacking_fraction = 0.3\nboundary = \"periodic\"\n\
                [[species]]\ncount = 2000\nradius = 0.5\nmass = 1.0\n[init]\nvelocities = \"fixed-speed\"\n\
                [run]\ntime = 20.0\nsample_interval = 2.0\n[observe.velocities]\nhistograms_at = [0, 10]\n";
    let config = config(text);
    let mut run = Run::<2>::new(config.clone()).unwrap();
    let Ok(_) = run.complete(&mut Discard);
    let Some(Observable::Velocities(v)) = run.observables.first() else { panic!("{:?}", run.observables) };
    let n = 2000.0f64;
    assert_eq!(v.snapshots.len(), 1 + run.thermo.samples.len());
    assert_eq!(v.histograms.iter().map(|h| h.t).collect::<Vec<_>>(), [0.0, v.snapshots[10].t]);
    let (first, last) = (&v.snapshots[0], v.snapshots.last().unwrap());
    assert!((first.sonine_a2 + 0.5).abs() < 0.01 && first.ks > 0.3, "{first:?}");
    assert!(last.ks <= 1.358 / n.sqrt(), "{last:?}");
    assert!(last.sonine_a2.abs() <= 3.0 * last.sonine_a2_error, "{last:?}");
    assert!((last.kurtosis - 3.0).abs() <= 3.0 * last.kurtosis_error, "{last:?}");
    let summary = reproducible(run.summary());
    assert_eq!(summary.observables["velocities"]["snapshots"].as_array().unwrap().len(), v.snapshots.len());
    let json = serde_json::to_string(&run.summary()).unwrap();
    assert!(json.contains("\"observe\":{\"velocities\":{\"histograms_at\":[0,10]}}"), "the configuration echoes it");

    // Through a checkpoint taken mid-production, to the same bits.
    let mut first = Run::<2>::new(config).unwrap();
    let stop = AtomicBool::new(false);
    struct StopAtSample<'a>(&'a AtomicBool);
    impl Sink<2> for StopAtSample<'_> {
        type Error = std::convert::Infallible;
        fn event(&mut self, run: &Run<2>, _: &Outcome<2>) -> Result<(), Self::Error> {
            if run.thermo.samples.len() >= 4 {
                self.0.store(true, Ordering::Relaxed);
            }
            Ok(())
        }
    }
    let Ok(_) = first.advance(&stop, &mut StopAtSample(&stop));
    let text = first.checkpoint(0).to_json();
    assert!(text.contains("\"observables\":[{\"velocities\""), "saved with the run");
    let mut resumed = Run::resume(Checkpoint::<2>::from_json(text.as_bytes()).unwrap()).unwrap();
    let Ok(_) = resumed.complete(&mut Discard);
    assert_eq!(reproducible(resumed.summary()), summary);
}

/// An observer handed to a run sees every production event and nothing of the equilibration.
#[test]
fn an_observer_of_the_caller_sees_production_only() {
    use collide::observe::Observer;
    struct Count(u64, f64);
    impl Observer<2> for Count {
        fn observe(&mut self, sim: &Simulation<2>, outcome: &Outcome<2>) {
            if let Outcome::Pair { .. } = outcome {
                self.0 += 1;
            }
            self.1 = self.1.min(sim.time());
        }
    }
    let mut run = equilibrated(periodic(100, 0.4, 3000, 2));
    let start = run.sim.time();
    let mut fresh = Run::new(periodic(100, 0.4, 3000, 2)).unwrap();
    let mut count = Count(0, f64::INFINITY);
    let Ok(_) = fresh.complete(&mut count);
    assert_eq!(count.0, 3000);
    assert!(count.1 > start, "an event at {} precedes production at {start}", count.1);
    let Ok(_) = run.complete(&mut Discard);
    assert_eq!(reproducible(run.summary()), reproducible(fresh.summary()));
}

fn reproducible(summary: Summary) -> Summary {
    Summary { wall_time_s: 0.0, collisions_per_second: 0.0, ..summary }
}
