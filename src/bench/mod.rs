//! The benchmarks: steady-state collisions per second across N and packing fraction, beside
//! the hardware's floor ([`floor`]) measured in the same process.
//!
//! Each point builds a periodic box of disks or spheres from a lattice ([`state`]; Maxwell
//! velocities, kT = 1), runs a warm-up that is not timed (so the lattice has melted and the
//! queue has reached its working size), then times a fixed number of pair collisions on one
//! core. Memory is
//! reported twice: the engine's own account of its heap (capacities of the particle array,
//! the event queue, the neighbour lists and their grid) and the process's peak resident set size when each point
//! runs in a process of its own (`collide bench` does that).

pub mod floor;
pub mod state;

pub use state::{BenchError, initial_state};

use crate::engine::{EventCounts, Neighbourhood, Simulation};
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
    /// Untimed warm-up collisions.
    pub warmup_collisions: u64,
    /// Timed pair collisions.
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

/// The process's peak resident set size (Linux `VmHWM`), if readable.
pub fn peak_rss_bytes() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024)
}

/// Measures one point in `d` dimensions (2 or 3): `warmup_per_particle` untimed collisions
/// per particle, then `timed` collisions, with the neighbourhood asked for.
pub fn measure(
    d: usize,
    n: usize,
    eta: f64,
    neighbourhood: Neighbourhood,
    warmup_per_particle: u64,
    timed: u64,
    seed: u64,
) -> Result<BenchPoint, BenchError> {
    match d {
        2 => measure_in::<2>(n, eta, neighbourhood, warmup_per_particle, timed, seed),
        3 => measure_in::<3>(n, eta, neighbourhood, warmup_per_particle, timed, seed),
        _ => Err(BenchError::Option { flag: "dimension", value: d.to_string(), allowed: "2 (disks) or 3 (spheres)" }),
    }
}

fn measure_in<const D: usize>(
    n: usize,
    eta: f64,
    neighbourhood: Neighbourhood,
    warmup_per_particle: u64,
    timed: u64,
    seed: u64,
) -> Result<BenchPoint, BenchError> {
    let (particles, sim_box) = initial_state::<D>(n, eta, seed)?;
    let mut sim = Simulation::with_neighbourhood(particles, sim_box, neighbourhood).map_err(BenchError::Setup)?;
    let warmup = warmup_per_particle * n as u64;
    while sim.counts().pair < warmup {
        sim.step().ok_or(BenchError::Stopped)?;
    }
    let before = sim.counts();
    let start = Instant::now();
    let target = before.pair + timed;
    while sim.counts().pair < target {
        sim.step().ok_or(BenchError::Stopped)?;
    }
    let seconds = start.elapsed().as_secs_f64();
    let events_by_kind = sim.counts().since(&before);
    let (engine_bytes, crowded, lists) = (sim.memory_bytes(), sim.crowded(), sim.lists());
    // Read before the floor allocates; the engine's memory goes first.
    let (peak_rss_bytes, huge_page_bytes) = (peak_rss_bytes(), crate::engine::internals::huge_page_bytes());
    drop(sim);
    // (The floor needs full rows of neighbours: none below two particles' worth of rows.)
    let floor = (n >= 2 * floor::rows(D) * floor::WIDTH)
        .then(|| floor::measure::<D>(n, eta, 2 * n as u64, timed, seed))
        .transpose()?;
    let collisions_per_second = timed as f64 / seconds;
    Ok(BenchPoint {
        dimension: D,
        n_particles: n,
        packing_fraction: eta,
        neighbourhood,
        lists,
        warmup_collisions: warmup,
        collisions: timed,
        seconds,
        collisions_per_second,
        ns_per_collision: seconds * 1e9 / timed as f64,
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
