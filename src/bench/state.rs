//! A benchmark's initial state, the engine's and the floor's alike: N particles of diameter 1
//! at packing fraction η in a periodic box, Maxwell velocities at kT = 1 — disks on a
//! triangular lattice, spheres on a simple cubic one (mechanically unstable: it melts within
//! a few collisions per particle, so a fluid is timed) up to η = 0.5, and on fcc above.

use crate::engine::init::{InitError, Placement, Species, Velocities, box_for_packing_fraction, initial_particles};
use crate::engine::{Boundary, Particle, SetupError, SimBox};
use crate::run::LimitError;
use std::fmt;

/// Why a benchmark point cannot be measured.
#[non_exhaustive]
#[derive(Clone, Debug, PartialEq)]
pub enum BenchError {
    /// A command-line option out of range: `--{flag} {value}: {allowed}`.
    Option {
        /// The option.
        flag: &'static str,
        /// Its value.
        value: String,
        /// What is allowed.
        allowed: &'static str,
    },
    /// More than this machine can hold.
    Limit(LimitError),
    /// The lattice could not be built.
    Init(InitError),
    /// The state is not valid.
    Setup(SetupError),
    /// Nothing could happen any more.
    Stopped,
}

impl fmt::Display for BenchError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            BenchError::Option { flag, value, allowed } => write!(f, "--{flag} {value}: {allowed}"),
            BenchError::Limit(e) => write!(f, "{e}"),
            BenchError::Init(e) => write!(f, "{e}"),
            BenchError::Setup(e) => write!(f, "{e}"),
            BenchError::Stopped => write!(f, "the gas stopped"),
        }
    }
}

impl std::error::Error for BenchError {}

/// The initial state of a point in `D` dimensions (see the module documentation).
pub fn initial_state<const D: usize>(
    n: usize,
    eta: f64,
    seed: u64,
) -> Result<(Vec<Particle<D>>, SimBox<D>), BenchError> {
    let (close, allowed) = match D {
        2 => (0.9069, "the packing fraction must lie in (0, 0.9069) (close packing is π/(2√3))"),
        _ => (0.7405, "the packing fraction must lie in (0, 0.7405) (close packing is π/√18)"),
    };
    if !(eta > 0.0 && eta < close) {
        return Err(BenchError::Option { flag: "eta", value: eta.to_string(), allowed });
    }
    if n < 2 {
        return Err(BenchError::Option {
            flag: "n",
            value: n.to_string(),
            allowed: "a benchmark needs at least 2 particles",
        });
    }
    crate::run::Limits::for_this_machine().check_memory("--n", n, 0.0).map_err(BenchError::Limit)?;
    let species = vec![Species { count: n, radius: 0.5, mass: 1.0 }];
    let placement = match D {
        2 => Placement::Triangular,
        _ if eta <= 0.5 => Placement::SimpleCubic,
        _ => Placement::Fcc,
    };
    let sim_box = box_for_packing_fraction(&species, eta, [Boundary::Periodic; D], placement, None);
    let particles =
        initial_particles(&species, &sim_box, placement, Velocities::Maxwell, 1.0, seed).map_err(BenchError::Init)?;
    Ok((particles, sim_box))
}
