//! `maxwell_boltzmann`: relaxation of a hard-disk or hard-sphere gas from equal speeds to the
//! Maxwell–Boltzmann distribution of its dimension.
//!
//! Every particle starts with the same speed √(d·kT/m) in a random direction (periodic box,
//! η = 0.3, the densest lattice: triangular or fcc). Time is measured in mean free times
//! τ = N·t/(2·collisions) (measured). At intervals of about τ/4 the speeds are compared with
//! the Maxwell speed density of d dimensions — Rayleigh's u·e^(−u²/2) for disks,
//! √(2/π)·u²·e^(−u²/2) for spheres (kT from the kinetic energy, not fitted): the KS distance
//! against its 95 % critical value, the H-function (KL divergence from the Maxwellian,
//! histogram bias removed), the Sonine coefficient a₂ = d/(d+2)·⟨u⁴⟩/⟨u²⟩² − 1 and the
//! kurtosis of the velocity components.
//!
//! Checks, on the last snapshot (≥ 10 τ): KS distance below the 95 % critical value
//! 1.358/√N; kurtosis within 3 standard errors √(24/(dN)) of 3; a₂ within 3 of its standard
//! errors (delta method; 1/√N in 2D) of 0; H − H_eq within 3 of its standard deviations
//! √(2(K−1))/(2N) of 0 and below its initial value. A true Maxwellian fails the KS check with
//! probability 5 % and each 3σ check with 0.3 %; the seed is fixed, so the verdict is
//! reproducible.

use super::plot::{Chart, Series, draw};
use super::stats::ks_critical_95;
use super::{Check, ExperimentError, ExperimentResult, Options, run_to_end};
use crate::observe::Observable;
use crate::observe::velocities::{self, Snapshot, histogram};
use crate::run::{Config, Discard, Run};
use crate::theory::{contact_value, enskog_rate};
use serde_json::json;

/// The experiment's name (binary, directory).
pub const NAME: &str = "maxwell_boltzmann";

/// The statistics of one snapshot of the velocities (the observable's [`Snapshot`]).
pub type Metrics = Snapshot;

/// Speeds and components in units of √(kT/m) from 2D velocities (equal masses m).
pub fn reduced(velocities: &[[f64; 2]], kt_over_m: f64) -> (Vec<f64>, Vec<f64>) {
    let s = kt_over_m.sqrt();
    let speeds = velocities.iter().map(|v| (v[0] * v[0] + v[1] * v[1]).sqrt() / s).collect();
    let components = velocities.iter().flat_map(|v| [v[0] / s, v[1] / s]).collect();
    (speeds, components)
}

/// The statistics of one 2D snapshot.
pub fn metrics(t: f64, speeds: &[f64], components: &[f64]) -> Metrics {
    Snapshot::of(t, 2, speeds, components)
}

/// The checks, from the first and last snapshots of `n` particles.
pub fn checks(first: &Metrics, last: &Metrics, n: usize) -> Vec<Check> {
    vec![
        Check::at_most(
            "KS distance to the Maxwell speed CDF of the dimension (kT from the energy)",
            last.ks,
            f64::NAN,
            ks_critical_95(n),
            "95 % critical value 1.358/√N of the Kolmogorov distribution",
        ),
        Check::within(
            "kurtosis of the velocity components",
            last.kurtosis,
            last.kurtosis_error,
            3.0,
            3.0 * last.kurtosis_error,
            "3 standard errors, √(24/(dN)) for dN Gaussian components",
        ),
        Check::within(
            "Sonine coefficient a₂",
            last.sonine_a2,
            last.sonine_a2_error,
            0.0,
            3.0 * last.sonine_a2_error,
            "3 standard errors for a Maxwellian (delta method; 1/√N in 2D, where u²/2 is exponential)",
        ),
        Check::within(
            "H − H_eq (bias-corrected KL divergence)",
            last.h,
            last.h_error,
            0.0,
            3.0 * last.h_error,
            "3 standard deviations √(2(K−1))/(2N): 2N·KL ~ χ²(K−1) for a Maxwellian",
        ),
        Check::at_most(
            "H − H_eq decreased from its initial value",
            last.h,
            last.h_error,
            first.h,
            "the H-theorem: H decreases towards its equilibrium value",
        ),
    ]
}

/// Runs the experiment.
pub fn run(options: &Options) -> Result<ExperimentResult, ExperimentError> {
    if options.dimension == 3 { run_in::<3>(options) } else { run_in::<2>(options) }
}

fn run_in<const D: usize>(options: &Options) -> Result<ExperimentResult, ExperimentError> {
    // Spheres on a perfect fcc lattice of 4k³ sites (k = 10, 20).
    let (n, horizon) = match (D, options.quick()) {
        (2, true) => (2000, 20.0),
        (2, false) => (20000, 30.0),
        (_, true) => (4000, 20.0),
        (_, false) => (32000, 30.0),
    };
    let eta: f64 = 0.3;
    // Enskog's mean free time, only to schedule the snapshots: Γ = 2nσ·g(σ)·√(πkT/m) (2D),
    // 4nσ²·g(σ)·√(πkT/m) (3D), with the contact value of the planning equations of state.
    let density = if D == 2 { 4.0 * eta / std::f64::consts::PI } else { 6.0 * eta / std::f64::consts::PI };
    let tau_enskog = 1.0 / enskog_rate(D, density, 1.0, contact_value(D, eta), 1.0, 1.0);
    let t_end = horizon * tau_enskog;
    let lattice = if D == 2 { "triangular" } else { "fcc" };
    // No equilibration: the relaxation itself is the production, sampled every τ/4, with the
    // velocity distribution observed at the start and at every sample.
    let text = format!(
        "dimension = {D}\nseed = {}\n[box]\npacking_fraction = {eta}\nboundary = \"periodic\"\n[[species]]\ncount = {n}\nradius = 0.5\nmass = 1.0\n\
         [init]\nplacement = \"{lattice}\"\nvelocities = \"fixed-speed\"\n\
         [run]\ntime = {t_end:?}\nsample_interval = {:?}\n[observe.velocities]\nhistograms_at = [0, 4, 12, 40]\n",
        options.seed,
        tau_enskog / 4.0
    );
    let mut run = Run::<D>::new(Config::parse(&text, NAME)?)?;
    run_to_end(&mut run, &mut Discard)?;
    let sim = &run.sim;
    let Some(Observable::Velocities(observed)) = run.observables.first() else {
        return Err(ExperimentError::Missing("the velocity observable"));
    };
    let (series, edges) = (&observed.snapshots, &observed.edges);
    let mut histograms: Vec<(f64, Vec<usize>)> = observed.histograms.iter().map(|h| (h.t, h.counts.clone())).collect();
    let (u, _) = velocities::reduced(sim);
    histograms.push((sim.time(), histogram(&u, edges)));
    let collisions = sim.counts().pair;
    let tau = n as f64 * sim.time() / (2.0 * collisions as f64);
    let checks = checks(&series[0], series.last().expect("snapshots"), n);

    // Plots.
    let dir = options.plot_dir(NAME)?;
    let in_tau = |t: f64| t / tau;
    let width = edges[1] - edges[0];
    // t = 0 is a delta at u = √d (every speed equal): left out so the scale shows the rest.
    let mut hist_series: Vec<Series> = histograms
        .iter()
        .skip(1)
        .map(|(t, counts)| {
            let points = counts
                .iter()
                .enumerate()
                .map(|(k, &c)| (edges[k] + width / 2.0, c as f64 / (n as f64 * width)))
                .collect();
            Series::points(&format!("t = {:.1} τ", in_tau(*t)), points)
        })
        .collect();
    let (density_label, speed_density): (&str, fn(f64) -> f64) = if D == 2 {
        ("Rayleigh u·exp(−u²/2)", |u| u * (-0.5 * u * u).exp())
    } else {
        ("Maxwell √(2/π)·u²·exp(−u²/2)", |u| {
            (2.0 / std::f64::consts::PI).sqrt() * u * u * (-0.5 * u * u).exp()
        })
    };
    hist_series
        .push(Series::line(density_label, (0..=250).map(|k| k as f64 * 0.02).map(|u| (u, speed_density(u))).collect()));
    let noun = if D == 2 { "2D" } else { "3D" };
    let charts = [
        (
            "speed_distribution.svg",
            Chart {
                title: format!("Speed distribution relaxing to the {noun} Maxwellian (t = 0: all at u = √{D})"),
                x_label: "speed u = v/√(kT/m)".into(),
                y_label: "probability density".into(),
                legend_left: false,
                series: hist_series,
            },
        ),
        (
            "ks_distance.svg",
            Chart {
                title: format!("KS distance to the {noun} Maxwell speed CDF"),
                x_label: "t / τ (mean free times)".into(),
                y_label: "KS distance D".into(),
                legend_left: false,
                series: vec![
                    Series::points("measured", series.iter().map(|m| (in_tau(m.t), m.ks)).collect()),
                    Series::line(
                        "95 % critical value 1.358/√N",
                        vec![(0.0, ks_critical_95(n)), (in_tau(sim.time()), ks_critical_95(n))],
                    ),
                ],
            },
        ),
        (
            "h_function.svg",
            Chart {
                title: "H-function relative to equilibrium".into(),
                x_label: "t / τ (mean free times)".into(),
                y_label: "H − H_eq (nats)".into(),
                legend_left: false,
                series: vec![Series::errors(
                    "bias-corrected KL divergence",
                    series.iter().map(|m| (in_tau(m.t), m.h)).collect(),
                    series.iter().map(|m| m.h_error).collect(),
                )],
            },
        ),
        (
            "moments.svg",
            Chart {
                title: "Sonine coefficient and kurtosis".into(),
                x_label: "t / τ (mean free times)".into(),
                y_label: "a₂, kurtosis − 3 (dimensionless)".into(),
                legend_left: false,
                series: vec![
                    Series::errors(
                        "a₂",
                        series.iter().map(|m| (in_tau(m.t), m.sonine_a2)).collect(),
                        series.iter().map(|m| m.sonine_a2_error).collect(),
                    ),
                    Series::errors(
                        "kurtosis − 3",
                        series.iter().map(|m| (in_tau(m.t), m.kurtosis - 3.0)).collect(),
                        series.iter().map(|m| m.kurtosis_error).collect(),
                    ),
                ],
            },
        ),
    ];
    let mut plots = Vec::new();
    for (file, chart) in &charts {
        draw(chart, &dir.join(file))?;
        plots.push(file.to_string());
    }
    Ok(options.result(
        NAME,
        json!({
            "dimension": D, "n_particles": n, "packing_fraction": eta, "boundary": "periodic", "kT": 1.0, "mass": 1.0,
            "lattice": lattice, "initial_velocities": "fixed-speed", "horizon_enskog_tau": horizon,
        }),
        json!({
            "tau_measured": tau, "tau_enskog": tau_enskog, "collisions": collisions, "sim_time": sim.time(),
            "snapshots": series, "histogram_edges": edges,
            "histograms": histograms.iter().map(|(t, c)| json!({"t": t, "counts": c})).collect::<Vec<_>>(),
        }),
        checks,
        plots,
    ))
}
