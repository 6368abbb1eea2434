//! `jamming`: Lubachevsky–Stillinger compressions to jamming at several rates — disks or
//! spheres.
//!
//! Each packing is a run with `[compress] until = "jammed"` (the engine's growth, see
//! `docs/configuration.md`) from a random start, to the reduced pressure [`PRESSURE_LIMIT`]:
//!
//! * **disks**: the 50:50 bidisperse mixture of diameters 1 and 1.4 (O'Hern et al., PRE 68,
//!   011306 (2003)), from φ = 0.5;
//! * **spheres**: monodisperse, from φ = 0.3;
//! * and, to show crystallisation, monodisperse particles of either kind compressed slowly
//!   (to `Z = 10⁴`: order forms long before).
//!
//! Every rate is run from several seeds (in parallel, one packing a thread; each is
//! deterministic, so the result is too). Of each packing: the jamming density φ_J reached;
//! the reduced pressure along the way, in windows of `N` collisions, whose divergence
//! `Z ≈ d·φ_J/(φ_J − φ)` (free-volume theory; Salsburg & Wood, J. Chem. Phys. 37, 798 (1962))
//! makes `1/Z` a straight line in φ near jamming — fitted by least squares over
//! `Z ∈ [10², 10⁵]` ([`FIT_RANGE`]) to *extrapolate* φ_J, with a jackknife error; the contact
//! network (contacts within the run's gap tolerance, rattlers removed, against the isostatic
//! count `N_iso = d(N′ − 1) + 1` of a periodic packing of `N′` particles, Goodrich, Liu &
//! Nagel, PRL 109, 095704 (2012), i.e. `z_iso = 2d − 2(d − 1)/N′`); the bond order ([`order`],
//! Ψ₆ or Q₆); the largest overlap.
//!
//! The checks, each with its tolerance and why, are in `docs/experiments.md` and
//! [`checks`]; they take the measured packings, so the tests can feed them wrong ones.
//!
//! [`order`]: crate::observe::order

use super::plot::{Chart, Series, draw};
use super::stats::{line_root_with_error, mean_and_error, three_sigma_factor};
use super::{Check, ExperimentError, ExperimentResult, Options};
use crate::engine::Outcome;
use crate::observe::contacts::contacts;
use crate::observe::order::{BOND_CUTOFF, bond_order};
use crate::run::{Config, Phase, Run, Sink};
use serde::{Deserialize, Serialize};
use serde_json::json;

/// The experiment's name.
pub const NAME: &str = "jamming";

/// The reduced pressure a compression to jamming stops at.
pub const PRESSURE_LIMIT: f64 = 1e12;

/// The reduced pressure at which a slow compression is stopped to look for a crystal.
pub const CRYSTAL_PRESSURE_LIMIT: f64 = 1e4;

/// The pressures over which `1/Z` is fitted: high enough for the free-volume form, low enough
/// that the fit *extrapolates* to the jamming density over four decades of pressure.
pub const FIT_RANGE: (f64, f64) = (1e2, 1e5);

/// The blocks of the jackknife error of an extrapolated φ_J.
const JACKKNIFE_BLOCKS: usize = 10;

/// The literature's jamming density of the system compressed at the reference rate: (value,
/// its stated uncertainty, the protocol's spread, the citation).
pub fn reference(d: usize) -> (f64, f64, f64, &'static str) {
    match d {
        2 => (
            0.842,
            0.001,
            0.0,
            "O'Hern, Silbert, Liu & Nagel, PRE 68, 011306 (2003): φ* = 0.842 for the 50:50 mixture of diameter ratio 1.4 (N → ∞), quoted to ±0.001",
        ),
        _ => (
            0.637,
            0.0,
            0.003,
            "Baranau & Tallarek, Soft Matter 10, 7838 (2014): fast Lubachevsky–Stillinger compressions of monodisperse spheres jam at 0.634–0.640 (the band's half-width is the protocol term); O'Hern et al. (2003): 0.639",
        ),
    }
}

/// How big the experiment is in one dimension and mode.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Plan {
    /// Particles of a jamming compression.
    pub n: usize,
    /// The compression rates, fastest first (relative growth of a radius per unit time).
    pub rates: Vec<f64>,
    /// The index in `rates` of the rate compared with the literature.
    pub reference_rate: usize,
    /// Seeds per rate.
    pub seeds: usize,
    /// The packing fraction the compressions start from.
    pub start: f64,
    /// Particles of the slow monodisperse compression.
    pub crystal_n: usize,
    /// Its rate.
    pub crystal_rate: f64,
    /// Its start.
    pub crystal_start: f64,
}

impl Plan {
    /// The plan for dimension `d`.
    pub fn new(d: usize, quick: bool) -> Plan {
        // Only the size and the number of seeds differ between quick and report size.
        let seeds = if quick { 4 } else { 8 };
        if d == 2 {
            Plan {
                n: if quick { 200 } else { 400 },
                rates: vec![0.03, 0.01, 0.003],
                reference_rate: 1,
                seeds,
                start: 0.5,
                crystal_n: 100,
                crystal_rate: 0.003,
                crystal_start: 0.5,
            }
        } else {
            Plan {
                n: 256,
                rates: vec![0.03, 0.01],
                reference_rate: 0,
                seeds,
                start: 0.3,
                crystal_n: 108,
                crystal_rate: 0.001,
                crystal_start: 0.3,
            }
        }
    }
}

/// The divergence of the pressure fitted to one compression.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Divergence {
    /// The jamming density extrapolated from `1/Z` over [`FIT_RANGE`].
    pub phi_j: f64,
    /// Its jackknife standard error.
    pub error: f64,
    /// The prefactor `c` of `Z ≈ c·φ_J/(φ_J − φ)` (free-volume theory: `d`).
    pub prefactor: f64,
    /// The pressure windows fitted.
    pub points: usize,
}

/// One packing.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Packing {
    /// The compression rate.
    pub rate: f64,
    /// The seed of its start.
    pub seed: u64,
    /// Particles.
    pub n: usize,
    /// The packing fraction reached (at the pressure limit, or where the clock stalled).
    pub phi_j: f64,
    /// The last window's reduced pressure.
    pub reduced_pressure: f64,
    /// Pair collisions of the compression.
    pub collisions: u64,
    /// Its simulated time.
    pub sim_time: f64,
    /// The largest overlap (a fraction of a contact distance).
    pub max_overlap: f64,
    /// The particles that are not rattlers, `N′`.
    pub held: usize,
    /// The contacts among them (and with walls), `N_c`.
    pub contacts: usize,
    /// The contact gap tolerance (a fraction of a contact distance).
    pub contact_tolerance: f64,
    /// Ψ₆ (disks) or Q₆ (spheres).
    pub order: f64,
    /// The pressure's divergence, when enough windows fell in the fit's range.
    pub divergence: Option<Divergence>,
    /// The pressure windows `(φ, Z)` of the fit's range, thinned to at most 200 (for plots).
    #[serde(skip)]
    pub curve: Vec<(f64, f64)>,
}

impl Packing {
    /// Contacts beyond (positive) or short of (negative) isostatic, `N_c − d(N′ − 1) − 1`
    /// (0 when every particle is a rattler: there is no network to count).
    pub fn excess_contacts(&self, d: usize) -> i64 {
        if self.held == 0 {
            return 0;
        }
        self.contacts as i64 - (d * (self.held - 1) + 1) as i64
    }

    /// Contacts per held particle, `z = 2N_c/N′`.
    pub fn z(&self) -> f64 {
        if self.held == 0 { 0.0 } else { 2.0 * self.contacts as f64 / self.held as f64 }
    }
}

/// Records `(φ, Z)` whenever the compression's pressure window closes.
struct Windows {
    points: Vec<(f64, f64)>,
    last: Option<f64>,
}

impl<const D: usize> Sink<D> for Windows {
    type Error = std::convert::Infallible;
    fn event(&mut self, run: &Run<D>, _: &Outcome<D>) -> Result<(), Self::Error> {
        if run.phase() != Phase::Compression {
            return Ok(());
        }
        let z = run.compression.as_ref().and_then(|c| c.reduced_pressure);
        if z != self.last {
            self.last = z;
            if let Some(z) = z {
                self.points.push((run.sim.packing_fraction(), z));
            }
        }
        Ok(())
    }
}

/// The species of `n` particles: the bidisperse disk mixture, or monodisperse.
fn species(n: usize, bidisperse: bool) -> String {
    if bidisperse {
        format!(
            "[[species]]\ncount = {}\nradius = 0.5\nmass = 1.0\n[[species]]\ncount = {}\nradius = 0.7\nmass = 1.0\n",
            n / 2,
            n - n / 2
        )
    } else {
        format!("[[species]]\ncount = {n}\nradius = 0.5\nmass = 1.0\n")
    }
}

/// One compression to `limit` of `n` particles from `start` at `rate`.
#[allow(clippy::too_many_arguments)]
pub fn compress<const D: usize>(
    n: usize,
    bidisperse: bool,
    start: f64,
    rate: f64,
    seed: u64,
    limit: f64,
) -> Result<Packing, ExperimentError> {
    let text = format!(
        "dimension = {D}\nseed = {seed}\n[box]\npacking_fraction = {start}\nboundary = \"periodic\"\n{}\
         [init]\nplacement = \"random\"\n[compress]\nrate = {rate}\nuntil = \"jammed\"\npressure_limit = {limit:e}\n",
        species(n, bidisperse)
    );
    let config = Config::parse(&text, NAME)?;
    let tolerance = config.compress.as_ref().map_or(0.0, |c| c.contact_tolerance(D));
    let mut run = Run::<D>::new(config)?;
    let mut windows = Windows { points: Vec::new(), last: None };
    let Ok(_) = run.complete(&mut windows);
    let c = run.compression.clone().ok_or(ExperimentError::Missing("the compression's record"))?;
    let network = contacts(&run.sim, tolerance);
    let in_range: Vec<(f64, f64)> =
        windows.points.iter().filter(|p| p.1 >= FIT_RANGE.0 && p.1 <= FIT_RANGE.1).copied().collect();
    let divergence =
        line_root_with_error(&in_range.iter().map(|&(phi, z)| (phi, 1.0 / z)).collect::<Vec<_>>(), JACKKNIFE_BLOCKS)
            .map(|(line, phi_j, error)| Divergence {
                phi_j,
                error,
                prefactor: -1.0 / (line.slope * phi_j),
                points: line.points,
            });
    let stride = in_range.len().div_ceil(200).max(1);
    Ok(Packing {
        rate,
        seed,
        n,
        phi_j: c.packing_fraction,
        reduced_pressure: c.reduced_pressure.unwrap_or(f64::NAN),
        collisions: c.collisions,
        sim_time: c.sim_time,
        max_overlap: c.max_overlap,
        held: n - network.rattlers.len(),
        contacts: network.held_contacts,
        contact_tolerance: tolerance,
        order: bond_order(&run.sim, BOND_CUTOFF).value,
        divergence,
        curve: in_range.into_iter().step_by(stride).collect(),
    })
}

/// Runs `jobs` on every core, each a packing; the results in the jobs' order.
fn in_parallel<F>(jobs: usize, job: F) -> Result<Vec<Packing>, ExperimentError>
where
    F: Fn(usize) -> Result<Packing, ExperimentError> + Sync,
{
    super::in_parallel(jobs, std::thread::available_parallelism().map_or(1, |n| n.get()), job)
}

/// The packings of one dimension: every rate and seed (fastest rate first), then the slow
/// monodisperse one.
pub fn packings<const D: usize>(plan: &Plan, seed: u64) -> Result<(Vec<Packing>, Packing), ExperimentError> {
    let bidisperse = D == 2;
    let jobs = plan.rates.len() * plan.seeds + 1;
    let mut all = in_parallel(jobs, |k| {
        if k == 0 {
            // The slowest job first, so that it does not end the run alone.
            compress::<D>(plan.crystal_n, false, plan.crystal_start, plan.crystal_rate, seed, CRYSTAL_PRESSURE_LIMIT)
        } else {
            let (r, s) = ((k - 1) / plan.seeds, (k - 1) % plan.seeds);
            compress::<D>(plan.n, bidisperse, plan.start, plan.rates[r], seed + s as u64, PRESSURE_LIMIT)
        }
    })?;
    let crystal = all.remove(0);
    Ok((all, crystal))
}

/// The jammed packings at `rate`: those with a contact network. (A compression too fast
/// for its size can reach the pressure limit with none — every particle a rattler, the
/// pressure carried by collisions the growth itself drives; that packing is not jammed, and
/// is counted apart, in the data's `"unjammed"`.)
fn at(packings: &[Packing], rate: f64) -> Vec<&Packing> {
    packings.iter().filter(|p| p.rate == rate && p.held > 0).collect()
}

/// The mean and standard error of `f` over the packings at `rate`, and their count.
fn stat(packings: &[Packing], rate: f64, f: impl Fn(&Packing) -> f64) -> (f64, f64, usize) {
    let values: Vec<f64> = at(packings, rate).into_iter().map(f).collect();
    let (mean, error) = mean_and_error(&values);
    (mean, error, values.len())
}

/// The perfect crystal's order (Ψ₆ of the triangular lattice; Q₆ of hcp, the lower of the
/// two close-packed stackings) and the threshold halfway to a random packing's `1/√B`.
pub fn crystal_threshold(d: usize) -> (f64, f64) {
    let perfect = if d == 2 { 1.0 } else { 0.4848 };
    (perfect, perfect / 2.0)
}

/// The checks of one dimension (see `docs/experiments.md`): the jamming packings (rates
/// fastest first) and the slow monodisperse one.
pub fn checks(d: usize, plan: &Plan, packings: &[Packing], crystal: &Packing) -> Vec<Check> {
    let mut checks = Vec::new();
    let slowest = *plan.rates.last().expect("rates");
    let reference_rate = plan.rates[plan.reference_rate];

    // 1. φ_J against the literature.
    let (value, uncertainty, protocol, citation) = reference(d);
    let (mean, error, count) = stat(packings, reference_rate, |p| p.phi_j);
    let spread = error * (count as f64).sqrt();
    let t = three_sigma_factor(count);
    checks.push(Check::within(
        &format!("jamming density at rate {reference_rate} (mean of {count} packings of {})", plan.n),
        mean,
        error,
        value,
        t * error + uncertainty + protocol + spread,
        &format!(
            "{citation}. Tolerance: Student-t 3σ-equivalent of the mean ({t:.2} standard errors, {} degrees of freedom) + the reference's uncertainty {uncertainty} + the protocol term {protocol} + a finite-size term: the width of the distribution of φ_J at this N (its standard deviation here, {spread:.4}), by which O'Hern et al. found the mean shifted too, both ∝ N^-1/2",
            count - 1
        ),
    ));

    // 2. The pressure's divergence extrapolates to the jamming density reached.
    let jammed: Vec<&Packing> = packings.iter().filter(|p| p.held > 0).collect();
    let differences: Vec<f64> =
        jammed.iter().filter_map(|p| p.divergence.as_ref().map(|v| v.phi_j - p.phi_j)).collect();
    let (mean, error) = mean_and_error(&differences);
    let t = three_sigma_factor(differences.len());
    checks.push(Check::within(
        &format!(
            "φ_J extrapolated from 1/Z over Z ∈ [{:e}, {:e}] − φ_J reached at Z = {PRESSURE_LIMIT:e} (mean of {} packings)",
            FIT_RANGE.0,
            FIT_RANGE.1,
            differences.len()
        ),
        if differences.len() == jammed.len() { mean } else { f64::NAN },
        error,
        0.0,
        t * error,
        &format!(
            "0 within the Student-t 3σ-equivalent ({t:.2} standard errors of the mean over independent packings): the pressure diverges as 1/(φ_J − φ) at the packing's own jamming density (free-volume theory); the limit's own offset, d·φ_J/{PRESSURE_LIMIT:e}, is negligible. NaN if a compression had no pressure window in the fit's range"
        ),
    ));

    // 3. No packing is hyperstatic.
    let excess = packings.iter().map(|p| p.excess_contacts(d)).max().unwrap_or(0);
    checks.push(Check::at_most(
        "largest number of contacts beyond isostatic, N_c − d(N′ − 1) − 1, over the packings",
        excess as f64,
        f64::NAN,
        0.0,
        "exact: an amorphous jammed packing of frictionless spheres with generic radii has no redundant contact; one more would be a contact miscounted (the gap tolerance) or an ordered packing",
    ));

    // 4. Isostaticity is approached as the compression slows: from the reference rate (at
    // the fastest, a large system may not jam at all) to the slowest.
    let deficit = |p: &Packing| -(p.excess_contacts(d) as f64);
    let fastest = reference_rate;
    let (fast, fast_error, n_fast) = stat(packings, fastest, deficit);
    let (slow, slow_error, n_slow) = stat(packings, slowest, deficit);
    let sigma = fast_error.hypot(slow_error);
    let t = three_sigma_factor(n_fast + n_slow - 1);
    checks.push(Check::at_least(
        &format!(
            "missing contacts at rate {fastest} − at rate {slowest} (means {fast:.1} and {slow:.1}): slower compressions come closer to isostatic"
        ),
        fast - slow,
        sigma,
        t * sigma,
        &format!(
            "positive beyond the 3σ-equivalent of the difference of two means ({t:.2} combined standard errors; Student t with the pooled degrees of freedom): a finite rate freezes the packing before every contact of the isostatic network forms; the deficit falls with the rate"
        ),
    ));

    // 5–6. Slow monodisperse compression crystallises; the mixtures' packings are amorphous.
    let (perfect, threshold) = crystal_threshold(d);
    let name = if d == 2 { "Ψ₆" } else { "Q₆" };
    checks.push(Check::at_least(
        &format!(
            "{name} of {} monodisperse particles compressed at rate {} to Z = {CRYSTAL_PRESSURE_LIMIT:e}: a crystal",
            crystal.n, plan.crystal_rate
        ),
        crystal.order,
        f64::NAN,
        threshold,
        &format!(
            "at least half the perfect crystal's {perfect} ({}), many times a disordered packing's ≈ 1/√bonds",
            if d == 2 { "triangular lattice" } else { "hcp; fcc has 0.5745" }
        ),
    ));
    let largest = jammed.iter().map(|p| p.order).fold(0.0, f64::max);
    checks.push(Check::at_most(
        &format!("largest {name} of the jammed packings: amorphous"),
        largest,
        f64::NAN,
        threshold,
        "below the crystal's threshold: the jamming densities compared are those of amorphous packings",
    ));

    // 7. No overlap.
    let overlap = packings.iter().chain([crystal]).map(|p| p.max_overlap).fold(0.0, f64::max);
    checks.push(Check::at_most(
        &format!("largest overlap at Z up to {PRESSURE_LIMIT:e} (fraction of a contact distance)"),
        overlap,
        f64::NAN,
        1e-10,
        "the exact growing contact kernel lets no pair overlap by more than rounding; 10⁻¹⁰ is a hundred times a contact's gap at the pressure limit",
    ));
    checks
}

/// Runs the experiment.
pub fn run(options: &Options) -> Result<ExperimentResult, ExperimentError> {
    let d = options.dimension;
    let plan = Plan::new(d, options.quick());
    let (packings, crystal) =
        if d == 3 { packings::<3>(&plan, options.seed)? } else { packings::<2>(&plan, options.seed)? };
    let checks = checks(d, &plan, &packings, &crystal);
    let dir = options.plot_dir(NAME)?;
    let plots = plot(d, &plan, &packings, &dir)?;
    let per_rate: Vec<serde_json::Value> = plan
        .rates
        .iter()
        .map(|&rate| {
            let (phi, phi_error, _) = stat(&packings, rate, |p| p.phi_j);
            let (z, z_error, _) = stat(&packings, rate, Packing::z);
            let (excess, excess_error, _) = stat(&packings, rate, |p| p.excess_contacts(d) as f64);
            let (rattlers, _, _) = stat(&packings, rate, |p| (p.n - p.held) as f64);
            let unjammed = packings.iter().filter(|p| p.rate == rate && p.held == 0).count();
            let (fit, fit_error, _) =
                stat(&packings, rate, |p| p.divergence.as_ref().map_or(f64::NAN, |v| v.phi_j));
            let (prefactor, prefactor_error, _) =
                stat(&packings, rate, |p| p.divergence.as_ref().map_or(f64::NAN, |v| v.prefactor));
            json!({ "rate": rate, "phi_j": phi, "phi_j_err": phi_error, "phi_j_extrapolated": fit,
                "phi_j_extrapolated_err": fit_error, "prefactor": prefactor, "prefactor_err": prefactor_error,
                "contacts_per_particle": z, "contacts_per_particle_err": z_error,
                "excess_contacts": excess, "excess_contacts_err": excess_error, "rattlers": rattlers, "unjammed": unjammed })
        })
        .collect();
    let (value, uncertainty, protocol, citation) = reference(d);
    Ok(options.result(
        NAME,
        json!({ "dimension": d, "plan": plan, "pressure_limit": PRESSURE_LIMIT,
            "crystal_pressure_limit": CRYSTAL_PRESSURE_LIMIT, "fit_range": [FIT_RANGE.0, FIT_RANGE.1],
            "system": if d == 2 { "50:50 bidisperse disks, diameters 1 and 1.4" } else { "monodisperse spheres" },
            "reference": { "phi_j": value, "uncertainty": uncertainty, "protocol": protocol, "source": citation } }),
        json!({ "rates": per_rate, "packings": packings, "crystal": crystal }),
        checks,
        plots,
    ))
}

/// The plots: 1/Z against φ with the fitted lines; φ_J and contacts per particle against the
/// rate.
fn plot(d: usize, plan: &Plan, packings: &[Packing], dir: &std::path::Path) -> Result<Vec<String>, ExperimentError> {
    let what = if d == 2 { "bidisperse disks" } else { "monodisperse spheres" };
    let mut series = Vec::new();
    for &rate in &plan.rates {
        let Some(p) = at(packings, rate).into_iter().next() else { continue };
        series.push(Series::points(
            &format!("rate {rate}, seed {}", p.seed),
            p.curve.iter().map(|&(phi, z)| (phi, 1.0 / z)).collect(),
        ));
        if let Some(v) = &p.divergence {
            let lo = p.curve.first().map_or(v.phi_j, |c| c.0);
            // 1/Z = (φ_J − φ)/(c·φ_J): the fitted line, to its root.
            series.push(Series::line(
                &format!("fit: φ_J = {:.5} ± {:.1e}", v.phi_j, v.error),
                vec![(lo, (v.phi_j - lo) / (v.prefactor * v.phi_j)), (v.phi_j, 0.0)],
            ));
        }
    }
    draw(
        &Chart {
            title: format!("Pressure divergence at jamming: {what}"),
            x_label: "packing fraction φ (dimensionless)".into(),
            y_label: "1/Z, Z = PV/(NkT) (dimensionless)".into(),
            legend_left: false,
            series,
        },
        &dir.join("pressure_divergence.svg"),
    )?;
    let log_rates: Vec<f64> = plan.rates.iter().map(|r| r.log10()).collect();
    let mut phi_points = Vec::new();
    let mut phi_errors = Vec::new();
    let mut z_points = Vec::new();
    let mut z_errors = Vec::new();
    let mut iso = Vec::new();
    for (&rate, &x) in plan.rates.iter().zip(&log_rates) {
        let (phi, phi_error, _) = stat(packings, rate, |p| p.phi_j);
        phi_points.push((x, phi));
        phi_errors.push(phi_error);
        let (z, z_error, _) = stat(packings, rate, Packing::z);
        z_points.push((x, z));
        z_errors.push(z_error);
        let (held, _, _) = stat(packings, rate, |p| p.held as f64);
        iso.push((x, 2.0 * d as f64 - 2.0 * (d as f64 - 1.0) / held));
    }
    let (value, ..) = reference(d);
    let ends = [log_rates[0] + 0.2, log_rates[log_rates.len() - 1] - 0.2];
    draw(
        &Chart {
            title: format!("Jamming density against compression rate: {what}"),
            x_label: "log10 rate (rate: relative growth per unit time)".into(),
            y_label: "jamming density φ_J (dimensionless)".into(),
            legend_left: false,
            series: vec![
                Series::errors("φ_J reached (mean ± standard error)", phi_points, phi_errors),
                Series::line(&format!("literature, {value}"), ends.iter().map(|&x| (x, value)).collect()),
            ],
        },
        &dir.join("jamming_density.svg"),
    )?;
    draw(
        &Chart {
            title: format!("Contacts per particle, rattlers removed: {what}"),
            x_label: "log10 rate (rate: relative growth per unit time)".into(),
            y_label: "contacts per particle z (dimensionless)".into(),
            legend_left: false,
            series: vec![
                Series::errors("z (mean ± standard error)", z_points, z_errors),
                Series::line("isostatic, 2d − 2(d − 1)/N′", iso),
            ],
        },
        &dir.join("contacts.svg"),
    )?;
    Ok(vec!["pressure_divergence.svg".into(), "jamming_density.svg".into(), "contacts.svg".into()])
}
