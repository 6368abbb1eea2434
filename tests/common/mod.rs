//! What the tests of the command line and of bad input share: the small run they start
//! from, and what strict JSON is.
#![allow(dead_code)]

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
