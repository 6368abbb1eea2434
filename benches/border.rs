//! What dividing space between two cores could keep, replayed from the engine's own events.
//!
//! The box (spheres at η = 0.45, the benchmark report's start, warmed up as `collide bench`
//! does) is cut into two slabs across x, one a core. The engine then runs serially and each
//! event it reports — a collision of `a` and `b`, or `a` leaving its skin — is given to the
//! core whose slab holds `a` at the event's time. Replayed on two ideal cores, each resolves
//! its own events in order of time, one unit of work each; an event starts only once its
//! core is free and every event of the *other* core it depends on has finished, and it costs
//! `h` more when it reads anything the other core wrote (the hand-over between their
//! caches). What "depends on" means gives the schedules ([`Rule`]):
//!
//! * **neighbours**: an event reads its particles and every particle within `R + s` of
//!   either (all their list members could be: `R` the list range, `s` the skin), and depends
//!   on the last event that changed each of them. What an engine needs that predicts from
//!   whatever state it reads, and waits (or undoes its work) when any of it may change: a
//!   conservative division with perfect knowledge of what is safe, or an optimistic one that
//!   undoes an event whenever a neighbour it read changes course earlier in time.
//! * **neighbours, undo for W**: as neighbours, with undo records kept for only W of a
//!   core's events beyond the other core's clock.
//! * **the other core's clock**: an event that reads a particle the other core can change
//!   (within a contact distance of the other slab, or last changed there) waits until the
//!   other core has resolved every event before its time — a conservative division.
//! * **partners**: an event depends only on the last event of each of its own particles —
//!   the physical causality. An optimistic engine that checks, when a neighbour it read
//!   changes course earlier, whether the new course meets its particles first (and undoes
//!   only then) can do no better than this, and no engine that resolves events in order of
//!   time on each core can beat it.
//!
//! Printed per size and rule: the share of events that cross (read what the other core
//! wrote or, for the clock, can change), the share that wait at all (with `h` = 0), the
//! slabs' balance (what their unequal numbers of events alone would keep), and the share
//! of the two cores kept, `events / (2 · the busier core's finishing time)` (1: both busy
//! throughout; 0.5: nothing gained over one core), for `h` = 0 … 0.3 of an event. Undo logs,
//! messages and clocks cost nothing here: each figure bounds what a real engine of its kind
//! keeps. A rebuild changes no course but the lists around its sphere, which the events of
//! the spheres around it read next: it counts as a change of its sphere.
//!
//! First, per size, the engine's own division ([`Divided`]) run in one thread beside the
//! whole box: the changes its sides tell each other per event, the share of the other
//! side's particles each holds, and its time per event against the whole box's. Then the
//! same division in two threads that apply each other's changes on arrival
//! ([`Divided::run_unordered`], an upper bound on a two-thread engine that keeps the order
//! of time), against the whole box in five alternated rounds, each followed by the time a
//! cache line takes from one thread to the other, on which it depends: free, and with
//! each side held within 16 and 64 of the whole box's mean times between events of the
//! other (as an engine that undoes what it did too early would hold them, so that its
//! undo records stay few). For each, how many of the changes that arrived late met a
//! particle the receiver had read since (its events' particles and their neighbours) —
//! those an engine that keeps the order has to undo its events for — how many events of
//! its own lay between, and how many of the others put an event of the receiver's into its
//! past. Last, the division in two threads that keeps the order of time
//! ([`Divided::run_ordered`], the whole box's events to the bit, checked each run), against
//! the whole box in three alternated rounds, free and within 4, 16 and 64 intervals, with
//! what it undid and how often the sides met.
//!
//! ```text
//! cargo bench --bench border                          # N = 10 976 and 97 556, 10⁶ events each
//! cargo bench --bench border -- 10976 --events 2000000
//! cargo bench --bench border -- 10976 --ordered       # the ordered runs' table alone
//! ```
//!
//! With `--test` (as `cargo bench -- --test` runs every bench) it checks the schedule on
//! cases with known answers, replays a small system and runs the ordered table on it.

use collide::engine::{Divided, Lead, Outcome, RANGE_HOLDS_3D, SimBox, Simulation, Stop};
use nalgebra::Vector3;

/// Packing fraction of the replayed fluid.
const ETA: f64 = 0.45;
/// The hand-over costs, in units of an event's work.
const HANDOVERS: [f64; 4] = [0.0, 0.1, 0.2, 0.3];

/// An event as the replay sees it: the core that resolves it, its own spheres (the two of a
/// collision, the one of a rebuild: those it changes), those it reads beyond them (its
/// neighbours), and whether the other core can change any of those (within a contact
/// distance of the border, or last changed there).
struct Replayed<'a> {
    time: f64,
    side: usize,
    own: &'a [u32],
    near: &'a [u32],
    border: bool,
}

/// What an event waits for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Rule {
    /// At the border, the other core's clock: every event of the other core before its time
    /// (a conservative division, as `benches/border_model.py` models it).
    Clock,
    /// The last event that changed any of its particles or neighbours, on the other core.
    Neighbours,
    /// The last event of each of its own particles, on the other core.
    Partners,
    /// As `Neighbours`, and with undo records for only this many of a core's events beyond
    /// the other core's clock: an event also waits until the other core has resolved every
    /// event before the one this many events back on its own core.
    Window(usize),
}

impl Rule {
    const ALL: [Rule; 5] = [Rule::Clock, Rule::Neighbours, Rule::Window(64), Rule::Window(16), Rule::Partners];

    fn name(self) -> String {
        match self {
            Rule::Clock => "the other core's clock".into(),
            Rule::Neighbours => "neighbours".into(),
            Rule::Window(w) => format!("neighbours, undo for {w}"),
            Rule::Partners => "partners".into(),
        }
    }
}

/// Two cores resolving their events in order, an event waiting for the other core's events
/// it depends on. `writer_core[m]` and `writer_done[m]`: the core of the last event that
/// changed particle `m` and when it finished (`u8::MAX`: none yet).
struct Schedule {
    rule: Rule,
    h: f64,
    clock: [f64; 2],
    writer_done: Vec<f64>,
    events: u64,
    per_side: [u64; 2],
    crossing: u64,
    waited: u64,
    /// Each core's events so far: their times and when they finished.
    history: [Vec<(f64, f64)>; 2],
}

impl Schedule {
    fn new(n: usize, rule: Rule, h: f64) -> Self {
        Schedule {
            rule,
            h,
            clock: [0.0; 2],
            writer_done: vec![0.0; n],
            events: 0,
            per_side: [0; 2],
            crossing: 0,
            waited: 0,
            history: [Vec::new(), Vec::new()],
        }
    }

    /// Places event `e`; `writer_core` is shared by every schedule (the same events change
    /// the same particles) and updated by the caller after all have placed `e`.
    fn place(&mut self, e: &Replayed, writer_core: &[u8]) {
        let mut ready = self.clock[e.side];
        let mut crosses = false;
        let reads = match self.rule {
            Rule::Clock => {
                if e.border {
                    crosses = true;
                    ready = ready.max(self.clock[1 - e.side]);
                }
                [&[][..], &[][..]]
            }
            Rule::Neighbours => [e.own, e.near],
            Rule::Window(w) => {
                let (own, other) = (&self.history[e.side], &self.history[1 - e.side]);
                if own.len() >= w {
                    let back = own[own.len() - w].0;
                    let passed = other.partition_point(|&(t, _)| t < back);
                    if passed > 0 {
                        ready = ready.max(other[passed - 1].1);
                    }
                }
                [e.own, e.near]
            }
            Rule::Partners => [e.own, &[][..]],
        };
        for &m in reads.into_iter().flatten() {
            let core = writer_core[m as usize];
            if core != u8::MAX && core as usize != e.side {
                crosses = true;
                ready = ready.max(self.writer_done[m as usize]);
            }
        }
        self.waited += (ready > self.clock[e.side]) as u64;
        let done = ready + 1.0 + if crosses { self.h } else { 0.0 };
        self.clock[e.side] = done;
        self.history[e.side].push((e.time, done));
        for &m in e.own {
            self.writer_done[m as usize] = done;
        }
        self.events += 1;
        self.per_side[e.side] += 1;
        self.crossing += crosses as u64;
    }

    /// The share of the two cores kept.
    fn kept(&self) -> f64 {
        self.events as f64 / (2.0 * self.clock[0].max(self.clock[1]))
    }

    /// The share the slabs' unequal numbers of events alone would keep.
    fn balance(&self) -> f64 {
        self.events as f64 / (2.0 * self.per_side[0].max(self.per_side[1]) as f64)
    }
}

/// The particles within `reach` of a point, found through a grid of cells at least
/// `reach + 2·slack` wide, from the positions of one instant; rebuilt (by the caller)
/// before any particle can have moved `slack` since.
struct Grid {
    cells: [usize; 3],
    width: [f64; 3],
    heads: Vec<u32>,
    next: Vec<u32>,
    valid_until: f64,
}

impl Grid {
    const SLACK: f64 = 0.1;

    fn build(sim: &Simulation<3>, reach: f64) -> Self {
        let lengths = sim.sim_box().lengths;
        let cells: [usize; 3] =
            std::array::from_fn(|a| ((lengths[a] / (reach + 2.0 * Self::SLACK)).floor() as usize).max(1));
        let width = std::array::from_fn(|a| lengths[a] / cells[a] as f64);
        let mut grid = Grid {
            cells,
            width,
            heads: vec![u32::MAX; cells.iter().product()],
            next: vec![u32::MAX; sim.particles().len()],
            valid_until: 0.0,
        };
        for (i, r) in sim.wrapped_positions().iter().enumerate() {
            let c = grid.cell_of(r);
            grid.next[i] = grid.heads[c];
            grid.heads[c] = i as u32;
        }
        // A collision changes speeds by at most a factor √2 (energy is shared, never made),
        // so twice the fastest speed bounds every speed over so short a time.
        let fastest = sim.particles().iter().map(|p| p.velocity.norm()).fold(0.0, f64::max);
        grid.valid_until = sim.time() + Self::SLACK / (2.0 * fastest);
        grid
    }

    fn coord(&self, r: &Vector3<f64>) -> [usize; 3] {
        std::array::from_fn(|a| ((r[a] / self.width[a]).floor() as usize).min(self.cells[a] - 1))
    }

    fn cell_of(&self, r: &Vector3<f64>) -> usize {
        let c = self.coord(r);
        (c[2] * self.cells[1] + c[1]) * self.cells[0] + c[0]
    }

    /// Pushes onto `out` every particle within `reach` of `centre` (a position at `t`,
    /// wrapped), minimum image.
    fn within(&self, sim: &Simulation<3>, centre: &Vector3<f64>, t: f64, reach: f64, out: &mut Vec<u32>) {
        let c = self.coord(centre);
        let span = |a: usize| -> Vec<usize> {
            let k = self.cells[a];
            if k < 3 { (0..k).collect() } else { vec![(c[a] + k - 1) % k, c[a], (c[a] + 1) % k] }
        };
        for z in span(2) {
            for y in span(1) {
                for x in span(0) {
                    let mut m = self.heads[(z * self.cells[1] + y) * self.cells[0] + x];
                    while m != u32::MAX {
                        if apart2(sim.sim_box(), &sim.particles()[m as usize].position_at(t), centre) < reach * reach {
                            out.push(m);
                        }
                        m = self.next[m as usize];
                    }
                }
            }
        }
    }
}

/// Spheres' records that cross between the two cores' caches (their capacity aside): a
/// core reading a record the other core changed since this core last read it, or changing
/// one the other core holds a copy of. An event reads its own spheres and the members of
/// their lists, taken as every sphere within the list range `R` of either.
#[derive(Default)]
struct Traffic {
    reads: u64,
    writes: u64,
    events: u64,
}

/// The squared distance between `a` and the nearest image of `b`.
fn apart2(sim_box: &SimBox<3>, a: &Vector3<f64>, b: &Vector3<f64>) -> f64 {
    let d = b - a;
    (d + sim_box.minimum_image_shift(&d)).norm_squared()
}

/// The list range and skin the engine chooses for spheres of diameter 1 at `ETA`
/// (`RANGE_HOLDS_3D` particles in range on average, the skin the rest beyond contact).
fn range_and_skin() -> (f64, f64) {
    let density = ETA * 6.0 / std::f64::consts::PI;
    let range = (RANGE_HOLDS_3D / (4.0 / 3.0 * std::f64::consts::PI * density)).cbrt();
    (range, range - 1.0)
}

/// `n` spheres at `ETA` from the benchmark report's start, warmed up as `collide bench` does.
fn warmed_up(n: usize) -> Simulation<3> {
    let (particles, sim_box) = collide::bench::state::initial_state::<3>(n, ETA, 1).unwrap_or_else(|e| {
        eprintln!("border: no benchmark start for N = {n} at η = {ETA}: {e}");
        std::process::exit(2)
    });
    let mut sim = Simulation::new(particles, sim_box).expect("a valid start");
    while sim.counts().pair < collide::bench::WARMUP * n as u64 {
        sim.step().expect("events go on");
    }
    sim
}

/// Replays `events` events of the warmed-up `sim` ([`warmed_up`]); one schedule per
/// dependency notion and hand-over cost.
fn replay(mut sim: Simulation<3>, events: u64) -> (Vec<Schedule>, Traffic) {
    let n = sim.particles().len();
    let (range, skin) = range_and_skin();
    let reach = range + skin;
    let half = 0.5 * sim.sim_box().lengths[0];
    let mut schedules: Vec<Schedule> =
        Rule::ALL.into_iter().flat_map(|rule| HANDOVERS.map(|h| Schedule::new(n, rule, h))).collect();
    let mut writer_core = vec![u8::MAX; n];
    let mut grid = Grid::build(&sim, reach);
    let (mut near, mut listed, mut seen) = (Vec::new(), Vec::new(), 0u64);
    let mut traffic = Traffic::default();
    // Which cores hold the present version of each sphere's record.
    let mut holds = vec![[true; 2]; n];
    while seen < events {
        let outcome = sim.step().expect("events go on");
        let t = sim.time();
        let (pair, spheres): ([u32; 2], usize) = match outcome {
            Outcome::Pair { i, j, .. } => ([i as u32, j as u32], 2),
            // A rebuild changes no course, but the lists around its sphere: what those
            // spheres' events read next depends on it, as on a change of the sphere.
            Outcome::Rebuild { i } => ([i as u32, u32::MAX], 1),
            _ => continue,
        };
        if t > grid.valid_until {
            grid = Grid::build(&sim, reach);
        }
        let own = &pair[..spheres];
        let wrap = |r: Vector3<f64>| r.zip_map(&sim.sim_box().lengths, |x, l| x.rem_euclid(l));
        let at = |m: u32| wrap(sim.particles()[m as usize].position_at(t));
        let side = (at(own[0])[0] >= half) as usize;
        near.clear();
        for &m in own {
            grid.within(&sim, &at(m), t, reach, &mut near);
        }
        // A sphere the other core can change: within a contact distance of the other slab
        // (a collision across the border, resolved there, moves it), or last changed there.
        let other = |m: &u32| {
            let x = at(*m)[0];
            let to_border = x.min((x - half).abs()).min(2.0 * half - x);
            to_border < 1.0 || (writer_core[*m as usize] != u8::MAX && writer_core[*m as usize] as usize != side)
        };
        let border = own.iter().chain(&near).any(other);
        let e = Replayed { time: t, side, own, near: &near, border };
        for s in &mut schedules {
            s.place(&e, &writer_core);
        }
        for &m in own {
            writer_core[m as usize] = side as u8;
        }
        listed.clear();
        listed.extend(own.iter().copied());
        listed.extend(
            near.iter()
                .copied()
                .filter(|&m| own.iter().any(|&o| apart2(sim.sim_box(), &at(o), &at(m)) < range * range)),
        );
        listed.sort_unstable();
        listed.dedup();
        for &m in &listed {
            traffic.reads += !holds[m as usize][side] as u64;
            holds[m as usize][side] = true;
        }
        for &m in own {
            traffic.writes += holds[m as usize][1 - side] as u64;
            holds[m as usize] = [side == 0, side == 1];
        }
        traffic.events += 1;
        seen += 1;
    }
    (schedules, traffic)
}

/// The engine's own division ([`Divided`]), run in one thread beside the whole box from the
/// same warmed-up state: the changes the sides tell each other per event, the share of the
/// other side's particles each holds, and the time per event against the whole box's
/// (both in this process, alternated in blocks of 10⁵ events).
fn divided(sim: &Simulation<3>, events: u64) {
    let (start, sim_box) = (sim.particles().to_vec(), *sim.sim_box());
    let mut whole = Simulation::new(start.clone(), sim_box).expect("a valid start");
    let mut divided = Divided::new(start, sim_box).expect("a valid start");
    let (mut t_whole, mut t_divided, mut done) = (0.0, 0.0, 0);
    while done < events {
        let block = 100_000.min(events - done);
        let clock = std::time::Instant::now();
        for _ in 0..block {
            whole.step().expect("events go on");
        }
        t_whole += clock.elapsed().as_secs_f64();
        let clock = std::time::Instant::now();
        for _ in 0..block {
            divided.step().expect("events go on");
        }
        t_divided += clock.elapsed().as_secs_f64();
        done += block;
    }
    assert_eq!(whole.counts(), divided.counts(), "the divided box's events differ from the whole box's");
    let (known, sides) = (divided.known(), divided.sides());
    println!(
        "divided, one thread: {:.3} changes told per event; each side holds {:.2} and {:.2} of the other's particles; time per event {:.3} of the whole box's",
        divided.told() as f64 / events as f64,
        known[0] as f64 / sides[1] as f64,
        known[1] as f64 / sides[0] as f64,
        t_divided / t_whole
    );
}

/// What a cache line takes to pass from one thread to another, one way, in nanoseconds: a
/// counter bumped in turn by two threads, 10⁶ times. It says where the two threads run (the
/// same machine's two cores have measured 25 ns and 200 ns in different hours), on which
/// the two-thread row depends.
fn handover_ns() -> f64 {
    use std::sync::atomic::{AtomicU64, Ordering};
    const PASSES: u64 = 1_000_000;
    let counter = AtomicU64::new(0);
    let bump = |parity: u64| {
        let mut x = parity;
        while x < PASSES {
            while counter.load(Ordering::Acquire) != x {
                std::hint::spin_loop();
            }
            counter.store(x + 1, Ordering::Release);
            x += 2;
        }
    };
    let clock = std::time::Instant::now();
    std::thread::scope(|scope| {
        scope.spawn(|| bump(1));
        bump(0);
    });
    clock.elapsed().as_secs_f64() / PASSES as f64 * 1e9
}

/// How far ahead of the other a side of the two-thread runs may go: as far as it goes, or
/// this many of the whole box's mean times between events (`None`: free).
const LEADS: [Option<f64>; 3] = [None, Some(16.0), Some(64.0)];

/// The engine's own division in two threads, each side applying the other's changes as
/// they arrive ([`Divided::run_unordered`]), free or held within a lead of the other
/// ([`LEADS`]): its events per second against the whole box's from the same warmed-up
/// start, in `ROUNDS` rounds alternated in this process (median ratio and range), the share
/// of the changes received that arrived in the receiver's past, and what an engine that
/// keeps the order would undo: the late changes that meet a particle read since, and the
/// events since them.
fn two_threads(sim: &Simulation<3>, events: u64) {
    const ROUNDS: usize = 5;
    let (start, sim_box) = (sim.particles().to_vec(), *sim.sim_box());
    // The whole box's mean time between events over the warm-up.
    let interval = sim.time() / sim.counts().total() as f64;
    #[derive(Default)]
    struct Tally {
        ratios: Vec<f64>,
        rounds: Vec<String>,
        received: u64,
        late: u64,
        conflicts: u64,
        undone: u64,
        overtaken: u64,
        events: u64,
    }
    let mut tallies: Vec<Tally> = LEADS.iter().map(|_| Tally::default()).collect();
    for _ in 0..ROUNDS {
        let mut whole = Simulation::new(start.clone(), sim_box).expect("a valid start");
        let clock = std::time::Instant::now();
        for _ in 0..events {
            whole.step().expect("events go on");
        }
        let whole_rate = events as f64 / clock.elapsed().as_secs_f64();
        for (lead, tally) in LEADS.iter().zip(&mut tallies) {
            let lead = lead.map_or(Lead::Free, |w| Lead::Within(w * interval));
            let divided = Divided::new(start.clone(), sim_box).expect("a valid start");
            let run = divided.run_unordered(events / 2, lead);
            let handover = handover_ns();
            // A side that ran out of events, a state gone NaN, a particle neither side holds
            // (its events lost) or a chain of collisions that stops the clock (particles
            // overlapping) makes the round no measurement.
            let stall = run.stall[0].max(run.stall[1]);
            let why = if run.stops.contains(&Stop::RanOut) {
                Some(format!("a side ran out of events ({:?}, holding {:?})", run.events, run.held))
            } else if run.not_numbers != [0; 2] {
                Some(format!("{} states not numbers", run.not_numbers[0] + run.not_numbers[1]))
            } else if run.disowned > 0 {
                Some(format!("{} disowned", run.disowned))
            } else if stall > 100 {
                Some(format!("{stall} events at one time"))
            } else {
                None
            };
            if let Some(why) = why {
                tally.rounds.push(format!("void: {why} ({handover:.0} ns)"));
                continue;
            }
            let ratio = run.rate() / whole_rate;
            tally.rounds.push(format!("{ratio:.3} ({handover:.0} ns)"));
            tally.ratios.push(ratio);
            tally.late += run.late[0] + run.late[1];
            tally.received += run.received[0] + run.received[1];
            tally.conflicts += run.conflicts[0] + run.conflicts[1];
            tally.undone += run.undone[0] + run.undone[1];
            tally.overtaken += run.overtaken[0] + run.overtaken[1];
            tally.events += run.events[0] + run.events[1];
        }
    }
    println!(
        "divided, two threads, changes applied on arrival (upper bounds): events per second over the whole box's, round by round (a cache line from thread to thread after it, one way)"
    );
    println!(
        "| lead | median (range) | rounds | late changes | late changes meeting a read, per event | events since them, per event | late changes meeting none that put an event in the past, per event |"
    );
    for (lead, tally) in LEADS.iter().zip(&mut tallies) {
        let lead = lead.map_or("free".to_string(), |w| format!("{w} intervals"));
        let Tally { ratios, rounds, .. } = tally;
        ratios.sort_by(f64::total_cmp);
        if ratios.is_empty() {
            println!("| {lead} | every round void | {} | | | | |", rounds.join(", "));
            continue;
        }
        let median = 0.5 * (ratios[(ratios.len() - 1) / 2] + ratios[ratios.len() / 2]);
        let per_event = |x: u64| x as f64 / tally.events as f64;
        println!(
            "| {lead} | {median:.3} ({:.3}–{:.3}) | {} | {:.3} | {:.5} | {:.4} | {:.5} |",
            ratios[0],
            ratios[ratios.len() - 1],
            rounds.join(", "),
            tally.late as f64 / tally.received as f64,
            per_event(tally.conflicts),
            per_event(tally.undone),
            per_event(tally.overtaken)
        );
    }
}

/// How far ahead of the other a side of the ordered runs may go, in the whole box's mean
/// times between events (`None`: free).
const ORDERED_LEADS: [Option<f64>; 4] = [None, Some(4.0), Some(16.0), Some(64.0)];

/// The engine's own division in two threads in the order of time ([`Divided::run_ordered`]),
/// against the whole box from the same warmed-up start: `ROUNDS` rounds alternated in this
/// process, each the whole box's `events` events and then the ordered run to the time of the
/// last of them, for each lead ([`ORDERED_LEADS`]). Every run is checked against the whole
/// box (one further item taken, the counts and particles equal to the bit), then its events
/// per second over the whole box's (median and range), and per own item what it undid,
/// the batches that came late and conflicted, and how often the sides met.
fn ordered(sim: &Simulation<3>, events: u64) {
    const ROUNDS: usize = 3;
    let (start, sim_box) = (sim.particles().to_vec(), *sim.sim_box());
    let interval = sim.time() / sim.counts().total() as f64;
    let mut ratios: Vec<Vec<f64>> = ORDERED_LEADS.iter().map(|_| Vec::new()).collect();
    let mut counted: Vec<[u64; 6]> = ORDERED_LEADS.iter().map(|_| [0; 6]).collect();
    // Collisions per second, the whole box's and each lead's ordered run's.
    let mut whole_rates = Vec::new();
    let mut rates: Vec<Vec<f64>> = ORDERED_LEADS.iter().map(|_| Vec::new()).collect();
    for _ in 0..ROUNDS {
        let mut whole = Simulation::new(start.clone(), sim_box).expect("a valid start");
        let clock = std::time::Instant::now();
        for _ in 0..events {
            whole.step().expect("events go on");
        }
        let whole_seconds = clock.elapsed().as_secs_f64();
        let whole_rate = events as f64 / whole_seconds;
        // (A new simulation counts from 0.)
        let collisions = whole.counts().pair as f64;
        whole_rates.push(collisions / whole_seconds);
        let end = whole.time();
        for (((lead, ratio), counts), rate) in ORDERED_LEADS.iter().zip(&mut ratios).zip(&mut counted).zip(&mut rates) {
            let lead = lead.map_or(Lead::Free, |w| Lead::Within(w * interval));
            let mut divided = Divided::new(start.clone(), sim_box).expect("a valid start");
            let clock = std::time::Instant::now();
            let run = divided.run_ordered(end, lead);
            let seconds = clock.elapsed().as_secs_f64();
            divided.step().expect("events go on");
            assert_eq!(divided.counts(), whole.counts(), "the ordered run's events differ from the whole box's");
            let same = divided
                .particles()
                .iter()
                .zip(whole.particles())
                .all(|(a, b)| a.position == b.position && a.velocity == b.velocity && a.time == b.time);
            assert!(same, "the ordered run's particles differ from the whole box's");
            ratio.push(events as f64 / seconds / whole_rate);
            rate.push(collisions / seconds);
            for (c, x) in counts.iter_mut().zip([
                run.items[0] + run.items[1],
                run.undone[0] + run.undone[1],
                run.late[0] + run.late[1],
                run.conflicts[0] + run.conflicts[1],
                run.rendezvous,
                run.waits[0] + run.waits[1],
            ]) {
                *c += x;
            }
        }
    }
    let median = |x: &mut Vec<f64>| {
        x.sort_by(f64::total_cmp);
        x[x.len() / 2]
    };
    println!(
        "divided, two threads in the order of time (the whole box's events to the bit): events per second over the whole box's (the whole box {:.3}·10⁶ collisions/s, median)",
        median(&mut whole_rates) * 1e-6
    );
    println!(
        "| lead | median (range) | 10⁶ collisions/s | undone per item | late batches per item | conflicts per item | meetings per item | waits per item |"
    );
    for (((lead, ratio), counts), rate) in ORDERED_LEADS.iter().zip(&mut ratios).zip(&counted).zip(&mut rates) {
        let lead = lead.map_or("free".to_string(), |w| format!("{w} intervals"));
        let middle = median(ratio);
        let per_item = |x: u64| x as f64 / counts[0] as f64;
        println!(
            "| {lead} | {middle:.3} ({:.3}–{:.3}) | {:.3} | {:.4} | {:.4} | {:.5} | {:.5} | {:.4} |",
            ratio[0],
            ratio[ratio.len() - 1],
            median(rate) * 1e-6,
            per_item(counts[1]),
            per_item(counts[2]),
            per_item(counts[3]),
            per_item(counts[4]),
            per_item(counts[5]),
        );
    }
}

fn report(n: usize, events: u64) {
    let sim = warmed_up(n);
    divided(&sim, events);
    two_threads(&sim, events);
    ordered(&sim, events);
    let (schedules, traffic) = replay(sim, events);
    let (range, skin) = range_and_skin();
    println!(
        "N = {n}, η = {ETA}, {events} events after the warm-up; two slabs across x; reads within R + s = {:.3}σ",
        range + skin
    );
    println!(
        "records crossing between the cores' caches, per event: {:.3} read, {:.3} changed (lists within R = {range:.3}σ)",
        traffic.reads as f64 / traffic.events as f64,
        traffic.writes as f64 / traffic.events as f64
    );
    println!(
        "| waits for | events that cross | waiting, h = 0 | balance | kept, h = {} |",
        HANDOVERS.map(|h| h.to_string()).join(" | ")
    );
    for rule in Rule::ALL {
        let row: Vec<&Schedule> = schedules.iter().filter(|s| s.rule == rule).collect();
        let kept: Vec<String> = row.iter().map(|s| format!("{:.3}", s.kept())).collect();
        println!(
            "| {} | {:.3} | {:.4} | {:.3} | {} |",
            rule.name(),
            row[0].crossing as f64 / row[0].events as f64,
            row[0].waited as f64 / row[0].events as f64,
            row[0].balance(),
            kept.join(" | ")
        );
    }
}

/// The schedule on cases with known answers, then a small replay whose shares must be
/// shares. Fails loudly (a panic is the bench harness's failure).
fn check() {
    // Alternating sides, nothing shared: both cores busy throughout, whatever the rule.
    for rule in Rule::ALL {
        let mut s = Schedule::new(2, rule, 0.0);
        for k in 0..1000u32 {
            let m = [k % 2];
            s.place(&Replayed { time: k as f64, side: (k % 2) as usize, own: &m, near: &[], border: false }, &[0, 1]);
        }
        assert!((s.kept() - 1.0).abs() < 1e-12, "{rule:?}: independent halves kept {}", s.kept());
    }
    // A chain through one particle handed from side to side: one core at a time; with a
    // hand-over cost of 0.2, paid by every event but the first.
    for (h, expected) in [(0.0, 0.5), (0.2, 1000.0 / (2.0 * (1000.0 + 999.0 * 0.2)))] {
        let mut s = Schedule::new(1, Rule::Partners, h);
        let mut cores = [u8::MAX];
        for k in 0..1000u32 {
            let m = [0u32];
            s.place(&Replayed { time: k as f64, side: (k % 2) as usize, own: &m, near: &[], border: true }, &cores);
            cores[0] = (k % 2) as u8;
        }
        assert!((s.kept() - expected).abs() < 1e-9, "a chain with h = {h} kept {}", s.kept());
    }
    // A neighbour last changed on the other side, and at the border: only the rule that
    // counts it waits (the clock makes everything at the border wait).
    for (rule, expected) in [(Rule::Clock, 0.5), (Rule::Neighbours, 0.5), (Rule::Partners, 1.0)] {
        let mut s = Schedule::new(2, rule, 0.0);
        for k in 0..1000u32 {
            let (side, m, other) = ((k % 2) as usize, [k % 2], [1 - k % 2]);
            s.place(&Replayed { time: k as f64, side, own: &m, near: &other, border: true }, &[0, 1]);
        }
        assert!((s.kept() - expected).abs() < 1e-12, "{rule:?}: kept {}", s.kept());
    }
    // One core's events all before the other's, nothing shared: without a window both run
    // at once; with undo for ten events the later core cannot run more than ten ahead of
    // the earlier one's clock: its first ten run at once, the rest after all of the other's.
    for (rule, expected) in [(Rule::Neighbours, 1.0), (Rule::Window(10), 2000.0 / (2.0 * 1990.0))] {
        let mut s = Schedule::new(2000, rule, 0.0);
        for k in 0..2000u32 {
            let side = (k >= 1000) as usize;
            let m = [k];
            s.place(&Replayed { time: k as f64, side, own: &m, near: &[], border: false }, &[u8::MAX; 2000]);
        }
        assert!((s.kept() - expected).abs() < 1e-12, "{rule:?}: kept {}", s.kept());
    }
    // The grid finds exactly the particles within reach (against all pairs), on a fluid
    // that has moved since the grid was built.
    let (particles, sim_box) = collide::bench::state::initial_state::<3>(500, ETA, 1).expect("a benchmark start");
    let mut sim = Simulation::new(particles, sim_box).expect("a valid start");
    for _ in 0..20_000 {
        sim.step().expect("events go on");
    }
    let reach = range_and_skin().0 + range_and_skin().1;
    let grid = Grid::build(&sim, reach);
    while sim.time() < grid.valid_until {
        sim.step().expect("events go on");
    }
    let t = grid.valid_until;
    let at: Vec<Vector3<f64>> = sim
        .particles()
        .iter()
        .map(|p| p.position_at(t).zip_map(&sim.sim_box().lengths, |x, l| x.rem_euclid(l)))
        .collect();
    let mut total = 0;
    for centre in &at {
        let mut found = Vec::new();
        grid.within(&sim, centre, t, reach, &mut found);
        found.sort_unstable();
        let all: Vec<u32> =
            (0..at.len() as u32).filter(|&m| apart2(sim.sim_box(), centre, &at[m as usize]) < reach * reach).collect();
        assert_eq!(found, all, "the grid's neighbours differ from all pairs'");
        total += all.len();
    }
    assert!(total > 10 * at.len(), "too few neighbours to test the grid: {total}");
    let (schedules, traffic) = replay(warmed_up(500), 20_000);
    assert!(traffic.reads > 0 && traffic.writes > 0 && traffic.reads < 40 * traffic.events, "traffic");
    for s in schedules {
        let crossing = s.crossing as f64 / s.events as f64;
        assert!(
            (0.5 / (1.0 + s.h) - 1e-9..=1.0).contains(&s.kept()) && (0.0..=1.0).contains(&crossing),
            "kept {}",
            s.kept()
        );
    }
    // The ordered runs' table on a small box: every run checked against the whole box.
    ordered(&warmed_up(2048), 20_000);
    println!("border: schedule checks passed");
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).filter(|a| a != "--bench").collect();
    if args.iter().any(|a| a == "--test") {
        check();
        return;
    }
    const USAGE: &str = "usage: cargo bench --bench border [-- [N ...] [--ordered] [--events COUNT]]\n\
        N: particle counts (default 10976 97556); --ordered: only the two-thread run in the order of \
        time; --events: events timed after the warm-up (default 1000000)";
    let fail = |what: String| -> ! {
        eprintln!("border: {what}\n{USAGE}");
        std::process::exit(2)
    };
    let mut sizes = Vec::new();
    let mut events = 1_000_000;
    let mut only_ordered = false;
    let mut it = args.iter();
    while let Some(a) = it.next() {
        match a.as_str() {
            "--ordered" => only_ordered = true,
            "--events" => match it.next() {
                Some(v) => match v.parse::<u64>() {
                    Ok(count) if count > 0 => events = count,
                    _ => fail(format!("--events takes a positive count, not {v:?}")),
                },
                None => fail("--events takes a positive count".into()),
            },
            "-h" | "--help" => {
                println!("{USAGE}");
                return;
            }
            _ => match a.parse::<usize>() {
                Ok(n) if n >= 2 => sizes.push(n),
                _ => fail(format!("{a:?} is not a particle count (an integer of at least 2) or an option")),
            },
        }
    }
    if sizes.is_empty() {
        sizes = vec![10_976, 97_556];
    }
    for n in sizes {
        if only_ordered {
            println!("N = {n}, η = {ETA}, {events} events after the warm-up; two slabs across x");
            ordered(&warmed_up(n), events);
        } else {
            report(n, events);
        }
    }
}
