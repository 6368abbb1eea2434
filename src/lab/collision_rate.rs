//! `collision_rate`: the collision frequency per particle against Enskog's, and the exact
//! equilibrium identity that links it to the pressure.
//!
//! Physics reference sheet: Γ = 2nσ·g(σ)·√(πkT/m) in 2D, with g(σ) the contact value of the
//! pair correlation; Z = 1 + 2η·g(σ) (so g(σ) = (Z − 1)/(2η) from the measured pressure);
//! Henderson's g(σ) = (1 − 7η/16)/(1 − η)². Because ⟨|Δp|⟩ = √(πmkT) per collision in
//! equilibrium, Z − 1 = (σΓ/(2d))·√(πm/kT) exactly: Γ predicted from the measured Z equals
//! the measured Γ to statistical precision. Mean free path λ = ⟨v⟩/Γ with ⟨v⟩ = √(πkT/2m).
//!
//! Checks, per density (periodic box, triangular lattice start, equilibrated):
//! * identity: the per-sample difference Γ − Γ(Z) has mean 0 within 3 block-average standard
//!   errors (Student-t 3σ-equivalent for 20 blocks: 3.45);
//! * Enskog with Henderson's g(σ), for η ≤ 0.5: |Γ − Γ_E| ≤ 3σ + the 0.5 % accuracy of
//!   Henderson's Z carried to g (a relative Z/(Z − 1)·0.5 %) + |Γ|/N finite size.

use super::plot::{Chart, Series, draw};
use super::stats::three_sigma_factor;
use super::{Check, ExperimentError, ExperimentResult, Options, run_to_end};
use crate::observe::block_error;
use crate::run::{Config, Discard, Run};
pub use crate::theory::{g_henderson, gamma_enskog};
use crate::theory::{mean_free_path_enskog, z_henderson};
use serde::{Deserialize, Serialize};
use serde_json::json;
use std::f64::consts::PI;

/// The experiment's name.
pub const NAME: &str = "collision_rate";

/// One measured state.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RateState {
    /// Packing fraction.
    pub eta: f64,
    /// N.
    pub n_particles: usize,
    /// Measured Γ (collisions per particle per time).
    pub gamma: f64,
    /// Its standard error.
    pub gamma_err: f64,
    /// Measured Z.
    pub z: f64,
    /// Its standard error.
    pub z_err: f64,
    /// Mean of Γ − Γ(Z) per sample.
    pub identity_difference: f64,
    /// Its standard error.
    pub identity_difference_err: f64,
    /// Mean free path ⟨v⟩/Γ.
    pub mean_free_path: f64,
}

/// Measures one state.
pub fn measure(eta: f64, n: usize, per_particle: u64, seed: u64) -> Result<RateState, ExperimentError> {
    let production = per_particle * n as u64;
    let mut config = Config::parse(
        &format!(
            "seed = {seed}\n[box]\npacking_fraction = {eta}\nboundary = \"periodic\"\n[[species]]\ncount = {n}\nradius = 0.5\nmass = 1.0\n\
             [equilibration]\ncollisions = {}\n[run]\ncollisions = {production}\n",
            production / 2
        ),
        NAME,
    )?;
    config.run.sample_interval = 2.0 * per_particle as f64 / gamma_enskog(eta, g_henderson(eta)) / 200.0;
    let mut run = Run::<2>::new(config)?;
    run_to_end(&mut run, &mut Discard)?;
    // Γ and the identity sample by sample, from the collisions and pressures of each interval.
    let (mut last_t, mut last_c) = (run.thermo.start_time, 0u64);
    let (mut rates, mut diffs) = (Vec::new(), Vec::new());
    let density = n as f64 / run.sim.sim_box().volume();
    for s in &run.thermo.samples {
        let rate = 2.0 * (s.collisions - last_c) as f64 / (n as f64 * (s.t - last_t));
        let z = s.pressure_virial / (density * s.kt);
        // Z − 1 = (σΓ/(2d))·√(πm/kT) ⇒ Γ(Z) = 4(Z − 1)·√(kT/(πm)) (d = 2, σ = m = 1).
        rates.push(rate);
        diffs.push(rate - 4.0 * (z - 1.0) * (s.kt / PI).sqrt());
        (last_t, last_c) = (s.t, s.collisions);
    }
    let summary = run.summary();
    let (_, gamma_err) = block_error(&rates, 20);
    let (identity_difference, identity_difference_err) = block_error(&diffs, 20);
    let gamma = summary.collision_rate_per_particle;
    Ok(RateState {
        eta,
        n_particles: n,
        gamma,
        gamma_err,
        z: summary.compressibility,
        z_err: summary.compressibility_error,
        identity_difference,
        identity_difference_err,
        mean_free_path: (PI * summary.kT / 2.0).sqrt() / gamma,
    })
}

/// The checks of one state.
pub fn checks_for(s: &RateState) -> Vec<Check> {
    let k = three_sigma_factor(20);
    let mut checks = vec![Check::within(
        &format!("η = {}: Γ − Γ(Z), the identity Z − 1 = (σΓ/2d)√(πm/kT)", s.eta),
        s.identity_difference,
        s.identity_difference_err,
        0.0,
        k * s.identity_difference_err,
        "exact in equilibrium (⟨|Δp|⟩ = √(πmkT)); 3σ-equivalent for a 20-block error (Student t: 3.45)",
    )];
    if s.eta <= 0.5 {
        let g = g_henderson(s.eta);
        let expected = gamma_enskog(s.eta, g);
        let zh = z_henderson(s.eta);
        checks.push(Check::within(
            &format!("η = {}: Γ vs Enskog with Henderson's g(σ)", s.eta),
            s.gamma,
            s.gamma_err,
            expected,
            k * s.gamma_err + expected * 0.005 * zh / (zh - 1.0) + s.gamma / s.n_particles as f64,
            "3σ-equivalent for a 20-block error (Student t: 3.45) + Henderson's 0.5 % in Z carried to g(σ) (×Z/(Z−1)) + Γ/N finite size",
        ));
    }
    checks
}

/// Runs the experiment.
pub fn run(options: &Options) -> Result<ExperimentResult, ExperimentError> {
    let (n, per_particle, etas) =
        if options.quick { (400, 200, vec![0.2, 0.5]) } else { (1600, 500, vec![0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.65]) };
    let mut states = Vec::new();
    for (k, &eta) in etas.iter().enumerate() {
        states.push(measure(eta, n, per_particle, options.seed + k as u64)?);
    }
    let checks: Vec<Check> = states.iter().flat_map(checks_for).collect();
    let dir = ExperimentResult::plot_dir(&options.out, NAME)?;
    let top = etas.iter().copied().fold(0.0, f64::max) + 0.02;
    let chart = Chart {
        title: "Collision frequency per particle".into(),
        x_label: "packing fraction η (dimensionless)".into(),
        y_label: "Γ (collisions per particle per σ√(m/kT))".into(),
        legend_left: true,
        series: vec![
            Series::errors(
                "measured",
                states.iter().map(|s| (s.eta, s.gamma)).collect(),
                states.iter().map(|s| s.gamma_err).collect(),
            ),
            Series::points(
                "Enskog with g(σ) from the measured Z",
                states.iter().map(|s| (s.eta, gamma_enskog(s.eta, (s.z - 1.0) / (2.0 * s.eta)))).collect(),
            ),
            Series::line(
                "Enskog with Henderson's g(σ)",
                (1..=100).map(|k| k as f64 * top / 100.0).map(|e| (e, gamma_enskog(e, g_henderson(e)))).collect(),
            ),
        ],
    };
    draw(&chart, &dir.join("collision_rate.svg"))?;
    Ok(ExperimentResult {
        name: NAME.into(),
        quick: options.quick,
        seed: options.seed,
        parameters: json!({ "n_particles": n, "packing_fractions": etas, "boundary": "periodic", "kT": 1.0,
            "production_collisions_per_particle": per_particle }),
        data: json!({
            "states": states,
            "enskog_henderson": states.iter().map(|s| gamma_enskog(s.eta, g_henderson(s.eta))).collect::<Vec<_>>(),
            "mean_free_path_enskog": states.iter().map(|s| mean_free_path_enskog(s.eta)).collect::<Vec<_>>(),
        }),
        checks,
        plots: vec!["collision_rate.svg".into()],
    })
}
