//! `hexatic`: bond-orientational order and pressure across the melting of hard disks
//! (and, in 3D, across the freezing of hard spheres) — a qualitative check.
//!
//! Disks: N ≈ 10⁴ in a periodic box from a triangular lattice at η = 0.69 … 0.73 (the liquid,
//! the liquid–hexatic coexistence of Bernard & Krauth, PRL 107, 155704 (2011), at
//! 0.700–0.716, the hexatic phase, the solid above 0.720), with the `bond_order` observer
//! (Ψ₆ = |⟨ψ₆⟩| of each sample, bonds within 1.4σ). Spheres: the fluid at η = 0.49 from a
//! simple cubic lattice and the fcc crystal at 0.55 (freezing 0.492, melting 0.543), with Q₆.
//!
//! Check: the global order at the densest state exceeds the one at the least dense by more
//! than the 3σ-equivalent (3.45) of their 20-block errors combined — the order appears across
//! the transition. Reported, not checked: βPσ^d against η, where Bernard & Krauth's
//! first-order liquid–hexatic transition shows as a non-monotonic pressure (a Mayer–Wood
//! loop). Finite-size caveats: the loop's height shrinks with N (it is the interface's free
//! energy over the box) and the states near coexistence relax over 10⁸–10⁹ collisions at
//! N = 10⁴ (Engel et al., Phys. Rev. E 87, 042134 (2013), with event-driven dynamics among
//! three methods); runs of about 10³ collisions a particle, started from a lattice, can show
//! the lattice's memory rather than the loop. The figure is the check's context, not a
//! measurement of the transition.

use super::plot::{Chart, Series, draw};
use super::stats::three_sigma_factor;
use super::{Check, ExperimentError, ExperimentResult, Options, Size, finished_run};
use crate::observe::Observable;
use crate::run::Config;
use serde::{Deserialize, Serialize};
use serde_json::json;

/// The experiment's name.
pub const NAME: &str = "hexatic";

/// One state.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct OrderState {
    /// Packing fraction.
    pub eta: f64,
    /// Particles.
    pub n_particles: usize,
    /// Production collisions.
    pub collisions: u64,
    /// Z and its error.
    pub z: f64,
    /// Its standard error.
    pub z_err: f64,
    /// `βPσ^d`.
    pub pressure: f64,
    /// Its standard error.
    pub pressure_err: f64,
    /// Ψ₆ (disks) or Q₆ (spheres), mean over samples.
    pub order: f64,
    /// Its standard error.
    pub order_err: f64,
    /// `N(⟨X²⟩ − ⟨X⟩²)`.
    pub susceptibility: f64,
}

/// Measures one state.
fn measure<const D: usize>(eta: f64, n: usize, per_particle: u64, seed: u64) -> Result<OrderState, ExperimentError> {
    let production = per_particle * n as u64;
    let placement = match (D, eta > 0.5) {
        (2, _) => "triangular",
        (_, true) => "fcc",
        _ => "simple_cubic",
    };
    let text = format!(
        "dimension = {D}\nseed = {seed}\n[box]\npacking_fraction = {eta}\nboundary = \"periodic\"\n\
         [[species]]\ncount = {n}\nradius = 0.5\nmass = 1.0\n[init]\nplacement = \"{placement}\"\n\
         [equilibration]\ncollisions = {}\n[run]\ncollisions = {production}\n[observe.bond_order]\nevery = 1.0\n",
        production / 2
    );
    let run = finished_run::<D>(Config::parse(&text, NAME)?)?;
    let summary = run.summary();
    let Some(Observable::BondOrder(order)) = run.observables.first() else {
        return Err(ExperimentError::Missing("the bond_order observable"));
    };
    let r = order.results();
    let density = n as f64 / run.sim.sim_box().volume();
    Ok(OrderState {
        eta,
        n_particles: n,
        collisions: production,
        z: summary.compressibility,
        z_err: summary.compressibility_error,
        pressure: summary.compressibility * density,
        pressure_err: summary.compressibility_error * density,
        order: r.value,
        order_err: r.error,
        susceptibility: r.susceptibility,
    })
}

/// The check: the order at the densest state above the least dense one's.
pub fn checks(d: usize, states: &[OrderState]) -> Vec<Check> {
    let (low, high) = (&states[0], &states[states.len() - 1]);
    let name = if d == 2 { "Ψ₆" } else { "Q₆" };
    vec![Check::at_least(
        &format!("{name}(η = {}) − {name}(η = {}) exceeds its 3σ-equivalent", high.eta, low.eta),
        high.order - low.order - three_sigma_factor(20) * high.order_err.hypot(low.order_err),
        high.order_err.hypot(low.order_err),
        0.0,
        "the order appears across the transition; 3.45 × both 20-block errors combined",
    )]
}

/// Runs the experiment.
pub fn run(options: &Options) -> Result<ExperimentResult, ExperimentError> {
    let d = options.dimension;
    let (n, per_particle, etas) = match (d, options.size) {
        (2, Size::Quick) => (2500, 300, vec![0.69, 0.71, 0.73]),
        (2, Size::Report) => (10_000, 400, vec![0.69, 0.70, 0.71, 0.72, 0.73]),
        (2, Size::Long) => (10_000, 20_000, vec![0.69, 0.70, 0.705, 0.71, 0.715, 0.72, 0.73]),
        (_, Size::Quick) => (1000, 300, vec![0.49, 0.55]),
        (_, Size::Report) => (4000, 600, vec![0.49, 0.55]),
        (_, Size::Long) => (4000, 5000, vec![0.49, 0.52, 0.55]),
    };
    let seed = options.seed;
    let states = super::in_parallel(etas.len(), 1, |k| {
        if d == 3 {
            measure::<3>(etas[k], n, per_particle, seed + k as u64)
        } else {
            measure::<2>(etas[k], n, per_particle, seed + k as u64)
        }
    })?;
    let checks = checks(d, &states);
    // Whether βP falls anywhere as η rises (beyond the two points' combined errors).
    let loop_seen =
        states.windows(2).any(|w| w[1].pressure + w[1].pressure_err.hypot(w[0].pressure_err) < w[0].pressure);
    let dir = options.plot_dir(NAME)?;
    let (kind, order) = if d == 2 { ("disks", "Ψ₆") } else { ("spheres", "Q₆") };
    draw(
        &Chart {
            title: format!("Pressure across the transition, N = {n} ({kind})"),
            x_label: "packing fraction η (dimensionless)".into(),
            y_label: format!("βPσ^{d} (dimensionless)"),
            legend_left: true,
            series: vec![Series::errors(
                "collision virial",
                states.iter().map(|s| (s.eta, s.pressure)).collect(),
                states.iter().map(|s| s.pressure_err).collect(),
            )],
        },
        &dir.join("pressure.svg"),
    )?;
    draw(
        &Chart {
            title: format!("Bond-orientational order, N = {n} ({kind})"),
            x_label: "packing fraction η (dimensionless)".into(),
            y_label: format!("{order} (dimensionless)"),
            legend_left: true,
            series: vec![Series::errors(
                order,
                states.iter().map(|s| (s.eta, s.order)).collect(),
                states.iter().map(|s| s.order_err).collect(),
            )],
        },
        &dir.join("order.svg"),
    )?;
    Ok(options.result(
        NAME,
        json!({ "dimension": d, "n_particles": n, "packing_fractions": etas, "boundary": "periodic", "kT": 1.0,
            "production_collisions_per_particle": per_particle, "bond_cutoff": crate::observe::bond_order::CUTOFF }),
        json!({ "states": states, "pressure_falls_somewhere": loop_seen }),
        checks,
        vec!["pressure.svg".into(), "order.svg".into()],
    ))
}
