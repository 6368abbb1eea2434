//! Sweeps: one run configuration with some of its values varied — densities × seeds × sizes —
//! as independent tasks, run on this machine's cores or as a scheduler's job array, and
//! collected into one table.
//!
//! # Data flow
//!
//! * A [`Sweep`] is read from a sweep file ([`Sweep::load`]): `[base]`, a complete run
//!   configuration (the format of `collide run`), `[vary]` and `[[zip]]`, the values to
//!   vary, and the optional `[plot]` and `[slurm]` tables. Every error names the file and the
//!   key.
//! * [`Sweep::tasks`] expands it into [`Task`]s: each one a validated
//!   [`Config`], its TOML text and the SHA-256 digest of that text. The
//!   varied keys form *factors* — each `[vary]` key one, each `[[zip]]` group one (its lists
//!   vary together) — and the tasks are their Cartesian product, numbered like nested loops
//!   in the order the factors are written, the first slowest.
//! * [`task`] runs one task into `DIR/tasks/NNNN/` (an ordinary run directory with its own
//!   `summary.json`), records a failure with its error, and tells each task's
//!   [`State`](task::State) from the files: a rerun skips what has finished.
//! * [`local`] runs the unfinished tasks as parallel processes (`collide sweep … --task K`);
//!   [`slurm`] writes the job-array script whose every element runs one the same way — the
//!   same code, so the same bits.
//! * [`table`] collects whatever has finished into `results.csv`, `results.json` and an SVG,
//!   and names what is missing or failed.
//!
//! # The sweep file
//!
//! ```toml
//! [base]                              # a complete run configuration (or base = "run.toml")
//! seed = 1
//! [base.box]
//! packing_fraction = 0.3
//! boundary = "periodic"
//! [[base.species]]
//! count = 400
//! radius = 0.5
//! mass = 1.0
//! [base.equilibration]
//! collisions = 20000
//! [base.run]
//! collisions = 100000
//!
//! [vary]                              # dotted keys into [base]; the Cartesian product
//! "box.packing_fraction" = [0.2, 0.3, 0.4]
//! seed = [1, 2]
//!
//! [[zip]]                             # optional: lists of one length, varied together
//! "species.0.count" = [100, 400]
//! "run.collisions" = [50000, 200000]
//!
//! [plot]                              # optional: the SVG's axes
//! y = "compressibility"               # a column of results.csv (default)
//! x = "box.packing_fraction"          # a varied key (default: the first)
//!
//! [slurm]                             # optional: the job array's resources
//! time = "02:00:00"
//! mem = "1G"
//! partition = "short"
//! account = "myproject"
//! throttle = 20                       # at most 20 tasks at once (--array=…%20)
//! options = ["--qos=normal"]          # further #SBATCH lines, verbatim
//! ```
//!
//! A dotted key walks tables by name and arrays by index (`species.0.count` is the count of
//! the first `[[species]]`); a missing table on the way is created, a missing array entry is
//! an error. Every task's configuration is validated before anything runs, so a sweep with a
//! bad value is refused whole, naming the task and the key.
//!
//! # Example
//!
//! ```
//! use collide::sweep::Sweep;
//! let text = r#"
//!     [base]
//!     seed = 1
//!     [base.box]
//!     packing_fraction = 0.3
//!     boundary = "periodic"
//!     [[base.species]]
//!     count = 100
//!     radius = 0.5
//!     mass = 1.0
//!     [base.run]
//!     collisions = 10000
//!     [vary]
//!     "box.packing_fraction" = [0.2, 0.4]
//!     seed = [1, 2, 3]
//! "#;
//! let sweep = Sweep::parse(text, "sweep.toml", std::path::Path::new("."))?;
//! let tasks = sweep.tasks()?;
//! assert_eq!(tasks.len(), 6);
//! // Nested loops, the first factor slowest: task 4 is η = 0.4 with seed 2.
//! assert_eq!(tasks[4].label(), "box.packing_fraction = 0.4, seed = 2");
//! assert_eq!(tasks[4].config.seed, 2);
//! # Ok::<(), collide::sweep::SweepError>(())
//! ```

pub mod local;
pub mod slurm;
pub mod table;
pub mod task;

use crate::run::config::{Config, ConfigError, MAX_FILE_BYTES};
use std::fmt;
use std::path::{Path, PathBuf};
use toml::{Table, Value};

/// The most tasks one sweep may hold (a sweep this large is more likely a mistake — a list
/// pasted twice — than a plan; Slurm's own default limit on an array is 1001).
pub const MAX_TASKS: usize = 100_000;

/// The tables a sweep file may hold.
const TABLES: [&str; 5] = ["base", "vary", "zip", "plot", "slurm"];

/// A sweep: the base configuration, the factors varied, and how to plot and submit it.
#[derive(Clone, Debug)]
pub struct Sweep {
    /// The sweep file, as errors name it.
    pub source: String,
    /// The factors, in the order written: `[vary]` keys, then `[[zip]]` groups.
    pub factors: Vec<Factor>,
    /// The SVG's axes.
    pub plot: Plot,
    /// The job array's resources (`[slurm]`).
    pub slurm: SlurmOptions,
    base: Table,
}

/// One factor of a sweep: one `[vary]` key, or one `[[zip]]` group of keys varied together.
#[derive(Clone, Debug, PartialEq)]
pub struct Factor {
    /// Where it was written (`[vary] "seed"`, `[[zip]] 1`).
    pub origin: String,
    /// Its dotted keys.
    pub keys: Vec<String>,
    /// Its levels: one value per key each.
    pub levels: Vec<Vec<Value>>,
}

/// The SVG's axes: `y`, a column of `results.csv`, against `x`, a varied key.
#[derive(Clone, Debug, PartialEq)]
pub struct Plot {
    /// A varied key.
    pub x: String,
    /// A column of the results (a summary scalar).
    pub y: String,
}

/// Resources for the job array (`[slurm]`, or the command line, which wins).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SlurmOptions {
    /// `--time` (wall-clock limit per task, e.g. `"02:00:00"`).
    pub time: Option<String>,
    /// `--mem` (memory per task, e.g. `"1G"`).
    pub mem: Option<String>,
    /// `--partition`.
    pub partition: Option<String>,
    /// `--account`.
    pub account: Option<String>,
    /// The most array tasks running at once (`--array=…%k`).
    pub throttle: Option<u32>,
    /// Further `#SBATCH` options, verbatim (`"--qos=normal"`).
    pub options: Vec<String>,
}

/// One task of a sweep: a complete run configuration.
#[derive(Clone, Debug)]
pub struct Task {
    /// Its number, from 0.
    pub index: usize,
    /// The varied keys and this task's values, in the factors' order.
    pub parameters: Vec<(String, Value)>,
    /// Its configuration, validated.
    pub config: Config,
    /// The configuration as TOML ([`Config::to_toml`]), as `config.toml` holds it.
    pub text: String,
    /// `"sha256:"` and the digest of `text`: a task directory whose record carries another
    /// digest holds another configuration's run.
    pub digest: String,
}

impl Task {
    /// `key = value, …`: the task's varied values, as TOML writes them.
    pub fn label(&self) -> String {
        self.parameters.iter().map(|(k, v)| format!("{k} = {v}")).collect::<Vec<_>>().join(", ")
    }

    /// Its directory's name under `tasks/`: the number, zero-padded to the width of the
    /// largest (at least four digits), so that the directories sort in task order.
    pub fn dir_name(&self, n_tasks: usize) -> String {
        let width = n_tasks.saturating_sub(1).to_string().len().max(4);
        format!("{:0width$}", self.index)
    }
}

/// A sweep file that cannot be used, or a task directory that cannot be written.
#[non_exhaustive]
#[derive(Debug)]
pub enum SweepError {
    /// The sweep file, or the base file it names, is not a readable TOML file.
    Read {
        /// The file.
        source: String,
        /// What is wrong.
        reason: String,
    },
    /// A key of the sweep file holds something not allowed.
    Invalid {
        /// The file.
        source: String,
        /// The table and key (`[vary] "box.packing_fraction"`).
        key: String,
        /// What is wrong, and what is allowed.
        problem: String,
    },
    /// A task's configuration is not a valid run configuration.
    Task {
        /// Its number.
        index: usize,
        /// Its varied values.
        label: String,
        /// The configuration's error (its source names the sweep file and the task).
        error: Box<ConfigError>,
    },
    /// A file of the sweep's output directory could not be read or written.
    Output(crate::run::rundir::OutputError),
    /// The output directory belongs to another sweep (its manifest disagrees).
    Manifest {
        /// The manifest.
        path: PathBuf,
        /// What disagrees.
        problem: String,
    },
}

impl fmt::Display for SweepError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SweepError::Read { source, reason } => write!(f, "{source}: {reason}"),
            SweepError::Invalid { source, key, problem } => write!(f, "{source}: {key}: {problem}"),
            SweepError::Task { error, .. } => write!(f, "{error}"),
            SweepError::Output(e) => write!(f, "{e}"),
            SweepError::Manifest { path, problem } => write!(f, "{}: {problem}", path.display()),
        }
    }
}

impl std::error::Error for SweepError {}

impl From<crate::run::rundir::OutputError> for SweepError {
    fn from(e: crate::run::rundir::OutputError) -> Self {
        SweepError::Output(e)
    }
}

/// Reads a TOML file into a table, with the checks of a run configuration's reading (size,
/// UTF-8, syntax with line and column).
fn read_table(path: &Path) -> Result<Table, SweepError> {
    let source = path.display().to_string();
    let read = |reason: String| SweepError::Read { source: source.clone(), reason };
    let bytes = std::fs::metadata(path).map_err(|e| read(format!("cannot read the file: {e}")))?.len();
    if bytes > MAX_FILE_BYTES {
        return Err(read(format!("the file holds {bytes} bytes, more than a sweep can ({MAX_FILE_BYTES})")));
    }
    let bytes = std::fs::read(path).map_err(|e| read(format!("cannot read the file: {e}")))?;
    let text = String::from_utf8(bytes).map_err(|_| read("not valid UTF-8 (TOML files are UTF-8 text)".into()))?;
    parse_table(&text, &source)
}

/// Parses TOML text into a table; a syntax error names the line and column.
fn parse_table(text: &str, source: &str) -> Result<Table, SweepError> {
    text.parse::<Table>().map_err(|e| {
        let at = e.span().map(|span| {
            let before = &text[..span.start.min(text.len())];
            let line = before.matches('\n').count() + 1;
            let column = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
            format!(" at line {line}, column {column}")
        });
        SweepError::Read {
            source: source.to_string(),
            reason: format!("TOML parse error{}: {}", at.unwrap_or_default(), e.message()),
        }
    })
}

impl Sweep {
    /// Reads and checks a sweep file (a `base = "file"` is read relative to it).
    pub fn load(path: &Path) -> Result<Sweep, SweepError> {
        let table = read_table(path)?;
        let dir = path.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."));
        Sweep::from_table(table, &path.display().to_string(), dir)
    }

    /// Parses and checks sweep text; `source` names it in errors, `dir` is where a
    /// `base = "file"` is looked for.
    pub fn parse(text: &str, source: &str, dir: &Path) -> Result<Sweep, SweepError> {
        Sweep::from_table(parse_table(text, source)?, source, dir)
    }

    fn from_table(mut table: Table, source: &str, dir: &Path) -> Result<Sweep, SweepError> {
        let invalid = |key: &str, problem: String| SweepError::Invalid {
            source: source.to_string(),
            key: key.to_string(),
            problem,
        };
        if let Some(unknown) = table.keys().find(|k| !TABLES.contains(&k.as_str())) {
            return Err(invalid(
                &format!("[{unknown}]"),
                "not a part of a sweep file, which holds [base], [vary], [[zip]], [plot] and [slurm]".into(),
            ));
        }
        let base = match table.remove("base") {
            Some(Value::Table(base)) => base,
            Some(Value::String(file)) => read_table(&dir.join(&file))?,
            Some(other) => {
                return Err(invalid(
                    "base",
                    format!("is {}; give a [base] table (a run configuration) or the name of one's file", kind(&other)),
                ));
            }
            None => return Err(invalid("[base]", "missing: a sweep varies a base run configuration".into())),
        };
        let mut factors = Vec::new();
        match table.remove("vary") {
            Some(Value::Table(vary)) => {
                for (key, values) in vary {
                    let origin = format!("[vary] \"{key}\"");
                    let levels = list(values, &origin).map_err(|p| invalid(&origin, p))?;
                    factors.push(Factor {
                        origin,
                        keys: vec![key],
                        levels: levels.into_iter().map(|v| vec![v]).collect(),
                    });
                }
            }
            Some(other) => return Err(invalid("vary", format!("is {}; give a [vary] table", kind(&other)))),
            None => {}
        }
        match table.remove("zip") {
            Some(Value::Array(groups)) => {
                for (g, group) in groups.into_iter().enumerate() {
                    let origin = format!("[[zip]] {}", g + 1);
                    let Value::Table(group) = group else {
                        return Err(invalid(&origin, "give each [[zip]] as a table of keys to lists".into()));
                    };
                    factors.push(zip(group, &origin).map_err(|p| invalid(&origin, p))?);
                }
            }
            Some(other) => return Err(invalid("zip", format!("is {}; write each group as [[zip]]", kind(&other)))),
            None => {}
        }
        check_keys(&factors, &base).map_err(|(key, problem)| invalid(&key, problem))?;
        let first = factors.first().map(|f| f.keys[0].clone()).unwrap_or_default();
        let plot = match table.remove("plot") {
            Some(Value::Table(plot)) => plot_axes(plot, &factors, first).map_err(|(k, p)| invalid(&k, p))?,
            Some(other) => return Err(invalid("plot", format!("is {}; give a [plot] table", kind(&other)))),
            None => Plot { x: first, y: "compressibility".into() },
        };
        let slurm = match table.remove("slurm") {
            Some(Value::Table(slurm)) => slurm_options(slurm).map_err(|(k, p)| invalid(&k, p))?,
            Some(other) => return Err(invalid("slurm", format!("is {}; give a [slurm] table", kind(&other)))),
            None => SlurmOptions::default(),
        };
        let sweep = Sweep { source: source.to_string(), factors, plot, slurm, base };
        let n = sweep.len_checked().ok_or_else(|| {
            invalid(
                "[vary] and [[zip]]",
                format!(
                    "the factors make more than {MAX_TASKS} tasks; split the sweep (or check for a list pasted twice)"
                ),
            )
        })?;
        debug_assert!(n >= 1);
        Ok(sweep)
    }

    /// The number of tasks (1 with nothing varied: the base alone).
    pub fn len(&self) -> usize {
        self.len_checked().expect("checked when read")
    }

    /// Whether the sweep has no task (never: the base alone is one).
    pub fn is_empty(&self) -> bool {
        false
    }

    fn len_checked(&self) -> Option<usize> {
        self.factors.iter().try_fold(1usize, |n, f| n.checked_mul(f.levels.len()).filter(|&n| n <= MAX_TASKS))
    }

    /// The varied keys, in the factors' order (the columns of the results after `task`).
    pub fn keys(&self) -> Vec<String> {
        self.factors.iter().flat_map(|f| f.keys.iter().cloned()).collect()
    }

    /// Every task, validated: the first invalid one is an error that names it.
    pub fn tasks(&self) -> Result<Vec<Task>, SweepError> {
        (0..self.len()).map(|k| self.task(k)).collect()
    }

    /// Task `index` (below [`len`](Self::len)).
    pub fn task(&self, index: usize) -> Result<Task, SweepError> {
        assert!(index < self.len(), "task {index} of {}", self.len());
        // Nested loops, the last factor fastest.
        let mut rest = index;
        let mut levels = vec![0; self.factors.len()];
        for (f, factor) in self.factors.iter().enumerate().rev() {
            levels[f] = rest % factor.levels.len();
            rest /= factor.levels.len();
        }
        let mut table = self.base.clone();
        let mut parameters = Vec::new();
        for (factor, &level) in self.factors.iter().zip(&levels) {
            for (key, value) in factor.keys.iter().zip(&factor.levels[level]) {
                set(&mut table, key, value.clone()).expect("keys checked when read");
                parameters.push((key.clone(), value.clone()));
            }
        }
        let mut task =
            Task { index, parameters, config: Config::default_config(), text: String::new(), digest: String::new() };
        let source = if task.parameters.is_empty() {
            format!("{} [base]", self.source)
        } else {
            format!("{}, task {index} ({})", self.source, task.label())
        };
        task.config = Config::from_table(table, &source).map_err(|error| SweepError::Task {
            index,
            label: task.label(),
            error: Box::new(error),
        })?;
        task.text = task.config.to_toml();
        task.digest = crate::run::checkpoint::sha256(task.text.as_bytes());
        Ok(task)
    }
}

/// What a TOML value is, for errors.
fn kind(value: &Value) -> &'static str {
    match value {
        Value::String(_) => "a string",
        Value::Integer(_) => "an integer",
        Value::Float(_) => "a float",
        Value::Boolean(_) => "a boolean",
        Value::Datetime(_) => "a date",
        Value::Array(_) => "a list",
        Value::Table(_) => "a table",
    }
}

/// A varied key's values: a non-empty list.
fn list(values: Value, _origin: &str) -> Result<Vec<Value>, String> {
    match values {
        Value::Array(values) if !values.is_empty() => Ok(values),
        Value::Array(_) => Err("an empty list: give at least one value".into()),
        other => Err(format!("is {}; give the list of its values, e.g. [0.2, 0.4]", kind(&other))),
    }
}

/// A `[[zip]]` group: keys to lists of one length.
fn zip(group: Table, origin: &str) -> Result<Factor, String> {
    if group.is_empty() {
        return Err("an empty group: give keys and their lists".into());
    }
    let mut keys = Vec::new();
    let mut lists: Vec<Vec<Value>> = Vec::new();
    for (key, values) in group {
        let values = list(values, origin).map_err(|p| format!("\"{key}\" {p}"))?;
        if let Some(first) = lists.first()
            && first.len() != values.len()
        {
            return Err(format!(
                "\"{}\" has {} values and \"{key}\" {}: the lists of a group vary together and need one length",
                keys[0],
                first.len(),
                values.len()
            ));
        }
        keys.push(key);
        lists.push(values);
    }
    let levels = (0..lists[0].len()).map(|l| lists.iter().map(|values| values[l].clone()).collect()).collect();
    Ok(Factor { origin: origin.to_string(), keys, levels })
}

/// Each key varied once, none inside another, each reachable in the base.
fn check_keys(factors: &[Factor], base: &Table) -> Result<(), (String, String)> {
    let mut seen: Vec<(&str, &str)> = Vec::new();
    for factor in factors {
        for key in &factor.keys {
            let at = || format!("{} \"{key}\"", factor.origin.split(" \"").next().unwrap_or(&factor.origin));
            if key.is_empty() || key.split('.').any(str::is_empty) {
                return Err((
                    at(),
                    "not a dotted key: give names joined by dots, e.g. \"box.packing_fraction\"".into(),
                ));
            }
            for (other, origin) in &seen {
                let nested = |a: &str, b: &str| b.strip_prefix(a).is_some_and(|rest| rest.starts_with('.'));
                if other == key {
                    return Err((at(), format!("varied twice (also in {origin}); vary each key once")));
                }
                if nested(other, key) || nested(key, other) {
                    return Err((
                        at(),
                        format!("overlaps \"{other}\" ({origin}); vary a value or the table that holds it, not both"),
                    ));
                }
            }
            // The first level settles whether the key can be set at all (the others only
            // change the value).
            let mut probe = base.clone();
            set(&mut probe, key, factor.levels[0][factor.keys.iter().position(|k| k == key).expect("own key")].clone())
                .map_err(|problem| (at(), problem))?;
            seen.push((key, &factor.origin));
        }
    }
    Ok(())
}

/// Sets the dotted `key` in `table`: names walk tables (missing ones created), numbers walk
/// lists (which must hold the entry).
fn set(table: &mut Table, key: &str, value: Value) -> Result<(), String> {
    let parts: Vec<&str> = key.split('.').collect();
    let mut here = Value::Table(std::mem::take(table));
    let result = set_in(&mut here, &parts, value, "[base]".to_string());
    let Value::Table(back) = here else { unreachable!("the root stays a table") };
    *table = back;
    result
}

/// [`set`] below `here`, which is `walked` (`[base] species.0`) in the base.
fn set_in(here: &mut Value, parts: &[&str], value: Value, walked: String) -> Result<(), String> {
    let (part, rest) = (parts[0], &parts[1..]);
    let slot: &mut Value = match here {
        Value::Table(t) => {
            if rest.is_empty() {
                t.insert(part.to_string(), value);
                return Ok(());
            }
            t.entry(part.to_string()).or_insert_with(|| Value::Table(Table::new()))
        }
        Value::Array(a) => {
            let Ok(i) = part.parse::<usize>() else {
                return Err(format!("{walked} is a list: index it by number (\"{part}\" is not one)"));
            };
            let len = a.len();
            let Some(slot) = a.get_mut(i) else {
                return Err(format!(
                    "{walked} has {len} entries (0 to {}): there is no entry {i}",
                    len.saturating_sub(1)
                ));
            };
            if rest.is_empty() {
                *slot = value;
                return Ok(());
            }
            slot
        }
        other => return Err(format!("{walked} is {}, not a table or list, so it holds no \"{part}\"", kind(other))),
    };
    let walked = if walked == "[base]" { format!("[base] {part}") } else { format!("{walked}.{part}") };
    set_in(slot, rest, value, walked)
}

/// `[plot]`: `y` (a string) and `x` (a varied key).
fn plot_axes(mut plot: Table, factors: &[Factor], first: String) -> Result<Plot, (String, String)> {
    let mut text = |name: &str| match plot.remove(name) {
        None => Ok(None),
        Some(Value::String(s)) if !s.is_empty() => Ok(Some(s)),
        Some(other) => Err((format!("[plot] {name}"), format!("is {}; give a column name as a string", kind(&other)))),
    };
    let y = text("y")?.unwrap_or_else(|| "compressibility".into());
    let x = match text("x")? {
        Some(x) if factors.iter().any(|f| f.keys.contains(&x)) => x,
        Some(x) => {
            return Err(("[plot] x".into(), format!("\"{x}\" is not a varied key; x is one of [vary] or [[zip]]")));
        }
        None => first,
    };
    if let Some(unknown) = plot.keys().next() {
        return Err((format!("[plot] {unknown}"), "unknown: [plot] holds x and y".into()));
    }
    Ok(Plot { x, y })
}

/// `[slurm]`: strings for the resources, a throttle, verbatim options.
fn slurm_options(mut slurm: Table) -> Result<SlurmOptions, (String, String)> {
    let mut text = |name: &str| match slurm.remove(name) {
        None => Ok(None),
        Some(Value::String(s)) => {
            slurm::check_option(name, &s).map(|()| Some(s)).map_err(|p| (format!("[slurm] {name}"), p))
        }
        Some(other) => {
            Err((format!("[slurm] {name}"), format!("is {}; give it as a string, as sbatch takes it", kind(&other))))
        }
    };
    let (time, mem, partition, account) = (text("time")?, text("mem")?, text("partition")?, text("account")?);
    let throttle = match slurm.remove("throttle") {
        None => None,
        Some(Value::Integer(k)) if k >= 1 && k <= u32::MAX as i64 => Some(k as u32),
        Some(other) => {
            return Err((
                "[slurm] throttle".into(),
                format!("{other} is not allowed: the most tasks at once, an integer ≥ 1"),
            ));
        }
    };
    let options = match slurm.remove("options") {
        None => Vec::new(),
        Some(Value::Array(items)) => items
            .into_iter()
            .map(|item| match item {
                Value::String(s) => slurm::check_option("options", &s).map(|()| s),
                other => Err(format!("holds {}; give sbatch options as strings, e.g. \"--qos=normal\"", kind(&other))),
            })
            .collect::<Result<_, _>>()
            .map_err(|p| ("[slurm] options".to_string(), p))?,
        Some(other) => return Err(("[slurm] options".into(), format!("is {}; give a list of strings", kind(&other)))),
    };
    if let Some(unknown) = slurm.keys().next() {
        return Err((
            format!("[slurm] {unknown}"),
            "unknown: [slurm] holds time, mem, partition, account, throttle and options".into(),
        ));
    }
    Ok(SlurmOptions { time, mem, partition, account, throttle, options })
}

#[cfg(test)]
mod tests;
