//! Observers: what a run measures, fed every event's [`Outcome`] as it happens.
//!
//! The push model (as in ripgrep's `Sink`): the [`Run`](crate::run::Run) owns the loop, and
//! after every event it hands each observer the simulation as the event left it and what the
//! event did ([`Observer::observe`]). An observer keeps only what it needs — sums, a time
//! series, histograms — so nothing is stored per event and a run of any length costs the
//! same memory.
//!
//! * [`Thermo`]: temperature, the collision-virial and wall pressures, the samples of the time
//!   series (every run has it; its estimators are specified in [`thermo`]).
//! * The registered observables a configuration names under `[observe.<name>]`
//!   ([`Selection`]): [`velocities`] (the velocity distribution against the Maxwellian),
//!   [`rdf`] (g(r) per species pair and its contact value), [`msd`] and [`vacf`] (the mean
//!   squared displacement and the velocity autocorrelation over many time origins, by the
//!   multiple-tau scheme of [`correlator`], and the diffusion coefficient from each), [`sk`]
//!   (the structure factor of a periodic box and its `k → 0` limit), [`bond_order`] (Ψ₆ and
//!   g₆(r) of disks, Q₆ of spheres, along the run). An observable that samples at
//!   instants of its own (every `every` time units) says when it is next
//!   [due](Observable::due); the run hands it the particles at that instant, before the
//!   event that follows it ([`Observable::sample`]), and writes its own files at the end
//!   ([`Observable::files`]).
//! * [`contacts`]: the contact network of a dense state (contacts per particle, rattlers),
//!   an analysis of one state rather than an observer of events; likewise [`order`], its
//!   bond-orientational order (Ψ₆ of disks, Q₆ of spheres: crystal or amorphous).
//!   A run keeps them in its checkpoints and reports them in `summary.json`
//!   (`"observables"`); an experiment can also build any observer itself and hand it to
//!   [`Run::advance`](crate::run::Run::advance).
//!
//! # Adding an observable
//!
//! Its file here, with an `Options` type (what `[observe.<name>]` may hold) and a type that
//! implements [`Observer`] and serde's traits; then, in this file: `pub mod`, its field of
//! [`Selection`], its variant of [`Observable`], and its line in each match below.

pub mod blocks;
pub mod bond_order;
pub mod contacts;
pub mod correlator;
pub mod msd;
pub mod order;
pub mod rdf;
pub mod sk;
pub mod thermo;
pub mod vacf;
pub mod velocities;

pub use blocks::block_error;
pub use thermo::{Sample, Thermo, Totals};

use crate::engine::{Outcome, Simulation};
use serde::{Deserialize, Serialize};

/// A unit-diameter, unit-mass particle of species 0 at `position` moving at `velocity` from
/// time 0: the observers' tests build their configurations from it.
#[cfg(test)]
pub(crate) fn test_particle<const D: usize>(position: [f64; D], velocity: [f64; D]) -> crate::engine::Particle<D> {
    crate::engine::Particle {
        position: position.into(),
        velocity: velocity.into(),
        time: 0.0,
        radius: 0.5,
        mass: 1.0,
        species: 0,
        events: 0,
    }
}

/// An option refused: its key (`observe.<observer>.<field>`), its value, and what is allowed.
pub type Refusal = (String, String, String);

/// Refuses `value` of `observe.<observer>.<key>` unless it is a positive finite number;
/// `what` names the quantity ("length", "time", "wave number").
fn positive(observer: &str, key: &str, value: Option<f64>, what: &str) -> Result<(), Refusal> {
    match value {
        Some(x) if !(x.is_finite() && x > 0.0) => {
            Err((format!("observe.{observer}.{key}"), x.to_string(), format!("must be a positive {what}")))
        }
        _ => Ok(()),
    }
}

/// Refuses a count `value` of `observe.<observer>.<key>` outside `1 ..= max`.
fn count_within(observer: &str, key: &str, value: Option<usize>, max: usize) -> Result<(), Refusal> {
    match value {
        Some(n) if !(1..=max).contains(&n) => {
            Err((format!("observe.{observer}.{key}"), n.to_string(), format!("must lie in 1 ..= {max}")))
        }
        _ => Ok(()),
    }
}

/// Anything that wants to see every event.
pub trait Observer<const D: usize> {
    /// Called after every processed event, with the simulation as the event left it.
    fn observe(&mut self, sim: &Simulation<D>, outcome: &Outcome<D>);
}

/// The observables a configuration asks for: `[observe.<name>]`, one table each, holding its
/// options (an empty table for the defaults). Unknown names are refused like any unknown
/// key.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Selection {
    /// The velocity distribution at the start and at every sample ([`velocities`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub velocities: Option<velocities::Options>,
    /// The radial distribution function ([`rdf`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rdf: Option<rdf::Options>,
    /// The mean squared displacement ([`msd`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub msd: Option<msd::Options>,
    /// The velocity autocorrelation ([`vacf`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub vacf: Option<vacf::Options>,
    /// The structure factor ([`sk`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sk: Option<sk::Options>,
    /// Bond-orientational order: Ψ₆ and g₆(r) of disks, Q₆ of spheres ([`bond_order`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bond_order: Option<bond_order::Options>,
}

impl Selection {
    /// Whether nothing is asked for.
    pub fn is_empty(&self) -> bool {
        *self == Selection::default()
    }

    /// Checks the options for a box `periodic` along every axis or not: the key, its value
    /// and what is allowed.
    pub fn check(&self, periodic: bool) -> Result<(), Refusal> {
        if let Some(options) = &self.rdf {
            options.check()?;
        }
        if let Some(options) = &self.msd {
            options.check("msd")?;
        }
        if let Some(options) = &self.vacf {
            options.check("vacf")?;
        }
        if let Some(options) = &self.sk {
            options.check(periodic)?;
        }
        if let Some(options) = &self.bond_order {
            options.check()?;
        }
        Ok(())
    }

    /// The observables asked for, observing `sim` from now, in registry order.
    pub fn start<const D: usize>(&self, sim: &Simulation<D>) -> Vec<Observable> {
        let mut out = Vec::new();
        if let Some(options) = &self.velocities {
            out.push(Observable::Velocities(velocities::Velocities::new(sim, options.clone())));
        }
        if let Some(options) = &self.rdf {
            out.push(Observable::Rdf(rdf::Rdf::new(sim, options.clone())));
        }
        if let Some(options) = &self.msd {
            out.push(Observable::Msd(msd::Msd::new(sim, options.clone())));
        }
        if let Some(options) = &self.vacf {
            out.push(Observable::Vacf(vacf::Vacf::new(sim, options.clone())));
        }
        if let Some(options) = &self.sk {
            out.push(Observable::Sk(sk::Sk::new(sim, options.clone())));
        }
        if let Some(options) = &self.bond_order {
            out.push(Observable::BondOrder(bond_order::BondOrder::new(sim, options.clone())));
        }
        out
    }

    /// The names asked for, in registry order (what [`start`](Self::start) builds).
    pub fn names(&self) -> Vec<&'static str> {
        let mut out = Vec::new();
        if self.velocities.is_some() {
            out.push("velocities");
        }
        if self.rdf.is_some() {
            out.push("rdf");
        }
        if self.msd.is_some() {
            out.push("msd");
        }
        if self.vacf.is_some() {
            out.push("vacf");
        }
        if self.sk.is_some() {
            out.push("sk");
        }
        if self.bond_order.is_some() {
            out.push("bond_order");
        }
        out
    }
}

/// A registered observable, as a run carries it (and saves it in its checkpoints).
#[non_exhaustive]
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Observable {
    /// The velocity distribution.
    Velocities(velocities::Velocities),
    /// g(r).
    Rdf(rdf::Rdf),
    /// The mean squared displacement.
    Msd(msd::Msd),
    /// The velocity autocorrelation.
    Vacf(vacf::Vacf),
    /// The structure factor.
    Sk(sk::Sk),
    /// Bond-orientational order.
    BondOrder(bond_order::BondOrder),
}

impl Observable {
    /// Its name (its key under `[observe]` and in the summary).
    pub fn name(&self) -> &'static str {
        match self {
            Observable::Velocities(_) => "velocities",
            Observable::Rdf(_) => "rdf",
            Observable::Msd(_) => "msd",
            Observable::Vacf(_) => "vacf",
            Observable::Sk(_) => "sk",
            Observable::BondOrder(_) => "bond_order",
        }
    }

    /// What it measured, for `summary.json`.
    pub fn results(&self) -> serde_json::Value {
        match self {
            Observable::Velocities(v) => serde_json::to_value(v),
            Observable::Rdf(g) => serde_json::to_value(g.results()),
            Observable::Msd(m) => serde_json::to_value(m.results()),
            Observable::Vacf(c) => serde_json::to_value(c.results()),
            Observable::Sk(s) => serde_json::to_value(s.results()),
            Observable::BondOrder(b) => serde_json::to_value(b.results()),
        }
        .expect("results serialise")
    }

    /// Whether it was built for `D` dimensions (a saved one must have been).
    pub fn dimension(&self) -> usize {
        match self {
            Observable::Velocities(v) => v.dimension,
            Observable::Rdf(g) => g.dimension,
            Observable::Msd(m) => m.dimension,
            Observable::Vacf(c) => c.dimension,
            Observable::Sk(s) => s.dimension,
            Observable::BondOrder(b) => b.dimension,
        }
    }

    /// When it next samples at an instant of its own (`None`: it samples on events only).
    #[inline]
    pub fn due(&self) -> Option<f64> {
        match self {
            Observable::Velocities(_) => None,
            Observable::Rdf(g) => Some(g.due()),
            Observable::Msd(m) => Some(m.due()),
            Observable::Vacf(c) => Some(c.due()),
            Observable::Sk(s) => Some(s.due()),
            Observable::BondOrder(b) => Some(b.due()),
        }
    }

    /// Samples at the instant `t` it was [`due`](Self::due): `sim`'s particles are all in
    /// free flight from their last update to `t` (no event lies between).
    pub fn sample<const D: usize>(&mut self, sim: &Simulation<D>, t: f64) {
        match self {
            Observable::Velocities(_) => {}
            Observable::Rdf(g) => g.sample(sim.particles(), sim.sim_box(), t),
            Observable::Msd(m) => m.sample(sim.particles(), t),
            Observable::Vacf(c) => c.sample(sim.particles(), t),
            Observable::Sk(s) => s.sample(sim.particles(), t),
            Observable::BondOrder(b) => b.sample(sim.particles(), sim.sim_box(), t),
        }
    }

    /// The files it writes into a run's directory: name and contents.
    pub fn files(&self) -> Vec<(&'static str, String)> {
        match self {
            Observable::Velocities(_) => Vec::new(),
            Observable::Rdf(g) => vec![("rdf.csv", g.csv())],
            Observable::Msd(m) => vec![("msd.csv", m.csv())],
            Observable::Vacf(c) => vec![("vacf.csv", c.csv())],
            Observable::Sk(s) => vec![("sk.csv", s.csv())],
            Observable::BondOrder(b) if b.dimension == 2 => {
                vec![("bond_order.csv", b.csv()), ("g6.csv", b.g6_csv())]
            }
            Observable::BondOrder(b) => vec![("bond_order.csv", b.csv())],
        }
    }
}

impl<const D: usize> Observer<D> for Observable {
    #[inline]
    fn observe(&mut self, sim: &Simulation<D>, outcome: &Outcome<D>) {
        match self {
            Observable::Velocities(v) => v.observe(sim, outcome),
            Observable::Rdf(g) => g.observe(sim, outcome),
            Observable::Msd(m) => m.observe(sim, outcome),
            Observable::Vacf(c) => c.observe(sim, outcome),
            Observable::Sk(s) => s.observe(sim, outcome),
            Observable::BondOrder(b) => b.observe(sim, outcome),
        }
    }
}
