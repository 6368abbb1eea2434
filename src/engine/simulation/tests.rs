//! The engine's own tests: its two searches, its neighbourhoods, its two queues, its saved
//! states, its counters and its lookahead, each against the other way of doing the same.

use super::*;
use rand::rngs::Xoshiro256PlusPlus;
use rand::{RngExt, SeedableRng};

/// A jittered grid of `side²` disks of radius 0.1 at spacing 0.25 (η ≈ 0.5), with
/// pseudo-random velocities; with `big`, one disk of radius 1 in the middle (the small
/// ones it would overlap removed), which makes the cells two wide, so that a prediction
/// sees far more than NEAR neighbours.
fn system(side: usize, big: bool, neighbourhood: Neighbourhood) -> Simulation<2> {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(7);
    let mut unit = move || rng.random_range(-0.5..0.5);
    let (spacing, l) = (0.25, side as f64 * 0.25);
    let centre = SVector::from([l / 2.0, l / 2.0]);
    let disk = |position, radius: f64, velocity| Particle {
        position,
        velocity,
        time: 0.0,
        radius,
        mass: radius * radius,
        species: 0,
        events: 0,
    };
    let mut particles: Vec<Particle<2>> = Vec::new();
    if big {
        particles.push(disk(centre, 1.0, SVector::from([0.3, -0.2])));
    }
    for k in 0..side * side {
        let (x, y) = ((k % side) as f64, (k / side) as f64);
        let position = SVector::from([(x + 0.5 + 0.1 * unit()) * spacing, (y + 0.5 + 0.1 * unit()) * spacing]);
        let velocity = SVector::from([unit(), unit()]);
        if !big || (position - centre).norm() > 1.15 {
            particles.push(disk(position, 0.1, velocity));
        }
    }
    let sim_box = SimBox { lengths: SVector::from([l, l]), boundary: [Boundary::Periodic; 2] };
    Simulation::with_neighbourhood(particles, sim_box, neighbourhood).expect("a valid system")
}

/// The batch search (neighbours bracketed LANES at a time, branch-free) and the scalar
/// search (one pair at a time, with a shrinking horizon) must give the same events bit
/// for bit — including with the big disk, where predictions see more than NEAR
/// neighbours and the batch hands over to the scalar search: only the order in which
/// the pairs are searched differs, and the result is the minimum in a total order.
#[test]
fn batch_and_scalar_searches_give_identical_events() {
    for (big, neighbourhood) in
        [(false, Neighbourhood::Grid), (true, Neighbourhood::Grid), (false, Neighbourhood::Lists)]
    {
        let batch = system(40, big, neighbourhood);
        assert_eq!(batch.lists(), neighbourhood == Neighbourhood::Lists);
        assert!(batch.search.batch);
        let batch = runs_as_the_scalar_search(batch, 20_000);
        assert!(batch.counts().pair > 10_000, "{:?}", batch.counts());
    }
}

/// Runs `batch` (a simulation with the batch search) for `steps` steps beside a copy that
/// searches one pair at a time, every particle predicted again that way as if it had been
/// on from the start, and asserts the same events at the same times and the same particles
/// at the end, bit for bit. Returns the batch run, for its counts.
fn runs_as_the_scalar_search<const D: usize>(mut batch: Simulation<D>, steps: usize) -> Simulation<D> {
    let mut scalar = batch.clone();
    scalar.search.batch = false;
    for i in 0..scalar.particles.len() {
        scalar.predict(i);
    }
    for _ in 0..steps {
        assert_eq!(batch.step(), scalar.step());
        assert_eq!(batch.time().to_bits(), scalar.time().to_bits());
    }
    assert_eq!(batch.particles(), scalar.particles());
    batch
}

/// Spheres, and a mixture: the batch search (both partners of a collision side by side,
/// `Search::bracket_both`) and the scalar search, one pair at a time, must give the same
/// events bit for bit. Every third sphere is a tenth smaller, so that a lane taking the
/// wrong particle's radius (or position, or clock) would change a contact time.
#[test]
fn batch_and_scalar_searches_give_identical_events_for_spheres() {
    let (mut particles, sim_box) = crate::bench::state::initial_state::<3>(500, 0.45, 5).expect("a state");
    for p in particles.iter_mut().step_by(3) {
        p.radius *= 0.9;
    }
    let batch = Simulation::with_neighbourhood(particles, sim_box, Neighbourhood::Lists).expect("a simulation");
    assert!(batch.search.batch && batch.neighbours.listed());
    let batch = runs_as_the_scalar_search(batch, 30_000);
    assert!(batch.counts().pair > 20_000, "{:?}", batch.counts());
}

/// A gas at rest has nothing to do: every prediction's bound is +∞, which the padding of
/// a chunk of lanes also brackets to; those lanes hold no neighbour and must not be taken
/// for candidates (they once were, and indexed the particles with a list's end marker).
/// With one disk moving, only its own collisions happen.
#[test]
fn a_gas_at_rest_stays_at_rest() {
    for neighbourhood in [Neighbourhood::Grid, Neighbourhood::Lists] {
        let moving = system(20, false, neighbourhood);
        let still: Vec<Particle<2>> =
            moving.particles.iter().map(|p| Particle { velocity: SVector::zeros(), ..p.clone() }).collect();
        let mut sim = Simulation::with_neighbourhood(still.clone(), moving.sim_box, neighbourhood).expect("valid");
        assert_eq!(sim.lists(), neighbourhood == Neighbourhood::Lists);
        assert_eq!(sim.step(), None);
        let mut one = still;
        one[7].velocity = SVector::from([0.3, 0.1]);
        let mut sim = Simulation::with_neighbourhood(one, moving.sim_box, neighbourhood).expect("valid");
        let first = loop {
            match sim.step() {
                Some(Outcome::Rebuild { .. }) => continue,
                other => break other,
            }
        };
        match first {
            Some(Outcome::Pair { i, j, .. }) => assert!(i == 7 || j == 7, "{i} {j}"),
            other => panic!("{other:?}"),
        }
    }
}

/// The collisions (pairs and walls) of a run, with their times, and nothing else.
fn collisions(
    sim: &mut Simulation<2>,
    count: usize,
    mut between: impl FnMut(&Simulation<2>),
) -> Vec<(u64, usize, usize)> {
    let mut out = Vec::with_capacity(count);
    while out.len() < count {
        if let Some((i, j)) = sim.step().expect("a live gas").collided() {
            out.push((sim.time().to_bits(), i, j));
        }
        between(sim);
    }
    out
}

/// The neighbour lists (on for this η ≈ 0.5 system) stay what they are defined to be —
/// `j` on `i`'s list exactly when their centres are within range — through many
/// rebuilds, and the collisions are those of the grid that follows the particles, bit
/// for bit.
#[test]
fn lists_keep_their_definition_and_the_collisions_of_the_grid() {
    let listed = system(40, false, Neighbourhood::Lists);
    assert!(listed.neighbours.listed());
    let mut grid = listed.clone();
    let reach = 2.0 * grid.particles.iter().map(|p| p.radius).fold(0.0, f64::max);
    grid.neighbours = Neighbours::following(&grid.sim_box, reach, &grid.particles, &crate::engine::arrays::Plain);
    grid.predict_everyone();
    assert!(!grid.neighbours.listed());
    let (mut listed, mut checks) = (listed, 0);
    let a = collisions(&mut listed, 20_000, |sim| {
        if sim.counts().pair % 1000 == 0 {
            sim.neighbours.check();
            checks += 1;
        }
    });
    let b = collisions(&mut grid, 20_000, |_| {});
    assert_eq!(a, b);
    assert_eq!(listed.particles(), grid.particles());
    assert!(checks >= 20, "{checks}");
    assert!(listed.counts().rebuild > 1000, "{:?}", listed.counts());
}

/// A saved state (through its JSON form) continues exactly as the run it came from, with
/// lists (η ≈ 0.5) and with the grid that follows the particles (η ≈ 0.13).
#[test]
fn saved_states_continue_bit_identically_in_both_neighbourhoods() {
    let sparse = {
        let dense = system(40, false, Neighbourhood::Grid);
        let particles = dense.particles.iter().map(|p| Particle { radius: 0.05, ..p.clone() }).collect();
        Simulation::new(particles, dense.sim_box).expect("a valid system")
    };
    for (mut sim, listed) in [(system(40, false, Neighbourhood::Lists), true), (sparse, false)] {
        assert_eq!(sim.neighbours.listed(), listed);
        collisions(&mut sim, 5_000, |_| {});
        let json = serde_json::to_string(&sim.state()).expect("serializable");
        let state: SimulationState<2> = serde_json::from_str(&json).expect("readable");
        assert_eq!((state.cells.is_empty(), state.centres.is_empty()), (listed, !listed));
        let mut resumed = Simulation::restore(state, sim.sim_box).expect("a consistent state");
        let (a, b) = (collisions(&mut sim, 5_000, |_| {}), collisions(&mut resumed, 5_000, |_| {}));
        assert_eq!(a, b);
        assert_eq!(sim.counts(), resumed.counts());
    }
}

/// A saved state whose centres do not fit the particles is refused, not run.
#[test]
fn a_state_with_a_particle_outside_its_skin_is_refused() {
    let sim = system(20, false, Neighbourhood::Lists);
    let mut state = sim.state();
    state.centres[3][0] += 0.15;
    let err = Simulation::restore(state, sim.sim_box).expect_err("outside its skin");
    assert!(err.to_string().contains("particle 3 is outside its skin"), "{err}");
}

/// Event counters are 32-bit and wrap: with every counter started a few events short of
/// the wrap, the collisions are those of the same system counting from 0, and right
/// after any counter wraps no pending event holds a count its partner no longer has
/// (without the re-prediction, events predicted before the wrap would).
#[test]
fn wrapping_event_counters_change_nothing() {
    let plain = system(40, false, Neighbourhood::Auto);
    let mut wrapping = plain.clone();
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(3);
    for p in &mut wrapping.particles {
        p.events = u32::MAX - rng.random_range(0..30);
    }
    wrapping.predict_everyone();
    let (mut plain, mut wraps) = (plain, 0);
    for _ in 0..20_000 {
        let collision = |o: Option<Outcome<2>>| o.and_then(|o| o.collided());
        let expected = loop {
            if let Some(c) = collision(plain.step()) {
                break (c, plain.time().to_bits());
            }
        };
        let got = loop {
            if let Some(c) = collision(wrapping.step()) {
                break (c, wrapping.time().to_bits());
            }
        };
        assert_eq!(got, expected);
        let ((i, j), _) = got;
        if wrapping.particles[i].events == 0 || wrapping.particles[j].events == 0 {
            wraps += 1;
            for e in wrapping.queue.pending() {
                if let EventKind::Pair { partner, partner_events } = e.kind {
                    assert_eq!(partner_events, wrapping.particles[partner as usize].events);
                }
            }
        }
    }
    assert!(wraps > 1000, "{wraps} wraps");
}

/// The two queue structures give the same run, bit for bit, with the grid and with
/// lists (the calendar is chosen below 3·2¹⁴ particles, the tree from there on).
#[test]
fn both_queues_give_the_same_run() {
    for neighbourhood in [Neighbourhood::Grid, Neighbourhood::Lists] {
        let calendar = system(40, false, neighbourhood);
        assert_eq!(calendar.queue.kind(), QueueKind::Calendar);
        let mut tree = calendar.clone();
        tree.queue = EventQueue::new(calendar.queue.pending(), QueueKind::Tree);
        let mut calendar = calendar;
        for _ in 0..20_000 {
            assert_eq!(calendar.step(), tree.step());
        }
        assert_eq!(calendar.particles(), tree.particles());
        assert_eq!(calendar.time().to_bits(), tree.time().to_bits());
        assert_eq!(calendar.counts(), tree.counts());
    }
}

/// The lookahead (on by default only where the state leaves the level-2 cache) prefetches and
/// nothing else: with it forced on, a small system runs through the same events bit for
/// bit, with the grid and with lists, and the guess it prefetches for is usually the
/// next event.
#[test]
fn lookahead_changes_nothing() {
    for (neighbourhood, kind) in [Neighbourhood::Grid, Neighbourhood::Lists]
        .into_iter()
        .flat_map(|h| [QueueKind::Calendar, QueueKind::Tree].map(|k| (h, k)))
    {
        let mut plain = system(40, false, neighbourhood);
        assert!(!plain.timing.lookahead);
        // The tree leaves out the particles near the pair (guess_levels(1600) = 2).
        plain.queue = EventQueue::new(plain.queue.pending(), kind);
        let mut ahead = plain.clone();
        ahead.timing.lookahead = true;
        let (mut plain, mut guessed, mut pairs) = (plain, 0, 0);
        for _ in 0..20_000 {
            let guess = match ahead.queue.first() {
                (i, Event { kind: EventKind::Pair { partner, .. }, .. }) => {
                    Some(ahead.queue.guess_next(i, partner as usize))
                }
                _ => None,
            };
            let (a, b) = (plain.step(), ahead.step());
            assert_eq!(a, b);
            if let (Some(guess), Some(Outcome::Pair { .. })) = (guess, b) {
                pairs += 1;
                guessed += (ahead.queue.first().0 == guess) as usize;
            }
        }
        assert_eq!(plain.particles(), ahead.particles());
        assert_eq!(plain.time().to_bits(), ahead.time().to_bits());
        // The guess is right almost always; right less than half the time, it is a bug.
        assert!(guessed * 2 > pairs, "{kind:?}: {guessed} of {pairs}");
    }
}

/// Spheres too (whose records span two lines, so the lookahead also asks for each
/// candidate's event count between the brackets and the exact times, and before a rebuild
/// walks the cells its scan will read): with the lookahead forced on, a fluid with lists
/// runs through the same events bit for bit, rebuilds among them.
#[test]
fn lookahead_changes_nothing_for_spheres() {
    let (particles, sim_box) = crate::bench::state::initial_state::<3>(500, 0.45, 3).expect("a state");
    let plain = Simulation::with_neighbourhood(particles, sim_box, Neighbourhood::Lists).expect("a simulation");
    assert!(!plain.timing.lookahead && plain.neighbours.listed());
    let mut ahead = plain.clone();
    ahead.timing.lookahead = true;
    let mut plain = plain;
    for _ in 0..30_000 {
        assert_eq!(plain.step(), ahead.step());
    }
    assert!(plain.counts().pair > 20_000);
    assert!(plain.counts().rebuild > 1_000, "{:?}", plain.counts());
    assert_eq!(plain.particles(), ahead.particles());
    assert_eq!(plain.time().to_bits(), ahead.time().to_bits());
    assert_eq!(plain.counts(), ahead.counts());
}

/// A prediction depends on the clock only as a floor under its candidates' times: predicted
/// again from any later clock no later than what it found, a particle gets the same event,
/// bit for bit — the property the ordered two-thread schedule relies on when a change
/// arrives that would have moved the clock of a re-prediction marker already taken
/// (docs/engine.md, "Two threads in the order of time"). Spheres with lists and disks with
/// the grid, every particle, three later clocks each; rebuilds and pairs among the events
/// found, and a clock past the event does change some (the floor is real).
#[test]
fn predictions_do_not_depend_on_an_earlier_clock() {
    fn check<const D: usize>(mut sim: Simulation<D>, steps: usize) {
        for _ in 0..steps {
            sim.step();
        }
        let (mut rebuilds, mut pairs, mut floored) = (0, 0, 0);
        for i in 0..sim.particles.len() {
            let mut first = sim.clone();
            first.predict(i);
            let found = first.queue.get(i);
            rebuilds += usize::from(found.kind == EventKind::Rebuild);
            pairs += usize::from(matches!(found.kind, EventKind::Pair { .. }));
            for share in [0.25, 0.75, 1.0] {
                let mut later = sim.clone();
                later.time = sim.time + share * (found.time - sim.time);
                later.predict(i);
                let again = later.queue.get(i);
                assert_eq!(
                    (again.time.to_bits(), again.kind),
                    (found.time.to_bits(), found.kind),
                    "particle {i} from the clock {} and {}",
                    sim.time,
                    later.time
                );
            }
            let mut past = sim.clone();
            past.time = found.time + 0.5 * (found.time - sim.time);
            past.predict(i);
            floored += usize::from(past.queue.get(i) != found);
        }
        let n = sim.particles.len();
        assert!(rebuilds > n / 50 && pairs > n / 2, "{rebuilds} rebuilds and {pairs} pairs of {n}");
        assert!(floored > n / 2, "a clock past the event changed only {floored} of {n}");
    }
    let (particles, sim_box) = crate::bench::state::initial_state::<3>(2048, 0.45, 3).expect("a state");
    check(Simulation::with_neighbourhood(particles, sim_box, Neighbourhood::Lists).expect("a simulation"), 30_000);
    check(system(40, false, Neighbourhood::Grid), 20_000);
}
