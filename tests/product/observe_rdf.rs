//! The g(r) observable in runs: its contact value against the pressure route (exact in
//! equilibrium), its file, mixtures, interruption, refusals.

use crate::common::{self, collide, scratch};
use collide::run::{Config, Run};

fn fluid(dimension: usize, n: usize, eta: f64, seed: u64) -> String {
    let (boundary, placement) = if dimension == 3 { ("periodic", "fcc") } else { ("periodic", "triangular") };
    format!(
        "dimension = {dimension}\nseed = {seed}\n[box]\npacking_fraction = {eta}\nboundary = \"{boundary}\"\n\
         [[species]]\ncount = {n}\nradius = 0.5\nmass = 1.0\n[init]\nplacement = \"{placement}\"\n\
         [equilibration]\ncollisions = {}\n[run]\ncollisions = {}\n[observe.rdf]\nr_max = 3.0\nbins = 300\nevery = 0.5\n",
        20 * n,
        400 * n
    )
}

/// `(g(σ⁺) from g(r), its error, g(σ⁺) from Z, its error)` of one run.
fn contact_two_ways<const D: usize>(text: &str) -> (f64, f64, f64, f64) {
    let mut run = Run::<D>::new(Config::parse(text, "fluid").unwrap()).unwrap();
    run.complete(&mut collide::run::Discard).unwrap();
    let s = run.summary();
    let rdf = &s.observables["rdf"];
    let contact = &rdf["contact"][0];
    let (g, g_err) = (contact["g"].as_f64().unwrap(), contact["error"].as_f64().unwrap());
    let factor = 2f64.powi(D as i32 - 1) * s.packing_fraction;
    ((g), g_err, (s.compressibility - 1.0) / factor, s.compressibility_error / factor)
}

/// In equilibrium `Z = 1 + 2^(d−1)·η·g(σ⁺)` exactly: the contact value extrapolated from the
/// histogram agrees with the one from the collision virial of the same run. Tolerance: the
/// 3σ-equivalent of the two errors combined (Student's t for 20 blocks, 3.45), no more; the
/// extrapolation's bias (a quadratic over 0.1σ) is part of what is tested. The check can
/// fail: the contact value of a run at another density lies outside it by many tolerances.
#[test]
fn the_contact_value_of_g_agrees_with_the_pressure_route() {
    let t = collide::lab::stats::three_sigma_factor(20);
    for (label, (g, g_err, p, p_err), other) in [
        (
            "disks η = 0.5",
            contact_two_ways::<2>(&fluid(2, 400, 0.5, 1)),
            contact_two_ways::<2>(&fluid(2, 400, 0.45, 1)),
        ),
        (
            "spheres η = 0.4",
            contact_two_ways::<3>(&fluid(3, 500, 0.4, 2)),
            contact_two_ways::<3>(&fluid(3, 500, 0.35, 2)),
        ),
    ] {
        let tolerance = t * g_err.hypot(p_err);
        eprintln!(
            "{label}: g(σ⁺) = {g:.4} ± {g_err:.4} from g(r), {p:.4} ± {p_err:.4} from Z; tolerance {tolerance:.4}"
        );
        assert!((g - p).abs() <= tolerance, "{label}: g(σ⁺) = {g} ± {g_err} from g(r), {p} ± {p_err} from Z");
        assert!(g_err > 0.0 && g_err < 0.02 * g, "{label}: error {g_err}");
        assert!((other.0 - p).abs() > 3.0 * tolerance, "{label}: a run at another density passes too ({})", other.0);
    }
}

/// `rdf.csv`: r at the bins' centres, g zero inside the core, a column per species pair in a
/// mixture; bit for bit the same after an interruption and a resume; refused options name
/// their key; and no file where it is not asked for.
#[test]
fn the_rdf_file_mixtures_interruption_and_refusals() {
    let dir = scratch("observe-rdf");
    let config = dir.join("mixture.toml");
    // Two species between walls along y (radii 0.5 and 0.3).
    let text = format!("{}\n[observe.rdf]\nr_max = 2.5\nbins = 250\nevery = 0.2\n", common::BASE);
    std::fs::write(&config, &text).unwrap();
    let (whole, part) = (dir.join("whole"), dir.join("part"));
    let run = collide(&["run", config.to_str().unwrap(), "--out", whole.to_str().unwrap()]);
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    let csv = std::fs::read_to_string(whole.join("rdf.csv")).unwrap();
    let mut lines = csv.lines();
    assert_eq!(lines.next(), Some("r,g_0_0,g_0_1,g_1_1"));
    let rows: Vec<Vec<f64>> = lines.map(|l| l.split(',').map(|x| x.parse().unwrap()).collect()).collect();
    assert_eq!(rows.len(), 250);
    for row in &rows {
        let r = row[0];
        // Cores: 1.0 (0–0), 0.8 (0–1), 0.6 (1–1); a bin wholly inside holds no pair.
        for (column, sigma) in [(1, 1.0), (2, 0.8), (3, 0.6)] {
            if r + 0.005 < sigma {
                assert_eq!(row[column], 0.0, "r = {r}: column {column}");
            }
            assert!(row[column].is_finite());
        }
    }
    assert!((rows[0][0] - 0.005).abs() < 1e-12 && (rows[249][0] - 2.495).abs() < 1e-12);
    let s: serde_json::Value = serde_json::from_slice(&std::fs::read(whole.join("summary.json")).unwrap()).unwrap();
    let contact = s["observables"]["rdf"]["contact"].as_array().unwrap();
    assert_eq!(contact.len(), 3);
    assert_eq!(contact[1]["species"], serde_json::json!([0, 1]));
    assert!((contact[1]["sigma"].as_f64().unwrap() - 0.8).abs() < 1e-15);

    // Interrupted and resumed: the same file and summary, to the bit.
    let stopped =
        collide(&["run", config.to_str().unwrap(), "--out", part.to_str().unwrap(), "--interrupt-after", "7000"]);
    assert_eq!(stopped.status.code(), Some(130));
    let ck = part.join("checkpoint.json");
    let resumed = collide(&["run", "--resume", ck.to_str().unwrap(), "--out", part.to_str().unwrap()]);
    assert!(resumed.status.success(), "{}", String::from_utf8_lossy(&resumed.stderr));
    assert_eq!(std::fs::read(part.join("rdf.csv")).unwrap(), std::fs::read(whole.join("rdf.csv")).unwrap());
    let t: serde_json::Value = serde_json::from_slice(&std::fs::read(part.join("summary.json")).unwrap()).unwrap();
    assert_eq!(t["observables"], s["observables"]);

    // Refusals name the key; an unknown key is refused like any.
    for (bad, needle) in [
        ("r_max = -1.0", "observe.rdf.r_max = -1"),
        ("bins = 0", "observe.rdf.bins = 0"),
        ("every = 0.0", "observe.rdf.every = 0"),
        ("colour = 1", "colour"),
    ] {
        let path = dir.join("bad.toml");
        std::fs::write(&path, format!("{}\n[observe.rdf]\n{bad}\n", common::BASE)).unwrap();
        let r = collide(&["run", path.to_str().unwrap(), "--out", dir.join("bad").to_str().unwrap()]);
        assert_eq!(r.status.code(), Some(2));
        assert!(
            String::from_utf8_lossy(&r.stderr).contains(needle),
            "{needle}: {}",
            String::from_utf8_lossy(&r.stderr)
        );
    }
    // Not asked for: no file.
    std::fs::write(&config, common::BASE).unwrap();
    let plain = dir.join("plain");
    assert!(collide(&["run", config.to_str().unwrap(), "--out", plain.to_str().unwrap()]).status.success());
    assert!(!plain.join("rdf.csv").exists());
}
