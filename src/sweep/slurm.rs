//! A sweep as a Slurm job array: `DIR/sweep.sbatch`, whose array task `K` runs `collide
//! sweep SWEEP --out DIR --task K` — one task, exactly as a local sweep's process does.
//!
//! The script names the collide binary, the sweep file and the output directory by absolute
//! path (the compute nodes must see them at the same paths: a shared file system, as
//! clusters have). `exec` makes collide the job's process, so the SIGTERM Slurm sends at the
//! time limit reaches it: the task stops at its next event with a checkpoint, and
//! submitting again continues it. The array lists the tasks not yet finished (all of them
//! the first time); failed ones only with `--retry-failed`.
//!
//! Other schedulers run the same command with their own array index:
//!
//! | scheduler | submit | task number |
//! |---|---|---|
//! | PBS Pro | `qsub -J 0-(n−1)` | `$PBS_ARRAY_INDEX` |
//! | Torque | `qsub -t 0-(n−1)` | `$PBS_ARRAYID` |
//! | LSF | `bsub -J "sweep[1-n]"` | `$((LSB_JOBINDEX - 1))` (LSF counts from 1) |
//! | HTCondor | `queue n` | `$(Process)` |

use super::{SlurmOptions, SweepError};
use crate::run::rundir::write_atomic;
use std::path::{Path, PathBuf};

/// Checks a value that becomes part of an `#SBATCH` line: one line, printable.
pub(crate) fn check_option(name: &str, value: &str) -> Result<(), String> {
    if value.trim().is_empty() {
        return Err(format!("an empty {name}: leave it out instead"));
    }
    if value.chars().any(char::is_control) {
        return Err(format!("{value:?} holds a line break or control character; an #SBATCH line is one line"));
    }
    Ok(())
}

/// `0-5,8,10-12`: the indices (ascending) as Slurm's `--array` ranges.
pub fn ranges(indices: &[usize]) -> String {
    let mut parts: Vec<String> = Vec::new();
    let mut k = 0;
    while k < indices.len() {
        let start = indices[k];
        let mut end = start;
        while k + 1 < indices.len() && indices[k + 1] == end + 1 {
            k += 1;
            end = indices[k];
        }
        parts.push(if end > start { format!("{start}-{end}") } else { start.to_string() });
        k += 1;
    }
    parts.join(",")
}

/// Quotes a path for the shell (single quotes, a quote inside written `'\''`).
fn quote(path: &Path) -> String {
    format!("'{}'", path.display().to_string().replace('\'', "'\\''"))
}

/// What [`emit`] wrote.
#[derive(Clone, Debug)]
pub struct Script {
    /// `DIR/sweep.sbatch`.
    pub path: PathBuf,
    /// The `--array` value.
    pub array: String,
    /// The tasks in the array.
    pub tasks: usize,
}

/// Writes `out/sweep.sbatch` for the tasks `todo` (ascending, not empty). `exe`, `sweep`
/// and `out` must be absolute. `options` are the resources; `retry_failed` is passed on to
/// every task.
pub fn emit(
    exe: &Path,
    sweep: &Path,
    out: &Path,
    todo: &[usize],
    options: &SlurmOptions,
    retry_failed: bool,
) -> Result<Script, SweepError> {
    let text_path = out.display().to_string();
    if text_path.chars().any(|c| c.is_whitespace() || c == '%') {
        return Err(SweepError::Invalid {
            source: "--out".into(),
            key: text_path,
            problem:
                "holds a space or a %, which an #SBATCH --output path cannot carry; choose another output directory"
                    .into(),
        });
    }
    let logs = out.join("slurm");
    std::fs::create_dir_all(&logs).map_err(crate::run::rundir::at(&logs))?;
    let mut array = ranges(todo);
    if let Some(k) = options.throttle {
        array += &format!("%{k}");
    }
    let name: String = out
        .file_name()
        .map(|n| {
            n.to_string_lossy()
                .chars()
                .map(|c| if c.is_ascii_alphanumeric() || "-_.".contains(c) { c } else { '_' })
                .collect()
        })
        .unwrap_or_default();
    let mut lines = vec![
        "#!/bin/bash".to_string(),
        "# A collide sweep as a Slurm job array: array task K runs task K of the sweep into".to_string(),
        "# tasks/K (zero-padded) beside this file. Submit: sbatch sweep.sbatch. Collect at any time:".to_string(),
        format!("#   {} sweep {} --out {} --collect", quote(exe), quote(sweep), quote(out)),
        format!("#SBATCH --job-name=collide-sweep-{name}"),
        format!("#SBATCH --array={array}"),
        "#SBATCH --ntasks=1".to_string(),
        "#SBATCH --cpus-per-task=1".to_string(),
        format!("#SBATCH --output={}/%A_%a.out", logs.display()),
    ];
    for (flag, value) in [
        ("time", &options.time),
        ("mem", &options.mem),
        ("partition", &options.partition),
        ("account", &options.account),
    ] {
        if let Some(value) = value {
            lines.push(format!("#SBATCH --{flag}={value}"));
        }
    }
    for option in &options.options {
        lines.push(format!("#SBATCH {option}"));
    }
    lines.push(String::new());
    lines.push(format!(
        "exec {} sweep {} --out {} --task \"$SLURM_ARRAY_TASK_ID\"{}",
        quote(exe),
        quote(sweep),
        quote(out),
        if retry_failed { " --retry-failed" } else { "" }
    ));
    let path = out.join("sweep.sbatch");
    write_atomic(&path, (lines.join("\n") + "\n").as_bytes())?;
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        let _ = std::fs::set_permissions(&path, std::fs::Permissions::from_mode(0o755));
    }
    Ok(Script { path, array, tasks: todo.len() })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn array_ranges_join_runs_of_consecutive_tasks() {
        assert_eq!(ranges(&[0, 1, 2, 3, 4, 5]), "0-5");
        assert_eq!(ranges(&[0, 2, 3, 4, 7, 9, 10]), "0,2-4,7,9-10");
        assert_eq!(ranges(&[6]), "6");
        assert_eq!(ranges(&[]), "");
    }

    #[test]
    fn an_option_must_be_one_printable_line() {
        assert!(check_option("time", "01:00:00").is_ok());
        assert!(check_option("time", "").is_err());
        assert!(check_option("options", "--qos=x\n#SBATCH --array=0-99999").is_err());
    }

    #[test]
    fn paths_are_quoted_for_the_shell() {
        assert_eq!(quote(Path::new("/a/it's")), "'/a/it'\\''s'");
    }
}
