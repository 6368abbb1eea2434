//! Pair collisions: when two particles touch, and the collision rule when they do.
//!
//! *Predict* (pure): the contact time of two particles in free flight, from the verified
//! kernel [`quadratic::contact_time`] (exact never/now/at classification, the time within
//! one ulp) — or, while the radii grow ([`Radii::Growing`]), from
//! [`quadratic::contact_time_growing`] with the same contract. A pair is predicted from the later of the two update times, with the first
//! particle at the origin and the second at its separation, so the same two states always
//! give the same time to the last bit — whichever engine asks, whenever, and in whichever
//! order the pair is named.
//!
//! *Resolve* (mutating): both particles moved to the contact, their velocities changed along
//! the line of centres by the mass-weighted rule ([`crate::engine::collision`]; while the
//! radii grow, the rule that reverses the gap's closing speed), their event counters
//! advanced.
//!
//! The engine evaluates this prediction for a particle against all its neighbours at once
//! through its batch search (`engine/search/`), which gives the same times bit for bit;
//! the reference engine calls [`predict`] for every pair.

use crate::engine::collision::{Body, Impulse, Restitution, resolve_growing_pair};
use crate::engine::geometry::{Boundary, Particle, SimBox};
use crate::engine::motion::Radii;
use nalgebra::SVector;
use quadratic::{Ball, Bracket, Contact, contact_bracket, contact_time_growing_unchecked, contact_time_within};

/// The positions of `i` and of the image of `j` nearest to it, at time `t`.
pub fn positions<const D: usize>(
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
///
/// `radii` says whether the radii grow; a growing pair is given its radii at `t0` and their
/// growth speeds ([`Radii`]), the same for either order.
pub fn predict<const D: usize>(
    pi: &Particle<D>,
    pj: &Particle<D>,
    sim_box: &SimBox<D>,
    now: f64,
    short: &[bool; D],
    radii: Radii,
) -> Option<f64> {
    predict_within(pi, pj, sim_box, now, short, f64::INFINITY, radii)
}

/// [`predict`] for a caller that only wants contacts at or before the absolute time
/// `horizon` (the earliest event found so far for a particle).
///
/// Returns `None` only when the pair certainly has no contact whose rounded absolute time
/// is `≤ horizon` — so an event that would tie with the horizon (and might win the tie) is
/// never dropped; otherwise exactly what [`predict`] returns. The kernel's
/// [`contact_time_within`] does the rejection before any double-double arithmetic (growing
/// pairs are not rejected early).
#[inline]
#[allow(clippy::too_many_arguments)]
pub fn predict_within<const D: usize>(
    pi: &Particle<D>,
    pj: &Particle<D>,
    sim_box: &SimBox<D>,
    now: f64,
    short: &[bool; D],
    horizon: f64,
    radii: Radii,
) -> Option<f64> {
    let rates = [radii.speed(pi.radius), radii.speed(pj.radius)];
    let contact = |a: &Ball<D>, b: &Ball<D>, h: f64| {
        if radii.growing() { Some(contact_time_growing_unchecked(a, b, rates)) } else { contact_time_within(a, b, h) }
    };
    if !short.iter().any(|&s| s) {
        let (a, b, t0) = balls(pi, pj, sim_box, now, radii);
        return absolute(contact(&a, &b, relative_horizon(horizon, t0))?, t0);
    }
    // Image counts (integers); a shift is always formed as one product count·L, so the same
    // image gives the same bits however it was reached.
    let base = sim_box.minimum_image_count(&(pj.position_at(now) - pi.position_at(now)));
    let t0 = pi.time.max(pj.time);
    let h = relative_horizon(horizon, t0);
    let d = pj.position_at(t0) - pi.position_at(t0);
    let a = Ball { position: [0.0; D], velocity: pi.velocity.into(), radius: radii.radius(pi.radius, t0) };
    let rj = radii.radius(pj.radius, t0);
    let earliest = |shift: &SVector<f64, D>| {
        let b = Ball { position: (d + shift).into(), velocity: pj.velocity.into(), radius: rj };
        absolute(contact(&a, &b, h)?, t0)
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

/// What [`bracket`] knows about a pair's contact, in absolute time.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum PairBracket {
    /// Certainly no contact at or before the horizon.
    Beyond,
    /// Exactly what [`predict`] returns.
    Known(Option<f64>),
    /// [`predict`] returns `Some(t)` with `lo ≤ t ≤ hi`.
    Between {
        /// Lower end.
        lo: f64,
        /// Upper end.
        hi: f64,
    },
}

/// A certified bracket of [`predict`]'s answer, without its double-double root
/// ([`contact_bracket`]): a search brackets every neighbour of a particle and evaluates
/// exactly only those whose lower end does not exceed the smallest upper end. The bracket
/// `[t0 ⊕ lo, t0 ⊕ hi]` holds `t0 ⊕ Δt` because rounding is monotone. Along short axes
/// (several images), and for growing radii, it falls back to [`predict_within`].
#[inline]
#[allow(clippy::too_many_arguments)]
pub fn bracket<const D: usize>(
    pi: &Particle<D>,
    pj: &Particle<D>,
    sim_box: &SimBox<D>,
    now: f64,
    short: &[bool; D],
    horizon: f64,
    radii: Radii,
) -> PairBracket {
    if short.iter().any(|&s| s) || radii.growing() {
        return match predict_within(pi, pj, sim_box, now, short, horizon, radii) {
            None => PairBracket::Beyond,
            known => PairBracket::Known(known),
        };
    }
    let (a, b, t0) = balls(pi, pj, sim_box, now, radii);
    match contact_bracket(&a, &b, relative_horizon(horizon, t0)) {
        Bracket::Beyond => PairBracket::Beyond,
        Bracket::Known(contact) => PairBracket::Known(absolute(contact, t0)),
        Bracket::Between { lo, hi } => PairBracket::Between { lo: t0 + lo, hi: t0 + hi },
    }
}

/// A contact of a pair whose kernel time starts at `t0`, as an absolute time (`None`: never).
#[inline(always)]
pub(crate) fn absolute(contact: Contact, t0: f64) -> Option<f64> {
    match contact {
        Contact::Never(_) => None,
        Contact::Now => Some(t0),
        Contact::At(dt) => Some(t0 + dt),
    }
}

/// The two balls the kernel is given for a pair when no axis is short, and `t0`, the later
/// of the two update times: `i` at the origin, `j` at the separation at `t0` from `i` to
/// `j`'s image nearest to `i` at `now` (see [`predict`] for why this form). The batch
/// search forms the same balls lane by lane. The radii are those at `t0`.
#[inline]
fn balls<const D: usize>(
    pi: &Particle<D>,
    pj: &Particle<D>,
    sim_box: &SimBox<D>,
    now: f64,
    radii: Radii,
) -> (Ball<D>, Ball<D>, f64) {
    let base = sim_box.minimum_image_count(&(pj.position_at(now) - pi.position_at(now)));
    let t0 = pi.time.max(pj.time);
    let d = (pj.position_at(t0) - pi.position_at(t0)) + base.component_mul(&sim_box.lengths);
    let a = Ball { position: [0.0; D], velocity: pi.velocity.into(), radius: radii.radius(pi.radius, t0) };
    let b = Ball { position: d.into(), velocity: pj.velocity.into(), radius: radii.radius(pj.radius, t0) };
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

/// Resolves the collision of particles `i < j` at time `t`: both are advanced to `t`, their
/// velocities updated along the line of centres (minimum image), their event counters
/// incremented. Returns the impulse on `j` and the contact vector. While the radii grow,
/// the gap's closing speed is what the rule reverses ([`resolve_growing_pair`]).
pub fn resolve<const D: usize>(
    particles: &mut [Particle<D>],
    i: usize,
    j: usize,
    sim_box: &SimBox<D>,
    t: f64,
    restitution: Restitution,
    radii: Radii,
) -> Impulse<D> {
    particles[i].advance(t);
    particles[j].advance(t);
    let (ri, rj) = positions(&particles[i], &particles[j], sim_box, t);
    let (pi, pj) = (&particles[i], &particles[j]);
    let mut a = Body { position: ri, velocity: pi.velocity, mass: pi.mass };
    let mut b = Body { position: rj, velocity: pj.velocity, mass: pj.mass };
    let impulse = resolve_growing_pair(&mut a, &mut b, restitution, radii.speed(pi.radius) + radii.speed(pj.radius));
    for (k, body) in [(i, a), (j, b)] {
        particles[k].velocity = body.velocity;
        particles[k].events = particles[k].events.wrapping_add(1);
    }
    impulse
}
