//! A particle's earliest pair collision among its neighbours, fast — the same answer, bit for
//! bit, as evaluating [`pair::predict`] for every neighbour and taking the earliest in the
//! total order (checked against that, and against the brute-force reference).
//!
//! Two passes. First every neighbour is *bracketed*: the certified f64 filter of the kernel,
//! in the predicted particle's frame ([`contact_brackets_from_origin`]), gives an interval
//! `[lo, hi]` holding the pair's contact time (or says there is none), [`LANES`] neighbours
//! at a time, branch-free, without any double-double arithmetic; the bound becomes the smallest upper end (or the particle's
//! earliest other event). Then only the *candidates* — the neighbours whose lower end
//! reaches down to the bound, usually one — get their exact time: from the bracket itself
//! when both ends round to the same absolute time (rounding is monotone, so that is the time
//! to the bit), else pinned to one ulp ([`Lanes::pinned`]), else from the exact root. A lower
//! end equal to the bound is kept: it may tie and win.
//!
//! The two partners of a collision are searched side by side
//! ([`bracket_both`](Search::bracket_both), then [`settle_both`](Search::settle_both)), their
//! chunks in turn: each search is a chain of dependent steps, and two independent chains keep
//! the core busy where one left it waiting. The rare exact root stays out of line
//! ([`Lanes::predict`]), so that the code the search runs every time stays compact.
//!
//! The neighbours' records are read eight at a time as whole cache lines where AVX-512 is
//! built in ([`lines`]): a chunk is bound by the vector operations it issues, and the
//! field-by-field gather was a hundred of them.
//!
//! Where a vector register holds four f64 rather than eight (AVX2), a chunk of eight is two
//! vectors per value, and a sphere's chunk spills registers; a search's last chunk, when its
//! neighbours fit in four lanes (a sphere has about twelve neighbours in its list: a full
//! chunk and a short one), is bracketed at half the width ([`bracket_half`]) — the same
//! brackets bit for bit (tested), half the vector operations. That chunk comes after the
//! full one has brought the bound down, and most often none of its pairs can meet by then:
//! a cheap certified screen ([`contact_clear_until_from_origin`]: receding, or the gap still
//! open at the bound by the tangent at the start) sees that, and the chunk skips the
//! brackets — lanes that could neither win nor lower the bound, so the same events (tested
//! against the unscreened search and the reference engine).
//!
//! Short periodic axes (several images of one pair) and crowds of more than [`NEAR`]
//! neighbours take the scalar search, one pair at a time with a shrinking horizon; same
//! events.

mod lines;

use super::geometry::{Boundary, Particle, SimBox, image_count, image_count_by_comparison};
use super::motion::{self, Radii};
use super::neighbours::Neighbours;
use super::sources::pair::{self, PairBracket};
use super::sources::{Event, EventKind};
use quadratic::{
    BallLanes, contact_brackets_from_origin, contact_clear_until_from_origin, contact_time_unchecked, narrow_contact,
};

/// Pairs bracketed at once: one AVX-512 register of f64 (two AVX2).
pub const LANES: usize = 8;

/// The lanes of [`bracket_half`], for a chunk whose neighbours fit in half of it.
pub const HALF: usize = LANES / 2;

/// Whether a short chunk is bracketed at half the width ([`bracket_half`]): where a vector
/// register holds fewer than [`LANES`] f64 (AVX2: four), the half-width kernel issues half
/// the vector operations; with AVX-512 one register holds the whole chunk either way.
const HALF_PAYS: bool = !cfg!(target_feature = "avx512f");

/// Neighbours gathered per prediction for the batch search (more: the scalar search).
pub(crate) const NEAR: usize = 64;

/// Brackets kept by the scalar search before it evaluates one exactly on the spot (a
/// particle rarely has more than a handful of approaching neighbours).
const HITS: usize = 32;

/// The batch search's scratch space, kept so that no prediction spends time initialising a
/// kilobyte of stack — two sides of it, so that both partners of a collision can be searched
/// side by side ([`bracket_both`](Search::bracket_both)); and whether the batch is used at
/// all.
#[derive(Clone, Debug)]
pub(crate) struct Search<const D: usize> {
    sides: [Side<D>; 2],
    /// Search with the batch kernel; false when an axis is short (several images per pair)
    /// — and in the test that compares both searches.
    pub(crate) batch: bool,
}

/// One particle's brackets and balls.
///
/// Aligned to a cache line, each array at a multiple of 64 bytes: the lanes are read and
/// written eight f64 at a time, and a vector that straddles two lines costs two accesses.
#[derive(Clone, Debug)]
#[repr(C, align(64))]
struct Side<const D: usize> {
    lo: [f64; NEAR],
    hi: [f64; NEAR],
    lanes: [Lanes<D>; NEAR / LANES],
}

impl<const D: usize> Side<D> {
    fn new() -> Self {
        Side { lo: [f64::INFINITY; NEAR], hi: [f64::INFINITY; NEAR], lanes: [Lanes::default(); NEAR / LANES] }
    }

    /// Pass 1 for the chunk `start..start + LANES` of particle `i`'s `n_near` neighbours
    /// `near`: its brackets, and the smallest upper end. `bound` is the search's bound so far
    /// (a short chunk is screened against it: [`bracket_half`]).
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    fn bracket_chunk(
        &mut self,
        particles: &[Particle<D>],
        sim_box: &SimBox<D>,
        now: f64,
        i: usize,
        near: &[u32; NEAR],
        n_near: usize,
        start: usize,
        bound: f64,
    ) -> f64 {
        let chunk = start..start + LANES;
        let (lo, hi) = (&mut self.lo[chunk.clone()], &mut self.hi[chunk.clone()]);
        let (lo, hi) = (lo.try_into().expect("LANES wide"), hi.try_into().expect("LANES wide"));
        let balls = &mut self.lanes[start / LANES];
        if HALF_PAYS && n_near - start <= HALF {
            let js = near[start..start + HALF].try_into().expect("HALF wide");
            return bracket_half(particles, i, js, n_near - start, sim_box, now, bound, lo, hi, balls);
        }
        let js = near[chunk.clone()].try_into().expect("LANES wide");
        bracket_neighbours(particles, i, js, n_near - start, sim_box, now, lo, hi, balls)
    }

    /// The lanes among the first `n_near` whose contact can come no later than `bound` (a
    /// bit each): the candidates [`settle`](Self::settle) times.
    #[inline(always)]
    fn marked(&self, n_near: usize, bound: f64) -> u64 {
        const { assert!(NEAR <= 64) };
        let lanes = n_near.div_ceil(LANES) * LANES;
        let mut marked = 0u64;
        for (k, &lo) in self.lo[..lanes].iter().enumerate() {
            marked |= ((lo <= bound) as u64) << k;
        }
        marked & if n_near < 64 { (1u64 << n_near) - 1 } else { u64::MAX }
    }

    /// Pass 2: the candidates whose bracket reaches down to `bound`, offered to `best` (the
    /// event of `owner`). Which lanes are candidates is a coin toss for the branch predictor:
    /// they are marked without branches first, one bit each, and the bits are visited lowest
    /// first. Only the neighbours' lanes count: the padding of the last chunk brackets to
    /// [+∞, +∞] too, which an infinite bound (nothing else pending, as for a disk at rest)
    /// would reach.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    fn settle(
        &self,
        particles: &[Particle<D>],
        now: f64,
        owner: u32,
        near: &[u32; NEAR],
        n_near: usize,
        bound: f64,
        best: &mut Event,
    ) {
        let Side { lo, hi, lanes: balls } = self;
        let mut marked = self.marked(n_near, bound);
        while marked != 0 {
            let k = marked.trailing_zeros() as usize;
            marked &= marked - 1;
            let (j, lo, hi) = (near[k] as usize, lo[k], hi[k]);
            let q = &particles[j];
            let lanes = &balls[k / LANES];
            let t = if lo == hi && lo < f64::INFINITY {
                // Both ends round to the same absolute time: that is the time.
                Some(lo)
            } else if let Some(t) = (hi < f64::INFINITY).then(|| lanes.pinned(k % LANES, lo, hi, now)).flatten() {
                // Pinned to one ulp, and settled (`Lanes::pinned`).
                Some(t)
            } else {
                // The exact root, from the balls the brackets were built from.
                lanes.predict(k % LANES, now)
            };
            if let Some(t) = t {
                let e = Event { time: t, kind: EventKind::Pair { partner: j as u32, partner_events: q.events } };
                if e.before(owner, best, owner) {
                    *best = e;
                }
            }
        }
    }
}

impl<const D: usize> Search<D> {
    /// The search for a box with (`batch = false`) or without short periodic axes.
    pub(crate) fn new(batch: bool) -> Self {
        Search { batch, sides: [Side::new(), Side::new()] }
    }

    /// Particle `i`'s neighbours but `skip`, for the batch search: how many, or `None` when
    /// the batch cannot take them (short axes, or more than [`NEAR`]).
    #[inline]
    pub(crate) fn gather(
        &self,
        neighbours: &Neighbours<D>,
        i: usize,
        skip: usize,
        near: &mut [u32; NEAR],
    ) -> Option<usize> {
        if self.batch { neighbours.gather(i, skip, near) } else { None }
    }

    /// Offers particle `i`'s earliest pair event but with `skip` (the partner just resolved
    /// with it: the partner's own prediction covers the pair) to `best`, no earlier than
    /// `now`. `near[..n]` are its neighbours when [`gather`](Self::gather) took them
    /// (`gathered = Some(n)`); `None`: the scalar search.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    pub(crate) fn earliest(
        &mut self,
        particles: &[Particle<D>],
        sim_box: &SimBox<D>,
        short: &[bool; D],
        neighbours: &Neighbours<D>,
        now: f64,
        i: usize,
        skip: usize,
        near: &[u32; NEAR],
        gathered: Option<usize>,
        radii: Radii,
        best: &mut Event,
    ) {
        let Some(n_near) = gathered else {
            return scalar(particles, sim_box, short, neighbours, now, i, skip, radii, best);
        };
        // Pass 1: bracket the neighbours LANES at a time (branch-free); `bound` is the
        // earliest time some candidate is certain to reach. Every chunk is LANES wide (the
        // lanes past the neighbours give [+∞, +∞]), so that no loop below ends at a count
        // the branch predictor cannot know.
        let side = &mut self.sides[0];
        let mut bound = best.time;
        for start in (0..n_near.div_ceil(LANES) * LANES).step_by(LANES) {
            bound = bound.min(side.bracket_chunk(particles, sim_box, now, i, near, n_near, start, bound));
        }
        side.settle(particles, now, i as u32, near, n_near, bound, best);
    }

    /// Pass 1 of [`earliest`](Self::earliest) for two particles at once — the partners of a
    /// collision, `i[0]` and `i[1]`, both gathered by the batch (`gathered[k]` neighbours in
    /// `near[k]`), their events so far `best[k]` —; returns their bounds, for
    /// [`settle_both`](Self::settle_both). Their chunks are bracketed in turn, one of each: a
    /// prediction is a chain of dependent steps (the gather, the motion, the filter, a square
    /// root and a division, the smallest upper end, the pin), and two independent chains
    /// side by side keep the core busy where one alone left it waiting (measured with
    /// alternating runs: `benches/HISTORY.md`).
    #[inline(always)]
    pub(crate) fn bracket_both(
        &mut self,
        particles: &[Particle<D>],
        sim_box: &SimBox<D>,
        now: f64,
        i: [usize; 2],
        near: [&[u32; NEAR]; 2],
        gathered: [usize; 2],
        best: [&Event; 2],
    ) -> [f64; 2] {
        let [a, b] = &mut self.sides;
        let (mut bound_a, mut bound_b) = (best[0].time, best[1].time);
        let chunks = [gathered[0].div_ceil(LANES), gathered[1].div_ceil(LANES)];
        for c in 0..chunks[0].max(chunks[1]) {
            let start = c * LANES;
            if c < chunks[0] {
                bound_a =
                    bound_a.min(a.bracket_chunk(particles, sim_box, now, i[0], near[0], gathered[0], start, bound_a));
            }
            if c < chunks[1] {
                bound_b =
                    bound_b.min(b.bracket_chunk(particles, sim_box, now, i[1], near[1], gathered[1], start, bound_b));
            }
        }
        [bound_a, bound_b]
    }

    /// Calls `f` with the candidates of both sides after [`bracket_both`](Self::bracket_both)
    /// (with its arguments and bounds): the neighbours [`settle_both`](Self::settle_both) will
    /// make an event with.
    #[inline(always)]
    pub(crate) fn candidates(
        &self,
        near: [&[u32; NEAR]; 2],
        gathered: [usize; 2],
        bounds: [f64; 2],
        mut f: impl FnMut(usize),
    ) {
        for s in 0..2 {
            let mut marked = self.sides[s].marked(gathered[s], bounds[s]);
            while marked != 0 {
                f(near[s][marked.trailing_zeros() as usize] as usize);
                marked &= marked - 1;
            }
        }
    }

    /// Pass 2 after [`bracket_both`](Self::bracket_both), with its arguments and bounds: the
    /// same events as two calls of [`earliest`](Self::earliest).
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn settle_both(
        &self,
        particles: &[Particle<D>],
        now: f64,
        i: [usize; 2],
        near: [&[u32; NEAR]; 2],
        gathered: [usize; 2],
        bounds: [f64; 2],
        best: [&mut Event; 2],
    ) {
        let [best_a, best_b] = best;
        self.sides[0].settle(particles, now, i[0] as u32, near[0], gathered[0], bounds[0], best_a);
        self.sides[1].settle(particles, now, i[1] as u32, near[1], gathered[1], bounds[1], best_b);
    }
}

/// The search one pair at a time, for the cases the batch cannot take: short periodic axes
/// (several images per pair), more than [`NEAR`] neighbours (tiny disks among large
/// ones), and growing radii. Same events.
#[cold]
#[allow(clippy::too_many_arguments)]
fn scalar<const D: usize>(
    particles: &[Particle<D>],
    sim_box: &SimBox<D>,
    short: &[bool; D],
    neighbours: &Neighbours<D>,
    now: f64,
    i: usize,
    skip: usize,
    radii: Radii,
    best: &mut Event,
) {
    let p = &particles[i];
    let owner = i as u32;
    let consider = |best: &mut Event, e: Event| {
        if e.before(owner, best, owner) {
            *best = e;
        }
    };
    // Pass 1: bracket every neighbour; `bound` is the earliest time some candidate is
    // certain to reach (an exact event time, or the upper end of a bracket).
    let mut bound = best.time;
    let mut hits = [(0u32, 0.0f64); HITS];
    let mut n_hits = 0;
    for j in neighbours.candidates(i) {
        if j == i || j == skip || !neighbours.searches(i, j) {
            continue;
        }
        let q = &particles[j];
        let exact = match pair::bracket(p, q, sim_box, now, short, bound, radii) {
            PairBracket::Beyond | PairBracket::Known(None) => continue,
            PairBracket::Known(Some(t)) => t,
            PairBracket::Between { lo, hi } if n_hits < HITS => {
                hits[n_hits] = (j as u32, lo.max(now));
                n_hits += 1;
                bound = bound.min(hi.max(now));
                continue;
            }
            // No room left to defer it: evaluate it now.
            PairBracket::Between { .. } => {
                pair::predict(p, q, sim_box, now, short, radii).expect("a bracketed contact")
            }
        };
        let kind = EventKind::Pair { partner: j as u32, partner_events: q.events };
        consider(best, Event { time: exact.max(now), kind });
        bound = bound.min(best.time);
    }
    // Pass 2, as in the batch.
    for &(j, lo) in &hits[..n_hits] {
        if lo > bound {
            continue;
        }
        let j = j as usize;
        let q = &particles[j];
        let t = pair::predict(p, q, sim_box, now, short, radii).expect("a bracketed contact");
        let kind = EventKind::Pair { partner: j as u32, partner_events: q.events };
        consider(best, Event { time: t.max(now), kind });
    }
}

/// [`pair::bracket`] for particle `i` against the neighbours `js[..len]` (up to [`LANES`])
/// at once, when no axis is short, through the branch-free batch kernel
/// [`contact_brackets_from_origin`]. On return, for each `k < len`: if [`pair::predict`] gives `Some(t)`
/// for the pair, then `lo[k] ≤ max(t, now) ≤ hi[k]` (absolute times); `lo[k] = +∞` when it
/// gives `None` (or a time that itself overflows to `+∞`, so a caller searching up to an
/// infinite bound still asks [`pair::predict`]). Lanes `k ≥ len` give `[+∞, +∞]` whatever
/// `js[k]` holds, so a caller can always pass full chunks. Returns the smallest `hi[k]`.
///
/// The balls are exactly those [`pair::predict`] forms (so the certified intervals are
/// [`pair::bracket`]'s to the bit), but built lane by lane without branches: the
/// neighbours' states are gathered first, then the separations and image counts are
/// computed for all lanes at once, which the compiler vectorizes. The balls are left in
/// `lanes`, for the exact roots of the candidates ([`Lanes::predict`]).
#[inline]
#[allow(clippy::too_many_arguments)]
pub fn bracket_neighbours<const D: usize>(
    particles: &[Particle<D>],
    i: usize,
    js: &[u32; LANES],
    len: usize,
    sim_box: &SimBox<D>,
    now: f64,
    lo: &mut [f64; LANES],
    hi: &mut [f64; LANES],
    lanes: &mut Lanes<D>,
) -> f64 {
    let fields = lines::first_lines(&records(particles, i, js, len));
    let Lanes { first, second, t0 } = lanes;
    bracket_fields(&particles[i], &fields, len, sim_box, now, None, lo, hi, first, second, t0)
}

/// [`bracket_neighbours`] for a chunk whose neighbours fit in its first [`HALF`] lanes
/// (`len ≤ HALF`), at half the width, screened against `bound` (an absolute time, no
/// earlier than `now`). Where the vector registers hold fewer f64 than a chunk (AVX2: four),
/// this issues half the vector operations — and a search's last chunk is often this short.
///
/// Two outcomes:
///
/// - **skipped**: when every neighbour's pair certainly meets after `bound` or not at all
///   ([`contact_clear_until_from_origin`] on the balls, against `next_up(bound) − t₀`), every
///   lane gets `[+∞, +∞]` and the return is `+∞`, without the brackets. A search passes
///   its bound so far, which some candidate's exact time or the particle's other event
///   reaches: such lanes can neither win nor lower it, so the search's event is the same.
///   This is the common case for a search's last chunk, bracketed after a full one has
///   brought the bound down (about three in four, for spheres at η = 0.45);
/// - **bracketed**: otherwise, the same brackets as [`bracket_neighbours`] in lanes `..HALF`
///   and the same smallest upper end, bit for bit (each lane is computed alone, and the
///   lanes past the neighbours give `[+∞, +∞]` either way); lanes `HALF..` get `[+∞, +∞]`.
///
/// Either way the balls of lanes `..HALF` are formed (for the candidates' exact times, and
/// for a search with no bound at all, whose `[+∞, +∞]` lanes it still asks), and those of
/// lanes `HALF..` are left as they were (no candidate is ever taken from them).
#[inline]
#[allow(clippy::too_many_arguments)]
pub fn bracket_half<const D: usize>(
    particles: &[Particle<D>],
    i: usize,
    js: &[u32; HALF],
    len: usize,
    sim_box: &SimBox<D>,
    now: f64,
    bound: f64,
    lo: &mut [f64; LANES],
    hi: &mut [f64; LANES],
    lanes: &mut Lanes<D>,
) -> f64 {
    let fields = lines::first_lines_by_field(&records(particles, i, js, len));
    let (mut first, mut second, mut t0) =
        (BallLanes::<D, HALF>::default(), BallLanes::<D, HALF>::default(), [0.0; HALF]);
    let (l, lo_rest) = lo.split_first_chunk_mut::<HALF>().expect("HALF within LANES");
    let (h, hi_rest) = hi.split_first_chunk_mut::<HALF>().expect("HALF within LANES");
    let m =
        bracket_fields(&particles[i], &fields, len, sim_box, now, Some(bound), l, h, &mut first, &mut second, &mut t0);
    lo_rest.fill(f64::INFINITY);
    hi_rest.fill(f64::INFINITY);
    // The balls, for the candidates' exact times; the first ball's positions stay at the
    // origin in both.
    for a in 0..D {
        lanes.first.velocity[a][..HALF].copy_from_slice(&first.velocity[a]);
        lanes.second.position[a][..HALF].copy_from_slice(&second.position[a]);
        lanes.second.velocity[a][..HALF].copy_from_slice(&second.velocity[a]);
    }
    lanes.first.radius[..HALF].copy_from_slice(&first.radius);
    lanes.second.radius[..HALF].copy_from_slice(&second.radius);
    lanes.t0[..HALF].copy_from_slice(&t0);
    m
}

/// The neighbours' records, one lane each (unused lanes pair `i` with itself).
#[inline(always)]
fn records<'a, const D: usize, const W: usize>(
    particles: &'a [Particle<D>],
    i: usize,
    js: &[u32; W],
    len: usize,
) -> [&'a Particle<D>; W] {
    let last = particles.len() - 1;
    core::array::from_fn(|k| &particles[std::hint::select_unpredictable(k < len, js[k] as usize, i).min(last)])
}

/// The body of [`bracket_neighbours`] and [`bracket_half`], `W` lanes wide, from the
/// neighbours' fields (`fields[f][k]`, as [`lines::first_lines`] lays them out); with
/// `screen = Some(bound)`, the brackets are skipped when no lane can meet by `bound` (see
/// [`bracket_half`]).
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn bracket_fields<const D: usize, const W: usize>(
    p: &Particle<D>,
    fields: &[[f64; W]; 8],
    len: usize,
    sim_box: &SimBox<D>,
    now: f64,
    screen: Option<f64>,
    lo: &mut [f64; W],
    hi: &mut [f64; W],
    first: &mut BallLanes<D, W>,
    second: &mut BallLanes<D, W>,
    t0: &mut [f64; W],
) -> f64 {
    let qx: [[f64; W]; D] = core::array::from_fn(|a| fields[a]);
    let qv: [[f64; W]; D] = core::array::from_fn(|a| fields[D + a]);
    let (qt, qr) = (fields[2 * D], fields[2 * D + 1]);
    // The balls, as `pair::predict` forms them: `i` at the origin (the same for every lane)
    // and the neighbour at its separation at `t0`, the later update time, from `i` to the
    // image nearest to `i` at `now`.
    let mut separation = [[0.0; W]; D];
    let mut apart = [[0.0; W]; D];
    // When the predicted particle's own time is `now` (the partners of the collision just
    // resolved: most predictions) and no neighbour's is later, `t₀ = now` in every lane and
    // the separation at `t₀` is the separation at `now`, the same expression: formed once,
    // the same bits.
    let mut fresh = p.time == now;
    for &t in qt.iter() {
        fresh &= t <= now;
    }
    let decided = if fresh {
        separations::<D, W, true>(p, &qx, &qv, &qt, &qr, sim_box, now, &mut separation, &mut apart, first, second, t0)
    } else {
        separations::<D, W, false>(p, &qx, &qv, &qt, &qr, sim_box, now, &mut separation, &mut apart, first, second, t0)
    };
    // A separation near half a box length (or beyond 3/2) needs the division: rare.
    if !decided {
        for a in 0..D {
            if sim_box.boundary[a] == Boundary::Periodic {
                for k in 0..W {
                    let count = image_count(separation[a][k], sim_box.lengths[a]);
                    second.position[a][k] = apart[a][k] + count * sim_box.lengths[a];
                }
            }
        }
    }
    // Screened against a bound: a chunk none of whose lanes can meet by then skips the
    // brackets (`bracket_half`).
    if let Some(bound) = screen {
        // `H ≥ next_up(bound) − t₀` exactly: the difference rounds by at most u of itself
        // (exactly, if subnormal) and the factor 1 + 4u, rounded, makes up for more than that.
        // A contact at `t ≥ H` then falls at `t₀ ⊕ t ≥ next_up(bound)`, after the bound.
        let beyond = bound.next_up();
        let horizon: [f64; W] = core::array::from_fn(|k| (beyond - t0[k]) * (1.0 + 2.0 * f64::EPSILON));
        let clear = contact_clear_until_from_origin(first, second, &horizon);
        // The lanes past the neighbours count as clear; an OR over the lanes, not a branch
        // per lane.
        let len = len as f64;
        let mut open = false;
        for (k, &clear) in clear.iter().enumerate() {
            open |= !clear & ((k as f64) < len);
        }
        if !open {
            lo.fill(f64::INFINITY);
            hi.fill(f64::INFINITY);
            return f64::INFINITY;
        }
    }
    contact_brackets_from_origin(first, second, lo, hi);
    // Absolute times, no earlier than `now`, and +∞ past the neighbours: selects on values
    // computed in every lane, which compile to vector compares and blends (a branch on
    // `k < len` per lane mispredicts in the last chunk, whose length varies).
    let len = len as f64;
    for k in 0..W {
        let floor = if (k as f64) < len { now } else { f64::INFINITY };
        lo[k] = larger(t0[k] + lo[k], floor);
        hi[k] = larger(t0[k] + hi[k], floor);
    }
    // Pairwise, while the ends are still in registers (a fold over the stored array is a
    // serial chain of minima behind store-to-load forwarding).
    const { assert!(W.is_power_of_two()) };
    let mut m = *hi;
    let mut width = W;
    while width > 1 {
        width /= 2;
        for k in 0..width {
            m[k] = smaller(m[k], m[k + width]);
        }
    }
    m[0]
}

/// The balls of [`bracket_fields`]' lanes, as `pair::predict` forms them, and each lane's
/// separation at `now` and at `t₀` (for the rare count the comparisons leave undecided);
/// returns whether the comparisons decided every count. `FRESH`: the predicted particle's
/// own time is `now`, so `t₀ = now` and the separation at `t₀` is the one at `now`.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn separations<const D: usize, const W: usize, const FRESH: bool>(
    p: &Particle<D>,
    qx: &[[f64; W]; D],
    qv: &[[f64; W]; D],
    qt: &[f64; W],
    qr: &[f64; W],
    sim_box: &SimBox<D>,
    now: f64,
    separation: &mut [[f64; W]; D],
    apart: &mut [[f64; W]; D],
    first: &mut BallLanes<D, W>,
    second: &mut BallLanes<D, W>,
    t0: &mut [f64; W],
) -> bool {
    // Whether every lane's count was decided by comparisons, reduced in registers (a flag
    // array stored lane by lane and read back as one vector stalls on store forwarding).
    let mut decided = true;
    for k in 0..W {
        let t = if FRESH { now } else { larger(p.time, qt[k]) };
        t0[k] = t;
        for a in 0..D {
            let d = motion::coordinate(qx[a][k], qv[a][k], now - qt[k])
                - motion::coordinate(p.position[a], p.velocity[a], now - p.time);
            let (count, known) = image_count_by_comparison(d, sim_box.lengths[a]);
            let periodic = sim_box.boundary[a] == Boundary::Periodic;
            let count = if periodic { count } else { 0.0 };
            let at = if FRESH {
                d
            } else {
                motion::coordinate(qx[a][k], qv[a][k], t - qt[k])
                    - motion::coordinate(p.position[a], p.velocity[a], t - p.time)
            };
            first.velocity[a][k] = p.velocity[a];
            second.position[a][k] = at + count * sim_box.lengths[a];
            second.velocity[a][k] = qv[a][k];
            separation[a][k] = d;
            apart[a][k] = at;
            decided &= known | !periodic;
        }
        first.radius[k] = p.radius;
        second.radius[k] = qr[k];
    }
    decided
}

/// The larger of two numbers that are not NaN (as `f64::max`, one vector instruction:
/// `f64::max` also handles NaN, which costs a compare and a blend more per lane). Here the
/// times and ends are never NaN: finite times plus ends in `[0, +∞]`.
#[inline(always)]
fn larger(a: f64, b: f64) -> f64 {
    if a > b { a } else { b }
}

/// The smaller of two numbers that are not NaN (see [`larger`]).
#[inline(always)]
fn smaller(a: f64, b: f64) -> f64 {
    if a < b { a } else { b }
}

/// The balls of one chunk of [`bracket_neighbours`]' lanes, and the `t0` of each.
#[derive(Clone, Copy, Debug, Default)]
pub struct Lanes<const D: usize> {
    /// The predicted particle, in every lane, at the origin: its positions stay `+0.0` (the
    /// default), which [`contact_brackets_from_origin`] assumes without reading them and
    /// [`predict`](Self::predict) and [`pinned`](Self::pinned) read.
    pub first: BallLanes<D, LANES>,
    /// The neighbours.
    pub second: BallLanes<D, LANES>,
    /// The later update time of each pair.
    pub t0: [f64; LANES],
}

impl<const D: usize> Lanes<D> {
    /// [`pair::predict`] for the pair in lane `k` — the same number, as the balls are the
    /// same (and with an infinite horizon the kernel's `contact_time_within` is
    /// [`contact_time_unchecked`]), without forming them again from the particles.
    // Out of line and cold: asked for only where a pin does not settle the time (rarely),
    // and inlined, its double-double root made the search three times the size (10 KB of
    // code in 3D; `benches/HISTORY.md`, "Two partners side by side").
    #[inline(never)]
    #[cold]
    pub fn predict(&self, k: usize, now: f64) -> Option<f64> {
        pair::absolute(contact_time_unchecked(&self.first.get(k), &self.second.get(k)), self.t0[k]).map(|t| t.max(now))
    }

    /// [`predict`](Self::predict) for lane `k` when its bracket's ends `[lo, hi]` (absolute,
    /// as [`bracket_neighbours`] leaves them) round to different times: [`narrow_contact`]
    /// pins the kernel's time `t` to one of two adjacent doubles `x₁ < x₂`; when `t₀ ⊕ x₁` and
    /// `t₀ ⊕ x₂` round to the same absolute time, that is `t₀ ⊕ t` (rounding is monotone),
    /// and otherwise [`Narrowed::time`](quadratic::Narrowed::time) tells `t` itself. The same
    /// number as `predict`'s; `None`: not settled (rarely), ask `predict`.
    ///
    /// Brackets are some tens of ulps of the contact time wide, and early in a run the
    /// clock's ulp is only some tens of the contact time's, so a candidate's ends often round
    /// apart: pinning settles most of those without the double-double root.
    // Out of line, so that profiles show its cost.
    #[inline(never)]
    pub fn pinned(&self, k: usize, lo: f64, hi: f64, now: f64) -> Option<f64> {
        let t0 = self.t0[k];
        let guess = (lo - t0) + 0.5 * (hi - lo);
        let narrowed = narrow_contact(&self.first.get(k), &self.second.get(k), guess)?;
        let (a, b) = ((t0 + narrowed.lo()).max(now), (t0 + narrowed.hi()).max(now));
        if a == b { Some(a) } else { narrowed.time().map(|t| (t0 + t).max(now)) }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::Simulation;

    /// The benchmark's start for `n` particles at `eta`, after 20 collisions a particle: the
    /// particles' own times differ, and some pairs are seen through the periodic boundary.
    fn run_state<const D: usize>(n: usize, eta: f64, seed: u64) -> Simulation<D> {
        let (particles, sim_box) = crate::bench::state::initial_state::<D>(n, eta, seed).expect("a state");
        let mut sim = Simulation::new(particles, sim_box).expect("a simulation");
        for _ in 0..20 * n {
            sim.step().expect("an event");
        }
        sim
    }

    /// A chunk of at most [`HALF`] neighbours gives the same brackets, smallest upper end and
    /// balls at half the width as at the full width, bit for bit — every lane of `lo` and
    /// `hi`, and the balls of the lanes that hold a neighbour (the only ones a candidate is
    /// taken from). The states are a run's, so that the particles' own times differ and
    /// some pairs are seen through the periodic boundary; every particle is tried against
    /// every count of the next particles in its list order, 1 to `HALF`. Unscreened (an
    /// infinite bound; the screened chunk is `screened_chunks_skip_only_later_pairs`).
    fn half_chunks_match<const D: usize>(n: usize, eta: f64) {
        let sim = run_state::<D>(n, eta, 11);
        let (ps, sim_box, now) = (sim.particles(), sim.sim_box(), sim.time());
        let mut tried = 0;
        for i in 0..ps.len() {
            for len in 1..=HALF {
                // The `len` particles after `i` in index order, and some far across the box.
                let js: [u32; HALF] = core::array::from_fn(|k| ((i + 1 + k * (1 + i % 7)) % ps.len()) as u32);
                let mut full = [i as u32; LANES];
                full[..HALF].copy_from_slice(&js);
                let (mut lo, mut hi, mut lanes) = ([0.0; LANES], [0.0; LANES], Lanes::default());
                let m = bracket_neighbours(ps, i, &full, len, sim_box, now, &mut lo, &mut hi, &mut lanes);
                let (mut lo2, mut hi2, mut lanes2) = ([1.0; LANES], [1.0; LANES], Lanes::default());
                let m2 = bracket_half(ps, i, &js, len, sim_box, now, f64::INFINITY, &mut lo2, &mut hi2, &mut lanes2);
                assert_eq!(m.to_bits(), m2.to_bits(), "particle {i}, {len} neighbours");
                for k in 0..LANES {
                    assert_eq!((lo[k].to_bits(), hi[k].to_bits()), (lo2[k].to_bits(), hi2[k].to_bits()), "lane {k}");
                }
                for k in 0..len {
                    assert_eq!(lanes.first.get(k), lanes2.first.get(k), "lane {k}");
                    assert_eq!(lanes.second.get(k), lanes2.second.get(k), "lane {k}");
                    assert_eq!(lanes.t0[k].to_bits(), lanes2.t0[k].to_bits(), "lane {k}");
                }
                tried += lo[..len].iter().filter(|&&l| l < f64::INFINITY).count();
            }
        }
        // Enough lanes bracket a contact that a wrong one would show.
        assert!(tried > n, "{tried} contacts bracketed");
    }

    /// A short chunk screened against a bound ([`bracket_half`]) is either bracketed exactly as
    /// unscreened, bit for bit, or skipped — and skipped only when no neighbour's pair has an
    /// event at or before the bound ([`pair::predict`], the exact time). The chunks are each
    /// particle's nearest neighbours of a run's state, in fours (every count 1 to `HALF`), and
    /// the bounds sit at, one ulp below, and some way either side of the chunk's earliest
    /// event, and at the smallest upper end (what a search passes): a skip one ulp too eager
    /// shows at the event's own time.
    fn screened_chunks_match<const D: usize>(n: usize, eta: f64) {
        let sim = run_state::<D>(n, eta, 5);
        let (ps, sim_box, now) = (sim.particles(), sim.sim_box(), sim.time());
        let short = [false; D];
        let gap = |i: usize, j: usize| {
            let (a, b) = pair::positions(&ps[i], &ps[j], sim_box, now);
            (b - a).norm_squared()
        };
        // (A chunk whose pairs all recede gives `[+∞, +∞]` either way: only skips past a
        // contact differ from the brackets.)
        let (mut skipped_hits, mut kept_at_event) = (0, 0);
        for i in 0..ps.len() {
            let mut others: Vec<usize> = (0..ps.len()).filter(|&j| j != i).collect();
            others.sort_by(|&a, &b| gap(i, a).total_cmp(&gap(i, b)));
            for start in (0..3 * HALF).step_by(HALF) {
                for len in 1..=HALF {
                    let js: [u32; HALF] = core::array::from_fn(|k| others[start + k] as u32);
                    let (mut lo, mut hi, mut lanes) = ([0.0; LANES], [0.0; LANES], Lanes::default());
                    let m = bracket_half(ps, i, &js, len, sim_box, now, f64::INFINITY, &mut lo, &mut hi, &mut lanes);
                    let times: Vec<Option<f64>> = js[..len]
                        .iter()
                        .map(|&j| pair::predict(&ps[i], &ps[j as usize], sim_box, now, &short, Radii::Fixed))
                        .collect();
                    let first = times.iter().flatten().fold(f64::INFINITY, |a, &t| a.min(t));
                    let bounds =
                        [first, first.next_down(), now + 0.5 * (first - now), now + 2.0 * (first - now), m, now];
                    for bound in bounds {
                        let (mut lo2, mut hi2, mut lanes2) = ([1.0; LANES], [1.0; LANES], Lanes::default());
                        let m2 = bracket_half(ps, i, &js, len, sim_box, now, bound, &mut lo2, &mut hi2, &mut lanes2);
                        let same = m.to_bits() == m2.to_bits()
                            && (0..LANES)
                                .all(|k| (lo[k].to_bits(), hi[k].to_bits()) == (lo2[k].to_bits(), hi2[k].to_bits()));
                        if same {
                            kept_at_event += (bound == first && first < f64::INFINITY) as usize;
                            continue;
                        }
                        // Not the unscreened brackets: it must be a skip, and a right one.
                        assert!(
                            m2 == f64::INFINITY && lo2.iter().chain(&hi2).all(|&x| x == f64::INFINITY),
                            "particle {i}"
                        );
                        for (k, t) in times.iter().enumerate() {
                            assert!(t.is_none_or(|t| t > bound), "particle {i}, lane {k}: {t:?} by {bound}");
                        }
                        skipped_hits += 1;
                    }
                }
            }
        }
        // Enough skips of chunks holding a contact, and of chunks kept for an event at the
        // bound itself, that a wrong screen would show.
        assert!(skipped_hits > n, "{skipped_hits} chunks with a contact skipped");
        assert!(kept_at_event > n, "{kept_at_event} chunks kept for an event at the bound");
    }

    /// A full chunk's lanes hold the balls [`pair::predict`] forms, bit for bit: each lane's
    /// exact root ([`Lanes::predict`]) is `pair::predict`'s time to the bit, and its bracket
    /// holds it — whether the predicted particle's own time is earlier than `now` (the
    /// separations formed at `now` and at `t₀`) or `now` itself (formed once: the partners of
    /// a collision). Each particle of a run's state against its eight nearest, both ways
    /// (moved to `now` for the second). A `t₀` or a separation formed at the wrong time moves
    /// the balls, and the roots with them.
    fn lanes_hold_pair_predict<const D: usize>(n: usize, eta: f64) {
        let sim = run_state::<D>(n, eta, 17);
        let (ps, sim_box, now) = (sim.particles(), sim.sim_box(), sim.time());
        let short = [false; D];
        let gap = |i: usize, j: usize| {
            let (a, b) = pair::positions(&ps[i], &ps[j], sim_box, now);
            (b - a).norm_squared()
        };
        let mut moved = ps.to_vec();
        let mut contacts = [0usize; 2];
        for i in 0..ps.len() {
            let mut others: Vec<usize> = (0..ps.len()).filter(|&j| j != i).collect();
            others.sort_by(|&a, &b| gap(i, a).total_cmp(&gap(i, b)));
            let js: [u32; LANES] = core::array::from_fn(|k| others[k] as u32);
            for fresh in [false, true] {
                if fresh {
                    moved[i].advance(now);
                    assert_eq!(moved[i].time, now);
                } else if ps[i].time == now {
                    continue;
                }
                let (mut lo, mut hi, mut lanes) = ([0.0; LANES], [0.0; LANES], Lanes::default());
                bracket_neighbours(&moved, i, &js, LANES, sim_box, now, &mut lo, &mut hi, &mut lanes);
                for (k, &j) in js.iter().enumerate() {
                    let want = pair::predict(&moved[i], &moved[j as usize], sim_box, now, &short, Radii::Fixed);
                    let got = lanes.predict(k, now);
                    assert_eq!(got.map(f64::to_bits), want.map(f64::to_bits), "particle {i}, lane {k}, fresh {fresh}");
                    match want {
                        Some(t) => {
                            assert!(
                                lo[k] <= t && t <= hi[k],
                                "particle {i}, lane {k}: {t} not in [{}, {}]",
                                lo[k],
                                hi[k]
                            );
                            contacts[fresh as usize] += 1;
                        }
                        None => assert_eq!(lo[k], f64::INFINITY, "particle {i}, lane {k}"),
                    }
                }
                moved[i] = ps[i].clone();
            }
        }
        // Enough contacts either way that a wrong ball would show.
        assert!(contacts[0] > n && contacts[1] > n, "{contacts:?} contacts");
    }

    #[test]
    fn lanes_hold_pair_predict_for_disks() {
        lanes_hold_pair_predict::<2>(400, 0.6);
    }

    #[test]
    fn lanes_hold_pair_predict_for_spheres() {
        lanes_hold_pair_predict::<3>(500, 0.45);
    }

    #[test]
    fn screened_chunks_skip_only_later_pairs_for_disks() {
        screened_chunks_match::<2>(400, 0.6);
    }

    #[test]
    fn screened_chunks_skip_only_later_pairs_for_spheres() {
        screened_chunks_match::<3>(500, 0.45);
    }

    #[test]
    fn half_chunks_bracket_as_full_ones_for_disks() {
        half_chunks_match::<2>(400, 0.6);
    }

    #[test]
    fn half_chunks_bracket_as_full_ones_for_spheres() {
        half_chunks_match::<3>(500, 0.45);
    }
}
