//! `collide run` as a user meets it: outputs and their formats, bad input, resume.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn collide(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_collide")).args(args).output().expect("the binary runs")
}

fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

const SMALL: &str = r#"seed = 3
[box]
packing_fraction = 0.4
boundary = ["periodic", "wall"]
[[species]]
count = 60
radius = 0.5
mass = 1.0
[[species]]
count = 40
radius = 0.3
mass = 0.5
[init]
placement = "square"
velocities = "fixed-speed"
kT = 2.0
[equilibration]
collisions = 5000
[run]
collisions = 30000
sample_interval = 0.5
[output]
trajectory_every = 4
checkpoint_every = 10000
"#;

fn json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

#[test]
fn run_writes_summary_timeseries_trajectory_and_checkpoint() {
    let dir = scratch("run-outputs");
    let config = dir.join("small.toml");
    std::fs::write(&config, SMALL).unwrap();
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
    assert_eq!(s["collisions"], 30000);
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
        lines[1].starts_with("Lattice=\"") && lines[1].contains("Properties=species:S:1:pos:R:3:radius:R:1:type:I:1")
    );
    assert!(lines[1].contains("pbc=\"T F F\""));
    let atom: Vec<&str> = lines[2].split(' ').collect();
    assert_eq!((atom[0], atom[3], atom.len()), ("X", "0.0", 6));
    let frames = xyz.lines().filter(|l| *l == "100").count() as u64;
    assert_eq!(frames, s["samples"].as_u64().unwrap() / 4);
    assert!(out.join("checkpoint.json").exists());
    assert!(std::fs::read_dir(&out).unwrap().all(|e| !e.unwrap().file_name().to_string_lossy().ends_with(".tmp")));
}

#[test]
fn resume_from_a_checkpoint_reproduces_the_run() {
    let dir = scratch("run-resume");
    let config = dir.join("small.toml");
    std::fs::write(&config, SMALL).unwrap();
    let (a, b) = (dir.join("a"), dir.join("b"));
    assert!(collide(&["run", config.to_str().unwrap(), "--out", a.to_str().unwrap()]).status.success());
    // checkpoint.json holds the state at 20 000 production collisions (the last one before the end).
    let ck = a.join("checkpoint.json");
    let result = collide(&["run", "--resume", ck.to_str().unwrap(), "--out", b.to_str().unwrap()]);
    assert!(result.status.success(), "{}", String::from_utf8_lossy(&result.stderr));
    let (mut sa, mut sb) = (json(&a.join("summary.json")), json(&b.join("summary.json")));
    for s in [&mut sa, &mut sb] {
        let m = s.as_object_mut().unwrap();
        m.remove("wall_time_s");
        m.remove("collisions_per_second");
    }
    assert_eq!(sa, sb);
    assert_eq!(std::fs::read(a.join("timeseries.csv")).unwrap(), std::fs::read(b.join("timeseries.csv")).unwrap());
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
        ("placement = \"square\"", "placement = \"random\"", &["random placement gave up"]),
        ("placement = \"square\"", "placement = \"hexagonal\"", &["hexagonal"]),
        ("kT = 2.0", "kT = -1.0", &["init.kT = -1"]),
        ("[run]", "[run", &["TOML parse error"]),
    ];
    for (k, (from, to, expect)) in cases.iter().enumerate() {
        let mut text = SMALL.replace(from, to);
        if *from == "placement = \"square\"" && to.contains("random") {
            text = text.replace("packing_fraction = 0.4", "packing_fraction = 0.7");
        }
        assert_ne!(text, SMALL);
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
