//! The bad-input suite: one row per case in `tests/product/bad_input/cases.toml` — the input (a
//! configuration or an edit of the base one, a checkpoint edit, command-line arguments,
//! JSON lines, a prepared output directory), the exit status expected, words the error must
//! contain, and the files that may exist in the output directory afterwards.
//!
//! Every row also asserts what holds for all bad input: no panic or backtrace, no hang (a
//! row is killed after 60 s and fails), an error of one short line when the status is 2,
//! strict JSON on stdout for the JSON-lines rows, and nothing written beyond the files the
//! row allows.

use crate::common::{BASE, strict_json};
use collide::run::{Checkpoint, Saved};
use serde::Deserialize;
use std::collections::BTreeSet;
use std::io::{Read, Write};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::OnceLock;
use std::time::{Duration, Instant};

#[derive(Deserialize)]
struct Cases {
    case: Vec<Case>,
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields, default)]
struct Case {
    /// What the row is about.
    name: String,
    /// The arguments; `{config}`, `{out}`, `{checkpoint}`, `{dir}` are replaced.
    args: Vec<String>,
    /// A whole configuration file.
    config: Option<String>,
    /// Edits of the base configuration: `[from, to]`, each of which must apply.
    edit: Vec<[String; 2]>,
    /// Bytes of the configuration file, as a list of numbers (for invalid UTF-8).
    config_bytes: Option<Vec<u8>>,
    /// A value that repeats to make a long configuration value: `[placeholder, char, n]`.
    long: Option<(String, String, usize)>,
    /// Edits of the base checkpoint: `[JSON pointer, JSON value]` (a key missing from its
    /// object is added).
    checkpoint_edit: Vec<[String; 2]>,
    /// Entries removed from the base checkpoint (JSON pointers into arrays or objects).
    checkpoint_remove: Vec<String>,
    /// Seal the edited checkpoint again (a fresh digest), so that its state is judged.
    reseal: bool,
    /// The checkpoint file's whole text instead.
    checkpoint_text: Option<String>,
    /// Standard input.
    stdin: Option<String>,
    /// Standard input as bytes.
    stdin_bytes: Option<Vec<u8>>,
    /// A long line of standard input: `[char, n]`.
    stdin_long: Option<(String, usize)>,
    /// How the output directory is prepared.
    setup: Vec<String>,
    /// The exit status.
    exit: i32,
    /// Words the error stream must contain.
    stderr: Vec<String>,
    /// Words standard output must contain.
    stdout: Vec<String>,
    /// Lines standard output must have.
    stdout_lines: Option<usize>,
    /// Every line of standard output must be strict JSON.
    json_out: bool,
    /// The files that may be in the output directory afterwards (hidden ones included);
    /// absent: none (the directory need not exist).
    files: Vec<String>,
    /// Files that must be there.
    require: Vec<String>,
    /// Skip when running as root (who can write anywhere).
    not_root: bool,
}

/// The binary the rows run: this build's, or another build named by
/// `COLLIDE_BAD_INPUT_BIN` (to see which rows an older build fails).
fn binary() -> String {
    std::env::var("COLLIDE_BAD_INPUT_BIN").unwrap_or_else(|_| env!("CARGO_BIN_EXE_collide").to_string())
}

fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("bad-input").join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// A finished run of the base configuration, interrupted after 10 000 production collisions
/// (its checkpoint is mid-run and its trajectory has frames): the directory.
fn template() -> &'static Path {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        let dir = scratch("template");
        std::fs::write(dir.join("base.toml"), BASE).unwrap();
        let out = dir.join("run");
        let status = Command::new(env!("CARGO_BIN_EXE_collide"))
            .args(["run", dir.join("base.toml").to_str().unwrap(), "--out", out.to_str().unwrap()])
            .args(["--interrupt-after", "10000"])
            .status()
            .unwrap();
        assert_eq!(status.code(), Some(130), "the template run is interrupted");
        out
    })
}

fn copy_dir(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for entry in std::fs::read_dir(from).unwrap() {
        let entry = entry.unwrap();
        std::fs::copy(entry.path(), to.join(entry.file_name())).unwrap();
    }
}

fn pointer_parent<'a>(root: &'a mut serde_json::Value, pointer: &str) -> (&'a mut serde_json::Value, String) {
    let (parent, last) = pointer.rsplit_once('/').expect("a JSON pointer");
    (root.pointer_mut(parent).unwrap_or_else(|| panic!("no {parent} in the checkpoint")), last.to_string())
}

/// The checkpoint of the row, written into `dir`.
fn checkpoint_for(case: &Case, dir: &Path) -> PathBuf {
    let path = dir.join("checkpoint.json");
    if let Some(text) = &case.checkpoint_text {
        std::fs::write(&path, text).unwrap();
        return path;
    }
    let text = std::fs::read_to_string(template().join("checkpoint.json")).unwrap();
    let mut value: serde_json::Value = serde_json::from_str(&text).unwrap();
    // `@latest` in a pointer: a particle last updated at the clock (so that a new velocity
    // leaves it where it is).
    let clock = value["run"]["state"]["time"].clone();
    let latest = value["run"]["state"]["particles"]
        .as_array()
        .unwrap()
        .iter()
        .position(|p| p["time"] == clock)
        .expect("the last collision's partners are at the clock");
    for [pointer, new] in &case.checkpoint_edit {
        let pointer = &pointer.replace("@latest", &latest.to_string());
        let new: serde_json::Value = serde_json::from_str(new).unwrap_or_else(|e| panic!("{}: {new}: {e}", case.name));
        match value.pointer_mut(pointer) {
            Some(old) => *old = new,
            // A key the writer leaves out (a default): added to its object.
            None => match pointer_parent(&mut value, pointer) {
                (serde_json::Value::Object(map), key) => drop(map.insert(key, new)),
                _ => panic!("{}: no {pointer}", case.name),
            },
        }
    }
    for pointer in &case.checkpoint_remove {
        let (parent, key) = pointer_parent(&mut value, pointer);
        match parent {
            serde_json::Value::Array(items) => {
                items.remove(key.parse::<usize>().unwrap());
            }
            serde_json::Value::Object(map) => {
                map.remove(&key);
            }
            _ => panic!("{}: {pointer} is not in an array or object", case.name),
        }
    }
    let out = if case.reseal {
        let saved: Saved<2> = serde_json::from_value(value["run"].clone())
            .unwrap_or_else(|e| panic!("{}: the edit does not make a state: {e}", case.name));
        Checkpoint::seal(saved).to_json()
    } else {
        serde_json::to_string(&value).unwrap()
    };
    std::fs::write(&path, out).unwrap();
    path
}

fn is_root() -> bool {
    // Whoever can write into a directory without write permission.
    let dir = scratch("root-probe");
    let ro = dir.join("ro");
    std::fs::create_dir(&ro).unwrap();
    use std::os::unix::fs::PermissionsExt;
    std::fs::set_permissions(&ro, std::fs::Permissions::from_mode(0o555)).unwrap();
    let root = std::fs::write(ro.join("x"), b"").is_ok();
    std::fs::set_permissions(&ro, std::fs::Permissions::from_mode(0o755)).unwrap();
    root
}

/// Runs one row; returns what is wrong with it, if anything.
fn check(case: &Case, root: bool) -> Result<(), String> {
    let slug: String = case.name.chars().map(|c| if c.is_ascii_alphanumeric() { c } else { '-' }).collect();
    let dir = scratch(&slug);
    let out = dir.join("out");
    let config = dir.join("config.toml");
    let mut text = case.config.clone().unwrap_or_else(|| BASE.to_string());
    for [from, to] in &case.edit {
        if !text.contains(from.as_str()) {
            return Err(format!("the edit '{from}' does not apply"));
        }
        text = text.replacen(from.as_str(), to, 1);
    }
    if let Some((placeholder, c, n)) = &case.long {
        text = text.replace(placeholder.as_str(), &c.repeat(*n));
    }
    match &case.config_bytes {
        Some(bytes) => std::fs::write(&config, bytes).unwrap(),
        None => std::fs::write(&config, &text).unwrap(),
    }
    let needs_checkpoint = case.args.iter().any(|a| a.contains("{checkpoint}"));
    let mut checkpoint = if needs_checkpoint { checkpoint_for(case, &dir) } else { PathBuf::new() };
    let victim = dir.join("victim");
    std::fs::write(&victim, b"not collide's").unwrap();
    let mut lock = None;
    for step in &case.setup {
        match step.split_once(':').map_or((step.as_str(), ""), |(a, b)| (a, b)) {
            ("earlier-run", _) => copy_dir(template(), &out),
            ("file-at-out", _) => std::fs::write(&out, b"a file").unwrap(),
            ("mkdir", _) => std::fs::create_dir_all(&out).unwrap(),
            ("symlink", name) => {
                std::fs::create_dir_all(&out).unwrap();
                std::os::unix::fs::symlink(&victim, out.join(name)).unwrap();
            }
            ("read-only", _) => {
                std::fs::create_dir_all(&out).unwrap();
                use std::os::unix::fs::PermissionsExt;
                std::fs::set_permissions(&out, std::fs::Permissions::from_mode(0o555)).unwrap();
            }
            ("locked", _) => {
                std::fs::create_dir_all(&out).unwrap();
                let file = std::fs::File::create(out.join(".collide.lock")).unwrap();
                file.lock().unwrap();
                lock = Some(file);
            }
            ("checkpoint-in-out", _) => {
                copy_dir(template(), &out);
                let edited = checkpoint_for(case, &out);
                checkpoint = edited;
            }
            ("cut-trajectory", _) => {
                let path = out.join("trajectory.xyz");
                let len = std::fs::metadata(&path).unwrap().len();
                std::fs::OpenOptions::new().write(true).open(&path).unwrap().set_len(len / 3).unwrap();
            }
            (other, _) => panic!("{}: unknown setup step {other}", case.name),
        }
    }
    if case.not_root && root {
        return Ok(());
    }
    let args: Vec<String> = case
        .args
        .iter()
        .map(|a| {
            a.replace("{config}", config.to_str().unwrap())
                .replace("{out}", out.to_str().unwrap())
                .replace("{checkpoint}", checkpoint.to_str().unwrap())
                .replace("{dir}", dir.to_str().unwrap())
        })
        .collect();
    let mut child = Command::new(binary())
        .args(&args)
        .current_dir(&dir)
        .env_remove("RUST_BACKTRACE")
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut input = case.stdin.clone().map(String::into_bytes).or(case.stdin_bytes.clone()).unwrap_or_default();
    if let Some((c, n)) = &case.stdin_long {
        input.extend(c.repeat(*n).into_bytes());
        input.extend(b"\n{\"id\": 9, \"a\": 1, \"b\": 0, \"c\": -1}\n");
    }
    let mut stdin = child.stdin.take().unwrap();
    let feeder = std::thread::spawn(move || {
        let _ = stdin.write_all(&input);
    });
    // Both streams are drained while the child runs, so that a flood of output is seen as a
    // flood, not as a child blocked on a full pipe.
    let drain = |mut pipe: Box<dyn std::io::Read + Send>| {
        std::thread::spawn(move || {
            let mut bytes = Vec::new();
            let _ = pipe.read_to_end(&mut bytes);
            bytes
        })
    };
    let out_reader = drain(Box::new(child.stdout.take().unwrap()));
    let err_reader = drain(Box::new(child.stderr.take().unwrap()));
    let started = Instant::now();
    let status = loop {
        if let Some(status) = child.try_wait().unwrap() {
            break status;
        }
        if started.elapsed() > Duration::from_secs(60) {
            child.kill().unwrap();
            let _ = child.wait();
            return Err("still running after 60 s: a hang".into());
        }
        std::thread::sleep(Duration::from_millis(5));
    };
    feeder.join().unwrap();
    drop(lock);
    let stderr = String::from_utf8_lossy(&err_reader.join().unwrap()).into_owned();
    let stdout = String::from_utf8_lossy(&out_reader.join().unwrap()).into_owned();
    let code = status.code();
    if code != Some(case.exit) {
        return Err(format!("exit {code:?}, expected {}; stderr: {stderr}", case.exit));
    }
    if stderr.contains("panicked") || stderr.contains("backtrace") {
        return Err(format!("a panic: {stderr}"));
    }
    if stderr.len() > 2000 {
        return Err(format!("{} bytes of error", stderr.len()));
    }
    // collide's own errors are one line; the argument parser's add a usage line and a hint.
    let lines = stderr.trim().lines().count();
    if case.exit == 2 && !(lines == 1 || (stderr.starts_with("error: ") && lines <= 8)) {
        return Err(format!("the error is not one short line: {stderr}"));
    }
    for word in &case.stderr {
        if !stderr.contains(word.as_str()) {
            return Err(format!("'{word}' not in the error: {stderr}"));
        }
    }
    for word in &case.stdout {
        if !stdout.contains(word.as_str()) {
            return Err(format!("'{word}' not in the output: {stdout}"));
        }
    }
    if let Some(n) = case.stdout_lines
        && stdout.lines().count() != n
    {
        return Err(format!("{} lines of output, expected {n}: {stdout}", stdout.lines().count()));
    }
    if case.json_out
        && let Some(bad) = stdout.lines().find(|l| !strict_json(l))
    {
        return Err(format!("not strict JSON: {bad}"));
    }
    if std::fs::read(&victim).unwrap() != b"not collide's" {
        return Err("a file outside the run was written through a link".into());
    }
    if out.is_dir() {
        use std::os::unix::fs::PermissionsExt;
        let _ = std::fs::set_permissions(&out, std::fs::Permissions::from_mode(0o755));
        let found: BTreeSet<String> =
            std::fs::read_dir(&out).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
        let allowed: BTreeSet<String> = case.files.iter().cloned().collect();
        let extra: Vec<&String> = found.difference(&allowed).collect();
        if !extra.is_empty() {
            return Err(format!("files not allowed in the output directory: {extra:?}"));
        }
        for f in &case.require {
            if !found.contains(f) {
                return Err(format!("{f} is missing from the output directory ({found:?})"));
            }
        }
    } else if !case.require.is_empty() {
        return Err("no output directory".into());
    }
    Ok(())
}

#[test]
fn every_bad_input_gets_a_clear_error() {
    let text =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/product/bad_input/cases.toml"))
            .unwrap();
    let cases: Cases = toml::from_str(&text).unwrap();
    assert!(cases.case.len() >= 80, "{} rows", cases.case.len());
    let names: BTreeSet<&str> = cases.case.iter().map(|c| c.name.as_str()).collect();
    assert_eq!(names.len(), cases.case.len(), "row names are unique");
    let root = is_root();
    let failures: Vec<String> =
        cases.case.iter().filter_map(|case| check(case, root).err().map(|e| format!("{}: {e}", case.name))).collect();
    if std::env::var_os("COLLIDE_BAD_INPUT_BIN").is_some() {
        eprintln!("{} of {} rows fail:\n{}", failures.len(), cases.case.len(), failures.join("\n"));
    }
    assert!(failures.is_empty(), "{} of {} rows fail:\n{}", failures.len(), cases.case.len(), failures.join("\n"));
}
