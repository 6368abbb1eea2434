//! The divided box against the whole box: the same events, markers and counts, bit for
//! bit, with particles crossing between the slabs — in 2D and 3D, periodic and walled, one
//! size and a mixture, with lists and with the grid.

use super::*;
use crate::engine::init::{Placement, Species, Velocities, box_for_packing_fraction, initial_particles};
use crate::engine::{Boundary, Neighbourhood};

/// The whole box and the divided one from the same start, with `neighbourhood`.
fn whole_and_divided<const D: usize>(
    particles: Vec<Particle<D>>,
    sim_box: SimBox<D>,
    neighbourhood: Neighbourhood,
) -> (Simulation<D>, Divided<D>) {
    let params = EngineParams::with_neighbourhood(neighbourhood);
    let whole = Simulation::with_params(particles.clone(), sim_box.clone(), params).expect("a valid start");
    (whole, Divided::with_params(particles, sim_box, params).expect("a valid start"))
}

/// 300 spheres and 200 smaller, lighter ones at η = 0.3, walls on every axis, in a box six
/// times as long on the axis divided as on the others.
fn walled_mixture() -> (Vec<Particle<3>>, SimBox<3>) {
    let species = [Species { count: 300, radius: 0.5, mass: 1.0 }, Species { count: 200, radius: 0.3, mass: 0.4 }];
    let sim_box =
        box_for_packing_fraction::<3>(&species, 0.3, [Boundary::Wall; 3], Placement::Random, Some([6.0, 1.0, 1.0]));
    let particles = initial_particles(&species, &sim_box, Placement::Random, Velocities::Maxwell, 1.0, 4).unwrap();
    (particles, sim_box)
}

/// Runs `steps` events of the whole box and the divided one side by side: every outcome
/// equal, then the counts (re-prediction markers included) and the particles; the
/// replicas agree; both slabs hold particles, and some changed side. Returns how many did.
fn same_events<const D: usize>(
    particles: Vec<Particle<D>>,
    sim_box: SimBox<D>,
    neighbourhood: Neighbourhood,
    steps: u64,
) -> usize {
    let (mut whole, mut divided) = whole_and_divided(particles, sim_box, neighbourhood);
    let start = divided.sides[0].region.as_deref().expect("divided").owner.clone();
    assert!(divided.sides().iter().all(|&n| n > 0), "{:?}", divided.sides());
    for k in 0..steps {
        let (a, b) = (whole.step(), divided.step());
        assert_eq!(a, b, "event {k}");
        assert!(a.is_some(), "events go on");
    }
    assert_eq!(whole.counts(), divided.counts());
    assert!(whole.counts().stale > 0, "markers were exercised");
    assert_eq!(whole.particles(), &divided.particles()[..]);
    assert_eq!(whole.time(), divided.time());
    assert!(divided.replicas_agree());
    // Each side's own rows are exact (the rows of the other's it leaves out of date).
    for side in &divided.sides {
        side.neighbours.check_among(|k| side.owns(k));
    }
    // Each side holds the states of some of the other's particles, not all.
    let (known, sides) = (divided.known(), divided.sides());
    assert!(known[0] > 0 && known[0] < sides[1] && known[1] > 0 && known[1] < sides[0], "{known:?} of {sides:?}");
    let end = &divided.sides[1].region.as_deref().expect("divided").owner;
    let moved = start.iter().zip(end).filter(|(a, b)| a != b).count();
    assert!(moved > 0, "no particle changed side");
    moved
}

fn bench_start<const D: usize>(n: usize, eta: f64) -> (Vec<Particle<D>>, SimBox<D>) {
    crate::bench::state::initial_state::<D>(n, eta, 5).expect("a benchmark start")
}

#[test]
fn spheres_at_the_benchmark_density() {
    for neighbourhood in [Neighbourhood::Lists, Neighbourhood::Grid] {
        let (particles, sim_box) = bench_start::<3>(10_976, 0.45);
        same_events(particles, sim_box, neighbourhood, 200_000);
    }
}

#[test]
fn dense_disks() {
    for neighbourhood in [Neighbourhood::Lists, Neighbourhood::Grid] {
        let (particles, sim_box) = bench_start::<2>(2000, 0.65);
        same_events(particles, sim_box, neighbourhood, 200_000);
    }
}

/// Walls on every axis (so on the axis divided) and two species of unequal size and mass,
/// in boxes long on the axis divided.
#[test]
fn walled_mixtures() {
    let (particles, sim_box) = walled_mixture();
    same_events(particles, sim_box, Neighbourhood::Lists, 100_000);
    let species = [Species { count: 300, radius: 0.5, mass: 1.0 }, Species { count: 200, radius: 0.3, mass: 0.4 }];
    let sim_box =
        box_for_packing_fraction::<2>(&species, 0.5, [Boundary::Wall; 2], Placement::Random, Some([4.0, 1.0]));
    let particles = initial_particles(&species, &sim_box, Placement::Random, Velocities::Maxwell, 1.0, 4).unwrap();
    same_events(particles, sim_box, Neighbourhood::Grid, 100_000);
}

/// Two threads, changes applied on arrival: the first side to resolve the events asked of
/// it stops the other, the two tell each other what changed (some of it in the receiver's
/// past, as the sides run at once), and the measure is a rate; once both have applied
/// everything, every particle is one side's. Checked to fail: with the sending left out,
/// nothing is received; without applying what was sent after a side stopped, particles in
/// hand-over were disowned (in one run of three); at N = 2048, where nearly everything is
/// near a border, a side runs out of events.
#[test]
fn two_threads_unordered() {
    let (particles, sim_box) = bench_start::<3>(10_976, 0.45);
    let run = Divided::new(particles, sim_box).expect("a valid start").run_unordered(100_000, Lead::Free);
    assert!(run.stops.contains(&Stop::Reached) && !run.stops.contains(&Stop::RanOut), "{run:?}");
    assert_eq!(run.events.iter().max(), Some(&100_000), "{run:?}");
    assert!(run.events.iter().all(|&e| e > 50_000), "{run:?}");
    assert_eq!((run.not_numbers, run.disowned), ([0; 2], 0), "{run:?}");
    assert!(run.received.iter().all(|&r| r > 5_000), "{run:?}");
    let ordered = |a: &[u64; 2], b: &[u64; 2]| a.iter().zip(b).all(|(x, y)| x <= y);
    assert!(ordered(&run.conflicts, &run.late) && ordered(&run.late, &run.received), "{run:?}");
    let quiet = [run.late[0] - run.conflicts[0], run.late[1] - run.conflicts[1]];
    assert!(ordered(&run.overtaken, &quiet), "{run:?}");
    assert!(run.seconds.iter().all(|&s| s > 0.0) && run.rate().is_finite(), "{run:?}");
}

/// Held within a lead of two of the whole box's mean times between events, the sides'
/// last events lie within the lead and a few more such times of each other (an item is
/// taken only within the lead of the other side's next as last read; the gaps seen were
/// 0.3–7.6 of those times), and the sides stood waiting. Checked to fail: free, the same
/// start ended with the last events 20 to 860 such times apart in six runs (beyond the
/// bound in five), and no side ever waits.
#[test]
fn two_threads_within_a_lead() {
    let (particles, sim_box) = bench_start::<3>(10_976, 0.45);
    let mut whole = Simulation::new(particles.clone(), sim_box.clone()).expect("a valid start");
    for _ in 0..50_000 {
        whole.step().expect("events go on");
    }
    let interval = whole.time() / 50_000.0;
    let lead = 2.0 * interval;
    let run = Divided::new(particles, sim_box).expect("a valid start").run_unordered(100_000, Lead::Within(lead));
    assert!(!run.stops.contains(&Stop::RanOut) && run.not_numbers == [0; 2], "{run:?}");
    assert!((run.clocks[0] - run.clocks[1]).abs() < lead + 30.0 * interval, "{run:?}, lead {lead}");
    assert!(run.held_back.iter().any(|&h| h > 0), "{run:?}");
}

/// A late change meets a read exactly when the changed particle, or one whose searches
/// read it, was read after the change's time: not at the time itself, not before, and not
/// by a particle out of range. Checked to fail: with the range left out (a particle in the
/// cells around, out of range, met it), with the changed particle's own read at the
/// change's time counted, and with the cells' filter turned round.
#[test]
fn late_changes_meet_the_reads_since() {
    let (particles, sim_box) = bench_start::<3>(2048, 0.45);
    let sim = Simulation::new(particles, sim_box).expect("a valid start");
    let neighbours = &sim.neighbours;
    let n = sim.particles.len();
    let k = 7;
    let reader = neighbours.candidates(k).find(|&i| i != k && neighbours.searches(i, k)).expect("a neighbour");
    let far = (0..n)
        .find(|&i| {
            neighbours
                .cells_around(k)
                .as_slice()
                .iter()
                .all(|&c| neighbours.cells().members(c).all(|m| m as usize != i))
        })
        .expect("a far particle");
    let beside = neighbours
        .cells_around(k)
        .as_slice()
        .iter()
        .flat_map(|&c| neighbours.cells().members(c))
        .map(|m| m as usize)
        .find(|&i| !neighbours.searches(i, k))
        .expect("a particle in the cells around, out of range");
    let fresh = || Watch::new(n, neighbours.cell_count());
    let cases = [(k, 2.0, true), (k, 1.0, false), (reader, 2.0, true), (reader, 1.0, false), (reader, 0.5, false)];
    for (who, at, meets) in cases.into_iter().chain([(beside, 2.0, false), (far, 2.0, false)]) {
        let mut watch = fresh();
        watch.stamp(neighbours, who, at);
        assert_eq!(watch.read_since(neighbours, k, 1.0), meets, "read of {who} at {at}");
    }
}

/// Everything an undo has to give back of a side, written out: particles (bits, the far
/// ones' `NaN`s included), pending events, anchors and sides, centres, crowded particles,
/// every row's entries in their order, the grid's coordinates, the clock, the counts and
/// the changes told. Where a particle sits in its cell's chain is left out: an undo does
/// not restore it, and no search reads it.
fn fingerprint<const D: usize>(side: &Simulation<D>) -> String {
    let region = side.region.as_deref().expect("divided");
    let rows: Vec<Vec<u32>> = (0..side.particles.len())
        .map(|k| side.neighbours.row(k).map_or_else(Vec::new, |r| r.entries().collect()))
        .collect();
    let coords = if side.neighbours.listed() { Vec::new() } else { side.neighbours.cells().coords().to_vec() };
    format!(
        "{:?}",
        (
            &side.particles,
            side.queue.pending(),
            (&region.anchor, &region.owner, region.told),
            side.neighbours.save(),
            rows,
            coords,
            side.time.to_bits(),
            side.counts
        )
    )
}

/// Recording, a divided box is run in stretches of different lengths (1 to about 4000
/// events, from a fixed seed): at each stretch's start a mark; after it, an undo back to
/// the mark must give both sides back exactly as they were (`fingerprint`), and the
/// stretch run again must give the same events bit for bit — which are the whole box's.
/// Returns the records the longest stretch took per event.
fn undo_replays<const D: usize>(
    particles: Vec<Particle<D>>,
    sim_box: SimBox<D>,
    neighbourhood: Neighbourhood,
    stretches: usize,
) -> f64 {
    use rand::{RngExt, SeedableRng};
    let (mut whole, mut divided) = whole_and_divided(particles, sim_box, neighbourhood);
    let mut rng = rand::rngs::StdRng::seed_from_u64(11);
    let (mut most, mut rebuilds) = (0.0f64, 0);
    for stretch in 0..stretches {
        // Forget what came before: only the stretch is undone.
        divided.record(true);
        let before = divided.sides.each_ref().map(fingerprint);
        let mark = divided.mark();
        let len = if stretch % 5 == 0 { rng.random_range(1..20) } else { rng.random_range(500..4000) };
        let first: Vec<_> = (0..len).map(|_| divided.step()).collect();
        let records: usize = divided.sides.iter().map(|s| s.records()).sum();
        most = most.max(records as f64 / len as f64);
        divided.undo_to(mark);
        let after = divided.sides.each_ref().map(fingerprint);
        assert!(before == after, "stretch {stretch}: the undo did not give the sides back");
        let again: Vec<_> = (0..len).map(|_| divided.step()).collect();
        assert_eq!(first, again, "stretch {stretch}: replayed after the undo");
        let reference: Vec<_> = (0..len).map(|_| whole.step()).collect();
        assert_eq!(again, reference, "stretch {stretch}: the whole box's");
        rebuilds += again.iter().filter(|o| matches!(o, Some(Outcome::Rebuild { .. }))).count();
    }
    assert!(rebuilds > 0 && whole.counts().stale > 0, "rebuilds and markers were undone");
    most
}

/// Undone and replayed, bit for bit: spheres at the benchmark's density with lists and
/// with the grid, dense disks, and a walled mixture. Checked to fail with the neighbourhood's
/// records left untaken, with the pending events', with the anchors', and with a batch's
/// records left out.
#[test]
fn undone_events_replay_bit_for_bit() {
    for neighbourhood in [Neighbourhood::Lists, Neighbourhood::Grid] {
        let (particles, sim_box) = bench_start::<3>(10_976, 0.45);
        undo_replays(particles, sim_box, neighbourhood, 25);
        let (particles, sim_box) = bench_start::<2>(2000, 0.65);
        undo_replays(particles, sim_box, neighbourhood, 25);
    }
    let (particles, sim_box) = walled_mixture();
    let per_event = undo_replays(particles, sim_box, Neighbourhood::Lists, 25);
    assert!(per_event < 20.0, "{per_event} records an event");
}

/// Runs the whole box through its items before the time of its `events`-th event, and the
/// divided box to the same end in two threads in the order of time: the same particles to
/// the bit, the same counts (markers included), replicas that agree; then both go on event
/// for event. Returns what the ordered run counted.
fn ordered_matches<const D: usize>(
    particles: Vec<Particle<D>>,
    sim_box: SimBox<D>,
    neighbourhood: Neighbourhood,
    events: u64,
    lead: Lead,
) -> Ordered {
    let (mut whole, divided) = whole_and_divided(particles, sim_box, neighbourhood);
    let mut probe = whole.clone();
    for _ in 0..events {
        probe.step();
    }
    let end = probe.time;
    while whole.queue.first().1.time < end {
        whole.take();
    }
    // In a thread of its own, watched: a schedule that loses track of its batches never
    // ends, and the test should fail, not hang (the run takes well under a second).
    let (done, finished) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        let mut divided = divided;
        let run = divided.run_ordered(end, lead);
        done.send((divided, run)).expect("the test waits");
    });
    let (divided, run) = finished
        .recv_timeout(std::time::Duration::from_secs(60))
        .expect("the ordered run did not end within a minute: sent and applied batches never met");
    assert_eq!(whole.counts(), divided.counts(), "{run:?}");
    let particles = divided.particles();
    for (k, p) in whole.particles.iter().enumerate() {
        assert_eq!(*p, particles[k], "particle {k} after {run:?}");
    }
    assert!(divided.replicas_agree(), "{run:?}");
    let mut divided = divided;
    for k in 0..5000 {
        assert_eq!(whole.step(), divided.step(), "event {k} after the ordered run");
    }
    run
}

/// Two threads in the order of time give the whole box's events bit for bit: spheres and
/// disks, lists and the grid, free and held within a lead, from many schedules (the
/// threads' timing differs from run to run; each run's late batches and conflicts are
/// counted, and some must have been undone, so the undoing is exercised).
#[test]
fn two_threads_in_order() {
    let mut undone = 0;
    for round in 0..3 {
        for (neighbourhood, lead) in [
            (Neighbourhood::Lists, Lead::Free),
            (Neighbourhood::Lists, Lead::Within(0.05)),
            (Neighbourhood::Grid, Lead::Free),
        ] {
            let (particles, sim_box) = bench_start::<3>(2048, 0.45);
            let run = ordered_matches(particles, sim_box, neighbourhood, 100_000, lead);
            eprintln!("round {round} {neighbourhood:?} {lead:?}: {run:?}");
            undone += run.undone[0] + run.undone[1];
        }
        let (particles, sim_box) = bench_start::<2>(2000, 0.65);
        let run = ordered_matches(particles, sim_box, Neighbourhood::Lists, 100_000, Lead::Free);
        eprintln!("round {round} disks: {run:?}");
        undone += run.undone[0] + run.undone[1];
        let (particles, sim_box) = walled_mixture();
        ordered_matches(particles, sim_box, Neighbourhood::Lists, 50_000, Lead::Free);
    }
    assert!(undone > 0, "nothing was undone");
}
