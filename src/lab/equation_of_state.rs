//! `equation_of_state`: the compressibility factor Z = βP/n from the collision virial, across
//! packing fractions, against the most accurate published equations of state — hard disks
//! (`--dimension 2`) or hard spheres (`--dimension 3`).
//!
//! Each state runs in a periodic box, equilibrated (the number of collisions per particle is
//! recorded), then measured; Z and its error come from the run summary (20 block averages).
//!
//! **Disks** start from a triangular lattice. References ([`crate::theory`]):
//! * η ≤ 0.2: the virial series through b₁₀ (Clisby & McCoy, J. Stat. Phys. 122, 15 (2006));
//!   its uncertainty is the first omitted term, estimated as b₁₁η¹⁰/(1 − η) with b₁₁ ≈ 11;
//! * 0.2 < η ≤ 0.65: Liu's stable-fluid equation of state (arXiv:2010.10624 (2020)), relative
//!   accuracy adopted 10⁻³ ([`Z_LIU_DISKS_ACCURACY`]); Henderson (1975) and Santos, López de
//!   Haro & Yuste (1995) are plotted beside it. Above η ≈ 0.69 the liquid–hexatic transition
//!   (Bernard & Krauth 2011) brings slow equilibration and strong finite-size effects: those
//!   states are measured and plotted, not judged.
//!
//! **Spheres**: a fluid branch η = 0.05–0.49 started from a simple cubic lattice (mechanically
//! unstable for hard spheres, it melts within a few collisions per particle; nucleation of the
//! crystal below freezing, η_f = 0.492, does not happen in these runs), against Hansen-Goos'
//! equation of state (J. Chem. Phys. 144, 164506 (2016)), relative accuracy 10⁻⁴
//! ([`Z_HANSEN_GOOS_ACCURACY`]); and an fcc crystal branch η = 0.55–0.72 started from a perfect
//! fcc crystal (N = 4k³ in a cube), against Speedy's fcc equation of state (J. Phys.: Condens.
//! Matter 10, 4387 (1998)), relative accuracy 10⁻³ ([`Z_SPEEDY_FCC_ACCURACY`]).
//! Carnahan–Starling is plotted beside the fluid.
//!
//! **Dense starts by compression** ([`Start::Compression`]): a lattice start is a crystal, so
//! the metastable fluid of spheres above freezing cannot start from one. Those states start
//! from a random dilute fluid (η = 0.3 spheres, 0.4 disks) compressed to their η at rate 0.01
//! (`[compress] target_packing_fraction`), then equilibrate and measure like the rest:
//! spheres at η = 0.50–0.53, judged against Hansen-Goos to 2·10⁻⁴
//! ([`Z_HANSEN_GOOS_METASTABLE_ACCURACY`]) — the Kolafa–Labík–Malijevský data it rests on reach
//! η ≈ 0.53 — beside the fcc branch from its lattice; and each such state must still be a
//! fluid at the end of its run (its Q₆ below the crystal threshold of the `jamming`
//! experiment: it did not freeze). Disks at η = 0.70 and 0.72 start both ways, from the
//! triangular lattice and from compression, and both are shown (not judged: no reference
//! states its accuracy there).
//!
//! Tolerance of every check: the 3σ-equivalent of an error estimated from 20 blocks (Student
//! t, 19 degrees of freedom: 3.45 standard errors), plus the reference's uncertainty, plus a
//! finite-size term |Z − 1|/N (the corrections of a periodic NVE system to the pressure are
//! O(1/N), with a coefficient of order |Z − 1|).

use super::plot::{Chart, Series, draw};
use super::stats::three_sigma_factor;
use super::{Check, ExperimentError, ExperimentResult, Options, run_to_end};
use crate::run::{Config, Discard, Run};
use crate::theory::{
    ETA_HANSEN_GOOS_METASTABLE, Z_HANSEN_GOOS_ACCURACY, Z_HANSEN_GOOS_METASTABLE_ACCURACY, Z_LIU_DISKS_ACCURACY,
    Z_SPEEDY_FCC_ACCURACY, contact_value, enskog_rate, z_carnahan_starling, z_hansen_goos, z_speedy_fcc,
};
pub use crate::theory::{z_henderson, z_liu_disks, z_slhy, z_virial};
use serde::{Deserialize, Serialize};
use serde_json::json;
use std::f64::consts::PI;

/// The experiment's name.
pub const NAME: &str = "equation_of_state";

/// Blocks for the error bars of every state.
pub const BLOCKS: usize = 20;

/// The phase a state is started in and measured as.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Phase {
    /// A fluid (disks: from a triangular lattice; spheres: from a simple cubic one).
    Fluid,
    /// An fcc crystal (spheres, from a perfect fcc lattice).
    Fcc,
}

/// How a state's particles were placed.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Start {
    /// On the lattice of its phase.
    Lattice,
    /// At random in a dilute fluid, then compressed to the state's η.
    Compression,
}

/// One measured state.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Point {
    /// 2 (disks) or 3 (spheres).
    pub dimension: usize,
    /// Packing fraction.
    pub eta: f64,
    /// Compressibility factor.
    #[serde(rename = "Z")]
    pub z: f64,
    /// Its standard error.
    #[serde(rename = "Z_err")]
    pub z_err: f64,
    /// The phase.
    pub phase: Phase,
    /// N.
    pub n_particles: usize,
    /// Measured collisions.
    pub collisions: u64,
    /// Equilibration collisions per particle.
    pub equilibration_per_particle: f64,
    /// How it started.
    pub start: Start,
    /// The bond order at the end of the run (Ψ₆ of disks, Q₆ of spheres; see
    /// [`crate::observe::order`]).
    pub order: f64,
}

/// A reference equation of state for a point: its name, Z, and Z's absolute uncertainty.
pub fn reference(p: &Point) -> Option<(&'static str, f64, f64)> {
    match (p.dimension, p.phase) {
        (2, _) if p.eta <= 0.2 => {
            Some(("the virial series (Clisby & McCoy 2006)", z_virial(p.eta), 11.0 * p.eta.powi(10) / (1.0 - p.eta)))
        }
        (2, _) if p.eta <= 0.65 => {
            let z = z_liu_disks(p.eta);
            Some(("Liu (2020)", z, Z_LIU_DISKS_ACCURACY * z))
        }
        (3, Phase::Fluid) if p.eta <= 0.49 => {
            let z = z_hansen_goos(p.eta);
            Some(("Hansen-Goos (2016)", z, Z_HANSEN_GOOS_ACCURACY * z))
        }
        (3, Phase::Fluid) if p.eta <= ETA_HANSEN_GOOS_METASTABLE => {
            let z = z_hansen_goos(p.eta);
            Some(("Hansen-Goos (2016), metastable fluid", z, Z_HANSEN_GOOS_METASTABLE_ACCURACY * z))
        }
        (3, Phase::Fcc) if (0.545..=0.725).contains(&p.eta) => {
            let z = z_speedy_fcc(p.eta);
            Some(("Speedy's fcc (1998)", z, Z_SPEEDY_FCC_ACCURACY * z))
        }
        _ => None,
    }
}

/// The check for one point, or `None` where no reference states its accuracy.
pub fn check_point(p: &Point) -> Option<Check> {
    let (name, z_ref, uncertainty) = reference(p)?;
    let finite_size = (p.z - 1.0).abs() / p.n_particles as f64;
    let k = three_sigma_factor(BLOCKS);
    let phase = if p.phase == Phase::Fcc { " (fcc)" } else { "" };
    Some(Check::within(
        &format!("Z at η = {}{phase} vs {name}", p.eta),
        p.z,
        p.z_err,
        z_ref,
        k * p.z_err + uncertainty + finite_size,
        &format!(
            "3σ-equivalent (Student t, 19 dof: 3.45 standard errors) + the reference's uncertainty ({}) + |Z−1|/N finite size",
            if p.dimension == 2 && p.eta <= 0.2 {
                "first omitted virial term b₁₁η¹⁰/(1−η), b₁₁ ≈ 11".to_string()
            } else {
                format!("{:e} relative", uncertainty / z_ref)
            }
        ),
    ))
}

/// For a sphere fluid above freezing (η > 0.49): that it is still a fluid at the end of its
/// run — its Q₆ below the crystal threshold of [`super::jamming::crystal_threshold`] — so that
/// its pressure is the metastable fluid's. `None` for other states.
pub fn check_still_fluid(p: &Point) -> Option<Check> {
    if !(p.dimension == 3 && p.phase == Phase::Fluid && p.eta > 0.49) {
        return None;
    }
    let (perfect, threshold) = super::jamming::crystal_threshold(3);
    Some(Check::at_most(
        &format!("Q₆ at the end of the metastable fluid at η = {}: still a fluid", p.eta),
        p.order,
        f64::NAN,
        threshold,
        &format!(
            "half the perfect hcp crystal's {perfect}: a fluid's global Q₆ is about 1/√bonds (≈ 0.01 here); a state that froze during its run would measure the crystal's pressure, not the fluid's"
        ),
    ))
}

/// Runs one state point of `n` particles in `d` dimensions, from the lattice of its phase or
/// by compression ([`Start`]).
#[allow(clippy::too_many_arguments)]
pub fn measure(
    d: usize,
    phase: Phase,
    start: Start,
    eta: f64,
    n: usize,
    equilibration: u64,
    production: u64,
    seed: u64,
) -> Result<Point, ExperimentError> {
    // The sampling interval (time between rows) is a few mean free times; Enskog's estimate
    // sets it (only for scheduling).
    let number_density = if d == 2 { 4.0 * eta / PI } else { 6.0 * eta / PI };
    let tau = 1.0 / enskog_rate(d, number_density, 1.0, contact_value(d, eta.min(0.5)), 1.0, 1.0);
    let samples_wanted = 100.0;
    let run_time = 2.0 * production as f64 / n as f64 * tau;
    let placement = match (start, d, phase) {
        (Start::Compression, ..) => "random",
        (_, 2, _) => "triangular",
        (_, _, Phase::Fluid) => "simple_cubic",
        (_, _, Phase::Fcc) => "fcc",
    };
    let (box_eta, compress) = match start {
        Start::Lattice => (eta, String::new()),
        Start::Compression => (
            if d == 2 { COMPRESSED_FROM_2D } else { COMPRESSED_FROM_3D },
            format!("[compress]\nrate = {COMPRESSION_RATE}\ntarget_packing_fraction = {eta}\n"),
        ),
    };
    let text = format!(
        "dimension = {d}\nseed = {seed}\n[box]\npacking_fraction = {box_eta}\nboundary = \"periodic\"\n[[species]]\ncount = {n}\nradius = 0.5\nmass = 1.0\n\
         [init]\nplacement = \"{placement}\"\n{compress}[equilibration]\ncollisions = {equilibration}\n\
         [run]\ncollisions = {production}\nsample_interval = {}\nblocks = {BLOCKS}\n",
        run_time / samples_wanted
    );
    let config = Config::parse(&text, NAME)?;
    let (s, order) = if d == 3 { summary_of::<3>(config)? } else { summary_of::<2>(config)? };
    Ok(Point {
        dimension: d,
        eta,
        z: s.compressibility,
        z_err: s.compressibility_error,
        phase,
        n_particles: n,
        collisions: s.collisions,
        equilibration_per_particle: s.equilibration.collisions as f64 / n as f64,
        start,
        order,
    })
}

/// The packing fraction a compressed state of disks starts from (random placement).
pub const COMPRESSED_FROM_2D: f64 = 0.4;
/// The packing fraction a compressed state of spheres starts from (random placement).
pub const COMPRESSED_FROM_3D: f64 = 0.3;
/// The compression rate of a compressed state (relative growth of a radius per unit time).
pub const COMPRESSION_RATE: f64 = 0.01;

/// The run's summary and the bond order of its final state.
fn summary_of<const D: usize>(config: Config) -> Result<(crate::run::Summary, f64), ExperimentError> {
    let mut run = Run::<D>::new(config)?;
    run_to_end(&mut run, &mut Discard)?;
    let order = crate::observe::order::bond_order(&run.sim, crate::observe::order::BOND_CUTOFF).value;
    Ok((run.summary(), order))
}

/// The states an experiment measures: (phase, start, η, N) in `d` dimensions.
fn states(d: usize, quick: bool) -> Vec<(Phase, Start, f64, usize)> {
    let with = |phase: Phase, start: Start, n: usize, etas: &[f64]| {
        etas.iter().map(|&e| (phase, start, e, n)).collect::<Vec<_>>()
    };
    use Start::{Compression, Lattice};
    match (d, quick) {
        (2, true) => {
            [with(Phase::Fluid, Lattice, 256, &[0.1, 0.3, 0.5, 0.65]), with(Phase::Fluid, Compression, 256, &[0.7])]
                .concat()
        }
        (2, false) => [
            with(
                Phase::Fluid,
                Lattice,
                1024,
                &[0.05, 0.1, 0.15, 0.2, 0.25, 0.3, 0.35, 0.4, 0.45, 0.5, 0.55, 0.6, 0.65, 0.68, 0.70, 0.72],
            ),
            with(Phase::Fluid, Compression, 1024, &[0.70, 0.72]),
        ]
        .concat(),
        // Spheres: the fluid from a simple cubic lattice of k³ (and above freezing by
        // compression), the crystal from fcc of 4k³.
        (_, true) => [
            with(Phase::Fluid, Lattice, 512, &[0.2, 0.45]),
            with(Phase::Fluid, Compression, 512, &[0.52]),
            with(Phase::Fcc, Lattice, 500, &[0.6]),
        ]
        .concat(),
        (_, false) => [
            with(Phase::Fluid, Lattice, 2197, &[0.05, 0.1, 0.2, 0.3, 0.35, 0.4, 0.45, 0.49]),
            with(Phase::Fluid, Compression, 2197, &[0.5, 0.51, 0.52, 0.53]),
            with(Phase::Fcc, Lattice, 2048, &[0.55, 0.58, 0.6, 0.62, 0.65, 0.68, 0.7, 0.72]),
        ]
        .concat(),
    }
}

/// Runs the experiment.
pub fn run(options: &Options) -> Result<ExperimentResult, ExperimentError> {
    let d = options.dimension;
    let per_particle: u64 = if options.quick() { 200 } else { 1000 };
    let mut points = Vec::new();
    for (k, &(phase, start, eta, n)) in states(d, options.quick()).iter().enumerate() {
        // Dense disks melt from the lattice slowly: equilibrate twice as long above η = 0.6; a
        // compressed state relaxes from the compression's excess pressure slower still: four
        // times as long.
        let equilibration = match start {
            Start::Compression => 2 * per_particle,
            Start::Lattice if d == 2 && eta > 0.6 => per_particle,
            Start::Lattice => per_particle / 2,
        } * n as u64;
        points.push(measure(d, phase, start, eta, n, equilibration, per_particle * n as u64, options.seed + k as u64)?);
    }
    let checks: Vec<Check> = points.iter().flat_map(|p| [check_point(p), check_still_fluid(p)]).flatten().collect();

    let dir = options.plot_dir(NAME)?;
    let curve = |f: &dyn Fn(f64) -> f64, from: f64, to: f64| {
        (0..=140).map(|k| from + k as f64 * (to - from) / 140.0).map(|e| (e, f(e))).collect::<Vec<_>>()
    };
    let top = points.iter().map(|p| p.eta).fold(0.0, f64::max) + 0.01;
    let measured = |phase: Phase, start: Start, label: &str| {
        let of: Vec<&Point> = points.iter().filter(|p| p.phase == phase && p.start == start).collect();
        Series::errors(label, of.iter().map(|p| (p.eta, p.z)).collect(), of.iter().map(|p| p.z_err).collect())
    };
    let (title, y_label, mut series) = if d == 2 {
        (
            "Hard-disk equation of state",
            "Z = βP/n (dimensionless)",
            vec![
                measured(Phase::Fluid, Start::Lattice, "collide (collision virial), from the lattice"),
                measured(Phase::Fluid, Start::Compression, "collide, from compression"),
                Series::line("Liu 2020 (stable fluid)", curve(&z_liu_disks, 0.0, top.min(0.7))),
                Series::line("Henderson 1975", curve(&z_henderson, 0.0, top)),
                Series::line("Santos, López de Haro, Yuste 1995", curve(&z_slhy, 0.0, top)),
                Series::line("virial series to b₁₀ (Clisby & McCoy 2006)", curve(&z_virial, 0.0, top.min(0.45))),
            ],
        )
    } else {
        (
            "Hard-sphere equation of state",
            "Z = βP/n (dimensionless)",
            vec![
                measured(Phase::Fluid, Start::Lattice, "collide, fluid (from simple cubic)"),
                measured(Phase::Fluid, Start::Compression, "collide, metastable fluid (from compression)"),
                measured(Phase::Fcc, Start::Lattice, "collide, fcc crystal"),
                Series::line("Hansen-Goos 2016 (fluid)", curve(&z_hansen_goos, 0.0, 0.55)),
                Series::line("Carnahan–Starling 1969", curve(&z_carnahan_starling, 0.0, 0.55)),
                Series::line("Speedy 1998 (fcc)", curve(&z_speedy_fcc, 0.545, top.max(0.6))),
            ],
        )
    };
    series.retain(|s| !s.points.is_empty());
    let z_chart = Chart {
        title: title.into(),
        x_label: "packing fraction η (dimensionless)".into(),
        y_label: y_label.into(),
        legend_left: true,
        series,
    };
    let judged: Vec<(&Point, f64, f64)> =
        points.iter().filter_map(|p| reference(p).map(|(_, z, u)| (p, z, u))).collect();
    let res_chart = Chart {
        title: "Relative residuals Z/Z_ref − 1 against each state's reference".into(),
        x_label: "packing fraction η (dimensionless)".into(),
        y_label: "Z/Z_ref − 1 (dimensionless)".into(),
        legend_left: true,
        series: vec![
            Series::errors(
                "measured (error bars: standard errors)",
                judged.iter().map(|(p, z, _)| (p.eta, p.z / z - 1.0)).collect(),
                judged.iter().map(|(p, z, _)| p.z_err / z).collect(),
            ),
            Series::points("reference's uncertainty", judged.iter().map(|(p, z, u)| (p.eta, u / z)).collect()),
            Series::line("zero", vec![(0.0, 0.0), (top, 0.0)]),
        ],
    };
    draw(&z_chart, &dir.join("z_of_eta.svg"))?;
    draw(&res_chart, &dir.join("residuals.svg"))?;
    let references: Vec<serde_json::Value> = points
        .iter()
        .map(|p| {
            if d == 2 {
                json!({ "eta": p.eta, "liu": z_liu_disks(p.eta), "henderson": z_henderson(p.eta),
                        "slhy": z_slhy(p.eta), "virial_b10": z_virial(p.eta) })
            } else if p.phase == Phase::Fluid {
                json!({ "eta": p.eta, "hansen_goos": z_hansen_goos(p.eta), "carnahan_starling": z_carnahan_starling(p.eta) })
            } else {
                json!({ "eta": p.eta, "speedy_fcc": z_speedy_fcc(p.eta) })
            }
        })
        .collect();
    let etas: Vec<f64> = points.iter().map(|p| p.eta).collect();
    Ok(options.result(
        NAME,
        json!({
            "dimension": d, "n_particles": points.iter().map(|p| p.n_particles).collect::<Vec<_>>(),
            "packing_fractions": etas, "boundary": "periodic", "kT": 1.0,
            "production_collisions_per_particle": per_particle,
            "equilibration_collisions_per_particle": "per_particle/2 (disks: doubled above η = 0.6)",
        }),
        json!({ "points": points, "references": references }),
        checks,
        vec!["z_of_eta.svg".into(), "residuals.svg".into()],
    ))
}
