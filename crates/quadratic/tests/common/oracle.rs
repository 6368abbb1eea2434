//! The exact oracle: every finite f64 is a dyadic rational m·2^e, so sums and products of
//! inputs are exact big integers with a binary exponent, and signs are exact. Square roots
//! are approximated by integer square roots at a precision chosen per comparison, so that
//! the measured error of a candidate root is itself accurate to 2⁻⁴⁰ ulp.

#![allow(dead_code)]

use num_bigint::{BigInt, Sign};
use num_traits::{Signed, ToPrimitive, Zero};
use quadratic::{Ball, Contact, Miss, Roots};

/// m·2^e exactly.
#[derive(Clone, Debug)]
pub struct Dy {
    pub m: BigInt,
    pub e: i64,
}

impl Dy {
    pub fn zero() -> Dy {
        Dy { m: BigInt::zero(), e: 0 }
    }
    pub fn from_f64(x: f64) -> Dy {
        assert!(x.is_finite());
        let bits = x.to_bits();
        let biased = ((bits >> 52) & 0x7ff) as i64;
        let frac = (bits & ((1u64 << 52) - 1)) as i64;
        let (mant, e) = if biased == 0 { (frac, -1074) } else { (frac | (1 << 52), biased - 1075) };
        let m = if x.is_sign_negative() { -BigInt::from(mant) } else { BigInt::from(mant) };
        Dy { m, e }
    }
    /// 2^k.
    pub fn pow2(k: i64) -> Dy {
        Dy { m: BigInt::from(1), e: k }
    }
    fn aligned(&self, o: &Dy) -> (BigInt, BigInt, i64) {
        let e = self.e.min(o.e);
        ((&self.m) << ((self.e - e) as usize), (&o.m) << ((o.e - e) as usize), e)
    }
    pub fn add(&self, o: &Dy) -> Dy {
        if self.m.is_zero() {
            return o.clone();
        }
        if o.m.is_zero() {
            return self.clone();
        }
        let (a, b, e) = self.aligned(o);
        Dy { m: a + b, e }
    }
    pub fn neg(&self) -> Dy {
        Dy { m: -&self.m, e: self.e }
    }
    pub fn sub(&self, o: &Dy) -> Dy {
        self.add(&o.neg())
    }
    pub fn mul(&self, o: &Dy) -> Dy {
        Dy { m: &self.m * &o.m, e: self.e + o.e }
    }
    pub fn abs(&self) -> Dy {
        Dy { m: self.m.abs(), e: self.e }
    }
    /// −1, 0, 1.
    pub fn sign(&self) -> i32 {
        match self.m.sign() {
            Sign::Minus => -1,
            Sign::NoSign => 0,
            Sign::Plus => 1,
        }
    }
    pub fn is_zero(&self) -> bool {
        self.m.is_zero()
    }
    /// ⌊log₂|x|⌋ for x ≠ 0.
    pub fn log2(&self) -> i64 {
        self.m.bits() as i64 - 1 + self.e
    }
    /// s ≥ 0 with |s − √x| < 2^err_exp, for x ≥ 0.
    pub fn sqrt_within(&self, err_exp: i64) -> Dy {
        assert!(self.sign() >= 0);
        if self.is_zero() {
            return Dy::zero();
        }
        // √(m·2^e) = √(m·2^(e−2f))·2^f with e − 2f ≥ 0 even-aligned.
        let f = err_exp.min(self.e.div_euclid(2));
        let shifted: BigInt = (&self.m) << ((self.e - 2 * f) as usize);
        let root = shifted.magnitude().sqrt();
        Dy { m: BigInt::from(root), e: f }
    }
    /// self / o as an f64 (relative accuracy ~2⁻⁶⁰), for o ≠ 0.
    pub fn ratio(&self, o: &Dy) -> f64 {
        if self.is_zero() {
            return 0.0;
        }
        let (a, ea) = top64(&self.m);
        let (b, eb) = top64(&o.m);
        let k = ea + self.e - eb - o.e;
        let q = a / b;
        if k > 1000 {
            f64::INFINITY.copysign(q)
        } else if k < -1000 {
            0.0
        } else {
            q * 2f64.powi(k as i32)
        }
    }
    /// The f64 nearest to self (ties to even), through the crate's correctly rounded hex parser.
    pub fn to_f64(&self) -> f64 {
        if self.is_zero() {
            return 0.0;
        }
        let sign = if self.sign() < 0 { "-" } else { "" };
        let text = format!("{sign}0x{:x}p{}", self.m.magnitude(), self.e);
        quadratic::hex::parse(&text).unwrap()
    }
}

/// (m as f64 from its top 64 bits, exponent) so that m ≈ value·2^exponent.
fn top64(m: &BigInt) -> (f64, i64) {
    let bits = m.bits() as i64;
    let shift = (bits - 64).max(0);
    let top = (m.magnitude() >> (shift as usize)).to_u64().unwrap() as f64;
    (if m.sign() == Sign::Minus { -top } else { top }, shift)
}

/// The smaller gap between x and its two neighbours: the strict unit for "within 1 ulp".
pub fn gap(x: f64) -> Dy {
    let ax = x.abs();
    if ax < f64::MIN_POSITIVE * 2.0 {
        return Dy::pow2(-1074);
    }
    let e = quadratic::exact::exponent(ax) as i64;
    let power_of_two = ax.to_bits() & ((1u64 << 52) - 1) == 0;
    Dy::pow2(if power_of_two { e - 53 } else { e - 52 })
}

/// |x − r| / gap(x) for the exact root r = (p + s·√Δ) / q  (s = ±1, q ≠ 0), i.e.
/// |q·x − p − s√Δ| / |q·gap(x)|, with √Δ accurate to 2⁻⁴⁰ of the denominator.
pub fn ulps_from_root(x: f64, p: &Dy, s: i32, disc: &Dy, q: &Dy) -> f64 {
    let unit = q.mul(&gap(x)).abs();
    let root = disc.sqrt_within(unit.log2() - 40);
    let root = if s < 0 { root.neg() } else { root };
    let num = q.mul(&Dy::from_f64(x)).sub(p).sub(&root);
    num.ratio(&unit).abs()
}

/// The exact answer of the quadratic: (count, measured ulp errors of each returned root).
/// `count` is 0, 1, 2, or usize::MAX for "all x".
pub fn check_roots(a: f64, b: f64, c: f64, got: &Roots) -> RootCheck {
    let (da, db, dc) = (Dy::from_f64(a), Dy::from_f64(b), Dy::from_f64(c));
    let expected = if da.is_zero() {
        if db.is_zero() { if dc.is_zero() { usize::MAX } else { 0 } } else { 1 }
    } else {
        let disc = db.mul(&db).sub(&Dy::from_f64(4.0).mul(&da).mul(&dc));
        match disc.sign() {
            -1 => 0,
            0 => 1,
            _ => 2,
        }
    };
    let got_count = match got {
        Roots::None => 0,
        Roots::One(_) => 1,
        Roots::Two(..) => 2,
        Roots::All => usize::MAX,
    };
    if got_count != expected {
        return RootCheck { count_ok: false, max_ulps: f64::NAN };
    }
    let mut max_ulps: f64 = 0.0;
    let mut measure = |x: f64, which: i32| {
        if x.is_nan() {
            max_ulps = f64::INFINITY;
            return;
        }
        if x.is_infinite() {
            // Accepted only if the exact root is beyond the finite range (checked by ratio).
            let e = exact_root_estimate(&da, &db, &dc, which);
            if e.abs() < f64::MAX {
                max_ulps = f64::INFINITY;
            }
            return;
        }
        let u = if da.is_zero() {
            // b·x + c = 0: |b·x + c| / |b·gap|
            Dy::from_f64(x).mul(&db).add(&dc).ratio(&db.mul(&gap(x)).abs()).abs()
        } else {
            let disc = db.mul(&db).sub(&Dy::from_f64(4.0).mul(&da).mul(&dc));
            let q = Dy::from_f64(2.0).mul(&da);
            // roots (−b ∓ √Δ)/2a; the smaller one takes −√Δ when a > 0.
            let s = if which == 0 { -1 } else { 1 } * da.sign();
            ulps_from_root(x, &db.neg(), s, &disc, &q)
        };
        max_ulps = max_ulps.max(u);
    };
    match *got {
        Roots::One(x) => measure(x, 0),
        Roots::Two(x1, x2) => {
            measure(x1, 0);
            measure(x2, 1);
        }
        _ => {}
    }
    RootCheck { count_ok: true, max_ulps }
}

/// A rough f64 value of root `which` (0 smaller), possibly ±∞, for overflow checks.
fn exact_root_estimate(a: &Dy, b: &Dy, c: &Dy, which: i32) -> f64 {
    if a.is_zero() {
        return c.neg().ratio(b);
    }
    let disc = b.mul(b).sub(&Dy::from_f64(4.0).mul(a).mul(c));
    let q = Dy::from_f64(2.0).mul(a);
    let root = disc.sqrt_within(disc.log2() / 2 - 80);
    let s = if which == 0 { -1 } else { 1 } * a.sign();
    let num = if s < 0 { b.neg().sub(&root) } else { b.neg().add(&root) };
    num.ratio(&q)
}

#[derive(Clone, Copy, Debug)]
pub struct RootCheck {
    pub count_ok: bool,
    pub max_ulps: f64,
}

/// The exact contact of two balls, and its time from the gap function a·t² + 2b·t + c with
/// D = b² − a·c: t = (−b − √D)/a when `At` and a ≠ 0 (for either sign of a: with a < 0 that
/// is the single positive root), t = −c/(2b) when a = 0 (growing balls only).
pub struct ExactContact {
    pub class: Contact,
    b: Dy,
    disc: Dy,
    a: Dy,
    c: Dy,
}

pub fn exact_contact<const D: usize>(p: &Ball<D>, q: &Ball<D>) -> ExactContact {
    let mut a = Dy::zero();
    let mut b = Dy::zero();
    let mut c = Dy::zero();
    for i in 0..D {
        let dr = Dy::from_f64(q.position[i]).sub(&Dy::from_f64(p.position[i]));
        let dv = Dy::from_f64(q.velocity[i]).sub(&Dy::from_f64(p.velocity[i]));
        a = a.add(&dv.mul(&dv));
        b = b.add(&dr.mul(&dv));
        c = c.add(&dr.mul(&dr));
    }
    let sigma = Dy::from_f64(p.radius).add(&Dy::from_f64(q.radius));
    c = c.sub(&sigma.mul(&sigma));
    let disc = b.mul(&b).sub(&a.mul(&c));
    let class = if a.is_zero() {
        Contact::Never(Miss::NoRelativeMotion)
    } else if b.sign() >= 0 {
        Contact::Never(Miss::Receding)
    } else if c.sign() <= 0 {
        Contact::Now
    } else if disc.sign() <= 0 {
        Contact::Never(Miss::PathsMiss)
    } else {
        Contact::At(f64::NAN)
    };
    ExactContact { class, b, disc, a, c }
}

/// The exact contact of two balls whose radii grow at `rates` (≥ 0): the semantics table of
/// `quadratic::growing`, evaluated on big integers. A = |Δv|² − G², b = ⟨Δr|Δv⟩ − σG,
/// C = |Δr|² − σ², D = b² − A·C, all exact.
pub fn exact_contact_growing<const D: usize>(p: &Ball<D>, q: &Ball<D>, rates: [f64; 2]) -> ExactContact {
    let mut dvsq = Dy::zero();
    let mut b = Dy::zero();
    let mut c = Dy::zero();
    for i in 0..D {
        let dr = Dy::from_f64(q.position[i]).sub(&Dy::from_f64(p.position[i]));
        let dv = Dy::from_f64(q.velocity[i]).sub(&Dy::from_f64(p.velocity[i]));
        dvsq = dvsq.add(&dv.mul(&dv));
        b = b.add(&dr.mul(&dv));
        c = c.add(&dr.mul(&dr));
    }
    let sigma = Dy::from_f64(p.radius).add(&Dy::from_f64(q.radius));
    let grow = Dy::from_f64(rates[0]).add(&Dy::from_f64(rates[1]));
    c = c.sub(&sigma.mul(&sigma));
    b = b.sub(&sigma.mul(&grow));
    let a = dvsq.sub(&grow.mul(&grow));
    let disc = b.mul(&b).sub(&a.mul(&c));
    let at = Contact::At(f64::NAN);
    let class = if dvsq.is_zero() && grow.is_zero() {
        Contact::Never(Miss::NoRelativeMotion)
    } else if c.sign() <= 0 {
        if b.sign() < 0 { Contact::Now } else { Contact::Never(Miss::Receding) }
    } else {
        match a.sign() {
            -1 => at,
            0 => {
                if b.sign() < 0 {
                    at
                } else {
                    Contact::Never(Miss::Receding)
                }
            }
            _ => {
                if b.sign() >= 0 {
                    Contact::Never(Miss::Receding)
                } else if disc.sign() <= 0 {
                    Contact::Never(Miss::PathsMiss)
                } else {
                    at
                }
            }
        }
    };
    ExactContact { class, b, disc, a, c }
}

/// Three-way class: 0 never, 1 now, 2 at.
pub fn class3(c: &Contact) -> u8 {
    match c {
        Contact::Never(_) => 0,
        Contact::Now => 1,
        Contact::At(_) => 2,
    }
}

impl ExactContact {
    /// ulps between `t` and the exact contact time (only for `At`).
    pub fn ulps(&self, t: f64) -> f64 {
        if t.is_nan() {
            return f64::INFINITY;
        }
        if t.is_infinite() {
            let est = if self.a.is_zero() {
                self.c.ratio(&self.b.neg()) / 2.0
            } else {
                let root = self.disc.sqrt_within(self.disc.log2() / 2 - 80);
                self.b.neg().sub(&root).ratio(&self.a)
            };
            return if est >= f64::MAX / 2.0 { 0.0 } else { f64::INFINITY };
        }
        if self.a.is_zero() {
            // 2b·t + c = 0: |2b·t + c| / |2b·gap|.
            let two_b = Dy::from_f64(2.0).mul(&self.b);
            return Dy::from_f64(t).mul(&two_b).add(&self.c).ratio(&two_b.mul(&gap(t)).abs()).abs();
        }
        ulps_from_root(t, &self.b.neg(), -1, &self.disc, &self.a)
    }
    /// Whether the exact contact time is later than `h` (only for `At`): with
    /// t = (−b − √D)/a and a > 0, t > h ⇔ −b − a·h > √D ⇔ (−b − a·h > 0 and (−b − a·h)² > D).
    pub fn exceeds(&self, h: f64) -> bool {
        if h.is_infinite() || h.is_nan() {
            return h == f64::NEG_INFINITY;
        }
        let x = self.b.neg().sub(&self.a.mul(&Dy::from_f64(h)));
        x.sign() > 0 && x.mul(&x).sub(&self.disc).sign() > 0
    }
    /// The exact contact time, correctly rounded (for the edge-case table).
    pub fn time_rounded(&self) -> f64 {
        if self.a.is_zero() {
            return divide(&self.c, &Dy::from_f64(-2.0).mul(&self.b), 200).to_f64();
        }
        let root = self.disc.sqrt_within(self.disc.log2() / 2 - 200);
        if self.b.sign() <= 0 {
            // t = c/(−b + √D), both terms non-negative: no cancellation when a ≈ 0.
            return divide(&self.c, &self.b.neg().add(&root), 200).to_f64();
        }
        // t = (−b − √D)/a (a < 0 here), both terms of the numerator negative.
        let num = self.b.neg().sub(&root);
        divide(&num, &self.a, 200).to_f64()
    }
}

/// n/d to about `extra` bits beyond 64 (truncated).
pub fn divide(n: &Dy, d: &Dy, extra: i64) -> Dy {
    let shift = (d.m.bits() as i64 + 64 + extra - n.m.bits() as i64).max(0);
    let q = ((&n.m) << (shift as usize)) / &d.m;
    Dy { m: q, e: n.e - shift - d.e }
}

/// The exact real roots of a·x² + b·x + c, each correctly rounded (for the edge-case table).
pub fn roots_rounded(a: f64, b: f64, c: f64) -> Option<Vec<f64>> {
    let (da, db, dc) = (Dy::from_f64(a), Dy::from_f64(b), Dy::from_f64(c));
    if da.is_zero() {
        if db.is_zero() {
            return if dc.is_zero() { None } else { Some(vec![]) };
        }
        return Some(vec![divide(&dc.neg(), &db, 200).to_f64()]);
    }
    let disc = db.mul(&db).sub(&Dy::from_f64(4.0).mul(&da).mul(&dc));
    let q = Dy::from_f64(2.0).mul(&da);
    match disc.sign() {
        -1 => Some(vec![]),
        0 => Some(vec![divide(&db.neg(), &q, 200).to_f64()]),
        _ => {
            // Cancellation-free: x₁ = (−b − sign(b)√Δ)/2a, x₂ = c/(a·x₁) = 2c/(−b − sign(b)√Δ).
            let root = disc.sqrt_within(disc.log2() / 2 - 300);
            let big = if db.sign() >= 0 { db.neg().sub(&root) } else { db.neg().add(&root) };
            let x1 = divide(&big, &q, 200).to_f64();
            let x2 = divide(&Dy::from_f64(2.0).mul(&dc), &big, 200).to_f64();
            Some(if x1 <= x2 { vec![x1, x2] } else { vec![x2, x1] })
        }
    }
}
