//! The experiments: their quick versions pass, their plots hold what they should, and every
//! check is able to fail when fed data that is physically wrong.

use collide::lab::maxwell_boltzmann::{self, Metrics, checks, metrics, reduced};
use collide::lab::{ExperimentResult, Options};
use rand::rngs::Xoshiro256PlusPlus;
use rand::{RngExt, SeedableRng};
use rand_distr::{Distribution, Normal};
use std::path::Path;

fn out(name: &str) -> std::path::PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(name);
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

fn assert_svgs(result: &ExperimentResult, dir: &Path) {
    assert!(!result.plots.is_empty());
    for plot in &result.plots {
        let svg = std::fs::read_to_string(dir.join(&result.name).join(plot)).unwrap();
        assert!(svg.starts_with("<svg"), "{plot} is not SVG");
        // Axis labels with units (or an explicit 'dimensionless'), a legend, and data marks.
        assert!(svg.matches("<text").count() >= 10, "{plot}: too little text");
        assert!(svg.contains('(') && svg.contains(')'), "{plot}: axis labels carry units in parentheses");
        let marks = svg.matches("<circle").count() + svg.matches("<polyline").count() + svg.matches("<line").count();
        assert!(marks >= 10, "{plot}: no data drawn");
    }
}

#[test]
fn maxwell_boltzmann_quick_passes_and_writes_its_outputs() {
    let dir = out("lab-mb");
    let options = Options { quick: true, seed: 1, out: dir.clone() };
    let result = maxwell_boltzmann::run(&options).unwrap();
    result.write(&dir).unwrap();
    assert!(result.passed(), "{}", collide::lab::check::table("maxwell_boltzmann", &result.checks));
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("maxwell_boltzmann/result.json")).unwrap()).unwrap();
    for key in ["parameters", "data", "checks", "plots"] {
        assert!(json.get(key).is_some(), "result.json lacks {key}");
    }
    for c in json["checks"].as_array().unwrap() {
        for key in ["measured", "error", "expected", "tolerance", "why", "pass"] {
            assert!(c.get(key).is_some(), "a check lacks {key}");
        }
    }
    assert_svgs(&result, &dir);
}

fn gaussian_velocities(n: usize, seed: u64) -> Vec<[f64; 2]> {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    let normal = Normal::new(0.0, 1.0).unwrap();
    (0..n).map(|_| [normal.sample(&mut rng), normal.sample(&mut rng)]).collect()
}

fn verdicts(v: &[[f64; 2]], kt: f64) -> Vec<bool> {
    let equal = vec![[2f64.sqrt(), 0.0]; v.len()];
    verdicts_from(&equal, v, kt)
}

fn verdicts_from(first: &[[f64; 2]], v: &[[f64; 2]], kt: f64) -> Vec<bool> {
    let first = {
        let (u, c) = reduced(first, 1.0);
        metrics(0.0, &u, &c)
    };
    let (u, c) = reduced(v, kt);
    let last: Metrics = metrics(1.0, &u, &c);
    checks(&first, &last, v.len()).iter().map(|c| c.pass).collect()
}

/// A true Maxwellian sample passes every check (seeded); non-Maxwellian data fail the checks
/// that are sensitive to them.
#[test]
fn maxwell_boltzmann_checks_can_fail() {
    let n = 20000;
    let good = gaussian_velocities(n, 5);
    assert!(verdicts(&good, 1.0).iter().all(|&p| p), "{:?}", verdicts(&good, 1.0));

    // A mis-set temperature (kT 10 % off): the KS check fails.
    assert!(!verdicts(&good, 1.1)[0]);
    // Uniform components (kurtosis 1.8): KS, kurtosis, a₂ and H all fail.
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(6);
    let s = 3f64.sqrt();
    let uniform: Vec<[f64; 2]> = (0..n).map(|_| [rng.random_range(-s..s), rng.random_range(-s..s)]).collect();
    let v = verdicts(&uniform, 1.0);
    assert!(!v[0] && !v[1] && !v[2] && !v[3], "{v:?}");
    // From a Maxwellian to equal speeds (H increased): every check fails.
    let equal: Vec<[f64; 2]> = (0..n)
        .map(|k| {
            let a = k as f64 * 2.399963;
            [2f64.sqrt() * a.cos(), 2f64.sqrt() * a.sin()]
        })
        .collect();
    let v = verdicts_from(&good, &equal, 1.0);
    assert!(v.iter().all(|&p| !p), "{v:?}");
}
