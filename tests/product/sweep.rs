//! `collide sweep` as a user meets it: a local sweep, its table, reruns that skip what has
//! finished, failures recorded and retried, single tasks, the Slurm script, refusals. (The
//! real Slurm run is `.ci/slurm-sweep`, which CI runs against a one-node cluster.)

use collide::sweep::Sweep;
use collide::sweep::task::{self, Outcome, State};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::sync::atomic::AtomicBool;

fn collide(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_collide")).args(args).env("CI", "true").output().expect("the binary runs")
}

fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn text(o: &Output) -> String {
    format!("{}{}", String::from_utf8_lossy(&o.stdout), String::from_utf8_lossy(&o.stderr))
}

/// Six small tasks: three densities × two seeds.
const SWEEP: &str = r#"
[base]
seed = 1
[base.box]
packing_fraction = 0.3
boundary = "periodic"
[[base.species]]
count = 100
radius = 0.5
mass = 1.0
[base.equilibration]
collisions = 2000
[base.run]
collisions = 20000

[vary]
"box.packing_fraction" = [0.2, 0.4, 0.6]
seed = [1, 2]
"#;

/// A task's summary without the two fields that depend on the machine's speed.
fn physics(dir: &Path) -> serde_json::Value {
    let mut s: serde_json::Value = serde_json::from_slice(&std::fs::read(dir.join("summary.json")).unwrap()).unwrap();
    let o = s.as_object_mut().unwrap();
    o.remove("wall_time_s").unwrap();
    o.remove("collisions_per_second").unwrap();
    s
}

fn rows(out: &Path) -> Vec<Vec<String>> {
    std::fs::read_to_string(out.join("results.csv"))
        .unwrap()
        .lines()
        .map(|l| l.split(',').map(str::to_string).collect())
        .collect()
}

#[test]
fn a_local_sweep_runs_every_task_into_its_directory_and_collects_one_table() {
    let dir = scratch("sweep-local");
    let file = dir.join("sweep.toml");
    std::fs::write(&file, SWEEP).unwrap();
    let (one, two) = (dir.join("one"), dir.join("two"));
    let a = collide(&["sweep", file.to_str().unwrap(), "--out", one.to_str().unwrap(), "--jobs", "1"]);
    assert!(a.status.success(), "{}", text(&a));
    assert!(text(&a).contains("6 tasks: 6 finished, 0 failed"), "{}", text(&a));
    let b = collide(&["sweep", file.to_str().unwrap(), "--out", two.to_str().unwrap(), "--jobs", "2"]);
    assert!(b.status.success(), "{}", text(&b));

    // The same tasks, bit for bit, however many ran at once; each an ordinary run whose
    // config.toml repeats it.
    let sweep = Sweep::load(&file).unwrap();
    let tasks = sweep.tasks().unwrap();
    for t in &tasks {
        let (d1, d2) = (task::dir(&one, t, 6), task::dir(&two, t, 6));
        assert_eq!(physics(&d1), physics(&d2), "task {}", t.index);
        assert_eq!(
            std::fs::read(d1.join("timeseries.csv")).unwrap(),
            std::fs::read(d2.join("timeseries.csv")).unwrap()
        );
        let s = physics(&d1);
        assert_eq!(s["seed"], t.config.seed);
        assert_eq!(s["config"]["box"]["packing_fraction"].as_f64(), t.config.sim_box.packing_fraction);
        let again = dir.join(format!("again-{}", t.index));
        let c =
            collide(&["run", d1.join("config.toml").to_str().unwrap(), "--out", again.to_str().unwrap(), "--quiet"]);
        assert!(c.status.success(), "{}", text(&c));
        assert_eq!(physics(&again), s, "collide run config.toml repeats task {}", t.index);
    }

    // The table: a header, then a row per task in order, varied values, then the summary's.
    let table = rows(&one);
    assert_eq!(table.len(), 7);
    let header = &table[0];
    assert_eq!(header[..4], ["task", "status", "box.packing_fraction", "seed"]);
    assert_eq!(header.iter().filter(|h| *h == "seed").count(), 1, "the summary's seed is the varied one");
    assert_eq!(header.last().unwrap(), "error");
    let col = |name: &str| header.iter().position(|h| h == name).unwrap_or_else(|| panic!("no column {name}"));
    for (k, row) in table[1..].iter().enumerate() {
        let s = physics(&task::dir(&one, &tasks[k], 6));
        assert_eq!(row[col("task")], k.to_string());
        assert_eq!(row[col("status")], "finished");
        assert_eq!(row[col("box.packing_fraction")], ["0.2", "0.4", "0.6"][k / 2]);
        assert_eq!(row[col("seed")], ["1", "2"][k % 2]);
        // Numbers as the summary holds them: read back, the same double.
        for name in ["compressibility", "compressibility_error", "pressure_virial", "collision_rate_per_particle"] {
            assert_eq!(row[col(name)].parse::<f64>().unwrap(), s[name].as_f64().unwrap(), "{name}");
        }
        assert_eq!(row[col("collisions")], "20000");
        assert_eq!(row[col("error")], "");
    }
    let results: serde_json::Value = serde_json::from_slice(&std::fs::read(one.join("results.json")).unwrap()).unwrap();
    assert_eq!(results["tasks"][5]["parameters"]["box.packing_fraction"], 0.6);
    assert_eq!(results["tasks"][5]["dir"], "tasks/0005");
    let svg = std::fs::read_to_string(one.join("results.svg")).unwrap();
    assert!(svg.contains("compressibility against box.packing_fraction") && svg.contains("seed = 2"));
    let manifest: serde_json::Value =
        serde_json::from_slice(&std::fs::read(one.join("manifest.json")).unwrap()).unwrap();
    assert_eq!(manifest["tasks"][3]["digest"].as_str().unwrap(), tasks[3].digest);

    // Rerun: nothing to run, nothing touched.
    let before = std::fs::read(task::dir(&one, &tasks[0], 6).join("summary.json")).unwrap();
    let r = collide(&["sweep", file.to_str().unwrap(), "--out", one.to_str().unwrap()]);
    assert!(r.status.success(), "{}", text(&r));
    assert!(!text(&r).contains("to run"), "{}", text(&r));
    assert_eq!(std::fs::read(task::dir(&one, &tasks[0], 6).join("summary.json")).unwrap(), before);

    // An edited value reruns exactly the tasks it changes (their digests differ).
    std::fs::write(&file, SWEEP.replace("[0.2, 0.4, 0.6]", "[0.2, 0.4, 0.5]")).unwrap();
    let e = collide(&["sweep", file.to_str().unwrap(), "--out", one.to_str().unwrap()]);
    assert!(e.status.success(), "{}", text(&e));
    assert!(text(&e).contains("6 tasks: 4 finished before, 2 to run"), "{}", text(&e));
    assert_eq!(std::fs::read(task::dir(&one, &tasks[0], 6).join("summary.json")).unwrap(), before);
    assert_eq!(physics(&task::dir(&one, &tasks[5], 6))["config"]["box"]["packing_fraction"], 0.5);
}

#[test]
fn a_failed_task_is_recorded_while_the_others_finish_and_retried_when_asked() {
    let dir = scratch("sweep-failed");
    let file = dir.join("sweep.toml");
    // Random placement cannot reach η = 0.6 with equal disks: that task fails at its start.
    let sweep = SWEEP
        .replace(
            "\"box.packing_fraction\" = [0.2, 0.4, 0.6]\nseed = [1, 2]",
            "\"init.placement\" = [\"triangular\", \"random\", \"square\"]",
        )
        .replace("packing_fraction = 0.3", "packing_fraction = 0.6");
    std::fs::write(&file, &sweep).unwrap();
    let out = dir.join("out");
    let a = collide(&["sweep", file.to_str().unwrap(), "--out", out.to_str().unwrap()]);
    assert_eq!(a.status.code(), Some(1), "{}", text(&a));
    assert!(text(&a).contains("3 tasks: 2 finished, 1 failed"), "{}", text(&a));
    assert!(text(&a).contains("task 1 failed: initial state: random placement"), "{}", text(&a));
    assert!(text(&a).contains("no results.svg"), "x takes strings: {}", text(&a));
    let failed: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("tasks/0001/failed.json")).unwrap()).unwrap();
    assert!(failed["error"].as_str().unwrap().contains("random placement"));
    let csv = std::fs::read_to_string(out.join("results.csv")).unwrap();
    let lines: Vec<&str> = csv.lines().collect();
    assert!(
        lines[2].starts_with("1,failed,random,,") && lines[2].ends_with(", which holds these disks up to η ≈ 0.9069\""),
        "{}",
        lines[2]
    );
    assert!(
        lines[2].contains("use placement = \"\"triangular\"\""),
        "quotes doubled inside a quoted cell: {}",
        lines[2]
    );
    assert!(lines[3].starts_with("2,finished,square,"));

    // A rerun leaves the failure alone; --retry-failed runs it again (and it fails again).
    let r = collide(&["sweep", file.to_str().unwrap(), "--out", out.to_str().unwrap()]);
    assert_eq!(r.status.code(), Some(1));
    assert!(!text(&r).contains("to run"), "{}", text(&r));
    let retry = collide(&["sweep", file.to_str().unwrap(), "--out", out.to_str().unwrap(), "--retry-failed"]);
    assert_eq!(retry.status.code(), Some(1));
    assert!(text(&retry).contains("3 tasks: 2 finished before, 1 to run"), "{}", text(&retry));
    // Fixed in the sweep file: the task's configuration changed, so it runs and finishes.
    std::fs::write(&file, sweep.replace("\"random\"", "\"triangular\"")).unwrap();
    let fixed = collide(&["sweep", file.to_str().unwrap(), "--out", out.to_str().unwrap()]);
    assert!(fixed.status.success(), "{}", text(&fixed));
    assert!(!out.join("tasks/0001/failed.json").exists());
}

#[test]
fn single_tasks_collect_and_the_slurm_script() {
    let dir = scratch("sweep-tasks");
    let file = dir.join("sweep.toml");
    std::fs::write(&file, format!("{SWEEP}\n[slurm]\ntime = \"00:10:00\"\nthrottle = 2\n")).unwrap();
    let out = dir.join("out");
    let (f, o) = (file.to_str().unwrap(), out.to_str().unwrap());

    // The script: an array of every task, the resources, one task per element.
    let e = collide(&["sweep", f, "--out", o, "--emit", "slurm", "--mem", "500M"]);
    assert!(e.status.success(), "{}", text(&e));
    let script = std::fs::read_to_string(out.join("sweep.sbatch")).unwrap();
    let exe = std::fs::canonicalize(env!("CARGO_BIN_EXE_collide")).unwrap();
    for line in [
        "#SBATCH --array=0-5%2".to_string(),
        "#SBATCH --time=00:10:00".to_string(),
        "#SBATCH --mem=500M".to_string(),
        format!("#SBATCH --output={}/slurm/%A_%a.out", std::path::absolute(&out).unwrap().display()),
        format!(
            "exec '{}' sweep '{}' --out '{}' --task \"$SLURM_ARRAY_TASK_ID\"",
            exe.display(),
            std::path::absolute(&file).unwrap().display(),
            std::path::absolute(&out).unwrap().display()
        ),
    ] {
        assert!(script.lines().any(|l| l == line), "{line} not in\n{script}");
    }
    assert!(out.join("manifest.json").is_file() && !out.join("tasks/0000").exists(), "emitting runs nothing");

    // A task another process is running (it holds the directory's lock) is refused, its
    // directory untouched; once the lock is gone it runs.
    {
        let busy = out.join("tasks/0000");
        let _held = collide::run::rundir::RunDir::open(&busy, false, Some(&busy)).unwrap();
        std::fs::write(busy.join("summary.json"), "{}").unwrap();
        let refused = collide(&["sweep", f, "--out", o, "--task", "0"]);
        assert_eq!(refused.status.code(), Some(2), "{}", text(&refused));
        assert!(text(&refused).contains("another collide run is writing"), "{}", text(&refused));
        assert_eq!(std::fs::read_to_string(busy.join("summary.json")).unwrap(), "{}", "untouched");
        assert!(!busy.join("failed.json").exists() && !busy.join("task.json").exists());
        std::fs::remove_file(busy.join("summary.json")).unwrap();
    }

    // Two tasks by number, as array elements would run them.
    for k in ["4", "1"] {
        let t = collide(&["sweep", f, "--out", o, "--task", k]);
        assert!(t.status.success(), "{}", text(&t));
        assert!(text(&t).contains(&format!("task {k} (")), "{}", text(&t));
    }
    let again = collide(&["sweep", f, "--out", o, "--task", "4"]);
    assert!(again.status.success() && text(&again).contains("finished before"), "{}", text(&again));
    assert!(!out.join("tasks/0000/summary.json").exists() && !out.join("tasks/0002").exists());
    let beyond = collide(&["sweep", f, "--out", o, "--task", "6"]);
    assert_eq!(beyond.status.code(), Some(2));
    assert!(text(&beyond).contains("makes 6 tasks, numbered 0 to 5"), "{}", text(&beyond));

    // Collect names what is missing, and says so in its exit status.
    let c = collide(&["sweep", f, "--out", o, "--collect"]);
    assert_eq!(c.status.code(), Some(1), "{}", text(&c));
    assert!(text(&c).contains("6 tasks: 2 finished, 0 failed, 0 interrupted, 4 missing"), "{}", text(&c));
    assert!(text(&c).contains("tasks 0, 2, 3, 5"), "{}", text(&c));
    let status: Vec<String> = rows(&out)[1..].iter().map(|r| r[1].clone()).collect();
    assert_eq!(status, ["missing", "finished", "missing", "missing", "finished", "missing"]);

    // Emitted again: only what is left.
    let e2 = collide(&["sweep", f, "--out", o, "--emit", "slurm"]);
    assert!(e2.status.success(), "{}", text(&e2));
    assert!(std::fs::read_to_string(out.join("sweep.sbatch")).unwrap().contains("#SBATCH --array=0,2-3,5%2\n"));

    // The sweep file edited after the manifest was written: an array element refuses.
    std::fs::write(&file, SWEEP.replace("seed = [1, 2]", "seed = [1, 3]")).unwrap();
    let stale = collide(&["sweep", f, "--out", o, "--task", "3"]);
    assert_eq!(stale.status.code(), Some(2), "{}", text(&stale));
    assert!(text(&stale).contains("manifest.json: task 3 has another configuration"), "{}", text(&stale));
}

#[test]
fn an_interrupted_task_continues_from_its_checkpoint_to_the_same_bits() {
    let dir = scratch("sweep-interrupted");
    let sweep = Sweep::parse(SWEEP, "sweep.toml", &dir).unwrap();
    let t = sweep.task(3).unwrap();
    let (whole, parts) = (dir.join("whole"), dir.join("parts"));
    let go = AtomicBool::new(false);
    assert!(matches!(task::run(&t, &whole, false, &go).unwrap(), Outcome::Finished(_)));
    // Stopped at its first event (as SIGTERM at a time limit would stop it later).
    let stopped = AtomicBool::new(true);
    assert_eq!(task::run(&t, &parts, false, &stopped).unwrap(), Outcome::Interrupted);
    assert_eq!(task::state(&parts, &t), State::Interrupted);
    assert!(matches!(task::run(&t, &parts, false, &go).unwrap(), Outcome::Finished(_)));
    assert_eq!(task::state(&parts, &t), State::Finished);
    assert_eq!(physics(&whole), physics(&parts));
    assert_eq!(
        std::fs::read(whole.join("timeseries.csv")).unwrap(),
        std::fs::read(parts.join("timeseries.csv")).unwrap()
    );
    assert_eq!(task::run(&t, &parts, false, &go).unwrap(), Outcome::AlreadyFinished);
}

#[test]
fn a_bad_sweep_file_is_refused_naming_the_key_and_nothing_is_written() {
    let dir = scratch("sweep-bad");
    let file = dir.join("sweep.toml");
    let out = dir.join("out");
    for (bad, needle) in [
        (SWEEP.replace("[0.2, 0.4, 0.6]", "[0.2, 0.95]"), "sweep.toml, task 2 (box.packing_fraction = 0.95, seed = 1)"),
        (SWEEP.replace("seed = [1, 2]", "seed = []"), "[vary] \"seed\": an empty list"),
        (SWEEP.replace("\"box.packing_fraction\"", "\"box.packing_fracton\""), "packing_fracton"),
    ] {
        std::fs::write(&file, &bad).unwrap();
        let r = collide(&["sweep", file.to_str().unwrap(), "--out", out.to_str().unwrap()]);
        assert_eq!(r.status.code(), Some(2), "{}", text(&r));
        assert!(text(&r).contains(needle), "{needle}: {}", text(&r));
        assert!(text(&r).contains("sweep.toml"), "{}", text(&r));
        assert!(!out.exists(), "nothing written for a refused sweep");
    }
    let missing = collide(&["sweep", dir.join("nope.toml").to_str().unwrap()]);
    assert_eq!(missing.status.code(), Some(2));
    assert!(text(&missing).contains("nope.toml: cannot read the file"), "{}", text(&missing));
}
