//! The output directory of a run, and how files get into it.
//!
//! # Policy
//!
//! * **One run per directory.** A directory that holds any of a run's files
//!   ([`RUN_FILES`]) is refused for a new run, naming the files, unless the caller asks to
//!   replace them (`--force`), which removes exactly those files first. Other files are
//!   never touched. Resuming from a checkpoint *in its own directory* continues that run
//!   there and is always allowed.
//! * **One writer at a time.** A run holds an exclusive lock on `DIR/.collide.lock` while it
//!   writes (released by the system when the process ends, however it ends); a second run
//!   into the same directory is refused. Taking the lock is also the first write, so a
//!   directory that cannot be written is found before the simulation, not after.
//! * **Whole files only.** `summary.json`, `timeseries.csv` and `checkpoint.json` are
//!   written to a new temporary file in the directory — created exclusively, so a file or
//!   a symbolic link planted under its name is never followed or overwritten — flushed to
//!   the disk, and renamed into place: a reader sees the old file or the new one.
//! * **The trajectory grows.** `trajectory.xyz` is written frame by frame and flushed at
//!   every checkpoint; each checkpoint records its length. A run killed without warning may
//!   leave part of a frame after the last checkpoint; resuming cuts the file back to the
//!   checkpoint's length and continues it, so that no frame is lost or written twice.

use std::fs::{self, File, OpenOptions};
use std::io::{self, Read, Seek, Write};
use std::path::{Path, PathBuf};

/// The files of a run (the observables' files among them: `rdf.csv`, `msd.csv`, `vacf.csv`,
/// `sk.csv`, `bond_order.csv`, `g6.csv`).
pub const RUN_FILES: [&str; 10] = [
    "summary.json",
    "timeseries.csv",
    "trajectory.xyz",
    "checkpoint.json",
    "rdf.csv",
    "msd.csv",
    "vacf.csv",
    "sk.csv",
    "bond_order.csv",
    "g6.csv",
];

/// The lock file.
pub const LOCK: &str = ".collide.lock";

/// A failed output operation, with the path involved.
#[non_exhaustive]
#[derive(Debug)]
pub enum OutputError {
    /// An operation on a file or directory failed.
    Io {
        /// The file or directory.
        path: PathBuf,
        /// What went wrong.
        error: io::Error,
    },
    /// The directory holds another run's files.
    Occupied {
        /// The directory.
        dir: PathBuf,
        /// The files found.
        files: Vec<String>,
    },
    /// Another process is writing into the directory.
    Locked {
        /// The directory.
        dir: PathBuf,
    },
    /// The trajectory of the run being resumed does not hold the frames its checkpoint
    /// says were written.
    Trajectory {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        problem: String,
    },
}

impl std::fmt::Display for OutputError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            OutputError::Io { path, error } => write!(f, "{}: {error}", path.display()),
            OutputError::Occupied { dir, files } => write!(
                f,
                "{} holds the results of an earlier run ({}): one directory holds one run; choose another --out, or pass --force to replace them",
                dir.display(),
                files.join(", ")
            ),
            OutputError::Locked { dir } => write!(
                f,
                "{}: another collide run is writing into this directory (it holds {LOCK}); wait for it or choose another --out",
                dir.display()
            ),
            OutputError::Trajectory { path, problem } => write!(
                f,
                "{}: {problem}; pass --force to start the trajectory afresh at the checkpoint",
                path.display()
            ),
        }
    }
}

impl std::error::Error for OutputError {}

/// An [`OutputError::Io`] at `path`.
pub fn at(path: &Path) -> impl FnOnce(io::Error) -> OutputError + '_ {
    move |error| OutputError::Io { path: path.to_path_buf(), error }
}

/// Options that refuse to follow a symbolic link in the last component.
fn no_follow(options: &mut OpenOptions) -> &mut OpenOptions {
    #[cfg(unix)]
    {
        use std::os::unix::fs::OpenOptionsExt;
        options.custom_flags(libc::O_NOFOLLOW);
    }
    options
}

/// Writes `contents` to `path` atomically: to a new temporary file in the same directory
/// (created exclusively, never through a link), flushed to the disk, then renamed over
/// `path`.
pub fn write_atomic(path: &Path, contents: &[u8]) -> Result<(), OutputError> {
    write_atomic_with(path, |w| w.write_all(contents))
}

/// [`write_atomic`] with the contents written by `fill` into a buffered writer, so that a
/// large file (a checkpoint) need not be held in memory as one string.
pub fn write_atomic_with(path: &Path, fill: impl FnOnce(&mut dyn Write) -> io::Result<()>) -> Result<(), OutputError> {
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    let mut attempt = 0u32;
    let (tmp, file) = loop {
        let tmp = path.with_file_name(format!(".{name}.{}.{attempt}.tmp", std::process::id()));
        match OpenOptions::new().write(true).create_new(true).open(&tmp) {
            Ok(file) => break (tmp, file),
            Err(e) if e.kind() == io::ErrorKind::AlreadyExists && attempt < 1000 => attempt += 1,
            Err(e) => return Err(at(&tmp)(e)),
        }
    };
    let mut out = io::BufWriter::with_capacity(1 << 16, file);
    let written = fill(&mut out)
        .and_then(|()| out.into_inner().map_err(io::IntoInnerError::into_error))
        .and_then(|file| file.sync_all());
    if let Err(e) = written.map_err(at(&tmp)).and_then(|()| fs::rename(&tmp, path).map_err(at(path))) {
        let _ = fs::remove_file(&tmp);
        return Err(e);
    }
    Ok(())
}

/// An output directory, locked for this process.
#[derive(Debug)]
pub struct RunDir {
    path: PathBuf,
    _lock: File,
}

/// Whether `path` is the same directory as `other` (both exist).
fn same_dir(path: &Path, other: &Path) -> bool {
    match (fs::canonicalize(path), fs::canonicalize(other)) {
        (Ok(a), Ok(b)) => a == b,
        _ => false,
    }
}

impl RunDir {
    /// Opens (creating it if needed) and locks `path` for a run. `continuing` is the
    /// directory of the checkpoint being resumed, if any: resuming there continues that
    /// run. Otherwise a run's files already there are refused, or with `force` removed.
    pub fn open(path: &Path, force: bool, continuing: Option<&Path>) -> Result<RunDir, OutputError> {
        if let Ok(meta) = fs::metadata(path)
            && !meta.is_dir()
        {
            return Err(OutputError::Io {
                path: path.to_path_buf(),
                error: io::Error::new(io::ErrorKind::AlreadyExists, "exists and is not a directory"),
            });
        }
        fs::create_dir_all(path).map_err(at(path))?;
        let lock_path = path.join(LOCK);
        let lock = no_follow(OpenOptions::new().read(true).write(true).create(true).truncate(false))
            .open(&lock_path)
            .map_err(at(&lock_path))?;
        match lock.try_lock() {
            Ok(()) => {}
            Err(fs::TryLockError::WouldBlock) => return Err(OutputError::Locked { dir: path.to_path_buf() }),
            Err(fs::TryLockError::Error(e)) => return Err(at(&lock_path)(e)),
        }
        let dir = RunDir { path: path.to_path_buf(), _lock: lock };
        if continuing.is_some_and(|c| same_dir(path, c)) {
            return Ok(dir);
        }
        let present: Vec<String> =
            RUN_FILES.iter().filter(|f| fs::symlink_metadata(path.join(f)).is_ok()).map(|f| f.to_string()).collect();
        if !present.is_empty() {
            if !force {
                return Err(OutputError::Occupied { dir: path.to_path_buf(), files: present });
            }
            for f in &present {
                let p = path.join(f);
                fs::remove_file(&p).map_err(at(&p))?;
            }
        }
        Ok(dir)
    }

    /// The directory.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The path of one of its files.
    pub fn file(&self, name: &str) -> PathBuf {
        self.path.join(name)
    }

    /// Writes one whole file ([`write_atomic`]).
    pub fn write(&self, name: &str, contents: &[u8]) -> Result<(), OutputError> {
        write_atomic(&self.file(name), contents)
    }

    /// Writes one whole file from a writer ([`write_atomic_with`]).
    pub fn write_with(
        &self,
        name: &str,
        fill: impl FnOnce(&mut dyn Write) -> io::Result<()>,
    ) -> Result<(), OutputError> {
        write_atomic_with(&self.file(name), fill)
    }
}

/// `trajectory.xyz` while a run writes it: frames appended, the length kept.
#[derive(Debug)]
pub struct Trajectory {
    out: io::BufWriter<File>,
    bytes: u64,
    path: PathBuf,
}

/// Whether the first `bytes` of `file` are exactly `frames` frames of `n` particles: as many
/// lines as those frames have, the last one ended.
fn holds_frames(file: &mut File, bytes: u64, frames: u64, n: u64) -> io::Result<bool> {
    if file.metadata()?.len() < bytes {
        return Ok(false);
    }
    file.rewind()?;
    let mut reader = io::BufReader::with_capacity(1 << 20, file.take(bytes));
    let (mut lines, mut last) = (0u64, b'\n');
    let mut buf = [0u8; 1 << 16];
    loop {
        let k = reader.read(&mut buf)?;
        if k == 0 {
            break;
        }
        lines += buf[..k].iter().filter(|&&b| b == b'\n').count() as u64;
        last = buf[k - 1];
    }
    Ok(last == b'\n' && Some(lines) == frames.checked_mul(n + 2))
}

impl Trajectory {
    /// A new, empty trajectory in `dir` (created exclusively: the directory was cleared).
    pub fn create(dir: &RunDir) -> Result<Trajectory, OutputError> {
        let path = dir.file("trajectory.xyz");
        let file = OpenOptions::new().write(true).create_new(true).open(&path).map_err(at(&path))?;
        Ok(Trajectory { out: io::BufWriter::with_capacity(1 << 20, file), bytes: 0, path })
    }

    /// The trajectory of a resumed run, holding the `frames` frames of `n` particles written
    /// before its checkpoint (`bytes` long): cut back to them in the run's own directory;
    /// copied from `source` into another one. A source without a trajectory gives a new
    /// one, with a warning; one that does not hold those frames is an error unless
    /// `force` (then, too, a new one).
    pub fn resume(
        dir: &RunDir,
        source: &Path,
        (bytes, frames, n): (u64, u64, u64),
        force: bool,
        warnings: &mut Vec<String>,
    ) -> Result<Trajectory, OutputError> {
        let path = dir.file("trajectory.xyz");
        let source_path = source.join("trajectory.xyz");
        let in_place = same_dir(dir.path(), source);
        let opened = no_follow(OpenOptions::new().read(true).write(in_place)).open(&source_path);
        let mut from = match opened {
            Ok(file) => file,
            Err(e) if e.kind() == io::ErrorKind::NotFound => {
                if bytes > 0 {
                    warnings.push(format!(
                        "{} is not there: the {frames} frames before the checkpoint are missing, the trajectory starts at the checkpoint",
                        source_path.display()
                    ));
                }
                return Trajectory::create(dir);
            }
            Err(e) => return Err(at(&source_path)(e)),
        };
        if !holds_frames(&mut from, bytes, frames, n).map_err(at(&source_path))? {
            let problem =
                format!("it does not begin with the {frames} frames ({bytes} bytes) written before the checkpoint");
            if !force {
                return Err(OutputError::Trajectory { path: source_path, problem });
            }
            warnings
                .push(format!("{}: {problem}; the trajectory starts afresh at the checkpoint", source_path.display()));
            drop(from);
            if in_place {
                fs::remove_file(&path).map_err(at(&path))?;
            }
            return Trajectory::create(dir);
        }
        if in_place {
            from.set_len(bytes).map_err(at(&path))?;
            from.seek(io::SeekFrom::End(0)).map_err(at(&path))?;
            return Ok(Trajectory { out: io::BufWriter::with_capacity(1 << 20, from), bytes, path });
        }
        let mut to = Trajectory::create(dir)?;
        from.rewind().map_err(at(&source_path))?;
        let copied = io::copy(&mut (&mut from).take(bytes), &mut to.out).map_err(at(&path))?;
        to.bytes = copied;
        Ok(to)
    }

    /// Appends one frame.
    pub fn append(&mut self, frame: &str) -> Result<(), OutputError> {
        self.out.write_all(frame.as_bytes()).map_err(at(&self.path))?;
        self.bytes += frame.len() as u64;
        Ok(())
    }

    /// Flushes what was appended to the disk and returns the length.
    pub fn flush(&mut self) -> Result<u64, OutputError> {
        self.out.flush().map_err(at(&self.path))?;
        self.out.get_ref().sync_data().map_err(at(&self.path))?;
        Ok(self.bytes)
    }
}
