//! `long_time_tail`: the velocity autocorrelation decays as `t^(−d/2)` — Alder & Wainwright's
//! long-time tail (Phys. Rev. A 1, 18 (1970)) — with the amplitude of mode-coupling theory.
//!
//! One fluid state (η = 0.3, periodic box, equilibrated from a lattice) runs with the `vacf`
//! observer sampling every mean free time `t_E` (Enskog's, with the contact value of
//! the reference equation of state) over many time origins, up to twice the sound-crossing
//! time `L/c` (`c² = d(ηZ)/dη + (2/d)Z²`, reduced units). With `φ(t) = C(t)/C(0)`, over the
//! lags of the window `[10 t_E, L/c]` — long against the collisions, shorter than the time
//! sound needs to cross the box and return through the periodic images:
//!
//! * **slope**: the least-squares slope of `ln φ` against `ln t` is `−d/2` within the
//!   3σ-equivalent (3.45) of its block-jackknife error plus 0.1 for the corrections to the
//!   asymptote inside a window of one decade (relative terms of order `(t_E/t)^(1/2)` at its
//!   start, the returning sound at its end), stated before measuring;
//! * **amplitude**: the mean of `φ(t)·t^(d/2)` over the window against mode coupling,
//!   `A = (d − 1)/(d·n)·[4π(D + ν)]^(−d/2)` (Ernst, Hauge & van Leeuwen, Phys. Rev. A 4, 2055
//!   (1971); Dorfman & Cohen, Phys. Rev. A 6, 776 (1972)) with Enskog's `D` and `ν = η_s/(mn)`
//!   (`crate::theory`): tolerance the 3σ-equivalent of its jackknife error plus 30 % of A,
//!   the theory's own uncertainty here — the true `D + ν` differs from Enskog's by 10–20 %
//!   at η = 0.3 (Erpenbeck & Wood, Phys. Rev. A 43, 4254 (1991) found the 3D tail agreeing
//!   with Enskog-valued mode coupling past 15–30 mean free times), and `A ∝ (D + ν)^(−d/2)`.
//!
//! The plot: `φ(t)` on log–log axes (as `ln φ` against `ln t`) with the theory's line.

use super::collision_rate::{enskog_reference, number_density};
use super::diffusion::{lags_within, slope};
use super::plot::{Chart, Series, draw};
use super::stats::three_sigma_factor;
use super::{Check, ExperimentError, ExperimentResult, Options, Size, finished_run, fluid_config};
use crate::observe::Observable;
use crate::run::Config;
use crate::theory::{enskog_diffusion, enskog_viscosity, sound_speed, tail_amplitude};
use serde::{Deserialize, Serialize};
use serde_json::json;

/// The experiment's name.
pub const NAME: &str = "long_time_tail";

/// The packing fraction.
pub const ETA: f64 = 0.3;

/// What was measured.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Tail {
    /// Particles.
    pub n_particles: usize,
    /// Production collisions.
    pub collisions: u64,
    /// The mean free time.
    pub mean_free_time: f64,
    /// The sound-crossing time L/c.
    pub sound_crossing: f64,
    /// The window's ends.
    pub window: [f64; 2],
    /// Lags in the window.
    pub lags_in_window: usize,
    /// The slope of ln φ against ln t, and its error.
    pub slope: f64,
    /// Its standard error.
    pub slope_err: f64,
    /// The mean of φ·t^(d/2) over the window, and its error.
    pub amplitude: f64,
    /// Its standard error.
    pub amplitude_err: f64,
    /// Mode coupling's amplitude with Enskog's coefficients.
    pub amplitude_theory: f64,
    /// `φ(t)`: lag, value, error.
    pub phi: Vec<[f64; 3]>,
}

/// The checks of the tail in `d` dimensions.
pub fn checks(d: usize, tail: &Tail) -> Vec<Check> {
    let t = three_sigma_factor(20);
    let half = d as f64 / 2.0;
    vec![
        Check::within(
            &format!("the VACF's log–log slope over [10 t_E, L/c] ({} lags)", tail.lags_in_window),
            tail.slope,
            tail.slope_err,
            -half,
            t * tail.slope_err + 0.1,
            "−d/2 (Alder & Wainwright 1970); 3σ-equivalent (3.45 × block jackknife) + 0.1 for the asymptote's corrections in a one-decade window",
        ),
        Check::within(
            "the tail's amplitude φ·t^(d/2) against mode coupling with Enskog's D and ν",
            tail.amplitude,
            tail.amplitude_err,
            tail.amplitude_theory,
            t * tail.amplitude_err + 0.3 * tail.amplitude_theory,
            "Ernst, Hauge & van Leeuwen 1971; 3σ-equivalent (3.45 × block jackknife) + 30 % for Enskog's D + ν against the true one",
        ),
    ]
}

/// Runs the experiment.
pub fn run(options: &Options) -> Result<ExperimentResult, ExperimentError> {
    let d = options.dimension;
    let (n, per_particle) = match (d, options.size) {
        (2, Size::Quick) => (2500, 1000),
        (2, Size::Report) => (10_000, 2000),
        (2, Size::Long) => (40_000, 4000),
        (_, Size::Quick) => (2744, 600),
        (_, Size::Report) => (13_824, 800),
        (_, Size::Long) => (32_768, 2000),
    };
    let tail = if d == 3 {
        measure::<3>(n, per_particle, options.seed)?
    } else {
        measure::<2>(n, per_particle, options.seed)?
    };
    let half = d as f64 / 2.0;
    let checks = checks(d, &tail);
    let dir = options.plot_dir(NAME)?;
    let kind = if d == 2 { "disks" } else { "spheres" };
    let positive: Vec<&[f64; 3]> = tail.phi.iter().filter(|p| p[1] > 0.0).collect();
    let theory: Vec<(f64, f64)> = positive
        .iter()
        .filter(|p| p[0] >= 2.0 * tail.mean_free_time)
        .map(|p| (p[0].ln(), (tail.amplitude_theory * p[0].powf(-half)).ln()))
        .collect();
    draw(
        &Chart {
            title: format!("Velocity autocorrelation, η = {ETA}, N = {n} ({kind})"),
            x_label: "ln t (t in σ√(m/kT))".into(),
            y_label: "ln C(t)/C(0)".into(),
            legend_left: false,
            series: vec![
                Series::errors(
                    "measured (C > 0)",
                    positive.iter().map(|p| (p[0].ln(), p[1].ln())).collect(),
                    positive.iter().map(|p| p[2] / p[1]).collect(),
                ),
                Series::line(&format!("mode coupling, A·t^(−{half}) (Enskog D, ν)"), theory),
                Series::line("window [10 t_E, L/c]", vec![(tail.window[0].ln(), -1.0), (tail.window[1].ln(), -1.0)]),
            ],
        },
        &dir.join("vacf.svg"),
    )?;
    Ok(options.result(
        NAME,
        json!({ "dimension": d, "n_particles": n, "packing_fraction": ETA, "boundary": "periodic", "kT": 1.0,
            "production_collisions_per_particle": per_particle, "sample_every_mean_free_times": 1.0 }),
        json!(tail),
        checks,
        vec!["vacf.svg".into()],
    ))
}

fn measure<const D: usize>(n: usize, per_particle: u64, seed: u64) -> Result<Tail, ExperimentError> {
    let production = per_particle * n as u64;
    let (rate, z, _, _) = enskog_reference(D, ETA);
    let h = 1e-5;
    let dz = (enskog_reference(D, ETA + h).1 - enskog_reference(D, ETA - h).1) / (2.0 * h);
    let density = number_density(D, ETA);
    let length = (n as f64 / density).powf(1.0 / D as f64);
    let crossing = length / sound_speed(D, ETA, z, dz);
    let every = 1.0 / rate;
    let observe = format!("[observe.vacf]\nevery = {every:?}\nmax_lag = {:?}\n", 2.0 * crossing);
    let config = Config::parse(&fluid_config(D, ETA, n, production / 10, production, seed, &observe), NAME)?;
    let run = finished_run::<D>(config)?;
    let Some(Observable::Vacf(vacf)) = run.observables.first() else {
        return Err(ExperimentError::Missing("the vacf observable"));
    };
    let c = &vacf.correlator;
    let window = [10.0 / rate, crossing];
    let lags = lags_within(c, window[0], window[1]);
    let half = D as f64 / 2.0;
    let (slope, slope_err) = c.estimate(|m| {
        slope(&lags.iter().map(|&k| (c.tau(k).ln(), (m(k, 0, 0) / m(0, 0, 0)).ln())).collect::<Vec<_>>())
    });
    let (amplitude, amplitude_err) = c.estimate(|m| {
        lags.iter().map(|&k| m(k, 0, 0) / m(0, 0, 0) * c.tau(k).powf(half)).sum::<f64>() / lags.len() as f64
    });
    let g = (z - 1.0) / (2f64.powi(D as i32 - 1) * ETA);
    let amplitude_theory = tail_amplitude(D, density, enskog_diffusion(D, density, g), enskog_viscosity(D, ETA, g));
    let phi = c
        .lags()
        .iter()
        .skip(1)
        .filter(|l| l.origins >= crate::observe::msd::MIN_ORIGINS)
        .map(|l| {
            let c0 = c.estimate(|m| m(0, 0, 0)).0;
            [l.tau, l.values[0][0].0 / c0, l.values[0][0].1 / c0]
        })
        .collect();
    Ok(Tail {
        n_particles: n,
        collisions: production,
        mean_free_time: 1.0 / rate,
        sound_crossing: crossing,
        window,
        lags_in_window: lags.len(),
        slope,
        slope_err,
        amplitude,
        amplitude_err,
        amplitude_theory,
        phi,
    })
}
