//! The sweep file: expansion, and every refusal naming its key.

use super::*;

const BASE: &str = r#"
[base]
seed = 1
[base.box]
packing_fraction = 0.3
boundary = "periodic"
[[base.species]]
count = 100
radius = 0.5
mass = 1.0
[base.run]
collisions = 1000
"#;

fn sweep(rest: &str) -> Result<Sweep, SweepError> {
    Sweep::parse(&format!("{BASE}{rest}"), "s.toml", Path::new("."))
}

fn error(rest: &str) -> String {
    match sweep(rest).and_then(|s| s.tasks().map(|_| s)) {
        Ok(_) => panic!("accepted: {rest}"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn tasks_are_the_product_of_the_factors_first_slowest_and_zip_groups_vary_together() {
    let s = sweep(
        r#"
        [vary]
        "box.packing_fraction" = [0.2, 0.4]
        seed = [1, 2, 3]
        [[zip]]
        "species.0.count" = [100, 400]
        "run.collisions" = [5000, 20000]
        "#,
    )
    .unwrap();
    assert_eq!(s.keys(), ["box.packing_fraction", "seed", "species.0.count", "run.collisions"]);
    let tasks = s.tasks().unwrap();
    assert_eq!(tasks.len(), 2 * 3 * 2);
    // Task 7 = (η index 1, seed index 0, zip index 1): 7 = 1·6 + 0·2 + 1.
    let t = &tasks[7];
    assert_eq!(t.label(), "box.packing_fraction = 0.4, seed = 1, species.0.count = 400, run.collisions = 20000");
    assert_eq!(t.config.sim_box.packing_fraction, Some(0.4));
    assert_eq!(t.config.seed, 1);
    assert_eq!(t.config.species[0].count, 400);
    assert_eq!(t.config.run.collisions, Some(20000));
    // Every combination once.
    let mut labels: Vec<String> = tasks.iter().map(Task::label).collect();
    labels.sort();
    labels.dedup();
    assert_eq!(labels.len(), 12);
    assert_eq!(tasks[11].dir_name(12), "0011");
    assert_eq!(tasks[11].dir_name(123_456), "000011");
}

#[test]
fn nothing_varied_is_one_task_the_base() {
    let tasks = sweep("").unwrap().tasks().unwrap();
    assert_eq!(tasks.len(), 1);
    assert!(tasks[0].parameters.is_empty());
    assert_eq!(tasks[0].config.seed, 1);
}

#[test]
fn a_task_configuration_reads_back_to_itself_and_its_digest_follows_its_values() {
    let s = sweep(
        r#"
        [vary]
        "box.packing_fraction" = [0.1, 0.30000000000000004]
        seed = [7]
        "#,
    )
    .unwrap();
    let tasks = s.tasks().unwrap();
    for t in &tasks {
        assert_eq!(Config::parse(&t.text, "back").unwrap(), t.config, "{}", t.text);
    }
    // 0.3 and its neighbour double are different runs: different digests.
    assert_ne!(tasks[0].digest, tasks[1].digest);
    assert_eq!(tasks[1].digest, s.task(1).unwrap().digest);
    assert!(tasks[1].digest.starts_with("sha256:") && tasks[1].digest.len() == 7 + 64);
    // Spheres with a compression and an observable read back too.
    let three = Sweep::parse(
        r#"
        [base]
        dimension = 3
        seed = 1
        [base.box]
        packing_fraction = 0.2
        boundary = ["periodic", "periodic", "wall"]
        [[base.species]]
        count = 108
        radius = 0.5
        mass = 1.0
        [base.init]
        placement = "random"
        [base.compress]
        rate = 0.1
        target_packing_fraction = 0.3
        [base.run]
        collisions = 1000
        [base.observe.velocities]
        [vary]
        "compress.target_packing_fraction" = [0.3, 0.35]
        "#,
        "3d.toml",
        Path::new("."),
    )
    .unwrap();
    for t in three.tasks().unwrap() {
        assert_eq!(Config::parse(&t.text, "back").unwrap(), t.config, "{}", t.text);
    }
}

#[test]
fn the_base_may_be_a_file_beside_the_sweep() {
    let dir = std::env::temp_dir().join(format!("collide-sweep-base-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("run.toml"), BASE.replace("[base.", "[").replace("[[base.", "[[").replace("[base]\n", ""))
        .unwrap();
    let path = dir.join("s.toml");
    std::fs::write(&path, "base = \"run.toml\"\n[vary]\nseed = [3, 4]\n").unwrap();
    let tasks = Sweep::load(&path).unwrap().tasks().unwrap();
    assert_eq!(tasks[1].config.seed, 4);
    assert_eq!(tasks[1].config.species[0].count, 100);
    std::fs::write(&path, "base = \"missing.toml\"\n").unwrap();
    let e = Sweep::load(&path).unwrap_err().to_string();
    assert!(e.contains("missing.toml") && e.contains("cannot read"), "{e}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn every_refusal_names_the_file_and_the_key() {
    let cases: &[(&str, &[&str])] = &[
        ("[vary]\nseed = []", &["s.toml", "[vary] \"seed\"", "empty list"]),
        ("[vary]\nseed = 3", &["[vary] \"seed\"", "is an integer", "list"]),
        ("[vary]\nseed = [1]\n[[zip]]\nseed = [2]", &["[[zip]] 1 \"seed\"", "varied twice", "[vary] \"seed\""]),
        ("[vary]\n\"box\" = [1]\n\"box.packing_fraction\" = [0.1]", &["\"box.packing_fraction\"", "overlaps \"box\""]),
        ("[[zip]]\nseed = [1, 2]\n\"run.collisions\" = [10]", &["[[zip]] 1", "\"seed\" has 2 values", "one length"]),
        ("[vary]\n\"species.3.count\" = [10]", &["\"species.3.count\"", "[base] species has 1 entries", "no entry 3"]),
        ("[vary]\n\"species.first.count\" = [10]", &["[base] species is a list", "\"first\""]),
        ("[vary]\n\"seed.x\" = [1]", &["[base] seed is an integer", "holds no \"x\""]),
        ("[vary]\n\"box..size\" = [1]", &["not a dotted key"]),
        ("[varry]\nseed = [1]", &["[varry]", "[base], [vary], [[zip]], [plot] and [slurm]"]),
        ("[vary]\nseed = [1]\n[plot]\nx = \"box.size\"", &["[plot] x", "not a varied key"]),
        ("[plot]\ncolour = \"red\"", &["[plot] colour", "holds x and y"]),
        ("[slurm]\nthrottle = 0", &["[slurm] throttle", "≥ 1"]),
        ("[slurm]\ntime = 3600", &["[slurm] time", "string"]),
        ("[slurm]\noptions = [\"--qos=a\\n#SBATCH --array=0-9\"]", &["[slurm] options", "line break"]),
        ("[slurm]\nnodes = 2", &["[slurm] nodes", "unknown"]),
        // The task's own configuration errors name the task and the key.
        (
            "[vary]\n\"box.packing_fraction\" = [0.2, 1.2]",
            &["s.toml, task 1 (box.packing_fraction = 1.2)", "packing_fraction"],
        ),
        ("[vary]\n\"box.packing_fracton\" = [0.2]", &["task 0", "packing_fracton"]),
        ("[vary]\n\"run.collisions\" = [1e5]", &["task 0 (run.collisions = 100000.0)", "collisions"]),
    ];
    for (rest, needles) in cases {
        let e = error(rest);
        for needle in *needles {
            assert!(e.contains(needle), "{rest:?}: {e:?} lacks {needle:?}");
        }
    }
    let missing = Sweep::parse("[vary]\nseed = [1]", "s.toml", Path::new(".")).unwrap_err().to_string();
    assert!(missing.contains("s.toml: [base]: missing"), "{missing}");
    let syntax = Sweep::parse("[base\nseed = 1", "s.toml", Path::new(".")).unwrap_err().to_string();
    assert!(syntax.contains("s.toml: TOML parse error at line 1"), "{syntax}");
    // 47 lists of two: 2⁴⁷ tasks.
    let huge: String = (0..47).map(|k| format!("\"observe.x{k}\" = [1, 2]\n")).collect();
    let e = error(&format!("[vary]\n{huge}"));
    assert!(e.contains("more than 100000 tasks"), "{e}");
}
