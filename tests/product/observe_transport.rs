//! The MSD and VACF observables in runs: the two routes to diffusion agreeing, their files,
//! mixtures, interruption, refusals and the memory they ask for.

use crate::common::{self, collide, scratch};
use collide::observe::Observable;
use collide::run::{Config, Discard, Limits, Run};

fn fluid(dimension: usize, n: usize, eta: f64, seed: u64) -> String {
    let placement = if dimension == 3 { "fcc" } else { "triangular" };
    format!(
        "dimension = {dimension}\nseed = {seed}\n[box]\npacking_fraction = {eta}\nboundary = \"periodic\"\n\
         [[species]]\ncount = {n}\nradius = 0.5\nmass = 1.0\n[init]\nplacement = \"{placement}\"\n\
         [equilibration]\ncollisions = {}\n[run]\ncollisions = {}\n\
         [observe.msd]\nevery = 0.25\nmax_lag = 60.0\n[observe.vacf]\nevery = 0.25\nmax_lag = 60.0\n",
        20 * n,
        1000 * n
    )
}

/// `(D from the MSD's slope over [τ/4, τ], its error, the mean of D_GK(s) over [τ/4, τ] by
/// the trapezoid rule over the lags, the error of D_GK(τ))` of one run.
fn diffusion_two_ways<const D: usize>(text: &str) -> (f64, f64, f64, f64) {
    let mut run = Run::<D>::new(Config::parse(text, "fluid").unwrap()).unwrap();
    run.complete(&mut Discard).unwrap();
    let (Observable::Msd(msd), Observable::Vacf(vacf)) = (&run.observables[0], &run.observables[1]) else {
        panic!("msd, then vacf")
    };
    let d = msd.diffusion().remove(0);
    let lags = vacf.correlator.lags();
    let within: Vec<_> = lags.iter().filter(|l| l.tau >= d.lag / 4.0 && l.tau <= d.lag).collect();
    assert!(within.len() >= 9, "{} lags", within.len());
    let integral: f64 =
        within.windows(2).map(|w| 0.5 * (w[0].values[0][1].0 + w[1].values[0][1].0) * (w[1].tau - w[0].tau)).sum();
    let mean = integral / (0.75 * d.lag * D as f64);
    let last = within.last().unwrap().values[0][1].1 / D as f64;
    (d.d, d.error, mean, last)
}

/// `⟨Δr²(τ)⟩ = 2∫₀^τ ⟨v(0)·Δr(s)⟩ ds` in equilibrium (time-reversal symmetry), so the MSD's
/// slope over [τ/4, τ] is the mean of the Green–Kubo running integral `D_GK(s)` over those
/// lags: two estimators, from two observers, of one number. Tolerance: the 3σ-equivalent
/// (Student's t for 32 blocks, about 3.45 as for 20: the larger, 3.45, is used) of the two
/// jackknife errors combined, plus the trapezoid rule's error over lags a quarter-octave
/// apart (below 10⁻³ relative for the smooth, slowly varying `D_GK`; 0.002·D allowed). The
/// check can fail: the MSD of a run at another density (η + 0.1) lies outside it.
#[test]
fn the_msd_and_the_green_kubo_integral_give_one_diffusion_coefficient() {
    let t = collide::lab::stats::three_sigma_factor(20);
    for (label, (d, d_err, gk, gk_err), other) in [
        (
            "disks η = 0.3",
            diffusion_two_ways::<2>(&fluid(2, 400, 0.3, 1)),
            diffusion_two_ways::<2>(&fluid(2, 400, 0.4, 1)),
        ),
        (
            "spheres η = 0.3",
            diffusion_two_ways::<3>(&fluid(3, 500, 0.3, 2)),
            diffusion_two_ways::<3>(&fluid(3, 500, 0.4, 2)),
        ),
    ] {
        let tolerance = t * d_err.hypot(gk_err) + 0.002 * gk;
        eprintln!(
            "{label}: D = {d:.4} ± {d_err:.4} from the MSD, {gk:.4} ± {gk_err:.4} from the VACF; tolerance {tolerance:.4}"
        );
        assert!((d - gk).abs() <= tolerance, "{label}: {d} ± {d_err} vs {gk} ± {gk_err}");
        assert!(d_err > 0.0 && d_err < 0.05 * d, "{label}: error {d_err}");
        assert!((other.0 - gk).abs() > tolerance, "{label}: a run at another density passes too ({})", other.0);
    }
}

/// `msd.csv` and `vacf.csv`: lags rising from 0, MSD 0 and VACF ⟨v²⟩ = d·kT/m (to rounding:
/// the kinetic energy is conserved) at lag 0, a column set per species in a mixture; bit for
/// bit the same after an interruption and a resume; refused options name their key; a run
/// whose stored samples would not fit in memory is refused before it starts.
#[test]
fn the_msd_and_vacf_files_mixtures_interruption_and_refusals() {
    let dir = scratch("observe-transport");
    let config = dir.join("mixture.toml");
    let text = format!("{}\n[observe.msd]\nevery = 0.3\n[observe.vacf]\nevery = 0.2\nmax_lag = 10.0\n", common::BASE);
    std::fs::write(&config, &text).unwrap();
    let (whole, part) = (dir.join("whole"), dir.join("part"));
    let run = collide(&["run", config.to_str().unwrap(), "--out", whole.to_str().unwrap()]);
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    let read = |file: &str| -> (String, Vec<Vec<f64>>) {
        let csv = std::fs::read_to_string(whole.join(file)).unwrap();
        let mut lines = csv.lines();
        let header = lines.next().unwrap().to_string();
        (header, lines.map(|l| l.split(',').map(|x| x.parse().unwrap()).collect()).collect())
    };
    let (header, msd) = read("msd.csv");
    assert_eq!(header, "t,origins,msd_0,msd_0_error,alpha2_0,msd_1,msd_1_error,alpha2_1");
    assert_eq!((msd[0][0], msd[0][2], msd[0][5]), (0.0, 0.0, 0.0));
    assert!(msd.windows(2).all(|w| w[1][0] > w[0][0] && w[1][1] <= w[0][1]));
    assert!(msd.iter().skip(1).all(|r| r[2] > 0.0 && r[5] > 0.0));
    let (header, vacf) = read("vacf.csv");
    assert_eq!(
        header,
        "t,origins,vacf_0,vacf_0_error,integral_0,integral_0_error,vacf_1,vacf_1_error,integral_1,integral_1_error"
    );
    let last = vacf.last().unwrap()[0];
    assert!((10.0..20.0).contains(&last), "longest lag {last}");
    let s: serde_json::Value = serde_json::from_slice(&std::fs::read(whole.join("summary.json")).unwrap()).unwrap();
    let start = &s["observables"]["vacf"]["start"];
    let c0: f64 = (0..2).map(|k| start[k]["c0"].as_f64().unwrap()).sum::<f64>();
    // Both species together hold d·kT per particle on average (mass-weighted here: kT/m each).
    assert!(c0 > 0.0 && vacf[0][2] == start[0]["c0"].as_f64().unwrap());
    assert_eq!(s["observables"]["msd"]["diffusion"].as_array().unwrap().len(), 2);

    // Interrupted and resumed: the same files and summary, to the bit.
    let stopped =
        collide(&["run", config.to_str().unwrap(), "--out", part.to_str().unwrap(), "--interrupt-after", "7000"]);
    assert_eq!(stopped.status.code(), Some(130));
    let ck = part.join("checkpoint.json");
    let resumed = collide(&["run", "--resume", ck.to_str().unwrap(), "--out", part.to_str().unwrap()]);
    assert!(resumed.status.success(), "{}", String::from_utf8_lossy(&resumed.stderr));
    for file in ["msd.csv", "vacf.csv"] {
        assert_eq!(std::fs::read(part.join(file)).unwrap(), std::fs::read(whole.join(file)).unwrap(), "{file}");
    }
    let t: serde_json::Value = serde_json::from_slice(&std::fs::read(part.join("summary.json")).unwrap()).unwrap();
    assert_eq!(t["observables"], s["observables"]);

    // Refusals name the key.
    for (bad, needle) in [
        ("[observe.msd]\nevery = -1.0", "observe.msd.every = -1"),
        ("[observe.vacf]\nmax_lag = 0.0", "observe.vacf.max_lag = 0"),
        (
            "[observe.vacf]\nevery = 1.0\nmax_lag = 0.5",
            "observe.vacf.max_lag = 0.5: must be at least observe.vacf.every",
        ),
        ("[observe.msd]\nlags = 3", "lags"),
    ] {
        let path = dir.join("bad.toml");
        std::fs::write(&path, format!("{}\n{bad}\n", common::BASE)).unwrap();
        let r = collide(&["run", path.to_str().unwrap(), "--out", dir.join("bad").to_str().unwrap()]);
        assert_eq!(r.status.code(), Some(2));
        let stderr = String::from_utf8_lossy(&r.stderr);
        assert!(stderr.contains(needle), "{needle}: {stderr}");
    }

    // Memory: 100 particles fit in 1 MB, but not with a VACF storing 2¹⁰ levels' samples.
    let limits = Limits { memory: Some(1_000_000), ..Limits::default() };
    assert!(Run::<2>::with_limits(Config::parse(common::BASE, "base").unwrap(), limits).is_ok());
    let greedy = format!("{}\n[observe.vacf]\nevery = 1e-6\nmax_lag = 1e6\n", common::BASE);
    let refused = Run::<2>::with_limits(Config::parse(&greedy, "greedy").unwrap(), limits).err().unwrap().to_string();
    assert!(refused.contains("with the observables' stored samples"), "{refused}");

    // Not asked for: no files.
    std::fs::write(&config, common::BASE).unwrap();
    let plain = dir.join("plain");
    assert!(collide(&["run", config.to_str().unwrap(), "--out", plain.to_str().unwrap()]).status.success());
    assert!(!plain.join("msd.csv").exists() && !plain.join("vacf.csv").exists());
}
