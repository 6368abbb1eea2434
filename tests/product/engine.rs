//! The engine against analytic two-body cases and against the brute-force reference.

use collide::engine::init::{Placement, Species, Velocities, box_for_packing_fraction, initial_particles};
use collide::engine::{Boundary, Neighbourhood, Outcome, Particle, ReferenceSimulation, SimBox, Simulation};
use nalgebra::Vector2;

use crate::common::assert_same_collisions;

fn disk(x: f64, y: f64, vx: f64, vy: f64, radius: f64, mass: f64) -> Particle<2> {
    Particle {
        position: Vector2::new(x, y),
        velocity: Vector2::new(vx, vy),
        time: 0.0,
        radius,
        mass,
        species: 0,
        events: 0,
    }
}

fn square_box(l: f64, b: Boundary) -> SimBox<2> {
    SimBox { lengths: Vector2::new(l, l), boundary: [b, b] }
}

/// The next pair collision (skipping cell crossings).
fn next_pair(sim: &mut Simulation<2>) -> (usize, usize) {
    loop {
        match sim.step().expect("an event") {
            Outcome::Pair { i, j, .. } => return (i, j),
            Outcome::Rebuild { .. } => continue,
            other => panic!("unexpected {other:?}"),
        }
    }
}

#[test]
fn head_on_equal_masses_exchange_velocities_at_the_known_time() {
    // Gap 2 − 1 = 1 closed at relative speed 1.5: t = 2/3.
    let p = vec![disk(10.0, 10.0, 1.0, 0.0, 0.5, 1.0), disk(12.0, 10.0, -0.5, 0.0, 0.5, 1.0)];
    let mut sim = Simulation::new(p, square_box(40.0, Boundary::Periodic)).unwrap();
    assert_eq!(next_pair(&mut sim), (0, 1));
    assert_eq!(sim.time(), 2.0 / 3.0);
    assert_eq!(sim.particles()[0].velocity, Vector2::new(-0.5, 0.0));
    assert_eq!(sim.particles()[1].velocity, Vector2::new(1.0, 0.0));
}

#[test]
fn unequal_masses_and_oblique_impact_conserve_momentum_and_energy() {
    let p = vec![disk(10.0, 10.0, 1.0, 0.2, 0.5, 3.0), disk(11.5, 10.6, -0.5, 0.0, 0.7, 1.0)];
    let mut sim = Simulation::new(p, square_box(40.0, Boundary::Periodic)).unwrap();
    let (p0, k0) = (sim.momentum(), sim.kinetic_energy());
    next_pair(&mut sim);
    let (p1, k1) = (sim.momentum(), sim.kinetic_energy());
    // One collision: a few roundings of O(1) quantities.
    assert!((p1 - p0).norm() <= 8.0 * f64::EPSILON * 4.0, "{p0} → {p1}");
    assert!((k1 - k0).abs() <= 16.0 * f64::EPSILON * k0, "{k0} → {k1}");
    // The contact is at distance R₁ + R₂ = 1.2.
    let q = sim.particles();
    let d = q[1].position_at(sim.time()) - q[0].position_at(sim.time());
    assert!((d.norm() - 1.2).abs() <= 1e-14, "{}", d.norm());
}

#[test]
fn wall_bounce_reverses_the_normal_velocity_with_impulse_2mv() {
    let p = vec![disk(5.0, 5.0, -2.0, 1.0, 0.5, 1.5)];
    let mut sim = Simulation::new(p, square_box(10.0, Boundary::Wall)).unwrap();
    loop {
        match sim.step().unwrap() {
            Outcome::Wall { i, axis, upper, impulse } => {
                assert_eq!((i, axis, upper, impulse), (0, 0, false, 2.0 * 1.5 * 2.0));
                break;
            }
            Outcome::Rebuild { .. } => {}
            other => panic!("unexpected {other:?}"),
        }
    }
    assert_eq!(sim.time(), 4.5 / 2.0); // from x = 5 to x = R = 0.5 at speed 2
    assert_eq!(sim.particles()[0].velocity, Vector2::new(2.0, 1.0));
}

fn random_system(
    n: usize,
    eta: f64,
    boundary: [Boundary; 2],
    seed: u64,
    mixture: bool,
) -> (Vec<Particle<2>>, SimBox<2>) {
    let species = if mixture {
        vec![Species { count: n / 2, radius: 0.5, mass: 1.0 }, Species { count: n - n / 2, radius: 0.35, mass: 0.4 }]
    } else {
        vec![Species { count: n, radius: 0.5, mass: 1.0 }]
    };
    let placement = Placement::Random;
    let sim_box = box_for_packing_fraction(&species, eta, boundary, placement, None);
    let particles = initial_particles(&species, &sim_box, placement, Velocities::Maxwell, 1.0, seed).unwrap();
    (particles, sim_box)
}

/// The fast engine (queue, cells, invalidation) and the O(N²) reference produce the same
/// collisions — same pairs, same times to the last bit — on small systems of every kind.
#[test]
fn fast_engine_matches_the_brute_force_reference_bit_for_bit() {
    let cases = [
        ([Boundary::Periodic, Boundary::Periodic], false),
        ([Boundary::Wall, Boundary::Wall], false),
        ([Boundary::Periodic, Boundary::Wall], true),
        ([Boundary::Periodic, Boundary::Periodic], true),
    ];
    for (case, &(boundary, mixture)) in cases.iter().enumerate() {
        for seed in 0..3 {
            let n = 6 + 5 * seed as usize;
            let (particles, sim_box) = random_system(n, 0.3, boundary, 100 + seed, mixture);
            let fast = Simulation::new(particles.clone(), sim_box).unwrap();
            let slow = ReferenceSimulation::new(particles, sim_box);
            assert_same_collisions(fast, slow, 3000, &format!("case {case}, seed {seed}"));
        }
    }
}

#[test]
fn unequal_masses_head_on_follow_the_1d_formula() {
    // Seed eq. 8 with m₁ = 3, m₂ = 1, u₁ = 1, u₂ = −1: v₁ = 0, v₂ = 2.
    let p = vec![disk(10.0, 10.0, 1.0, 0.0, 0.5, 3.0), disk(12.0, 10.0, -1.0, 0.0, 0.5, 1.0)];
    let mut sim = Simulation::new(p, square_box(40.0, Boundary::Periodic)).unwrap();
    next_pair(&mut sim);
    assert_eq!(sim.time(), 0.5);
    assert_eq!(sim.particles()[0].velocity, Vector2::new(0.0, 0.0));
    assert_eq!(sim.particles()[1].velocity, Vector2::new(2.0, 0.0));
}

/// Dense lattice starts (many simultaneous near-contacts, "now" events, several cells per
/// axis) through the same comparison with the reference, with the grid that follows the
/// particles (the automatic choice at η = 0.7 would keep lists, tested below).
/// The dense lattice starts of the reference comparisons, `count` disks each: a triangular
/// lattice at η = 0.70 in a periodic box and a square one at η = 0.60 between walls.
fn dense_lattices(count: usize) -> Vec<(Placement, Vec<Particle<2>>, SimBox<2>)> {
    [(Placement::Triangular, 0.70, [Boundary::Periodic; 2]), (Placement::Square, 0.60, [Boundary::Wall; 2])]
        .into_iter()
        .map(|(placement, eta, boundary)| {
            let species = vec![Species { count, radius: 0.5, mass: 1.0 }];
            let sim_box = box_for_packing_fraction(&species, eta, boundary, placement, None);
            let particles = initial_particles(&species, &sim_box, placement, Velocities::Maxwell, 1.0, 9).unwrap();
            (placement, particles, sim_box)
        })
        .collect()
}

#[test]
fn fast_engine_matches_the_reference_from_dense_lattices() {
    for (placement, particles, sim_box) in dense_lattices(64) {
        let fast = Simulation::with_neighbourhood(particles.clone(), sim_box, Neighbourhood::Grid).unwrap();
        assert!(!fast.lists() && fast.cell_counts().iter().all(|&n| n >= 4), "{:?}", fast.cell_counts());
        let slow = ReferenceSimulation::new(particles, sim_box);
        assert_same_collisions(fast, slow, 5000, &format!("{placement:?}"));
    }
}

/// With neighbour lists forced on (the automatic choice keeps them only from packing
/// fraction 0.63 on), the fast engine still produces the reference's collisions bit for bit: random systems with walls, periodic axes and
/// mixtures, and dense lattices.
#[test]
fn fast_engine_with_lists_matches_the_reference() {
    let mut listed = 0;
    for (case, boundary, mixture) in [
        (0, [Boundary::Periodic, Boundary::Periodic], false),
        (1, [Boundary::Wall, Boundary::Wall], false),
        (2, [Boundary::Periodic, Boundary::Wall], true),
    ] {
        for seed in 0..3 {
            let (particles, sim_box) = random_system(40 + 10 * seed as usize, 0.3, boundary, 200 + seed, mixture);
            let fast = Simulation::with_neighbourhood(particles.clone(), sim_box, Neighbourhood::Lists).unwrap();
            listed += fast.lists() as usize;
            let slow = ReferenceSimulation::new(particles, sim_box);
            assert_same_collisions(fast, slow, 3000, &format!("lists, case {case}, seed {seed}"));
        }
    }
    for (placement, particles, sim_box) in dense_lattices(100) {
        let fast = Simulation::with_neighbourhood(particles.clone(), sim_box, Neighbourhood::Lists).unwrap();
        assert!(fast.lists());
        let slow = ReferenceSimulation::new(particles, sim_box);
        assert_same_collisions(fast, slow, 5000, &format!("lists, {placement:?}"));
    }
    assert!(listed >= 6, "lists were kept in {listed} of 9 random systems");
}

/// Every tunable of [`EngineParams`] — neighbourhood, queue, lookahead, huge pages — changes
/// the speed and the bookkeeping events, never a collision: every combination gives the
/// automatic engine's collisions bit for bit, and the same final state.
#[test]
fn engine_params_change_no_collision() {
    use collide::engine::{EngineParams, QueueChoice, Switch};
    let (particles, sim_box) = random_system(400, 0.5, [Boundary::Periodic, Boundary::Wall], 31, true);
    let collisions = |params: EngineParams| {
        let mut sim = Simulation::with_params(particles.clone(), sim_box, params).unwrap();
        let mut out = Vec::new();
        while out.len() < 20_000 {
            match sim.step().expect("an event") {
                Outcome::Pair { i, j, .. } => out.push((sim.time().to_bits(), i, j)),
                Outcome::Wall { i, .. } => out.push((sim.time().to_bits(), i, i)),
                _ => {}
            }
        }
        (out, sim.particles().to_vec(), sim.counts().rebuild)
    };
    let (expected, state, _) = collisions(EngineParams::default());
    let mut rebuilds = Vec::new();
    for neighbourhood in [Neighbourhood::Grid, Neighbourhood::Lists] {
        for queue in [QueueChoice::Calendar, QueueChoice::Tree] {
            for lookahead in [Switch::On, Switch::Off] {
                for huge_pages in [Switch::On, Switch::Off] {
                    let mut params = EngineParams::with_neighbourhood(neighbourhood);
                    (params.queue, params.lookahead, params.huge_pages) = (queue, lookahead, huge_pages);
                    let (got, final_state, rebuild) = collisions(params);
                    assert!(got == expected, "{params:?}: the collisions differ");
                    assert!(final_state == state, "{params:?}: the final state differs");
                    rebuilds.push(rebuild);
                }
            }
        }
    }
    // The neighbourhoods do differ in their bookkeeping (cell crossings against list rebuilds).
    assert_ne!(rebuilds[0], rebuilds[8]);
}

/// A sampling interval below the clock's resolution must not schedule samples at the same
/// instant forever: sampling stops and the dynamics goes on.
#[test]
fn sampling_below_clock_resolution_does_not_hang() {
    let p = vec![disk(10.0, 10.0, 1.0, 0.0, 0.5, 1.0), disk(12.0, 10.0, -0.5, 0.0, 0.5, 1.0)];
    let mut sim = Simulation::new(p, square_box(40.0, Boundary::Periodic)).unwrap();
    while sim.time() < 1.0 {
        sim.step().unwrap();
    }
    sim.sample_every(1e-300);
    let mut samples = 0;
    for _ in 0..1000 {
        if let Outcome::Sample = sim.step().unwrap() {
            samples += 1;
        }
    }
    assert!(samples <= 1, "{samples} samples at one instant");
}

/// A pair's predicted contact does not depend on which particle comes first — to the bit,
/// with lazily updated states at different times, across periodic images, with short axes
/// (several images tried), walls, unequal radii, near-misses, and growing radii. The batch
/// search relies on it: its lanes put the predicted particle first whatever the indices.
#[test]
fn pair_predictions_do_not_depend_on_the_order_of_the_pair() {
    use collide::engine::Radii;
    use collide::engine::sources::pair::{bracket as bracket_pair, predict as predict_pair};
    use rand::rngs::Xoshiro256PlusPlus;
    use rand::{RngExt, SeedableRng};
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(7);
    let boxes = [
        (square_box(20.0, Boundary::Periodic), [false, false]),
        (square_box(20.0, Boundary::Wall), [false, false]),
        (SimBox { lengths: Vector2::new(3.0, 20.0), boundary: [Boundary::Periodic; 2] }, [true, false]),
    ];
    let (mut hits, mut tested) = (0, 0);
    for ((sim_box, short), grow) in boxes.iter().flat_map(|b| [(b, false), (b, true)]) {
        for _ in 0..10_000 {
            let (l, now) = (sim_box.lengths, rng.random_range(0.0..50.0));
            let radii = if grow { Radii::Growing { rate: 0.05, origin: now - 2.0 } } else { Radii::Fixed };
            let state = |rng: &mut Xoshiro256PlusPlus, x: f64, y: f64| {
                let (ti, r) = (now - rng.random_range(0.0..1.0), rng.random_range(0.2..0.6));
                let v = Vector2::new(rng.random_range(-2.0..2.0), rng.random_range(-2.0..2.0));
                // Unwrapped positions: several box lengths away from the primary cell.
                let wraps = Vector2::new(rng.random_range(-3..4) as f64, rng.random_range(-3..4) as f64);
                let mut p = disk(0.0, 0.0, v.x, v.y, r, 1.0);
                p.position = Vector2::new(x, y) + wraps.component_mul(&l) - v * (now - ti);
                p.time = ti;
                p
            };
            let (x, y) = (rng.random_range(1.0..l.x - 1.0), rng.random_range(1.0..l.y - 1.0));
            let p = state(&mut rng, x, y);
            // A neighbour one to three radii away at `now`, possibly across the boundary.
            let (dx, dy) = (rng.random_range(-2.0..2.0), rng.random_range(-2.0..2.0));
            let q = state(&mut rng, x + dx, y + dy);
            let forward = predict_pair(&p, &q, sim_box, now, short, radii);
            let backward = predict_pair(&q, &p, sim_box, now, short, radii);
            assert_eq!(forward.map(f64::to_bits), backward.map(f64::to_bits), "{p:?} {q:?} at {now}");
            let horizon = now + rng.random_range(0.0..2.0);
            assert_eq!(
                bracket_pair(&p, &q, sim_box, now, short, horizon, radii),
                bracket_pair(&q, &p, sim_box, now, short, horizon, radii),
                "{p:?} {q:?} at {now}"
            );
            hits += forward.is_some() as usize;
            tested += 1;
        }
    }
    // Both outcomes must be well represented for the test to mean anything.
    assert!(hits > tested / 5 && hits < tested * 4 / 5, "{hits} contacts of {tested}");
}
