//! The compression phase of a run (`[compress]`): the engine's growth
//! ([`Simulation::grow`]) driven to a packing fraction or to jamming, its reduced pressure
//! watched, and what it reached reported (`summary.json`'s `"compression"`).
//!
//! * **To a packing fraction** (`target_packing_fraction`): one growth ending exactly there;
//!   the run then equilibrates and measures at that density. Should the packing jam first
//!   (the engine's stall guard ends the growth), the run ends there, jammed, with a warning.
//! * **To jamming** (`until = "jammed"`): growths in stages — the first to close packing
//!   (π/(2√3), π/√18; the grid is sized for the radii there), each next one 0.02 further, as
//!   long as the box holds the particles — until the reduced pressure of a window of
//!   collisions reaches `pressure_limit`, or the clock stalls. The run ends at the jammed
//!   packing, whose contact network ([`contacts`]) is reported.
//!
//! The reduced pressure during compression is the collision virial over a window of `N`
//! pair collisions, `Z = 1 + Σ⟨r₁₂ | J⟩ / (d·N·kT·Δt)` with `kT` the thermostat's target
//! (free-volume theory: near jamming `Z ≈ d·φ_J/(φ_J − φ)`, so it diverges there).

use super::config::{Config, close_packing};
use crate::engine::{Ending, Outcome, SetupError, Simulation};
use crate::observe::contacts::contacts;
use serde::{Deserialize, Serialize};

/// What a compression reached (and, while it runs, its pressure window).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Compression {
    /// The packing fraction reached.
    pub packing_fraction: f64,
    /// The reduced pressure `Z = PV/(NkT)` of the last full window (absent before one).
    pub reduced_pressure: Option<f64>,
    /// Whether the packing jammed (the pressure limit, or a stalled clock).
    pub jammed: bool,
    /// How its last growth ended.
    pub ending: Option<Ending>,
    /// Pair collisions during the compression.
    pub collisions: u64,
    /// Simulated time of the compression.
    pub sim_time: f64,
    /// Growth stages run.
    pub stages: u32,
    /// The overlap audit at the end (largest overlap as a fraction of a contact distance).
    pub max_overlap: f64,
    /// For a jammed packing: contacts per particle that is not a rattler.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub contacts_per_particle: Option<f64>,
    /// For a jammed packing: how many particles rattle.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rattlers: Option<usize>,
    /// For a jammed packing: the gap tolerance of a contact.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub contact_tolerance: Option<f64>,
    /// Whether it is over.
    pub done: bool,
    /// The clock and the pair collisions when it started.
    pub started_at: (f64, u64),
    /// While it runs, the pressure window: its start, collisions and virial sum.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    window: Option<(f64, u64, f64)>,
}

/// Why a compression could not start.
#[derive(Clone, Debug, PartialEq)]
pub struct CompressionError {
    /// The engine's reason.
    pub error: SetupError,
    /// The keys it comes from.
    pub from: String,
}

impl Compression {
    /// Starts the compression `config` asks for on `sim` (at its initial state).
    pub fn start<const D: usize>(sim: &mut Simulation<D>, config: &Config) -> Result<Compression, CompressionError> {
        let c = config.compress.as_ref().expect("a [compress] table");
        let mut compression = Compression {
            packing_fraction: sim.packing_fraction(),
            window: Some((sim.time(), 0, 0.0)),
            started_at: (sim.time(), sim.counts().pair),
            ..Compression::default()
        };
        let target = match c.target_packing_fraction {
            Some(target) => target,
            None => close_packing(D).0,
        };
        compression.stage(sim, config, target).map_err(|error| CompressionError {
            error,
            from: match c.target_packing_fraction {
                Some(t) => format!("compress.target_packing_fraction = {t}"),
                None => "compress.until = \"jammed\"".into(),
            },
        })?;
        Ok(compression)
    }

    /// Starts a growth stage to `target` (for jamming: no further than the box holds).
    fn stage<const D: usize>(
        &mut self,
        sim: &mut Simulation<D>,
        config: &Config,
        target: f64,
    ) -> Result<(), SetupError> {
        let c = config.compress.as_ref().expect("a [compress] table");
        let every = c.thermostat_every.unwrap_or(sim.particles().len() as u64);
        let target = if c.to_jamming() { target.min(box_limit(sim)) } else { target };
        sim.grow_to(target, c.rate, config.init.kt, every)?;
        self.stages += 1;
        Ok(())
    }

    /// Fed every event of the compression: the pressure window, and the limit.
    pub fn observe<const D: usize>(&mut self, sim: &mut Simulation<D>, config: &Config, outcome: &Outcome<D>) {
        let (Outcome::Pair { impulse, .. }, Some(window)) = (outcome, self.window.as_mut()) else { return };
        window.1 += 1;
        window.2 += impulse.virial();
        let n = sim.particles().len();
        if window.1 < n as u64 {
            return;
        }
        let dt = sim.time() - window.0;
        let z = 1.0 + window.2 / (D as f64 * n as f64 * config.init.kt * dt);
        self.reduced_pressure = Some(z);
        *window = (sim.time(), 0, 0.0);
        let c = config.compress.as_ref().expect("a [compress] table");
        if c.to_jamming() && sim.growth().is_some() && !(z < c.pressure_limit()) {
            sim.end_growth();
        }
    }

    /// After every event of the compression: whether it is over (a growth that reached a
    /// stage's end starts the next stage when compressing to jamming).
    pub fn over<const D: usize>(&mut self, sim: &mut Simulation<D>, config: &Config) -> bool {
        if self.done {
            return true;
        }
        if sim.growth().is_some() {
            return false;
        }
        let c = config.compress.as_ref().expect("a [compress] table");
        let ending = sim.growth_ending();
        let jammed = match ending {
            Some(Ending::Stalled) => true,
            Some(Ending::Stopped) => c.to_jamming(),
            _ => false,
        };
        if c.to_jamming() && !jammed {
            // A stage reached its end unjammed: the next, if the box holds it.
            let next = (sim.packing_fraction() + 0.02).min(box_limit(sim));
            if next > sim.packing_fraction() * (1.0 + 1e-9) && self.stage(sim, config, next).is_ok() {
                return false;
            }
        }
        self.finish(sim, config, ending, jammed);
        true
    }

    /// Records what the compression reached.
    fn finish<const D: usize>(&mut self, sim: &Simulation<D>, config: &Config, ending: Option<Ending>, jammed: bool) {
        self.done = true;
        self.window = None;
        self.ending = ending;
        self.jammed = jammed;
        self.packing_fraction = sim.packing_fraction();
        self.collisions = sim.counts().pair - self.started_at.1;
        self.sim_time = sim.time() - self.started_at.0;
        self.max_overlap = sim.check_overlaps().fraction;
        let c = config.compress.as_ref().expect("a [compress] table");
        if jammed && c.to_jamming() {
            let tolerance = c.contact_tolerance(D);
            let network = contacts(sim, tolerance);
            self.contacts_per_particle = Some(network.contacts_per_particle);
            self.rattlers = Some(network.rattlers.len());
            self.contact_tolerance = Some(tolerance);
        }
    }

    /// The clock and the pair collisions at its end (where the equilibration starts).
    pub fn end_mark(&self) -> (f64, u64) {
        (self.started_at.0 + self.sim_time, self.started_at.1 + self.collisions)
    }

    /// The fraction of the compression done: of the packing fraction's way to its target,
    /// or (to jamming) of `log Z`'s way to the limit's.
    pub fn progress<const D: usize>(&self, sim: &Simulation<D>, config: &Config) -> f64 {
        if self.done {
            return 1.0;
        }
        let c = config.compress.as_ref().expect("a [compress] table");
        match c.target_packing_fraction {
            Some(target) => {
                let start = config.initial_packing_fraction(D);
                ((sim.packing_fraction() - start) / (target - start)).clamp(0.0, 1.0)
            }
            None => self.reduced_pressure.map_or(0.0, |z| (z.max(1.0).ln() / c.pressure_limit().ln()).clamp(0.0, 1.0)),
        }
    }
}

/// The largest packing fraction the box holds the particles at: every diameter below half a
/// periodic edge and below an edge between walls (less a part in 10⁹).
fn box_limit<const D: usize>(sim: &Simulation<D>) -> f64 {
    let b = sim.sim_box();
    let room = (0..D)
        .map(|a| if b.boundary[a] == crate::engine::Boundary::Periodic { 0.5 * b.lengths[a] } else { b.lengths[a] })
        .fold(f64::INFINITY, f64::min);
    let widest = (0..sim.particles().len()).map(|i| 2.0 * sim.radius(i)).fold(0.0, f64::max);
    sim.packing_fraction() * (room / widest).powi(D as i32) * (1.0 - 1e-9)
}
