//! `collide run` as a user meets it: outputs and their formats, bad input, resume.

use crate::common::{BASE, collide, scratch};
use std::path::{Path, PathBuf};
use std::process::Command;

fn json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

#[test]
fn run_writes_summary_timeseries_trajectory_and_checkpoint() {
    let dir = scratch("run-outputs");
    let config = dir.join("small.toml");
    std::fs::write(&config, BASE).unwrap();
    let out = dir.join("out");
    let result = collide(&["run", config.to_str().unwrap(), "--out", out.to_str().unwrap()]);
    assert!(result.status.success(), "{}", String::from_utf8_lossy(&result.stderr));

    let s = json(&out.join("summary.json"));
    for key in [
        "n_particles",
        "packing_fraction",
        "seed",
        "collisions",
        "events",
        "sim_time",
        "wall_time_s",
        "collisions_per_second",
        "kT",
        "pressure_virial",
        "pressure_virial_error",
        "wall_pressures",
        "energy_relative_drift",
        "max_overlap",
        "config",
        "collide_version",
    ] {
        assert!(s.get(key).is_some(), "summary.json lacks {key}");
    }
    assert_eq!(s["n_particles"], 100);
    assert_eq!(s["collisions"], 20000);
    assert_eq!(s["wall_pressures"].as_array().unwrap().len(), 2, "walls only along y");
    assert!((s["kT"].as_f64().unwrap() - 2.0).abs() < 1e-12);

    let csv = std::fs::read_to_string(out.join("timeseries.csv")).unwrap();
    let mut lines = csv.lines();
    assert_eq!(
        lines.next().unwrap(),
        "t,kinetic_energy,kT,collisions,pressure_virial,pressure_wall_y_lower,pressure_wall_y_upper"
    );
    let rows: Vec<Vec<f64>> = lines.map(|l| l.split(',').map(|x| x.parse().unwrap()).collect()).collect();
    assert_eq!(rows.len() as u64, s["samples"].as_u64().unwrap());
    assert!(rows.windows(2).all(|w| w[1][0] > w[0][0] && w[1][3] >= w[0][3]), "time and collisions increase");

    // Extended XYZ: N, a comment line with Lattice and Properties, N atom lines with z = 0.
    let xyz = std::fs::read_to_string(out.join("trajectory.xyz")).unwrap();
    let lines: Vec<&str> = xyz.lines().collect();
    assert_eq!(lines[0], "100");
    assert!(
        lines[1].starts_with("Lattice=\"")
            && lines[1].contains("Properties=species:S:1:pos:R:3:radius:R:1:species_index:I:1"),
        "{}",
        lines[1]
    );
    assert!(lines[1].contains("pbc=\"T F F\""));
    // Each species its own chemical symbol (OVITO's particle type, ASE's symbols), its index
    // in the last column.
    let atoms: Vec<Vec<&str>> = lines[2..102].iter().map(|l| l.split(' ').collect()).collect();
    assert!(atoms.iter().all(|a| a.len() == 6 && a[3] == "0.0"));
    assert!(atoms.iter().all(|a| (a[0], a[5]) == ("H", "0") || (a[0], a[5]) == ("He", "1")), "{:?}", atoms[0]);
    assert_eq!(atoms.iter().filter(|a| a[0] == "He").count(), 40);
    let frames = xyz.lines().filter(|l| *l == "100").count() as u64;
    assert_eq!(frames, s["samples"].as_u64().unwrap() / 4);
    assert!(out.join("checkpoint.json").exists());
    assert!(std::fs::read_dir(&out).unwrap().all(|e| !e.unwrap().file_name().to_string_lossy().ends_with(".tmp")));
}

/// summary.json without the two wall-clock fields.
fn reproducible(path: &Path) -> serde_json::Value {
    let mut s = json(path);
    let m = s.as_object_mut().unwrap();
    m.remove("wall_time_s");
    m.remove("collisions_per_second");
    s
}

/// The files of a run that must be the same, byte for byte, however it was interrupted.
fn same_results(a: &Path, b: &Path) {
    assert_eq!(reproducible(&a.join("summary.json")), reproducible(&b.join("summary.json")));
    for file in ["timeseries.csv", "trajectory.xyz"] {
        let (x, y) = (std::fs::read(a.join(file)).unwrap(), std::fs::read(b.join(file)).unwrap());
        assert!(x == y, "{file} differs: {} and {} bytes", x.len(), y.len());
    }
}

fn no_temporary_files(dir: &Path) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let name = entry.unwrap().file_name().to_string_lossy().into_owned();
        assert!(!name.ends_with(".tmp"), "{name} left in {}", dir.display());
    }
}

/// A run interrupted at a known point (as SIGINT would stop it) saves a checkpoint and a
/// summary marked interrupted, with the trajectory flushed; resumed in its own directory,
/// or copied elsewhere, it ends with the files of the run never interrupted — the
/// trajectory neither cut nor doubled, every event count the same — and its speed counts
/// the wall-clock time of both processes.
#[test]
fn an_interrupted_run_resumes_to_the_files_of_an_uninterrupted_one() {
    let dir = scratch("run-resume");
    let config = dir.join("small.toml");
    std::fs::write(&config, BASE).unwrap();
    let (whole, part, elsewhere) = (dir.join("whole"), dir.join("part"), dir.join("elsewhere"));
    assert!(collide(&["run", config.to_str().unwrap(), "--out", whole.to_str().unwrap()]).status.success());
    let stopped =
        collide(&["run", config.to_str().unwrap(), "--out", part.to_str().unwrap(), "--interrupt-after", "12345"]);
    assert_eq!(stopped.status.code(), Some(130), "{}", String::from_utf8_lossy(&stopped.stderr));
    assert!(String::from_utf8_lossy(&stopped.stderr).contains("collide run --resume"));
    let s = json(&part.join("summary.json"));
    assert_eq!((s["status"].as_str(), s["collisions"].as_u64()), (Some("interrupted"), Some(12345)));
    no_temporary_files(&part);
    let xyz = std::fs::read_to_string(part.join("trajectory.xyz")).unwrap();
    assert_eq!(xyz.lines().filter(|l| *l == "100").count() as u64, s["samples"].as_u64().unwrap() / 4);
    let first_wall = s["wall_time_s"].as_f64().unwrap();

    // Elsewhere: the frames before the checkpoint are copied.
    let ck = part.join("checkpoint.json");
    let moved = collide(&["run", "--resume", ck.to_str().unwrap(), "--out", elsewhere.to_str().unwrap()]);
    assert!(moved.status.success(), "{}", String::from_utf8_lossy(&moved.stderr));
    same_results(&whole, &elsewhere);
    // In place: the run continues in its own directory.
    let resumed = collide(&["run", "--resume", ck.to_str().unwrap(), "--out", part.to_str().unwrap()]);
    assert!(resumed.status.success(), "{}", String::from_utf8_lossy(&resumed.stderr));
    same_results(&whole, &part);
    assert_eq!(json(&part.join("summary.json"))["events_by_kind"], json(&whole.join("summary.json"))["events_by_kind"]);
    let s = json(&part.join("summary.json"));
    let (wall, rate) = (s["wall_time_s"].as_f64().unwrap(), s["collisions_per_second"].as_f64().unwrap());
    assert!(wall > first_wall, "the wall-clock time of both processes: {wall} after {first_wall}");
    assert!((rate * wall / 20000.0 - 1.0).abs() < 1e-12, "{rate} collisions/s over {wall} s");
    assert!(s.get("status").is_none(), "complete");
    no_temporary_files(&part);
}

/// Spheres through the command line: `dimension = 3` runs the 3D engine from an fcc
/// crystal with walls along z; summary.json says `"dimension": 3` and the box has three
/// edges; the trajectory has real z; interrupted and resumed (the checkpoint names its
/// dimension), it ends with the files of the run never interrupted.
#[test]
fn spheres_run_and_resume_from_the_command_line() {
    let dir = scratch("run-spheres");
    let config = dir.join("spheres.toml");
    let text = BASE
        .replace("seed = 3", "dimension = 3\nseed = 3")
        .replace(r#"boundary = ["periodic", "wall"]"#, r#"boundary = ["periodic", "periodic", "wall"]"#)
        .replace(r#"placement = "square""#, r#"placement = "fcc""#);
    std::fs::write(&config, text).unwrap();
    let (whole, part) = (dir.join("whole"), dir.join("part"));
    let run = collide(&["run", config.to_str().unwrap(), "--out", whole.to_str().unwrap()]);
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    let s = json(&whole.join("summary.json"));
    assert_eq!(s["dimension"], 3);
    assert_eq!(s["box_lengths"].as_array().unwrap().len(), 3);
    assert_eq!(s["config"]["dimension"], 3);
    let axes: Vec<u64> = s["wall_pressures"].as_array().unwrap().iter().map(|w| w["axis"].as_u64().unwrap()).collect();
    assert_eq!(axes, [2, 2]);
    assert!(s["compressibility"].as_f64().unwrap() > 1.0);
    assert!(s["max_overlap"]["fraction"].as_f64().unwrap() <= 1e-12);
    let xyz = std::fs::read_to_string(whole.join("trajectory.xyz")).unwrap();
    let z: Vec<f64> =
        xyz.lines().skip(2).take(100).map(|l| l.split_whitespace().nth(3).unwrap().parse().unwrap()).collect();
    assert!(z.iter().any(|&z| z != z.round()) && z.iter().any(|&z| z > 1.0), "real z: {z:?}");
    let stopped =
        collide(&["run", config.to_str().unwrap(), "--out", part.to_str().unwrap(), "--interrupt-after", "7000"]);
    assert_eq!(stopped.status.code(), Some(130), "{}", String::from_utf8_lossy(&stopped.stderr));
    let ck = part.join("checkpoint.json");
    let resumed = collide(&["run", "--resume", ck.to_str().unwrap(), "--out", part.to_str().unwrap()]);
    assert!(resumed.status.success(), "{}", String::from_utf8_lossy(&resumed.stderr));
    same_results(&whole, &part);
}

/// The process ids of signals sent in the tests below come from `Child::id`.
fn signal(child: &std::process::Child, signal: i32) {
    // SAFETY: kill(2) on a child of this process, which has not been waited for.
    assert_eq!(unsafe { libc::kill(child.id() as i32, signal) }, 0);
}

/// A configuration that runs for a few seconds: long enough to be stopped mid-run.
fn long_config(dir: &Path) -> PathBuf {
    let config = dir.join("long.toml");
    let text = BASE
        .replace("collisions = 20000", "collisions = 3000000")
        .replace("checkpoint_every = 5000", "checkpoint_every = 200000")
        .replace("trajectory_every = 4", "trajectory_every = 200");
    std::fs::write(&config, text).unwrap();
    config
}

/// SIGINT and SIGTERM stop a run at its next event: exit status 130, a checkpoint and a
/// summary marked interrupted, no temporary file; the checkpoint continues it to the
/// results of the run never stopped.
#[test]
fn sigint_and_sigterm_stop_a_run_that_resumes_bit_identically() {
    let dir = scratch("run-signals");
    let config = long_config(&dir);
    let whole = dir.join("whole");
    assert!(collide(&["run", config.to_str().unwrap(), "--out", whole.to_str().unwrap()]).status.success());
    for (name, sig) in [("int", libc::SIGINT), ("term", libc::SIGTERM)] {
        let out = dir.join(name);
        let child = Command::new(env!("CARGO_BIN_EXE_collide"))
            .args(["run", config.to_str().unwrap(), "--out", out.to_str().unwrap()])
            .stdout(std::process::Stdio::null())
            .stderr(std::process::Stdio::piped())
            .spawn()
            .unwrap();
        // Until production has started (the summary of an interruption during the
        // equilibration says so, and resumes as well, but this test is about production).
        std::thread::sleep(std::time::Duration::from_millis(400));
        signal(&child, sig);
        let output = child.wait_with_output().unwrap();
        let s = json(&out.join("summary.json"));
        // 3·10⁶ collisions of 100 disks take seconds; the signal comes after 0.4 s.
        assert_eq!(output.status.code(), Some(130), "{}", String::from_utf8_lossy(&output.stderr));
        assert_eq!(s["status"], "interrupted");
        no_temporary_files(&out);
        let ck = out.join("checkpoint.json");
        assert!(collide(&["run", "--resume", ck.to_str().unwrap(), "--out", out.to_str().unwrap()]).status.success());
        same_results(&whole, &out);
    }
}

/// A run killed without warning (SIGKILL) leaves its last periodic checkpoint and a
/// trajectory that goes past it, often into the middle of a frame: resuming cuts the
/// trajectory back to the checkpoint and continues, to the files of the run never killed.
#[test]
fn a_killed_run_resumes_from_its_last_checkpoint() {
    let dir = scratch("run-killed");
    let config = dir.join("killed.toml");
    // A frame every sample (about 5 kB), so that the trajectory outgrows its write buffer
    // between two checkpoints.
    let text = BASE
        .replace("collisions = 20000", "collisions = 600000")
        .replace("checkpoint_every = 5000", "checkpoint_every = 100000")
        .replace("trajectory_every = 4", "trajectory_every = 1");
    std::fs::write(&config, text).unwrap();
    let whole = dir.join("whole");
    assert!(collide(&["run", config.to_str().unwrap(), "--out", whole.to_str().unwrap()]).status.success());
    let checkpoint_bytes = |ck: &Path| -> Option<u64> {
        let text = std::fs::read_to_string(ck).ok()?;
        serde_json::from_str::<serde_json::Value>(&text).ok()?["run"]["trajectory_bytes"].as_u64()
    };
    let mut cut = false;
    for attempt in 0..5 {
        let killed = dir.join(format!("killed{attempt}"));
        let mut child = Command::new(env!("CARGO_BIN_EXE_collide"))
            .args(["run", config.to_str().unwrap(), "--out", killed.to_str().unwrap()])
            .stdout(std::process::Stdio::null())
            .stderr(std::process::Stdio::null())
            .spawn()
            .unwrap();
        let (ck, xyz) = (killed.join("checkpoint.json"), killed.join("trajectory.xyz"));
        let started = std::time::Instant::now();
        // Until the trajectory is past the checkpoint's length.
        while started.elapsed() < std::time::Duration::from_secs(60) {
            let len = std::fs::metadata(&xyz).map_or(0, |m| m.len());
            if checkpoint_bytes(&ck).is_some_and(|b| len > b) {
                break;
            }
            std::thread::sleep(std::time::Duration::from_millis(2));
        }
        signal(&child, libc::SIGKILL);
        assert!(!child.wait().unwrap().success(), "killed mid-run (6·10⁵ collisions with frames take a second)");
        let (len, bytes) = (std::fs::metadata(&xyz).unwrap().len(), checkpoint_bytes(&ck).unwrap());
        let resumed = collide(&["run", "--resume", ck.to_str().unwrap(), "--out", killed.to_str().unwrap()]);
        assert!(resumed.status.success(), "{}", String::from_utf8_lossy(&resumed.stderr));
        same_results(&whole, &killed);
        if len > bytes {
            cut = true;
            break;
        }
    }
    assert!(cut, "no attempt left a trajectory longer than its checkpoint");
}

/// Each bad input: exit status 2, one line naming the file, field and value, no panic, and
/// no output directory.
#[test]
fn bad_input_gets_a_clear_error_and_writes_nothing() {
    let dir = scratch("run-bad");
    let cases: [(&str, &str, &[&str]); 9] = [
        ("seed = 3", "seed = 3\ncolour = 1", &["unknown field", "colour"]),
        ("radius = 0.3", "radius = 0.0", &["species[1].radius = 0", "positive"]),
        ("mass = 0.5", "mass = nan", &["species[1].mass = NaN"]),
        ("packing_fraction = 0.4", "size = [0.8, 30.0]", &["box edge 0 = 0.8 is too short", "at least 2"]),
        ("packing_fraction = 0.4", "packing_fraction = 0.84", &["overlap by", "particles"]),
        ("placement = \"square\"", "placement = \"random\"", &["random placement found no room", "start at or below"]),
        ("placement = \"square\"", "placement = \"hexagonal\"", &["hexagonal"]),
        ("kT = 2.0", "kT = -1.0", &["init.kT = -1"]),
        ("[run]", "[run", &["TOML parse error"]),
    ];
    for (k, (from, to, expect)) in cases.iter().enumerate() {
        let mut text = BASE.replace(from, to);
        if *from == "placement = \"square\"" && to.contains("random") {
            text = text.replace("packing_fraction = 0.4", "packing_fraction = 0.7");
        }
        assert_ne!(text, BASE);
        let config = dir.join(format!("bad{k}.toml"));
        std::fs::write(&config, &text).unwrap();
        let out = dir.join(format!("out{k}"));
        let result = collide(&["run", config.to_str().unwrap(), "--out", out.to_str().unwrap()]);
        let err = String::from_utf8_lossy(&result.stderr);
        assert_eq!(result.status.code(), Some(2), "case {k}: {err}");
        assert_eq!(err.trim().lines().count(), 1, "case {k}: one line, got {err}");
        assert!(err.contains(&format!("bad{k}.toml")), "case {k} names the file: {err}");
        for e in *expect {
            assert!(err.contains(e), "case {k}: '{e}' not in {err}");
        }
        assert!(!err.contains("panicked"), "case {k}: {err}");
        assert!(!out.exists(), "case {k}: nothing may be written");
    }
    let missing = collide(&["run", "/nonexistent/config.toml", "--out", dir.join("x").to_str().unwrap()]);
    assert_eq!(missing.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&missing.stderr).contains("/nonexistent/config.toml: cannot read the file"));
}
