//! `[compress]` through a run: to a packing fraction (then equilibrated and measured there)
//! and to jamming (the run ends at the jammed packing), in 2D and 3D; the summary's
//! `compression`; a compression interrupted and resumed from its checkpoint to the same bits;
//! the files `collide run` writes.

use collide::engine::Ending;
use collide::engine::Outcome;

use crate::common::reproducible;
use collide::run::{Checkpoint, Config, Phase, Run, Sink, Status, Summary};

fn config(dimension: usize, n: usize, start: f64, compress: &str, rest: &str) -> Config {
    let text = format!(
        "dimension = {dimension}\nseed = 5\n[box]\npacking_fraction = {start}\nboundary = \"periodic\"\n\
         [[species]]\ncount = {}\nradius = 0.5\nmass = 1.0\n[[species]]\ncount = {}\nradius = 0.7\nmass = 1.96\n\
         [init]\nplacement = \"random\"\n[compress]\n{compress}\n{rest}",
        n / 2,
        n - n / 2
    );
    Config::parse(&text, "compress").unwrap()
}

/// Compressed to φ = 0.75 (2D) and 0.52 (3D), the run equilibrates and measures there: the
/// summary's packing fraction is the target (to rounding), every radius is its species'
/// times one factor, the equilibration and production lengths count from the compression's
/// end, and nothing overlaps.
#[test]
fn a_compression_to_a_target_equilibrates_and_measures_there() {
    for (d, target) in [(2usize, 0.75), (3, 0.52)] {
        let c = config(
            d,
            200,
            0.3,
            &format!("rate = 0.02\ntarget_packing_fraction = {target}"),
            "[equilibration]\ncollisions = 5000\n[run]\ncollisions = 20000\n",
        );
        let summary = match d {
            2 => {
                let mut run = Run::<2>::new(c).unwrap();
                run.complete(&mut collide::run::Discard).unwrap();
                run.summary()
            }
            _ => {
                let mut run = Run::<3>::new(c).unwrap();
                run.complete(&mut collide::run::Discard).unwrap();
                run.summary()
            }
        };
        let compression = summary.compression.clone().expect("a compression");
        assert_eq!(summary.status, Status::Complete);
        assert!((summary.packing_fraction - target).abs() <= 1e-12, "{d}D: φ = {}", summary.packing_fraction);
        assert_eq!(summary.packing_fraction, compression.packing_fraction);
        assert_eq!((compression.ending, compression.jammed, compression.done), (Some(Ending::Reached), false, true));
        assert!(compression.collisions > 1000 && compression.sim_time > 0.0);
        assert_eq!((summary.equilibration.collisions, summary.collisions), (5000, 20000));
        assert!(summary.max_overlap.fraction <= 1e-12 && compression.max_overlap <= 1e-12);
        assert!(summary.compressibility > 3.0, "{d}D: Z = {}", summary.compressibility);
    }
}

/// Stops a run after `after` events of its compression (as a signal would).
struct StopAfter {
    after: u64,
    stop: std::sync::Arc<std::sync::atomic::AtomicBool>,
}

impl<const D: usize> Sink<D> for StopAfter {
    type Error = std::convert::Infallible;
    fn event(&mut self, run: &Run<D>, _: &Outcome<D>) -> Result<(), Self::Error> {
        if run.phase() == Phase::Compression {
            self.after = self.after.saturating_sub(1);
            if self.after == 0 {
                self.stop.store(true, std::sync::atomic::Ordering::Relaxed);
            }
        }
        Ok(())
    }
}

/// Interrupted in the middle of its compression, checkpointed to JSON and resumed, a run
/// ends with the summary and particles of the run never interrupted, to the bit — to a
/// target and to jamming.
#[test]
fn a_compression_resumes_bit_identically_from_its_checkpoint() {
    let cases = [
        (
            "rate = 0.02\ntarget_packing_fraction = 0.7",
            "[equilibration]\ncollisions = 2000\n[run]\ncollisions = 5000\n",
        ),
        ("rate = 0.05\nuntil = \"jammed\"\npressure_limit = 1e6", ""),
    ];
    for (compress, rest) in cases {
        let c = config(2, 60, 0.4, compress, rest);
        let mut whole = Run::<2>::new(c.clone()).unwrap();
        whole.complete(&mut collide::run::Discard).unwrap();
        let stop = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
        let mut first = Run::<2>::new(c).unwrap();
        let status = first.advance(&stop, &mut StopAfter { after: 3000, stop: stop.clone() }).unwrap();
        assert_eq!((status, first.phase()), (Status::Interrupted, Phase::Compression), "{compress}");
        let text = first.checkpoint(0).to_json();
        let mut resumed = Run::resume(Checkpoint::<2>::from_json(text.as_bytes()).unwrap()).unwrap();
        resumed.complete(&mut collide::run::Discard).unwrap();
        // As JSON: a run that ends at jamming has no production, and its pressures are null.
        let json = |s: Summary| serde_json::to_string(&reproducible(s)).unwrap();
        assert_eq!(json(resumed.summary()), json(whole.summary()), "{compress}");
        assert_eq!(resumed.sim.particles(), whole.sim.particles());
    }
}

/// Compressed until jammed, 50:50 disks of diameter ratio 1.4 end near φ_J ≈ 0.84 (O'Hern et
/// al., PRE 68, 011306 (2003); ±0.02 for N = 200 and this rate) with the reduced pressure at
/// its limit, no overlap beyond rounding, the contact network reported (at most isostatic,
/// `2d` contacts per held particle), and no production. Spheres (50:50, ratio 1.4) jam near
/// random close packing, 0.64 (±0.03 at N = 200).
#[test]
fn a_compression_to_jamming_ends_at_the_jammed_packing() {
    let c = config(2, 200, 0.5, "rate = 0.01\nuntil = \"jammed\"\npressure_limit = 1e10", "");
    let mut run = Run::<2>::new(c).unwrap();
    assert_eq!(run.complete(&mut collide::run::Discard).unwrap(), Status::Complete);
    let summary = run.summary();
    let jam = summary.compression.clone().unwrap();
    assert!(jam.jammed && jam.done, "{jam:?}");
    assert!(matches!(jam.ending, Some(Ending::Stopped | Ending::Stalled)), "{jam:?}");
    assert!((0.82..0.86).contains(&jam.packing_fraction), "φ_J = {}", jam.packing_fraction);
    assert!(jam.reduced_pressure.unwrap() >= 1e10 || jam.ending == Some(Ending::Stalled), "{jam:?}");
    assert!(jam.max_overlap <= 1e-12, "{jam:?}");
    let z = jam.contacts_per_particle.unwrap();
    assert!(z > 3.5 && z <= 4.0 + 1e-9 && jam.rattlers.unwrap() < 50, "{jam:?}");
    assert_eq!((summary.collisions, summary.samples), (0, 0));
    assert_eq!(summary.packing_fraction, jam.packing_fraction);

    let c = config(3, 200, 0.3, "rate = 0.01\nuntil = \"jammed\"\npressure_limit = 1e10", "");
    let mut run = Run::<3>::new(c).unwrap();
    run.complete(&mut collide::run::Discard).unwrap();
    let jam = run.summary().compression.unwrap();
    assert!(jam.jammed && (0.61..0.67).contains(&jam.packing_fraction), "{jam:?}");
    let z = jam.contacts_per_particle.unwrap();
    assert!(z > 5.0 && z <= 6.0 + 1e-9, "{jam:?}");
}

/// `collide run` with a compression writes the packing as it stands at the compression's
/// end (`compressed.xyz`) beside the usual files, and says what it reached.
#[test]
fn collide_run_writes_the_compressed_packing() {
    let dir = std::env::temp_dir().join(format!("collide-compress-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let text = "seed = 2\n[box]\npacking_fraction = 0.4\nboundary = \"wall\"\n[[species]]\ncount = 80\nradius = 0.5\nmass = 1.0\n\
                [init]\nplacement = \"random\"\n[compress]\nrate = 0.05\ntarget_packing_fraction = 0.6\n[run]\ncollisions = 2000\n";
    std::fs::write(dir.join("c.toml"), text).unwrap();
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_collide"))
        .args(["run", dir.join("c.toml").to_str().unwrap(), "--out", dir.join("out").to_str().unwrap(), "--quiet"])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.contains("compressed to φ = 0.600000"), "{stdout}");
    let xyz = std::fs::read_to_string(dir.join("out/compressed.xyz")).unwrap();
    assert_eq!(xyz.lines().count(), 82);
    let summary: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("out/summary.json")).unwrap()).unwrap();
    assert_eq!(summary["compression"]["ending"], "reached");
    assert!(summary["compression"].get("window").is_none());
    let _ = std::fs::remove_dir_all(&dir);
}

/// Compressed too fast (rate 0.1), 200 disks reach the pressure limit with no contact network
/// at all — the pressure of the growth itself — and the summary says so instead of passing
/// it off as a jammed packing.
#[test]
fn a_pressure_without_a_contact_network_is_flagged() {
    let c = config(2, 200, 0.5, "rate = 0.1\nuntil = \"jammed\"\npressure_limit = 1e10", "");
    let mut run = Run::<2>::new(c).unwrap();
    run.complete(&mut collide::run::Discard).unwrap();
    let summary = run.summary();
    let jam = summary.compression.clone().unwrap();
    assert_eq!(jam.rattlers, Some(200), "{jam:?}");
    assert!(
        summary.warnings.iter().any(|w| w.contains("no contact network holding any particle")),
        "{:?}",
        summary.warnings
    );
}

/// Where packing codes give up: a polydisperse mixture (ten radii from 0.4 to 0.6), a 1 : 10
/// size ratio, fifty spheres in a periodic box some three diameters wide, fifty particles
/// between walls — each compressed through `[compress]` in a run, to jamming (or, for the
/// 1 : 10 mixture, to a dense target), with no overlap beyond rounding, and, where jammed, a
/// contact network that is at most isostatic. The neighbourhood is sized for the final radii
/// (or, where a periodic axis is too short for four cells, searched over images): no "system
/// too small".
#[test]
fn polydisperse_size_asymmetric_small_and_walled_systems_compress() {
    let run = |dimension: usize, text: String| -> Summary {
        let config = Config::parse(&format!("dimension = {dimension}\nseed = 3\n{text}"), "where-others-fail").unwrap();
        match dimension {
            2 => {
                let mut run = Run::<2>::new(config).unwrap();
                assert_eq!(run.complete(&mut collide::run::Discard).unwrap(), Status::Complete);
                run.summary()
            }
            _ => {
                let mut run = Run::<3>::new(config).unwrap();
                assert_eq!(run.complete(&mut collide::run::Discard).unwrap(), Status::Complete);
                run.summary()
            }
        }
    };
    let species = |list: &[(usize, f64, f64)]| {
        list.iter()
            .map(|(n, r, m)| format!("[[species]]\ncount = {n}\nradius = {r:?}\nmass = {m:?}\n"))
            .collect::<String>()
    };
    let jam = "[init]\nplacement = \"random\"\n[compress]\nrate = 0.01\nuntil = \"jammed\"\n";
    let poly: Vec<(usize, f64, f64)> = (0..10).map(|k| (10, 0.4 + 0.2 * k as f64 / 9.0, 1.0)).collect();
    let cases = [
        (
            "polydisperse disks",
            2,
            format!("[box]\npacking_fraction = 0.5\nboundary = \"periodic\"\n{jam}{}", species(&poly)),
            0.80..0.88,
        ),
        (
            "50 spheres, periodic",
            3,
            format!(
                "[box]\npacking_fraction = 0.3\nboundary = \"periodic\"\n{jam}pressure_limit = 1e4\n{}",
                species(&[(50, 0.5, 1.0)])
            ),
            0.60..0.68,
        ),
        (
            "50 disks between walls",
            2,
            format!(
                "[box]\npacking_fraction = 0.4\nboundary = \"wall\"\n{jam}{}",
                species(&[(25, 0.5, 1.0), (25, 0.7, 1.0)])
            ),
            0.70..0.86,
        ),
        (
            "50 spheres between walls",
            3,
            format!(
                "[box]\npacking_fraction = 0.25\nboundary = \"wall\"\n{jam}{}",
                species(&[(25, 0.5, 1.0), (25, 0.7, 1.0)])
            ),
            0.45..0.62,
        ),
    ];
    for (label, d, text, range) in cases {
        let summary = run(d, text);
        let c = summary.compression.clone().unwrap();
        assert!(c.jammed && range.contains(&c.packing_fraction), "{label}: {c:?}");
        assert!(c.max_overlap <= 1e-12, "{label}: {c:?}");
        let (z, rattlers) = (c.contacts_per_particle.unwrap(), c.rattlers.unwrap());
        let n = summary.n_particles;
        assert!(rattlers < n && z > d as f64, "{label}: {c:?}");
        // At most isostatic: d(N′ − 1) + 1 periodic; between walls (no free translation) dN′.
        let held = (n - rattlers) as f64;
        assert!(z * held / 2.0 <= d as f64 * held + 1.0, "{label}: z = {z} with {held} held");
    }
    // 1 : 10: ten large disks among a hundred small ones, compressed to φ = 0.75 and run there.
    let text = format!(
        "[box]\npacking_fraction = 0.4\nboundary = \"periodic\"\n[init]\nplacement = \"random\"\n\
         [compress]\nrate = 0.01\ntarget_packing_fraction = 0.75\n[equilibration]\ncollisions = 1000\n[run]\ncollisions = 5000\n{}",
        species(&[(10, 0.5, 1.0), (100, 0.05, 0.01)])
    );
    let summary = run(2, text);
    let c = summary.compression.clone().unwrap();
    assert!(!c.jammed && (summary.packing_fraction - 0.75).abs() <= 1e-12, "1:10: {c:?}");
    assert!(summary.max_overlap.fraction <= 1e-12 && c.max_overlap <= 1e-12, "1:10: {c:?}");
    assert_eq!(summary.collisions, 5000);
}
