//! The run configuration (TOML): parsing, defaults, validation.
//!
//! Unknown keys are errors (they are usually typos). Every validation error names the file,
//! the field and the value, and says what is allowed.

use crate::engine::Boundary;
use crate::engine::init::{Placement, Species, Velocities};
use serde::{Deserialize, Serialize};
use std::fmt;
use std::path::Path;

/// The embedded default configuration, run by `collide run` without a file.
pub const DEFAULT_CONFIG: &str = r#"# collide's embedded default: 1000 hard disks at packing fraction 0.5 in a periodic box.
seed = 1

[box]
packing_fraction = 0.5
boundary = "periodic"

[[species]]
count = 1000
radius = 0.5
mass = 1.0

[init]
placement = "triangular"
velocities = "maxwell"
kT = 1.0

[equilibration]
collisions = 200000

[run]
collisions = 1000000
sample_interval = 1.0
blocks = 20
"#;

/// A full run configuration.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Config {
    /// Seed of the portable random generator (Xoshiro256++) for the initial state.
    pub seed: u64,
    /// The box.
    #[serde(rename = "box")]
    pub sim_box: BoxConfig,
    /// The kinds of disk.
    pub species: Vec<Species>,
    /// The initial state.
    #[serde(default)]
    pub init: InitConfig,
    /// Equilibration before measuring.
    #[serde(default)]
    pub equilibration: Length,
    /// The measured (production) run.
    pub run: RunConfig,
    /// Optional outputs.
    #[serde(default)]
    pub output: OutputConfig,
}

/// Boundaries: one for all axes, or one per axis.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum Boundaries {
    /// The same on every axis.
    All(Boundary),
    /// One per axis.
    PerAxis(Vec<Boundary>),
}

/// The box: either its size or the packing fraction (N comes from the species).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BoxConfig {
    /// Edge lengths `[Lx, Ly]`.
    pub size: Option<Vec<f64>>,
    /// Packing fraction η = Σπ Rᵢ² / A.
    pub packing_fraction: Option<f64>,
    /// Ly/Lx when the size comes from the packing fraction (default 1; a periodic triangular
    /// lattice uses its own aspect ratio instead).
    pub aspect: Option<f64>,
    /// "periodic", "wall", or one per axis.
    pub boundary: Boundaries,
}

/// The initial state (each field optional: triangular, maxwell, kT = 1).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct InitConfig {
    /// "random", "triangular" or "square".
    pub placement: Placement,
    /// "maxwell" or "fixed-speed".
    pub velocities: Velocities,
    /// Temperature kT (energy unit).
    #[serde(rename = "kT")]
    pub kt: f64,
}

impl Default for InitConfig {
    fn default() -> Self {
        InitConfig { placement: Placement::Triangular, velocities: Velocities::Maxwell, kt: 1.0 }
    }
}

/// A run length: pair collisions, time, or both (whichever comes first).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Length {
    /// Pair collisions.
    pub collisions: Option<u64>,
    /// Simulated time.
    pub time: Option<f64>,
}

/// The production run.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RunConfig {
    /// Pair collisions to run.
    pub collisions: Option<u64>,
    /// Simulated time to run.
    pub time: Option<f64>,
    /// Time between samples (rows of timeseries.csv).
    #[serde(default = "default_sample_interval")]
    pub sample_interval: f64,
    /// Blocks for the error bars.
    #[serde(default = "default_blocks")]
    pub blocks: usize,
}

fn default_sample_interval() -> f64 {
    1.0
}

fn default_blocks() -> usize {
    20
}

/// Optional outputs.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OutputConfig {
    /// Write a trajectory frame every this many samples (0 or absent: none).
    pub trajectory_every: Option<u64>,
    /// Write a checkpoint every this many production pair collisions (0 or absent: none).
    pub checkpoint_every: Option<u64>,
}

/// A configuration that could not be used.
#[derive(Clone, Debug, PartialEq)]
pub struct ConfigError {
    /// Where it came from (a path, or "the embedded default").
    pub source: String,
    /// What is wrong.
    pub message: String,
}

impl fmt::Display for ConfigError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: {}", self.source, self.message)
    }
}

impl std::error::Error for ConfigError {}

impl Config {
    /// Parses and validates TOML text; `source` names it in errors.
    pub fn parse(text: &str, source: &str) -> Result<Config, ConfigError> {
        let err = |message: String| ConfigError { source: source.to_string(), message };
        let config: Config = toml::from_str(text).map_err(|e| err(e.to_string().trim_end().replace('\n', " ")))?;
        config.validate().map_err(err)?;
        Ok(config)
    }

    /// Reads, parses and validates a file.
    pub fn load(path: &Path) -> Result<Config, ConfigError> {
        let source = path.display().to_string();
        let text = std::fs::read_to_string(path)
            .map_err(|e| ConfigError { source: source.clone(), message: format!("cannot read the file: {e}") })?;
        Config::parse(&text, &source)
    }

    /// The embedded default.
    pub fn default_config() -> Config {
        Config::parse(DEFAULT_CONFIG, "the embedded default").expect("the embedded default is valid")
    }

    /// Boundaries per axis (2D).
    pub fn boundaries(&self) -> [Boundary; 2] {
        match &self.sim_box.boundary {
            Boundaries::All(b) => [*b; 2],
            Boundaries::PerAxis(v) => [v[0], v[1]],
        }
    }

    /// Total number of particles.
    pub fn n_particles(&self) -> usize {
        self.species.iter().map(|s| s.count).sum()
    }

    fn validate(&self) -> Result<(), String> {
        let positive = |name: &str, x: f64| {
            if x.is_finite() && x > 0.0 {
                Ok(())
            } else {
                Err(format!("{name} = {x}: must be a positive finite number"))
            }
        };
        if let Boundaries::PerAxis(v) = &self.sim_box.boundary
            && v.len() != 2
        {
            return Err(format!("box.boundary has {} entries: give one per axis (2) or a single string", v.len()));
        }
        match (&self.sim_box.size, self.sim_box.packing_fraction) {
            (Some(_), Some(_)) => return Err("box: give either size or packing_fraction, not both".into()),
            (None, None) => return Err("box: give size = [Lx, Ly] or packing_fraction".into()),
            (Some(size), None) => {
                if size.len() != 2 {
                    return Err(format!("box.size has {} entries: give [Lx, Ly]", size.len()));
                }
                for (i, &l) in size.iter().enumerate() {
                    positive(&format!("box.size[{i}]"), l)?;
                }
            }
            (None, Some(eta)) => {
                // Close packing of equal disks: π/(2√3) ≈ 0.9069.
                if !(eta.is_finite() && eta > 0.0 && eta < 0.9069) {
                    return Err(format!(
                        "box.packing_fraction = {eta}: must lie in (0, 0.9069) (close packing is π/(2√3))"
                    ));
                }
            }
        }
        if let Some(aspect) = self.sim_box.aspect {
            positive("box.aspect", aspect)?;
        }
        if self.species.is_empty() {
            return Err("species: give at least one [[species]] with count, radius and mass".into());
        }
        for (k, s) in self.species.iter().enumerate() {
            if s.count == 0 {
                return Err(format!("species[{k}].count = 0: must be at least 1"));
            }
            positive(&format!("species[{k}].radius"), s.radius)?;
            positive(&format!("species[{k}].mass"), s.mass)?;
        }
        positive("init.kT", self.init.kt)?;
        if self.run.collisions.is_none() && self.run.time.is_none() {
            return Err("run: give collisions and/or time (the run stops at whichever comes first)".into());
        }
        if self.run.collisions == Some(0) {
            return Err("run.collisions = 0: must be at least 1".into());
        }
        if let Some(t) = self.run.time {
            positive("run.time", t)?;
        }
        if let Some(t) = self.equilibration.time
            && !(t.is_finite() && t >= 0.0)
        {
            return Err(format!("equilibration.time = {t}: must be a finite number ≥ 0"));
        }
        positive("run.sample_interval", self.run.sample_interval)?;
        if let Some(t) = self.run.time
            && t / self.run.sample_interval > 1e8
        {
            return Err(format!(
                "run.sample_interval = {}: with run.time = {t} that is more than 10⁸ samples; use a larger interval",
                self.run.sample_interval
            ));
        }
        if self.run.blocks < 2 {
            return Err(format!("run.blocks = {}: must be at least 2 (error bars need two blocks)", self.run.blocks));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn default_parses() {
        let c = Config::default_config();
        assert_eq!(c.n_particles(), 1000);
        assert_eq!(c.boundaries(), [Boundary::Periodic; 2]);
    }

    fn error_of(edit: &str, with: &str) -> String {
        let text = DEFAULT_CONFIG.replace(edit, with);
        assert_ne!(text, DEFAULT_CONFIG, "edit '{edit}' did not apply");
        Config::parse(&text, "test.toml").unwrap_err().to_string()
    }

    #[test]
    fn bad_values_are_named() {
        assert_eq!(
            error_of("radius = 0.5", "radius = -1.0"),
            "test.toml: species[0].radius = -1: must be a positive finite number"
        );
        assert_eq!(
            error_of("mass = 1.0", "mass = 0.0"),
            "test.toml: species[0].mass = 0: must be a positive finite number"
        );
        assert_eq!(
            error_of("mass = 1.0", "mass = nan"),
            "test.toml: species[0].mass = NaN: must be a positive finite number"
        );
        assert!(error_of("packing_fraction = 0.5", "packing_fraction = 0.95").contains("box.packing_fraction = 0.95"));
        let unknown = error_of("seed = 1", "seed = 1\ncolour = \"red\"");
        assert!(unknown.starts_with("test.toml: ") && unknown.contains("colour"), "{unknown}");
        let typo = error_of("placement = \"triangular\"", "placement = \"hexagonal\"");
        assert!(typo.contains("hexagonal"), "{typo}");
        assert!(Config::parse("this is not toml", "x.toml").unwrap_err().to_string().starts_with("x.toml: "));
        let flood = error_of("sample_interval = 1.0", "sample_interval = 1e-12\ntime = 10.0");
        assert!(flood.contains("more than 10⁸ samples"), "{flood}");
    }
}
