//! The benchmark report: a point, its table row and its chart (speed itself is never
//! asserted).

use std::path::Path;

fn out(name: &str) -> std::path::PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(name);
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

/// One small benchmark point, its table row and its chart (speed itself is never asserted).
#[test]
fn bench_point_table_and_chart() {
    use collide::bench::{chart, markdown, measure};
    use collide::engine::Neighbourhood;
    // Both neighbourhoods can be asked for; the point records which one ran, and both see
    // the same collisions (bit-identical trajectories), so the same event counts but for
    // the neighbourhood updates themselves.
    let lists = measure(2, 300, 0.6, Neighbourhood::Lists, 1, 5_000, 1, 1).unwrap();
    let p = measure(2, 300, 0.6, Neighbourhood::Grid, 1, 5_000, 1, 1).unwrap();
    assert!(lists.lists && !p.lists && lists.neighbourhood == Neighbourhood::Lists);
    assert_eq!((lists.events_by_kind.pair, lists.events_by_kind.wall), (p.events_by_kind.pair, p.events_by_kind.wall));
    assert_ne!(lists.events_by_kind.rebuild, p.events_by_kind.rebuild);
    assert_eq!(p.events_by_kind.pair, 5_000);
    assert!(p.collisions_per_second > 0.0 && p.ns_per_collision > 0.0);
    assert!(p.engine_bytes_per_particle > 100.0, "particles alone take more: {}", p.engine_bytes_per_particle);
    // The floor was measured, and the fraction is the ratio of the two rates.
    let (floor, fraction) = (p.floor_collisions_per_second.unwrap(), p.fraction_of_floor.unwrap());
    assert!(floor > 0.0 && (fraction - p.collisions_per_second / floor).abs() <= 1e-12 * fraction);
    let md = markdown(&[p.clone()], "collide bench --quick", "test machine");
    assert!(
        md.contains("| 2 | 300 | 0.6 | grid |") && md.contains("test machine") && md.contains("collide bench --quick")
    );
    assert!(md.contains(&format!("| {:.1} % |", 100.0 * fraction)), "{md}");
    let dir = out("bench-chart");
    std::fs::create_dir_all(&dir).unwrap();
    // Two sizes at one packing fraction, as the matrix has them (N by N): one series each.
    let mut q = p.clone();
    q.n_particles = 3_000;
    q.packing_fraction = 0.3;
    // Spheres: their own series, with a floor of their own.
    let s = measure(3, 500, 0.45, Neighbourhood::Auto, 1, 5_000, 1, 1).unwrap();
    assert_eq!((s.dimension, s.events_by_kind.pair), (3, 5_000));
    let (floor, fraction) = (s.floor_collisions_per_second.unwrap(), s.fraction_of_floor.unwrap());
    assert!(floor > 0.0 && (fraction - s.collisions_per_second / floor).abs() <= 1e-12 * fraction);
    // Spheres keep lists from η = 0.38 on.
    assert!(s.lists && markdown(&[s.clone()], "c", "m").contains("| 3 | 500 | 0.45 | lists |"));
    let c = chart(&[p.clone(), q.clone(), p.clone(), q, s]);
    let names: Vec<&str> = c.series.iter().map(|s| s.label.as_str()).collect();
    assert_eq!(
        names,
        [
            "disks, η = 0.3",
            "floor, disks, η = 0.3",
            "disks, η = 0.6",
            "floor, disks, η = 0.6",
            "spheres, η = 0.45",
            "floor, spheres, η = 0.45"
        ]
    );
    collide::lab::plot::draw(&chart(&[p]), &dir.join("c.svg")).unwrap();
    let svg = std::fs::read_to_string(dir.join("c.svg")).unwrap();
    assert!(svg.contains("log₁₀ N") && svg.contains("floor, disks, η = 0.6"));
    // A dimension other than 2 or 3, and a packing fraction past close packing of spheres.
    assert!(measure(4, 500, 0.3, Neighbourhood::Auto, 1, 10, 1, 1).unwrap_err().to_string().contains("--dimension 4"));
    let err = measure(3, 500, 0.75, Neighbourhood::Auto, 1, 10, 1, 1).unwrap_err().to_string();
    assert!(err.contains("π/√18"), "{err}");
}
