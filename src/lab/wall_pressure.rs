//! `wall_pressure`: the pressure on hard walls, three ways.
//!
//! (a) **Ideal-gas limit** — one disk between walls: ½(P_x + P_y) = kT/((L_x − σ)(L_y − σ))
//!     exactly in the time average (physics reference sheet); tolerance: one hit more or less
//!     on each axis, ½·m(|v_x|/(L_y − σ) + |v_y|/(L_x − σ))/t.
//! (b) **Walled-box virial identity** at η = 0.4: ½(P_x + P_y)(L_x − σ)(L_y − σ) =
//!     N·kT + (1/2t)·Σσ|Δp|, sample by sample; tolerance 3 block-average standard errors of
//!     the difference (as everywhere a block error is used, the 3σ-equivalent Student-t
//!     factor for 20 blocks, 3.45).
//! (c) **Across densities**: walls adsorb disks, so the bulk density of a closed box is below
//!     N/A_acc and the wall pressure sits below the bulk equation of state at N/A_acc by
//!     O(σ/L). The density is therefore measured in the bulk region — every point at least 5σ
//!     from every wall (the layering at a hard wall decays within a few σ) — and the wall
//!     pressure compared with Henderson's EOS at that density: P = n·kT·Z_H(η_bulk), for
//!     η ≤ 0.5 where Henderson is good to 0.5 %. The bulk count fluctuates by slow diffusive
//!     exchange with the wall layers (a run spans only a few of those times), so its tolerance
//!     is the largest Student-t 3σ-equivalent over 20, 10 and 5 blocks. Tolerance: the wall
//!     pressure's 3σ-equivalent and the EOS pressure's (through the density's), in quadrature,
//!     + 0.5 %.

use super::plot::{Chart, Series, draw};
use super::stats::{conservative_tolerance, three_sigma_factor};
use super::{Check, ExperimentError, ExperimentResult, Options, run_to_end};
use crate::engine::{Outcome, Particle, Simulation};
use crate::observe::{Observer, block_error};
use crate::run::{Config, Run};
use crate::theory::{g_henderson, gamma_enskog, z_henderson, z_slhy};
use nalgebra::Vector2;
use serde::{Deserialize, Serialize};
use serde_json::json;
use std::f64::consts::PI;

/// The experiment's name.
pub const NAME: &str = "wall_pressure";

/// Distance from the walls beyond which the fluid counts as bulk (in σ).
pub const BULK_MARGIN: f64 = 5.0;

/// One walled state.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct WalledState {
    /// Nominal packing fraction Σπr²/A.
    pub eta: f64,
    /// N.
    pub n_particles: usize,
    /// kT.
    pub kt: f64,
    /// Mean of the four wall pressures.
    pub p_wall: f64,
    /// Its standard error.
    pub p_wall_err: f64,
    /// Collision-virial pressure (walled-box identity).
    pub p_virial: f64,
    /// Its standard error.
    pub p_virial_err: f64,
    /// Mean of (wall − virial) per sample.
    pub difference: f64,
    /// Its standard error.
    pub difference_err: f64,
    /// Number density in the bulk region (≥ 5σ from every wall).
    pub n_mid: f64,
    /// Its 3σ-equivalent tolerance (conservative blocking, see the module docs).
    pub n_mid_tolerance: f64,
    /// N/A_acc.
    pub n_accessible: f64,
}

impl WalledState {
    /// Packing fraction in the middle of the box (σ = 1).
    pub fn eta_mid(&self) -> f64 {
        self.n_mid * PI / 4.0
    }
    /// Henderson's pressure at the bulk density, and its tolerance through the density's.
    pub fn p_eos_mid(&self) -> (f64, f64) {
        let p = |n: f64| n * self.kt * z_henderson(n * PI / 4.0);
        let h = 1e-6 * self.n_mid;
        let slope = (p(self.n_mid + h) - p(self.n_mid - h)) / (2.0 * h);
        (p(self.n_mid), slope.abs() * self.n_mid_tolerance)
    }
}

/// The number density of the bulk region — every point at least [`BULK_MARGIN`] from every
/// wall — at every sample.
struct BulkDensity {
    lengths: Vector2<f64>,
    densities: Vec<f64>,
}

impl Observer<2> for BulkDensity {
    fn observe(&mut self, sim: &Simulation<2>, outcome: &Outcome<2>) {
        if let Outcome::Sample = outcome {
            let (l, m) = (self.lengths, BULK_MARGIN);
            let inside =
                sim.wrapped_positions().iter().filter(|r| (0..2).all(|a| r[a] >= m && r[a] <= l[a] - m)).count();
            self.densities.push(inside as f64 / ((l[0] - 2.0 * m) * (l[1] - 2.0 * m)));
        }
    }
}

/// Runs a walled box of `n` disks at nominal packing fraction `eta`.
pub fn measure(eta: f64, n: usize, collisions_per_particle: u64, seed: u64) -> Result<WalledState, ExperimentError> {
    let production = collisions_per_particle * n as u64;
    let text = format!(
        "seed = {seed}\n[box]\npacking_fraction = {eta}\nboundary = \"wall\"\n[[species]]\ncount = {n}\nradius = 0.5\nmass = 1.0\n\
         [init]\nplacement = \"square\"\n[equilibration]\ncollisions = {}\n[run]\ncollisions = {production}\nsample_interval = 1.0\n",
        production / 2
    );
    let mut config = Config::parse(&text, NAME)?;
    // About 200 samples: the sampling interval from Enskog's collision rate (scheduling only).
    let rate = gamma_enskog(eta, g_henderson(eta));
    config.run.sample_interval = 2.0 * collisions_per_particle as f64 / rate / 200.0;
    let mut run = Run::<2>::new(config)?;
    let lengths = run.sim.sim_box().lengths;
    let mut bulk = BulkDensity { lengths, densities: Vec::new() };
    run_to_end(&mut run, &mut bulk)?;
    let mid = bulk.densities;
    let s = run.summary();
    let samples = &run.thermo.samples;
    let walls: Vec<f64> = samples
        .iter()
        .map(|x| {
            let (a, b) = (x.pressure_walls[0].expect("walls"), x.pressure_walls[1].expect("walls"));
            0.25 * (a[0] + a[1] + b[0] + b[1])
        })
        .collect();
    let diffs: Vec<f64> = walls.iter().zip(samples).map(|(w, x)| w - x.pressure_virial).collect();
    let (_, p_wall_err) = block_error(&walls, 20);
    let (difference, difference_err) = block_error(&diffs, 20);
    let (n_mid, n_mid_tolerance) = conservative_tolerance(&mid);
    let p_wall = s.wall_pressures.iter().map(|w| w.pressure).sum::<f64>() / s.wall_pressures.len() as f64;
    Ok(WalledState {
        eta,
        n_particles: n,
        kt: s.kT,
        p_wall,
        p_wall_err,
        p_virial: s.pressure_virial,
        p_virial_err: s.pressure_virial_error,
        difference,
        difference_err,
        n_mid,
        n_mid_tolerance,
        n_accessible: n as f64 / ((lengths[0] - 1.0) * (lengths[1] - 1.0)),
    })
}

/// The impulse each walled axis received (both walls), summed in the order of the events.
struct AxisImpulses([f64; 2]);

impl Observer<2> for AxisImpulses {
    fn observe(&mut self, _: &Simulation<2>, outcome: &Outcome<2>) {
        if let Outcome::Wall { axis, impulse, .. } = outcome {
            self.0[*axis] += impulse;
        }
    }
}

/// One disk between walls for a time `t_end`: (½(P_x + P_y), kT/A_acc, tolerance).
pub fn one_disk(t_end: f64) -> Result<(f64, f64, f64), ExperimentError> {
    let disk = Particle {
        position: Vector2::new(3.1, 2.2),
        velocity: Vector2::new(0.8123, -0.5839),
        time: 0.0,
        radius: 0.5,
        mass: 1.0,
        species: 0,
        events: 0,
    };
    let (lx, ly) = (9.0, 7.0);
    // No equilibration, no samples (the interval is past the end): the run is the flight.
    let text = format!(
        "seed = 1\n[box]\nsize = [{lx:?}, {ly:?}]\nboundary = \"wall\"\n[[species]]\ncount = 1\nradius = 0.5\nmass = 1.0\n\
         [run]\ntime = {t_end:?}\nsample_interval = {:?}\n",
        2.0 * t_end
    );
    let mut run = Run::<2>::from_particles(Config::parse(&text, NAME)?, vec![disk.clone()])?;
    let mut impulse = AxisImpulses([0.0; 2]);
    run_to_end(&mut run, &mut impulse)?;
    let impulse = impulse.0;
    let (t, ax, ay) = (run.sim.time(), lx - 1.0, ly - 1.0);
    let measured = 0.5 * (impulse[0] / 2.0 / (t * ay) + impulse[1] / 2.0 / (t * ax));
    let tolerance = 0.5 * disk.mass * (disk.velocity.x.abs() / ay + disk.velocity.y.abs() / ax) / t;
    Ok((measured, run.sim.kt() / (ax * ay), tolerance))
}

/// The ideal-gas check of the one-disk run.
pub fn ideal_gas_check(measured: f64, expected: f64, tolerance: f64) -> Check {
    Check::within(
        "ideal-gas limit, one disk: ½(Px + Py)",
        measured,
        f64::NAN,
        expected,
        tolerance,
        "exact kT/((Lx−σ)(Ly−σ)) up to one partial flight per axis: ½m(|vx|/(Ly−σ) + |vy|/(Lx−σ))/t",
    )
}

/// The check of a state against Henderson at its bulk density (η_bulk ≤ 0.5), if any.
pub fn eos_check(s: &WalledState) -> Option<Check> {
    if s.eta_mid() > 0.5 {
        return None;
    }
    let (p_eos, p_eos_tolerance) = s.p_eos_mid();
    let statistical = (three_sigma_factor(20) * s.p_wall_err).hypot(p_eos_tolerance);
    Some(Check::within(
        &format!("wall pressure at η = {} vs Henderson at the bulk density η_bulk = {:.4}", s.eta, s.eta_mid()),
        s.p_wall,
        s.p_wall_err,
        p_eos,
        statistical + 0.005 * p_eos,
        "3σ-equivalents of the wall pressure (20 blocks, Student t) and of the EOS through the bulk density (conservative blocking), in quadrature, + Henderson's 0.5 %",
    ))
}

/// The identity check of a state.
pub fn identity_check(s: &WalledState) -> Check {
    Check::within(
        &format!("walled-box virial identity at η = {}: wall − virial pressure", s.eta),
        s.difference,
        s.difference_err,
        0.0,
        three_sigma_factor(20) * s.difference_err,
        "3σ-equivalent for a 20-block error (Student t: 3.45 standard errors) of the per-sample difference; exact identity",
    )
}

/// Runs the experiment.
pub fn run(options: &Options) -> Result<ExperimentResult, ExperimentError> {
    let (n, per_particle, etas, t_one) = if options.quick {
        (400, 200, vec![0.2, 0.4], 2.0e4)
    } else {
        (1600, 500, vec![0.1, 0.2, 0.3, 0.4, 0.5, 0.6], 2.0e5)
    };
    let (p1, p1_expected, p1_tol) = one_disk(t_one)?;
    let mut checks = vec![ideal_gas_check(p1, p1_expected, p1_tol)];
    let mut states = Vec::new();
    for (k, &eta) in etas.iter().enumerate() {
        states.push(measure(eta, n, per_particle, options.seed + k as u64)?);
    }
    let at_04 =
        states.iter().find(|s| (s.eta - 0.4).abs() < 1e-12).ok_or(ExperimentError::Missing("the state at η = 0.4"))?;
    checks.push(identity_check(at_04));
    checks.extend(states.iter().filter_map(eos_check));

    let dir = ExperimentResult::plot_dir(&options.out, NAME)?;
    let top = states.iter().map(|s| s.eta_mid()).fold(0.0, f64::max) + 0.02;
    let eos = |z: fn(f64) -> f64| {
        (1..=120).map(|k| k as f64 * top / 120.0).map(|e| (e, 4.0 * e / PI * z(e))).collect::<Vec<_>>()
    };
    let chart = Chart {
        title: format!("Pressure in a walled box (N = {n})"),
        x_label: "packing fraction η (bulk density; nominal for the virial points)".into(),
        y_label: "pressure P (kT/σ²)".into(),
        legend_left: true,
        series: vec![
            Series::errors(
                "wall impulses vs bulk density",
                states.iter().map(|s| (s.eta_mid(), s.p_wall)).collect(),
                states.iter().map(|s| s.p_wall_err).collect(),
            ),
            Series::errors(
                "collision virial vs nominal N/A",
                states.iter().map(|s| (s.eta, s.p_virial)).collect(),
                states.iter().map(|s| s.p_virial_err).collect(),
            ),
            Series::line("Henderson 1975 (bulk EOS)", eos(z_henderson)),
            Series::line("Santos, López de Haro, Yuste 1995", eos(z_slhy)),
        ],
    };
    draw(&chart, &dir.join("pressure.svg"))?;
    Ok(ExperimentResult {
        name: NAME.into(),
        quick: options.quick,
        seed: options.seed,
        parameters: json!({
            "n_particles": n, "packing_fractions": etas, "boundary": "wall", "kT": 1.0,
            "production_collisions_per_particle": per_particle, "one_disk_time": t_one,
            "bulk_region": "at least 5σ from every wall",
        }),
        data: json!({
            "one_disk": {"measured": p1, "expected": p1_expected, "tolerance": p1_tol},
            "states": states,
            "eta_mid": states.iter().map(|s| s.eta_mid()).collect::<Vec<_>>(),
        }),
        checks,
        plots: vec!["pressure.svg".into()],
    })
}
