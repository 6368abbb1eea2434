//! `structure`: g(r) and S(k) of the equilibrium fluid against the pressure and the equation
//! of state — disks or spheres.
//!
//! Each state (periodic box, equilibrated from a lattice) runs with the `rdf` and `sk`
//! observers (`crate::observe`). Checks per density:
//!
//! * **contact value, two routes**: g(σ⁺) extrapolated from g(r) (a quadratic in ln g over 0.1σ) and
//!   `(Z − 1)/(2^(d−1)η)` from the collision virial of the same run agree — exact in
//!   equilibrium — within the 3σ-equivalent of the two 20-block errors combined (Student's t:
//!   3.45);
//! * **contact value against the published equation of state**: g(σ⁺) from g(r) against
//!   `(Z_ref − 1)/(2^(d−1)η)`, `Z_ref` the most accurate fluid equation of state (disks: the
//!   virial series through b₁₀ for η ≤ 0.2, Liu's above, stated 10⁻³; spheres: Hansen-Goos',
//!   10⁻⁴; see `collision_rate`): tolerance 3.45σ + the reference's accuracy carried to g
//!   (×Z/(Z − 1)) + a finite-size term g/N;
//! * **S(k → 0) against the compressibility**: `S(0) = kT(∂n/∂P)_T = 1/(d(ηZ_ref)/dη)`
//!   (the derivative by central differences of the reference), against the `sk` observer's
//!   extrapolation (`a + bk² + ck⁴` over k ≤ 2.5/σ, applied per sample, 20-block error):
//!   tolerance 3.45σ + the reference's accuracy ×10 for its derivative + S(0)/N finite size
//!   (the canonical ensemble's O(1/N) shift, Lebowitz & Percus, Phys. Rev. 122, 1675 (1961)).
//!
//! * **g(r) of a dilute fluid against its exact density expansion**: at η = 0.05, over the
//!   first shell `[σ, 2σ]` in ten bins of 0.1σ, `g(r) = 1 + n·X(r)` (`X` the overlap of two
//!   exclusion disks or spheres, [`crate::theory::g_first_order`]; Nijboer & van Hove, Phys.
//!   Rev. 85, 777 (1952)). Each bin within 3.64 of its Poisson error (the two-sided 3σ
//!   level's 0.27 % shared by the ten bins; samples every
//!   ideal-gas collision time, by when a pair within 2σ has parted: independent counts)
//!   + the omitted O(η²) term at its contact size `c₂η²` (0.5 % of g for disks, 1.1 % for
//!   spheres; [`crate::theory::contact_second_order`]) + g/N. The check reports the largest
//!   `|g − g₁|/tolerance` over the ten bins, at most 1.
//!
//! Plots: g(r) and S(k) at each density; the contact values and S(0) against η with the
//! reference curves.

use super::collision_rate::enskog_reference;
use super::plot::{Chart, Series, draw};
use super::stats::three_sigma_factor;
use super::{Check, ExperimentError, ExperimentResult, Options, Size, finished_run, fluid_config};
use crate::observe::Observable;
use crate::run::Config;
use serde::{Deserialize, Serialize};
use serde_json::json;

/// The experiment's name.
pub const NAME: &str = "structure";

/// One measured state.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct StructureState {
    /// Packing fraction.
    pub eta: f64,
    /// Particles.
    pub n_particles: usize,
    /// Production collisions.
    pub collisions: u64,
    /// Z from the collision virial, and its error.
    pub z: f64,
    /// Its standard error.
    pub z_err: f64,
    /// g(σ⁺) from g(r).
    pub g_contact: f64,
    /// Its standard error.
    pub g_contact_err: f64,
    /// g(σ⁺) from Z.
    pub g_pressure: f64,
    /// Its standard error.
    pub g_pressure_err: f64,
    /// g(σ⁺) of the reference equation of state.
    pub g_reference: f64,
    /// S(k → 0) extrapolated.
    pub s0: f64,
    /// Its standard error.
    pub s0_err: f64,
    /// S(0) of the reference equation of state.
    pub s0_reference: f64,
    /// The reference's relative accuracy in Z.
    pub reference_accuracy: f64,
    /// g(r): bin centres and values.
    pub rdf: Vec<[f64; 2]>,
    /// S(k): bin wave numbers and values.
    pub sk: Vec<[f64; 2]>,
}

/// One bin of the dilute fluid's first shell.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ShellBin {
    /// Its inner and outer radius.
    pub r: [f64; 2],
    /// g over the bin (pairs counted over the ideal gas's).
    pub g: f64,
    /// Its Poisson error.
    pub error: f64,
    /// The first-order g over the bin (weighted as the ideal gas's pairs are).
    pub first_order: f64,
    /// The tolerance: 3.64 errors + c₂η² + g/N.
    pub tolerance: f64,
}

/// The dilute state whose first shell is compared with the density expansion.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct DiluteState {
    /// Packing fraction.
    pub eta: f64,
    /// Particles.
    pub n_particles: usize,
    /// Production collisions.
    pub collisions: u64,
    /// Samples of g(r).
    pub samples: u64,
    /// The ten bins of `[σ, 2σ]`.
    pub bins: Vec<ShellBin>,
}

impl DiluteState {
    /// The largest `|g − g₁|/tolerance` of the bins.
    pub fn worst(&self) -> f64 {
        self.bins.iter().map(|b| (b.g - b.first_order).abs() / b.tolerance).fold(0.0, f64::max)
    }
}

/// The dilute fluid's packing fraction.
pub const DILUTE_ETA: f64 = 0.05;

/// Measures the dilute state: `n` particles at [`DILUTE_ETA`], `per_particle` collisions each
/// of production (after a tenth as many of equilibration: a dilute gas forgets its lattice in a few collisions), `g(r)` to `2.5σ` in bins of `0.01σ`
/// sampled every ideal-gas collision time (a pair within 2σ has parted by the next sample:
/// a particle flies a mean free path, 2.4σ for spheres and 5.5σ for disks at this density).
pub fn measure_dilute(d: usize, n: usize, per_particle: u64, seed: u64) -> Result<DiluteState, ExperimentError> {
    let eta = DILUTE_ETA;
    let production = per_particle * n as u64;
    let density = crate::lab::collision_rate::number_density(d, eta);
    let every = 1.0 / crate::theory::enskog_rate(d, density, 1.0, 1.0, 1.0, 1.0);
    let observe = format!("[observe.rdf]\nevery = {every:?}\nr_max = 2.5\nbins = 250\n");
    let config = Config::parse(&fluid_config(d, eta, n, production / 10, production, seed, &observe), NAME)?;
    let rdf = if d == 3 { dilute_rdf::<3>(config)? } else { dilute_rdf::<2>(config)? };
    Ok(dilute_state(d, eta, n, production, &rdf))
}

fn dilute_rdf<const D: usize>(config: Config) -> Result<crate::observe::rdf::Rdf, ExperimentError> {
    let run = finished_run::<D>(config)?;
    match run.observables.into_iter().next() {
        Some(Observable::Rdf(rdf)) => Ok(rdf),
        _ => Err(ExperimentError::Missing("the rdf observable")),
    }
}

/// The dilute state's first shell from `rdf` (bins of 0.01σ from 0).
pub fn dilute_state(d: usize, eta: f64, n: usize, collisions: u64, rdf: &crate::observe::rdf::Rdf) -> DiluteState {
    let dr = rdf.r_max / rdf.bins as f64;
    let per = (0.1 / dr).round() as usize;
    let start = (1.0 / dr).round() as usize;
    let density = crate::lab::collision_rate::number_density(d, eta);
    let ideal = rdf.ideal(0);
    let m = rdf.samples as f64;
    let t = bin_factor();
    let omitted = crate::theory::contact_second_order(d) * eta * eta;
    let bins = (0..10)
        .map(|j| {
            let fine = start + j * per..start + (j + 1) * per;
            let counts: u64 = rdf.counts[0][fine.clone()].iter().sum();
            let ideal_sum: f64 = ideal[fine.clone()].iter().sum();
            let expected = ideal_sum * m;
            let first_order = fine
                .clone()
                .map(|k| ideal[k] * crate::theory::g_first_order(d, density, (k as f64 + 0.5) * dr))
                .sum::<f64>()
                / ideal_sum;
            let (g, error) = (counts as f64 / expected, (counts as f64).sqrt() / expected);
            ShellBin {
                r: [fine.start as f64 * dr, fine.end as f64 * dr],
                g,
                error,
                first_order,
                tolerance: t * error + omitted + first_order / n as f64,
            }
        })
        .collect();
    DiluteState { eta, n_particles: n, collisions, samples: rdf.samples, bins }
}

/// The per-bin multiple of the Poisson error: the two-sided 3σ level's 0.27 % shared among
/// the ten bins (Bonferroni), 3.64.
pub fn bin_factor() -> f64 {
    use statrs::distribution::{ContinuousCDF, Normal};
    Normal::standard().inverse_cdf(1.0 - 0.0027 / 20.0)
}

/// The dilute state's check.
pub fn dilute_check(s: &DiluteState) -> Check {
    Check::at_most(
        &format!(
            "η = {}: g(r) over [σ, 2σ] vs its exact first order in density (largest |Δg|/tolerance of 10 bins)",
            s.eta
        ),
        s.worst(),
        f64::NAN,
        1.0,
        "g = 1 + n·X(r) (Nijboer & van Hove 1952); per bin 3.64 Poisson errors (the 3σ level shared by 10 bins) + the omitted O(η²) term at its contact size c₂η² + g/N finite size",
    )
}

/// `S(0) = 1/(d(ηZ)/dη)` of the reference equation of state of the dimension.
/// Both sides of the difference from the branch the reference takes at `eta` (in 2D it
/// changes formula at η = 0.2).
pub fn s0_reference(d: usize, eta: f64) -> f64 {
    let h = 1e-5;
    let z = |e: f64| match d {
        2 if eta <= 0.2 => crate::theory::z_virial(e),
        2 => crate::theory::z_liu_disks(e),
        _ => crate::theory::z_hansen_goos(e),
    };
    let pz = |e: f64| e * z(e);
    1.0 / ((pz(eta + h) - pz(eta - h)) / (2.0 * h))
}

/// Measures one state.
pub fn measure(d: usize, eta: f64, n: usize, per_particle: u64, seed: u64) -> Result<StructureState, ExperimentError> {
    let production = per_particle * n as u64;
    // About 400 samples of g(r), 200 of S(k), over the production (Enskog's rate for the length).
    let (rate, _, _, _) = enskog_reference(d, eta);
    let every = 2.0 * per_particle as f64 / rate / 400.0;
    // S(k) costs more a sample than g(r): half as many.
    let observe = format!("[observe.rdf]\nevery = {every:?}\n[observe.sk]\nevery = {:?}\n", 2.0 * every);
    // As long an equilibration as the production: a lattice melted for less leaves g(σ⁺) and
    // Z out of step at η = 0.45 (the identity fails by 4σ after 100 collisions a particle).
    let config = Config::parse(&fluid_config(d, eta, n, production, production, seed, &observe), NAME)?;
    if d == 3 { measure_in::<3>(config, eta, n, production) } else { measure_in::<2>(config, eta, n, production) }
}

fn measure_in<const D: usize>(
    config: Config,
    eta: f64,
    n: usize,
    collisions: u64,
) -> Result<StructureState, ExperimentError> {
    let run = finished_run::<D>(config)?;
    let summary = run.summary();
    let (Some(Observable::Rdf(rdf)), Some(Observable::Sk(sk))) = (run.observables.first(), run.observables.get(1))
    else {
        return Err(ExperimentError::Missing("the rdf and sk observables"));
    };
    let contact = rdf.results().contact.remove(0);
    let factor = 2f64.powi(D as i32 - 1) * eta;
    let (_, z_ref, accuracy, _) = enskog_reference(D, eta);
    let dr = rdf.r_max / rdf.bins as f64;
    let s = sk.results();
    Ok(StructureState {
        eta,
        n_particles: n,
        collisions,
        z: summary.compressibility,
        z_err: summary.compressibility_error,
        g_contact: contact.g,
        g_contact_err: contact.error,
        g_pressure: (summary.compressibility - 1.0) / factor,
        g_pressure_err: summary.compressibility_error / factor,
        g_reference: (z_ref - 1.0) / factor,
        s0: s.s0,
        s0_err: s.s0_error,
        s0_reference: s0_reference(D, eta),
        reference_accuracy: accuracy,
        rdf: rdf.g(0).iter().enumerate().map(|(k, &g)| [(k as f64 + 0.5) * dr, g]).collect(),
        sk: sk.curve().into_iter().map(|(k, _, s)| [k, s]).collect(),
    })
}

/// The checks of one state.
pub fn checks_for(s: &StructureState) -> Vec<Check> {
    let t = three_sigma_factor(20);
    let n = s.n_particles as f64;
    let carried = s.reference_accuracy * s.z / (s.z - 1.0);
    vec![
        Check::within(
            &format!("η = {}: g(σ⁺) from g(r) vs from the pressure of the same run", s.eta),
            s.g_contact,
            s.g_contact_err,
            s.g_pressure,
            t * s.g_contact_err.hypot(s.g_pressure_err),
            "Z = 1 + 2^(d−1)ηg(σ⁺) exactly in equilibrium; 3σ-equivalent of both 20-block errors combined (Student t: 3.45)",
        ),
        Check::within(
            &format!("η = {}: g(σ⁺) from g(r) vs the reference equation of state", s.eta),
            s.g_contact,
            s.g_contact_err,
            s.g_reference,
            t * s.g_contact_err + s.g_reference * carried + s.g_reference / n,
            "3σ-equivalent (20 blocks, 3.45) + the reference's accuracy in Z carried to g (×Z/(Z−1)) + g/N finite size",
        ),
        Check::within(
            &format!("η = {}: S(k → 0) vs 1/(d(ηZ)/dη) of the reference", s.eta),
            s.s0,
            s.s0_err,
            s.s0_reference,
            t * s.s0_err + s.s0_reference * (10.0 * s.reference_accuracy + 1.0 / n),
            "3σ-equivalent (20 blocks, 3.45) + the reference's accuracy ×10 for its derivative + S(0)/N finite size (canonical ensemble)",
        ),
    ]
}

/// Runs the experiment.
pub fn run(options: &Options) -> Result<ExperimentResult, ExperimentError> {
    let d = options.dimension;
    let (n, per_particle, etas) = match (d, options.size) {
        (2, Size::Quick) => (900, 200, vec![0.3, 0.6]),
        (2, Size::Report) => (3600, 400, vec![0.2, 0.4, 0.55, 0.65]),
        (2, Size::Long) => (10_000, 2000, vec![0.2, 0.3, 0.4, 0.5, 0.55, 0.6, 0.65]),
        (_, Size::Quick) => (1000, 200, vec![0.3, 0.45]),
        (_, Size::Report) => (3375, 300, vec![0.2, 0.35, 0.45]),
        (_, Size::Long) => (10_648, 2000, vec![0.1, 0.2, 0.3, 0.35, 0.4, 0.45, 0.49]),
    };
    let (dilute_n, dilute_per_particle) = match (d, options.size) {
        (2, Size::Quick) => (900, 500),
        (2, Size::Report) => (3600, 700),
        (2, Size::Long) => (10_000, 4000),
        (_, Size::Quick) => (1000, 500),
        (_, Size::Report) => (3375, 700),
        (_, Size::Long) => (10_648, 4000),
    };
    let states = super::in_parallel(etas.len(), 1, |k| measure(d, etas[k], n, per_particle, options.seed + k as u64))?;
    let dilute = measure_dilute(d, dilute_n, dilute_per_particle, options.seed + etas.len() as u64)?;
    let mut checks: Vec<Check> = states.iter().flat_map(checks_for).collect();
    checks.push(dilute_check(&dilute));
    let dir = options.plot_dir(NAME)?;
    let kind = if d == 2 { "disks" } else { "spheres" };
    let curves = |pick: fn(&StructureState) -> &Vec<[f64; 2]>| -> Vec<Series> {
        states
            .iter()
            .map(|s| Series::line(&format!("η = {}", s.eta), pick(s).iter().map(|p| (p[0], p[1])).collect()))
            .collect()
    };
    draw(
        &Chart {
            title: format!("Radial distribution function ({kind})"),
            x_label: "r (σ)".into(),
            y_label: "g(r) (dimensionless)".into(),
            series: curves(|s| &s.rdf),
            legend_left: false,
        },
        &dir.join("rdf.svg"),
    )?;
    draw(
        &Chart {
            title: format!("Static structure factor ({kind})"),
            x_label: "k (1/σ)".into(),
            y_label: "S(k) (dimensionless)".into(),
            series: curves(|s| &s.sk),
            legend_left: false,
        },
        &dir.join("sk.svg"),
    )?;
    let density = crate::lab::collision_rate::number_density(d, DILUTE_ETA);
    draw(
        &Chart {
            title: format!("g(r) of a dilute fluid (η = {DILUTE_ETA}, {kind}) against its first order in density"),
            x_label: "r (σ)".into(),
            y_label: "g(r) (dimensionless)".into(),
            legend_left: false,
            series: vec![
                Series::errors(
                    "measured (bins of 0.1σ)",
                    dilute.bins.iter().map(|b| (0.5 * (b.r[0] + b.r[1]), b.g)).collect(),
                    dilute.bins.iter().map(|b| b.error).collect(),
                ),
                Series::line(
                    "1 + n·X(r) (Nijboer & van Hove)",
                    (0..=120)
                        .map(|k| 1.0 + k as f64 / 100.0)
                        .map(|r| (r, crate::theory::g_first_order(d, density, r)))
                        .collect(),
                ),
            ],
        },
        &dir.join("dilute.svg"),
    )?;
    let top = etas.iter().copied().fold(0.0, f64::max) + 0.02;
    let line = |f: &dyn Fn(f64) -> f64| (1..=100).map(|k| k as f64 * top / 100.0).map(|e| (e, f(e))).collect();
    draw(
        &Chart {
            title: format!("Contact value and S(0) against the equation of state ({kind})"),
            x_label: "packing fraction η (dimensionless)".into(),
            y_label: "g(σ⁺), S(0) (dimensionless)".into(),
            legend_left: true,
            series: vec![
                Series::errors(
                    "g(σ⁺) from g(r)",
                    states.iter().map(|s| (s.eta, s.g_contact)).collect(),
                    states.iter().map(|s| s.g_contact_err).collect(),
                ),
                Series::line(
                    "g(σ⁺) of the reference EOS",
                    line(&|e| (enskog_reference(d, e).1 - 1.0) / (2f64.powi(d as i32 - 1) * e)),
                ),
                Series::errors(
                    "S(k → 0)",
                    states.iter().map(|s| (s.eta, s.s0)).collect(),
                    states.iter().map(|s| s.s0_err).collect(),
                ),
                Series::line("1/(d(ηZ)/dη) of the reference EOS", line(&|e| s0_reference(d, e))),
            ],
        },
        &dir.join("contact_and_s0.svg"),
    )?;
    Ok(options.result(
        NAME,
        json!({ "dimension": d, "n_particles": n, "packing_fractions": etas, "boundary": "periodic", "kT": 1.0,
            "production_collisions_per_particle": per_particle, "dilute": { "eta": DILUTE_ETA, "n_particles": dilute_n,
            "production_collisions_per_particle": dilute_per_particle, "rdf_r_max": 2.5, "rdf_bins": 250 } }),
        json!({ "states": states, "dilute": dilute }),
        checks,
        vec!["rdf.svg".into(), "sk.svg".into(), "contact_and_s0.svg".into(), "dilute.svg".into()],
    ))
}
