//! What the integration tests share: the small run the command-line and bad-input tests
//! start from, what strict JSON is, and the engine held against the reference.
#![allow(dead_code)]

use collide::engine::{ReferenceSimulation, Simulation};
use collide::run::Summary;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// Runs the collide binary with `args`.
pub fn collide(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_collide")).args(args).output().expect("the binary runs")
}

/// An empty directory of the test's own under the target's scratch space.
pub fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// A small mixture with walls along y, a trajectory and periodic checkpoints, that runs in
/// a fraction of a second; the tests edit it.
pub const BASE: &str = r#"seed = 3
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
collisions = 2000
[run]
collisions = 20000
sample_interval = 0.5
[output]
trajectory_every = 4
checkpoint_every = 5000
"#;

/// Strict JSON: `text` parses, and every number in it is a finite f64.
pub fn strict_json(text: &str) -> bool {
    fn finite(v: &serde_json::Value) -> bool {
        match v {
            serde_json::Value::Number(n) => n.to_string().parse::<f64>().is_ok_and(f64::is_finite),
            serde_json::Value::Array(items) => items.iter().all(finite),
            serde_json::Value::Object(map) => map.values().all(finite),
            _ => true,
        }
    }
    serde_json::from_str::<serde_json::Value>(text).is_ok_and(|v| finite(&v))
}

/// Runs both engines for `n` collisions and requires identical (time bits, i, j); the fast
/// engine's bookkeeping events (neighbourhood updates, samples) are passed over.
pub fn assert_same_collisions<const D: usize>(
    mut fast: Simulation<D>,
    mut slow: ReferenceSimulation<D>,
    n: usize,
    label: &str,
) {
    for k in 0..n {
        let expected = slow.step().expect("a collision");
        let got = loop {
            if let Some((i, j)) = fast.step().expect("an event").collided() {
                break (fast.time(), i, j);
            }
        };
        assert_eq!(
            (got.0.to_bits(), got.1, got.2),
            (expected.0.to_bits(), expected.1, expected.2),
            "{label}, collision {k}: fast {got:?}, reference {expected:?}"
        );
    }
}

/// A summary without its wall-clock fields (the only ones a rerun changes).
pub fn reproducible(summary: Summary) -> Summary {
    Summary { wall_time_s: 0.0, collisions_per_second: 0.0, ..summary }
}
