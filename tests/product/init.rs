//! Initial states: lattices up to high density without overlap, velocities as asked.

use collide::engine::init::{Placement, Species, Velocities, box_for_packing_fraction, initial_particles};
use collide::engine::{Boundary, Simulation};

fn build(n: usize, eta: f64, placement: Placement, velocities: Velocities, boundary: [Boundary; 2]) -> Simulation<2> {
    let species = vec![Species { count: n, radius: 0.5, mass: 2.0 }];
    let sim_box = box_for_packing_fraction(&species, eta, boundary, placement, None);
    let particles = initial_particles(&species, &sim_box, placement, velocities, 1.5, 42).unwrap();
    Simulation::new(particles, sim_box).expect("a valid initial state")
}

#[test]
fn triangular_lattice_up_to_eta_0_72_has_no_overlap() {
    for n in [100, 1000, 1001, 4096] {
        for eta in [0.3, 0.5, 0.7, 0.72] {
            let sim = build(n, eta, Placement::Triangular, Velocities::Maxwell, [Boundary::Periodic; 2]);
            let eta_actual: f64 = n as f64 * std::f64::consts::PI * 0.25 / sim.sim_box().volume();
            assert!((eta_actual - eta).abs() < 1e-12, "η = {eta_actual}");
            assert_eq!(sim.check_overlaps().fraction, 0.0, "n = {n}, η = {eta}");
        }
    }
    // Between walls and on a square lattice too (lower densities: a square lattice jams at π/4).
    build(400, 0.70, Placement::Triangular, Velocities::Maxwell, [Boundary::Wall; 2]);
    build(400, 0.65, Placement::Square, Velocities::Maxwell, [Boundary::Periodic, Boundary::Wall]);
}

#[test]
fn velocities_have_zero_momentum_and_the_exact_temperature() {
    let sim = build(500, 0.3, Placement::Random, Velocities::Maxwell, [Boundary::Periodic; 2]);
    let p = sim.momentum();
    let scale: f64 = sim.particles().iter().map(|q| q.mass * q.velocity.norm()).sum();
    assert!(p.norm() <= 1e-14 * scale, "momentum {p}");
    assert!((sim.kt() - 1.5).abs() <= 1e-14, "kT = {}", sim.kt());
    // Between walls the momentum is not removed (it is not conserved) and dof = 2N.
    let walled = build(500, 0.3, Placement::Square, Velocities::Maxwell, [Boundary::Wall; 2]);
    assert!(walled.momentum().norm() > 1e-3);
    assert!((walled.kinetic_energy() / 500.0 - 1.5).abs() <= 1e-13);
}

#[test]
fn fixed_speed_start_has_one_speed_between_walls() {
    // Without momentum removal (walls) the speeds are exactly equal: |v| = √(2kT/m).
    let sim = build(300, 0.4, Placement::Square, Velocities::FixedSpeed, [Boundary::Wall; 2]);
    let speeds: Vec<f64> = sim.particles().iter().map(|p| p.velocity.norm()).collect();
    let expected = (2.0 * 1.5f64 / 2.0).sqrt();
    assert!(speeds.iter().all(|s| (s - expected).abs() < 1e-14), "{:?}", &speeds[..3]);
}

#[test]
fn the_same_seed_gives_the_same_state() {
    let a = build(200, 0.4, Placement::Random, Velocities::Maxwell, [Boundary::Periodic; 2]);
    let b = build(200, 0.4, Placement::Random, Velocities::Maxwell, [Boundary::Periodic; 2]);
    assert_eq!(a.particles(), b.particles());
}

/// Lattice sites between walls never round past the accessible region (a 1-ulp excess
/// would be rejected as "outside the walls").
#[test]
fn walled_lattices_stay_inside_at_many_sizes() {
    for n in [100, 400, 1000, 1600, 2500] {
        for eta in [0.05, 0.1, 0.2, 0.4, 0.6] {
            for placement in [Placement::Square, Placement::Triangular] {
                build(n, eta, placement, Velocities::Maxwell, [Boundary::Wall; 2]);
            }
        }
    }
}
