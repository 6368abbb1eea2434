//! All real roots of `a·x² + b·x + c = 0` for finite f64 coefficients.
//!
//! # Method
//!
//! Zero coefficients are decided first, exactly (−0.0 counts as 0):
//!
//! | case | roots |
//! |---|---|
//! | `a = b = c = 0` | every x ([`Roots::All`]) |
//! | `a = b = 0 ≠ c` | none |
//! | `a = 0 ≠ b` | `x = −c/b` (one correctly rounded division) |
//! | `c = 0 ≠ a` | `x = 0` and `x = −b/a` (one root `0` if also `b = 0`) |
//! | `b = 0`, `a, c ≠ 0` | `x = ±√(−c/a)` if `−c/a > 0`, else none |
//!
//! Otherwise let `K = e_a + e_c − 2e_b` (binary exponents), so that `4ac/b² ≈ 2^(K+2)`:
//!
//! * `K < −220` (`b² ≫ |4ac|`): `x₁ = −b/a`, `x₂ = −c/b`. The neglected terms are below
//!   `2⁻²¹⁸` relative, far inside the rounding of the division.
//! * `K > 220` (`|4ac| ≫ b²`): no root if `ac > 0`, else `x = ±√(−c/a)`; the shift `−b/2a`
//!   is below `2⁻¹⁰⁹` relative.
//! * otherwise: substitute `x = 2^s·y` and multiply by `2^m` so that `a', b' ∈ [1, 2)` and
//!   `|c'| < 2²²²` (exact power-of-two scaling: nothing overflows or underflows). The
//!   discriminant `Δ' = b'² − 4a'c'` is held *exactly* as an expansion of four f64 (two
//!   FMA products, Kahan 2004), so its sign — two, one or no roots — is exact. Then,
//!   without cancellation (Higham §1.8):
//!
//!   `q = −(b' + sign(b')·√Δ') / 2`,   `y₁ = q / a'`,   `y₂ = c' / q`,
//!
//!   evaluated in double-double (~2⁻¹⁰³ relative) and scaled back by `2^s` with one rounding.
//!
//! # Accuracy contract
//!
//! For every finite `a, b, c`:
//!
//! * the number of distinct real roots of the exact (f64-valued) coefficients is returned
//!   exactly;
//! * every returned root is within one ulp of the exact root it stands for — in fact
//!   correctly rounded except within `2⁻⁵⁰` ulp of a rounding boundary, or where the
//!   result is subnormal (one extra rounding). A root beyond `±f64::MAX` is returned as
//!   `±∞`, as IEEE 754 rounding would; a zero root is `+0.0`.
//!
//! The tests in `crates/quadratic/tests/` prove this against an exact big-integer oracle.

use crate::exact::{
    Dd, compress_in_place, dd_of_compressed, exponent, grow_in_place, pow2, scale2, sign_of, two_prod, two_sum,
};
use core::cmp::Ordering;
use core::fmt;

/// The real roots of a quadratic (or lower-degree) equation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Roots {
    /// No real root: `Δ < 0`, or the equation is `c = 0` with `c ≠ 0`.
    None,
    /// Exactly one real root: the equation is linear (`a = 0 ≠ b`) or has a double root
    /// (`b² = 4ac` exactly).
    One(f64),
    /// Two distinct real roots `x₁ ≤ x₂` (two distinct exact roots may round to the same f64).
    Two(f64, f64),
    /// Every x is a root: `a = b = c = 0`.
    All,
}

impl Roots {
    /// The finite list of roots, ascending (empty for [`Roots::None`] and [`Roots::All`]).
    pub fn as_vec(&self) -> Vec<f64> {
        match *self {
            Roots::None | Roots::All => Vec::new(),
            Roots::One(x) => vec![x],
            Roots::Two(x1, x2) => vec![x1, x2],
        }
    }
}

/// Which coefficient of `a·x² + b·x + c`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Coefficient {
    /// The quadratic coefficient.
    A,
    /// The linear coefficient.
    B,
    /// The constant term.
    C,
}

/// Why [`solve`] refused its input.
#[non_exhaustive]
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SolveError {
    /// A coefficient is NaN or infinite.
    NonFinite {
        /// Which one.
        coefficient: Coefficient,
        /// Its value.
        value: f64,
    },
}

impl fmt::Display for SolveError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SolveError::NonFinite { coefficient, value } => {
                let name = match coefficient {
                    Coefficient::A => "a",
                    Coefficient::B => "b",
                    Coefficient::C => "c",
                };
                write!(f, "coefficient {name} = {value} is not finite (NaN and ±inf have no roots to speak of)")
            }
        }
    }
}

impl std::error::Error for SolveError {}

/// Beyond this exponent gap the smaller of `b²` and `|4ac|` cannot move a rounded root.
const DOMINANCE: i32 = 220;

/// All real roots of `a·x² + b·x + c = 0`; see the [module docs](self) for the contract.
///
/// ```
/// use quadratic::{solve, Roots};
/// // x² − 3x + 2 = (x − 1)(x − 2)
/// assert_eq!(solve(1.0, -3.0, 2.0), Ok(Roots::Two(1.0, 2.0)));
/// // The textbook formula loses the small root to cancellation here; we do not.
/// assert_eq!(solve(1.0, -1e8, 1.0), Ok(Roots::Two(1e-8, 1e8 - 1e-8)));
/// ```
pub fn solve(a: f64, b: f64, c: f64) -> Result<Roots, SolveError> {
    for (coefficient, value) in [(Coefficient::A, a), (Coefficient::B, b), (Coefficient::C, c)] {
        if !value.is_finite() {
            return Err(SolveError::NonFinite { coefficient, value });
        }
    }
    Ok(solve_finite(a, b, c))
}

/// `+0.0` for either zero; zero roots are reported as `+0.0`.
#[inline]
fn plus_zero(x: f64) -> f64 {
    if x == 0.0 { 0.0 } else { x }
}

fn two_sorted(x: f64, y: f64) -> Roots {
    let (x, y) = (plus_zero(x), plus_zero(y));
    if x <= y { Roots::Two(x, y) } else { Roots::Two(y, x) }
}

fn solve_finite(a: f64, b: f64, c: f64) -> Roots {
    if a == 0.0 {
        if b == 0.0 {
            return if c == 0.0 { Roots::All } else { Roots::None };
        }
        return Roots::One(plus_zero(-c / b));
    }
    if c == 0.0 {
        if b == 0.0 {
            return Roots::One(0.0);
        }
        return two_sorted(0.0, -b / a);
    }
    if b == 0.0 {
        return symmetric_pair(a, c);
    }
    let (ea, eb, ec) = (exponent(a), exponent(b), exponent(c));
    let k = ea + ec - 2 * eb;
    if k < -DOMINANCE {
        return two_sorted(-b / a, -c / b);
    }
    if k > DOMINANCE {
        return symmetric_pair(a, c);
    }

    // x = 2^s·y, equation times 2^m: a' = a·2^(2s+m), b' = b·2^(s+m), c' = c·2^m.
    let s = eb - ea;
    let m = ea - 2 * eb;
    let a1 = scale2(a, -ea);
    let b1 = scale2(b, -eb);
    let c1 = scale2(c, m); // exponent of c' is K ∈ [−220, 220]: exact

    // Δ' = b'² − 4a'c' = (p + pe) − (q + qe) exactly, with p = fl(b'²), q = fl(4a'c').
    let (p, pe) = two_prod(b1, b1);
    let (q, qe) = two_prod(4.0 * a1, c1);
    let (d, de) = two_sum(p, -q);
    // Fast path: when |p − q| is far above the tails (|pe|, |qe| ≤ u·(p + |q|)), the sign is
    // that of d (the tail is below |d|/2) and (d, de + pe − qe) is the value to ~2⁻⁸⁵ relative. Otherwise (near-double
    // roots) the four terms are summed exactly as an expansion on the stack.
    let mut terms = [0.0; 4];
    let (sign, value) = if d.abs() >= pow2(-20) * (p + q.abs()) {
        (if d > 0.0 { Ordering::Greater } else { Ordering::Less }, Dd::new(d, de + (pe - qe)))
    } else {
        let mut len = 0;
        for term in [pe, -qe, de, d] {
            len = grow_in_place(&mut terms, len, term);
        }
        let len = compress_in_place(&mut terms, len);
        (sign_of(&terms[..len]), dd_of_compressed(&terms[..len]))
    };
    match sign {
        Ordering::Less => Roots::None,
        Ordering::Equal => Roots::One(plus_zero(scale2(-b1 / (2.0 * a1), s))),
        Ordering::Greater => {
            let root = value.sqrt();
            let signed = if b1 > 0.0 { root } else { root.neg() };
            // q = −(b' + sign(b')√Δ')/2: the two terms have the same sign, no cancellation.
            let q = Dd::from_f64(b1).add(signed);
            let q = Dd { hi: -0.5 * q.hi, lo: -0.5 * q.lo };
            let y1 = q.div(Dd::from_f64(a1));
            let y2 = Dd::from_f64(c1).div(q);
            two_sorted(y1.to_f64_scaled(s), y2.to_f64_scaled(s))
        }
    }
}

/// `±√(−c/a)` when `−c/a > 0` (none otherwise), accurate to ~2⁻¹⁰³ before the final rounding.
fn symmetric_pair(a: f64, c: f64) -> Roots {
    if (a > 0.0) == (c > 0.0) {
        return Roots::None;
    }
    // −c/a = (|c|·2^-ec) / (|a|·2^-ea) · 2^(ec−ea); make the exponent even so it halves exactly.
    let (ea, ec) = (exponent(a), exponent(c));
    let mut e = ec - ea;
    let mut cn = scale2(c.abs(), -ec);
    if e % 2 != 0 {
        cn *= 2.0;
        e -= 1;
    }
    let an = scale2(a.abs(), -ea);
    let r = Dd::from_f64(cn).div(Dd::from_f64(an)).sqrt().to_f64_scaled(e / 2);
    Roots::Two(-r, r)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn zero_coefficient_cases_are_exact() {
        assert_eq!(solve_finite(0.0, 0.0, 0.0), Roots::All);
        assert_eq!(solve_finite(-0.0, 0.0, -0.0), Roots::All);
        assert_eq!(solve_finite(0.0, -0.0, 1.0), Roots::None);
        assert_eq!(solve_finite(0.0, 2.0, -0.0), Roots::One(0.0));
        assert_eq!(solve_finite(0.0, 3.0, -1.0), Roots::One(1.0 / 3.0));
        assert_eq!(solve_finite(2.0, 0.0, -0.0), Roots::One(0.0));
        assert_eq!(solve_finite(2.0, -6.0, 0.0), Roots::Two(0.0, 3.0));
        assert_eq!(solve_finite(1.0, -0.0, -4.0), Roots::Two(-2.0, 2.0));
        assert_eq!(solve_finite(1.0, 0.0, 4.0), Roots::None);
    }

    #[test]
    fn exact_double_root_is_one_root() {
        // (x − 3)² = x² − 6x + 9
        assert_eq!(solve_finite(1.0, -6.0, 9.0), Roots::One(3.0));
        // Kahan's Fibonacci-like case: b² − 4ac = 0 needs all 106 bits of b².
        let (a, b, c) = (94906265.625, -189812534.0, 94906268.375);
        assert!(matches!(solve_finite(a, b, c), Roots::Two(_, _)));
    }

    #[test]
    fn extreme_scales_neither_overflow_nor_underflow() {
        // (x − 2^600)(x − 2^601) times 2^-900: coefficients 2^-900, −3·2^-300, 2^301.
        let r = solve_finite(scale2(1.0, -900), -3.0 * scale2(1.0, -300), scale2(1.0, 301));
        assert_eq!(r, Roots::Two(scale2(1.0, 600), scale2(1.0, 601)));
        // (x − 1)(x − 2) times 2^1000: b² overflows in f64, the roots are tame.
        let r = solve_finite(scale2(1.0, 1000), -3.0 * scale2(1.0, 1000), scale2(1.0, 1001));
        assert_eq!(r, Roots::Two(1.0, 2.0));
    }
}
