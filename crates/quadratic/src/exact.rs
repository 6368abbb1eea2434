//! Error-free transformations, exact expansion arithmetic and double-double helpers.
//!
//! Three layers, each used where the one below it is not enough:
//!
//! * **Error-free transformations** ([`two_sum`], [`two_prod`]): `a + b = s + e` and
//!   `a · b = p + e` *exactly*, with `s = fl(a + b)`, `p = fl(a · b)` (Knuth; Dekker; the product
//!   by one fused multiply–add). Exact as long as nothing overflows and the product's error term
//!   is not below the subnormal range.
//! * **Expansions** ([`Expansion`]): a value held exactly as an unevaluated sum of non-overlapping
//!   f64 components (Shewchuk 1997, "Adaptive Precision Floating-Point Arithmetic and Fast Robust
//!   Geometric Predicates"). Sums and products of expansions are exact, so the *sign* of a
//!   polynomial in f64 inputs is exact. Used only where a cheaper evaluation cannot certify
//!   its answer.
//! * **Double-double** ([`Dd`]): about 106 significant bits, enough to round a root correctly
//!   in all but the rarest cases and within one ulp always.

use core::cmp::Ordering;

/// `(s, e)` with `s = fl(a + b)` and `s + e = a + b` exactly (Knuth's TwoSum, branch-free).
#[inline(always)]
pub fn two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    let bb = s - a;
    let e = (a - (s - bb)) + (b - bb);
    (s, e)
}

/// TwoSum when `|a| ≥ |b|` (or `a = 0`) is known: three operations instead of six.
#[inline(always)]
pub fn fast_two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    let e = b - (s - a);
    (s, e)
}

/// `(p, e)` with `p = fl(a · b)` and `p + e = a · b` exactly, by one FMA.
///
/// Exact unless `a · b` overflows or its rounding error lies below the subnormal range
/// (exponent of `a · b` below about −969).
#[inline(always)]
pub fn two_prod(a: f64, b: f64) -> (f64, f64) {
    let p = a * b;
    let e = a.mul_add(b, -p);
    (p, e)
}

/// The binary exponent `⌊log₂|x|⌋` of a finite non-zero `x`, subnormals included.
#[inline]
pub fn exponent(x: f64) -> i32 {
    let bits = x.to_bits() & !(1u64 << 63);
    let e = (bits >> 52) as i32;
    if e == 0 {
        let m = bits & ((1u64 << 52) - 1);
        -1074 + (63 - m.leading_zeros() as i32)
    } else {
        e - 1023
    }
}

/// `2^k` for `-1022 ≤ k ≤ 1023`.
#[inline]
pub const fn pow2(k: i32) -> f64 {
    debug_assert!(k >= -1022 && k <= 1023);
    f64::from_bits(((k + 1023) as u64) << 52)
}

/// `x · 2^k` rounded once (to nearest, ties to even), for any `k`.
///
/// A plain `x * 2f64.powi(k)` may round twice (or overflow in `powi`); here every
/// intermediate step is exact and only the final one may round, into the subnormal
/// range or to ±∞.
pub fn scale2(x: f64, k: i32) -> f64 {
    if x == 0.0 || !x.is_finite() || k == 0 {
        return x;
    }
    let ex = exponent(x);
    let target = ex.saturating_add(k);
    if (-1022..=1023).contains(&k) && (-1022..=1023).contains(&target) && ex >= -1022 {
        // Normal in, normal out, 2^k representable: one exact multiplication.
        return x * pow2(k);
    }
    if target > 1023 {
        return f64::INFINITY.copysign(x);
    }
    if target >= -1022 {
        // Every intermediate exponent lies between ex and target: no rounding.
        let mut y = x;
        let mut rest = k;
        while rest != 0 {
            let step = rest.clamp(-1000, 1000);
            y *= pow2(step);
            rest -= step;
        }
        return y;
    }
    // Subnormal (or zero) result: bring x exactly to [1, 2), then to the bottom of the
    // normal range (exact), then one rounding multiplication.
    let mut y = x;
    let mut rest = -ex;
    while rest != 0 {
        let step = rest.clamp(-1000, 1000);
        y *= pow2(step);
        rest -= step;
    }
    y *= pow2(-1022);
    y * pow2((target + 1022).max(-60))
}

/// A double-double number `hi + lo` with `|lo| ≤ ulp(hi)/2` (after normalisation).
///
/// The operations below are the classical ones (Dekker 1971; Bailey's QD library), written
/// for positive operands without cancellation, which is all the solvers need: each has a
/// relative error of a few units of 2⁻¹⁰⁴.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Dd {
    /// The leading part, `fl(hi + lo)`.
    pub hi: f64,
    /// The trailing part.
    pub lo: f64,
}

impl Dd {
    /// `x` exactly.
    #[inline]
    pub fn from_f64(x: f64) -> Self {
        Dd { hi: x, lo: 0.0 }
    }

    /// `hi + lo`, renormalised so that `hi = fl(hi + lo)`.
    #[inline]
    pub fn new(hi: f64, lo: f64) -> Self {
        let (hi, lo) = two_sum(hi, lo);
        Dd { hi, lo }
    }

    /// `-self`, exactly.
    #[inline]
    pub fn neg(self) -> Self {
        Dd { hi: -self.hi, lo: -self.lo }
    }

    /// `self + other`; accurate to ~2⁻¹⁰⁴ relative when both have the same sign.
    #[inline]
    pub fn add(self, other: Dd) -> Dd {
        let (s, e) = two_sum(self.hi, other.hi);
        let e = e + (self.lo + other.lo);
        let (hi, lo) = fast_two_sum(s, e);
        Dd { hi, lo }
    }

    /// `self · other`, ~2⁻¹⁰⁴ relative.
    #[inline]
    pub fn mul(self, other: Dd) -> Dd {
        let (p, e) = two_prod(self.hi, other.hi);
        let e = self.hi.mul_add(other.lo, self.lo.mul_add(other.hi, e));
        let (hi, lo) = fast_two_sum(p, e);
        Dd { hi, lo }
    }

    /// `self / other`, ~2⁻¹⁰³ relative: one long-division step on the FMA remainder.
    #[inline]
    pub fn div(self, other: Dd) -> Dd {
        let q1 = self.hi / other.hi;
        // r = self − q1·other, exactly in its leading part (q1·other.hi ≈ self.hi).
        let (p, e) = two_prod(q1, other.hi);
        let r = ((self.hi - p) - e + self.lo) - q1 * other.lo;
        let q2 = r / other.hi;
        let (hi, lo) = fast_two_sum(q1, q2);
        Dd { hi, lo }
    }

    /// `√self` for `self > 0`, ~2⁻¹⁰⁴ relative: one Newton step on the FMA residual.
    #[inline]
    pub fn sqrt(self) -> Dd {
        let s = self.hi.sqrt();
        let (p, e) = two_prod(s, s);
        let r = ((self.hi - p) - e + self.lo) / (2.0 * s);
        let (hi, lo) = fast_two_sum(s, r);
        Dd { hi, lo }
    }

    /// The nearest f64 to `hi + lo` times `2^k`, within one ulp (one rounding of the
    /// double-double to f64, and at most one more if the result is subnormal).
    #[inline]
    pub fn to_f64_scaled(self, k: i32) -> f64 {
        scale2(self.hi + self.lo, k)
    }
}

/// Adds `b` to the expansion `e[..len]` in place (Shewchuk's GROW-EXPANSION with zero
/// elimination); `e` needs room for `len + 1` components. Returns the new length.
#[inline]
pub fn grow_in_place(e: &mut [f64], len: usize, b: f64) -> usize {
    let mut q = b;
    let mut out = 0;
    for i in 0..len {
        let (s, h) = two_sum(q, e[i]);
        if h != 0.0 {
            e[out] = h; // out ≤ i: never overwrites a component still to be read
            out += 1;
        }
        q = s;
    }
    if q != 0.0 {
        e[out] = q;
        out += 1;
    }
    out
}

/// Compresses the expansion `e[..len]` in place (Shewchuk's COMPRESS, which allows its
/// input and output to coincide); afterwards the components are non-adjacent, so the
/// largest approximates the value within one ulp. Returns the new length.
pub fn compress_in_place(e: &mut [f64], len: usize) -> usize {
    if len < 2 {
        return len;
    }
    let mut bottom = len - 1;
    let mut q = e[len - 1];
    for i in (0..len - 1).rev() {
        let (s, t) = fast_two_sum(q, e[i]);
        if t != 0.0 {
            e[bottom] = s;
            bottom -= 1;
            q = t;
        } else {
            q = s;
        }
    }
    e[bottom] = q;
    let mut top = 0;
    for i in bottom + 1..len {
        let (s, t) = fast_two_sum(e[i], q);
        if t != 0.0 {
            e[top] = t;
            top += 1;
        }
        q = s;
    }
    if q != 0.0 {
        e[top] = q;
        top += 1;
    }
    top
}

/// The value of a compressed expansion as a double-double (~2⁻¹⁰⁴ relative): summing a
/// geometrically decreasing expansion from the bottom keeps the error below the tail.
#[inline]
pub fn dd_of_compressed(e: &[f64]) -> Dd {
    let mut hi = 0.0;
    let mut lo = 0.0;
    for &x in e {
        let (s, t) = two_sum(hi, x);
        hi = s;
        lo += t;
    }
    Dd::new(hi, lo)
}

/// The exact sign of an expansion (that of its largest, i.e. last, component).
#[inline]
pub fn sign_of(e: &[f64]) -> Ordering {
    match e.last() {
        None => Ordering::Equal,
        Some(&x) if x > 0.0 => Ordering::Greater,
        Some(_) => Ordering::Less,
    }
}

/// An exact real number held as a sum of non-overlapping f64 components, in increasing
/// order of magnitude, with no zero components (Shewchuk 1997). The empty expansion is 0.
///
/// Every operation is exact as long as no component overflows and no product's error term
/// falls below the subnormal range; callers scale their inputs by powers of two first.
/// Expansions allocate; they sit on the rare, slow path of the solvers.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Expansion {
    c: Vec<f64>,
}

impl Expansion {
    /// The expansion of `x`.
    pub fn from_f64(x: f64) -> Self {
        let mut c = Vec::with_capacity(1);
        if x != 0.0 {
            c.push(x);
        }
        Expansion { c }
    }

    /// The expansion of `hi + lo` where `(hi, lo)` came out of [`two_sum`] or [`two_prod`]
    /// (so the two do not overlap).
    pub fn from_pair(hi: f64, lo: f64) -> Self {
        let mut c = Vec::with_capacity(2);
        if lo != 0.0 {
            c.push(lo);
        }
        if hi != 0.0 {
            c.push(hi);
        }
        Expansion { c }
    }

    /// The components, smallest first.
    pub fn components(&self) -> &[f64] {
        &self.c
    }

    /// `self + b`, exactly (Shewchuk's GROW-EXPANSION with zero elimination).
    pub fn add_f64(&self, b: f64) -> Expansion {
        let mut c = Vec::with_capacity(self.c.len() + 1);
        c.extend_from_slice(&self.c);
        c.push(0.0);
        let len = grow_in_place(&mut c, self.c.len(), b);
        c.truncate(len);
        Expansion { c }
    }

    /// `self + other`, exactly.
    pub fn add(&self, other: &Expansion) -> Expansion {
        let (mut acc, rest) =
            if self.c.len() >= other.c.len() { (self.clone(), &other.c) } else { (other.clone(), &self.c) };
        for &x in rest {
            acc = acc.add_f64(x);
        }
        acc
    }

    /// `-self`, exactly.
    pub fn neg(&self) -> Expansion {
        Expansion { c: self.c.iter().map(|x| -x).collect() }
    }

    /// `self − other`, exactly.
    pub fn sub(&self, other: &Expansion) -> Expansion {
        self.add(&other.neg())
    }

    /// `self · b`, exactly (Shewchuk's SCALE-EXPANSION with zero elimination).
    pub fn scale(&self, b: f64) -> Expansion {
        let mut out = Vec::with_capacity(2 * self.c.len());
        let Some((&first, rest)) = self.c.split_first() else {
            return Expansion::default();
        };
        if b == 0.0 {
            return Expansion::default();
        }
        let (mut q, h) = two_prod(first, b);
        if h != 0.0 {
            out.push(h);
        }
        for &e in rest {
            let (t_hi, t_lo) = two_prod(e, b);
            let (s, h) = two_sum(q, t_lo);
            if h != 0.0 {
                out.push(h);
            }
            let (s2, h2) = fast_two_sum(t_hi, s);
            if h2 != 0.0 {
                out.push(h2);
            }
            q = s2;
        }
        if q != 0.0 {
            out.push(q);
        }
        Expansion { c: out }
    }

    /// `self · other`, exactly (a sum of scaled expansions).
    pub fn mul(&self, other: &Expansion) -> Expansion {
        let mut acc = Expansion::default();
        for &f in &other.c {
            acc = acc.add(&self.scale(f));
        }
        acc.compress()
    }

    /// `self · 2^k`, exact when no component leaves the normal range.
    pub fn scale2(&self, k: i32) -> Expansion {
        Expansion { c: self.c.iter().map(|&x| scale2(x, k)).filter(|&x| x != 0.0).collect() }
    }

    /// The same value with fewer, non-adjacent components (Shewchuk's COMPRESS); afterwards
    /// the largest component approximates the value to within one ulp.
    pub fn compress(&self) -> Expansion {
        let mut c = self.c.clone();
        let len = compress_in_place(&mut c, self.c.len());
        c.truncate(len);
        Expansion { c }
    }

    /// The exact sign: that of the largest component.
    pub fn sign(&self) -> Ordering {
        sign_of(&self.c)
    }

    /// The largest component's magnitude (0 for 0): within a factor 2 of `|value|` after
    /// [`compress`](Self::compress).
    pub fn magnitude(&self) -> f64 {
        self.c.last().map_or(0.0, |x| x.abs())
    }

    /// The value rounded to a double-double, ~2⁻¹⁰⁴ relative.
    pub fn to_dd(&self) -> Dd {
        dd_of_compressed(&self.compress().c)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn two_sum_and_two_prod_are_error_free_on_classic_cases() {
        // 1 + 2⁻⁶⁰ is not representable: the error term must hold the lost 2⁻⁶⁰.
        assert_eq!(two_sum(1.0, pow2(-60)), (1.0, pow2(-60)));
        // (1 + 2⁻³⁰)² = 1 + 2⁻²⁹ + 2⁻⁶⁰.
        let x = 1.0 + pow2(-30);
        assert_eq!(two_prod(x, x), (1.0 + pow2(-29), pow2(-60)));
    }

    #[test]
    fn exponent_covers_normals_and_subnormals() {
        assert_eq!(exponent(1.0), 0);
        assert_eq!(exponent(-3.0), 1);
        assert_eq!(exponent(f64::MIN_POSITIVE), -1022);
        assert_eq!(exponent(f64::from_bits(1)), -1074);
        assert_eq!(exponent(f64::MAX), 1023);
    }

    #[test]
    fn scale2_rounds_once_into_subnormals() {
        // 1.5 · 2⁻¹⁰⁷⁴ is a tie between 1 and 2 times 2⁻¹⁰⁷⁴: ties-to-even gives 2.
        assert_eq!(scale2(1.5, -1074), f64::from_bits(2));
        // (1 + 2⁻⁵²)·2⁻¹⁰⁷⁴ just above 2⁻¹⁰⁷⁴: rounds to 2⁻¹⁰⁷⁴ (single rounding).
        assert_eq!(scale2(1.0 + f64::EPSILON, -1074), f64::from_bits(1));
        assert_eq!(scale2(f64::from_bits(1), 2000), pow2(926));
        assert_eq!(scale2(1.0, 1024), f64::INFINITY);
        assert_eq!(scale2(-1.0, -1076), -0.0);
    }

    #[test]
    fn expansions_cancel_exactly() {
        // (2⁶⁰ + 1) − 2⁶⁰ − 1 = 0 exactly, although no f64 holds 2⁶⁰ + 1.
        let e = Expansion::from_f64(pow2(60)).add_f64(1.0);
        assert_eq!(e.components().len(), 2);
        let z = e.add_f64(-pow2(60)).add_f64(-1.0);
        assert_eq!(z.sign(), Ordering::Equal);
        // (1 + 2⁻⁵²)² − 1 − 2⁻⁵¹ = 2⁻¹⁰⁴ > 0.
        let x = Expansion::from_f64(1.0 + f64::EPSILON);
        let sq = x.mul(&x).add_f64(-1.0).add_f64(-pow2(-51));
        assert_eq!(sq.sign(), Ordering::Greater);
        assert_eq!(sq.to_dd(), Dd::from_f64(pow2(-104)));
    }
}
