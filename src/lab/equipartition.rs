//! `equipartition`: a binary mixture started with its two species at different temperatures
//! relaxes to one temperature — disks or spheres.
//!
//! Species A (m = 1) and B (m = 10), half the particles each, periodic box, η = 0.3, from the
//! densest lattice (triangular or fcc); case 1 with equal radii 0.5, case 2 with radii 0.5 and
//! 0.35. A starts at kT = 2, B at kT = 0.5 (same
//! total energy as kT = 1.25). Elastic collisions drive every species to the same mean kinetic
//! energy per particle (physics reference sheet). With the total momentum fixed at zero, the
//! exact equilibrium expectation is ⟨K_s⟩ = (d/2)·kT·N_s·(1 − m_s/M), M the total mass, so
//! each species' temperature is measured as kT_s = 2K_s/(d·N_s·(1 − m_s/M)).
//!
//! Check, per case: over the second half of the run, the mean of kT_A − kT_B (sampled about
//! every mean free time) is 0 within the 3σ-equivalent of its 20-block standard error
//! (Student t with 19 degrees of freedom: 3.45 standard errors).
//!
//! The run is 2000 mean free times long at both sizes and in both dimensions, so that a block
//! (50 samples) is long against the correlations of kT_A − kT_B. Calibrated on 60 seeds of
//! disks at N = 400 (mean over
//! seeds of (mean/error)², whose root Student's t puts at 1.06 for 20 blocks): 1.14 (equal
//! radii) and 1.08 (unequal) at 2000 τ; 1.54 and 1.30 at 1000 τ, and 1.60 and 1.96 at the
//! 200 τ this check once ran for in quick mode — there one run in 20 failed the 3σ check.

use super::plot::{Chart, Series, draw};
use super::stats::three_sigma_factor;
use super::{Check, ExperimentError, ExperimentResult, Options, run_to_end};
use crate::engine::init::{Velocities, initial_particles};
use crate::engine::{Outcome, Simulation};
use crate::observe::{Observer, block_error};
use crate::run::{Config, Discard, Run, box_of};
use nalgebra::SVector;
use serde_json::json;

/// The experiment's name.
pub const NAME: &str = "equipartition";

/// kT of each species, with the momentum-constraint correction: d·(1 − m/M) degrees of
/// freedom per particle.
pub fn species_temperatures<const D: usize>(sim: &Simulation<D>, species: usize) -> Vec<f64> {
    let total_mass: f64 = sim.particles().iter().map(|p| p.mass).sum();
    let mut k = vec![0.0; species];
    let mut dof = vec![0.0; species];
    for p in sim.particles() {
        k[p.species as usize] += p.kinetic_energy();
        dof[p.species as usize] += D as f64 * (1.0 - p.mass / total_mass);
    }
    k.iter().zip(&dof).map(|(k, d)| 2.0 * k / d).collect()
}

/// The species temperatures at every sample, in mean free times `tau`.
struct SpeciesTemperatures {
    tau: f64,
    series: Vec<[f64; 3]>,
}

impl<const D: usize> Observer<D> for SpeciesTemperatures {
    fn observe(&mut self, sim: &Simulation<D>, outcome: &Outcome<D>) {
        if let Outcome::Sample = outcome {
            let t = species_temperatures(sim, 2);
            self.series.push([sim.time() / self.tau, t[0], t[1]]);
        }
    }
}

/// One mixture of `n` particles in `D` dimensions: returns (times, kT_A, kT_B) and the check.
pub fn relax<const D: usize>(
    radii: [f64; 2],
    n: usize,
    mean_free_times: f64,
    seed: u64,
    label: &str,
) -> Result<(Vec<[f64; 3]>, Check), ExperimentError> {
    // The equilibration is a warm-up of n collisions that measures the mean free time; the
    // production, planned from it, samples once per mean free time.
    let text = format!(
        "dimension = {D}\nseed = {seed}\n[box]\npacking_fraction = 0.3\nboundary = \"periodic\"\n\
         [[species]]\ncount = {}\nradius = {:?}\nmass = 1.0\n[[species]]\ncount = {}\nradius = {:?}\nmass = 10.0\n\
         [equilibration]\ncollisions = {n}\n[run]\ncollisions = 1\n",
        n / 2,
        radii[0],
        n - n / 2,
        radii[1]
    );
    let config = Config::parse(&text, NAME)?;
    let sim_box = box_of::<D>(&config);
    let mut particles =
        initial_particles(&config.species, &sim_box, config.placement(), Velocities::Maxwell, 1.0, seed)?;
    // Heat A to kT = 2 and cool B to kT = 0.5 (the total momentum stays zero only on average;
    // remove it again, then the species temperatures are as set to O(1/N)).
    for p in particles.iter_mut() {
        p.velocity *= if p.species == 0 { 2f64.sqrt() } else { 0.5f64.sqrt() };
    }
    let momentum: SVector<f64, D> = particles.iter().map(|p| p.velocity * p.mass).sum();
    let total_mass: f64 = particles.iter().map(|p| p.mass).sum();
    for p in particles.iter_mut() {
        p.velocity -= momentum / total_mass;
    }
    let mut run = Run::<D>::from_particles(config, particles)?;
    let Ok(_) = run.equilibrate(&mut Discard);
    let warm = run.sim.counts().pair;
    let tau = n as f64 * run.sim.time() / (2.0 * warm as f64);
    run.plan_production(None, Some(mean_free_times * tau - run.sim.time()), tau)?;
    let t = species_temperatures(&run.sim, 2);
    let mut observer = SpeciesTemperatures { tau, series: vec![[run.sim.time() / tau, t[0], t[1]]] };
    run_to_end(&mut run, &mut observer)?;
    let series = observer.series;
    let late: Vec<f64> = series[series.len() / 2..].iter().map(|s| s[1] - s[2]).collect();
    let (mean, error) = block_error(&late, 20);
    let check = Check::within(
        &format!("{label}: kT_A − kT_B over the second half"),
        mean,
        error,
        0.0,
        three_sigma_factor(20) * error,
        "3σ-equivalent for a 20-block error (Student t: 3.45 standard errors; blocks of 50 τ, calibrated on 60 seeds); kT_s corrected for the zero total momentum",
    );
    Ok((series, check))
}

/// Runs the experiment.
pub fn run(options: &Options) -> Result<ExperimentResult, ExperimentError> {
    // The length is set by the statistics (see the module docs), the size by the budget.
    let d = options.dimension;
    // Spheres on an fcc lattice of 4k³ sites (k = 5, 8).
    let (n, horizon) = match (d, options.quick()) {
        (2, true) => (400, 2000.0),
        (2, false) => (2000, 2000.0),
        (_, true) => (500, 2000.0),
        (_, false) => (2048, 2000.0),
    };
    let cases = [("equal radii", [0.5, 0.5]), ("radii 0.5 and 0.35", [0.5, 0.35])];
    let mut checks = Vec::new();
    let mut data = Vec::new();
    let mut plot_series = Vec::new();
    for (k, (label, radii)) in cases.iter().enumerate() {
        let seed = options.seed + k as u64;
        let (series, check) = if d == 3 {
            relax::<3>(*radii, n, horizon, seed, label)?
        } else {
            relax::<2>(*radii, n, horizon, seed, label)?
        };
        plot_series
            .push(Series::line(&format!("{label}: species A (m = 1)"), series.iter().map(|s| (s[0], s[1])).collect()));
        plot_series
            .push(Series::line(&format!("{label}: species B (m = 10)"), series.iter().map(|s| (s[0], s[2])).collect()));
        data.push(json!({ "case": label, "radii": radii, "series": series }));
        checks.push(check);
    }
    let dir = options.plot_dir(NAME)?;
    draw(
        &Chart {
            title: format!(
                "Equipartition in a binary mixture of {} (mass ratio 1:10)",
                if d == 2 { "disks" } else { "spheres" }
            ),
            x_label: "t / τ (mean free times)".into(),
            y_label: "species temperature kT_s (kT units)".into(),
            legend_left: false,
            series: plot_series,
        },
        &dir.join("species_temperatures.svg"),
    )?;
    Ok(options.result(
        NAME,
        json!({ "dimension": d, "n_particles": n, "packing_fraction": 0.3, "masses": [1.0, 10.0],
            "initial_kT": [2.0, 0.5], "horizon_mean_free_times": horizon }),
        json!({ "cases": data }),
        checks,
        vec!["species_temperatures.svg".into()],
    ))
}
