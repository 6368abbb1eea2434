//! The run configuration (TOML): parsing, defaults, validation.
//!
//! Unknown keys are errors (they are usually typos), in every table. Every error is a
//! [`ConfigError`] naming the file and the field (or the line and column of a syntax error),
//! the value — cut short when it is long ([`crate::text`]) — and what is allowed. The keys,
//! their defaults and their ranges are specified in `docs/configuration.md`.
//!
//! A configuration is validated for a dimension ([`Config::check_for`]): the box's entries
//! and the close-packing limit depend on it.

use crate::engine::Boundary;
use crate::engine::init::{Placement, Species, Velocities};
use crate::observe::Selection;
use crate::text::{line_column, num, shorten};
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
    /// 2 (disks) or 3 (spheres); 2 when absent (and then not written back, so that a 2D
    /// configuration echoes as it was read).
    #[serde(default = "two", skip_serializing_if = "is_two")]
    pub dimension: usize,
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
    /// Compression from the initial state before equilibration (`[compress]`; absent: none).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub compress: Option<CompressConfig>,
    /// Equilibration before measuring.
    #[serde(default)]
    pub equilibration: Length,
    /// The measured (production) run (absent only with `compress.until = "jammed"`, where
    /// the run ends at the jammed packing).
    #[serde(default)]
    pub run: RunConfig,
    /// Optional outputs.
    #[serde(default)]
    pub output: OutputConfig,
    /// Observables measured besides the thermodynamics (`[observe.<name>]`).
    #[serde(default, skip_serializing_if = "Selection::is_empty")]
    pub observe: Selection,
}

fn two() -> usize {
    2
}

fn is_two(d: &usize) -> bool {
    *d == 2
}

/// The shape of a box made from a packing fraction.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum Aspect {
    /// `Ly/Lx`, every other edge equal to `Lx`.
    Ratio(f64),
    /// The edges' proportions `[Lx, Ly(, Lz)]`, one per axis (any scale).
    Edges(Vec<f64>),
}

impl Aspect {
    /// The edges' proportions in `D` dimensions, `Lx`'s entry first (checked for `D`).
    pub fn edges<const D: usize>(&self) -> [f64; D] {
        match self {
            Aspect::Ratio(r) => std::array::from_fn(|a| if a == 1 { *r } else { 1.0 }),
            Aspect::Edges(e) => std::array::from_fn(|a| e[a]),
        }
    }
}

impl fmt::Display for Aspect {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Aspect::Ratio(r) => write!(f, "{}", num(*r)),
            Aspect::Edges(e) => write!(f, "[{}]", e.iter().map(|&x| num(x)).collect::<Vec<_>>().join(", ")),
        }
    }
}

/// Boundaries: one for all axes, or one per axis.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(untagged)]
pub enum Boundaries {
    /// The same on every axis.
    All(Boundary),
    /// One per axis.
    PerAxis(Vec<Boundary>),
}

impl<'de> Deserialize<'de> for Boundaries {
    fn deserialize<D: serde::Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        use serde::de::{self, SeqAccess, Visitor};
        const ALLOWED: &str = r#""periodic" or "wall", or one per axis such as ["periodic", "wall"]"#;
        fn named<E: de::Error>(name: &str) -> Result<Boundary, E> {
            match name {
                "periodic" => Ok(Boundary::Periodic),
                "wall" => Ok(Boundary::Wall),
                other => Err(E::custom(format!(
                    "box.boundary: \"{}\" is not a boundary; expected {ALLOWED}",
                    crate::text::excerpt(other)
                ))),
            }
        }
        struct Either;
        impl<'de> Visitor<'de> for Either {
            type Value = Boundaries;
            fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                f.write_str(ALLOWED)
            }
            fn visit_str<E: de::Error>(self, v: &str) -> Result<Boundaries, E> {
                named(v).map(Boundaries::All)
            }
            fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Boundaries, A::Error> {
                let mut axes = Vec::new();
                while let Some(name) = seq.next_element::<String>()? {
                    axes.push(named(&name)?);
                }
                Ok(Boundaries::PerAxis(axes))
            }
        }
        deserializer.deserialize_any(Either)
    }
}

/// The box: either its size or the packing fraction (N comes from the species).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BoxConfig {
    /// Edge lengths `[Lx, Ly]` or `[Lx, Ly, Lz]`.
    pub size: Option<Vec<f64>>,
    /// Packing fraction η = Σ V(Rᵢ) / V_box (V(R) = πR² for disks, 4πR³/3 for spheres).
    pub packing_fraction: Option<f64>,
    /// The box's shape when its size comes from the packing fraction: `Ly/Lx`, or the
    /// proportions of the edges, one per axis (default a square or cube; a periodic
    /// triangular lattice uses its own aspect ratio instead).
    pub aspect: Option<Aspect>,
    /// "periodic", "wall", or one per axis.
    pub boundary: Boundaries,
}

/// The initial state (each field optional: the densest lattice of the dimension —
/// triangular or fcc —, maxwell, kT = 1).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct InitConfig {
    /// "random"; "triangular" or "square" in 2D; "fcc" or "simple_cubic" in 3D. Absent: the
    /// densest lattice ([`Config::placement`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub placement: Option<Placement>,
    /// "maxwell" or "fixed-speed".
    pub velocities: Velocities,
    /// Temperature kT (energy unit).
    #[serde(rename = "kT")]
    pub kt: f64,
}

impl Default for InitConfig {
    fn default() -> Self {
        InitConfig { placement: None, velocities: Velocities::Maxwell, kt: 1.0 }
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

/// `[compress]`: a Lubachevsky–Stillinger compression from the initial state — every radius
/// grows in proportion, `dRᵢ/dt = rate·Rᵢ(0)`, the velocities rescaled to `init.kT` every
/// `thermostat_every` pair collisions — to a packing fraction (the run then equilibrates and
/// measures there) or until the packing jams (the run ends there).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CompressConfig {
    /// Relative growth rate per unit time (> 0).
    pub rate: f64,
    /// The packing fraction to compress to.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub target_packing_fraction: Option<f64>,
    /// `"jammed"`: compress until the packing jams.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub until: Option<Until>,
    /// With `until = "jammed"`: the reduced pressure `Z = PV/(NkT)` at which the packing
    /// counts as jammed (default [`PRESSURE_LIMIT`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pressure_limit: Option<f64>,
    /// Pair collisions between rescalings of the velocities (default: the number of
    /// particles).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub thermostat_every: Option<u64>,
    /// With `until = "jammed"`: the gap, as a fraction of the contact distance, within which
    /// two particles (or a particle and a wall) count as in contact (default: see
    /// [`CompressConfig::contact_tolerance`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub contact_tolerance: Option<f64>,
}

/// Where a compression stops, when not at a packing fraction.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Until {
    /// When the packing jams: its reduced pressure reaches `pressure_limit`, or its clock
    /// stalls.
    Jammed,
}

/// The default reduced-pressure limit of a compression to jamming: `Z = 10¹²`, where the
/// gaps of the contacts are some `d·φ/Z ≈ 10⁻¹²` diameters — a thousand times below the
/// default contact tolerance and still some thousand ulps of a diameter.
pub const PRESSURE_LIMIT: f64 = 1e12;

impl CompressConfig {
    /// Whether the compression runs until the packing jams.
    pub fn to_jamming(&self) -> bool {
        self.until == Some(Until::Jammed)
    }

    /// The reduced pressure at which the packing counts as jammed.
    pub fn pressure_limit(&self) -> f64 {
        self.pressure_limit.unwrap_or(PRESSURE_LIMIT)
    }

    /// The contact tolerance: the one given, or `1000·d/Z_limit` (at most 10⁻³) — a thousand
    /// times the free-volume gap of a contact at the pressure limit, `d·φ/Z` (`10⁻⁹` at the
    /// default limit, in 3D), and far below the gaps of particles not in contact.
    pub fn contact_tolerance(&self, d: usize) -> f64 {
        self.contact_tolerance.unwrap_or((1000.0 * d as f64 / self.pressure_limit()).min(1e-3))
    }
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

impl Default for RunConfig {
    fn default() -> Self {
        RunConfig { collisions: None, time: None, sample_interval: default_sample_interval(), blocks: default_blocks() }
    }
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
    /// Write a trajectory frame every this many samples (absent: no trajectory).
    pub trajectory_every: Option<u64>,
    /// Write a checkpoint every this many production pair collisions (absent: only the
    /// final one, which every run writes).
    pub checkpoint_every: Option<u64>,
}

/// A value a configuration may not hold: the field, what it holds, and what is allowed.
#[non_exhaustive]
#[derive(Clone, Debug, PartialEq)]
pub enum Invalid {
    /// A value outside what is allowed: `{field} = {value}: {allowed}`.
    Value {
        /// The field (`species[1].radius`).
        field: String,
        /// Its value, as written in messages.
        value: String,
        /// What is allowed.
        allowed: String,
    },
    /// A list with the wrong number of entries: `{field} has {entries} entries: {allowed}`.
    Entries {
        /// The field.
        field: String,
        /// How many it has.
        entries: usize,
        /// What is allowed.
        allowed: String,
    },
    /// A value given where another key decides: `{field} = {value} is used only with
    /// {with}; {allowed}`.
    OnlyWith {
        /// The field.
        field: String,
        /// Its value.
        value: String,
        /// The key it goes with.
        with: String,
        /// What to do.
        allowed: String,
    },
    /// Keys that do not go together, or one that is missing: `{field}: {allowed}`.
    Fields {
        /// The table or field.
        field: String,
        /// What is allowed.
        allowed: String,
    },
}

impl Invalid {
    fn value(field: impl Into<String>, value: impl Into<String>, allowed: impl Into<String>) -> Invalid {
        Invalid::Value { field: field.into(), value: value.into(), allowed: allowed.into() }
    }

    fn fields(field: impl Into<String>, allowed: impl Into<String>) -> Invalid {
        Invalid::Fields { field: field.into(), allowed: allowed.into() }
    }

    /// The field it names.
    pub fn field(&self) -> &str {
        match self {
            Invalid::Value { field, .. }
            | Invalid::Entries { field, .. }
            | Invalid::OnlyWith { field, .. }
            | Invalid::Fields { field, .. } => field,
        }
    }
}

impl fmt::Display for Invalid {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Invalid::Value { field, value, allowed } => write!(f, "{field} = {value}: {allowed}"),
            Invalid::Entries { field, entries, allowed } => write!(f, "{field} has {entries} entries: {allowed}"),
            Invalid::OnlyWith { field, value, with, allowed } => {
                write!(f, "{field} = {value} is used only with {with}; {allowed}")
            }
            Invalid::Fields { field, allowed } => write!(f, "{field}: {allowed}"),
        }
    }
}

impl std::error::Error for Invalid {}

/// A configuration that could not be used; every variant names where it came from (a path,
/// or "the embedded default").
#[non_exhaustive]
#[derive(Clone, Debug, PartialEq)]
pub enum ConfigError {
    /// The file could not be read.
    Read {
        /// The file.
        source: String,
        /// What the system said.
        reason: String,
    },
    /// A file too large to be a configuration.
    TooLarge {
        /// The file.
        source: String,
        /// Its size.
        bytes: u64,
    },
    /// Not UTF-8.
    NotUtf8 {
        /// The file.
        source: String,
        /// Where the first bad byte is (1-based).
        line: usize,
        /// Its column (1-based).
        column: usize,
    },
    /// Not TOML, or not this layout (an unknown key, a wrong type, an unknown name).
    Syntax {
        /// The file.
        source: String,
        /// Line and column, when known (1-based).
        at: Option<(usize, usize)>,
        /// What the parser said.
        message: String,
    },
    /// A value that is not allowed.
    Invalid {
        /// The file.
        source: String,
        /// What is wrong.
        invalid: Invalid,
    },
}

impl fmt::Display for ConfigError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let text = match self {
            ConfigError::Read { source, reason } => format!("{source}: cannot read the file: {reason}"),
            ConfigError::TooLarge { source, bytes } => format!(
                "{source}: the file holds {bytes} bytes, more than a configuration can ({MAX_FILE_BYTES}); is it the right file?"
            ),
            ConfigError::NotUtf8 { source, line, column } => {
                format!("{source}: line {line}, column {column}: not valid UTF-8 (TOML files are UTF-8 text)")
            }
            ConfigError::Syntax { source, at: Some((line, column)), message } => {
                format!("{source}: TOML parse error at line {line}, column {column}: {message}")
            }
            ConfigError::Syntax { source, at: None, message } => format!("{source}: TOML parse error: {message}"),
            ConfigError::Invalid { source, invalid } => format!("{source}: {invalid}"),
        };
        f.write_str(&shorten(&text))
    }
}

impl std::error::Error for ConfigError {}

/// The largest configuration file read (a configuration is a few hundred bytes).
pub const MAX_FILE_BYTES: u64 = 1 << 24;

/// Close packing in `d` dimensions: π/(2√3) for disks (the triangular lattice), π/√18 for
/// spheres (fcc and hcp; Hales 2005). A packing fraction must lie below it.
pub fn close_packing(d: usize) -> (f64, &'static str) {
    match d {
        2 => (0.9069, "π/(2√3)"),
        _ => (0.7405, "π/√18"),
    }
}

impl Config {
    /// Parses and validates TOML text (for the dimension it names, 2 by default); `source`
    /// names it in errors. A syntax error or an unknown key is reported with its line and
    /// column.
    pub fn parse(text: &str, source: &str) -> Result<Config, ConfigError> {
        let config: Config = toml::from_str(text).map_err(|e| ConfigError::Syntax {
            source: source.to_string(),
            at: e.span().map(|span| line_column(text, span.start)),
            message: e.message().to_string(),
        })?;
        config.check().map_err(|invalid| ConfigError::Invalid { source: source.to_string(), invalid })?;
        Ok(config)
    }

    /// Validates a configuration already parsed into a TOML table (a sweep's task: its
    /// `[base]` with the varied values set); `source` names it in errors. Type errors and
    /// unknown keys are reported without a position (the table has no text).
    pub fn from_table(table: toml::Table, source: &str) -> Result<Config, ConfigError> {
        let config: Config = toml::Value::Table(table).try_into().map_err(|e: toml::de::Error| {
            ConfigError::Syntax { source: source.to_string(), at: None, message: e.message().to_string() }
        })?;
        config.check().map_err(|invalid| ConfigError::Invalid { source: source.to_string(), invalid })?;
        Ok(config)
    }

    /// The configuration as TOML text that [`Config::parse`] reads back to the same value
    /// (every field written, defaults included; floats in their shortest round-trip form).
    pub fn to_toml(&self) -> String {
        toml::to_string(self).expect("a configuration serialises to TOML")
    }

    /// Reads, parses and validates a file.
    pub fn load(path: &Path) -> Result<Config, ConfigError> {
        let source = path.display().to_string();
        let unreadable = |e: std::io::Error| ConfigError::Read { source: source.clone(), reason: e.to_string() };
        let bytes = std::fs::metadata(path).map_err(unreadable)?.len();
        if bytes > MAX_FILE_BYTES {
            return Err(ConfigError::TooLarge { source, bytes });
        }
        let bytes = std::fs::read(path).map_err(unreadable)?;
        let text = String::from_utf8(bytes).map_err(|e| {
            let (line, column) = line_column(&String::from_utf8_lossy(e.as_bytes()), e.utf8_error().valid_up_to());
            ConfigError::NotUtf8 { source: source.clone(), line, column }
        })?;
        Config::parse(&text, &source)
    }

    /// The embedded default.
    pub fn default_config() -> Config {
        Config::parse(DEFAULT_CONFIG, "the embedded default").expect("the embedded default is valid")
    }

    /// Boundaries per axis (the configuration has been checked for `D`).
    pub fn boundaries<const D: usize>(&self) -> [Boundary; D] {
        match &self.sim_box.boundary {
            Boundaries::All(b) => [*b; D],
            Boundaries::PerAxis(v) => std::array::from_fn(|a| v[a]),
        }
    }

    /// Total number of particles (saturating: [`check`](Self::check) refuses more than
    /// `usize::MAX`).
    pub fn n_particles(&self) -> usize {
        self.species.iter().fold(0usize, |n, s| n.saturating_add(s.count))
    }

    /// The placement: the one given, or the densest lattice of the dimension (triangular in
    /// 2D, fcc in 3D).
    pub fn placement(&self) -> Placement {
        self.init.placement.unwrap_or(if self.dimension == 3 { Placement::Fcc } else { Placement::Triangular })
    }

    /// The packing fraction of the initial state: `box.packing_fraction`, or the species'
    /// volume over the box's.
    pub fn initial_packing_fraction(&self, d: usize) -> f64 {
        match (self.sim_box.packing_fraction, &self.sim_box.size) {
            (Some(eta), _) => eta,
            (None, Some(size)) => {
                let volume = match d {
                    3 => crate::engine::init::particle_volume::<3>(&self.species),
                    _ => crate::engine::init::particle_volume::<2>(&self.species),
                };
                volume / size.iter().product::<f64>()
            }
            (None, None) => f64::NAN,
        }
    }

    /// Validates `[compress]` (if any) for a run in `d` dimensions.
    fn check_compress(&self, d: usize) -> Result<(), Invalid> {
        let Some(c) = &self.compress else { return Ok(()) };
        if !(c.rate.is_finite() && c.rate > 0.0) {
            return Err(Invalid::value(
                "compress.rate",
                num(c.rate),
                "must be a positive finite number (relative growth per unit time)",
            ));
        }
        match (c.target_packing_fraction, c.until) {
            (Some(_), Some(_)) => {
                return Err(Invalid::fields(
                    "compress",
                    "give either target_packing_fraction or until = \"jammed\", not both",
                ));
            }
            (None, None) => {
                return Err(Invalid::fields("compress", "give target_packing_fraction = φ or until = \"jammed\""));
            }
            (Some(target), None) => {
                let (limit, formula) = close_packing(d);
                let start = self.initial_packing_fraction(d);
                if !(target.is_finite() && target > start && target < limit) {
                    return Err(Invalid::value(
                        "compress.target_packing_fraction",
                        num(target),
                        format!(
                            "must lie between the initial packing fraction {} and close packing {limit} ({formula})",
                            num(start)
                        ),
                    ));
                }
                for (field, given) in [
                    ("compress.pressure_limit", c.pressure_limit.map(num)),
                    ("compress.contact_tolerance", c.contact_tolerance.map(num)),
                ] {
                    if let Some(value) = given {
                        return Err(Invalid::OnlyWith {
                            field: field.into(),
                            value,
                            with: "compress.until = \"jammed\"".into(),
                            allowed: "a compression to a packing fraction stops there (remove it)".into(),
                        });
                    }
                }
            }
            (None, Some(Until::Jammed)) => {
                if let Some(p) = c.pressure_limit
                    && !(p.is_finite() && p > 10.0)
                {
                    return Err(Invalid::value(
                        "compress.pressure_limit",
                        num(p),
                        "must be a finite reduced pressure above 10",
                    ));
                }
                if let Some(t) = c.contact_tolerance
                    && !(t.is_finite() && t > 0.0 && t < 0.1)
                {
                    return Err(Invalid::value(
                        "compress.contact_tolerance",
                        num(t),
                        "must lie in (0, 0.1) (a fraction of the contact distance)",
                    ));
                }
            }
        }
        if c.thermostat_every == Some(0) {
            return Err(Invalid::value(
                "compress.thermostat_every",
                "0",
                "must be at least 1 collision (leave it out for N)",
            ));
        }
        Ok(())
    }

    /// Validates every value for the dimension the configuration names, as
    /// [`parse`](Self::parse) does.
    pub fn check(&self) -> Result<(), Invalid> {
        if !matches!(self.dimension, 2 | 3) {
            return Err(Invalid::value("dimension", self.dimension.to_string(), "must be 2 (disks) or 3 (spheres)"));
        }
        self.check_for(self.dimension)
    }

    /// Validates every value for a run in `d` dimensions: a configuration built or edited in
    /// memory, or carried by a checkpoint, is checked exactly like a file. A configuration of
    /// another dimension than `d` is refused.
    pub fn check_for(&self, d: usize) -> Result<(), Invalid> {
        if self.dimension != d {
            return Err(Invalid::value(
                "dimension",
                self.dimension.to_string(),
                format!("this is a {d}D run: give dimension = {d}"),
            ));
        }
        let periodic = match &self.sim_box.boundary {
            Boundaries::All(b) => *b == Boundary::Periodic,
            Boundaries::PerAxis(v) => v.iter().all(|b| *b == Boundary::Periodic),
        };
        self.observe.check(periodic).map_err(|(field, value, allowed)| Invalid::value(field, value, allowed))?;
        let positive = |name: &str, x: f64| {
            if x.is_finite() && x > 0.0 {
                Ok(())
            } else {
                Err(Invalid::value(name, num(x), "must be a positive finite number"))
            }
        };
        let lengths = ["Lx", "Ly", "Lz"][..d.min(3)].join(", ");
        if let Boundaries::PerAxis(v) = &self.sim_box.boundary
            && v.len() != d
        {
            return Err(Invalid::Entries {
                field: "box.boundary".into(),
                entries: v.len(),
                allowed: format!("give one per axis ({d}) or a single string"),
            });
        }
        match (&self.sim_box.size, self.sim_box.packing_fraction) {
            (Some(_), Some(_)) => return Err(Invalid::fields("box", "give either size or packing_fraction, not both")),
            (None, None) => return Err(Invalid::fields("box", format!("give size = [{lengths}] or packing_fraction"))),
            (Some(size), None) => {
                if size.len() != d {
                    return Err(Invalid::Entries {
                        field: "box.size".into(),
                        entries: size.len(),
                        allowed: format!("give [{lengths}]"),
                    });
                }
                for (i, &l) in size.iter().enumerate() {
                    positive(&format!("box.size[{i}]"), l)?;
                }
            }
            (None, Some(eta)) => {
                let (limit, formula) = close_packing(d);
                if !(eta.is_finite() && eta > 0.0 && eta < limit) {
                    return Err(Invalid::value(
                        "box.packing_fraction",
                        num(eta),
                        format!("must lie in (0, {limit}) (close packing is {formula})"),
                    ));
                }
            }
        }
        if let Some(aspect) = &self.sim_box.aspect {
            match aspect {
                Aspect::Ratio(r) => positive("box.aspect", *r)?,
                Aspect::Edges(e) => {
                    if e.len() != d {
                        return Err(Invalid::Entries {
                            field: "box.aspect".into(),
                            entries: e.len(),
                            allowed: format!("give the proportions [{lengths}] or the single number Ly/Lx"),
                        });
                    }
                    for (i, &x) in e.iter().enumerate() {
                        positive(&format!("box.aspect[{i}]"), x)?;
                    }
                }
            }
            if self.sim_box.size.is_some() {
                return Err(Invalid::OnlyWith {
                    field: "box.aspect".into(),
                    value: aspect.to_string(),
                    with: "packing_fraction".into(),
                    allowed: format!("with size = [{lengths}] the size gives the shape (remove one of them)"),
                });
            }
        }
        if let Some(placement) = self.init.placement
            && !placement.exists_in(d)
        {
            return Err(Invalid::value(
                "init.placement",
                format!("\"{}\"", placement.name()),
                format!("in {d}D use {}", Placement::allowed_in(d)),
            ));
        }
        if self.species.is_empty() {
            return Err(Invalid::fields("species", "give at least one [[species]] with count, radius and mass"));
        }
        for (k, s) in self.species.iter().enumerate() {
            if s.count == 0 {
                return Err(Invalid::value(format!("species[{k}].count"), "0", "must be at least 1"));
            }
            positive(&format!("species[{k}].radius"), s.radius)?;
            positive(&format!("species[{k}].mass"), s.mass)?;
        }
        if self.species.iter().try_fold(0usize, |n, s| n.checked_add(s.count)).is_none() {
            return Err(Invalid::fields("species", "the counts add up to more than 2⁶⁴ particles"));
        }
        positive("init.kT", self.init.kt)?;
        for (k, s) in self.species.iter().enumerate() {
            // The thermal speed √(2kT/m) must be a number, and so must the total energy ~N·kT.
            let speed2 = 2.0 * self.init.kt / s.mass;
            if !(speed2.is_finite() && speed2 > 0.0) {
                return Err(Invalid::value(
                    "init.kT",
                    format!("{} with species[{k}].mass = {}", num(self.init.kt), num(s.mass)),
                    "the thermal speed √(2kT/m) is out of the f64 range",
                ));
            }
        }
        if !(self.init.kt * self.n_particles() as f64).is_finite() {
            return Err(Invalid::value(
                "init.kT",
                format!("{} with {} particles", num(self.init.kt), self.n_particles()),
                "the total kinetic energy overflows",
            ));
        }
        self.check_compress(d)?;
        let jamming = self.compress.as_ref().is_some_and(CompressConfig::to_jamming);
        if jamming {
            let given =
                [("run.collisions", self.run.collisions.map(|c| c.to_string())), ("run.time", self.run.time.map(num))]
                    .into_iter()
                    .chain([
                        ("equilibration.collisions", self.equilibration.collisions.map(|c| c.to_string())),
                        ("equilibration.time", self.equilibration.time.map(num)),
                    ]);
            for (field, value) in given {
                if let Some(value) = value {
                    return Err(Invalid::OnlyWith {
                        field: field.into(),
                        value,
                        with: "a compression to a packing fraction".into(),
                        allowed: "with compress.until = \"jammed\" the run ends at the jammed packing (remove it)"
                            .into(),
                    });
                }
            }
        } else if self.run.collisions.is_none() && self.run.time.is_none() {
            return Err(Invalid::fields("run", "give collisions and/or time (the run stops at whichever comes first)"));
        }
        if self.run.collisions == Some(0) {
            return Err(Invalid::value("run.collisions", "0", "must be at least 1"));
        }
        if let Some(t) = self.run.time {
            positive("run.time", t)?;
        }
        if let Some(t) = self.equilibration.time
            && !(t.is_finite() && t >= 0.0)
        {
            return Err(Invalid::value("equilibration.time", num(t), "must be a finite number ≥ 0"));
        }
        // How many samples that makes is checked with the other limits of a run
        // (`run::limits`), which also estimate it when the run is given in collisions.
        positive("run.sample_interval", self.run.sample_interval)?;
        if self.run.blocks < 2 {
            return Err(Invalid::value(
                "run.blocks",
                self.run.blocks.to_string(),
                "must be at least 2 (error bars need two blocks)",
            ));
        }
        for (name, every) in
            [("trajectory_every", self.output.trajectory_every), ("checkpoint_every", self.output.checkpoint_every)]
        {
            if every == Some(0) {
                return Err(Invalid::value(
                    format!("output.{name}"),
                    "0",
                    format!(
                        "must be at least 1 (leave it out for {})",
                        if name == "trajectory_every" { "no trajectory" } else { "only the final checkpoint" }
                    ),
                ));
            }
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
        assert_eq!(c.boundaries::<2>(), [Boundary::Periodic; 2]);
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
    }

    /// The errors are typed: the field, the value and what is allowed can be read off them,
    /// not only printed.
    #[test]
    fn errors_carry_the_field_the_value_and_what_is_allowed() {
        let text = DEFAULT_CONFIG.replace("radius = 0.5", "radius = -1.0");
        match Config::parse(&text, "t.toml") {
            Err(ConfigError::Invalid { source, invalid: Invalid::Value { field, value, allowed } }) => {
                assert_eq!((source.as_str(), field.as_str(), value.as_str()), ("t.toml", "species[0].radius", "-1"));
                assert!(allowed.contains("positive finite"), "{allowed}");
            }
            other => panic!("{other:?}"),
        }
        match Config::parse("seed = 1\n[box]\nsize = [1.0]\n", "s.toml") {
            Err(ConfigError::Syntax { at: Some((line, _)), .. }) => assert!(line >= 1),
            other => panic!("{other:?}"),
        }
    }

    /// A configuration is checked for the dimension it names: the entries of the box, of
    /// the boundaries and of the aspect, the placements and the limit of close packing follow
    /// it (π/(2√3) for disks, π/√18 for spheres); a configuration of one dimension is refused
    /// by a run of the other.
    #[test]
    fn the_dimension_decides_the_box() {
        let three = |text: &str| format!("dimension = 3\n{text}");
        let spheres = three(&DEFAULT_CONFIG.replace("packing_fraction = 0.5", "size = [20.0, 20.0, 20.0]"))
            .replace("\"triangular\"", "\"fcc\"");
        let config = Config::parse(&spheres, "3d").expect("three edges in 3D");
        assert_eq!(config.boundaries::<3>(), [Boundary::Periodic; 3]);
        assert_eq!(config.placement(), Placement::Fcc);
        let err = Config::parse(&spheres.replace("dimension = 3\n", ""), "2d").unwrap_err();
        assert!(err.to_string().contains("box.size has 3 entries: give [Lx, Ly]"), "{err}");
        let err = Config::parse(&three(DEFAULT_CONFIG).replace("packing_fraction = 0.5", "size = [20.0, 20.0]"), "s")
            .unwrap_err();
        assert!(matches!(&err, ConfigError::Invalid { invalid: Invalid::Entries { entries: 2, .. }, .. }), "{err}");
        assert!(err.to_string().contains("box.size has 2 entries: give [Lx, Ly, Lz]"), "{err}");
        let err = Config::parse(&three(DEFAULT_CONFIG), "lattice").unwrap_err().to_string();
        assert!(
            err.contains(r#"init.placement = "triangular": in 3D use placement = "fcc", "simple_cubic" or "random""#),
            "{err}"
        );
        let err = Config::parse(&DEFAULT_CONFIG.replace("\"triangular\"", "\"fcc\""), "fcc").unwrap_err().to_string();
        assert!(err.contains(r#"init.placement = "fcc": in 2D use placement = "triangular""#), "{err}");
        let without = three(&DEFAULT_CONFIG.replace("placement = \"triangular\"\n", ""));
        assert_eq!(Config::parse(&without, "default").unwrap().placement(), Placement::Fcc);
        let dense = DEFAULT_CONFIG.replace("packing_fraction = 0.5", "packing_fraction = 0.8");
        assert!(Config::parse(&dense, "disks").is_ok());
        let err =
            Config::parse(&three(&dense.replace("\"triangular\"", "\"fcc\"")), "spheres").unwrap_err().to_string();
        assert!(err.contains("(0, 0.7405)") && err.contains("π/√18"), "{err}");
        let lists = DEFAULT_CONFIG.replace("boundary = \"periodic\"", "boundary = [\"periodic\", \"wall\"]");
        assert!(Config::parse(&lists, "2d").is_ok());
        let err = Config::parse(&three(&lists.replace("\"triangular\"", "\"fcc\"")), "3d").unwrap_err().to_string();
        assert!(err.contains("box.boundary has 2 entries: give one per axis (3)"), "{err}");
        let err = Config::parse(&DEFAULT_CONFIG.replace("seed = 1", "dimension = 4\nseed = 1"), "4d").unwrap_err();
        assert!(err.to_string().contains("dimension = 4: must be 2 (disks) or 3 (spheres)"), "{err}");
        let aspect =
            three(&DEFAULT_CONFIG.replace("packing_fraction = 0.5", "packing_fraction = 0.3\naspect = [1.0, 2.0]"));
        let err = Config::parse(&aspect.replace("\"triangular\"", "\"random\""), "a").unwrap_err().to_string();
        assert!(err.contains("box.aspect has 2 entries: give the proportions [Lx, Ly, Lz]"), "{err}");
        let two = Config::default_config();
        let err = two.check_for(3).unwrap_err().to_string();
        assert_eq!(err, "dimension = 2: this is a 3D run: give dimension = 3");
    }
}
