//! One task of a sweep: its directory, what state its files say it is in, and running it.
//!
//! `DIR/tasks/NNNN/` is an ordinary run directory (`summary.json`, `timeseries.csv`,
//! `checkpoint.json`, …) with three files more:
//!
//! | file | written | holds |
//! |---|---|---|
//! | `task.json` | before the run starts | the task's number, varied values and configuration digest |
//! | `config.toml` | before the run starts | the configuration (`collide run config.toml` repeats the task) |
//! | `failed.json` | when the run fails | the error, as `collide run` would have printed it |
//!
//! A task's [`State`] is read from these files alone, so that any process — a local sweep,
//! a Slurm array task, `--collect` — tells it the same way. A task directory whose
//! `task.json` carries another digest holds the run of another configuration (the sweep
//! file was edited): the task counts as not started and runs afresh.

use super::{SweepError, Task};
use crate::run::output::{AnyCheckpoint, RunOptions, Start, load_any_checkpoint, run_into};
use crate::run::rundir::{OutputError, RunDir, write_atomic};
use crate::run::{Status, Summary};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;
use toml::Value;

/// The task's record.
pub const RECORD: &str = "task.json";
/// The task's configuration.
pub const CONFIG: &str = "config.toml";
/// The failure record.
pub const FAILED: &str = "failed.json";
/// What a local sweep's process for the task printed.
pub const LOG: &str = "log.txt";

/// What a task's directory says about it.
#[derive(Clone, Debug, PartialEq)]
pub enum State {
    /// Not started, started for another configuration, or stopped without a trace (killed,
    /// or still running).
    NotFinished,
    /// Its run completed: `summary.json` is there and says so.
    Finished,
    /// Its run failed; the error.
    Failed(String),
    /// Stopped by a signal after saving its checkpoint: running it again continues it.
    Interrupted,
}

impl State {
    /// `finished`, `failed`, `interrupted` or `missing`: the `status` column of the results.
    pub fn name(&self) -> &'static str {
        match self {
            State::NotFinished => "missing",
            State::Finished => "finished",
            State::Failed(_) => "failed",
            State::Interrupted => "interrupted",
        }
    }
}

/// How running a task went.
#[derive(Clone, Debug, PartialEq)]
pub enum Outcome {
    /// It had finished before: nothing was run.
    AlreadyFinished,
    /// It had failed before and failures are not retried: nothing was run.
    AlreadyFailed(String),
    /// It ran to completion.
    Finished(Box<Summary>),
    /// It failed (recorded in `failed.json`).
    Failed(String),
    /// A signal stopped it; its checkpoint continues it.
    Interrupted,
}

/// `task.json`.
#[derive(Clone, Debug, Serialize, Deserialize)]
struct Record {
    index: usize,
    parameters: serde_json::Map<String, serde_json::Value>,
    digest: String,
}

/// `failed.json`.
#[derive(Clone, Debug, Serialize, Deserialize)]
struct Failure {
    index: usize,
    error: String,
}

/// Varied values (a task's `parameters`) as JSON.
pub(crate) fn parameters_json(parameters: &[(String, Value)]) -> serde_json::Map<String, serde_json::Value> {
    parameters.iter().map(|(k, v)| (k.clone(), serde_json::to_value(v).unwrap_or(serde_json::Value::Null))).collect()
}

/// The task's directory under the sweep's output directory `out`.
pub fn dir(out: &Path, task: &Task, n_tasks: usize) -> PathBuf {
    out.join("tasks").join(task.dir_name(n_tasks))
}

/// Whether `dir`'s `task.json` is `task`'s: its number and its configuration's digest.
fn recorded(dir: &Path, task: &Task) -> bool {
    std::fs::read(dir.join(RECORD))
        .ok()
        .and_then(|b| serde_json::from_slice::<Record>(&b).ok())
        .is_some_and(|r| r.digest == task.digest && r.index == task.index)
}

/// Writes `failed.json` for `task` into `dir`.
fn write_failure(task: &Task, dir: &Path, error: &str) -> Result<(), SweepError> {
    let failure = Failure { index: task.index, error: error.to_string() };
    write_atomic(&dir.join(FAILED), serde_json::to_string_pretty(&failure).expect("serialises").as_bytes())?;
    Ok(())
}

/// The state of `task`, from the files in its directory `dir`.
pub fn state(dir: &Path, task: &Task) -> State {
    if !recorded(dir, task) {
        return State::NotFinished;
    }
    if let Some(failure) = std::fs::read(dir.join(FAILED)).ok().and_then(|b| serde_json::from_slice::<Failure>(&b).ok())
    {
        return State::Failed(failure.error);
    }
    // Read as JSON, not as a `Summary`: an interrupted run's summary holds nulls (no
    // estimates yet) where a complete one holds numbers.
    let Some(summary) =
        std::fs::read(dir.join("summary.json")).ok().and_then(|b| serde_json::from_slice::<serde_json::Value>(&b).ok())
    else {
        return State::NotFinished;
    };
    match summary.get("status").and_then(|s| s.as_str()) {
        None => State::Finished,
        Some("interrupted") if dir.join("checkpoint.json").is_file() => State::Interrupted,
        Some("interrupted") => State::NotFinished,
        // Recorded in failed.json when the run ended so; this is a summary without it.
        Some(other) => State::Failed(format!("the run ended {other}")),
    }
}

/// Runs `task` into `dir`, unless it has finished (or failed, unless `retry_failed`): an
/// interrupted task continues from its checkpoint, anything else starts afresh (the
/// directory's earlier run files replaced). `stop` stops it as SIGINT stops `collide run`:
/// at its next event, with a checkpoint. A failure of the run is recorded in `failed.json`
/// and returned as [`Outcome::Failed`]; `Err` only when the task's own files cannot be
/// written.
pub fn run(task: &Task, dir: &Path, retry_failed: bool, stop: &AtomicBool) -> Result<Outcome, SweepError> {
    let state = state(dir, task);
    match &state {
        State::Finished => return Ok(Outcome::AlreadyFinished),
        State::Failed(error) if !retry_failed => return Ok(Outcome::AlreadyFailed(error.clone())),
        _ => {}
    }
    // Another process running this task (an array element submitted twice, a second sweep
    // into the same directory) holds the directory's lock: refused before any of its files
    // is touched. (Opening creates the directory; resuming there is always allowed.)
    drop(RunDir::open(dir, false, Some(dir))?);
    let checkpoint = dir.join("checkpoint.json");
    let resumed = match state {
        State::Interrupted => load_any_checkpoint(&checkpoint).ok(),
        _ => None,
    };
    let quiet = |_: crate::run::Phase, _: f64| {};
    let ran = match resumed {
        // Continued in its own directory, which `run_into` always allows.
        Some(AnyCheckpoint::Disks(saved)) => run_into::<2>(
            Start::Resume { checkpoint: saved, path: &checkpoint },
            dir,
            RunOptions::default(),
            stop,
            quiet,
        ),
        Some(AnyCheckpoint::Spheres(saved)) => run_into::<3>(
            Start::Resume { checkpoint: saved, path: &checkpoint },
            dir,
            RunOptions::default(),
            stop,
            quiet,
        ),
        None => {
            // Whatever an earlier run left goes first, the record last: a directory never
            // pairs this task's record with another configuration's summary.
            for name in [FAILED, RECORD, "summary.json"] {
                match std::fs::remove_file(dir.join(name)) {
                    Err(e) if e.kind() != std::io::ErrorKind::NotFound => {
                        return Err(crate::run::rundir::at(&dir.join(name))(e).into());
                    }
                    _ => {}
                }
            }
            let header = format!("# collide sweep, task {}: {}\n", task.index, task.label());
            write_atomic(&dir.join(CONFIG), format!("{header}{}", task.text).as_bytes())?;
            let record = Record {
                index: task.index,
                parameters: parameters_json(&task.parameters),
                digest: task.digest.clone(),
            };
            write_atomic(&dir.join(RECORD), serde_json::to_string_pretty(&record).expect("serialises").as_bytes())?;
            let options = RunOptions { force: true, interrupt_after: None };
            let config = task.config.clone();
            match config.dimension {
                3 => run_into::<3>(Start::Fresh(config), dir, options, stop, quiet),
                _ => run_into::<2>(Start::Fresh(config), dir, options, stop, quiet),
            }
        }
    };
    let error = match ran {
        Ok(summary) if summary.status == Status::Interrupted => return Ok(Outcome::Interrupted),
        Ok(summary) => match summary.problem() {
            Some(problem) => problem,
            None => return Ok(Outcome::Finished(Box::new(summary))),
        },
        Err(e) => e.to_string(),
    };
    write_failure(task, dir, &error)?;
    Ok(Outcome::Failed(error))
}

/// Records a failure the task's own process could not record (it was killed, or crashed):
/// `error` in `failed.json`, if the task's record is this task's — and no other process is
/// running the task (then the process that ended was refused its directory, and the task is
/// not failed).
pub fn record_failure(task: &Task, dir: &Path, error: &str) -> Result<(), SweepError> {
    if matches!(RunDir::open(dir, false, Some(dir)), Err(OutputError::Locked { .. })) {
        return Ok(());
    }
    if recorded(dir, task) && state(dir, task) == State::NotFinished {
        write_failure(task, dir, error)?;
    }
    Ok(())
}

/// `manifest.json`: the sweep's tasks, their directories, values and digests.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Manifest {
    /// The version that wrote it.
    pub collide_version: String,
    /// The sweep file.
    pub sweep: String,
    /// The varied keys.
    pub parameters: Vec<String>,
    /// One entry a task.
    pub tasks: Vec<ManifestTask>,
}

/// One task of [`Manifest`].
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct ManifestTask {
    /// Its number.
    pub index: usize,
    /// Its directory, relative to the sweep's.
    pub dir: String,
    /// Its varied values.
    pub parameters: serde_json::Map<String, serde_json::Value>,
    /// Its configuration's digest.
    pub digest: String,
}

/// The manifest file of `out`.
pub fn manifest_path(out: &Path) -> PathBuf {
    out.join("manifest.json")
}

/// Writes `out/manifest.json` for `tasks`.
pub fn write_manifest(out: &Path, source: &str, keys: &[String], tasks: &[Task]) -> Result<(), SweepError> {
    std::fs::create_dir_all(out.join("tasks")).map_err(crate::run::rundir::at(out))?;
    let n = tasks.len();
    let manifest = Manifest {
        collide_version: env!("CARGO_PKG_VERSION").to_string(),
        sweep: source.to_string(),
        parameters: keys.to_vec(),
        tasks: tasks
            .iter()
            .map(|t| ManifestTask {
                index: t.index,
                dir: format!("tasks/{}", t.dir_name(n)),
                parameters: parameters_json(&t.parameters),
                digest: t.digest.clone(),
            })
            .collect(),
    };
    write_atomic(&manifest_path(out), serde_json::to_string_pretty(&manifest).expect("serialises").as_bytes())?;
    Ok(())
}

/// Refuses to run `task` (of `n` tasks) into `out` when `out`'s manifest, if there is one,
/// was written for another sweep: a job array submitted before the sweep file was edited
/// would otherwise mix two sweeps in one directory.
pub fn check_manifest(out: &Path, task: &Task, n: usize) -> Result<(), SweepError> {
    let path = manifest_path(out);
    let Ok(bytes) = std::fs::read(&path) else { return Ok(()) };
    let manifest: Manifest = serde_json::from_slice(&bytes)
        .map_err(|e| SweepError::Manifest { path: path.clone(), problem: format!("not a sweep manifest: {e}") })?;
    let problem = if manifest.tasks.len() != n {
        Some(format!("lists {} tasks, the sweep file makes {n}", manifest.tasks.len()))
    } else if manifest.tasks.get(task.index).is_none_or(|t| t.digest != task.digest) {
        Some(format!("task {} has another configuration than the sweep file gives it ({})", task.index, task.label()))
    } else {
        None
    };
    match problem {
        Some(problem) => Err(SweepError::Manifest {
            path,
            problem: format!(
                "{problem}: the sweep file changed after the manifest was written; write it again (collide sweep … --emit slurm, or a local run) or choose another --out"
            ),
        }),
        None => Ok(()),
    }
}
