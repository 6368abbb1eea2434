//! `equation_of_state`: the compressibility factor Z = βP/n of hard disks from the collision
//! virial, across packing fractions, against three equations of state.
//!
//! Each density runs in a periodic box from a triangular lattice, equilibrated (the number
//! of collisions per particle is recorded), then measured; Z and its error come from the
//! run summary (20 block averages). References (physics reference sheet):
//!
//! * Henderson, Mol. Phys. 30, 971 (1975): Z = (1 + η²/8)/(1 − η)², good to about 0.5 % up to
//!   η ≈ 0.5;
//! * Santos, López de Haro & Yuste, J. Chem. Phys. 103, 4622 (1995):
//!   Z = [1 − 2η + (2η_cp − 1)η²/η_cp²]⁻¹, η_cp = π/(2√3);
//! * the virial series Z = 1 + Σ b_k η^(k−1), b₂…b₁₀ from Clisby & McCoy, J. Stat. Phys. 122,
//!   15 (2006), Table 1 (D = 2): excellent below η ≈ 0.2.
//!
//! (The formulas are in [`crate::theory`].)
//!
//! Checks: η ≤ 0.2 against the virial series, 0.2 < η ≤ 0.5 against Henderson. Tolerance:
//! the 3σ-equivalent for an error estimated from 20 blocks (Student t: 3.45 standard
//! errors), plus the reference's own accuracy (0.5 % for Henderson; the first
//! omitted virial term, estimated as b₁₁η¹⁰ with b₁₁ ≈ 11, for the series), plus a
//! finite-size allowance |Z − 1|/N (canonical corrections to the pressure are O(1/N)).
//! Denser states are measured and plotted but not judged: no reference here states its
//! accuracy there, and above η ≈ 0.69 the liquid–hexatic transition (Bernard & Krauth 2011)
//! brings slow equilibration and strong finite-size effects.

use super::plot::{Chart, Series, draw};
use super::stats::three_sigma_factor;
use super::{Check, ExperimentError, ExperimentResult, Options, run_to_end};
use crate::run::{Config, Discard, Run};
use crate::theory::{g_henderson, gamma_enskog};
pub use crate::theory::{z_henderson, z_slhy, z_virial};
use serde::{Deserialize, Serialize};
use serde_json::json;

/// The experiment's name.
pub const NAME: &str = "equation_of_state";

/// Blocks for the error bars of every state.
pub const BLOCKS: usize = 20;

/// One measured state.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Point {
    /// Packing fraction.
    pub eta: f64,
    /// Compressibility factor.
    #[serde(rename = "Z")]
    pub z: f64,
    /// Its standard error.
    #[serde(rename = "Z_err")]
    pub z_err: f64,
    /// N.
    pub n_particles: usize,
    /// Measured collisions.
    pub collisions: u64,
    /// Equilibration collisions per particle.
    pub equilibration_per_particle: f64,
}

/// The check for one point, or `None` where no reference states its accuracy (η > 0.5).
pub fn check_point(p: &Point) -> Option<Check> {
    let finite_size = (p.z - 1.0).abs() / p.n_particles as f64;
    let k = three_sigma_factor(BLOCKS);
    if p.eta <= 0.2 {
        let truncation = 11.0 * p.eta.powi(10) / (1.0 - p.eta);
        Some(Check::within(
            &format!("Z at η = {} vs virial series (Clisby & McCoy 2006)", p.eta),
            p.z,
            p.z_err,
            z_virial(p.eta),
            k * p.z_err + truncation + finite_size,
            "3σ-equivalent (Student t, 19 dof: 3.45 standard errors) + first omitted virial term (b₁₁η¹⁰/(1−η), b₁₁ ≈ 11) + |Z−1|/N finite size",
        ))
    } else if p.eta <= 0.5 {
        let zh = z_henderson(p.eta);
        Some(Check::within(
            &format!("Z at η = {} vs Henderson (1975)", p.eta),
            p.z,
            p.z_err,
            zh,
            k * p.z_err + 0.005 * zh + finite_size,
            "3σ-equivalent (Student t, 19 dof: 3.45 standard errors) + Henderson's 0.5 % accuracy up to η ≈ 0.5 + |Z−1|/N finite size",
        ))
    } else {
        None
    }
}

/// Runs one state point.
pub fn measure(eta: f64, n: usize, equilibration: u64, production: u64, seed: u64) -> Result<Point, ExperimentError> {
    // The sampling interval (time between rows) is a few mean free times; Enskog's estimate
    // with Henderson's contact value sets it (only for scheduling).
    let tau = 1.0 / gamma_enskog(eta, g_henderson(eta));
    let samples_wanted = 100.0;
    let run_time = 2.0 * production as f64 / n as f64 * tau;
    let text = format!(
        "seed = {seed}\n[box]\npacking_fraction = {eta}\nboundary = \"periodic\"\n[[species]]\ncount = {n}\nradius = 0.5\nmass = 1.0\n\
         [init]\nplacement = \"triangular\"\n[equilibration]\ncollisions = {equilibration}\n\
         [run]\ncollisions = {production}\nsample_interval = {}\nblocks = 20\n",
        run_time / samples_wanted
    );
    let mut run = Run::<2>::new(Config::parse(&text, NAME)?)?;
    run_to_end(&mut run, &mut Discard)?;
    let s = run.summary();
    Ok(Point {
        eta,
        z: s.compressibility,
        z_err: s.compressibility_error,
        n_particles: n,
        collisions: s.collisions,
        equilibration_per_particle: s.equilibration.collisions as f64 / n as f64,
    })
}

/// Runs the experiment.
pub fn run(options: &Options) -> Result<ExperimentResult, ExperimentError> {
    let (n, etas, per_particle): (usize, Vec<f64>, u64) = if options.quick {
        (256, vec![0.1, 0.3, 0.5, 0.65], 200)
    } else {
        (1024, vec![0.05, 0.1, 0.15, 0.2, 0.25, 0.3, 0.35, 0.4, 0.45, 0.5, 0.55, 0.6, 0.65, 0.68, 0.70], 1000)
    };
    let mut points = Vec::new();
    for (k, &eta) in etas.iter().enumerate() {
        // Dense states melt from the lattice slowly: equilibrate twice as long above η = 0.6.
        let equilibration = if eta > 0.6 { per_particle } else { per_particle / 2 } * n as u64;
        points.push(measure(eta, n, equilibration, per_particle * n as u64, options.seed + k as u64)?);
    }
    let checks: Vec<Check> = points.iter().filter_map(check_point).collect();

    let dir = ExperimentResult::plot_dir(&options.out, NAME)?;
    let curve =
        |f: fn(f64) -> f64, top: f64| (0..=140).map(|k| k as f64 * top / 140.0).map(|e| (e, f(e))).collect::<Vec<_>>();
    let top = etas.iter().copied().fold(0.0, f64::max) + 0.01;
    let z_chart = Chart {
        title: "Hard-disk equation of state".into(),
        x_label: "packing fraction η (dimensionless)".into(),
        y_label: "Z = βP/n (dimensionless)".into(),
        legend_left: true,
        series: vec![
            Series::errors(
                "collide (collision virial)",
                points.iter().map(|p| (p.eta, p.z)).collect(),
                points.iter().map(|p| p.z_err).collect(),
            ),
            Series::line("Henderson 1975", curve(z_henderson, top)),
            Series::line("Santos, López de Haro, Yuste 1995", curve(z_slhy, top)),
            Series::line("virial series to b₁₀ (Clisby & McCoy 2006)", curve(z_virial, top.min(0.45))),
        ],
    };
    let residual = |f: fn(f64) -> f64| points.iter().map(|p| (p.eta, p.z / f(p.eta) - 1.0)).collect::<Vec<_>>();
    let res_chart = Chart {
        title: "Relative residuals Z/Z_ref − 1".into(),
        x_label: "packing fraction η (dimensionless)".into(),
        y_label: "Z/Z_ref − 1 (dimensionless)".into(),
        legend_left: true,
        series: vec![
            Series::errors(
                "vs Henderson",
                residual(z_henderson),
                points.iter().map(|p| p.z_err / z_henderson(p.eta)).collect(),
            ),
            Series::points("vs SLHY", residual(z_slhy)),
            Series::line("zero", vec![(0.0, 0.0), (top, 0.0)]),
        ],
    };
    draw(&z_chart, &dir.join("z_of_eta.svg"))?;
    draw(&res_chart, &dir.join("residuals.svg"))?;
    Ok(ExperimentResult {
        name: NAME.into(),
        quick: options.quick,
        seed: options.seed,
        parameters: json!({
            "n_particles": n, "packing_fractions": etas, "boundary": "periodic", "kT": 1.0,
            "production_collisions_per_particle": per_particle,
            "equilibration_collisions_per_particle": "per_particle/2, doubled above η = 0.6",
        }),
        data: json!({
            "points": points,
            "references": points.iter().map(|p| json!({
                "eta": p.eta, "henderson": z_henderson(p.eta), "slhy": z_slhy(p.eta), "virial_b10": z_virial(p.eta),
            })).collect::<Vec<_>>(),
        }),
        checks,
        plots: vec!["z_of_eta.svg".into(), "residuals.svg".into()],
    })
}
