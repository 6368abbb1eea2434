//! The benchmarks: steady-state collisions per second across N and packing fraction, beside
//! the hardware's floor ([`floor`]) measured in the same process.
//!
//! Each point builds a periodic box of disks or spheres from a lattice ([`state`]; Maxwell
//! velocities, kT = 1), runs a warm-up that is not timed (so the lattice has melted and the
//! queue has reached its working size), then times a fixed number of pair collisions on one
//! core — or, with two threads, on the box divided between two
//! ([`Divided::run_ordered`](crate::engine::Divided::run_ordered), the whole box's events bit
//! for bit). Memory is
//! reported twice: the engine's own account of its heap (capacities of the particle array,
//! the event queue, the neighbour lists and their grid) and the process's peak resident set size when each point
//! runs in a process of its own (`collide bench` does that).

pub mod floor;
pub mod state;

pub use state::{BenchError, initial_state};

use crate::engine::{Divided, EventCounts, Lead, Neighbourhood, Simulation};
use crate::lab::plot::{Chart, Series};
use serde::{Deserialize, Serialize};
use std::time::Instant;

/// One measured configuration.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct BenchPoint {
    /// 2 (disks) or 3 (spheres).
    #[serde(default = "two")]
    pub dimension: usize,
    /// N.
    pub n_particles: usize,
    /// Packing fraction.
    pub packing_fraction: f64,
    /// The neighbourhood asked for (`auto`, `grid` or `lists`).
    #[serde(default)]
    pub neighbourhood: Neighbourhood,
    /// Whether neighbour lists were in use (else the grid that follows the particles).
    #[serde(default)]
    pub lists: bool,
    /// Threads the timed collisions ran in: 1, the whole box; 2, the box divided in two
    /// slabs across the first axis, a thread each, in the order of time
    /// ([`Divided::run_ordered`](crate::engine::Divided::run_ordered): the same events as
    /// one thread, bit for bit).
    #[serde(default = "one")]
    pub threads: usize,
    /// Untimed warm-up collisions.
    pub warmup_collisions: u64,
    /// Timed pair collisions (with two threads, those before the end time that `--timed`
    /// asked for: see [`measure`]).
    pub collisions: u64,
    /// Timed wall-clock seconds.
    pub seconds: f64,
    /// Pair collisions per second.
    pub collisions_per_second: f64,
    /// Nanoseconds per pair collision.
    pub ns_per_collision: f64,
    /// Processed events per second (all kinds, stale ones excluded).
    pub events_per_second: f64,
    /// Timed events by kind (stale = discarded invalid events).
    pub events_by_kind: EventCounts,
    /// The engine's heap (particles, queue, neighbour lists and their grid) per particle, bytes, at the end.
    pub engine_bytes_per_particle: f64,
    /// The fraction of particles crowded at the end (more neighbours in range than a list
    /// holds: they search the cell grid instead).
    pub crowded_fraction: f64,
    /// Peak resident set size of the process, bytes (when known).
    pub peak_rss_bytes: Option<u64>,
    /// The process's memory in 2 MB pages at the end, bytes (`AnonHugePages`, when known;
    /// see `engine::pages`).
    #[serde(default)]
    pub huge_page_bytes: Option<u64>,
    /// The hardware's floor for the same N and η on this machine ([`floor`]: move two
    /// particles, bounce, re-predict both against fixed neighbours — eight disks or sixteen
    /// spheres; no queue, no list upkeep, no exact times), collisions per second — measured
    /// in the same process after the engine, with as many timed collisions.
    #[serde(default)]
    pub floor_collisions_per_second: Option<f64>,
    /// Whether the floor's faster loop was the one that prefetches (`bench::floor::Floor::run`).
    #[serde(default)]
    pub floor_lookahead: Option<bool>,
    /// `collisions_per_second / floor_collisions_per_second`.
    #[serde(default)]
    pub fraction_of_floor: Option<f64>,
}

fn two() -> usize {
    2
}

fn one() -> usize {
    1
}

/// The process's peak resident set size (Linux `VmHWM`), if readable.
pub fn peak_rss_bytes() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024)
}

/// Measures one point in `d` dimensions (2 or 3): `warmup_per_particle` untimed collisions
/// per particle, then `timed` collisions, with the neighbourhood asked for, in `threads`
/// threads.
///
/// With one thread the timed stretch ends at the `timed`-th collision. With two, the warmed-up
/// box is divided ([`Divided`]) and run in the order of time up to an end time, the clock
/// after the warm-up plus `timed / ν`, where ν is the collisions per unit time over the
/// second half of the warm-up: about `timed` collisions once the start has melted, and
/// `collisions` says how many. Two threads need a warm-up (`warmup_per_particle ≥ 1`) to
/// know ν, and a machine (or an affinity mask) with two cores: on one, the two threads would
/// spin through each other's time slices.
#[allow(clippy::too_many_arguments)]
pub fn measure(
    d: usize,
    n: usize,
    eta: f64,
    neighbourhood: Neighbourhood,
    warmup_per_particle: u64,
    timed: u64,
    seed: u64,
    threads: usize,
) -> Result<BenchPoint, BenchError> {
    if !(1..=2).contains(&threads) {
        return Err(BenchError::Option {
            flag: "threads",
            value: threads.to_string(),
            allowed: "1 (the whole box) or 2 (two slabs, a thread each, in the order of time)",
        });
    }
    // Two threads on one core spin through each other's time slices: refused, not crawled.
    if threads == 2 && std::thread::available_parallelism().is_ok_and(|cores| cores.get() < 2) {
        return Err(BenchError::Option {
            flag: "threads",
            value: "2".into(),
            allowed: "1 only: this process may run on one core (its CPU affinity), where two threads would wait out each other's time slices",
        });
    }
    if threads == 2 && warmup_per_particle == 0 {
        return Err(BenchError::Option {
            flag: "warmup",
            value: "0".into(),
            allowed: "at least 1 with --threads 2 (the warm-up's collision rate sets the end time)",
        });
    }
    match d {
        2 => measure_in::<2>(n, eta, neighbourhood, warmup_per_particle, timed, seed, threads),
        3 => measure_in::<3>(n, eta, neighbourhood, warmup_per_particle, timed, seed, threads),
        _ => Err(BenchError::Option { flag: "dimension", value: d.to_string(), allowed: "2 (disks) or 3 (spheres)" }),
    }
}

/// What the timed stretch of a point gave.
struct Timed {
    seconds: f64,
    counts: EventCounts,
    engine_bytes: usize,
    crowded: usize,
    lists: bool,
}

/// The timed stretch in one thread: `timed` collisions of `sim`.
fn timed_whole<const D: usize>(mut sim: Simulation<D>, timed: u64) -> Result<Timed, BenchError> {
    let before = sim.counts();
    let start = Instant::now();
    let target = before.pair + timed;
    while sim.counts().pair < target {
        sim.step().ok_or(BenchError::Stopped)?;
    }
    let seconds = start.elapsed().as_secs_f64();
    let counts = sim.counts().since(&before);
    Ok(Timed { seconds, counts, engine_bytes: sim.memory_bytes(), crowded: sim.crowded(), lists: sim.lists() })
}

/// The timed stretch in two threads: `sim` divided where it stands
/// ([`Divided::from_simulation`]) and run in the order of time until `end` (every item before
/// it); the divided box, for a test to compare.
fn timed_divided<const D: usize>(sim: Simulation<D>, end: f64) -> Result<(Timed, Divided<D>), BenchError> {
    let mut divided = Divided::from_simulation(sim).map_err(BenchError::Setup)?;
    let start = Instant::now();
    divided.run_ordered(end, Lead::Free);
    let seconds = start.elapsed().as_secs_f64();
    let timed = Timed {
        seconds,
        counts: divided.counts(),
        engine_bytes: divided.memory_bytes(),
        crowded: divided.crowded(),
        lists: divided.lists(),
    };
    Ok((timed, divided))
}

fn measure_in<const D: usize>(
    n: usize,
    eta: f64,
    neighbourhood: Neighbourhood,
    warmup_per_particle: u64,
    timed: u64,
    seed: u64,
    threads: usize,
) -> Result<BenchPoint, BenchError> {
    let (particles, sim_box) = initial_state::<D>(n, eta, seed)?;
    let mut sim = Simulation::with_neighbourhood(particles, sim_box, neighbourhood).map_err(BenchError::Setup)?;
    let warmup = warmup_per_particle * n as u64;
    // The clock and count halfway through the warm-up: the rate of its second half (the
    // lattice melted) sets the end time of a run in two threads.
    let mut halfway = (0.0, 0);
    while sim.counts().pair < warmup {
        sim.step().ok_or(BenchError::Stopped)?;
        if halfway.1 == 0 && 2 * sim.counts().pair >= warmup {
            halfway = (sim.time(), sim.counts().pair);
        }
    }
    let Timed { seconds, counts: events_by_kind, engine_bytes, crowded, lists } = if threads == 2 {
        let rate = (sim.counts().pair - halfway.1) as f64 / (sim.time() - halfway.0);
        let end = sim.time() + timed as f64 / rate;
        timed_divided(sim, end)?.0
    } else {
        timed_whole(sim, timed)?
    };
    // Read before the floor allocates; the engine's memory goes first.
    let (peak_rss_bytes, huge_page_bytes) = (peak_rss_bytes(), crate::engine::internals::huge_page_bytes());
    // (The floor needs full rows of neighbours: none below two particles' worth of rows.)
    let floor = (n >= 2 * floor::rows(D) * floor::WIDTH)
        .then(|| floor::measure::<D>(n, eta, 2 * n as u64, timed, seed))
        .transpose()?;
    let collisions = events_by_kind.pair;
    let collisions_per_second = collisions as f64 / seconds;
    Ok(BenchPoint {
        dimension: D,
        n_particles: n,
        packing_fraction: eta,
        neighbourhood,
        lists,
        threads,
        warmup_collisions: warmup,
        collisions,
        seconds,
        collisions_per_second,
        ns_per_collision: seconds * 1e9 / collisions as f64,
        events_per_second: events_by_kind.total() as f64 / seconds,
        events_by_kind,
        engine_bytes_per_particle: engine_bytes as f64 / n as f64,
        crowded_fraction: crowded as f64 / n as f64,
        peak_rss_bytes,
        huge_page_bytes,
        floor_collisions_per_second: floor.as_ref().map(|f| f.collisions_per_second),
        floor_lookahead: floor.as_ref().map(|f| f.lookahead),
        fraction_of_floor: floor.map(|f| collisions_per_second / f.collisions_per_second),
    })
}

/// Untimed warm-up collisions per particle before a point is timed: the lattice start
/// relaxes slowly at η = 0.65, and a point timed before the steady state measures a rattling
/// lattice with half the list rebuilds of the fluid. List rebuilds per collision, a measure
/// of how far the disks wander, reach their steady value (about 0.12) after some 20
/// collisions per particle at any N; at η = 0.3 the rate is steady from the first collision
/// on (the counts are in `benches/HISTORY.md`).
pub const WARMUP: u64 = 20;

/// The matrix: (dimension, N, η), warm-up collisions per particle, timed collisions for N.
/// Disks at η = 0.3 and 0.65, spheres at η = 0.3 and 0.45 (a dense fluid below freezing),
/// N = 10³ … 10⁶; the quick matrix is disks at N = 10³ and 10⁴ and spheres at N = 10⁴, η = 0.45.
pub fn matrix(quick: bool) -> (Vec<(usize, usize, f64)>, u64, fn(usize) -> u64) {
    let sizes: &[usize] = if quick { &[1_000, 10_000] } else { &[1_000, 10_000, 100_000, 1_000_000] };
    let mut points: Vec<(usize, usize, f64)> = sizes.iter().flat_map(|&n| [0.3, 0.65].map(|eta| (2, n, eta))).collect();
    if quick {
        points.push((3, 10_000, 0.45));
    } else {
        points.extend(sizes.iter().flat_map(|&n| [0.3, 0.45].map(|eta| (3, n, eta))));
    }
    if quick {
        (points, WARMUP, |n| (2 * n as u64).max(200_000))
    } else {
        (points, WARMUP, |n| (5 * n as u64).max(2_000_000))
    }
}

/// Today's date (UTC) as YYYY-MM-DD, from the system clock (civil-from-days).
pub fn today() -> String {
    let secs = std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).map(|d| d.as_secs()).unwrap_or(0);
    let z = (secs / 86_400) as i64 + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1_460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = doy - (153 * mp + 2) / 5 + 1;
    let m = if mp < 10 { mp + 3 } else { mp - 9 };
    let y = yoe + era * 400 + i64::from(m <= 2);
    format!("{y:04}-{m:02}-{d:02}")
}

/// The Markdown table of a report.
pub fn markdown(points: &[BenchPoint], command: &str, machine: &str) -> String {
    let mut md = format!(
        "# collide benchmark report\n\n{} · collide {} · {machine} · one core\n\nCommand: `{command}`\n\n\
         | d | N | η | neighbourhood | collisions/s | ns/collision | events/s | pair : wall : rebuild : stale per collision | engine bytes/particle | peak RSS bytes/particle | floor collisions/s | of the floor |\n\
         |---|---|---|---|---|---|---|---|---|---|---|---|\n",
        today(),
        env!("CARGO_PKG_VERSION")
    );
    for p in points {
        let e = &p.events_by_kind;
        let per = |x: u64| x as f64 / e.pair.max(1) as f64;
        md.push_str(&format!(
            "| {} | {} | {} | {} | {:.3e} | {:.0} | {:.3e} | 1 : {:.2} : {:.2} : {:.2} | {:.0} | {} | {} | {} |\n",
            p.dimension,
            p.n_particles,
            p.packing_fraction,
            if p.lists { "lists" } else { "grid" },
            p.collisions_per_second,
            p.ns_per_collision,
            p.events_per_second,
            per(e.wall),
            per(e.rebuild),
            per(e.stale),
            p.engine_bytes_per_particle,
            p.peak_rss_bytes.map_or("—".into(), |b| format!("{:.0}", b as f64 / p.n_particles as f64)),
            p.floor_collisions_per_second.map_or("—".into(), |f| format!("{f:.3e}")),
            p.fraction_of_floor.map_or("—".into(), |f| format!("{:.1} %", 100.0 * f)),
        ));
    }
    md.push_str(
        "\nThe floor: the same N and η with nothing but moving two particles, bouncing them and \
         re-predicting both against fixed neighbours (eight disks, sixteen spheres) with the textbook \
         formula (no queue, no list upkeep, no exact times; `collide::bench::floor`), measured in the \
         same process.\n",
    );
    md
}

/// The chart: collisions per second against N (log₁₀ N on the x axis), one series per
/// dimension and η, and the floor's beside them.
pub fn chart(points: &[BenchPoint]) -> Chart {
    let mut series: Vec<(usize, f64)> = points.iter().map(|p| (p.dimension, p.packing_fraction)).collect();
    // Sorted first: the matrix runs N by N, so equal packing fractions are not adjacent (an
    // unsorted dedup drew every series once per N).
    series.sort_by(|a, b| a.0.cmp(&b.0).then(a.1.total_cmp(&b.1)));
    series.dedup();
    Chart {
        title: "Steady-state collisions per second (one core)".into(),
        x_label: "log₁₀ N (number of particles)".into(),
        y_label: "collisions per second (10⁶/s)".into(),
        legend_left: false,
        series: series
            .iter()
            .flat_map(|&(d, eta)| {
                let at = |rate: fn(&BenchPoint) -> Option<f64>| -> Vec<(f64, f64)> {
                    points
                        .iter()
                        .filter(|p| p.dimension == d && p.packing_fraction == eta)
                        .filter_map(|p| Some(((p.n_particles as f64).log10(), rate(p)? / 1e6)))
                        .collect()
                };
                let what = if d == 2 { "disks" } else { "spheres" };
                let engine = Series::points(&format!("{what}, η = {eta}"), at(|p| Some(p.collisions_per_second)));
                let floor = at(|p| p.floor_collisions_per_second);
                let floor = (!floor.is_empty()).then(|| Series::line(&format!("floor, {what}, η = {eta}"), floor));
                std::iter::once(engine).chain(floor)
            })
            .collect(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The timed stretch in two threads runs the whole box's events, bit for bit: the same
    /// collisions, rebuilds and particle records (every field) as one thread going on to the
    /// same end (spheres with lists, disks with the grid; only the re-prediction markers
    /// differ, as the divided box predicts every particle again where it starts). Fails if the
    /// divided box starts from anything but the warmed-up state, or if the end time is not
    /// honoured.
    #[test]
    fn two_threads_run_the_whole_box_events() {
        fn check<const D: usize>(n: usize, eta: f64, neighbourhood: Neighbourhood) {
            let (particles, sim_box) = initial_state::<D>(n, eta, 7).expect("a start");
            let mut sim = Simulation::with_neighbourhood(particles, sim_box, neighbourhood).expect("valid");
            while sim.counts().pair < 3 * n as u64 {
                sim.step().expect("events go on");
            }
            let mut whole = sim.clone();
            let before = whole.counts();
            for _ in 0..30_000 {
                whole.step().expect("events go on");
            }
            let went = whole.counts().since(&before);
            // Every item before the end in two threads, then the event at the end.
            let (timed, mut divided) = timed_divided(sim, whole.time()).expect("divided");
            divided.step().expect("events go on");
            let c = divided.counts();
            assert_eq!((c.pair, c.wall, c.rebuild), (went.pair, went.wall, went.rebuild), "{D}D: the counts differ");
            assert!(timed.counts.pair > 0 && timed.counts.pair < went.pair);
            assert!(timed.seconds > 0.0 && timed.engine_bytes > 0);
            assert_eq!(timed.lists, neighbourhood != Neighbourhood::Grid);
            assert!(divided.particles() == whole.particles(), "{D}D: the particles differ");
        }
        check::<3>(2048, 0.45, Neighbourhood::Auto);
        check::<2>(2000, 0.65, Neighbourhood::Grid);
    }

    /// Threads other than one or two, and two without a warm-up, are refused by name.
    #[test]
    fn threads_are_one_or_two() {
        let refused = |threads, warmup| match measure(3, 500, 0.4, Neighbourhood::Auto, warmup, 10, 1, threads) {
            Err(BenchError::Option { flag, .. }) => flag,
            other => panic!("not refused: {other:?}"),
        };
        assert_eq!(refused(0, 1), "threads");
        assert_eq!(refused(3, 1), "threads");
        assert_eq!(refused(2, 0), "warmup");
    }
}
