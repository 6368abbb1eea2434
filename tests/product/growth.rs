//! Compression (growing radii) in the engine: the fast engine against the growing reference,
//! bit for bit, in 2D and 3D, periodic and walled, mixtures; the end of the growth at the
//! target packing fraction; the thermostat; checkpoints; the errors.

use collide::engine::init::{Placement, Species, Velocities, box_for_packing_fraction, initial_particles};
use collide::engine::{
    Boundary, Ending, GROWTH_STRETCH, Neighbourhood, Outcome, Particle, ReferenceSimulation, SimBox, Simulation,
    SimulationState,
};

use crate::common::assert_same_collisions;

fn system<const D: usize>(
    species: &[Species],
    eta: f64,
    boundary: [Boundary; D],
    seed: u64,
) -> (Vec<Particle<D>>, SimBox<D>) {
    let sim_box = box_for_packing_fraction(species, eta, boundary, Placement::Random, None);
    let particles = initial_particles(species, &sim_box, Placement::Random, Velocities::Maxwell, 1.0, seed).unwrap();
    (particles, sim_box)
}

fn one(count: usize) -> Vec<Species> {
    vec![Species { count, radius: 0.5, mass: 1.0 }]
}

fn two(count: usize, ratio: f64) -> Vec<Species> {
    vec![
        Species { count: count / 2, radius: 0.5, mass: 1.0 },
        Species { count: count - count / 2, radius: 0.5 * ratio, mass: ratio * ratio },
    ]
}

/// The growth's end time for a target packing fraction, as the engine computes it.
fn grown<const D: usize>(
    particles: &[Particle<D>],
    sim_box: SimBox<D>,
    target: f64,
    rate: f64,
    every: u64,
) -> (Simulation<D>, ReferenceSimulation<D>) {
    let mut fast = Simulation::new(particles.to_vec(), sim_box).unwrap();
    fast.grow_to(target, rate, 1.0, every).unwrap();
    let until = fast.growth().unwrap().until;
    let mut slow = ReferenceSimulation::new(particles.to_vec(), sim_box);
    slow.grow(rate, until, 1.0, every).unwrap();
    (fast, slow)
}

/// A compression collides as the growing reference says, bit for bit — through the
/// thermostat's rescalings, the end of the growth and the rigid run after it — in 2D and 3D,
/// periodic and walled, one species and a 1 : 1.4 mixture.
#[test]
fn a_compression_collides_as_the_growing_reference_says() {
    let cases2: [(&str, Vec<Species>, [Boundary; 2]); 3] = [
        ("2D periodic", one(30), [Boundary::Periodic; 2]),
        ("2D walled", one(30), [Boundary::Wall; 2]),
        ("2D mixture, one wall axis", two(40, 1.4), [Boundary::Wall, Boundary::Periodic]),
    ];
    for (label, species, boundary) in cases2 {
        for seed in 0..2 {
            let (particles, sim_box) = system(&species, 0.3, boundary, 10 + seed);
            let (fast, slow) = grown(&particles, sim_box, 0.6, 0.02, 25);
            assert_same_collisions(fast, slow, 2500, &format!("{label}, seed {seed}"));
        }
    }
    let cases3: [(&str, Vec<Species>, [Boundary; 3]); 2] =
        [("3D periodic", one(40), [Boundary::Periodic; 3]), ("3D walled mixture", two(40, 1.4), [Boundary::Wall; 3])];
    for (label, species, boundary) in cases3 {
        let (particles, sim_box) = system(&species, 0.2, boundary, 20);
        let (fast, slow) = grown(&particles, sim_box, 0.45, 0.02, 25);
        assert_same_collisions(fast, slow, 2500, label);
    }
}

/// The neighbourhood adapts as the radii grow: it is rebuilt for each stretch of
/// [`GROWTH_STRETCH`] — lists or the grid, as asked — and the collisions are still the
/// growing reference's, bit for bit, through every rebuild to the end of the growth. The
/// number of stretches is the one the growth law gives (`⌈ln(final/initial radius) /
/// ln(stretch)⌉`, one more where rounding lands a stretch's end a hair short), so a
/// neighbourhood sized once for the final radii (one stretch) would fail here.
#[test]
fn the_neighbourhood_adapts_as_the_radii_grow_and_the_collisions_do_not_change() {
    fn compare<const D: usize>(species: &[Species], eta: f64, target: f64, choice: Neighbourhood, label: &str) {
        let (particles, sim_box) = system(species, eta, [Boundary::Periodic; D], 7);
        let mut fast = Simulation::with_neighbourhood(particles.clone(), sim_box, choice).unwrap();
        fast.grow_to(target, 0.1, 1.0, 40).unwrap();
        let until = fast.growth().unwrap().until;
        let mut slow = ReferenceSimulation::new(particles, sim_box);
        slow.grow(0.1, until, 1.0, 40).unwrap();
        let mut stretches = vec![fast.state().neighbourhood_until.unwrap()];
        let mut listed = 0;
        let mut k = 0;
        while fast.growth().is_some() {
            let outcome = fast.step().expect("an event");
            let state_until = fast.growth().map(|_| fast.state().neighbourhood_until.unwrap());
            if let Some(t) = state_until
                && t != *stretches.last().unwrap()
            {
                assert!(t > *stretches.last().unwrap(), "{label}: the stretches end later and later");
                stretches.push(t);
                listed += !fast.state().centres.is_empty() as usize;
            }
            let Some((i, j)) = outcome.collided() else { continue };
            let expected = slow.step().expect("a collision");
            assert_eq!(
                (fast.time().to_bits(), i, j),
                (expected.0.to_bits(), expected.1, expected.2),
                "{label}, collision {k}"
            );
            k += 1;
        }
        let growth = (target / eta).powf(1.0 / D as f64);
        let expected = (growth.ln() / GROWTH_STRETCH.ln()).ceil() as usize;
        assert!(
            stretches.len() == expected || stretches.len() == expected + 1,
            "{label}: {} stretches for a growth by {growth}, {expected} expected",
            stretches.len()
        );
        assert_eq!(*stretches.last().unwrap(), until, "{label}: the last stretch ends with the growth");
        match choice {
            Neighbourhood::Lists => assert_eq!(listed, stretches.len() - 1, "{label}: lists in every stretch"),
            _ => assert_eq!(listed, 0, "{label}: the grid in every stretch"),
        }
        assert!(k > 1000, "{label}: only {k} collisions");
    }
    compare::<2>(&one(120), 0.2, 0.7, Neighbourhood::Lists, "disks, lists");
    compare::<2>(&two(120, 1.4), 0.2, 0.7, Neighbourhood::Grid, "mixed disks, grid");
    compare::<3>(&one(150), 0.15, 0.45, Neighbourhood::Lists, "spheres, lists");
}

/// The comparison above passes through the end of the growth: here the same runs stop just
/// after it and both engines hold the same particles, to the bit, with the radii frozen at
/// the target packing fraction (to rounding), no overlap beyond rounding, and kT within the
/// thermostat's reach of its target.
#[test]
fn the_growth_ends_at_the_target_in_both_engines() {
    let (particles, sim_box) = system(&two(40, 1.4), 0.3, [Boundary::Periodic; 2], 3);
    let (mut fast, mut slow) = grown(&particles, sim_box, 0.7, 0.05, 40);
    let until = fast.growth().unwrap().until;
    let mut collisions = 0;
    loop {
        match fast.step().expect("an event") {
            Outcome::GrowthEnd => break,
            outcome if outcome.collided().is_some() => collisions += 1,
            _ => {}
        }
    }
    assert_eq!(fast.time(), until);
    assert!(fast.growth().is_none());
    assert!(collisions > 1000, "only {collisions} collisions during the growth");
    // The reference has done the same collisions; its next one is after the end.
    for _ in 0..collisions {
        slow.step().unwrap();
    }
    assert!(slow.growth.is_some());
    let next = slow.step().unwrap();
    assert!(next.0 >= until && slow.growth.is_none());
    let phi = fast.packing_fraction();
    assert!((phi - 0.7).abs() <= 1e-12, "packing fraction {phi}");
    for (a, b) in fast.particles().iter().zip(&particles) {
        assert_eq!(a.radius / b.radius, fast.particles()[0].radius / particles[0].radius);
    }
    let audit = fast.check_overlaps();
    assert!(audit.fraction <= 1e-12, "overlap {audit:?}");
    // Rescaled every 40 collisions: kT drifts by the energy of at most 40 growing
    // collisions between rescalings, a few per cent at this rate.
    let kt = fast.kt();
    assert!((kt - 1.0).abs() < 0.1, "kT = {kt}");
}

/// A checkpoint taken during a compression resumes to the same collisions and the same end.
#[test]
fn a_compression_resumes_bit_identically_from_its_checkpoint() {
    let (particles, sim_box) = system(&one(60), 0.3, [Boundary::Wall, Boundary::Periodic], 5);
    let (mut whole, _) = grown(&particles, sim_box, 0.65, 0.05, 30);
    for _ in 0..1500 {
        whole.step().unwrap();
    }
    assert!(whole.growth().is_some(), "the checkpoint must fall inside the growth");
    let text = serde_json::to_string(&whole.state()).unwrap();
    let state: SimulationState<2> = serde_json::from_str(&text).unwrap();
    assert!(state.growth.is_some() && state.neighbourhood_until.is_some());
    // A checkpoint written before the neighbourhood adapted (no `neighbourhood_until`, the
    // grid) resumes too, with the grid sized for the final radii: the same collisions.
    let mut old = state.clone();
    old.neighbourhood_until = None;
    assert!(old.centres.is_empty(), "this run keeps the grid");
    let mut resumed = Simulation::restore(state, sim_box).unwrap();
    let mut resumed_old = Simulation::restore(old, sim_box).unwrap();
    let mut ended = false;
    let mut collisions = Vec::new();
    for k in 0..4000 {
        let (a, b) = (whole.step().unwrap(), resumed.step().unwrap());
        assert_eq!((whole.time().to_bits(), a.collided()), (resumed.time().to_bits(), b.collided()), "event {k}");
        ended |= a == Outcome::GrowthEnd;
        if let Some(pair) = a.collided() {
            collisions.push((whole.time().to_bits(), pair));
        }
    }
    assert!(ended, "the growth should end within the comparison");
    assert_eq!(whole.particles(), resumed.particles());
    // The old checkpoint's run has other cell crossings, and the same collisions.
    for (k, expected) in collisions.iter().enumerate() {
        let pair = loop {
            if let Some(pair) = resumed_old.step().unwrap().collided() {
                break pair;
            }
        };
        assert_eq!((resumed_old.time().to_bits(), pair), *expected, "collision {k} after the old checkpoint");
    }
}

/// Small systems, walls and a 1 : 10 size ratio compress without trouble: periodic axes too
/// short for one image per pair (searched over the neighbouring images), and a grid sized
/// for the large particles.
#[test]
fn small_systems_and_large_size_ratios_compress() {
    for (label, species, eta, target) in [
        ("N = 12", one(12), 0.3, 0.75),
        ("N = 50, 1:10", two(50, 0.1), 0.2, 0.6),
        ("N = 50, 1:1.4", two(50, 1.4), 0.3, 0.8),
    ] {
        let (particles, sim_box) = system(&species, eta, [Boundary::Periodic; 2], 1);
        let mut sim = Simulation::new(particles, sim_box).unwrap();
        sim.grow_to(target, 0.02, 1.0, 50).unwrap();
        while sim.growth().is_some() {
            sim.step().expect("an event");
        }
        let phi = sim.packing_fraction();
        assert!((phi - target).abs() <= 1e-12, "{label}: φ = {phi}");
        assert!(sim.check_overlaps().fraction <= 1e-12, "{label}: {:?}", sim.check_overlaps());
        for _ in 0..1000 {
            sim.step();
        }
        assert!(sim.check_overlaps().fraction <= 1e-12, "{label}, after: {:?}", sim.check_overlaps());
    }
    let (particles, sim_box) = system(&one(30), 0.2, [Boundary::Wall; 3], 2);
    let mut sim = Simulation::new(particles, sim_box).unwrap();
    sim.grow_to(0.4, 0.05, 1.0, 30).unwrap();
    while sim.growth().is_some() {
        sim.step().expect("an event");
    }
    assert_eq!(sim.growth_ending(), Some(Ending::Reached));
    assert!(sim.check_overlaps().fraction <= 1e-12, "3D walls: {:?}", sim.check_overlaps());
}

/// A target beyond jamming (30 spheres in a walled box some three diameters wide jam near
/// φ ≈ 0.47 at this rate) ends where the clock stalls — jammed, no overlap beyond rounding —
/// instead of hanging; the reference stalls at the same collision. (The packing is then
/// jammed for rigid dynamics too: its pressure is infinite, and a run stops there.)
#[test]
fn a_target_beyond_jamming_ends_jammed_instead_of_hanging() {
    let (particles, sim_box) = system(&one(30), 0.2, [Boundary::Wall; 3], 2);
    let (mut fast, mut slow) = grown(&particles, sim_box, 0.6, 0.05, 30);
    let mut collisions = 0u64;
    while fast.growth().is_some() {
        if fast.step().expect("an event").collided().is_some() {
            collisions += 1;
        }
    }
    assert_eq!(fast.growth_ending(), Some(Ending::Stalled));
    let phi = fast.packing_fraction();
    assert!(phi > 0.4 && phi < 0.55, "jammed at φ = {phi}");
    assert!(fast.check_overlaps().fraction <= 1e-12, "{:?}", fast.check_overlaps());
    for _ in 0..collisions {
        slow.step().unwrap();
    }
    assert!(slow.growth.is_none(), "the reference stalls at the same collision");
    for (a, b) in fast.particles().iter().zip(&slow.particles) {
        assert_eq!(a.radius.to_bits(), b.radius.to_bits());
        assert_eq!(a.velocity, b.velocity);
    }
}

/// A growth that cannot start says why.
#[test]
fn a_growth_that_cannot_start_is_refused_with_the_reason() {
    let (particles, sim_box) = system(&one(20), 0.3, [Boundary::Periodic; 2], 4);
    let mut sim = Simulation::new(particles, sim_box).unwrap();
    let message = |r: Result<(), collide::engine::SetupError>| r.unwrap_err().to_string();
    assert!(message(sim.grow(0.0, 1.0, 1.0, 10)).contains("rate = 0"));
    assert!(message(sim.grow(0.1, -1.0, 1.0, 10)).contains("until = -1"));
    assert!(message(sim.grow_to(0.2, 0.1, 1.0, 10)).contains("must exceed the present one"));
    // Grown to diameters beyond half the box: refused before anything moves.
    let l = sim.sim_box().lengths[0];
    assert!(message(sim.grow(0.1, 10.0 * l, 1.0, 10)).contains("too short"));
    sim.grow_to(0.4, 0.1, 1.0, 10).unwrap();
    assert!(message(sim.grow_to(0.5, 0.1, 1.0, 10)).contains("already under way"));
}

/// Compressed until the clock stalls, a 50:50 mixture of disks with diameter ratio 1.4
/// jams near φ_J ≈ 0.84 (O'Hern, Silbert, Liu & Nagel, PRE 68, 011306 (2003): 0.84 for
/// N → ∞; small N and fast compressions spread it by about ±0.02, hence the window), with no
/// overlap beyond rounding. Its contact network, once the rattlers are removed, is stable
/// over six decades of tolerance (10⁻¹²…10⁻⁶: the gaps of contacts and of non-contacts are
/// that far apart), and it is not hyperstatic: a generic frictionless packing has at most
/// `2d` contacts per particle (less `2/N′` for the free translations of a periodic box).
/// (Measured at this seed: φ_J = 0.8438, z = 3.80 — a stalled compression's backbone is
/// slightly hypostatic; the isostatic value itself is the jamming experiment's check, after
/// compressing to a reduced-pressure limit.)
#[test]
fn a_bidisperse_packing_jams_near_the_known_density() {
    let (particles, sim_box) = system(&two(200, 1.4), 0.5, [Boundary::Periodic; 2], 8);
    let mut sim = Simulation::new(particles, sim_box).unwrap();
    sim.grow_to(0.9, 0.01, 1.0, 200).unwrap();
    while sim.growth().is_some() {
        sim.step().expect("an event");
    }
    assert_eq!(sim.growth_ending(), Some(Ending::Stalled));
    let phi = sim.packing_fraction();
    assert!((0.82..0.86).contains(&phi), "φ_J = {phi}");
    assert!(sim.check_overlaps().fraction <= 1e-12, "{:?}", sim.check_overlaps());
    let tight = collide::observe::contacts::contacts(&sim, 1e-12);
    let loose = collide::observe::contacts::contacts(&sim, 1e-6);
    assert_eq!(tight.rattlers, loose.rattlers);
    assert!(
        loose.held_contacts - tight.held_contacts <= 2,
        "{} and {} contacts",
        tight.held_contacts,
        loose.held_contacts
    );
    let held = (200 - tight.rattlers.len()) as f64;
    let isostatic = 4.0 * (1.0 - 1.0 / held) + 2.0 / held;
    assert!(tight.contacts_per_particle <= isostatic + 1e-9, "z = {}", tight.contacts_per_particle);
    assert!(tight.contacts_per_particle > 3.5 && tight.rattlers.len() < 40, "{tight:?}");
}
