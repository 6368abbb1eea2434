//! `collision_rate`: the collision frequency per particle against Enskog's, and the exact
//! equilibrium identity that links it to the pressure — disks or spheres.
//!
//! Physics reference sheet: Γ = 2nσ·g(σ)·√(πkT/m) in 2D and Γ = 4nσ²·g(σ)·√(πkT/m) in 3D,
//! with g(σ) the contact value of the pair correlation; Z = 1 + 2η·g(σ) (2D), 1 + 4η·g(σ)
//! (3D). Because ⟨|Δp|⟩ = √(πmkT) per collision in equilibrium, Z − 1 = (σΓ/(2d))·√(πm/kT)
//! exactly: Γ predicted from the measured Z equals the measured Γ to statistical precision.
//! Mean free path λ = ⟨v⟩/Γ with ⟨v⟩ = √(πkT/2m) (2D), √(8kT/πm) (3D).
//!
//! Checks, per density (periodic box; disks from a triangular lattice, spheres from a simple
//! cubic one that melts at once; equilibrated):
//! * identity: the per-sample difference Γ − Γ(Z) has mean 0 within 3 block-average standard
//!   errors (Student-t 3σ-equivalent for 20 blocks: 3.45);
//! * Enskog with the contact value of the most accurate equation of state of the fluid —
//!   the virial series through b₁₀ for disks at η ≤ 0.2 and Liu's above (η ≤ 0.65), Hansen-Goos' for
//!   spheres (η ≤ 0.49), g(σ) = (Z − 1)/(2^(d−1)·η):
//!   |Γ − Γ_E| ≤ 3σ + the reference's relative accuracy in Z carried to g (×Z/(Z − 1)) +
//!   |Γ|/N finite size.

use super::plot::{Chart, Series, draw};
use super::stats::three_sigma_factor;
use super::{Check, ExperimentError, ExperimentResult, Options, run_to_end};
use crate::observe::block_error;
use crate::run::{Config, Discard, Run};
use crate::theory::{
    Z_HANSEN_GOOS_ACCURACY, Z_LIU_DISKS_ACCURACY, contact_value, enskog_rate, z_hansen_goos, z_virial,
};
pub use crate::theory::{g_liu_disks, z_liu_disks};
use serde::{Deserialize, Serialize};
use serde_json::json;
use std::f64::consts::PI;

/// The experiment's name.
pub const NAME: &str = "collision_rate";

/// One measured state.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RateState {
    /// 2 (disks) or 3 (spheres).
    pub dimension: usize,
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

/// The number density of unit-diameter particles at packing fraction `eta` in `d` dimensions.
pub fn number_density(d: usize, eta: f64) -> f64 {
    if d == 2 { 4.0 * eta / PI } else { 6.0 * eta / PI }
}

/// Enskog's Γ with the contact value of the reference equation of state, Z, that reference's
/// relative accuracy in Z, and its name (σ = m = kT = 1): for disks the virial series through
/// b₁₀ up to η = 0.2 (its first omitted term, b₁₁η¹⁰/(1 − η) with b₁₁ ≈ 11, as the
/// uncertainty: below 10⁻⁵ there, far below the statistics) and Liu's equation of state above;
/// for spheres Hansen-Goos'. g(σ) = (Z − 1)/(2^(d−1)·η) in every case.
pub fn enskog_reference(d: usize, eta: f64) -> (f64, f64, f64, &'static str) {
    let (z, accuracy, name) = if d == 2 && eta <= 0.2 {
        let z = z_virial(eta);
        (z, 11.0 * eta.powi(10) / (1.0 - eta) / z, "the virial series'")
    } else if d == 2 {
        (z_liu_disks(eta), Z_LIU_DISKS_ACCURACY, "Liu's")
    } else {
        (z_hansen_goos(eta), Z_HANSEN_GOOS_ACCURACY, "Hansen-Goos'")
    };
    let g = (z - 1.0) / (2f64.powi(d as i32 - 1) * eta);
    (enskog_rate(d, number_density(d, eta), 1.0, g, 1.0, 1.0), z, accuracy, name)
}

/// Measures one state of `n` particles in `d` dimensions.
pub fn measure(d: usize, eta: f64, n: usize, per_particle: u64, seed: u64) -> Result<RateState, ExperimentError> {
    let production = per_particle * n as u64;
    let placement = if d == 2 { "triangular" } else { "simple_cubic" };
    let mut config = Config::parse(
        &format!(
            "dimension = {d}\nseed = {seed}\n[box]\npacking_fraction = {eta}\nboundary = \"periodic\"\n[[species]]\ncount = {n}\nradius = 0.5\nmass = 1.0\n\
             [init]\nplacement = \"{placement}\"\n[equilibration]\ncollisions = {}\n[run]\ncollisions = {production}\n",
            production / 2
        ),
        NAME,
    )?;
    let planned = enskog_rate(d, number_density(d, eta), 1.0, contact_value(d, eta), 1.0, 1.0);
    config.run.sample_interval = 2.0 * per_particle as f64 / planned / 200.0;
    if d == 3 { measure_in::<3>(config, eta, n) } else { measure_in::<2>(config, eta, n) }
}

fn measure_in<const D: usize>(config: Config, eta: f64, n: usize) -> Result<RateState, ExperimentError> {
    let mut run = Run::<D>::new(config)?;
    run_to_end(&mut run, &mut Discard)?;
    // Γ and the identity sample by sample, from the collisions and pressures of each interval.
    let (mut last_t, mut last_c) = (run.thermo.start_time, 0u64);
    let (mut rates, mut diffs) = (Vec::new(), Vec::new());
    let density = n as f64 / run.sim.sim_box().volume();
    for s in &run.thermo.samples {
        let rate = 2.0 * (s.collisions - last_c) as f64 / (n as f64 * (s.t - last_t));
        let z = s.pressure_virial / (density * s.kt);
        // Z − 1 = (σΓ/(2d))·√(πm/kT) ⇒ Γ(Z) = 2d(Z − 1)·√(kT/(πm)) (σ = m = 1).
        rates.push(rate);
        diffs.push(rate - 2.0 * D as f64 * (z - 1.0) * (s.kt / PI).sqrt());
        (last_t, last_c) = (s.t, s.collisions);
    }
    let summary = run.summary();
    let (_, gamma_err) = block_error(&rates, 20);
    let (identity_difference, identity_difference_err) = block_error(&diffs, 20);
    let gamma = summary.collision_rate_per_particle;
    let mean_speed = if D == 2 { (PI * summary.kT / 2.0).sqrt() } else { (8.0 * summary.kT / PI).sqrt() };
    Ok(RateState {
        dimension: D,
        eta,
        n_particles: n,
        gamma,
        gamma_err,
        z: summary.compressibility,
        z_err: summary.compressibility_error,
        identity_difference,
        identity_difference_err,
        mean_free_path: mean_speed / gamma,
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
    let within = if s.dimension == 2 { 0.65 } else { 0.49 };
    if s.eta <= within {
        let (expected, z, accuracy, name) = enskog_reference(s.dimension, s.eta);
        checks.push(Check::within(
            &format!("η = {}: Γ vs Enskog with {name} g(σ)", s.eta),
            s.gamma,
            s.gamma_err,
            expected,
            k * s.gamma_err + expected * accuracy * z / (z - 1.0) + s.gamma / s.n_particles as f64,
            &format!(
                "3σ-equivalent for a 20-block error (Student t: 3.45) + {name} {accuracy:.1e} relative accuracy in Z carried to g(σ) (×Z/(Z−1)) + Γ/N finite size"
            ),
        ));
    }
    checks
}

/// Runs the experiment.
pub fn run(options: &Options) -> Result<ExperimentResult, ExperimentError> {
    let d = options.dimension;
    // Spheres on a simple cubic lattice of k³ sites (k = 8, 12).
    let (n, per_particle, etas) = match (d, options.quick()) {
        (2, true) => (400, 200, vec![0.2, 0.5]),
        (2, false) => (1600, 500, vec![0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.65]),
        (_, true) => (512, 200, vec![0.2, 0.45]),
        (_, false) => (1728, 500, vec![0.1, 0.2, 0.3, 0.4, 0.45, 0.49]),
    };
    let mut states = Vec::new();
    for (k, &eta) in etas.iter().enumerate() {
        states.push(measure(d, eta, n, per_particle, options.seed + k as u64)?);
    }
    let checks: Vec<Check> = states.iter().flat_map(checks_for).collect();
    let dir = options.plot_dir(NAME)?;
    let top = etas.iter().copied().fold(0.0, f64::max) + 0.02;
    let g_from_z = |s: &RateState| (s.z - 1.0) / (if d == 2 { 2.0 } else { 4.0 } * s.eta);
    let chart = Chart {
        title: format!("Collision frequency per particle ({})", if d == 2 { "disks" } else { "spheres" }),
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
                states
                    .iter()
                    .map(|s| (s.eta, enskog_rate(d, number_density(d, s.eta), 1.0, g_from_z(s), 1.0, 1.0)))
                    .collect(),
            ),
            Series::line(
                if d == 2 {
                    "Enskog with g(σ) of the virial series (η ≤ 0.2), then Liu's"
                } else {
                    "Enskog with Hansen-Goos' g(σ)"
                },
                (1..=100).map(|k| k as f64 * top / 100.0).map(|e| (e, enskog_reference(d, e).0)).collect(),
            ),
        ],
    };
    draw(&chart, &dir.join("collision_rate.svg"))?;
    let mean_free_path = |e: f64| {
        let speed = if d == 2 { (PI / 2.0).sqrt() } else { (8.0 / PI).sqrt() };
        speed / enskog_reference(d, e).0
    };
    Ok(options.result(
        NAME,
        json!({ "dimension": d, "n_particles": n, "packing_fractions": etas, "boundary": "periodic", "kT": 1.0,
            "production_collisions_per_particle": per_particle }),
        json!({
            "states": states,
            "enskog_reference": states.iter().map(|s| enskog_reference(d, s.eta).0).collect::<Vec<_>>(),
            "mean_free_path_enskog": states.iter().map(|s| mean_free_path(s.eta)).collect::<Vec<_>>(),
        }),
        checks,
        vec!["collision_rate.svg".into()],
    ))
}
