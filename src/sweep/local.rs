//! A sweep on this machine: its unfinished tasks as parallel processes, each `collide sweep
//! SWEEP --out DIR --task K` — exactly what a scheduler's array task runs, so a task gives
//! the same bits wherever it ran. A process per task also keeps one task's crash from taking
//! the others with it: the parent records the failure and goes on.
//!
//! Each process writes what it prints to its task's `log.txt`. When `stop` is set (the
//! parent got SIGINT or SIGTERM), no further task starts; the running ones stop at their next
//! event with a checkpoint when the signal reaches them too (Ctrl-C at a terminal signals the
//! whole process group, a scheduler every process of its job), else they run to their end.
//! The next run of the sweep continues the interrupted ones.

use super::task::{self, LOG, State};
use super::{SweepError, Task};
use std::path::Path;
use std::process::{Command, Stdio};
use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::time::Instant;

/// How a task's process ended.
#[derive(Clone, Debug, PartialEq)]
pub enum Ended {
    /// Its run completed.
    Finished,
    /// It failed: the error (from `failed.json`, or how the process died).
    Failed(String),
    /// Stopped by a signal, with its checkpoint.
    Interrupted,
}

/// What the pool reports as it goes.
#[derive(Clone, Debug, PartialEq)]
pub enum Progress {
    /// Task `index` started.
    Started {
        /// The task's number.
        index: usize,
    },
    /// Task `index` ended after `seconds`.
    Ended {
        /// The task's number.
        index: usize,
        /// How.
        ended: Ended,
        /// Its wall-clock time.
        seconds: f64,
    },
}

/// The lines of a log kept in a failure's message when the process died without saying why.
const LOG_TAIL: usize = 5;

/// Runs `tasks[k]` for every `k` in `todo` as processes of `exe` (the collide binary), at most
/// `jobs` at once, into `out` (`sweep` is the sweep file, as the processes are to read it);
/// `retry_failed` is passed on. Returns how each ended, in `todo`'s order (`None`: not
/// started, because `stop` was set first). `report` hears of every start and end.
#[allow(clippy::too_many_arguments)]
pub fn run(
    exe: &Path,
    sweep: &Path,
    out: &Path,
    tasks: &[Task],
    todo: &[usize],
    jobs: usize,
    retry_failed: bool,
    stop: &AtomicBool,
    report: impl FnMut(Progress) + Send,
) -> Result<Vec<Option<Ended>>, SweepError> {
    let n = tasks.len();
    let next = AtomicUsize::new(0);
    let report = Mutex::new(report);
    let ended: Mutex<Vec<Option<Ended>>> = Mutex::new(vec![None; todo.len()]);
    let errors: Mutex<Vec<SweepError>> = Mutex::new(Vec::new());
    std::thread::scope(|scope| {
        for _ in 0..jobs.clamp(1, todo.len().max(1)) {
            scope.spawn(|| {
                loop {
                    if stop.load(Ordering::Relaxed) {
                        break;
                    }
                    let slot = next.fetch_add(1, Ordering::Relaxed);
                    let Some(&k) = todo.get(slot) else { break };
                    let task = &tasks[k];
                    (report.lock().expect("no reporter panics"))(Progress::Started { index: k });
                    let began = Instant::now();
                    match one(exe, sweep, out, task, n, retry_failed) {
                        Ok(how) => {
                            let seconds = began.elapsed().as_secs_f64();
                            ended.lock().expect("no worker panics")[slot] = Some(how.clone());
                            (report.lock().expect("no reporter panics"))(Progress::Ended {
                                index: k,
                                ended: how,
                                seconds,
                            });
                        }
                        Err(e) => {
                            errors.lock().expect("no worker panics").push(e);
                            break;
                        }
                    }
                }
            });
        }
    });
    if let Some(e) = errors.into_inner().expect("no worker panics").into_iter().next() {
        return Err(e);
    }
    Ok(ended.into_inner().expect("no worker panics"))
}

/// One task's process, from start to end.
fn one(exe: &Path, sweep: &Path, out: &Path, task: &Task, n: usize, retry_failed: bool) -> Result<Ended, SweepError> {
    let dir = task::dir(out, task, n);
    std::fs::create_dir_all(&dir).map_err(crate::run::rundir::at(&dir))?;
    let log_path = dir.join(LOG);
    let log = std::fs::OpenOptions::new()
        .create(true)
        .append(true)
        .open(&log_path)
        .map_err(crate::run::rundir::at(&log_path))?;
    let err_log = log.try_clone().map_err(crate::run::rundir::at(&log_path))?;
    let mut command = Command::new(exe);
    command.arg("sweep").arg(sweep).arg("--out").arg(out).arg("--task").arg(task.index.to_string());
    if retry_failed {
        command.arg("--retry-failed");
    }
    let mut child = command
        .stdin(Stdio::null())
        .stdout(Stdio::from(log))
        .stderr(Stdio::from(err_log))
        .spawn()
        .map_err(|e| crate::run::rundir::OutputError::Io { path: exe.to_path_buf(), error: e })?;
    // Waited for without a timeout: a signal to stop reaches the task's process itself (a
    // terminal's Ctrl-C goes to the whole process group; a scheduler signals every process
    // of its job), which then stops at its next event with a checkpoint.
    let status = child.wait();
    let how = match status {
        Ok(status) if status.code() == Some(130) => Ended::Interrupted,
        Ok(status) => match task::state(&dir, task) {
            State::Finished if status.success() => Ended::Finished,
            State::Failed(error) => Ended::Failed(error),
            State::Interrupted => Ended::Interrupted,
            _ => {
                let how = died(status);
                let error = format!("{how}; {}", tail(&log_path));
                task::record_failure(task, &dir, &error)?;
                Ended::Failed(error)
            }
        },
        Err(e) => Ended::Failed(format!("could not wait for the task's process: {e}")),
    };
    Ok(how)
}

/// How a process that left no verdict ended.
fn died(status: std::process::ExitStatus) -> String {
    #[cfg(unix)]
    {
        use std::os::unix::process::ExitStatusExt;
        if let Some(signal) = status.signal() {
            return format!("the task's process was killed by signal {signal}");
        }
    }
    match status.code() {
        Some(code) => format!("the task's process exited with status {code} without recording why"),
        None => "the task's process ended without an exit status".to_string(),
    }
}

/// The last lines of a task's log, for a failure's message.
fn tail(path: &Path) -> String {
    let text = std::fs::read_to_string(path).unwrap_or_default();
    let lines: Vec<&str> = text.lines().filter(|l| !l.trim().is_empty()).collect();
    if lines.is_empty() {
        return format!("{} is empty", path.display());
    }
    let from = lines.len().saturating_sub(LOG_TAIL);
    format!("the end of {}: {}", path.display(), lines[from..].join(" | "))
}
