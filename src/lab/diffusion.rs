//! `diffusion`: self-diffusion from the mean squared displacement and from the Green–Kubo
//! integral of the velocity autocorrelation, against Enskog's — disks or spheres.
//!
//! Each state (periodic box, equilibrated from a lattice) runs with the `msd` and `vacf`
//! observers, sampling every mean free time. Checks per density:
//!
//! * **two routes to D**: `⟨Δr²(τ)⟩ = 2∫₀^τ ⟨v(0)·Δr(s)⟩ ds` in equilibrium, so the MSD's
//!   slope over `[τ/4, τ]` (the `msd` observer's D, `τ` its longest well-sampled lag) equals
//!   the mean over those lags of the Green–Kubo running integral `D_GK(s) = (1/d)⟨v(0)·Δr(s)⟩`
//!   (exact, not a quadrature; the mean by the trapezoid rule over lags a quarter octave
//!   apart, below 10⁻³ of D): the difference is 0 within the 3σ-equivalent (3.45) of its
//!   block jackknife — the two observers sample at the same instants, so their blocks are
//!   the same stretches of the run and the correlation of the two routes is accounted for —
//!   plus 0.002·D for the quadrature.
//! * **disks: D(t) grows like ln t** (Alder & Wainwright, Phys. Rev. A 1, 18 (1970)): the
//!   slope of `D_GK` against `ln t` between 10 mean free times and the sound-crossing time
//!   `L/c` is positive by more than its 3σ-equivalent (a jackknife error) — in 3D it levels
//!   off instead.
//!
//! Reported, not checked: `D/D_E` against density (Enskog's `D_E`, with the contact value of
//! the reference equation of state), beside the published event-driven values it is usually
//! compared with (Alder, Gass & Wainwright, J. Chem. Phys. 53, 3813 (1970); Erpenbeck &
//! Wood, Phys. Rev. A 43, 4254 (1991); in 3D with the finite-size correction
//! `D_∞ = D_L + 2.837297·kT/(6πη_sL)` of Yeh & Hummer, J. Phys. Chem. B 108, 15873 (2004),
//! here with Enskog's η_s): their stated uncertainties were not at hand to make a check of
//! them. In 2D D has no finite limit; the value at the longest lag is reported.

use super::collision_rate::{enskog_reference, number_density};
use super::plot::{Chart, Series, draw};
use super::stats::three_sigma_factor;
use super::{Check, ExperimentError, ExperimentResult, Options, Size, finished_run, fluid_config};
use crate::observe::Observable;
use crate::observe::correlator::Correlator;
use crate::run::Config;
use crate::theory::{enskog_diffusion, enskog_viscosity, sound_speed};
use serde::{Deserialize, Serialize};
use serde_json::json;

/// The experiment's name.
pub const NAME: &str = "diffusion";

/// One measured state.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct DiffusionState {
    /// Packing fraction.
    pub eta: f64,
    /// Particles.
    pub n_particles: usize,
    /// Production collisions.
    pub collisions: u64,
    /// The mean free time (Enskog, reference contact value).
    pub mean_free_time: f64,
    /// D from the MSD's slope, its error and its lag.
    pub d_msd: f64,
    /// Its standard error.
    pub d_msd_err: f64,
    /// The lag it is read at.
    pub lag: f64,
    /// The mean of D_GK over [lag/4, lag].
    pub d_gk_mean: f64,
    /// The error of D_GK at the lag.
    pub d_gk_err: f64,
    /// `D_msd − mean D_GK`, and its jackknife error (both routes' blocks together).
    pub difference: f64,
    /// Its standard error.
    pub difference_err: f64,
    /// Enskog's D.
    pub d_enskog: f64,
    /// `D_msd/D_E`.
    pub ratio: f64,
    /// The Yeh–Hummer correction (3D; 0 in 2D).
    pub yeh_hummer: f64,
    /// `dD_GK/d ln t` over [10 mean free times, L/c], and its jackknife error.
    pub log_slope: f64,
    /// Its error.
    pub log_slope_err: f64,
    /// The running `D_GK(t)`: lag, value, error.
    pub running: Vec<[f64; 3]>,
}

/// The least-squares slope of `y` against `x`.
pub fn slope(points: &[(f64, f64)]) -> f64 {
    let n = points.len() as f64;
    let (mx, my) = points.iter().fold((0.0, 0.0), |(a, b), p| (a + p.0 / n, b + p.1 / n));
    let sxy: f64 = points.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    let sxx: f64 = points.iter().map(|p| (p.0 - mx).powi(2)).sum();
    sxy / sxx
}

/// The lags of `c` within `[from, to]`, as indices.
pub fn lags_within(c: &Correlator, from: f64, to: f64) -> Vec<usize> {
    let longest = c.longest_lag(crate::observe::msd::MIN_ORIGINS).unwrap_or(0);
    (1..=longest).filter(|&k| c.tau(k) >= from && c.tau(k) <= to).collect()
}

/// Measures one state.
pub fn measure(d: usize, eta: f64, n: usize, per_particle: u64, seed: u64) -> Result<DiffusionState, ExperimentError> {
    let production = per_particle * n as u64;
    let (rate, _, _, _) = enskog_reference(d, eta);
    let every = 1.0 / rate;
    let observe = format!("[observe.msd]\nevery = {every:?}\n[observe.vacf]\nevery = {every:?}\n");
    let config = Config::parse(&fluid_config(d, eta, n, production / 10, production, seed, &observe), NAME)?;
    if d == 3 { measure_in::<3>(config, eta, n, production) } else { measure_in::<2>(config, eta, n, production) }
}

fn measure_in<const D: usize>(
    config: Config,
    eta: f64,
    n: usize,
    collisions: u64,
) -> Result<DiffusionState, ExperimentError> {
    let run = finished_run::<D>(config)?;
    let (Some(Observable::Msd(msd)), Some(Observable::Vacf(vacf))) = (run.observables.first(), run.observables.get(1))
    else {
        return Err(ExperimentError::Missing("the msd and vacf observables"));
    };
    let diffusion = msd.diffusion();
    let (Some(dm), Some((k, q))) = (diffusion.first(), msd.diffusion_lags()) else {
        return Err(ExperimentError::Missing("a lag with enough origins"));
    };
    let c = &vacf.correlator;
    let df = D as f64;
    // The mean of D_GK over [τ/4, τ] by the trapezoid rule.
    let within = lags_within(c, dm.lag / 4.0, dm.lag);
    let lags = c.lags();
    let at = |k: usize| lags.iter().find(|l| l.tau == c.tau(k)).expect("a lag with origins");
    let trapezoid: f64 = within
        .windows(2)
        .map(|w| 0.5 * (at(w[0]).values[0][1].0 + at(w[1]).values[0][1].0) * (c.tau(w[1]) - c.tau(w[0])))
        .sum();
    let d_gk_mean = trapezoid / (0.75 * dm.lag * df);
    let d_gk_err = at(*within.last().expect("lags within")).values[0][1].1 / df;
    // The difference of the two routes over the MSD's own lags, jackknifed over the blocks
    // both share (the two correlators sample at the same instants, so their lags coincide).
    let (difference, difference_err) = msd.correlator.estimate_with(c, |m, v| {
        let from_msd = (m(k, 0, 0) - m(q, 0, 0)) / (2.0 * df * 0.75 * c.tau(k));
        let integral: f64 =
            within.windows(2).map(|w| 0.5 * (v(w[0], 0, 1) + v(w[1], 0, 1)) * (c.tau(w[1]) - c.tau(w[0]))).sum();
        from_msd - integral / (0.75 * c.tau(k) * df)
    });
    // dD_GK/d ln t over [10 mean free times, L/c].
    let (rate, z, _, _) = enskog_reference(D, eta);
    let h = 1e-5;
    let dz = (enskog_reference(D, eta + h).1 - enskog_reference(D, eta - h).1) / (2.0 * h);
    let c_sound = sound_speed(D, eta, z, dz);
    let length = run.sim.sim_box().volume().powf(1.0 / df);
    let window = lags_within(c, 10.0 / rate, length / c_sound);
    let (log_slope, log_slope_err) = if window.len() >= 3 {
        c.estimate(|m| slope(&window.iter().map(|&k| (c.tau(k).ln(), m(k, 0, 1) / df)).collect::<Vec<_>>()))
    } else {
        (f64::NAN, f64::NAN)
    };
    let density = number_density(D, eta);
    let g = (z - 1.0) / (2f64.powi(D as i32 - 1) * eta);
    let d_enskog = enskog_diffusion(D, density, g);
    let yeh_hummer =
        if D == 3 { 2.837297 / (6.0 * std::f64::consts::PI * enskog_viscosity(3, eta, g) * length) } else { 0.0 };
    Ok(DiffusionState {
        eta,
        n_particles: n,
        collisions,
        mean_free_time: 1.0 / rate,
        d_msd: dm.d,
        d_msd_err: dm.error,
        lag: dm.lag,
        d_gk_mean,
        d_gk_err,
        difference,
        difference_err,
        d_enskog,
        ratio: dm.d / d_enskog,
        yeh_hummer,
        log_slope,
        log_slope_err,
        running: lags.iter().skip(1).map(|l| [l.tau, l.values[0][1].0 / df, l.values[0][1].1 / df]).collect(),
    })
}

/// The checks of one state in `d` dimensions.
pub fn checks_for(d: usize, s: &DiffusionState) -> Vec<Check> {
    let t = three_sigma_factor(20);
    let mut checks = vec![Check::within(
        &format!("η = {}: D from the MSD's slope − the Green–Kubo integral over the same lags", s.eta),
        s.difference,
        s.difference_err,
        0.0,
        t * s.difference_err + 0.002 * s.d_gk_mean,
        "⟨Δr²⟩ = 2∫⟨v(0)·Δr⟩ in equilibrium; 3σ-equivalent (3.45) of the difference's block jackknife (both routes' blocks together) + 0.002·D for the trapezoid rule",
    )];
    if d == 2 && s.log_slope.is_finite() {
        checks.push(Check::at_least(
            &format!("η = {}: dD/d ln t over [10 mean free times, L/c] is positive", s.eta),
            s.log_slope - t * s.log_slope_err,
            s.log_slope_err,
            0.0,
            "the long-time tail t⁻¹ makes D(t) grow like ln t in 2D; the slope less its 3σ-equivalent (3.45 × jackknife error) above 0",
        ));
    }
    checks
}

/// Runs the experiment.
pub fn run(options: &Options) -> Result<ExperimentResult, ExperimentError> {
    let d = options.dimension;
    let (n, per_particle, etas) = match (d, options.size) {
        (2, Size::Quick) => (900, 600, vec![0.3]),
        (2, Size::Report) => (2500, 1500, vec![0.1, 0.3, 0.5]),
        (2, Size::Long) => (10_000, 4000, vec![0.1, 0.2, 0.3, 0.4, 0.5, 0.6]),
        (_, Size::Quick) => (1000, 600, vec![0.3]),
        (_, Size::Report) => (2744, 1000, vec![0.1, 0.25, 0.4]),
        (_, Size::Long) => (8000, 2000, vec![0.1, 0.2, 0.3, 0.4, 0.45]),
    };
    let states = super::in_parallel(etas.len(), 1, |k| measure(d, etas[k], n, per_particle, options.seed + k as u64))?;
    let checks: Vec<Check> = states.iter().flat_map(|s| checks_for(d, s)).collect();
    let dir = options.plot_dir(NAME)?;
    let kind = if d == 2 { "disks" } else { "spheres" };
    draw(
        &Chart {
            title: format!("Running Green–Kubo D(t) ({kind})"),
            x_label: "ln(t/t_E), t_E the mean free time".into(),
            y_label: "D_GK(t)/D_E (dimensionless)".into(),
            legend_left: true,
            series: states
                .iter()
                .map(|s| {
                    Series::errors(
                        &format!("η = {}", s.eta),
                        s.running.iter().map(|r| ((r[0] / s.mean_free_time).ln(), r[1] / s.d_enskog)).collect(),
                        s.running.iter().map(|r| r[2] / s.d_enskog).collect(),
                    )
                })
                .collect(),
        },
        &dir.join("running_d.svg"),
    )?;
    draw(
        &Chart {
            title: format!("Self-diffusion against Enskog ({kind})"),
            x_label: "packing fraction η (dimensionless)".into(),
            y_label: "D/D_E (dimensionless)".into(),
            legend_left: false,
            series: vec![Series::errors(
                "D from the MSD",
                states.iter().map(|s| (s.eta, s.ratio)).collect(),
                states.iter().map(|s| s.d_msd_err / s.d_enskog).collect(),
            )],
        },
        &dir.join("d_over_enskog.svg"),
    )?;
    Ok(options.result(
        NAME,
        json!({ "dimension": d, "n_particles": n, "packing_fractions": etas, "boundary": "periodic", "kT": 1.0,
            "production_collisions_per_particle": per_particle, "sample_every_mean_free_times": 1.0 }),
        json!({ "states": states }),
        checks,
        vec!["running_d.svg".into(), "d_over_enskog.svg".into()],
    ))
}
