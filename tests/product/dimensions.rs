//! The product generic over the dimension: initial states, the engine against the reference
//! (with the grid and with neighbour lists), runs, checkpoints and trajectories in 3D as in
//! 2D, every piece driven through the library.

use collide::engine::init::{InitError, Placement, Species, Velocities, box_for_packing_fraction, initial_particles};
use collide::engine::{Boundary, Neighbourhood, ReferenceSimulation, Simulation};
use collide::run::output::xyz_frame;
use collide::run::{Checkpoint, Config, Discard, Run, RunError, Summary};

use crate::common::{assert_same_collisions, reproducible};

const EPS: f64 = f64::EPSILON;

fn spheres(n: usize, eta: f64, boundary: &str, collisions: u64, seed: u64) -> Config {
    let text = format!(
        "dimension = 3\nseed = {seed}\n[box]\npacking_fraction = {eta}\nboundary = {boundary}\n\
         [[species]]\ncount = {}\nradius = 0.5\nmass = 1.0\n[[species]]\ncount = {}\nradius = 0.4\nmass = 0.6\n\
         [init]\nplacement = \"random\"\n[equilibration]\ncollisions = 5000\n\
         [run]\ncollisions = {collisions}\nsample_interval = 0.5\n",
        n / 2,
        n - n / 2
    );
    Config::parse(&text, "spheres").unwrap()
}

/// A mixture of spheres in a box periodic along x and y and walled along z: energy and the
/// momentum along the periodic axes conserved to rounding, no overlap, the wall pressures of
/// z only, and a checkpoint taken mid-run that resumes to the same bits.
///
/// Tolerances as in the 2D physics tests: rounding errors of independent collisions add like
/// a random walk, |ΔK|/K ≤ 4ε√M over M collisions; an overlap is a few ε of the coordinates.
#[test]
fn a_run_of_spheres_conserves_and_resumes_bit_identically() {
    let config = spheres(300, 0.25, r#"["periodic", "periodic", "wall"]"#, 60_000, 4);
    let mut run = Run::<3>::new(config.clone()).unwrap();
    let Ok(_) = run.equilibrate(&mut Discard);
    let (p0, k0) = (run.sim.momentum(), run.sim.kinetic_energy());
    let Ok(_) = run.complete(&mut Discard);
    let whole = reproducible(run.summary());
    let m = whole.collisions as f64;
    assert_eq!(whole.collisions, 60_000);
    assert!(whole.energy_relative_drift.abs() <= 4.0 * EPS * m.sqrt(), "{}", whole.energy_relative_drift);
    assert!(((run.sim.kinetic_energy() - k0) / k0).abs() <= 4.0 * EPS * m.sqrt());
    let dp = run.sim.momentum() - p0;
    let scale: f64 = run.sim.particles().iter().map(|p| p.mass * p.velocity.norm()).sum();
    assert!(dp[0].abs().max(dp[1].abs()) <= 4.0 * EPS * m.sqrt() * scale, "{dp}");
    assert!(dp[2].abs() > 1e-3 * scale / 300.0, "the walls exchange momentum along z");
    assert!(whole.max_overlap.fraction <= 1e-12, "{:?}", whole.max_overlap);
    let axes: Vec<usize> = whole.wall_pressures.iter().map(|w| w.axis).collect();
    assert_eq!(axes, [2, 2]);
    assert!(whole.wall_pressures.iter().all(|w| w.pressure > 0.0));
    assert!(whole.samples > 20 && whole.compressibility > 1.0);

    resumes_to(config, &whole, run.sim.particles());
}

/// The run of `config`, checkpointed at the end of equilibration and resumed from the JSON
/// text, ends with the summary `whole` and the particles `end` of the run never interrupted.
fn resumes_to(config: Config, whole: &Summary, end: &[collide::engine::Particle<3>]) {
    let mut first = Run::<3>::new(config).unwrap();
    let Ok(_) = first.equilibrate(&mut Discard);
    let text = first.checkpoint(0).to_json();
    let mut resumed = Run::resume(Checkpoint::<3>::from_json(text.as_bytes()).unwrap()).unwrap();
    let Ok(_) = resumed.complete(&mut Discard);
    assert_eq!(&reproducible(resumed.summary()), whole);
    assert_eq!(resumed.sim.particles(), end);
}

/// The fast engine and the O(N²) reference give the same collisions, to the bit, for spheres
/// in periodic, walled and mixed boxes, a mixture of two sizes — with the grid and with
/// neighbour lists (two rows a sphere) forced on.
#[test]
fn spheres_collide_as_the_reference_says() {
    use Boundary::{Periodic as P, Wall as W};
    let mut listed = 0;
    for (boundary, seed) in [([P; 3], 1), ([W; 3], 2), ([P, W, P], 3)] {
        let species =
            [Species { count: 100, radius: 0.5, mass: 1.0 }, Species { count: 100, radius: 0.3, mass: 0.4 }].to_vec();
        let sim_box = box_for_packing_fraction::<3>(&species, 0.25, boundary, Placement::Random, None);
        let particles =
            initial_particles(&species, &sim_box, Placement::Random, Velocities::Maxwell, 1.0, seed).unwrap();
        for neighbourhood in [Neighbourhood::Grid, Neighbourhood::Lists] {
            let fast = Simulation::with_neighbourhood(particles.clone(), sim_box, neighbourhood).unwrap();
            listed += fast.lists() as usize;
            let slow = ReferenceSimulation::new(particles.clone(), sim_box);
            assert_same_collisions(fast, slow, 3000, &format!("{boundary:?}, seed {seed}, {neighbourhood}"));
        }
    }
    assert_eq!(listed, 3, "lists were kept in {listed} of 3 boxes");
}

/// Dense crystals from fcc (and a simple cubic lattice between walls): the fast engine and
/// the reference agree to the bit from a perfect fcc crystal near close packing (η = 0.70,
/// 108 spheres, periodic), from one with vacancies between walls, and from a simple cubic
/// lattice in a mixed box.
#[test]
fn dense_lattice_starts_collide_as_the_reference_says() {
    use Boundary::{Periodic as P, Wall as W};
    let cases = [
        (108, 0.70, [P; 3], Placement::Fcc, 3),
        (100, 0.55, [W; 3], Placement::Fcc, 4),
        (125, 0.45, [P, W, P], Placement::SimpleCubic, 5),
    ];
    let mut listed = 0;
    for (n, eta, boundary, placement, seed) in cases {
        let species = vec![Species { count: n, radius: 0.5, mass: 1.0 }];
        let sim_box = box_for_packing_fraction::<3>(&species, eta, boundary, placement, None);
        let particles = initial_particles(&species, &sim_box, placement, Velocities::Maxwell, 1.0, seed).unwrap();
        for neighbourhood in [Neighbourhood::Grid, Neighbourhood::Lists] {
            let fast = Simulation::with_neighbourhood(particles.clone(), sim_box, neighbourhood).unwrap();
            assert_eq!(fast.check_overlaps().at, None);
            listed += fast.lists() as usize;
            let slow = ReferenceSimulation::new(particles.clone(), sim_box);
            assert_same_collisions(fast, slow, 4000, &format!("{neighbourhood}, {placement:?} η = {eta} {boundary:?}"));
        }
    }
    assert!(listed >= 2, "lists were kept in {listed} of 3 lattices");
}

/// A dense fluid of spheres with lists (the automatic choice at η = 0.45, from a simple cubic
/// start): a checkpoint taken mid-run (the centres and the crowded particles saved) resumes
/// to the same bits as the run never interrupted.
#[test]
fn spheres_with_lists_resume_bit_identically() {
    let text = "dimension = 3\nseed = 6\n[box]\npacking_fraction = 0.45\nboundary = \"periodic\"\n\
                [[species]]\ncount = 512\nradius = 0.5\nmass = 1.0\n[init]\nplacement = \"simple_cubic\"\n\
                [equilibration]\ncollisions = 20000\n[run]\ncollisions = 40000\nsample_interval = 0.2\n";
    let config = Config::parse(text, "dense spheres").unwrap();
    let mut run = Run::<3>::new(config.clone()).unwrap();
    assert!(run.sim.lists());
    let Ok(_) = run.complete(&mut Discard);
    let whole = reproducible(run.summary());
    assert!(whole.max_overlap.fraction <= 1e-12, "{:?}", whole.max_overlap);
    resumes_to(config, &whole, run.sim.particles());
}

/// Initial states in 3D: random placement without overlap, one speed per species with
/// fixed-speed velocities (walls: no momentum removed), the temperature exact; the 2D
/// lattices refused with the way out.
#[test]
fn initial_states_in_three_dimensions() {
    let species = vec![Species { count: 500, radius: 0.5, mass: 2.0 }];
    let sim_box = box_for_packing_fraction::<3>(&species, 0.3, [Boundary::Wall; 3], Placement::Random, None);
    assert!((sim_box.volume() - 500.0 * 4.0 / 3.0 * std::f64::consts::PI * 0.125 / 0.3).abs() < 1e-9);
    let particles = initial_particles(&species, &sim_box, Placement::Random, Velocities::FixedSpeed, 1.5, 9).unwrap();
    let speeds: Vec<f64> = particles.iter().map(|p| p.velocity.norm()).collect();
    let v = (3.0 * 1.5 / 2.0f64).sqrt();
    assert!(speeds.iter().all(|s| (s - v).abs() <= 8.0 * EPS * v), "{:?}", &speeds[..3]);
    let sim = Simulation::new(particles, sim_box).expect("inside the walls, no overlap");
    assert!((sim.kt() - 1.5).abs() <= 8.0 * EPS * 1.5, "{}", sim.kt());
    assert_eq!(sim.check_overlaps().at, None);
    // Directions fill the sphere: the mean of each component is small against the speed.
    let mean = sim.momentum() / (2.0 * 500.0 * v);
    assert!(mean.norm() < 0.1, "{mean}");
    for placement in [Placement::Triangular, Placement::Square] {
        let err = initial_particles(&species, &sim_box, placement, Velocities::Maxwell, 1.0, 1).unwrap_err();
        assert_eq!(err, InitError::NotInDimension { placement, dimension: 3 });
        assert!(err.to_string().contains("is not a lattice of 3D; use placement = \"fcc\""), "{err}");
    }
    let config = Config::parse(
        "dimension = 3\nseed = 1\n[box]\npacking_fraction = 0.3\nboundary = \"periodic\"\n[[species]]\ncount = 50\nradius = 0.5\nmass = 1.0\n[run]\ncollisions = 10\n",
        "lattice",
    )
    .unwrap();
    assert_eq!(config.placement(), Placement::Fcc, "the densest lattice by default");
    let Err(RunError::Config(_)) = Run::<2>::new(config) else { panic!("a 3D configuration in a 2D run") };
}

/// Extended XYZ in 3D: real z coordinates inside the box, the third edge in the lattice, the
/// periodicity of each axis.
#[test]
fn trajectory_frames_carry_z_in_three_dimensions() {
    let mut run = Run::<3>::new(spheres(40, 0.1, r#"["periodic", "wall", "periodic"]"#, 200, 2)).unwrap();
    let Ok(_) = run.complete(&mut Discard);
    let frame = xyz_frame(&run.sim);
    let lines: Vec<&str> = frame.lines().collect();
    assert_eq!(lines[0], "40");
    let l = run.sim.sim_box().lengths;
    assert!(
        lines[1].contains(&format!("Lattice=\"{} 0.0 0.0 0.0 {} 0.0 0.0 0.0 {}\"", l[0], l[1], l[2])),
        "{}",
        lines[1]
    );
    assert!(lines[1].contains("pbc=\"T F T\""), "{}", lines[1]);
    let zs: Vec<f64> = lines[2..].iter().map(|row| row.split_whitespace().nth(3).unwrap().parse().unwrap()).collect();
    assert_eq!(zs.len(), 40);
    assert!(zs.iter().all(|&z| (0.0..l[2]).contains(&z)), "{zs:?}");
    assert!(zs.iter().any(|&z| z != zs[0]), "z varies");
}

/// Every engine tunable leaves the collisions of spheres unchanged to the bit, as of disks:
/// both neighbourhoods, both queues, with and without the lookahead (forced on at this small
/// N, so that its prefetches walk the two rows of a sphere's list) — a dense fluid from a
/// simple cubic start, where lists are kept and some spheres are crowded.
#[test]
fn engine_tunables_change_no_collision_of_spheres() {
    use collide::engine::{EngineParams, Outcome, QueueChoice, Switch};
    let species = vec![Species { count: 343, radius: 0.5, mass: 1.0 }];
    let sim_box = box_for_packing_fraction::<3>(&species, 0.45, [Boundary::Periodic; 3], Placement::SimpleCubic, None);
    let particles =
        initial_particles(&species, &sim_box, Placement::SimpleCubic, Velocities::Maxwell, 1.0, 12).unwrap();
    let collisions = |params: EngineParams| {
        let mut sim = Simulation::with_params(particles.clone(), sim_box, params).unwrap();
        let mut out = Vec::new();
        while out.len() < 20_000 {
            if let Outcome::Pair { i, j, .. } = sim.step().expect("an event") {
                out.push((sim.time().to_bits(), i, j));
            }
        }
        (out, sim.particles().to_vec(), sim.lists())
    };
    // The lattice's 6 + 12 nearest sites lie within range: every sphere starts crowded.
    let start = Simulation::with_neighbourhood(particles.clone(), sim_box, Neighbourhood::Lists).unwrap();
    assert!(start.crowded() > 0, "no crowded sphere");
    let (expected, state, _) = collisions(EngineParams::with_neighbourhood(Neighbourhood::Grid));
    let mut listed = 0;
    for neighbourhood in [Neighbourhood::Grid, Neighbourhood::Lists] {
        for queue in [QueueChoice::Calendar, QueueChoice::Tree] {
            for lookahead in [Switch::On, Switch::Off] {
                let mut params = EngineParams::with_neighbourhood(neighbourhood);
                (params.queue, params.lookahead) = (queue, lookahead);
                let (got, final_state, lists) = collisions(params);
                assert!(got == expected, "{params:?}: the collisions differ");
                assert!(final_state == state, "{params:?}: the final state differs");
                listed += lists as usize;
            }
        }
    }
    assert_eq!(listed, 4);
}
