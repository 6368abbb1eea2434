//! Events, their total order, and the pure predictions (`predict_*`) shared by the fast
//! engine and the brute-force reference.
//!
//! Every prediction is a pure function of the states involved. A pair is predicted from the
//! later of the two particles' update times, lower index first, so the same two states
//! always give the same event time to the last bit — whichever engine asks, and whenever.

use super::collision::{Body, Impulse, Restitution, resolve_pair};
use super::geometry::{Boundary, Particle, SimBox, image_count, image_count_by_comparison};
use nalgebra::SVector;
use quadratic::{
    Ball, BallLanes, Bracket, Contact, contact_bracket, contact_brackets, contact_time_unchecked, contact_time_within,
    narrow_contact,
};
use serde::{Deserialize, Serialize};
use std::cmp::Ordering;

/// What an event is about.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum EventKind {
    /// Particles `i < j` touch.
    Pair {
        /// The partner (always greater than the event's `i`).
        j: usize,
        /// The partner's event counter at prediction.
        j_events: u32,
    },
    /// Particle `i` hits the wall at the `upper` or lower end of `axis`.
    Wall {
        /// The axis.
        axis: usize,
        /// Upper (at L) or lower (at 0) wall.
        upper: bool,
    },
    /// Particle `i`'s neighbourhood is updated (it leaves its skin, or its cell).
    Rebuild,
    /// A scheduled sampling instant (no particle).
    Sample,
}

impl EventKind {
    fn rank(&self) -> (u8, usize, bool) {
        match *self {
            EventKind::Pair { j, .. } => (0, j, false),
            EventKind::Wall { axis, upper } => (1, axis, upper),
            EventKind::Rebuild => (2, 0, false),
            EventKind::Sample => (3, 0, false),
        }
    }
}

/// A predicted event.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Event {
    /// When.
    pub time: f64,
    /// The (lower-index) particle; `usize::MAX` for samples.
    pub i: usize,
    /// Particle `i`'s event counter at prediction.
    pub i_events: u32,
    /// What.
    pub kind: EventKind,
}

impl Event {
    /// The total order of events: by time, then pair < wall < rebuild < sample, then by the
    /// particles and axes involved. No two distinct live events compare equal, so the
    /// sequence of events never depends on the order in which they were pushed.
    pub fn order(&self, other: &Event) -> Ordering {
        self.time
            .total_cmp(&other.time)
            .then_with(|| self.kind.rank().0.cmp(&other.kind.rank().0))
            .then_with(|| self.i.cmp(&other.i))
            .then_with(|| self.kind.rank().cmp(&other.kind.rank()))
            .then_with(|| self.i_events.cmp(&other.i_events))
    }
}

/// The positions of `i` and of the image of `j` nearest to it, at time `t`.
pub fn pair_positions<const D: usize>(
    pi: &Particle<D>,
    pj: &Particle<D>,
    sim_box: &SimBox<D>,
    t: f64,
) -> (SVector<f64, D>, SVector<f64, D>) {
    let ri = pi.position_at(t);
    let rj = pj.position_at(t);
    let shift = sim_box.minimum_image_shift(&(rj - ri));
    (ri, rj + shift)
}

/// Periodic axes too short for four cells of width `reach`: there a pair can be adjacent
/// through two images at once, so predictions try the images on either side of the nearest.
pub fn short_axes<const D: usize>(sim_box: &SimBox<D>, reach: f64) -> [bool; D] {
    let mut short = [false; D];
    for a in 0..D {
        short[a] = sim_box.boundary[a] == Boundary::Periodic && sim_box.lengths[a] < 4.0 * reach * (1.0 + 1e-9);
    }
    short
}

/// When particles `pi`, `pj` next touch while approaching, as an absolute time.
///
/// The image of `j` is the one nearest to `i` at the current time `now` (and, along
/// `short` axes, the images one box length to either side, the earliest contact winning);
/// the contact itself is computed from the later of the two update times `t0`, so for a
/// given image the answer is a pure function of the two states. It is also the same for
/// `(pj, pi)` as for `(pi, pj)`, to the bit: the kernel is given `i` at the origin and `j`
/// at the separation `Δr = (r_j(t0) − r_i(t0)) + n·L` (`n` the image counts), and swapping
/// the pair negates `Δr` and `Δv` exactly (rounding to nearest is symmetric under negation;
/// the counts are odd functions of the separation), which leaves every product the kernel
/// forms unchanged. So a pair needs no agreed order: the batch search builds its lanes
/// without a select per pair on which particle comes first.
pub fn predict_pair<const D: usize>(
    pi: &Particle<D>,
    pj: &Particle<D>,
    sim_box: &SimBox<D>,
    now: f64,
    short: &[bool; D],
) -> Option<f64> {
    predict_pair_within(pi, pj, sim_box, now, short, f64::INFINITY)
}

/// [`predict_pair`] for a caller that only wants contacts at or before the absolute time
/// `horizon` (the earliest event found so far for a particle).
///
/// Returns `None` only when the pair certainly has no contact whose rounded absolute time
/// is `≤ horizon` — so an event that would tie with the horizon (and might win the tie) is
/// never dropped; otherwise exactly what [`predict_pair`] returns. The kernel's
/// [`contact_time_within`] does the rejection before any double-double arithmetic.
#[inline]
pub fn predict_pair_within<const D: usize>(
    pi: &Particle<D>,
    pj: &Particle<D>,
    sim_box: &SimBox<D>,
    now: f64,
    short: &[bool; D],
    horizon: f64,
) -> Option<f64> {
    if !short.iter().any(|&s| s) {
        let (a, b, t0) = pair_balls(pi, pj, sim_box, now);
        return absolute(contact_time_within(&a, &b, relative_horizon(horizon, t0))?, t0);
    }
    // Image counts (integers); a shift is always formed as one product count·L, so the same
    // image gives the same bits however it was reached.
    let base = sim_box.minimum_image_count(&(pj.position_at(now) - pi.position_at(now)));
    let t0 = pi.time.max(pj.time);
    let h = relative_horizon(horizon, t0);
    let d = pj.position_at(t0) - pi.position_at(t0);
    let a = Ball { position: [0.0; D], velocity: pi.velocity.into(), radius: pi.radius };
    let earliest = |shift: &SVector<f64, D>| {
        let b = Ball { position: (d + shift).into(), velocity: pj.velocity.into(), radius: pj.radius };
        absolute(contact_time_within(&a, &b, h)?, t0)
    };
    // Every combination of −1, 0, +1 box lengths along the short axes.
    let mut best: Option<f64> = None;
    let mut offset = [0i32; D];
    for a in 0..D {
        if short[a] {
            offset[a] = -1;
        }
    }
    loop {
        let mut shift = SVector::zeros();
        for a in 0..D {
            shift[a] = (base[a] + offset[a] as f64) * sim_box.lengths[a];
        }
        if let Some(t) = earliest(&shift) {
            best = Some(best.map_or(t, |b: f64| b.min(t)));
        }
        let mut a = 0;
        while a < D && (!short[a] || offset[a] == 1) {
            if short[a] {
                offset[a] = -1;
            }
            a += 1;
        }
        if a == D {
            return best;
        }
        offset[a] += 1;
    }
}

/// What [`bracket_pair`] knows about a pair's contact, in absolute time.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum PairBracket {
    /// Certainly no contact at or before the horizon.
    Beyond,
    /// Exactly what [`predict_pair`] returns.
    Known(Option<f64>),
    /// [`predict_pair`] returns `Some(t)` with `lo ≤ t ≤ hi`.
    Between {
        /// Lower end.
        lo: f64,
        /// Upper end.
        hi: f64,
    },
}

/// A certified bracket of [`predict_pair`]'s answer, without its double-double root
/// ([`contact_bracket`]): the engine brackets every neighbour of a particle and evaluates
/// exactly only those whose lower end does not exceed the smallest upper end. The bracket
/// `[t0 ⊕ lo, t0 ⊕ hi]` holds `t0 ⊕ Δt` because rounding is monotone. Along short axes
/// (several images) it falls back to [`predict_pair_within`].
#[inline]
pub fn bracket_pair<const D: usize>(
    pi: &Particle<D>,
    pj: &Particle<D>,
    sim_box: &SimBox<D>,
    now: f64,
    short: &[bool; D],
    horizon: f64,
) -> PairBracket {
    if short.iter().any(|&s| s) {
        return match predict_pair_within(pi, pj, sim_box, now, short, horizon) {
            None => PairBracket::Beyond,
            known => PairBracket::Known(known),
        };
    }
    let (a, b, t0) = pair_balls(pi, pj, sim_box, now);
    match contact_bracket(&a, &b, relative_horizon(horizon, t0)) {
        Bracket::Beyond => PairBracket::Beyond,
        Bracket::Known(contact) => PairBracket::Known(absolute(contact, t0)),
        Bracket::Between { lo, hi } => PairBracket::Between { lo: t0 + lo, hi: t0 + hi },
    }
}

/// Pairs bracketed at once by [`bracket_neighbours`]: one AVX-512 register of f64 (two AVX2).
pub const LANES: usize = 8;

/// [`bracket_pair`] for particle `i` against the neighbours `js[..len]` (up to [`LANES`])
/// at once, when no axis is short, through the branch-free batch kernel
/// [`contact_brackets`]. On return, for each `k < len`: if [`predict_pair`] gives `Some(t)`
/// for the pair, then `lo[k] ≤ max(t, now) ≤ hi[k]` (absolute times); `lo[k] = +∞` when it
/// gives `None` (or a time that itself overflows to `+∞`, so a caller searching up to an
/// infinite bound still asks [`predict_pair`]). Lanes `k ≥ len` give `[+∞, +∞]` whatever
/// `js[k]` holds, so a caller can always pass full chunks. Returns the smallest `hi[k]`.
///
/// The balls are exactly those `pair_balls` forms (so the certified intervals are
/// [`bracket_pair`]'s to the bit), but built lane by lane without branches: the neighbours'
/// states are gathered first, then the separations and image counts are computed for all
/// lanes at once, which the compiler vectorizes. Built one pair at a time, the lanes cost
/// twice what the kernel did (profile at N = 10⁴, η = 0.65); since `predict_pair` no longer
/// depends on which particle of a pair comes first, the selects that put the lower index
/// first in every lane are gone too (7 636 → 7 189 instructions per collision, callgrind).
/// The balls are left in `lanes`, for the exact roots of the candidates ([`Lanes::predict`]).
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
    let p = &particles[i];
    let last = particles.len() - 1;
    // Gather: the neighbours' states, one lane each (unused lanes pair `i` with itself).
    let mut qx = [[0.0; LANES]; D];
    let mut qv = [[0.0; LANES]; D];
    let mut qt = [0.0; LANES];
    let mut qr = [0.0; LANES];
    for k in 0..LANES {
        let j = std::hint::select_unpredictable(k < len, js[k] as usize, i).min(last);
        let q = &particles[j];
        for a in 0..D {
            qx[a][k] = q.position[a];
            qv[a][k] = q.velocity[a];
        }
        qt[k] = q.time;
        qr[k] = q.radius;
    }
    // The balls, as `pair_balls` forms them: `i` at the origin (the same for every lane) and
    // the neighbour at its separation at `t0`, the later update time, from `i` to the image
    // nearest to `i` at `now`.
    let Lanes { first, second, t0 } = lanes;
    let mut separation = [[0.0; LANES]; D];
    let mut apart = [[0.0; LANES]; D];
    // Whether every lane's count was decided by comparisons, reduced in registers: stored
    // lane by lane and read back as one vector, a flag array stalled the load on store
    // forwarding (9 % of the prediction's samples in `perf`, N = 10⁴, η = 0.65).
    let mut decided = true;
    for k in 0..LANES {
        let t = p.time.max(qt[k]);
        t0[k] = t;
        for a in 0..D {
            let d = (qx[a][k] + qv[a][k] * (now - qt[k])) - (p.position[a] + p.velocity[a] * (now - p.time));
            let (count, known) = image_count_by_comparison(d, sim_box.lengths[a]);
            let periodic = sim_box.boundary[a] == Boundary::Periodic;
            let count = if periodic { count } else { 0.0 };
            let at = (qx[a][k] + qv[a][k] * (t - qt[k])) - (p.position[a] + p.velocity[a] * (t - p.time));
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
    // A separation near half a box length (or beyond 3/2) needs the division: rare.
    if !decided {
        for a in 0..D {
            if sim_box.boundary[a] == Boundary::Periodic {
                for k in 0..LANES {
                    let count = image_count(separation[a][k], sim_box.lengths[a]);
                    second.position[a][k] = apart[a][k] + count * sim_box.lengths[a];
                }
            }
        }
    }
    contact_brackets(first, second, lo, hi);
    for k in 0..LANES {
        let used = k < len;
        lo[k] = if used { (t0[k] + lo[k]).max(now) } else { f64::INFINITY };
        hi[k] = if used { (t0[k] + hi[k]).max(now) } else { f64::INFINITY };
    }
    // Pairwise, while the ends are still in registers (a fold over the stored array was a
    // serial chain of minima behind store-to-load forwarding).
    const { assert!(LANES.is_power_of_two()) };
    let mut m = *hi;
    let mut width = LANES;
    while width > 1 {
        width /= 2;
        for k in 0..width {
            m[k] = m[k].min(m[k + width]);
        }
    }
    m[0]
}

/// The balls of one chunk of [`bracket_neighbours`]' lanes, and the `t0` of each.
#[derive(Clone, Copy, Debug, Default)]
pub struct Lanes<const D: usize> {
    /// The predicted particle, in every lane.
    pub first: BallLanes<D, LANES>,
    /// The neighbours.
    pub second: BallLanes<D, LANES>,
    /// The later update time of each pair.
    pub t0: [f64; LANES],
}

impl<const D: usize> Lanes<D> {
    /// [`predict_pair`] for the pair in lane `k` — the same number, as the balls are the same
    /// (and with an infinite horizon [`contact_time_within`] is [`contact_time_unchecked`]),
    /// without forming them again from the particles: about a fifth of an exact root's cost
    /// (callgrind, N = 10⁴, η = 0.65).
    #[inline]
    pub fn predict(&self, k: usize, now: f64) -> Option<f64> {
        absolute(contact_time_unchecked(&self.first.get(k), &self.second.get(k)), self.t0[k]).map(|t| t.max(now))
    }

    /// [`predict`](Self::predict) for lane `k` when its bracket's ends `[lo, hi]` (absolute,
    /// as [`bracket_neighbours`] leaves them) round to different times: [`narrow_contact`]
    /// pins the kernel's time `t` to one of two adjacent doubles `x₁ < x₂`; when `t₀ ⊕ x₁` and
    /// `t₀ ⊕ x₂` round to the same absolute time, that is `t₀ ⊕ t` (rounding is monotone),
    /// and otherwise [`Narrowed::time`](quadratic::Narrowed::time) tells `t` itself. The same
    /// number as `predict`'s; `None`: not settled (rarely), ask `predict`.
    ///
    /// A bracket is some tens of ulps of the contact time wide, and the clock's ulp, early in
    /// a run, only some tens of the contact time's: 54 % of the candidates of the benchmark
    /// (N = 10⁴, η = 0.65, 10⁶ collisions from t = 0) had bracket ends rounding apart, 1.1
    /// double-double roots per collision (counted).
    // Out of line, so that profiles show its cost (inlined, it measured the same).
    #[inline(never)]
    pub fn pinned(&self, k: usize, lo: f64, hi: f64, now: f64) -> Option<f64> {
        let t0 = self.t0[k];
        let guess = (lo - t0) + 0.5 * (hi - lo);
        let narrowed = narrow_contact(&self.first.get(k), &self.second.get(k), guess)?;
        let (a, b) = ((t0 + narrowed.lo()).max(now), (t0 + narrowed.hi()).max(now));
        if a == b { Some(a) } else { narrowed.time().map(|t| (t0 + t).max(now)) }
    }
}

/// A contact of a pair whose kernel time starts at `t0`, as an absolute time (`None`: never).
#[inline(always)]
fn absolute(contact: Contact, t0: f64) -> Option<f64> {
    match contact {
        Contact::Never(_) => None,
        Contact::Now => Some(t0),
        Contact::At(dt) => Some(t0 + dt),
    }
}

/// The two balls the kernel is given for a pair when no axis is short, and `t0`, the later
/// of the two update times: `i` at the origin, `j` at the separation at `t0` from `i` to
/// `j`'s image nearest to `i` at `now` (see [`predict_pair`] for why this form).
#[inline]
fn pair_balls<const D: usize>(
    pi: &Particle<D>,
    pj: &Particle<D>,
    sim_box: &SimBox<D>,
    now: f64,
) -> (Ball<D>, Ball<D>, f64) {
    let base = sim_box.minimum_image_count(&(pj.position_at(now) - pi.position_at(now)));
    let t0 = pi.time.max(pj.time);
    let d = (pj.position_at(t0) - pi.position_at(t0)) + base.component_mul(&sim_box.lengths);
    let a = Ball { position: [0.0; D], velocity: pi.velocity.into(), radius: pi.radius };
    let b = Ball { position: d.into(), velocity: pj.velocity.into(), radius: pj.radius };
    (a, b, t0)
}

/// The horizon relative to `t0`, widened so that a dropped contact (exact Δt > h) rounds to
/// an absolute time `t0 ⊕ Δt > horizon`: the margin 2⁻⁴⁴·(|horizon| + |t0|) exceeds the
/// rounding of both subtractions and of the final addition by a factor of over 100.
#[inline]
fn relative_horizon(horizon: f64, t0: f64) -> f64 {
    if horizon == f64::INFINITY {
        f64::INFINITY
    } else {
        (horizon - t0) + f64::from_bits(0x3D30_0000_0000_0000) * (horizon.abs() + t0.abs())
    }
}

/// The first wall particle `p` hits: `(time, axis, upper)`. A particle already touching or
/// beyond a wall (by round-off) and moving into it hits it now.
pub fn predict_wall<const D: usize>(p: &Particle<D>, sim_box: &SimBox<D>) -> Option<(f64, usize, bool)> {
    let mut best: Option<(f64, usize, bool)> = None;
    for a in 0..D {
        if sim_box.boundary[a] != Boundary::Wall || p.velocity[a] == 0.0 {
            continue;
        }
        let upper = p.velocity[a] > 0.0;
        let contact = if upper { sim_box.lengths[a] - p.radius } else { p.radius };
        let dt = ((contact - p.position[a]) / p.velocity[a]).max(0.0);
        if best.is_none_or(|(b, _, _)| dt < b) {
            best = Some((dt, a, upper));
        }
    }
    best.map(|(dt, a, upper)| (p.time + dt, a, upper))
}

/// Resolves the collision of particles `i < j` at time `t`: both are advanced to `t`, their
/// velocities updated along the line of centres (minimum image), their event counters
/// incremented. Returns the impulse on `j` and the contact vector.
pub fn resolve_pair_event<const D: usize>(
    particles: &mut [Particle<D>],
    i: usize,
    j: usize,
    sim_box: &SimBox<D>,
    t: f64,
    restitution: Restitution,
) -> Impulse<D> {
    particles[i].advance(t);
    particles[j].advance(t);
    let (ri, rj) = pair_positions(&particles[i], &particles[j], sim_box, t);
    let (pi, pj) = (&particles[i], &particles[j]);
    let mut a = Body { position: ri, velocity: pi.velocity, mass: pi.mass };
    let mut b = Body { position: rj, velocity: pj.velocity, mass: pj.mass };
    let impulse = resolve_pair(&mut a, &mut b, restitution);
    for (k, body) in [(i, a), (j, b)] {
        particles[k].velocity = body.velocity;
        particles[k].events = particles[k].events.wrapping_add(1);
    }
    impulse
}

/// Resolves particle `p` hitting the `upper` or lower wall of `axis` at time `t`: advanced,
/// the normal velocity reversed if it moves into the wall, the counter incremented. Returns
/// the impulse |Δp| = 2m|v⊥| (0 if it was not moving into the wall).
pub fn resolve_wall_event<const D: usize>(p: &mut Particle<D>, axis: usize, upper: bool, t: f64) -> f64 {
    p.advance(t);
    let v = p.velocity[axis];
    p.events = p.events.wrapping_add(1);
    if v != 0.0 && (v > 0.0) == upper {
        p.velocity[axis] = -v;
        2.0 * p.mass * v.abs()
    } else {
        0.0
    }
}

/// A particle's one pending event (the fast engine keeps exactly one per particle).
///
/// A pair event is stored with the partner's event counter at prediction: when the partner
/// has changed velocity since, the event has become a *re-prediction marker* — its time is
/// still a lower bound on every event of the owner that it stood for, so when it comes up
/// the owner is simply predicted again. The owner's own counter is not stored: whenever the
/// owner changes velocity it is predicted again at once.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Pending {
    /// When (`+∞` for nothing; written `"inf"` in JSON, which has no infinity).
    #[serde(with = "extended_float")]
    pub time: f64,
    /// What.
    pub kind: PendingKind,
}

/// An f64 in JSON with its infinities: finite values as numbers, `±∞` as the strings
/// `"inf"` and `"-inf"` (serde_json writes them as `null`, which reads back as no number).
mod extended_float {
    use serde::{Deserialize, Deserializer, Serializer, de};

    pub fn serialize<S: Serializer>(x: &f64, s: S) -> Result<S::Ok, S::Error> {
        match *x {
            f64::INFINITY => s.serialize_str("inf"),
            f64::NEG_INFINITY => s.serialize_str("-inf"),
            x => s.serialize_f64(x),
        }
    }

    // Through a JSON value: serde_json's exact numbers (`arbitrary_precision`) do not pass
    // through serde's untagged enums.
    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
        match serde_json::Value::deserialize(d)? {
            serde_json::Value::Number(n) => n.as_f64().ok_or_else(|| de::Error::custom(format!("{n} is not an f64"))),
            serde_json::Value::String(w) if w == "inf" => Ok(f64::INFINITY),
            serde_json::Value::String(w) if w == "-inf" => Ok(f64::NEG_INFINITY),
            _ => Err(de::Error::custom("expected a number, \"inf\" or \"-inf\"")),
        }
    }
}

/// What a [`Pending`] event is about.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum PendingKind {
    /// Nothing will ever happen to this particle (it is at rest and alone).
    Nothing,
    /// A collision with `partner`, valid while the partner's counter is `partner_events`.
    Pair {
        /// The other particle.
        partner: u32,
        /// Its event counter at prediction.
        partner_events: u32,
    },
    /// The owner hits the `upper` or lower wall of `axis`.
    Wall {
        /// The axis.
        axis: u8,
        /// Upper (at L) or lower (at 0) wall.
        upper: bool,
    },
    /// The owner's neighbourhood is updated: it leaves its skin (its list is rebuilt) or,
    /// with the grid, its cell.
    Rebuild,
}

/// Rank of a sampling event among events at the same instant (after pairs, walls, rebuilds).
pub const SAMPLE_RANK: u8 = 3;

impl Pending {
    /// Nothing pending.
    pub const NOTHING: Pending = Pending { time: f64::INFINITY, kind: PendingKind::Nothing };

    /// The tie-break key of `owner`'s pending event, the same as [`Event::order`] after the
    /// time: kind rank (pair < wall < rebuild < sample < nothing), lower particle, then partner
    /// or axis and direction.
    #[inline]
    pub fn key(&self, owner: u32) -> (u8, u32, u32, u8) {
        match self.kind {
            PendingKind::Pair { partner, .. } => (0, owner.min(partner), owner.max(partner), 0),
            PendingKind::Wall { axis, upper } => (1, owner, axis as u32, upper as u8),
            PendingKind::Rebuild => (2, owner, 0, 0),
            PendingKind::Nothing => (SAMPLE_RANK + 1, owner, 0, 0),
        }
    }

    /// Whether this event (of `owner`) comes before `other`'s (of `other_owner`).
    #[inline]
    pub fn before(&self, owner: u32, other: &Pending, other_owner: u32) -> bool {
        self.time < other.time || (self.time == other.time && self.key(owner) < other.key(other_owner))
    }
}
