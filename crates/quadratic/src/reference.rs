//! The edge-case reference: hard inputs, each with its exact answer.
//!
//! Every `exact` field below is the exact answer for the exact f64 inputs — root count or
//! contact class exactly, values correctly rounded — computed by the big-integer oracle in
//! `tests/reference.rs`, which fails if any stored answer is wrong and keeps the table in
//! the crate's `README.md` in sync with this file. [`check_all`] recomputes everything with
//! this crate and with [`crate::textbook`], so the reference can be re-verified on any
//! machine (`collide check`).

use crate::exact::pow2;
use crate::{Ball, Contact, Miss, Roots, contact_time, contact_time_growing, solve, textbook};
use std::fmt::Write;

/// A quadratic `a·x² + b·x + c = 0` with its exact roots.
#[derive(Clone, Copy, Debug)]
pub struct RootCase {
    /// What the case exercises.
    pub name: &'static str,
    /// The coefficients.
    pub a: f64,
    /// See `a`.
    pub b: f64,
    /// See `a`.
    pub c: f64,
    /// The exact roots, correctly rounded.
    pub exact: Roots,
}

/// Two disks with their exact contact.
#[derive(Clone, Copy, Debug)]
pub struct ContactCase {
    /// What the case exercises.
    pub name: &'static str,
    /// Disk 1.
    pub first: Ball<2>,
    /// Disk 2.
    pub second: Ball<2>,
    /// The exact contact (class and reason exact, time correctly rounded).
    pub exact: Contact,
}

/// Two disks whose radii grow at `rates` (`R + g·t`), with their exact contact.
#[derive(Clone, Copy, Debug)]
pub struct GrowingCase {
    /// What the case exercises.
    pub name: &'static str,
    /// Disk 1.
    pub first: Ball<2>,
    /// Disk 2.
    pub second: Ball<2>,
    /// The growth rates `[g₁, g₂]`.
    pub rates: [f64; 2],
    /// The exact contact (class and reason exact, time correctly rounded).
    pub exact: Contact,
}

const fn disk(x: f64, y: f64, vx: f64, vy: f64, radius: f64) -> Ball<2> {
    Ball { position: [x, y], velocity: [vx, vy], radius }
}

const fn bits(b: u64) -> f64 {
    f64::from_bits(b)
}

/// 1 + k·2⁻⁵² (k ulps above 1).
const fn one_plus_ulps(k: u64) -> f64 {
    f64::from_bits(0x3ff0000000000000 + k)
}

/// 1 − k·2⁻⁵³ (k ulps below 1).
const fn one_minus_ulps(k: u64) -> f64 {
    f64::from_bits(0x3ff0000000000000 - k)
}

/// The quadratic cases.
pub const ROOT_CASES: &[RootCase] = &[
    RootCase {
        name: "cancellation: x² − 10⁸x + 1",
        a: 1.0,
        b: -1e8,
        c: 1.0,
        exact: Roots::Two(bits(0x3e45798ee2308c3a), bits(0x4197d783ffffffff)),
    },
    RootCase {
        name: "total cancellation: x² + 10⁹x + 1",
        a: 1.0,
        b: 1e9,
        c: 1.0,
        exact: Roots::Two(bits(0xc1cdcd6500000000), bits(0xbe112e0be826d695)),
    },
    RootCase {
        name: "near-double root (Kahan 2004)",
        a: 94906265.625,
        b: -189812534.0,
        c: 94906268.375,
        exact: Roots::Two(bits(0x3ff0000000000000), bits(0x3ff0000007c73673)),
    },
    RootCase {
        name: "Fibonacci F₇₄x² − 2F₇₃x + F₇₂ (Δ = 4)",
        a: 1304969544928657.0,
        b: -1613031066098786.0,
        c: 498454011879264.0,
        exact: Roots::Two(bits(0x3fe3c6ef372fe949), bits(0x3fe3c6ef372fe956)),
    },
    RootCase {
        name: "Fibonacci F₇₃x² − 2F₇₂x + F₇₁ (Δ = −4)",
        a: 806515533049393.0,
        b: -996908023758528.0,
        c: 308061521170129.0,
        exact: Roots::None,
    },
    RootCase {
        name: "exact double root (67108859x − 67108837)²",
        a: 4503598956281881.0,
        b: -9007194959773966.0,
        c: 4503596003492569.0,
        exact: Roots::One(bits(0x3fefffff4fffff24)),
    },
    RootCase {
        name: "b² overflows: 2¹⁰⁰⁰(x − 1)(x − 2)",
        a: pow2(1000),
        b: -3.0 * pow2(1000),
        c: pow2(1001),
        exact: Roots::Two(1.0, 2.0),
    },
    RootCase {
        name: "4ac overflows: 10³⁰⁰x² + x − 10³⁰⁰",
        a: 1e300,
        b: 1.0,
        c: -1e300,
        exact: Roots::Two(bits(0xbff0000000000000), bits(0x3ff0000000000000)),
    },
    RootCase {
        name: "4ac underflows: 10⁻²⁰⁰x² + x + 10⁻²⁰⁰",
        a: 1e-200,
        b: 1.0,
        c: 1e-200,
        exact: Roots::Two(bits(0xe974e718d7d7625a), bits(0x96687e92154ef7ac)),
    },
    RootCase {
        name: "subnormal coefficients: 2⁻¹⁰⁷⁴x² − 2⁻¹⁰⁷⁴",
        a: bits(1),
        b: 0.0,
        c: -bits(1),
        exact: Roots::Two(-1.0, 1.0),
    },
    RootCase {
        name: "subnormal roots: x² − 2⁻¹⁰⁶⁰x",
        a: 1.0,
        b: -bits(1 << 14),
        c: 0.0,
        exact: Roots::Two(0.0, bits(1 << 14)),
    },
    RootCase { name: "linear: 0x² + 3x − 1", a: 0.0, b: 3.0, c: -1.0, exact: Roots::One(bits(0x3fd5555555555555)) },
    RootCase { name: "every x: 0 = 0 (with −0.0)", a: -0.0, b: 0.0, c: -0.0, exact: Roots::All },
    RootCase { name: "no x: 0x² + 0x + 1", a: 0.0, b: -0.0, c: 1.0, exact: Roots::None },
    RootCase { name: "c = 0: x² − 5x", a: 1.0, b: -5.0, c: 0.0, exact: Roots::Two(0.0, 5.0) },
    RootCase { name: "b = c = 0: 7x² (double root 0)", a: 7.0, b: 0.0, c: -0.0, exact: Roots::One(0.0) },
];

/// The contact-time cases (unit-diameter disks unless stated).
pub const CONTACT_CASES: &[ContactCase] = &[
    ContactCase {
        name: "head on, t = 1",
        first: disk(0.0, 0.0, 1.0, 0.0, 0.5),
        second: disk(3.0, 0.0, -1.0, 0.0, 0.5),
        exact: Contact::At(1.0),
    },
    ContactCase {
        name: "gap of 1 ulp, oblique approach",
        first: disk(0.0, 0.0, 0.0, 0.0, 0.5),
        second: disk(one_plus_ulps(1), 0.0, -0.6, 0.8, 0.5),
        exact: Contact::At(bits(0x3cbaaaaaaaaaaaac)),
    },
    ContactCase {
        name: "r₂ − r₁ rounds to σ: x = −0.1 and 0.9, true gap 2.8·10⁻¹⁷",
        first: disk(-0.1, 0.0, 0.0, 0.0, 0.5),
        second: disk(0.9, 0.0, -1.0, 0.0, 0.5),
        exact: Contact::At(bits(0x3c80000000000000)),
    },
    ContactCase {
        name: "overlap of 1 ulp, approaching",
        first: disk(0.0, 0.0, 0.0, 0.0, 0.5),
        second: disk(one_minus_ulps(1), 0.0, -1.0, 0.0, 0.5),
        exact: Contact::Now,
    },
    ContactCase {
        name: "overlap of 1 ulp, separating",
        first: disk(0.0, 0.0, 0.0, 0.0, 0.5),
        second: disk(one_minus_ulps(1), 0.0, 1.0, 0.0, 0.5),
        exact: Contact::Never(Miss::Receding),
    },
    ContactCase {
        name: "overlapping, exactly tangential motion",
        first: disk(0.0, 0.0, 0.0, 0.0, 0.5),
        second: disk(0.6, 0.8, -0.8, 0.6, 0.5),
        exact: Contact::Never(Miss::Receding),
    },
    ContactCase {
        name: "graze at 10¹² σ, impact parameter σ(1 + 2⁻⁵²): miss",
        first: disk(0.0, 0.0, 0.0, 0.0, 0.5),
        second: disk(1e12, one_plus_ulps(1), -1.0, 0.0, 0.5),
        exact: Contact::Never(Miss::PathsMiss),
    },
    ContactCase {
        name: "graze at 10¹² σ, impact parameter σ(1 − 2⁻⁵³): hit",
        first: disk(0.0, 0.0, 0.0, 0.0, 0.5),
        second: disk(1e12, one_minus_ulps(1), -1.0, 0.0, 0.5),
        exact: Contact::At(bits(0x426d1a94a2000000)),
    },
    ContactCase {
        name: "exact graze, impact parameter = σ: miss",
        first: disk(0.0, 0.0, 0.0, 0.0, 0.5),
        second: disk(1e6, 1.0, -1.0, 0.0, 0.5),
        exact: Contact::Never(Miss::PathsMiss),
    },
    ContactCase {
        name: "zero relative velocity",
        first: disk(0.0, 0.0, 0.1, 0.2, 0.5),
        second: disk(2.0, 0.0, 0.1, 0.2, 0.5),
        exact: Contact::Never(Miss::NoRelativeMotion),
    },
    ContactCase {
        name: "relative velocity of 1 ulp",
        first: disk(0.0, 0.0, 0.1, 0.0, 0.5),
        second: disk(2.0, 0.0, bits(0x3fb9999999999999), 0.0, 0.5),
        exact: Contact::At(bits(0x4370000000000000)),
    },
    ContactCase {
        name: "large coordinates: neighbours at x ≈ 10⁹",
        first: disk(1e9, 0.3, 0.25, 0.0, 0.5),
        second: disk(1000000001.7, 0.3, -0.25, 0.0, 0.5),
        exact: Contact::At(bits(0x3ff6666680000000)),
    },
    ContactCase {
        name: "tiny radii 2⁻⁶⁰⁰, head on (σ² underflows)",
        first: disk(0.0, 0.0, 0.0, 0.0, pow2(-600)),
        second: disk(1.0, 1.0, -1.0, -1.0, pow2(-600)),
        exact: Contact::At(1.0),
    },
    ContactCase {
        name: "lengths ×2⁵²⁰, velocities ×2⁻⁴⁸⁰ (Δr² overflows)",
        first: disk(0.0, 0.0, pow2(-480), 0.0, 0.5 * pow2(520)),
        second: disk(3.0 * pow2(520), 0.0, -pow2(-480), 0.0, 0.5 * pow2(520)),
        exact: Contact::At(pow2(1000)),
    },
    ContactCase {
        name: "far and fast: 10¹² apart at 10¹², offset 0.9σ",
        first: disk(0.0, 0.0, 0.0, 0.0, 0.5),
        second: disk(1e12, 0.9, -1e12, 0.0, 0.5),
        exact: Contact::At(bits(0x3feffffffffff0aa)),
    },
];

/// The growing-contact cases ([`crate::contact_time_growing`]).
pub const GROWING_CASES: &[GrowingCase] = &[
    GrowingCase {
        name: "at rest 3 apart, σ(t) = 1 + t: growth alone",
        first: disk(0.0, 0.0, 0.0, 0.0, 0.5),
        second: disk(3.0, 0.0, 0.0, 0.0, 0.5),
        rates: [0.5, 0.5],
        exact: Contact::At(2.0),
    },
    GrowingCase {
        name: "receding at ½ while σ grows at 1 (A < 0, b > 0)",
        first: disk(0.0, 0.0, 0.0, 0.0, 0.5),
        second: disk(3.0, 0.0, 0.5, 0.0, 0.5),
        rates: [0.5, 0.5],
        exact: Contact::At(4.0),
    },
    GrowingCase {
        name: "relative speed = G = 5 exactly (A = 0): the linear root 2/7",
        first: disk(0.0, 0.0, 0.0, 0.0, 0.5),
        second: disk(3.0, 0.0, -3.0, 4.0, 0.5),
        rates: [2.5, 2.5],
        exact: Contact::At(bits(0x3fd2492492492492)),
    },
    GrowingCase {
        name: "receding, G one ulp above the relative speed 5 (A < 0): far future contact",
        first: disk(0.0, 0.0, 0.0, 0.0, 0.5),
        second: disk(3.0, 0.0, 3.0, 4.0, 0.5),
        rates: [2.5, bits(0x4004000000000001)],
        exact: Contact::At(bits(0x431999999999999c)),
    },
    GrowingCase {
        name: "receding, G one ulp below the relative speed 5 (A > 0): never",
        first: disk(0.0, 0.0, 0.0, 0.0, 0.5),
        second: disk(3.0, 0.0, 3.0, 4.0, 0.5),
        rates: [2.5, bits(0x4003ffffffffffff)],
        exact: Contact::Never(Miss::Receding),
    },
    GrowingCase {
        name: "jammed: gap 10⁻¹⁴σ at rest, growing at 10⁻³",
        first: disk(0.0, 0.0, 0.0, 0.0, 0.5),
        second: disk(1.00000000000001, 0.0, 0.0, 0.0, 0.5),
        rates: [5e-4, 5e-4],
        exact: Contact::At(bits(0x3da5f90000000000)),
    },
    GrowingCase {
        name: "jammed: gap 2⁻⁵² σ, sliding sideways, growing at 10⁻⁶",
        first: disk(0.0, 0.0, 0.0, 0.0, 0.5),
        second: disk(one_plus_ulps(1), 0.0, 0.0, 1e-3, 0.5),
        rates: [5e-7, 5e-7],
        exact: Contact::At(bits(0x3dee8480000e8d4b)),
    },
    GrowingCase {
        name: "overlap of 1 ulp, at rest, growing: now",
        first: disk(0.0, 0.0, 0.0, 0.0, 0.5),
        second: disk(one_minus_ulps(1), 0.0, 0.0, 0.0, 0.5),
        rates: [1e-3, 0.0],
        exact: Contact::Now,
    },
    GrowingCase {
        name: "touching, fleeing faster than growth: never",
        first: disk(0.0, 0.0, 0.0, 0.0, 0.5),
        second: disk(1.0, 0.0, 1.0, 0.0, 0.5),
        rates: [0.25, 0.25],
        exact: Contact::Never(Miss::Receding),
    },
    GrowingCase {
        name: "lengths ×2⁵⁰⁰, velocities and rates ×2⁻⁵⁰⁰, at rest",
        first: disk(0.0, 0.0, 0.0, 0.0, pow2(499)),
        second: disk(3.0 * pow2(500), 0.0, 0.0, 0.0, pow2(499)),
        rates: [pow2(-501), pow2(-501)],
        exact: Contact::At(pow2(1001)),
    },
];

/// `x` and `y` are equal or adjacent f64 of the same sign (zeros of either sign equal).
fn within_one_ulp(x: f64, y: f64) -> bool {
    if x == y {
        return true;
    }
    if x.is_sign_negative() != y.is_sign_negative() || !x.is_finite() || !y.is_finite() {
        return false;
    }
    x.to_bits().abs_diff(y.to_bits()) <= 1
}

/// `got` has the exact root count of `exact` and each root is within one ulp of it.
pub fn roots_agree(got: &Roots, exact: &Roots) -> bool {
    match (got, exact) {
        (Roots::None, Roots::None) | (Roots::All, Roots::All) => true,
        (Roots::One(x), Roots::One(y)) => within_one_ulp(*x, *y),
        (Roots::Two(x1, x2), Roots::Two(y1, y2)) => within_one_ulp(*x1, *y1) && within_one_ulp(*x2, *y2),
        _ => false,
    }
}

/// `got` has the exact class (and reason) of `exact`, and a time within one ulp.
pub fn contacts_agree(got: &Contact, exact: &Contact) -> bool {
    match (got, exact) {
        (Contact::At(x), Contact::At(y)) => within_one_ulp(*x, *y),
        _ => got == exact,
    }
}

/// A root list in hex floats: `none`, `all`, `{x}`, `{x₁, x₂}`.
pub fn describe_roots(r: &Roots) -> String {
    use crate::hex::format as h;
    match r {
        Roots::None => "none".into(),
        Roots::All => "all x".into(),
        Roots::One(x) => format!("{{{}}}", h(*x)),
        Roots::Two(x, y) => format!("{{{}, {}}}", h(*x), h(*y)),
    }
}

/// A contact in words and hex floats.
pub fn describe_contact(c: &Contact) -> String {
    match c {
        Contact::Never(Miss::NoRelativeMotion) => "never (no relative motion)".into(),
        Contact::Never(Miss::Receding) => "never (receding)".into(),
        Contact::Never(Miss::PathsMiss) => "never (paths miss)".into(),
        Contact::Now => "now (t = 0)".into(),
        Contact::At(t) => format!("t = {}", crate::hex::format(*t)),
    }
}

/// What [`check_all`] found.
#[derive(Clone, Debug)]
pub struct Report {
    /// A plain-text table: case, textbook answer, this crate's answer, exact answer.
    pub text: String,
    /// Number of cases.
    pub cases: usize,
    /// Cases where this crate disagrees with the stored exact answer.
    pub failures: usize,
}

/// One case of the plain-text report: verdict, name, then the three answers.
fn entry(text: &mut String, ok: &str, name: &str, naive: (String, bool), got: String, exact: String) {
    let mark = if naive.1 { "" } else { "  ✗" };
    writeln!(text, "  [{ok}] {name}").unwrap();
    writeln!(text, "      textbook: {}{mark}", naive.0).unwrap();
    writeln!(text, "      collide:  {got}").unwrap();
    writeln!(text, "      exact:    {exact}").unwrap();
}

/// Recomputes every reference case with this crate and with the textbook formula.
pub fn check_all() -> Report {
    let mut text = String::new();
    let mut failures = 0;
    let mut verdict = |ok: bool| {
        failures += usize::from(!ok);
        if ok { "ok" } else { "MISMATCH" }
    };
    writeln!(text, "Quadratic a·x² + b·x + c = 0").unwrap();
    for case in ROOT_CASES {
        let got = solve(case.a, case.b, case.c).expect("reference inputs are finite");
        let naive = textbook::solve(case.a, case.b, case.c);
        let ok = verdict(roots_agree(&got, &case.exact));
        let naive_ok = roots_agree(&naive, &case.exact);
        let [naive, got, exact] = [naive, got, case.exact].map(|r| describe_roots(&r));
        entry(&mut text, ok, case.name, (naive, naive_ok), got, exact);
    }
    writeln!(text, "Contact time of two disks").unwrap();
    for case in CONTACT_CASES {
        let got = contact_time(&case.first, &case.second).expect("reference inputs are valid");
        let naive = textbook::contact_time(&case.first, &case.second);
        let ok = verdict(contacts_agree(&got, &case.exact));
        let naive_ok = contacts_agree(&naive, &case.exact);
        let [naive, got, exact] = [naive, got, case.exact].map(|c| describe_contact(&c));
        entry(&mut text, ok, case.name, (naive, naive_ok), got, exact);
    }
    writeln!(text, "Contact time of two growing disks").unwrap();
    for case in GROWING_CASES {
        let got = contact_time_growing(&case.first, &case.second, case.rates).expect("reference inputs are valid");
        let naive = textbook::contact_time_growing(&case.first, &case.second, case.rates);
        let ok = verdict(contacts_agree(&got, &case.exact));
        let naive_ok = contacts_agree(&naive, &case.exact);
        let [naive, got, exact] = [naive, got, case.exact].map(|c| describe_contact(&c));
        entry(&mut text, ok, case.name, (naive, naive_ok), got, exact);
    }
    Report { text, cases: ROOT_CASES.len() + CONTACT_CASES.len() + GROWING_CASES.len(), failures }
}
