//! The earliest contact time of two balls (disks in 2D, spheres in 3D) in uniform motion.
//!
//! # The question
//!
//! Ball *i* is at `rᵢ + vᵢ·t` with radius `Rᵢ`. With `Δr = r₂ − r₁`, `Δv = v₂ − v₁`,
//! `σ = R₁ + R₂`, they touch when `|Δr + Δv·t|² = σ²`, i.e. (seed eq. 5–7)
//!
//! `a·t² + 2b·t + c = 0`, with `a = |Δv|²`, `b = ⟨Δv | Δr⟩`, `c = |Δr|² − σ²`.
//!
//! # Semantics
//!
//! | condition (exact, on the f64 inputs) | answer |
//! |---|---|
//! | `Δv = 0` | [`Contact::Never`]`(`[`Miss::NoRelativeMotion`]`)` |
//! | `b ≥ 0`: separating, or tangential — even when overlapping | `Never(`[`Miss::Receding`]`)` |
//! | `b < 0` and `c ≤ 0`: approaching while touching or overlapping | [`Contact::Now`] (`t = 0`) |
//! | `b < 0`, `c > 0`, `D ≤ 0`: the paths miss, or only graze | `Never(`[`Miss::PathsMiss`]`)` |
//! | `b < 0`, `c > 0`, `D > 0` | [`Contact::At`]`(t)`, `t = c / (−b + √D)` |
//!
//! where `D = b² − a·c` is, by the Lagrange identity, `D = |Δv|²·σ² − |Δr ∧ Δv|²`
//! (in 2D `Δr ∧ Δv = Δx·Δv_y − Δy·Δv_x`; in 3D the cross product). This form has no
//! `|Δr|²` terms to cancel, and `t = c / (−b + √D)` is the smaller root written without
//! cancellation (both terms of the denominator are positive). An exact graze (`D = 0`)
//! is a miss: the normal relative velocity vanishes at the touching instant, so there is
//! nothing to resolve. Two balls of zero radius never collide (their contact would be a
//! graze).
//!
//! # Accuracy contract
//!
//! * The classification (never / now / at) is **exact** for the exact values of the f64
//!   inputs: `Δr`, `Δv` and `σ` are formed without rounding (TwoSum), and every sign is
//!   either certified by a rigorous error bound or computed exactly with expansions.
//! * `t` is **within one ulp** of the exact contact time of the f64 inputs (not of rounded
//!   `a`, `b`, `c`); a contact time beyond `f64::MAX` is `+∞`, one below the smallest
//!   subnormal is the smallest subnormal (so `At(t)` always has `t > 0`).
//!
//! Both hold whenever the differences can be scaled by powers of two without loss: lengths
//! are scaled by one power of two and velocities by another, so any overall scale works;
//! only a component more than about 2⁹⁰⁰ times smaller than the largest of its kind can lose
//! bits (to underflow) — far outside any physical configuration, and documented here rather
//! than hidden.
//!
//! # Speed
//!
//! The answer is first computed in f64 and double-double with rigorous error bounds (a
//! "filter", as in Shewchuk's adaptive predicates); only when a bound cannot certify a sign,
//! or the inputs leave the range `2^±150` where the bounds are proved, does the exact
//! expansion path run. Typical simulation pairs never reach it.

use crate::exact::{
    Dd, Expansion, compress_in_place, dd_of_compressed, exponent, grow_in_place, pow2, scale2, sign_of, two_prod,
    two_sum,
};
use core::cmp::Ordering;
use core::fmt;

/// A ball in uniform motion: position, velocity and radius, in any consistent units.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ball<const D: usize> {
    /// Position at `t = 0`.
    pub position: [f64; D],
    /// Constant velocity.
    pub velocity: [f64; D],
    /// Radius (≥ 0).
    pub radius: f64,
}

/// Why two balls never touch while approaching.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Miss {
    /// `Δv = 0` exactly: their distance never changes.
    NoRelativeMotion,
    /// `⟨Δv | Δr⟩ ≥ 0`: separating or moving tangentially (also when overlapping).
    Receding,
    /// Approaching, but the closest approach is at or beyond contact (`D ≤ 0`).
    PathsMiss,
}

/// When two balls first touch while approaching.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Contact {
    /// Never, and why.
    Never(Miss),
    /// Approaching and already touching or overlapping: collide at `t = 0`.
    Now,
    /// First contact at this time, `t > 0`.
    At(f64),
}

impl Contact {
    /// The contact time: `None` for never, `Some(0.0)` for now.
    pub fn time(&self) -> Option<f64> {
        match *self {
            Contact::Never(_) => None,
            Contact::Now => Some(0.0),
            Contact::At(t) => Some(t),
        }
    }
}

/// Which input of [`contact_time`] is at fault.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Field {
    /// Component `i` of the position.
    Position(usize),
    /// Component `i` of the velocity.
    Velocity(usize),
    /// The radius.
    Radius,
    /// The growth rate of the radius ([`contact_time_growing`](crate::contact_time_growing)).
    Growth,
}

/// Why [`contact_time`] refused its input.
#[non_exhaustive]
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ContactError {
    /// A NaN or infinite input.
    NonFinite {
        /// 1 or 2: which ball.
        ball: u8,
        /// Which field.
        field: Field,
        /// The value.
        value: f64,
    },
    /// A negative radius.
    NegativeRadius {
        /// 1 or 2: which ball.
        ball: u8,
        /// The value.
        value: f64,
    },
    /// A negative growth rate ([`contact_time_growing`](crate::contact_time_growing)): radii
    /// may grow or stay, not shrink.
    NegativeGrowth {
        /// 1 or 2: which ball.
        ball: u8,
        /// The value.
        value: f64,
    },
}

impl fmt::Display for ContactError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let name = |ball: u8, field: Field| match field {
            Field::Position(i) => format!("r{ball}[{i}]"),
            Field::Velocity(i) => format!("v{ball}[{i}]"),
            Field::Radius => format!("R{ball}"),
            Field::Growth => format!("g{ball}"),
        };
        match *self {
            ContactError::NonFinite { ball, field, value } => {
                write!(f, "{} = {value} is not finite", name(ball, field))
            }
            ContactError::NegativeRadius { ball, value } => {
                write!(f, "R{ball} = {value} is negative; a radius must be ≥ 0")
            }
            ContactError::NegativeGrowth { ball, value } => {
                write!(f, "g{ball} = {value} is negative; a growth rate must be ≥ 0 (radii grow or stay)")
            }
        }
    }
}

impl std::error::Error for ContactError {}

/// The earliest contact of two balls; see the [module docs](self) for semantics and contract.
///
/// ```
/// use quadratic::{contact_time, Ball, Contact, Miss};
/// let a = Ball { position: [0.0, 0.0], velocity: [1.0, 0.0], radius: 0.5 };
/// let b = Ball { position: [3.0, 0.0], velocity: [-1.0, 0.0], radius: 0.5 };
/// assert_eq!(contact_time(&a, &b), Ok(Contact::At(1.0)));
/// let c = Ball { position: [3.0, 0.0], velocity: [1.0, 0.0], radius: 0.5 };
/// assert_eq!(contact_time(&a, &c), Ok(Contact::Never(Miss::NoRelativeMotion)));
/// ```
pub fn contact_time<const D: usize>(first: &Ball<D>, second: &Ball<D>) -> Result<Contact, ContactError> {
    match filtered::<D, false>(first, second, f64::INFINITY) {
        Verdict::Decided(contact) => Ok(contact),
        _ => validated_exact(first, second),
    }
}

/// The cold path of [`contact_time`]: invalid inputs are reported here, valid ones go to
/// the exact path.
#[cold]
#[inline(never)]
fn validated_exact<const D: usize>(first: &Ball<D>, second: &Ball<D>) -> Result<Contact, ContactError> {
    if valid_balls(first, second) { Ok(exact_full(first, second)) } else { Err(first_invalid(first, second)) }
}

/// Whether both balls have finite coordinates and finite, non-negative radii.
pub(crate) fn valid_balls<const D: usize>(first: &Ball<D>, second: &Ball<D>) -> bool {
    [first, second]
        .iter()
        .all(|b| b.position.iter().chain(&b.velocity).all(|x| x.is_finite()) && b.radius.is_finite() && b.radius >= 0.0)
}

/// The first offending input (cold path of [`contact_time`]).
#[cold]
pub(crate) fn first_invalid<const D: usize>(first: &Ball<D>, second: &Ball<D>) -> ContactError {
    for (ball, b) in [(1u8, first), (2u8, second)] {
        for i in 0..D {
            for (field, value) in [(Field::Position(i), b.position[i]), (Field::Velocity(i), b.velocity[i])] {
                if !value.is_finite() {
                    return ContactError::NonFinite { ball, field, value };
                }
            }
        }
        if !b.radius.is_finite() {
            return ContactError::NonFinite { ball, field: Field::Radius, value: b.radius };
        }
        if b.radius < 0.0 {
            return ContactError::NegativeRadius { ball, value: b.radius };
        }
    }
    unreachable!("first_invalid called on valid input")
}

/// A length or velocity difference held exactly as `hi + lo` (TwoSum output).
pub(crate) type Pair = (f64, f64);

/// [`contact_time`] for inputs already known to be finite with non-negative radii.
#[inline]
pub fn contact_time_unchecked<const D: usize>(first: &Ball<D>, second: &Ball<D>) -> Contact {
    match filtered::<D, false>(first, second, f64::INFINITY) {
        Verdict::Decided(contact) => contact,
        _ => exact_full(first, second),
    }
}

/// [`contact_time_unchecked`] for a caller that only wants contacts at or before `horizon`
/// (the earliest event found so far, in an event-driven simulation).
///
/// Returns `None` only when the balls certainly do not touch at or before `horizon`: the
/// exact contact time of the f64 inputs is later than `horizon`, or there is none.
/// Otherwise it returns exactly `Some(contact_time_unchecked(first, second))` — which may
/// itself be a `Never`, or a time after `horizon` when the cheap bound could not decide.
///
/// The test is a certified lower bound that costs a comparison: when the filter has
/// certified `b < 0` and `c > 0`, then `√D ≤ −b` (as `D = b² − a·c ≤ b²`), so
///
/// `t = c / (−b + √D) ≥ c / (−2b)`,
///
/// and with the filter's error bounds `|b − b̃| ≤ β`, `|c − c̃| ≤ γ` the pair is rejected
/// when `(c̃ − γ) > 2·horizon·(−b̃ + β)` holds with a further margin for the rounding of
/// that comparison. The double-double root (the expensive part of a hit) is then never
/// computed. The classification of what is returned stays exact.
///
/// ```
/// use quadratic::{contact_time_within, Ball, Contact};
/// let a = Ball { position: [0.0, 0.0], velocity: [1.0, 0.0], radius: 0.5 };
/// let b = Ball { position: [5.0, 0.0], velocity: [-1.0, 0.0], radius: 0.5 };
/// assert_eq!(contact_time_within(&a, &b, 1.0), None); // they touch at t = 2
/// assert_eq!(contact_time_within(&a, &b, 2.0), Some(Contact::At(2.0)));
/// ```
#[inline]
pub fn contact_time_within<const D: usize>(first: &Ball<D>, second: &Ball<D>, horizon: f64) -> Option<Contact> {
    match filtered::<D, false>(first, second, horizon) {
        Verdict::Decided(contact) => Some(contact),
        Verdict::Beyond => None,
        _ => Some(exact_full(first, second)),
    }
}

/// A contact time known to lie in an interval, from [`contact_bracket`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Bracket {
    /// Certainly no contact at or before the horizon (the exact time is later, or there is none).
    Beyond,
    /// The answer, exactly as [`contact_time_unchecked`] gives it.
    Known(Contact),
    /// A contact: [`contact_time_unchecked`] returns `At(t)` with `lo ≤ t ≤ hi`.
    Between {
        /// Lower end (≥ 0).
        lo: f64,
        /// Upper end.
        hi: f64,
    },
}

/// A cheap certified bracket of the contact time, for a caller that looks for the earliest of
/// many contacts (an event-driven simulation predicting one particle against its neighbours):
/// bracket them all, then evaluate [`contact_time_unchecked`] only for the contacts whose
/// lower end does not exceed the smallest upper end — usually one.
///
/// The filter's f64 values `b̃`, `D̃` and their error bounds `β`, `δ`, and a compensated
/// `c̃ = |Δr|² − σ²` (TwoSum tails of the differences, TwoProd squares, the heads summed
/// exactly) with its bound `γ ≈ 2u·c̃`, give
///
/// `(c̃ − γ) / (−b̃ + β + √(D̃ + δ)) ≤ t ≤ (c̃ + γ) / (−b̃ − β + √(D̃ − δ))`
///
/// to first order in the bounds — computed with one square root and one division, the
/// second-order terms bounded (see `bracket_ends`) — and widened by 12u for the rounding of
/// these expressions and the one ulp of the returned time. Typical pairs get a bracket some
/// tens of ulps wide (it is the plain f64 `c`, whose error grows like u·(|Δr|² + σ²)/c near
/// contact, that would make it hundreds) at the cost of one square root, one division and a
/// dozen error-free operations; the double-double root is left for the one pair that needs
/// it. When the filter cannot decide, the exact path runs and the answer is
/// [`Bracket::Known`]. A lower end later than `horizon` gives [`Bracket::Beyond`] (pass `+∞`
/// for none).
///
/// ```
/// use quadratic::{contact_bracket, Ball, Bracket};
/// let a = Ball { position: [0.0, 0.0], velocity: [1.0, 0.0], radius: 0.5 };
/// let b = Ball { position: [5.0, 0.0], velocity: [-1.0, 0.0], radius: 0.5 };
/// let Bracket::Between { lo, hi } = contact_bracket(&a, &b, f64::INFINITY) else { panic!() };
/// assert!(lo <= 2.0 && 2.0 <= hi && hi - lo < 1e-13);
/// assert_eq!(contact_bracket(&a, &b, 1.0), Bracket::Beyond);
/// ```
#[inline]
pub fn contact_bracket<const D: usize>(first: &Ball<D>, second: &Ball<D>, horizon: f64) -> Bracket {
    match filtered::<D, true>(first, second, horizon) {
        Verdict::Decided(contact) => Bracket::Known(contact),
        Verdict::Beyond => Bracket::Beyond,
        Verdict::Between(lo, hi) => Bracket::Between { lo, hi },
        Verdict::Undecided => Bracket::Known(exact_full(first, second)),
    }
}

/// `L` balls in structure-of-arrays form (lane `k` is one ball), for [`contact_brackets`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BallLanes<const D: usize, const L: usize> {
    /// `position[axis][lane]`.
    pub position: [[f64; L]; D],
    /// `velocity[axis][lane]`.
    pub velocity: [[f64; L]; D],
    /// `radius[lane]`.
    pub radius: [f64; L],
}

impl<const D: usize, const L: usize> Default for BallLanes<D, L> {
    fn default() -> Self {
        BallLanes { position: [[0.0; L]; D], velocity: [[0.0; L]; D], radius: [0.0; L] }
    }
}

impl<const D: usize, const L: usize> BallLanes<D, L> {
    /// Puts `ball` into lane `k`.
    #[inline]
    pub fn set(&mut self, k: usize, ball: &Ball<D>) {
        for axis in 0..D {
            self.position[axis][k] = ball.position[axis];
            self.velocity[axis][k] = ball.velocity[axis];
        }
        self.radius[k] = ball.radius;
    }

    /// The ball in lane `k`.
    pub fn get(&self, k: usize) -> Ball<D> {
        Ball {
            position: core::array::from_fn(|axis| self.position[axis][k]),
            velocity: core::array::from_fn(|axis| self.velocity[axis][k]),
            radius: self.radius[k],
        }
    }
}

/// [`contact_bracket`] for `L` pairs at once, without branches: lane `k` of `first` against
/// lane `k` of `second`. On return `lo[k] ≤ T ≤ hi[k]`, where `T` is the time of
/// [`contact_time_unchecked`]`(first_k, second_k)` — `0` for [`Contact::Now`], `t` for
/// `At(t)`, `+∞` for `Never`:
///
/// | the filter certifies | `[lo, hi]` |
/// |---|---|
/// | receding (`b > 0`) or missing paths (`D < 0`) | `[+∞, +∞]` |
/// | approaching while overlapping (`b < 0`, `c < 0`) | `[0, 0]` |
/// | a contact (`b < 0`, `c > 0`, `D > 0`) | exactly [`contact_bracket`]'s `Between { lo, hi }` |
/// | nothing (a sign too close to call, or inputs outside `2^±150`, NaN, ∞) | `[0, +∞]` |
///
/// Every lane computes every step and the verdicts are merged by selects, so the compiler
/// can keep all `L` lanes in vector registers (the engine uses `L = 8`, one AVX-512
/// register or two AVX2 ones): on a particle's neighbours the verdict is data-dependent
/// and close to a coin toss (about half the neighbours recede), which a branch per pair
/// mispredicts. The caller evaluates [`contact_time_unchecked`] only where `lo` does not
/// exceed the smallest `hi`. Unused lanes may hold anything; their output is meaningless.
///
/// ```
/// use quadratic::{contact_brackets, Ball, BallLanes};
/// let mut first = BallLanes::<2, 4>::default();
/// let mut second = BallLanes::<2, 4>::default();
/// first.set(0, &Ball { position: [0.0, 0.0], velocity: [1.0, 0.0], radius: 0.5 });
/// second.set(0, &Ball { position: [5.0, 0.0], velocity: [-1.0, 0.0], radius: 0.5 }); // t = 2
/// first.set(1, &Ball { position: [0.0, 0.0], velocity: [-1.0, 0.0], radius: 0.5 });
/// second.set(1, &Ball { position: [5.0, 0.0], velocity: [1.0, 0.0], radius: 0.5 }); // receding
/// let (mut lo, mut hi) = ([0.0; 4], [0.0; 4]);
/// contact_brackets(&first, &second, &mut lo, &mut hi);
/// assert!(lo[0] <= 2.0 && 2.0 <= hi[0] && hi[0] - lo[0] < 1e-13);
/// assert_eq!((lo[1], hi[1]), (f64::INFINITY, f64::INFINITY));
/// ```
#[inline]
pub fn contact_brackets<const D: usize, const L: usize>(
    first: &BallLanes<D, L>,
    second: &BallLanes<D, L>,
    lo: &mut [f64; L],
    hi: &mut [f64; L],
) {
    brackets::<D, L, false>(first, second, lo, hi)
}

/// [`contact_brackets`] with every first ball at the origin: `first.position` is not read,
/// and each lane's brackets are those `contact_brackets` gives with `first.position` all
/// `+0.0`, bit for bit — for the frame of an event-driven engine, whose predicted particle
/// sits at the origin of every pair it forms. The difference `second − first` is then the
/// second position itself, exactly, and its TwoSum in the compensated gap has a zero tail,
/// which saves a few operations in every lane.
///
/// ```
/// use quadratic::{contact_brackets, contact_brackets_from_origin, Ball, BallLanes};
/// let mut first = BallLanes::<3, 8>::default();
/// let mut second = BallLanes::<3, 8>::default();
/// for k in 0..8 {
///     first.set(k, &Ball { position: [0.0; 3], velocity: [1.0, 0.0, 0.0], radius: 0.5 });
///     let y = 0.1 * k as f64;
///     second.set(k, &Ball { position: [5.0, y, 0.0], velocity: [-1.0, 0.0, 0.0], radius: 0.5 });
/// }
/// let (mut lo, mut hi) = ([0.0; 8], [0.0; 8]);
/// let (mut lo0, mut hi0) = ([0.0; 8], [0.0; 8]);
/// contact_brackets(&first, &second, &mut lo, &mut hi);
/// contact_brackets_from_origin(&first, &second, &mut lo0, &mut hi0);
/// assert_eq!((lo, hi), (lo0, hi0));
/// assert!(lo[0] <= 2.0 && 2.0 <= hi[0]);
/// ```
#[inline]
pub fn contact_brackets_from_origin<const D: usize, const L: usize>(
    first: &BallLanes<D, L>,
    second: &BallLanes<D, L>,
    lo: &mut [f64; L],
    hi: &mut [f64; L],
) {
    brackets::<D, L, true>(first, second, lo, hi)
}

/// Which of `L` pairs, every first ball at the origin (as [`contact_brackets_from_origin`]
/// takes them), certainly do not touch before `horizon[k]`: `true` in lane `k` means that
/// [`contact_time_unchecked`] gives `Never`, or `At(t)` with the exact time of the inputs
/// later than `horizon[k]` (so `t ≥ horizon[k]` after rounding) — for a `horizon[k] ≥ 0`. A
/// cheaper verdict than a bracket, for the lanes an engine has no use for: those receding and
/// those whose contact falls after an event it already holds. `false` claims nothing.
///
/// Branch-free, like the brackets: `true` when the inputs are in the filter's range (as
/// [`contact_brackets`] checks it) and either
///
/// - the pair certainly recedes, `b̃ > β` (the brackets' own test: they give `[+∞, +∞]`), or
/// - `(c̃ − γ)(1 − 8u) > 2H·(β − b̃) + 2⁻¹⁰²²`, [`contact_time_within`]'s test: with `b̃` and
///   `c̃` within `β` and `γ` of the exact `b` and `c`, it makes `c > 2H·max(−b, 0)`, so the
///   gap `F(t) = c + 2bt + |Δv|²t² ≥ c + 2bt` stays open on `[0, H]` — the pair recedes,
///   misses, or meets at a smaller root `c/(−b + √D) ≥ c/(−2b) > H`.
///
/// The second test is the tangent at the start, which pairs far from contact undershoot
/// (below, lane 0 at `H = 1.5`); NaN and infinite inputs fail the range check, and an
/// overflowing right side (a NaN or +∞) fails the comparison.
///
/// ```
/// use quadratic::{contact_clear_until_from_origin, BallLanes, Ball};
/// let mut first = BallLanes::<3, 4>::default();
/// let mut second = BallLanes::<3, 4>::default();
/// for k in 0..4 {
///     first.set(k, &Ball { position: [0.0; 3], velocity: [1.0, 0.0, 0.0], radius: 0.5 });
/// }
/// let at = |x: f64, v: f64| Ball { position: [x, 0.0, 0.0], velocity: [v, 0.0, 0.0], radius: 0.5 };
/// second.set(0, &at(5.0, -1.0)); // meets at t = 2
/// second.set(1, &at(5.0, -1.0)); // meets at t = 2
/// second.set(2, &at(5.0, 2.0)); // recedes
/// second.set(3, &at(0.5, -1.0)); // overlaps, approaching: now
/// let clear = contact_clear_until_from_origin(&first, &second, &[1.0, 2.5, 1e9, 1.0]);
/// assert_eq!(clear, [true, false, true, false]);
/// let clear = contact_clear_until_from_origin(&first, &second, &[1.5, 2.0, 1e9, 0.0]);
/// assert_eq!(clear, [false, false, true, false]); // 1.5: the tangent meets at 1.2
/// ```
#[inline(always)]
pub fn contact_clear_until_from_origin<const D: usize, const L: usize>(
    first: &BallLanes<D, L>,
    second: &BallLanes<D, L>,
    horizon: &[f64; L],
) -> [bool; L] {
    // A loop over the lanes (as in the brackets), not `array::from_fn`, whose closure the
    // compiler keeps out of line and scalar.
    let mut clear = [false; L];
    for k in 0..L {
        let (r1, r2) = (first.radius[k], second.radius[k]);
        let h: [f64; D] = core::array::from_fn(|i| second.position[i][k]);
        let g: [f64; D] = core::array::from_fn(|i| second.velocity[i][k] - first.velocity[i][k]);
        let (b, _, bound_b) = filter_b(&h, &g);
        let (c, _, bound_c) = filter_c(&h, r1 + r2);
        // The brackets' range check; its NaN screen is here the comparisons': a NaN in `h`
        // makes `c̃` NaN, one in `g` makes `b̃` NaN, and both tests then fail.
        let ok = magnitudes_in_range(r1, r2, &h, &g);
        let big_h = horizon[k];
        let open_until = (c - bound_c) * (1.0 - 8.0 * U) > big_h * (2.0 * (bound_b - b)) + f64::MIN_POSITIVE;
        clear[k] = ok & (big_h >= 0.0) & ((b > bound_b) | open_until);
    }
    clear
}

/// [`contact_brackets`], or with `ORIGIN` [`contact_brackets_from_origin`].
#[inline(always)]
fn brackets<const D: usize, const L: usize, const ORIGIN: bool>(
    first: &BallLanes<D, L>,
    second: &BallLanes<D, L>,
    lo: &mut [f64; L],
    hi: &mut [f64; L],
) {
    const INF: f64 = f64::INFINITY;
    // The same expressions as `filtered` (see the bounds there), lane by lane; the brackets
    // of certified contacts are bit-identical to `contact_bracket`'s.
    for k in 0..L {
        let (r1, r2) = (first.radius[k], second.radius[k]);
        let s = r1 + r2;
        let h: [f64; D] = core::array::from_fn(|i| {
            if ORIGIN { second.position[i][k] } else { second.position[i][k] - first.position[i][k] }
        });
        let g: [f64; D] = core::array::from_fn(|i| second.velocity[i][k] - first.velocity[i][k]);
        let (b, _, bound_b) = filter_b(&h, &g);
        let (c, q, bound_c) = filter_c(&h, s);
        let (disc, scale, bound_d) = filter_disc(&h, &g, s);
        let ok = in_range(r1, r2, &h, &g, q, scale);
        let tight = if ORIGIN {
            tight_c_of(&h, |_| 0.0, r1, r2)
        } else {
            let p1: [f64; D] = core::array::from_fn(|i| first.position[i][k]);
            let p2: [f64; D] = core::array::from_fn(|i| second.position[i][k]);
            tight_c(&p1, &p2, r1, r2)
        };
        let (low, high) = bracket_ends((b, bound_b), tight, (disc, bound_d));
        // The verdicts in the filter's order; the first that applies wins.
        let approaching = b < -bound_b;
        let (l, h) = if !ok {
            (0.0, INF)
        } else if b > bound_b {
            (INF, INF)
        } else if !approaching {
            (0.0, INF)
        } else if c < -bound_c {
            (0.0, 0.0)
        } else if c <= bound_c {
            (0.0, INF)
        } else if disc < -bound_d {
            (INF, INF)
        } else if disc <= bound_d {
            (0.0, INF)
        } else {
            (low, high)
        };
        lo[k] = l;
        hi[k] = h;
    }
}

/// Pins a contact time to one ulp, from a guess: `Some(n)` when [`contact_time_unchecked`]
/// certainly returns `At(t)` with `t` one of the two neighbouring doubles `n.lo()` and
/// `n.hi()`; `None` when that cannot be certified this way (the caller then asks
/// [`contact_time_unchecked`]). [`Narrowed::time`] then tells which of the two, exactly.
/// Any finite `guess` is safe; one within some hundreds of ulps (the middle of a
/// [`contact_bracket`], say) almost always succeeds.
///
/// What it is for: an event-driven simulation needs the *absolute* time `t₀ + t` of an event
/// to the bit. A [`contact_bracket`] is some tens of ulps of `t` wide; when its ends, added to
/// `t₀`, round to two different times, the double-double root used to be the only way to tell
/// which. One ulp usually settles it, and when it does not, [`Narrowed::time`] does. The
/// price: one compensated evaluation of the gap function and a division (and one more
/// evaluation for `time`), with no branch on the data.
///
/// (Pinning is for the candidates whose brackets do leave two times; done for every lane of
/// the engine's batch of neighbours instead, in vector registers, it costs more than it saves.)
///
/// How. With `F(x) = |Δr + Δv·x|² − σ²` (the exact differences of the inputs, as TwoSum
/// pairs), one Newton step from the guess gives `c = guess − F(guess)/F′(guess)`, within about
/// an ulp of the root when the guess is within a few hundred. The certified signs of `F` at
/// `c` and at its two neighbouring doubles — each from the evaluation at the guess, shifted
/// (below) — say on which side of `c` the root lies, and close the
/// interval: `x₁ < x₂` (adjacent doubles) with `F(x₁) > 0` and `F(x₂) < 0` certified. This
/// means that `F` has two real roots `r₁ < x₂ < r₂` (it is negative only
/// between them) and that `x₁ < r₁` (`F(x₁) > 0` and `x₁ < x₂ < r₂`). With `x₁ > 0` it is the
/// case `b < 0, c > 0, D > 0` of the semantics table (`F(0) = c > 0` by convexity, both roots
/// positive so `b < 0`, two distinct roots so `D > 0`): the answer is `At(t)` with `t` the
/// smaller root `r₁`, rounded. Both ways the kernel computes it (the double-double root and
/// the expansions) round to nearest a value within 2⁻⁷⁰ of `r₁` relatively (the module's
/// contract, one ulp, tightened to what both paths do), far less than half the gap below `x₁`
/// or above `x₂` (2⁻⁵⁴ of them at least, `x₁` being normal): `t` is `x₁` or `x₂`.
///
/// The evaluation, at `x = x_h + x_l` (`|x_l| ≤ u|x_h|`; the midpoint of [`Narrowed::time`]
/// has a tail): `gᵢx_h = p + e` (TwoProd), `hᵢ + p = w + f` (TwoSum), so the exact
/// `Δrᵢ + Δvᵢx = w + τᵢ` with `τᵢ = f + e + gᵢx_l + lᵢ + mᵢx`, `|τᵢ| ≤ 5.02u·Mᵢ`,
/// `Mᵢ = |hᵢ| + |p|` (`l`, `m` the tails of `Δr`, `Δv`; `mᵢx_l`, below 1.01u²Mᵢ, is dropped).
/// Then `F = Σw² − s² + [Σ2wτᵢ − 2st] + Στᵢ² − t²`, the first part as exact TwoProd heads
/// summed by a TwoSum chain (as in the compensated `c` of [`contact_bracket`]) with every tail
/// collected in f64. With `Q = ΣMᵢ² + s²`: the tails add up to at most `(D + 11.1)·u·Q` over
/// `3D + 1` roundings, an error below `(3D + 1)(D + 11.1)·1.01·u²Q` (143u²Q for `D = 3`);
/// `τ̃ᵢ` errs by 15.1u²Mᵢ (31u²Q through `2wτ`); the dropped `Στᵢ² + t²` is below 26u²Q; the
/// final sum errs by `u|F̃|`. So `|F̃ − F| ≤ u|F̃| + 200u²Q`, and a sign is taken as certified
/// beyond `2u|F̃| + 256u²Q̃ + 10⁻³⁰⁰` (`Q̃` the f64 value, within `(D + 3)u` of `Q`; the last
/// term covers underflow, as in the filter). Overflow gives ∞ or NaN, which certify nothing.
///
/// The shift, from `y` (the guess) to `x = y + δ`: exactly `F(x) = F(y) + 2δ⟨w(y)|Δv⟩ +
/// δ²|Δv|²`, computed as `F̃(y) ⊕ t₁ ⊕ t₂` with `t₁ = 2δ ⊗ S̃`, `t₂ = δ ⊗ δ ⊗ ã` (`S̃` the f64
/// `Σwᵢgᵢ`, `ã` the f64 `Σgᵢ²`). `δ = x − y` is exact (Sterbenz: both positive, within a
/// factor of two; otherwise nothing is certified). `S̃` is off from `⟨w(y)|Δv⟩` by at most
/// `D·u·Σ|wᵢgᵢ|` (the FMA chain) plus the dropped `Σ|wᵢmᵢ| + |τᵢ||Δvᵢ|`, in all
/// `(D + 5.1)·u·R` with `R = ΣMᵢ|gᵢ|`: at most `16.4u|δ|R` through `t₁` (`D ≤ 3`). `t₁` rounds
/// by `1.01u|t₁|`, `t₂` errs by `(D + 5.1)u|t₂|` (two roundings and `ã`'s own), the two sums
/// by `1.01u(|F̃(y)| + |t₁|)` and `u|F̃(x)|`. With `F̃(y)`'s error above, the bound
/// `3u(|F̃(y)| + |t₁|) + 9u|t₂| + 2u|F̃(x)| + 256u²Q̃ + 20u|δ|R̃ + 10⁻³⁰⁰` covers them all (`R̃`,
/// the f64 value, within `(D + 1)u` of `R`). Three shifts cost a few operations each where
/// three evaluations cost some fifty.
///
/// ```
/// use quadratic::{narrow_contact, contact_time, Ball, Contact};
/// let a = Ball { position: [0.0, 0.0], velocity: [1.0, 0.0], radius: 0.5 };
/// let b = Ball { position: [5.0, 0.1], velocity: [-1.0, 0.0], radius: 0.5 };
/// let Contact::At(t) = contact_time(&a, &b).unwrap() else { panic!() };
/// let n = narrow_contact(&a, &b, t * (1.0 + 1e-13)).unwrap();
/// assert!(n.lo() <= t && t <= n.hi() && n.hi() == n.lo().next_up());
/// assert_eq!(n.time(), Some(t));
/// assert!(narrow_contact(&a, &Ball { position: [5.0, 3.0], ..b }, 2.0).is_none()); // a miss
/// ```
#[inline]
pub fn narrow_contact<const D: usize>(first: &Ball<D>, second: &Ball<D>, guess: f64) -> Option<Narrowed<D>> {
    let (dr, dv, sigma) = differences(first, second, 0, 0);
    let (pinned, lo) = narrow(&dr, &dv, sigma, guess);
    pinned.then_some(Narrowed { lo, dr, dv, sigma })
}

/// The neighbouring doubles of a positive normal `x` (not the largest): one step of its bit
/// pattern (`f64::next_up` checks for NaN, ∞ and 0 first).
#[inline(always)]
fn next_up_normal(x: f64) -> f64 {
    f64::from_bits(x.to_bits() + 1)
}

/// See [`next_up_normal`].
#[inline(always)]
fn next_down_normal(x: f64) -> f64 {
    f64::from_bits(x.to_bits() - 1)
}

/// The heart of [`narrow_contact`], without branches: whether the contact is pinned, and
/// `x₁` (meaningless when it is not).
#[inline(always)]
fn narrow<const D: usize>(dr: &[Pair; D], dv: &[Pair; D], sigma: Pair, guess: f64) -> (bool, f64) {
    // Normal, and far from overflow: the gaps around x₁ and x₂ are relative, and the kernel's
    // answer is neither clamped to the smallest subnormal nor +∞.
    const LOWEST: f64 = pow2(-900);
    const HIGHEST: f64 = pow2(1000);
    let at_guess = gap_at(dr, dv, sigma, (guess, 0.0));
    let centre = guess - at_guess.value / (2.0 * at_guess.slope);
    let in_range = (LOWEST..HIGHEST).contains(&centre);
    // All three signs at once, from the one evaluation, then a select: which side of the
    // centre the root lies on is a coin toss for a branch predictor. (Out of range, the
    // neighbours are garbage, and ignored.)
    let (below, above) = (next_down_normal(centre), next_up_normal(centre));
    let (at_below, at_centre, at_above) =
        (at_guess.shifted(guess, below), at_guess.shifted(guess, centre), at_guess.shifted(guess, above));
    let up = at_centre.positive(0.0) & at_above.negative(0.0);
    let down = at_below.positive(0.0) & at_centre.negative(0.0);
    (in_range & (up | down), if up { centre } else { below })
}

/// A contact time pinned to one ulp by [`narrow_contact`].
#[derive(Clone, Copy, Debug)]
pub struct Narrowed<const D: usize> {
    lo: f64,
    dr: [Pair; D],
    dv: [Pair; D],
    sigma: Pair,
}

impl<const D: usize> Narrowed<D> {
    /// The lower of the two doubles the contact time is one of.
    pub fn lo(&self) -> f64 {
        self.lo
    }

    /// The upper one, `lo().next_up()`.
    pub fn hi(&self) -> f64 {
        next_up_normal(self.lo)
    }

    /// The contact time [`contact_time_unchecked`] returns, to the bit — or `None` when the
    /// exact root lies too close to the midpoint `m` of `lo()` and `hi()` to tell which way
    /// the kernel rounds (a relative distance of about 2⁻⁶⁰, for ordinary pairs).
    ///
    /// The kernel's time is `hi()` when the value it rounds lies above `m`, `lo()` when below.
    /// That value is within `ε = 2⁻⁷⁰·hi()` of the root `r₁`, so the sign of `F(m)` must be
    /// certified with a margin: if `r₁ ≤ m + ε`, then `F(m) ≤ 0` (`m` past the root) or `F(m)`
    /// is at most `|F′(lo)|·ε` (between `m` and `r₁` the slope is negative, and steepest at
    /// `lo`, `F` being convex), and `|F′(lo)|·ε ≤ 2Σ|wᵢ||Δvᵢ|·ε ≤ 2.001·2⁻⁷⁰·ΣMᵢ|pᵢ|` (`pᵢ`
    /// being `gᵢ·lo` rounded, as the midpoint is `lo` plus a tail). So `F̃(m)` beyond the
    /// bound plus `2⁻⁶⁴·ΣMᵢ|pᵢ|` (as computed, with room for its rounding) means the kernel's
    /// value is above `m`, and symmetrically below. This fails about once in 2¹⁰ near-midpoint
    /// cases for ordinary pairs, where `ΣMᵢ|pᵢ|` is about `|F′|·lo/2`.
    pub fn time(&self) -> Option<f64> {
        // The midpoint lo + ulp/2, exactly, as a double-double.
        let (lo, hi) = (self.lo, self.hi());
        let half = 0.5 * (hi - lo);
        let at_midpoint = gap_at(&self.dr, &self.dv, self.sigma, (lo, half));
        let margin = pow2(-64) * at_midpoint.reach;
        if at_midpoint.positive(margin) {
            Some(hi)
        } else if at_midpoint.negative(margin) {
            Some(lo)
        } else {
            None
        }
    }
}

/// `F(x) = |Δr + Δv·x|² − σ²`, compensated (see [`narrow_contact`]).
struct Gap {
    /// `F̃`.
    value: f64,
    /// `Q̃ = ΣMᵢ² + s²`, the scale of its error.
    scale: f64,
    /// `S̃ = ⟨w|g⟩ ≈ F′(x)/2`.
    slope: f64,
    /// `Σ Mᵢ|p|`, which bounds `|F′(x)|·x/2` (see [`Narrowed::time`]).
    reach: f64,
    /// `R̃ = Σ Mᵢ|gᵢ|`, the scale of the slope's error.
    span: f64,
    /// `ã = Σgᵢ²`.
    square: f64,
    /// What [`shifted`](Gap::shifted) adds to the error bound (0 for an evaluation).
    extra: f64,
}

impl Gap {
    /// `F` at `x = y + δ`, from its evaluation at `y` (see [`narrow_contact`] for the bound).
    #[inline(always)]
    fn shifted(&self, y: f64, x: f64) -> Gap {
        let exact = y > 0.0 && x > 0.0 && x <= 2.0 * y && y <= 2.0 * x;
        let delta = if exact { x - y } else { f64::NAN };
        let t1 = 2.0 * delta * self.slope;
        let t2 = delta * delta * self.square;
        let value = (self.value + t1) + t2;
        let extra = 3.0 * U * (self.value.abs() + t1.abs()) + 9.0 * U * t2.abs() + 20.0 * U * delta.abs() * self.span;
        Gap { value, extra, ..*self }
    }

    /// Whether `F > margin` certainly (`margin ≥ 0`).
    #[inline(always)]
    fn positive(&self, margin: f64) -> bool {
        self.value > self.bound() + margin
    }

    /// Whether `F < −margin` certainly.
    #[inline(always)]
    fn negative(&self, margin: f64) -> bool {
        self.value < -(self.bound() + margin)
    }

    /// The error bound `2u|F̃| + 256u²Q̃ + 10⁻³⁰⁰` (NaN or ∞ after overflow, which certify
    /// nothing).
    #[inline(always)]
    fn bound(&self) -> f64 {
        2.0 * U * self.value.abs() + 256.0 * U * U * self.scale + self.extra + SLACK
    }
}

/// [`Gap`] at `x = x_h + x_l`.
#[inline(always)]
fn gap_at<const D: usize>(dr: &[Pair; D], dv: &[Pair; D], (s, t): Pair, (xh, xl): Pair) -> Gap {
    let (ps, es) = two_prod(s, s);
    let mut acc = -ps;
    let mut tail = -(2.0 * s).mul_add(t, es);
    let mut q = s * s;
    let mut slope = 0.0;
    let mut reach = 0.0;
    let (mut span, mut square) = (0.0, 0.0);
    for i in 0..D {
        let ((h, l), (g, m)) = (dr[i], dv[i]);
        let (p, e) = two_prod(g, xh);
        let (w, f) = two_sum(h, p);
        let tau = (m.mul_add(xh, l) + (f + e)) + g * xl;
        let (pw, ew) = two_prod(w, w);
        let (sum, f2) = two_sum(acc, pw);
        acc = sum;
        tail += f2 + ew;
        tail = (2.0 * w).mul_add(tau, tail);
        let magnitude = h.abs() + p.abs();
        q = magnitude.mul_add(magnitude, q);
        reach = magnitude.mul_add(p.abs(), reach);
        span = magnitude.mul_add(g.abs(), span);
        square = g.mul_add(g, square);
        slope = w.mul_add(g, slope);
    }
    Gap { value: acc + tail, scale: q, slope, reach, span, square, extra: 0.0 }
}

/// What the filter concluded.
enum Verdict {
    /// The certified answer.
    Decided(Contact),
    /// Certainly no contact at or before the horizon.
    Beyond,
    /// The exact path must decide (or the input is invalid).
    Undecided,
    /// A contact whose time lies in `[lo, hi]` (only when asked for a bracket).
    Between(f64, f64),
}

/// The exact (expansion) path alone, bypassing the filter: for the tests that prove both
/// paths against the oracle, and for the benchmarks. Inputs as for [`contact_time_unchecked`].
#[doc(hidden)]
pub fn contact_time_exact_path<const D: usize>(first: &Ball<D>, second: &Ball<D>) -> Contact {
    exact_full(first, second)
}

/// The exact path from the inputs: exact differences (TwoSum), scaled, then expansions.
fn exact_full<const D: usize>(first: &Ball<D>, second: &Ball<D>) -> Contact {
    // TwoSum is exact unless something near the top of the range overflows; then the
    // differences are redone with lengths and/or velocities scaled by 2⁻⁴ (which can only
    // drop subnormal bits of inputs 2²⁰⁰⁰ times smaller than the largest — see the contract).
    let (dr, dv, sigma) = differences(first, second, 0, 0);
    let (lpre, vpre) = prescale(&dr, &dv, sigma, None);
    let (dr, dv, sigma) = if lpre == 0 && vpre == 0 { (dr, dv, sigma) } else { differences(first, second, lpre, vpre) };
    contact_of_differences(&dr, &dv, sigma, vpre - lpre)
}

/// The powers of two (0 or −4) by which lengths and velocities must be scaled before the
/// exact path, so that nothing near the top of the range overflows: −4 where the largest
/// head (of `Δr` and `σ`; of `Δv` and the growth head `grow`, if any) is not below 2¹⁰²⁰
/// (or is not a number).
pub(crate) fn prescale<const D: usize>(dr: &[Pair; D], dv: &[Pair; D], sigma: Pair, grow: Option<f64>) -> (i32, i32) {
    let safe = |m: f64| m < pow2(1020);
    let vm = max_velocity(dv);
    let vm = match grow {
        Some(g) if g.is_nan() || g > vm => g,
        _ => vm,
    };
    (if safe(max_length(dr, sigma)) { 0 } else { -4 }, if safe(vm) { 0 } else { -4 })
}

/// The exponents `(el, ev)` that scale the exact differences' lengths and velocities (the
/// growth head `grow` among them, if any) to magnitude [1, 2) — or the answer, when nothing
/// moves (`Δv = 0` and no growth: no relative motion) or nothing has extent (`Δr = 0` and
/// `σ = 0`: tangential).
pub(crate) fn scale_exponents<const D: usize>(
    dr: &[Pair; D],
    dv: &[Pair; D],
    sigma: Pair,
    grow: Option<f64>,
) -> Result<(i32, i32), Contact> {
    // A TwoSum head is 0 exactly when the sum is.
    let vmax = match grow {
        Some(g) => max_velocity(dv).max(g.abs()),
        None => max_velocity(dv),
    };
    if vmax == 0.0 {
        return Err(Contact::Never(Miss::NoRelativeMotion));
    }
    let lmax = max_length(dr, sigma);
    if lmax == 0.0 {
        // Δr = 0 and σ = 0: b = 0 (and C = 0), tangential.
        return Err(Contact::Never(Miss::Receding));
    }
    Ok((exponent(lmax), exponent(vmax)))
}

/// `(hi, lo)` scaled by `2^k`.
#[inline(always)]
pub(crate) fn scale_pair(p: Pair, k: i32) -> Pair {
    (scale2(p.0, k), scale2(p.1, k))
}

/// `Δr`, `Δv`, `σ` as exact TwoSum pairs, lengths scaled by `2^lpre`, velocities by `2^vpre`.
#[inline(always)]
pub(crate) fn differences<const D: usize>(
    first: &Ball<D>,
    second: &Ball<D>,
    lpre: i32,
    vpre: i32,
) -> ([Pair; D], [Pair; D], Pair) {
    let len = |x: f64| if lpre == 0 { x } else { scale2(x, lpre) };
    let vel = |x: f64| if vpre == 0 { x } else { scale2(x, vpre) };
    let mut dr = [(0.0, 0.0); D];
    let mut dv = [(0.0, 0.0); D];
    for i in 0..D {
        dr[i] = two_sum(len(second.position[i]), -len(first.position[i]));
        dv[i] = two_sum(vel(second.velocity[i]), -vel(first.velocity[i]));
    }
    (dr, dv, two_sum(len(first.radius), len(second.radius)))
}

/// The largest |head| of Δr and σ; NaN or ∞ (which compare as "not < 2¹⁰²⁰") after overflow.
#[inline(always)]
pub(crate) fn max_length<const D: usize>(dr: &[Pair; D], sigma: Pair) -> f64 {
    let mut m = sigma.0 + sigma.1 * 0.0;
    for p in dr {
        let a = p.0.abs() + p.1 * 0.0;
        m = if a > m || a.is_nan() { a } else { m };
    }
    m
}

/// The largest |head| of Δv (NaN or ∞ after overflow).
#[inline(always)]
pub(crate) fn max_velocity<const D: usize>(dv: &[Pair; D]) -> f64 {
    let mut m = 0.0;
    for p in dv {
        let a = p.0.abs() + p.1 * 0.0;
        m = if a > m || a.is_nan() { a } else { m };
    }
    m
}

/// The contact given exact differences `Δr`, `Δv`, `σ` as (hi, lo) pairs, by the exact
/// path; the resulting time is multiplied by `2^time_exp`.
fn contact_of_differences<const D: usize>(dr: &[Pair; D], dv: &[Pair; D], sigma: Pair, time_exp: i32) -> Contact {
    // Scale lengths and velocities separately to magnitude [1, 2): exact (but for the
    // underflow caveat in the contract), and the time scales by 2^(el − ev).
    let (el, ev) = match scale_exponents(dr, dv, sigma, None) {
        Ok(exponents) => exponents,
        Err(answer) => return answer,
    };
    let dr = dr.map(|p| scale_pair(p, -el));
    let dv = dv.map(|p| scale_pair(p, -ev));
    exact(&dr, &dv, scale_pair(sigma, -el), time_exp + el - ev)
}

// ---------------------------------------------------------------------------------------
// The filter: f64 signs, then double-double values, each with a rigorous error bound.
// ---------------------------------------------------------------------------------------

/// Unit roundoff u = 2⁻⁵³.
pub(crate) const U: f64 = f64::EPSILON / 2.0;
/// Absolute slack covering underflow in the filter: every f64 operation on inputs in
/// `2^±150` errs by at most 2⁻¹⁰⁷⁵ absolutely through underflow; a few hundred such
/// operations stay far below 2⁻¹⁰⁰⁰.
pub(crate) const SLACK: f64 = 1e-300;
/// A double-double value is used for the root only when its certified relative error is
/// below 2⁻⁸⁰ — then the root is correctly rounded unless within ~2⁻²⁵ ulp of a midpoint.
/// Its bound is ~2⁻⁹⁸ of the scale below, so values above 2⁻¹⁸ of the scale qualify.
pub(crate) const DD_ACCEPT: f64 = 1.0 / (1u64 << 18) as f64;

/// The certified answer, [`Verdict::Beyond`] when the contact is certainly later than
/// `horizon` (pass `+∞` for none), or [`Verdict::Undecided`] when the exact path must decide
/// (or the input is invalid: a NaN, an infinity or a negative radius fails the range screen
/// and goes to the cold path).
///
/// Notation: `Δrᵢ = hᵢ + lᵢ`, `Δvᵢ = gᵢ + mᵢ`, `σ = s + t`, where the heads are the rounded
/// differences (sum) and the tails their rounding errors, `|lᵢ| ≤ u|hᵢ|` (and alike),
/// u = 2⁻⁵³. The sign tests use the heads alone, with bounds that allow for the tails; the
/// tails are computed (TwoSum) only when a contact time must be evaluated. All of `|hᵢ|`,
/// `s`, `|gᵢ|` must lie in `2^±150` (largest of each kind at least 2⁻¹⁵⁰), which keeps
/// every product in range.
#[inline(always)]
fn filtered<const D: usize, const BRACKET: bool>(first: &Ball<D>, second: &Ball<D>, horizon: f64) -> Verdict {
    const HI: f64 = pow2(150);
    const LO: f64 = pow2(-150);
    let mut h = [0.0; D];
    let mut g = [0.0; D];
    let s = first.radius + second.radius;
    // Comparisons with NaN are false, so one flag screens NaN, ±∞ and negative radii too.
    let mut ok = first.radius >= 0.0 && second.radius >= 0.0 && s <= HI;
    let (mut lmax, mut vmax) = (s, 0.0f64);
    for i in 0..D {
        h[i] = second.position[i] - first.position[i];
        g[i] = second.velocity[i] - first.velocity[i];
        let (ah, ag) = (h[i].abs(), g[i].abs());
        ok &= ah <= HI && ag <= HI;
        lmax = lmax.max(ah);
        vmax = vmax.max(ag);
    }
    if !(ok && lmax >= LO && vmax >= LO) {
        return Verdict::Undecided;
    }
    // --- b = ⟨Δv|Δr⟩ in f64. With P = Σ|hᵢgᵢ|: the FMA chain errs by ≤ D·u·P(1+Du) and
    // the dropped terms hᵢmᵢ + lᵢgᵢ + lᵢmᵢ by ≤ (2u + u²)P; (D + 4)·u·P covers both.
    let (b, p, bound_b) = filter_b(&h, &g);
    if b > bound_b {
        return Verdict::Decided(Contact::Never(Miss::Receding));
    }
    if b >= -bound_b {
        return Verdict::Undecided;
    }
    // --- c = |Δr|² − σ². With Q = Σhᵢ² + s²: chain error ≤ (D + 1)·u·Q, dropped
    // 2hᵢlᵢ + lᵢ² − 2st − t² ≤ (2u + u²)·Q.
    let (c, q, bound_c) = filter_c(&h, s);
    if c < -bound_c {
        return Verdict::Decided(Contact::Now);
    }
    if c <= bound_c {
        return Verdict::Undecided;
    }
    // --- Horizon: t ≥ c/(−2b) (see `contact_time_within`). Each side of the comparison is
    // off by at most 2u relatively after rounding (8u covers both), and the right side by
    // at most 2⁻¹⁰⁷⁴ absolutely through underflow, which the added 2⁻¹⁰²² covers. With
    // horizon = +∞ the right side is +∞ and nothing is rejected; a NaN rejects nothing.
    if (c - bound_c) * (1.0 - 8.0 * U) > horizon * (2.0 * (bound_b - b)) + f64::MIN_POSITIVE {
        return Verdict::Beyond;
    }
    // --- D = |Δv|²σ² − Σ_{i<j}(ΔrᵢΔvⱼ − ΔrⱼΔvᵢ)². With Xᵢⱼ = |hᵢgⱼ| + |hⱼgᵢ| and
    // A = a·s² + ΣXᵢⱼ²: each factor errs by a few u relative to its own scale (a by
    // (D + 3)u, s² by 3u, each cross term by 4u·Xᵢⱼ), so 32·u·A bounds the total for D ≤ 3.
    let (disc, scale, bound_d) = filter_disc(&h, &g, s);
    if disc < -bound_d {
        return Verdict::Decided(Contact::Never(Miss::PathsMiss));
    }
    if disc <= bound_d {
        return Verdict::Undecided;
    }
    if BRACKET {
        // t = c/(−b + √D) with c ∈ [c̃ ∓ γ], −b ∈ [−b̃ ∓ β] (both > 0) and D ∈ [D̃ ∓ δ] (> 0):
        // smallest numerator over largest denominator and vice versa, widened for the
        // roundings and the returned time's ulp (`bracket_ends`). The signs above used
        // the cheap `c̃`; the bracket takes the compensated one (`tight_c`), whose bound is
        // about 2u·c instead of 7u·(|Δr|² + σ²).
        let tight = tight_c(&first.position, &second.position, first.radius, second.radius);
        let (lo, hi) = bracket_ends((b, bound_b), tight, (disc, bound_d));
        return if lo > horizon { Verdict::Beyond } else { Verdict::Between(lo, hi) };
    }
    // --- All three signs certified: b < 0, c > 0, D > 0. Now the values, in double-double.
    // Each is an exact sum of TwoProd heads plus small terms accumulated in f64; its error is
    // below 2⁻⁹⁸ of the scale (P, Q or A: a dozen terms each ≤ 2u·scale, summed with error
    // ≤ u each, plus the TwoProd tails' own rounding), so accepting values ≥ 2⁻¹⁸·scale
    // bounds the relative error by 2⁻⁸⁰.
    if -b < DD_ACCEPT * p || c < DD_ACCEPT * q || disc < DD_ACCEPT * scale {
        return Verdict::Undecided;
    }
    // The tails, now that they are needed: TwoSum heads equal the rounded differences above.
    let (dr, dv, sigma) = differences(first, second, 0, 0);
    let (dr, dv) = (&dr, &dv);
    let st = sigma.1;
    let neg_b = {
        let mut acc = Acc::default();
        for i in 0..D {
            let ((h, l), (g, m)) = (dr[i], dv[i]);
            acc.prod(-h, g);
            acc.small(-(h.mul_add(m, l * g) + l * m));
        }
        acc.dd()
    };
    let c_dd = gap_dd(dr, sigma);
    let d_dd = {
        let mut a_acc = Acc::default();
        for &(g, m) in dv {
            a_acc.prod(g, g);
            a_acc.small((2.0 * g).mul_add(m, m * m));
        }
        let mut s_acc = Acc::default();
        s_acc.prod(s, s);
        s_acc.small((2.0 * s).mul_add(st, st * st));
        let asig = a_acc.dd().mul(s_acc.dd());
        let mut acc = Acc::default();
        acc.prod(asig.hi, 1.0);
        acc.small(asig.lo);
        acc.minus_cross_squares(dr, dv);
        acc.dd()
    };
    let den = neg_b.add(d_dd.sqrt());
    let t = c_dd.div(den);
    Verdict::Decided(Contact::At(t.hi + t.lo))
}

/// The filter's range check, as the batch takes it: radii `≥ 0`, and every `|hᵢ|`, `|gᵢ|` and
/// `s = r₁ + r₂` at most 2¹⁵⁰, with `max(s, |hᵢ|) ≥ 2⁻¹⁵⁰` and `max |gᵢ| ≥ 2⁻¹⁵⁰` (as in
/// [`filtered`]) — written as two maxima compared once each, without NaN handling in the
/// maxima: a NaN among the `hᵢ` (or `s`) makes `q = |h|² + s²` NaN, and one among the `gᵢ`
/// makes `scale = |g|²s² + …` NaN, so the last two tests reject it (`q` and `scale` as
/// [`filter_c`] and [`filter_disc`] return them). Fewer vector operations a lane than a
/// test per axis; the same verdict for every input (tested against that form).
#[inline(always)]
fn in_range<const D: usize>(r1: f64, r2: f64, h: &[f64; D], g: &[f64; D], q: f64, scale: f64) -> bool {
    #[allow(clippy::eq_op)]
    let numbers = q == q && scale == scale;
    magnitudes_in_range(r1, r2, h, g) && numbers
}

/// [`in_range`] but its NaN screen: radii `≥ 0`, and the two maxima (`max(s, |hᵢ|)` and
/// `max |gᵢ|`) within `2^±150`. A NaN among the `hᵢ` or `gᵢ` passes here; each caller
/// rejects it through a value it computes anyway.
#[inline(always)]
fn magnitudes_in_range<const D: usize>(r1: f64, r2: f64, h: &[f64; D], g: &[f64; D]) -> bool {
    const HI: f64 = pow2(150);
    const LO: f64 = pow2(-150);
    let (mut lmax, mut vmax) = (r1 + r2, 0.0f64);
    for i in 0..D {
        let (ah, ag) = (h[i].abs(), g[i].abs());
        lmax = if ah > lmax { ah } else { lmax };
        vmax = if ag > vmax { ag } else { vmax };
    }
    r1 >= 0.0 && r2 >= 0.0 && (LO..=HI).contains(&lmax) && (LO..=HI).contains(&vmax)
}

/// `b̃ = ⟨g|h⟩` (FMA chain), `P = Σ|hᵢgᵢ|` and the bound `β` on `|b − b̃|` (see [`filtered`]).
#[inline(always)]
fn filter_b<const D: usize>(h: &[f64; D], g: &[f64; D]) -> (f64, f64, f64) {
    let (mut b, mut p) = (0.0, 0.0);
    for i in 0..D {
        b = h[i].mul_add(g[i], b);
        p += (h[i] * g[i]).abs();
    }
    (b, p, (D as f64 + 4.0) * U * p + SLACK)
}

/// `c̃ = |h|² − s²`, `Q = |h|² + s²` and the bound `γ` on `|c − c̃|` (see [`filtered`]).
#[inline(always)]
pub(crate) fn filter_c<const D: usize>(h: &[f64; D], s: f64) -> (f64, f64, f64) {
    let (mut c, mut q) = (-(s * s), s * s);
    for &x in h {
        c = x.mul_add(x, c);
        q = x.mul_add(x, q);
    }
    (c, q, (D as f64 + 5.0) * U * q + SLACK)
}

/// `c = |Δr|² − σ²` to about one ulp of itself, and a bound on its error, for the brackets:
/// [`filter_c`]'s value is off by up to ~7u·Q (`Q = Σhᵢ² + s²`), which near contact (`c ≪ Q`,
/// the usual case for neighbours in a dense fluid) made that error dominate the bracket width
/// — a few hundred ulps of the time, too wide for most brackets to pin the absolute event time
/// of a simulation (measured: 24 % of an engine's candidates; 59 % with this `c`).
///
/// Exactly: `Δrᵢ = hᵢ + lᵢ` and `σ = s + t` (TwoSum), `hᵢ² = pᵢ + eᵢ` and `s² = p_s + e_s`
/// (TwoProd, FMA), and the heads are summed by a chain of TwoSums, `Σpᵢ − p_s = acc + Σfₖ`, so
///
/// `c = acc + [Σfₖ + Σwᵢ − w_s] + Σlᵢ² − t²`, with `wᵢ = 2hᵢlᵢ + eᵢ`, `w_s = 2st + e_s`.
///
/// Magnitudes (`Q′ = Σpᵢ + p_s`, within a factor 1 + u of `Q`): `|eᵢ| ≤ u·pᵢ` and
/// `|2hᵢlᵢ| ≤ 2u(1 + u)·pᵢ`, so `|wᵢ| ≤ 3.01u·pᵢ` (and `w_s` alike); the partial sums of the
/// chain stay below `1.01·Q′`, so `|fₖ| ≤ 1.01u·Q′`. The bracketed tail has `2D + 1` terms
/// with `Σ|terms| ≤ (3.01 + 1.01·D)·u·Q′`; each `w` is one FMA (error ≤ u|w|) and the tail is
/// summed left to right (error ≤ 2D·u·Σ|terms|·1.01), so its error is below `41u²Q′` for
/// `D ≤ 3`, and the dropped `Σlᵢ² + t² ≤ u²(1 + u)Q′`. The final `c̃ = acc ⊕ τ̃` errs by at
/// most `u|c̃|`. So `|c̃ − c| ≤ u|c̃| + 42u²Q′`; the returned bound `2u|c̃| + 128u²Q̃ + SLACK`
/// covers that with room (`Q̃`, the f64 sum, is within 4u of `Q`), and SLACK covers
/// underflow, as in [`filtered`]. Inputs are in the filter's range `2^±150`, so nothing
/// overflows and TwoSum and TwoProd are exact (up to that underflow).
#[inline(always)]
fn tight_c<const D: usize>(first: &[f64; D], second: &[f64; D], r1: f64, r2: f64) -> (f64, f64) {
    let diff: [(f64, f64); D] = core::array::from_fn(|i| two_sum(second[i], -first[i]));
    tight_c_of::<D>(&core::array::from_fn(|i| diff[i].0), |i| diff[i].1, r1, r2)
}

/// [`tight_c`] from the exact differences `Δrᵢ = h[i] + tail(i)` (TwoSum pairs). With the
/// first ball at the origin, `Δrᵢ` is the second position, `tail = 0` — what TwoSum gives
/// for `x − 0` with `x` finite, so the same numbers (infinite or NaN inputs fail the
/// filter's range check before the value is used).
#[inline(always)]
fn tight_c_of<const D: usize>(h: &[f64; D], tail_of: impl Fn(usize) -> f64, r1: f64, r2: f64) -> (f64, f64) {
    let (s, t) = two_sum(r1, r2);
    let (ps, es) = two_prod(s, s);
    let mut acc = -ps;
    let mut tail = -(2.0 * s).mul_add(t, es);
    let mut q = s * s;
    for i in 0..D {
        let (h, l) = (h[i], tail_of(i));
        let (p, e) = two_prod(h, h);
        let (sum, f) = two_sum(acc, p);
        acc = sum;
        tail += f;
        tail += (2.0 * h).mul_add(l, e);
        q = h.mul_add(h, q);
    }
    let c = acc + tail;
    (c, 2.0 * U * c.abs() + 128.0 * U * U * q + SLACK)
}

/// `D̃ = |g|²s² − Σ_{i<j}(hᵢgⱼ − hⱼgᵢ)²`, its scale `A` and the bound `δ` on `|D − D̃|` (see
/// [`filtered`]).
#[inline(always)]
fn filter_disc<const D: usize>(h: &[f64; D], g: &[f64; D], s: f64) -> (f64, f64, f64) {
    let mut a = 0.0;
    for &x in g {
        a = x.mul_add(x, a);
    }
    let asig = a * (s * s);
    let (mut disc, mut scale) = (asig, asig);
    for i in 0..D {
        for j in i + 1..D {
            let (hi, hj, gi, gj) = (h[i], h[j], g[i], g[j]);
            let cross = hi.mul_add(gj, -(hj * gi));
            let x = (hi * gj).abs() + (hj * gi).abs();
            disc = (-cross).mul_add(cross, disc);
            scale = x.mul_add(x, scale);
        }
    }
    (disc, scale, 32.0 * U * scale + SLACK)
}

/// The certified bracket of `t = c/(−b + √D)` from the three values and their bounds, when
/// `b < 0`, `c > 0`, `D > 0` are certified (see the bracket step of [`filtered`]): one square
/// root and one division.
///
/// With `c ∈ [c̃ ∓ γ]`, `−b ∈ [B ∓ β]` (`B = −b̃`) and `D ∈ [D̃ ∓ δ]` (`δ < D̃`), write
/// `r = √D̃`, `d = B + r`, `z = δ/r` and `y = δ/D̃ < 1`. Since `√(1 + y) ≤ 1 + y/2` and
/// `√(1 − y) ≥ 1 − y/2 − y²/2` on `[0, 1]` (the Taylor coefficients past the first are all
/// negative and sum to −½), the true denominator `−b + √D` lies in `[d − e₊, d + e₋]` with
/// `e₋ = β + z/2` and `e₊ = β + (z/2)(1 + y)`. With `x₋ = e₋/d` and `x₊ = e₊/d`,
/// `1/(d + e₋) ≥ (1 − x₋)/d` always and `1/(d − e₊) = (1 + x₊ + x₊²/(1 − x₊))/d ≤
/// (1 + x₊ + 2x₊²)/d` for `x₊ ≤ ½`, so
///
/// `(c̃ − γ)·(1 − x₋)/d ≤ t ≤ (c̃ + γ)·(1 + x₊(1 + 2x₊))/d`.
///
/// Both reciprocals come from one division: `p = d̃ ⊗ r̃`, `i = 1 ⊘ p`, then `1/d ≈ r̃ ⊗ i`
/// (within 5u: `r̃`, `d̃`, `p`, `i` and the product round once each, `d̃` a sum of positive
/// terms) and `1/r ≈ d̃ ⊗ i` (within 4u). The computed `w± = ẽ± ⊗ (1/d ⊗ K)`, `K = 1 + 64u`
/// (`below` and `above` in the code), are within 24u of `K·x±` relatively (`z̃` 5u, `ỹ` 10u,
/// the sums and products one each, `1/d` 5u), so above `x±·(1 + W)`; the factors `1 − W − w₋` and
/// `1 + W + w₊(1 + 2w₊)` (FMAs) stay below `(1 − x₋)(1 − W)` and above
/// `(1 + x₊ + 2x₊²)(1 + W)` but for their final rounding. Each end is then a numerator (one
/// rounding), `1/d` (5u), the factor (one) and two products: 9u in all, and the time the
/// kernel returns is within one ulp (at most 2u relatively) of `t`, so [`WIDEN`]` = W = 12u`
/// covers the 11u with room for the second-order terms; ∓MIN_POSITIVE covers underflow of the
/// ends (and of `w±`, whose absolute error is then far below the factors' rounding). When
/// `w₊ > 0.49` (`x₊` might exceed ½: a glancing pair whose `D̃` is barely certified) the
/// bracket is `[0, +∞]`, and the caller evaluates the time exactly. The reciprocals round
/// relatively: `p ≥ r̃² ≈ D̃ > δ ≥ 10⁻³⁰⁰` (the filter's floor) and, by the inputs' range
/// `2^±150`, `p < 2⁶¹⁰`, so `i`, `1/d` and `1/r` are normal numbers. (The tests
/// `bracket_ends_hold_the_one_ulp_band` and `bracket_ends_hold_the_box` check that 12u holds,
/// that a smaller widening does not, and that the bracket holds every root the bounds allow.)
#[inline(always)]
fn bracket_ends(b: (f64, f64), c: (f64, f64), disc: (f64, f64)) -> (f64, f64) {
    widened_ends(b, c, disc, WIDEN)
}

/// The relative widening of [`bracket_ends`].
const WIDEN: f64 = 12.0 * U;

/// [`bracket_ends`] with the widening `widen` (relative, on each side).
#[inline(always)]
fn widened_ends(
    (b, bound_b): (f64, f64),
    (c, bound_c): (f64, f64),
    (disc, bound_d): (f64, f64),
    widen: f64,
) -> (f64, f64) {
    const K: f64 = 1.0 + 64.0 * U;
    let r = disc.sqrt();
    let d = r - b;
    let p = d * r;
    let i = 1.0 / p;
    let (inv_d, inv_r) = (r * i, d * i);
    let z = bound_d * inv_r;
    let half_z = 0.5 * z;
    let e_minus = half_z + bound_b;
    let e_plus = half_z.mul_add(z * inv_r, e_minus);
    let inv_dk = inv_d * K;
    let (below, above) = (e_minus * inv_dk, e_plus * inv_dk);
    let lo = (c - bound_c) * inv_d * (1.0 - widen - below);
    let hi = (c + bound_c) * inv_d * above.mul_add(2.0f64.mul_add(above, 1.0), 1.0 + widen);
    // Comparisons with NaN are false: a NaN `above` gives the fallback too.
    let fine = above <= 0.49;
    let lo = if fine { (lo - f64::MIN_POSITIVE).max(0.0) } else { 0.0 };
    let hi = if fine { hi + f64::MIN_POSITIVE } else { f64::INFINITY };
    (lo, hi)
}

/// `C = |Δr|² − σ²` in double-double, from the exact differences (error below 2⁻⁹⁸ of
/// `|Δr|² + σ²`; see [`filtered`]).
#[inline(always)]
pub(crate) fn gap_dd<const D: usize>(dr: &[Pair; D], (s, st): Pair) -> Dd {
    let mut acc = Acc::default();
    acc.prod(-s, s);
    acc.small(-(2.0 * s).mul_add(st, st * st));
    for &(h, l) in dr {
        acc.prod(h, h);
        acc.small((2.0 * h).mul_add(l, l * l));
    }
    acc.dd()
}

/// `C = |Δr|² − σ²` exactly, from the exact differences: every square split by TwoProd
/// (`(h + l)² = h² + 2hl + l²`, each product a head and its exact error), the terms summed
/// into an expansion on the stack (Shewchuk's GROW-EXPANSION, then COMPRESS). Returns its
/// exact sign and its value as a double-double (~2⁻¹⁰⁴ relative, however much cancels) —
/// near contact, where [`gap_dd`]'s accuracy is only absolute (2⁻⁹⁸ of `|Δr|² + σ²`) and a
/// gap of 10⁻¹² diameters keeps 2⁻⁵⁸ of it. `None` when a product's error term would fall
/// below 2⁻⁹⁶⁰ (near the subnormals, where TwoProd stops being exact): the caller then takes
/// the exact path.
#[inline]
pub(crate) fn exact_gap<const D: usize>(dr: &[Pair; D], (s, t): Pair) -> Option<(Ordering, Dd)> {
    const { assert!(D <= 9, "the stack holds 6·(D + 1) + 1 terms") };
    const FLOOR: f64 = pow2(-960);
    let mut e = [0.0f64; 64];
    let mut len = 0;
    let mut fine = true;
    let mut square = |e: &mut [f64; 64], len: &mut usize, h: f64, l: f64, sign: f64| {
        for (x, y) in [(h, h), (2.0 * h, l), (l, l)] {
            let (p, err) = two_prod(x, y);
            fine &= p == 0.0 || p.abs() >= FLOOR;
            *len = grow_in_place(e, *len, sign * p);
            *len = grow_in_place(e, *len, sign * err);
        }
    };
    for &(h, l) in dr {
        square(&mut e, &mut len, h, l, 1.0);
    }
    square(&mut e, &mut len, s, t, -1.0);
    if !fine {
        return None;
    }
    let len = compress_in_place(&mut e, len);
    Some((sign_of(&e[..len]), dd_of_compressed(&e[..len])))
}

/// A double-double accumulator: heads summed exactly by TwoSum, tails in plain f64.
#[derive(Default)]
pub(crate) struct Acc {
    hi: f64,
    lo: f64,
}

impl Acc {
    /// Adds `x·y` (exactly split by TwoProd).
    #[inline(always)]
    pub(crate) fn prod(&mut self, x: f64, y: f64) {
        let (p, e) = two_prod(x, y);
        let (s, f) = two_sum(self.hi, p);
        self.hi = s;
        self.lo += f + e;
    }
    /// Adds a small term (already below the heads by a factor ~u).
    #[inline(always)]
    pub(crate) fn small(&mut self, x: f64) {
        self.lo += x;
    }
    #[inline(always)]
    pub(crate) fn dd(&self) -> Dd {
        Dd::new(self.hi, self.lo)
    }
    /// Adds `x²` for a double-double `x` (its head exactly, its tail as a small term).
    #[inline(always)]
    pub(crate) fn square(&mut self, x: Dd) {
        let sq = x.mul(x);
        self.prod(sq.hi, 1.0);
        self.small(sq.lo);
    }
    /// Subtracts `|Δr ∧ Δv|² = Σ_{i<j}(ΔrᵢΔvⱼ − ΔrⱼΔvᵢ)²`, each cross product formed in
    /// double-double from the exact differences.
    #[inline(always)]
    pub(crate) fn minus_cross_squares<const D: usize>(&mut self, dr: &[Pair; D], dv: &[Pair; D]) {
        for i in 0..D {
            for j in i + 1..D {
                let ((hi, li), (gi, mi)) = (dr[i], dv[i]);
                let ((hj, lj), (gj, mj)) = (dr[j], dv[j]);
                let mut x = Acc::default();
                x.prod(hi, gj);
                x.prod(-hj, gi);
                x.small(hi.mul_add(mj, li * gj) - hj.mul_add(mi, lj * gi) + (li * mj - lj * mi));
                let sq = x.dd().mul(x.dd());
                self.prod(-sq.hi, 1.0);
                self.small(-sq.lo);
            }
        }
    }
}

// ---------------------------------------------------------------------------------------
// The exact path: expansions, on inputs scaled to magnitude [1, 2).
// ---------------------------------------------------------------------------------------

fn exact<const D: usize>(dr: &[Pair; D], dv: &[Pair; D], sigma: Pair, time_exp: i32) -> Contact {
    let ex = |p: Pair| Expansion::from_pair(p.0, p.1);
    let drx: Vec<Expansion> = dr.iter().map(|&p| ex(p)).collect();
    let dvx: Vec<Expansion> = dv.iter().map(|&p| ex(p)).collect();
    let sx = ex(sigma);

    let mut b = Expansion::default();
    for i in 0..D {
        b = b.add(&drx[i].mul(&dvx[i]));
    }
    if b.sign() != Ordering::Less {
        return Contact::Never(Miss::Receding);
    }
    let mut c = sx.mul(&sx).neg();
    for x in &drx {
        c = c.add(&x.mul(x));
    }
    if c.sign() != Ordering::Greater {
        return Contact::Now;
    }
    let mut a = Expansion::default();
    for x in &dvx {
        a = a.add(&x.mul(x));
    }
    let mut crosses = Vec::with_capacity(D * (D - 1) / 2);
    for i in 0..D {
        for j in i + 1..D {
            crosses.push(drx[i].mul(&dvx[j]).sub(&drx[j].mul(&dvx[i])).compress());
        }
    }
    // D = aσ² − Σ cross² is homogeneous of degree 2 in lengths: evaluate it at lengths scaled
    // by 2^k so that max(σ, |cross|) ~ 1 — otherwise tiny radii (σ² below the subnormal range)
    // would turn a head-on hit into a graze.
    let m = crosses.iter().fold(sigma.0, |m, x| m.max(x.magnitude()));
    let k = if m == 0.0 { 0 } else { (-exponent(m)).max(0) };
    let sk = sx.scale2(k);
    let mut disc = a.mul(&sk.mul(&sk));
    for x in &crosses {
        let xk = x.scale2(k);
        disc = disc.sub(&xk.mul(&xk));
    }
    if disc.sign() != Ordering::Greater {
        return Contact::Never(Miss::PathsMiss);
    }
    let root = disc.to_dd().sqrt();
    let root = Dd { hi: scale2(root.hi, -k), lo: scale2(root.lo, -k) };
    let t = c.to_dd().div(b.neg().to_dd().add(root));
    Contact::At(t.to_f64_scaled(time_exp).max(f64::from_bits(1)))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ball(position: [f64; 2], velocity: [f64; 2], radius: f64) -> Ball<2> {
        Ball { position, velocity, radius }
    }

    /// Runs both paths (the filter where it applies, and the exact one) and checks they agree.
    fn both(p: &Ball<2>, q: &Ball<2>) -> Contact {
        let fast = contact_time(p, q).unwrap();
        assert_eq!(fast, contact_time_exact_path(p, q), "filter and exact path disagree");
        fast
    }

    #[test]
    fn head_on_and_classification_cases() {
        let a = ball([0.0, 0.0], [1.0, 0.0], 0.5);
        assert_eq!(both(&a, &ball([3.0, 0.0], [-1.0, 0.0], 0.5)), Contact::At(1.0));
        assert_eq!(both(&a, &ball([3.0, 0.0], [2.0, 0.0], 0.5)), Contact::Never(Miss::Receding));
        assert_eq!(both(&a, &ball([3.0, 5.0], [-1.0, 0.0], 0.5)), Contact::Never(Miss::PathsMiss));
        // Exact graze: impact parameter equals σ = 1.
        assert_eq!(both(&a, &ball([3.0, 1.0], [-1.0, 0.0], 0.5)), Contact::Never(Miss::PathsMiss));
        // Overlapping and approaching: now; overlapping and separating: never.
        assert_eq!(both(&a, &ball([0.5, 0.0], [-1.0, 0.0], 0.5)), Contact::Now);
        assert_eq!(both(&a, &ball([0.5, 0.0], [3.0, 0.0], 0.5)), Contact::Never(Miss::Receding));
        // Touching exactly and approaching.
        assert_eq!(both(&a, &ball([1.0, 0.0], [0.0, 0.0], 0.5)), Contact::Now);
    }

    #[test]
    fn tiny_radii_head_on_still_hit() {
        let r = scale2(1.0, -700);
        let p = ball([0.0, 0.0], [0.0, 0.0], r);
        let q = ball([1.0, 1.0], [-1.0, -1.0], r);
        // t = 1 − σ/|Δr| with σ = 2^-699, |Δr| = √2: rounds to 1 − 2⁻⁵³ or 1.
        let t = both(&p, &q).time().unwrap();
        assert!(t == 1.0 || t == 1.0 - U, "{t}");
    }

    #[test]
    fn errors_name_the_field() {
        let mut p = ball([0.0, 0.0], [0.0, 0.0], 1.0);
        let q = ball([0.0, 0.0], [0.0, 0.0], 1.0);
        p.velocity[1] = f64::NAN;
        let e = contact_time(&p, &q).unwrap_err();
        assert_eq!(e.to_string(), "v1[1] = NaN is not finite");
        let q = ball([0.0, 0.0], [0.0, 0.0], -2.0);
        let p = ball([0.0, 0.0], [0.0, 0.0], 1.0);
        assert!(matches!(contact_time(&p, &q), Err(ContactError::NegativeRadius { ball: 2, .. })));
    }

    /// The batch's range check (`in_range`) gives the verdict of the per-axis form the filter
    /// is written in, on every combination of special values in two dimensions (NaN, ±∞,
    /// both sides of 2^±150, zeros of both signs, ordinary numbers).
    #[test]
    fn the_range_check_is_the_filters() {
        let values = [
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
            pow2(151),
            -pow2(150),
            pow2(149),
            pow2(-149),
            -pow2(-150),
            pow2(-151),
            0.0,
            -0.0,
            0.7,
            -3.0,
        ];
        let per_axis = |r1: f64, r2: f64, h: &[f64; 2], g: &[f64; 2]| {
            let (hi, lo) = (pow2(150), pow2(-150));
            let s = r1 + r2;
            let mut ok = r1 >= 0.0 && r2 >= 0.0 && s <= hi;
            let (mut lmax, mut vmax) = (s, 0.0f64);
            for i in 0..2 {
                ok &= h[i].abs() <= hi && g[i].abs() <= hi;
                lmax = lmax.max(h[i].abs());
                vmax = vmax.max(g[i].abs());
            }
            ok && lmax >= lo && vmax >= lo
        };
        let (mut checked, mut accepted) = (0, 0);
        for &r1 in &values {
            for &r2 in &values {
                for &h0 in &values {
                    for &h1 in &values {
                        for &g0 in &values {
                            for &g1 in &values {
                                let (h, g) = ([h0, h1], [g0, g1]);
                                let (_, q, _) = filter_c(&h, r1 + r2);
                                let (_, scale, _) = filter_disc(&h, &g, r1 + r2);
                                let want = per_axis(r1, r2, &h, &g);
                                assert_eq!(in_range(r1, r2, &h, &g, q, scale), want, "{r1} {r2} {h:?} {g:?}");
                                checked += 1;
                                accepted += want as usize;
                            }
                        }
                    }
                }
            }
        }
        assert!(accepted > checked / 50 && accepted < checked / 2, "{accepted} of {checked}");
    }

    /// The widening of [`bracket_ends`] against its derivation: with exact values (zero
    /// bounds), every bracket must hold the band `t·(1 ∓ 2u)` — one ulp either side of the
    /// exact root `t`, where the kernel's time may lie — for `b`, `c`, `D` spread over twelve
    /// decades and `D` down to 10⁻⁸·b² (glancing). The root is computed in double-double
    /// (relative error ~2⁻¹⁰³, far inside the margins). With 12u this must hold everywhere;
    /// with 5u it must fail somewhere (measured: about 6 100 of the 200 000 cases; 11 900 with
    /// 4u, one with 6u, none from 7u on — the ends' roundings reach past 4u, their bound being
    /// 9u), so the test tells a widening too small from a sufficient one.
    #[test]
    fn bracket_ends_hold_the_one_ulp_band() {
        let mut unit = crate::uniform_stream(0x2545_F491_4F6C_DD1Du64);
        let misses = |widen: f64, unit: &mut dyn FnMut() -> f64| {
            let mut missed = 0;
            for _ in 0..200_000 {
                let b = -(10f64.powf(12.0 * unit() - 6.0));
                let c = 10f64.powf(12.0 * unit() - 6.0);
                let disc = b * b * 10f64.powf(-8.0 * unit());
                let (lo, hi) = widened_ends((b, 0.0), (c, 0.0), (disc, 0.0), widen);
                let t = Dd::from_f64(c).div(Dd::from_f64(-b).add(Dd::from_f64(disc).sqrt()));
                let below = t.mul(Dd::from_f64(1.0 - 2.0 * U));
                let above = t.mul(Dd::from_f64(1.0 + 2.0 * U));
                // lo ≤ below and hi ≥ above; the differences of nearby doubles are exact.
                let holds = lo - below.hi <= below.lo && hi - above.hi >= above.lo;
                missed += usize::from(!holds);
            }
            missed
        };
        assert_eq!(misses(WIDEN, &mut unit), 0, "the widening of bracket_ends misses the band");
        assert!(misses(5.0 * U, &mut unit) > 0, "a widening of 5u should miss: the test has no teeth");
    }

    /// The error terms of [`bracket_ends`] against its derivation: with nonzero bounds, the
    /// bracket must hold every root the box `c ∈ [c̃ ∓ γ]`, `−b ∈ [B ∓ β]`, `D ∈ [D̃ ∓ δ]`
    /// allows, one ulp either side — that is, `(c̃ − γ)/(B + β + √(D̃ + δ))·(1 − 2u)` and
    /// `(c̃ + γ)/(B − β + √(D̃ − δ))·(1 + 2u)`, in double-double — for `δ/D̃` spread over
    /// `(0, 1)` (up to a `D` barely certified) and `β/B` up to a quarter. And it must not be
    /// vacuous: at most a tenth of the cases may fall back to `[0, +∞]`, and where the box is
    /// narrow and the second-order terms negligible (`x₋ < 10⁻⁹`, `y < 10⁻⁹`) the bracket may
    /// be at most 40u wider, relatively, than the box's own roots (measured: 30u, of which
    /// the widening is 24u; 16 fallbacks). Teeth: dropping the second-order term `y` of `e₊`,
    /// or bounding `1/(d − e₊)` by `(1 + x₊)/d`, makes it fail.
    #[test]
    fn bracket_ends_hold_the_box() {
        let mut unit = crate::uniform_stream(0x9E37_79B9_7F4A_7C15u64);
        let (mut fallbacks, mut narrow, mut widest) = (0, 0, 0.0f64);
        for _ in 0..200_000 {
            let big_b = 10f64.powf(12.0 * unit() - 6.0);
            let c = 10f64.powf(12.0 * unit() - 6.0);
            let disc = big_b * big_b * 10f64.powf(-8.0 * unit());
            let bound_b = big_b * 0.25 * 10f64.powf(-14.0 * unit());
            let bound_c = c * 0.25 * 10f64.powf(-14.0 * unit());
            let y = if unit() < 0.5 { unit() } else { 10f64.powf(-14.0 * unit()) };
            let bound_d = disc * y.min(0.999);
            let (lo, hi) = bracket_ends((-big_b, bound_b), (c, bound_c), (disc, bound_d));
            if hi == f64::INFINITY {
                assert_eq!(lo, 0.0);
                fallbacks += 1;
                continue;
            }
            let dd = Dd::from_f64;
            let small = dd(c).add(dd(-bound_c));
            let large = dd(c).add(dd(bound_c));
            let root_plus = dd(disc).add(dd(bound_d)).sqrt();
            let root_minus = dd(disc).add(dd(-bound_d)).sqrt();
            let t_min = small.div(dd(big_b).add(dd(bound_b)).add(root_plus));
            let t_max = large.div(dd(big_b).add(dd(-bound_b)).add(root_minus));
            let below = t_min.mul(dd(1.0 - 2.0 * U));
            let above = t_max.mul(dd(1.0 + 2.0 * U));
            assert!(
                lo - below.hi <= below.lo && hi - above.hi >= above.lo,
                "b {big_b:e}±{bound_b:e} c {c:e}±{bound_c:e} D {disc:e}±{bound_d:e}: [{lo:e}, {hi:e}] \
                 does not hold [{:e}, {:e}]",
                t_min.hi,
                t_max.hi
            );
            let x = (bound_b + 0.5 * bound_d / disc.sqrt()) / (big_b + disc.sqrt());
            if x < 1e-9 && y < 1e-9 {
                narrow += 1;
                let excess = ((hi - lo) - (t_max.hi - t_min.hi)) / (U * t_max.hi);
                widest = widest.max(excess);
            }
        }
        assert!(fallbacks < 20_000, "{fallbacks} of 200 000 brackets fell back to [0, +∞]");
        assert!(narrow > 10_000, "only {narrow} narrow boxes");
        assert!(widest <= 40.0, "a bracket {widest:.1}u wider than its box");
    }
}
