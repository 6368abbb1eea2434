//! The earliest contact of two balls whose radii grow while they move (Lubachevsky–Stillinger
//! compression), with the same contract as [`contact_time`].
//!
//! # The question
//!
//! Ball *i* is at `rᵢ + vᵢ·t` with radius `Rᵢ + gᵢ·t` (`gᵢ ≥ 0`, its growth rate). With
//! `Δr = r₂ − r₁`, `Δv = v₂ − v₁`, `σ = R₁ + R₂` and `G = g₁ + g₂`, the gap function
//!
//! `f(t) = |Δr + Δv·t|² − (σ + G·t)² = A·t² + 2b·t + C`, with
//! `A = |Δv|² − G²`, `b = ⟨Δv | Δr⟩ − σG`, `C = |Δr|² − σ²`
//!
//! is positive while the balls are apart. Unlike a rigid pair, `A` has any sign: growth can
//! outrun the relative motion. The quarter discriminant is, by the Lagrange identity
//! `|Δr|²|Δv|² = ⟨Δr|Δv⟩² + |Δr ∧ Δv|²`,
//!
//! `Δ = b² − A·C = |σ·Δv − G·Δr|² − |Δr ∧ Δv|²`,
//!
//! which has no `|Δr|²|Δv|²` terms to cancel (with `G = 0` it is [`contact_time`]'s `D`).
//!
//! # Semantics
//!
//! | condition (exact, on the f64 inputs) | answer |
//! |---|---|
//! | `g₁ = g₂ = 0` | exactly [`contact_time`]'s answer, bit for bit |
//! | `Δv = 0` and `G = 0` | [`Contact::Never`]`(`[`Miss::NoRelativeMotion`]`)` |
//! | `C ≤ 0` (touching or overlapping), `b < 0` | [`Contact::Now`] |
//! | `C ≤ 0`, `b ≥ 0` | `Never(`[`Miss::Receding`]`)` (`b = 0`: tangential, as today) |
//! | `C > 0`, `A < 0` | [`Contact::At`]`(t)`, the single positive root: growth always wins |
//! | `C > 0`, `A = 0`, `b < 0` | `At(C / (−2b))` |
//! | `C > 0`, `A = 0`, `b ≥ 0` | `Never(Receding)` |
//! | `C > 0`, `A > 0`, `b ≥ 0` | `Never(Receding)` |
//! | `C > 0`, `A > 0`, `b < 0`, `Δ ≤ 0` | `Never(`[`Miss::PathsMiss`]`)` (`Δ = 0`: a double root, an exact graze) |
//! | `C > 0`, `A > 0`, `b < 0`, `Δ > 0` | `At(t)`, the smaller root |
//!
//! With `A < 0` the roots' product `C/A` is negative: one root is positive, and `f` falls
//! through zero there (`f(0) = C > 0`, `f → −∞`). Every root is written without cancellation:
//! `t = C / (−b + √Δ)` when `b ≤ 0` (both terms of the denominator non-negative), and
//! `t = (b + √Δ) / (−A)` when `b > 0` (which the table allows only with `A < 0`).
//!
//! # Contract
//!
//! As [`contact_time`]'s: the classification is exact for the exact values of the f64
//! inputs, and `t` is within one ulp of the exact contact time of those inputs, in any
//! dimension and at any overall scale of lengths and of velocities (growth rates are
//! velocities). Proved against the exact big-integer oracle on adversarial families
//! (`A` exactly 0 and within ulps of 0 of both signs, growth-dominated pairs, jammed gaps of
//! 10⁻¹⁴…10⁻⁶ σ, overlaps by ulps, scales 2^±500) in `tests/accuracy.rs`.
//!
//! # Speed
//!
//! As in [`contact_time`]: an f64 filter certifies the signs of `C`, `A`, `b` and `Δ` with
//! rigorous error bounds and the root comes from double-double values; only when a sign is
//! too close to call (`A` within a few ulps of 0, say) does the exact expansion path run.
//! A gap too small for the double-double's absolute accuracy — a pair within about 10⁻⁶ of
//! contact, as every neighbour is near jamming — is summed exactly on the stack instead
//! (its sign exact, its value to 2⁻¹⁰⁴ of itself), so the filter still decides it.

use crate::contact::{
    Acc, DD_ACCEPT, Pair, SLACK, U, differences, exact_gap, filter_c, first_invalid, gap_dd, prescale, scale_exponents,
    scale_pair, valid_balls,
};
use crate::exact::{Dd, Expansion, exponent, pow2, scale2, two_sum};
use crate::{Ball, Contact, ContactError, Field, Miss, contact_time, contact_time_unchecked};
use core::cmp::Ordering;

/// The earliest contact of two balls whose radii grow at `rates = [g₁, g₂]` (length per unit
/// time, each ≥ 0); see the [module docs](self) for the semantics and the contract.
///
/// Errors name the first offending input: the balls' fields as [`contact_time`] does, then
/// a non-finite rate ([`Field::Growth`]) or a negative one ([`ContactError::NegativeGrowth`]).
///
/// ```
/// use quadratic::{contact_time_growing, Ball, Contact, Miss};
/// // Two unit-diameter disks at rest, centres 3 apart, each radius growing at 1/2:
/// // σ(t) = 1 + t reaches 3 at t = 2.
/// let a = Ball { position: [0.0, 0.0], velocity: [0.0, 0.0], radius: 0.5 };
/// let b = Ball { position: [3.0, 0.0], velocity: [0.0, 0.0], radius: 0.5 };
/// assert_eq!(contact_time_growing(&a, &b, [0.5, 0.5]), Ok(Contact::At(2.0)));
/// // Without growth they never meet.
/// assert_eq!(contact_time_growing(&a, &b, [0.0, 0.0]), Ok(Contact::Never(Miss::NoRelativeMotion)));
/// // Receding at speed 2 while the diameter grows at 1: never.
/// let c = Ball { velocity: [2.0, 0.0], ..b };
/// assert_eq!(contact_time_growing(&a, &c, [0.5, 0.5]), Ok(Contact::Never(Miss::Receding)));
/// ```
pub fn contact_time_growing<const D: usize>(
    first: &Ball<D>,
    second: &Ball<D>,
    rates: [f64; 2],
) -> Result<Contact, ContactError> {
    if rates[0] == 0.0 && rates[1] == 0.0 {
        return contact_time(first, second);
    }
    match filtered(first, second, rates) {
        Some(contact) => Ok(contact),
        None => validated_exact(first, second, rates),
    }
}

/// [`contact_time_growing`] for inputs already known to be valid (finite, radii and rates
/// non-negative).
#[inline]
pub fn contact_time_growing_unchecked<const D: usize>(first: &Ball<D>, second: &Ball<D>, rates: [f64; 2]) -> Contact {
    if rates[0] == 0.0 && rates[1] == 0.0 {
        return contact_time_unchecked(first, second);
    }
    filtered(first, second, rates).unwrap_or_else(|| exact_full(first, second, rates))
}

/// The exact (expansion) path alone, bypassing the filter (and the `G = 0` shortcut): for the
/// tests that prove both paths against the oracle. Inputs as for
/// [`contact_time_growing_unchecked`].
#[doc(hidden)]
pub fn contact_time_growing_exact_path<const D: usize>(first: &Ball<D>, second: &Ball<D>, rates: [f64; 2]) -> Contact {
    exact_full(first, second, rates)
}

/// The cold path: invalid inputs are reported here, valid ones go to the exact path.
#[cold]
#[inline(never)]
fn validated_exact<const D: usize>(
    first: &Ball<D>,
    second: &Ball<D>,
    rates: [f64; 2],
) -> Result<Contact, ContactError> {
    if !valid_balls(first, second) {
        return Err(first_invalid(first, second));
    }
    for (ball, value) in [(1u8, rates[0]), (2u8, rates[1])] {
        if !value.is_finite() {
            return Err(ContactError::NonFinite { ball, field: Field::Growth, value });
        }
        if value < 0.0 {
            return Err(ContactError::NegativeGrowth { ball, value });
        }
    }
    Ok(exact_full(first, second, rates))
}

/// The exact path from the inputs: exact differences (TwoSum), scaled, then expansions.
fn exact_full<const D: usize>(first: &Ball<D>, second: &Ball<D>, rates: [f64; 2]) -> Contact {
    // As in `contact_time`: TwoSum is exact unless something near the top of the range
    // overflows; then lengths and/or velocities (growth rates among them) are scaled by 2⁻⁴.
    let differences_at = |lpre: i32, vpre: i32| {
        let (dr, dv, sigma) = differences(first, second, lpre, vpre);
        let vel = |x: f64| if vpre == 0 { x } else { scale2(x, vpre) };
        (dr, dv, sigma, two_sum(vel(rates[0]), vel(rates[1])))
    };
    let (dr, dv, sigma, grow) = differences_at(0, 0);
    let (lpre, vpre) = prescale(&dr, &dv, sigma, Some(grow.0));
    let (dr, dv, sigma, grow) = if lpre == 0 && vpre == 0 { (dr, dv, sigma, grow) } else { differences_at(lpre, vpre) };
    of_differences(&dr, &dv, sigma, grow, vpre - lpre)
}

/// The contact given exact differences `Δr`, `Δv`, `σ` and the growth `G` as (hi, lo)
/// pairs, by the exact path; the time is multiplied by `2^time_exp`.
fn of_differences<const D: usize>(dr: &[Pair; D], dv: &[Pair; D], sigma: Pair, grow: Pair, time_exp: i32) -> Contact {
    // Δv = 0 and G = 0: nothing changes. Lengths and velocities scaled separately to
    // magnitude [1, 2): exact (but for the underflow caveat of the contract); the time
    // scales by 2^(el − ev).
    let (el, ev) = match scale_exponents(dr, dv, sigma, Some(grow.0)) {
        Ok(exponents) => exponents,
        Err(answer) => return answer,
    };
    let (dr, dv) = (dr.map(|p| scale_pair(p, -el)), dv.map(|p| scale_pair(p, -ev)));
    exact(&dr, &dv, scale_pair(sigma, -el), scale_pair(grow, -ev), time_exp + el - ev)
}

/// The exact path on scaled differences: every sign from expansions, the root in
/// double-double from the exact values (relative error ~2⁻¹⁰⁰), rounded once.
fn exact<const D: usize>(dr: &[Pair; D], dv: &[Pair; D], sigma: Pair, grow: Pair, time_exp: i32) -> Contact {
    let ex = |p: Pair| Expansion::from_pair(p.0, p.1);
    let drx: Vec<Expansion> = dr.iter().map(|&p| ex(p)).collect();
    let dvx: Vec<Expansion> = dv.iter().map(|&p| ex(p)).collect();
    let (sx, gx) = (ex(sigma), ex(grow));

    let mut b = sx.mul(&gx).neg();
    for i in 0..D {
        b = b.add(&drx[i].mul(&dvx[i]));
    }
    let mut c = sx.mul(&sx).neg();
    for x in &drx {
        c = c.add(&x.mul(x));
    }
    if c.sign() != Ordering::Greater {
        return if b.sign() == Ordering::Less { Contact::Now } else { Contact::Never(Miss::Receding) };
    }
    let mut a = gx.mul(&gx).neg();
    for x in &dvx {
        a = a.add(&x.mul(x));
    }
    let at = |t: Dd| Contact::At(t.to_f64_scaled(time_exp).max(f64::from_bits(1)));
    match a.sign() {
        Ordering::Equal => {
            // f(t) = 2b·t + C: a root at C/(−2b) when approaching.
            if b.sign() != Ordering::Less {
                return Contact::Never(Miss::Receding);
            }
            at(c.to_dd().div(b.neg().to_dd().mul(Dd::from_f64(2.0))))
        }
        Ordering::Greater if b.sign() != Ordering::Less => Contact::Never(Miss::Receding),
        sign => {
            // Δ = |σΔv − GΔr|² − |Δr ∧ Δv|², evaluated at lengths scaled by 2^k so that the
            // largest term is ~1 (tiny radii would otherwise square into the subnormals).
            let mut terms = Vec::with_capacity(D + D * (D - 1) / 2);
            for i in 0..D {
                terms.push((sx.mul(&dvx[i]).sub(&gx.mul(&drx[i])).compress(), true));
            }
            for i in 0..D {
                for j in i + 1..D {
                    terms.push((drx[i].mul(&dvx[j]).sub(&drx[j].mul(&dvx[i])).compress(), false));
                }
            }
            let m = terms.iter().fold(0.0f64, |m, (x, _)| m.max(x.magnitude()));
            let k = if m == 0.0 { 0 } else { (-exponent(m)).max(0) };
            let mut disc = Expansion::default();
            for (x, plus) in &terms {
                let xk = x.scale2(k);
                let sq = xk.mul(&xk);
                disc = if *plus { disc.add(&sq) } else { disc.sub(&sq) };
            }
            if disc.sign() != Ordering::Greater {
                // Only with A > 0: with A < 0, Δ = b² − A·C > 0.
                debug_assert_eq!(sign, Ordering::Greater);
                return Contact::Never(Miss::PathsMiss);
            }
            let root = disc.to_dd().sqrt();
            let root = Dd { hi: scale2(root.hi, -k), lo: scale2(root.lo, -k) };
            if b.sign() == Ordering::Greater {
                // A < 0 here: t = (b + √Δ)/(−A), two positive terms.
                at(b.to_dd().add(root).div(a.neg().to_dd()))
            } else {
                at(c.to_dd().div(b.neg().to_dd().add(root)))
            }
        }
    }
}

/// The certified answer from the f64 filter and double-double values, or `None` when the
/// exact path must decide (a sign too close to call, a value too small for the double-double
/// bound, inputs outside `2^±150`, or invalid input).
///
/// Notation as in [`contact_time`]'s filter: `Δrᵢ = hᵢ + lᵢ`, `Δvᵢ = gᵢ + mᵢ`, `σ = s + t`,
/// and `G = γ + γ_l` (TwoSum of the rates), heads the rounded f64 values, tails at most u of
/// their heads (u = 2⁻⁵³). Each filter value is a sum of `n` products of two heads, computed
/// with at most `n + 1` roundings, each within u of a partial sum bounded by the scale `S`
/// (the sum of the products' magnitudes); the dropped tails change each product by at most
/// `(2u + u²)` of itself. So every value below errs by at most `(n + 3)·u·S` (plus 2⁻¹⁰⁷⁵
/// per operation through underflow, which `SLACK` covers):
///
/// * `b̃ = Σhᵢgᵢ − sγ`, `P = Σ|hᵢgᵢ| + sγ`, `n = D + 1`: bound `(D + 5)·u·P`;
/// * `C̃` as in [`contact_time`] (`filter_c`);
/// * `Ã = Σgᵢ² − γ²`, `P_A = Σgᵢ² + γ²`, `n = D + 1`: bound `(D + 5)·u·P_A`;
/// * `Δ̃ = Σwᵢ² − Σ_{i<j}xᵢⱼ²` with `wᵢ = sgᵢ − γhᵢ` and `xᵢⱼ = hᵢgⱼ − hⱼgᵢ` (each one FMA and
///   one product): `wᵢ` errs by at most `4.01u·Yᵢ` (`Yᵢ = |sgᵢ| + |γhᵢ|`), so `wᵢ²` by
///   `8.03u·Yᵢ²`, and alike `xᵢⱼ²` by `8.03u·Xᵢⱼ²` (`Xᵢⱼ = |hᵢgⱼ| + |hⱼgᵢ|`); the FMA chain
///   of six terms (`D = 3`) adds `6u` of `S_Δ = ΣYᵢ² + ΣXᵢⱼ²`: about `15u·S_Δ`, bounded by
///   `32u·S_Δ`.
///
/// The double-double values are exact sums of TwoProd heads with every small term
/// accumulated in f64, as in [`contact_time`]: each errs by less than 2⁻⁹⁸ of its scale, so
/// values of at least 2⁻¹⁸ of their scale are relatively within 2⁻⁸⁰, and the root, from a
/// few such values by operations without cancellation, rounds to within one ulp.
#[inline(always)]
fn filtered<const D: usize>(first: &Ball<D>, second: &Ball<D>, rates: [f64; 2]) -> Option<Contact> {
    const HI: f64 = pow2(150);
    const LO: f64 = pow2(-150);
    let s = first.radius + second.radius;
    let grow = rates[0] + rates[1];
    // Comparisons with NaN are false: one flag screens NaN, ±∞ and negative radii and rates.
    let mut ok = first.radius >= 0.0 && second.radius >= 0.0 && rates[0] >= 0.0 && rates[1] >= 0.0;
    ok &= s <= HI && grow <= HI;
    let (mut lmax, mut vmax) = (s, grow);
    let mut h = [0.0; D];
    let mut g = [0.0; D];
    for i in 0..D {
        h[i] = second.position[i] - first.position[i];
        g[i] = second.velocity[i] - first.velocity[i];
        let (ah, ag) = (h[i].abs(), g[i].abs());
        ok &= ah <= HI && ag <= HI;
        lmax = lmax.max(ah);
        vmax = vmax.max(ag);
    }
    if !(ok && lmax >= LO && vmax >= LO) {
        return None;
    }
    let (mut b, mut p) = (-(s * grow), s * grow);
    let (mut a, mut pa) = (-(grow * grow), grow * grow);
    for i in 0..D {
        b = h[i].mul_add(g[i], b);
        p += (h[i] * g[i]).abs();
        a = g[i].mul_add(g[i], a);
        pa = g[i].mul_add(g[i], pa);
    }
    let bound_b = (D as f64 + 5.0) * U * p + SLACK;
    let bound_a = (D as f64 + 5.0) * U * pa + SLACK;
    let (c, q, bound_c) = filter_c(&h, s);
    let (approaching, receding) = (b < -bound_b, b > bound_b);
    // A gap too small for the double-double's absolute accuracy (a pair near contact: what a
    // compression meets all the time near jamming) is summed exactly instead: its sign and
    // its value to 2⁻¹⁰⁴ of itself.
    let (dr, dv, sigma) = differences(first, second, 0, 0);
    let exact_c = if c.abs() < DD_ACCEPT * q { Some(exact_gap(&dr, sigma)?) } else { None };
    let touching = match exact_c {
        Some((sign, _)) => sign != Ordering::Greater,
        None => c < 0.0,
    };
    if touching {
        return match (approaching, receding) {
            (true, _) => Some(Contact::Now),
            (_, true) => Some(Contact::Never(Miss::Receding)),
            _ => None,
        };
    }
    debug_assert!(exact_c.is_some() || c > bound_c);
    // C > 0. Growth wins (A < 0): a contact, whatever b. Otherwise (A > 0) only an approach
    // whose paths truly cross.
    let growth_wins = a < -bound_a;
    if !growth_wins {
        if a <= bound_a {
            return None;
        }
        if receding {
            return Some(Contact::Never(Miss::Receding));
        }
    }
    if !(approaching || receding) {
        return None;
    }
    let (disc, scale_d) = lagrange_disc(&h, &g, s, grow);
    let bound_d = 32.0 * U * scale_d + SLACK;
    if !growth_wins && disc < -bound_d {
        return Some(Contact::Never(Miss::PathsMiss));
    }
    if disc <= bound_d {
        return None;
    }
    // Every sign is certified: the values, in double-double, each accepted when far enough
    // above its error bound.
    if b.abs() < DD_ACCEPT * p || disc < DD_ACCEPT * scale_d {
        return None;
    }
    if receding && -a < DD_ACCEPT * pa {
        return None;
    }
    let st = sigma.1;
    let (gh, gl) = two_sum(rates[0], rates[1]);
    let neg_b = {
        let mut acc = Acc::default();
        acc.prod(s, gh);
        acc.small(s.mul_add(gl, st * gh) + st * gl);
        for i in 0..D {
            let ((h, l), (g, m)) = (dr[i], dv[i]);
            acc.prod(-h, g);
            acc.small(-(h.mul_add(m, l * g) + l * m));
        }
        acc.dd()
    };
    let root = {
        let mut acc = Acc::default();
        for i in 0..D {
            let ((h, l), (g, m)) = (dr[i], dv[i]);
            let mut w = Acc::default();
            w.prod(s, g);
            w.prod(-gh, h);
            w.small(s.mul_add(m, st * g) + st * m - (gh.mul_add(l, gl * h) + gl * l));
            acc.square(w.dd());
        }
        acc.minus_cross_squares(&dr, &dv);
        acc.dd().sqrt()
    };
    let t = if approaching {
        exact_c.map_or_else(|| gap_dd(&dr, sigma), |(_, c)| c).div(neg_b.add(root))
    } else {
        // Receding while growth wins: t = (b + √Δ)/(−A).
        let neg_a = {
            let mut acc = Acc::default();
            acc.prod(gh, gh);
            acc.small((2.0 * gh).mul_add(gl, gl * gl));
            for &(g, m) in &dv {
                acc.prod(-g, g);
                acc.small(-(2.0 * g).mul_add(m, m * m));
            }
            acc.dd()
        };
        neg_b.neg().add(root).div(neg_a)
    };
    Some(Contact::At(t.hi + t.lo))
}

/// `Δ̃ = Σ(sgᵢ − γhᵢ)² − Σ_{i<j}(hᵢgⱼ − hⱼgᵢ)²` in f64 and its scale `S_Δ` (see [`filtered`]).
#[inline(always)]
fn lagrange_disc<const D: usize>(h: &[f64; D], g: &[f64; D], s: f64, grow: f64) -> (f64, f64) {
    let (mut disc, mut scale) = (0.0, 0.0);
    for i in 0..D {
        let w = s.mul_add(g[i], -(grow * h[i]));
        let y = (s * g[i]).abs() + (grow * h[i]).abs();
        disc = w.mul_add(w, disc);
        scale = y.mul_add(y, scale);
    }
    for i in 0..D {
        for j in i + 1..D {
            let (hi, hj, gi, gj) = (h[i], h[j], g[i], g[j]);
            let cross = hi.mul_add(gj, -(hj * gi));
            let x = (hi * gj).abs() + (hj * gi).abs();
            disc = (-cross).mul_add(cross, disc);
            scale = x.mul_add(x, scale);
        }
    }
    (disc, scale)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ball<const D: usize>(position: [f64; D], velocity: [f64; D], radius: f64) -> Ball<D> {
        Ball { position, velocity, radius }
    }

    /// Both paths, which must agree.
    fn both<const D: usize>(p: &Ball<D>, q: &Ball<D>, rates: [f64; 2]) -> Contact {
        let fast = contact_time_growing(p, q, rates).unwrap();
        assert_eq!(fast, contact_time_growing_exact_path(p, q, rates), "filter and exact path disagree");
        fast
    }

    #[test]
    fn every_row_of_the_semantics_table() {
        let a = ball([0.0, 0.0], [0.0, 0.0], 0.5);
        // A < 0 at rest: σ(t) = 1 + t reaches 3 at t = 2.
        assert_eq!(both(&a, &ball([3.0, 0.0], [0.0, 0.0], 0.5), [0.5, 0.5]), Contact::At(2.0));
        // A < 0 while receding at 1/2: 3 + t/2 = 1 + t at t = 4 (b > 0 form).
        assert_eq!(both(&a, &ball([3.0, 0.0], [0.5, 0.0], 0.5), [0.5, 0.5]), Contact::At(4.0));
        // A = 0 (|Δv| = G = 1), approaching head on: 3 − t = 1 + t at t = 1.
        assert_eq!(both(&a, &ball([3.0, 0.0], [-1.0, 0.0], 0.5), [0.5, 0.5]), Contact::At(1.0));
        // A = 0 receding: never.
        assert_eq!(both(&a, &ball([3.0, 0.0], [1.0, 0.0], 0.5), [0.5, 0.5]), Contact::Never(Miss::Receding));
        // A = 0, moving sideways (b = −σG < 0): |(3, t)|² = (1 + t)² at t = 4.
        assert_eq!(both(&a, &ball([3.0, 0.0], [0.0, 1.0], 0.5), [0.5, 0.5]), Contact::At(4.0));
        // A > 0 receding: never.
        assert_eq!(both(&a, &ball([3.0, 0.0], [3.0, 0.0], 0.5), [0.5, 0.5]), Contact::Never(Miss::Receding));
        // A > 0, b < 0, paths miss: far to the side, fast.
        let miss = ball([3.0, 10.0], [-100.0, 0.0], 0.5);
        assert_eq!(both(&a, &miss, [0.001, 0.001]), Contact::Never(Miss::PathsMiss));
        // Touching and growing (b = −σG < 0): now; overlapping and fleeing faster: never.
        assert_eq!(both(&a, &ball([1.0, 0.0], [0.0, 0.0], 0.5), [0.5, 0.0]), Contact::Now);
        assert_eq!(both(&a, &ball([0.5, 0.0], [3.0, 0.0], 0.5), [0.5, 0.5]), Contact::Never(Miss::Receding));
        // No growth: exactly contact_time, reasons included.
        assert_eq!(both(&a, &ball([3.0, 0.0], [0.0, 0.0], 0.5), [0.0, 0.0]), Contact::Never(Miss::NoRelativeMotion));
        // 3D, A < 0: spheres at rest 2 apart, diameter 1 + 2t: t = 1/2.
        let s = ball([0.0, 0.0, 0.0], [0.0; 3], 0.5);
        assert_eq!(both(&s, &ball([0.0, 0.0, 2.0], [0.0; 3], 0.5), [1.0, 1.0]), Contact::At(0.5));
    }

    /// The filter, not the exact path, answers for the pairs a compression meets: neighbours
    /// 1–2.5σ apart with velocity components in [−2, 2], radii growing at 0–0.5 of themselves
    /// per unit time (`A` of either sign). A filter whose bounds were too wide, or that gave up
    /// on `A < 0`, would send them to the expansions, some twenty times slower.
    #[test]
    fn the_filter_decides_ordinary_pairs() {
        let mut unit = crate::uniform_stream(0x9E37_79B9_7F4A_7C15u64);
        let (mut decided, mut growth_wins, cases) = (0, 0, 20_000);
        for _ in 0..cases {
            let p: [f64; 3] = core::array::from_fn(|_| 100.0 * unit());
            let dir: [f64; 3] = core::array::from_fn(|_| unit() - 0.5);
            let n = dir.iter().map(|x| x * x).sum::<f64>().sqrt().max(1e-3);
            let dist = 1.0 + 1.5 * unit();
            let q = core::array::from_fn(|i| p[i] + dist * dir[i] / n);
            let v1 = core::array::from_fn(|_| 4.0 * unit() - 2.0);
            let v2 = core::array::from_fn(|_| 4.0 * unit() - 2.0);
            let rate = 0.5 * unit();
            let (a, b) = (ball(p, v1, 0.5), ball(q, v2, 0.5));
            let rates = [0.5 * rate, 0.5 * rate];
            let fast = filtered(&a, &b, rates);
            decided += usize::from(fast.is_some());
            if let Some(c) = fast {
                assert_eq!(c, contact_time_growing_exact_path(&a, &b, rates));
            }
            let dv2: f64 = (0..3).map(|i| (v2[i] - v1[i]).powi(2)).sum();
            growth_wins += usize::from(dv2 < rate * rate);
        }
        assert!(decided as f64 >= 0.999 * cases as f64, "the filter decided only {decided} of {cases}");
        assert!(growth_wins > 10, "the family should hold pairs with A < 0 ({growth_wins})");
    }

    /// Near jamming every neighbour is a hair from contact: gaps of 10⁻¹⁵…10⁻⁶ diameters
    /// (approaching, receding, sliding). The filter must still decide nearly all of them —
    /// the gap summed exactly on the stack — and agree with the exact path; a filter that
    /// sent them to the expansions made a compression to jamming spend most of its time there.
    #[test]
    fn the_filter_decides_pairs_near_contact() {
        let mut unit = crate::uniform_stream(0x2545_F491_4F6C_DD1Du64);
        let (mut decided, cases) = (0, 20_000);
        for _ in 0..cases {
            let p: [f64; 2] = [40.0 * unit(), 40.0 * unit()];
            let angle = std::f64::consts::TAU * unit();
            let (r1, r2) = (0.5 + 0.2 * unit(), 0.5 + 0.2 * unit());
            let gap = 10f64.powf(-15.0 + 9.0 * unit());
            let d = (r1 + r2) * (1.0 + gap);
            let q = [p[0] + d * angle.cos(), p[1] + d * angle.sin()];
            let v = [unit() - 0.5, unit() - 0.5];
            let (a, b) = (ball(p, [0.0, 0.0], r1), ball(q, v, r2));
            let rates = [1e-3 * r1, 1e-3 * r2];
            if let Some(c) = filtered(&a, &b, rates) {
                decided += 1;
                assert_eq!(c, contact_time_growing_exact_path(&a, &b, rates), "{a:?} {b:?}");
            }
        }
        assert!(decided as f64 >= 0.99 * cases as f64, "the filter decided only {decided} of {cases}");
    }

    #[test]
    fn errors_name_the_rate() {
        let a = ball([0.0, 0.0], [0.0, 0.0], 0.5);
        let e = contact_time_growing(&a, &a, [0.0, -1.0]).unwrap_err();
        assert_eq!(e.to_string(), "g2 = -1 is negative; a growth rate must be ≥ 0 (radii grow or stay)");
        let e = contact_time_growing(&a, &a, [f64::INFINITY, 0.0]).unwrap_err();
        assert_eq!(e.to_string(), "g1 = inf is not finite");
        // The balls' own errors come first.
        let bad = ball([0.0, f64::NAN], [0.0, 0.0], 0.5);
        assert_eq!(contact_time_growing(&bad, &a, [-1.0, 0.0]).unwrap_err().to_string(), "r1[1] = NaN is not finite");
    }
}
