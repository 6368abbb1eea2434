//! Checkpoints: everything needed to continue a run bit-identically, sealed by a digest.
//!
//! # Format (`checkpoint.json`)
//!
//! ```text
//! { "collide_version": "0.1.0",
//!   "digest": "sha256:<64 hex digits>",
//!   "run": { "config": …, "phase": "production", "state": …, "thermo": …,
//!            ["observables": […],] "equilibration": …, "start_counts": …,
//!            "wall_time_s": …, "trajectory_bytes": … } }
//! ```
//!
//! The digest is the SHA-256 of the version, a NUL byte, and the compact JSON of `run` as
//! collide writes it. Reading a checkpoint writes `run` again from what was read and
//! compares digests: any change to the file — an edited packing fraction, a moved
//! particle, a truncated sample list — is refused with the reason, before anything else is
//! looked at. (Numbers are written as the shortest decimal that reads back to the same
//! f64, so the text written again is the text that was read.)
//!
//! A checkpoint that passes is then validated exactly like a fresh start, and its state
//! against its own configuration ([`Run::resume`](super::Run::resume)).

use super::config::Config;
use super::{Equilibration, Phase, RunError};
use crate::engine::{EventCounts, SetupError, SimulationState};
use crate::observe::{Observable, Thermo};
use crate::text::shorten;
use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};
use std::fmt;
use std::path::Path;

/// A run's complete state, as saved.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Saved<const D: usize> {
    /// The configuration.
    pub config: Config,
    /// The phase the run is in.
    pub phase: Phase,
    /// The simulation.
    pub state: SimulationState<D>,
    /// The thermodynamics (of production; empty during equilibration).
    pub thermo: Thermo,
    /// The observables the configuration names (of production), in registry order.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub observables: Vec<Observable>,
    /// The equilibration that preceded production (zero until it is over).
    pub equilibration: Equilibration,
    /// The compression, with `[compress]` (absent without).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub compression: Option<super::Compression>,
    /// Event counts when production started.
    pub start_counts: EventCounts,
    /// Wall-clock seconds of production so far, over every process that ran it.
    pub wall_time_s: f64,
    /// The length of `trajectory.xyz` at this point, bytes (the frames written so far).
    pub trajectory_bytes: u64,
}

/// A checkpoint: the state, the version that wrote it, and their digest.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Checkpoint<const D: usize> {
    /// The version that wrote it.
    pub collide_version: String,
    /// `"sha256:"` and the digest of the version and `run` (see the module docs).
    pub digest: String,
    /// The state.
    pub run: Saved<D>,
}

/// Why a checkpoint cannot be used.
#[non_exhaustive]
#[derive(Clone, Debug, PartialEq)]
pub enum CheckpointError {
    /// The file could not be read.
    Read(String),
    /// Not a checkpoint (not JSON, or not this layout).
    Format(String),
    /// Written by another version: a resumed run would not be bit-identical.
    Version {
        /// The version that wrote it.
        found: String,
    },
    /// The content does not match the digest.
    Digest,
    /// The configuration it carries is invalid, or the run it describes out of reach.
    Config(Box<RunError>),
    /// The state does not agree with the configuration, or is not a state a run reaches.
    State(StateError),
    /// The saved simulation cannot be restored (overlaps, events that are not what its
    /// state predicts, particles outside their cells).
    Setup(SetupError),
}

/// A part of a saved run that does not agree with its configuration or with the rest.
#[derive(Clone, Debug, PartialEq)]
pub struct StateError {
    /// Where in the checkpoint (`run.state.particles`).
    pub field: &'static str,
    /// What it holds.
    pub found: String,
    /// What it must hold.
    pub expected: String,
}

impl fmt::Display for StateError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}, {}", self.found, self.expected)
    }
}

impl fmt::Display for CheckpointError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            CheckpointError::Read(e) => write!(f, "cannot read the checkpoint: {e}"),
            CheckpointError::Format(e) => write!(f, "not a collide checkpoint: {e}"),
            CheckpointError::Version { found } => write!(
                f,
                "written by collide {}, this is {}: a resumed run would not be bit-identical",
                shorten(found),
                env!("CARGO_PKG_VERSION")
            ),
            CheckpointError::Digest => write!(
                f,
                "its content does not match its digest: the file was edited or damaged after collide wrote it, and a run continued from it would not be the run it claims to be"
            ),
            CheckpointError::Config(e) => write!(f, "the configuration it carries: {e}"),
            CheckpointError::State(e) => write!(f, "its state does not fit its configuration: {e}"),
            CheckpointError::Setup(e) => write!(f, "its state does not fit its configuration: {e}"),
        }
    }
}

impl std::error::Error for CheckpointError {}

/// A writer that feeds a hash: the digest of a state is taken as it is written out, without
/// holding its text.
struct Hashing(Sha256);

impl std::io::Write for Hashing {
    fn write(&mut self, bytes: &[u8]) -> std::io::Result<usize> {
        self.0.update(bytes);
        Ok(bytes.len())
    }
    fn flush(&mut self) -> std::io::Result<()> {
        Ok(())
    }
}

/// The digest of a version and a saved state.
fn digest<const D: usize>(version: &str, run: &Saved<D>) -> String {
    let mut hash = Hashing(Sha256::new());
    hash.0.update(version.as_bytes());
    hash.0.update([0u8]);
    serde_json::to_writer(&mut hash, run).expect("a saved state serialises");
    labelled(&hash.0.finalize())
}

/// `"sha256:"` and the SHA-256 of `bytes` in hex: how collide writes a digest (a sweep task's
/// configuration has one too).
pub fn sha256(bytes: &[u8]) -> String {
    labelled(&Sha256::digest(bytes))
}

fn labelled(digest: &[u8]) -> String {
    let mut hex = String::with_capacity(7 + 64);
    hex.push_str("sha256:");
    for b in digest {
        hex.push_str(&format!("{b:02x}"));
    }
    hex
}

/// The dimension of the run a checkpoint's text holds (`run.config.dimension`, 2 when
/// absent), read without building its state: the caller then reads it as a
/// [`Checkpoint<D>`] of that dimension. Text that is not a checkpoint says 2, and reading it
/// then says what is wrong with it.
pub fn dimension_of(bytes: &[u8]) -> usize {
    #[derive(Deserialize)]
    struct Outer {
        run: Inner,
    }
    #[derive(Deserialize)]
    struct Inner {
        config: Dimension,
    }
    #[derive(Deserialize)]
    struct Dimension {
        #[serde(default = "two")]
        dimension: usize,
    }
    fn two() -> usize {
        2
    }
    serde_json::from_slice::<Outer>(bytes).map_or(2, |outer| outer.run.config.dimension)
}

impl<const D: usize> Checkpoint<D> {
    /// Seals a saved state with this version and its digest.
    pub fn seal(run: Saved<D>) -> Checkpoint<D> {
        let collide_version = env!("CARGO_PKG_VERSION").to_string();
        Checkpoint { digest: digest(&collide_version, &run), collide_version, run }
    }

    /// Checks the version and the digest.
    pub fn verify(&self) -> Result<(), CheckpointError> {
        if self.collide_version != env!("CARGO_PKG_VERSION") {
            return Err(CheckpointError::Version { found: self.collide_version.clone() });
        }
        if digest(&self.collide_version, &self.run) != self.digest {
            return Err(CheckpointError::Digest);
        }
        Ok(())
    }

    /// The checkpoint as the text of `checkpoint.json`.
    pub fn to_json(&self) -> String {
        serde_json::to_string(self).expect("a checkpoint serialises")
    }

    /// Writes the text of `checkpoint.json` to `out`.
    pub fn write_json(&self, out: &mut dyn std::io::Write) -> std::io::Result<()> {
        serde_json::to_writer(out, self).map_err(std::io::Error::other)
    }

    /// Reads and verifies a checkpoint file.
    pub fn load(path: &Path) -> Result<Checkpoint<D>, CheckpointError> {
        let bytes = std::fs::read(path).map_err(|e| CheckpointError::Read(e.to_string()))?;
        Checkpoint::from_json(&bytes)
    }

    /// Parses and verifies the text of a checkpoint.
    pub fn from_json(bytes: &[u8]) -> Result<Checkpoint<D>, CheckpointError> {
        let checkpoint: Checkpoint<D> =
            serde_json::from_slice(bytes).map_err(|e| CheckpointError::Format(shorten(&e.to_string())))?;
        checkpoint.verify()?;
        Ok(checkpoint)
    }
}
