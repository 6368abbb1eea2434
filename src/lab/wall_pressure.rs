//! `wall_pressure`: the pressure on hard walls, three ways — disks or spheres.
//!
//! (a) **Ideal-gas limit** — one particle between walls: the mean over axes of the wall
//!     pressures is kT/Π(L_a − σ) exactly in the time average (physics reference sheet);
//!     tolerance: one hit more or less on each axis, (1/d)·Σ_a m|v_a|/(t·A_a), A_a the
//!     accessible area of the walls normal to a.
//! (b) **Walled-box virial identity** at η = 0.4 (disks) or 0.3 (spheres): the mean wall
//!     pressure times Π(L_a − σ) equals N·kT + (1/(d·t))·Σσ|Δp|, sample by sample; tolerance
//!     3 block-average standard errors of the difference (as everywhere a block error is used,
//!     the 3σ-equivalent Student-t factor for 20 blocks, 3.45).
//! (c) **Across densities**: walls adsorb particles, so the bulk density of a closed box is
//!     below N/V_acc and the wall pressure sits below the bulk equation of state at N/V_acc by
//!     O(σ/L). The density is therefore measured in the bulk region — every point at least 5σ
//!     from every wall (the layering at a hard wall decays within a few σ) — and compared with
//!     the most accurate equation of state at that density, P = n·kT·Z(η_bulk): Liu's for
//!     disks (η ≤ 0.65), Hansen-Goos' for spheres (η ≤ 0.49). The pressure compared is that
//!     of the *middle of each wall*: the impulses of the hits at least 5σ from every other
//!     wall, per time and per area of that middle. Where two walls meet, the pressure along
//!     one wall is the tangential pressure of the other's adsorbed layers, not the bulk
//!     pressure (their difference integrates to the wall tension), so the mean over a whole
//!     wall differs from the bulk pressure by O(σ/L): +3 % for disks at η = 0.6 (N = 1600),
//!     +6 % for spheres at η = 0.3 (N = 4096). In the middle of a wall the normal pressure is
//!     the bulk pressure (mechanical equilibrium). Both counts fluctuate by slow exchange with
//!     the wall layers (a run spans only a few of those times), so their tolerances are the
//!     largest Student-t 3σ-equivalent over 20, 10 and 5 blocks. Tolerance: the two
//!     3σ-equivalents, in quadrature, + the reference's relative accuracy.

use super::plot::{Chart, Series, draw};
use super::stats::{conservative_tolerance, three_sigma_factor};
use super::{Check, ExperimentError, ExperimentResult, Options, run_to_end};
use crate::engine::{Outcome, Particle, Simulation};
use crate::observe::{Observer, block_error};
use crate::run::{Config, Run};
use crate::theory::{
    Z_HANSEN_GOOS_ACCURACY, Z_LIU_DISKS_ACCURACY, contact_value, enskog_rate, z_hansen_goos, z_henderson, z_liu_disks,
};
use nalgebra::SVector;
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
    /// 2 (disks) or 3 (spheres).
    pub dimension: usize,
    /// Nominal packing fraction Σ V(R)/V.
    pub eta: f64,
    /// N.
    pub n_particles: usize,
    /// kT.
    pub kt: f64,
    /// Mean of the 2d wall pressures.
    pub p_wall: f64,
    /// Its standard error.
    pub p_wall_err: f64,
    /// The pressure on the middle of the walls (hits at least 5σ from every other wall).
    pub p_middle: f64,
    /// Its 3σ-equivalent tolerance (conservative blocking, see the module docs).
    pub p_middle_tolerance: f64,
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
    /// N/V_acc.
    pub n_accessible: f64,
}

/// The reference equation of state of the fluid in `d` dimensions, its relative accuracy, the
/// densest packing fraction it is checked at, and its name.
pub fn reference(d: usize) -> (fn(f64) -> f64, f64, f64, &'static str) {
    if d == 2 {
        (z_liu_disks, Z_LIU_DISKS_ACCURACY, 0.65, "Liu (2020)")
    } else {
        (z_hansen_goos, Z_HANSEN_GOOS_ACCURACY, 0.49, "Hansen-Goos (2016)")
    }
}

/// The packing fraction of unit-diameter particles at number density `n` in `d` dimensions.
fn eta_of(d: usize, n: f64) -> f64 {
    if d == 2 { n * PI / 4.0 } else { n * PI / 6.0 }
}

impl WalledState {
    /// Packing fraction in the middle of the box (σ = 1).
    pub fn eta_mid(&self) -> f64 {
        eta_of(self.dimension, self.n_mid)
    }
    /// The reference pressure at the bulk density, and its tolerance through the density's.
    pub fn p_eos_mid(&self) -> (f64, f64) {
        let (z, _, _, _) = reference(self.dimension);
        let p = |n: f64| n * self.kt * z(eta_of(self.dimension, n));
        let h = 1e-6 * self.n_mid;
        let slope = (p(self.n_mid + h) - p(self.n_mid - h)) / (2.0 * h);
        (p(self.n_mid), slope.abs() * self.n_mid_tolerance)
    }
}

/// The bulk region at every sample: the number density of every point at least
/// [`BULK_MARGIN`] from every wall, and the pressure on the middle of the walls since the last
/// sample (the impulses of hits at least [`BULK_MARGIN`] from every other wall, per time and
/// per area of those middles).
struct Bulk<const D: usize> {
    lengths: SVector<f64, D>,
    densities: Vec<f64>,
    pressures: Vec<f64>,
    impulse: f64,
    since: f64,
}

impl<const D: usize> Bulk<D> {
    fn inside(&self, r: &SVector<f64, D>, except: Option<usize>) -> bool {
        let m = BULK_MARGIN;
        (0..D).all(|a| Some(a) == except || (r[a] >= m && r[a] <= self.lengths[a] - m))
    }
}

impl<const D: usize> Observer<D> for Bulk<D> {
    fn observe(&mut self, sim: &Simulation<D>, outcome: &Outcome<D>) {
        let (l, m) = (self.lengths, BULK_MARGIN);
        match outcome {
            Outcome::Wall { i, axis, impulse, .. } => {
                if self.inside(&sim.particles()[*i].position_at(sim.time()), Some(*axis)) {
                    self.impulse += impulse;
                }
            }
            Outcome::Sample => {
                let inside = sim.wrapped_positions().iter().filter(|r| self.inside(r, None)).count();
                let volume: f64 = (0..D).map(|a| l[a] - 2.0 * m).product();
                self.densities.push(inside as f64 / volume);
                // Two walls normal to each axis, each with a middle of Π_{b≠a}(L_b − 2m).
                let area: f64 = (0..D).map(|a| 2.0 * volume / (l[a] - 2.0 * m)).sum();
                self.pressures.push(self.impulse / ((sim.time() - self.since) * area));
                (self.impulse, self.since) = (0.0, sim.time());
            }
            _ => {}
        }
    }
}

/// Runs a walled box of `n` particles in `d` dimensions at nominal packing fraction `eta`.
pub fn measure(
    d: usize,
    eta: f64,
    n: usize,
    collisions_per_particle: u64,
    seed: u64,
) -> Result<WalledState, ExperimentError> {
    let production = collisions_per_particle * n as u64;
    let lattice = if d == 2 { "square" } else { "simple_cubic" };
    let text = format!(
        "dimension = {d}\nseed = {seed}\n[box]\npacking_fraction = {eta}\nboundary = \"wall\"\n[[species]]\ncount = {n}\nradius = 0.5\nmass = 1.0\n\
         [init]\nplacement = \"{lattice}\"\n[equilibration]\ncollisions = {}\n[run]\ncollisions = {production}\nsample_interval = 1.0\n",
        production / 2
    );
    let mut config = Config::parse(&text, NAME)?;
    // About 200 samples: the sampling interval from Enskog's collision rate (scheduling only).
    let density = if d == 2 { 4.0 * eta / PI } else { 6.0 * eta / PI };
    let rate = enskog_rate(d, density, 1.0, contact_value(d, eta), 1.0, 1.0);
    config.run.sample_interval = 2.0 * collisions_per_particle as f64 / rate / 200.0;
    if d == 3 { measure_in::<3>(config, eta, n) } else { measure_in::<2>(config, eta, n) }
}

fn measure_in<const D: usize>(config: Config, eta: f64, n: usize) -> Result<WalledState, ExperimentError> {
    let mut run = Run::<D>::new(config)?;
    let lengths = run.sim.sim_box().lengths;
    if (0..D).any(|a| lengths[a] <= 2.0 * BULK_MARGIN + 1.0) {
        return Err(ExperimentError::Missing("a bulk region: the box is too small for one 5σ from every wall"));
    }
    let Ok(_) = run.equilibrate(&mut crate::run::Discard);
    let mut bulk = Bulk { lengths, densities: Vec::new(), pressures: Vec::new(), impulse: 0.0, since: run.sim.time() };
    run_to_end(&mut run, &mut bulk)?;
    let mid = bulk.densities;
    let (p_middle, p_middle_tolerance) = conservative_tolerance(&bulk.pressures);
    let s = run.summary();
    let samples = &run.thermo.samples;
    let walls: Vec<f64> = samples
        .iter()
        .map(|x| {
            let sum: f64 = x.pressure_walls.iter().map(|w| w.expect("walls on every axis")).map(|w| w[0] + w[1]).sum();
            sum / (2 * D) as f64
        })
        .collect();
    let diffs: Vec<f64> = walls.iter().zip(samples).map(|(w, x)| w - x.pressure_virial).collect();
    let (_, p_wall_err) = block_error(&walls, 20);
    let (difference, difference_err) = block_error(&diffs, 20);
    let (n_mid, n_mid_tolerance) = conservative_tolerance(&mid);
    let p_wall = s.wall_pressures.iter().map(|w| w.pressure).sum::<f64>() / s.wall_pressures.len() as f64;
    let accessible: f64 = (0..D).map(|a| lengths[a] - 1.0).product();
    Ok(WalledState {
        dimension: D,
        eta,
        n_particles: n,
        kt: s.kT,
        p_wall,
        p_wall_err,
        p_middle,
        p_middle_tolerance,
        p_virial: s.pressure_virial,
        p_virial_err: s.pressure_virial_error,
        difference,
        difference_err,
        n_mid,
        n_mid_tolerance,
        n_accessible: n as f64 / accessible,
    })
}

/// The impulse each walled axis received (both walls), summed in the order of the events.
struct AxisImpulses<const D: usize>([f64; D]);

impl<const D: usize> Observer<D> for AxisImpulses<D> {
    fn observe(&mut self, _: &Simulation<D>, outcome: &Outcome<D>) {
        if let Outcome::Wall { axis, impulse, .. } = outcome {
            self.0[*axis] += impulse;
        }
    }
}

/// One disk between walls for a time `t_end`: (mean wall pressure, kT/V_acc, tolerance).
pub fn one_disk(t_end: f64) -> Result<(f64, f64, f64), ExperimentError> {
    one_particle::<2>(t_end)
}

/// One particle of diameter 1 between walls (a 9 × 7 box, 9 × 7 × 8 in 3D) for a time
/// `t_end`: (the mean over axes of the wall pressures, kT/V_acc, tolerance).
pub fn one_particle<const D: usize>(t_end: f64) -> Result<(f64, f64, f64), ExperimentError> {
    let start = [3.1, 2.2, 4.3];
    let speed = [0.8123, -0.5839, 0.4417];
    let edges = [9.0, 7.0, 8.0];
    let particle = Particle {
        position: SVector::from_fn(|a, _| start[a]),
        velocity: SVector::from_fn(|a, _| speed[a]),
        time: 0.0,
        radius: 0.5,
        mass: 1.0,
        species: 0,
        events: 0,
    };
    let size: Vec<String> = edges[..D].iter().map(|l| format!("{l:?}")).collect();
    // No equilibration, no samples (the interval is past the end): the run is the flight.
    let text = format!(
        "dimension = {D}\nseed = 1\n[box]\nsize = [{}]\nboundary = \"wall\"\n[[species]]\ncount = 1\nradius = 0.5\nmass = 1.0\n\
         [run]\ntime = {t_end:?}\nsample_interval = {:?}\n",
        size.join(", "),
        2.0 * t_end
    );
    let mut run = Run::<D>::from_particles(Config::parse(&text, NAME)?, vec![particle.clone()])?;
    let mut impulse = AxisImpulses([0.0; D]);
    run_to_end(&mut run, &mut impulse)?;
    let t = run.sim.time();
    let accessible: [f64; D] = std::array::from_fn(|a| edges[a] - 1.0);
    let volume: f64 = accessible.iter().product();
    // The area of the two walls normal to axis a is V_acc/(L_a − σ).
    let area = |a: usize| volume / accessible[a];
    let measured = (0..D).map(|a| impulse.0[a] / 2.0 / (t * area(a))).sum::<f64>() / D as f64;
    let tolerance = (0..D).map(|a| particle.mass * speed[a].abs() / area(a)).sum::<f64>() / (D as f64 * t);
    Ok((measured, run.sim.kt() / volume, tolerance))
}

/// The ideal-gas check of the one-disk run.
pub fn ideal_gas_check(measured: f64, expected: f64, tolerance: f64) -> Check {
    Check::within(
        "ideal-gas limit, one particle: the mean over axes of the wall pressures",
        measured,
        f64::NAN,
        expected,
        tolerance,
        "exact kT/Π(L−σ) up to one partial flight per axis: (1/d)·Σ m|v_a|/(t·A_a), A_a the accessible wall area",
    )
}

/// The check of a state against the reference at its bulk density (where it is checked), if
/// any.
pub fn eos_check(s: &WalledState) -> Option<Check> {
    let (_, accuracy, up_to, name) = reference(s.dimension);
    if s.eta_mid() > up_to {
        return None;
    }
    let (p_eos, p_eos_tolerance) = s.p_eos_mid();
    let statistical = s.p_middle_tolerance.hypot(p_eos_tolerance);
    Some(Check::within(
        &format!(
            "pressure on the middle of the walls at η = {} vs {name} at the bulk density η_bulk = {:.4}",
            s.eta,
            s.eta_mid()
        ),
        s.p_middle,
        s.p_middle_tolerance / three_sigma_factor(20),
        p_eos,
        statistical + accuracy * p_eos,
        &format!(
            "3σ-equivalents of the middle-wall pressure and of the EOS through the bulk density (both conservative blocking), in quadrature, + {name}'s {accuracy:e} relative accuracy"
        ),
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
    let d = options.dimension;
    // Spheres start from a simple cubic lattice of k³ sites (k = 14, 16): a box with a bulk
    // region 5σ from every wall.
    let (n, per_particle, etas, t_one, identity_at) = match (d, options.quick()) {
        (2, true) => (400, 200, vec![0.2, 0.4], 2.0e4, 0.4),
        (2, false) => (1600, 500, vec![0.1, 0.2, 0.3, 0.4, 0.5, 0.6], 2.0e5, 0.4),
        (_, true) => (2744, 100, vec![0.1, 0.3], 2.0e4, 0.3),
        (_, false) => (4096, 300, vec![0.1, 0.2, 0.3, 0.4, 0.45], 2.0e5, 0.3),
    };
    let (p1, p1_expected, p1_tol) = if d == 3 { one_particle::<3>(t_one)? } else { one_particle::<2>(t_one)? };
    let mut checks = vec![ideal_gas_check(p1, p1_expected, p1_tol)];
    let mut states = Vec::new();
    for (k, &eta) in etas.iter().enumerate() {
        states.push(measure(d, eta, n, per_particle, options.seed + k as u64)?);
    }
    let at = states
        .iter()
        .find(|s| (s.eta - identity_at).abs() < 1e-12)
        .ok_or(ExperimentError::Missing("the state of the identity check"))?;
    checks.push(identity_check(at));
    checks.extend(states.iter().filter_map(eos_check));

    let dir = options.plot_dir(NAME)?;
    let top = states.iter().map(|s| s.eta_mid()).fold(0.0, f64::max) + 0.02;
    let per_volume = if d == 2 { 4.0 / PI } else { 6.0 / PI };
    let eos = |z: fn(f64) -> f64| {
        (1..=120).map(|k| k as f64 * top / 120.0).map(|e| (e, per_volume * e * z(e))).collect::<Vec<_>>()
    };
    let (z_ref, _, _, name) = reference(d);
    let mut lines = vec![Series::line(&format!("{name} (bulk EOS)"), eos(z_ref))];
    if d == 2 {
        lines.push(Series::line("Henderson 1975", eos(z_henderson)));
    }
    let chart = Chart {
        title: format!("Pressure in a walled box (N = {n}, {})", if d == 2 { "disks" } else { "spheres" }),
        x_label: "packing fraction η (bulk density; nominal for the virial points)".into(),
        y_label: format!("pressure P (kT/σ^{d})"),
        legend_left: true,
        series: [
            vec![
                Series::errors(
                    "middle of the walls vs bulk density",
                    states.iter().map(|s| (s.eta_mid(), s.p_middle)).collect(),
                    states.iter().map(|s| s.p_middle_tolerance / three_sigma_factor(20)).collect(),
                ),
                Series::points("whole walls vs bulk density", states.iter().map(|s| (s.eta_mid(), s.p_wall)).collect()),
                Series::errors(
                    "collision virial vs nominal N/V",
                    states.iter().map(|s| (s.eta, s.p_virial)).collect(),
                    states.iter().map(|s| s.p_virial_err).collect(),
                ),
            ],
            lines,
        ]
        .concat(),
    };
    draw(&chart, &dir.join("pressure.svg"))?;
    Ok(options.result(
        NAME,
        json!({
            "dimension": d, "n_particles": n, "packing_fractions": etas, "boundary": "wall", "kT": 1.0,
            "production_collisions_per_particle": per_particle, "one_particle_time": t_one,
            "bulk_region": "at least 5σ from every wall", "identity_at": identity_at,
        }),
        json!({
            "one_particle": {"measured": p1, "expected": p1_expected, "tolerance": p1_tol},
            "states": states,
            "eta_mid": states.iter().map(|s| s.eta_mid()).collect::<Vec<_>>(),
        }),
        checks,
        vec!["pressure.svg".into()],
    ))
}
