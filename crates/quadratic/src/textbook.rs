//! The seed's textbook formulas, verbatim in f64 — **for comparison only**.
//!
//! These exist so that tests, benchmarks and the edge-case table can show what the
//! robust functions fix. Do not use them to simulate anything.

use crate::{Ball, Contact, Miss, Roots};

/// `x = (−b ± √(b² − 4ac)) / 2a` in plain f64, with only the guards a careful textbook
/// implementation has: `a = 0` falls back to the linear root, `b² − 4ac < 0` (or NaN)
/// means no root, `= 0` one root. It cancels, overflows and misjudges the discriminant.
pub fn solve(a: f64, b: f64, c: f64) -> Roots {
    if a == 0.0 {
        if b == 0.0 {
            return if c == 0.0 { Roots::All } else { Roots::None };
        }
        return Roots::One(-c / b);
    }
    let disc = b * b - 4.0 * a * c;
    if disc.is_nan() || disc < 0.0 {
        return Roots::None;
    }
    if disc == 0.0 {
        return Roots::One(-b / (2.0 * a));
    }
    let r = disc.sqrt();
    let x1 = (-b - r) / (2.0 * a);
    let x2 = (-b + r) / (2.0 * a);
    if x1 <= x2 { Roots::Two(x1, x2) } else { Roots::Two(x2, x1) }
}

/// The seed's contact time (eq. 5–7) in plain f64: `a = |Δv|²`, `b = 2⟨Δv|Δr⟩`,
/// `c = |Δr|² − σ²`, `t = (−b − √(b² − 4ac)) / 2a`, with the usual guards: no root or
/// `b ≥ 0` → never; `t ≤ 0` (already overlapping) → now.
pub fn contact_time<const D: usize>(first: &Ball<D>, second: &Ball<D>) -> Contact {
    let mut a = 0.0;
    let mut b = 0.0;
    let mut c = 0.0;
    for i in 0..D {
        let dr = second.position[i] - first.position[i];
        let dv = second.velocity[i] - first.velocity[i];
        a += dv * dv;
        b += 2.0 * dv * dr;
        c += dr * dr;
    }
    let sigma = first.radius + second.radius;
    c -= sigma * sigma;
    if a == 0.0 {
        return Contact::Never(Miss::NoRelativeMotion);
    }
    if b >= 0.0 {
        return Contact::Never(Miss::Receding);
    }
    let disc = b * b - 4.0 * a * c;
    if disc.is_nan() || disc <= 0.0 {
        return Contact::Never(Miss::PathsMiss);
    }
    let t = (-b - disc.sqrt()) / (2.0 * a);
    if t.is_nan() {
        Contact::Never(Miss::PathsMiss)
    } else if t <= 0.0 {
        Contact::Now
    } else {
        Contact::At(t)
    }
}

/// The growing-contact time as a careful textbook code writes it, in plain f64:
/// `A = |Δv|² − G²`, `B = 2(⟨Δv|Δr⟩ − σG)`, `C = |Δr|² − σ²`; `C ≤ 0` → now if `B < 0`,
/// else never; `A = 0` → the linear root `−C/B` when `B < 0`; otherwise
/// `t = (−B − √(B² − 4AC)) / 2A` for `A > 0` (never if `B ≥ 0` or the discriminant is not
/// positive) and `t = (−B − √(B² − 4AC)) / 2A` for `A < 0` too (the positive root).
pub fn contact_time_growing<const D: usize>(first: &Ball<D>, second: &Ball<D>, rates: [f64; 2]) -> Contact {
    let (mut a, mut b, mut c) = (0.0, 0.0, 0.0);
    for i in 0..D {
        let dr = second.position[i] - first.position[i];
        let dv = second.velocity[i] - first.velocity[i];
        a += dv * dv;
        b += 2.0 * dv * dr;
        c += dr * dr;
    }
    let sigma = first.radius + second.radius;
    let grow = rates[0] + rates[1];
    a -= grow * grow;
    b -= 2.0 * sigma * grow;
    c -= sigma * sigma;
    if c <= 0.0 {
        return if b < 0.0 { Contact::Now } else { Contact::Never(Miss::Receding) };
    }
    if a == 0.0 {
        return if b < 0.0 { Contact::At(-c / b) } else { Contact::Never(Miss::Receding) };
    }
    if a > 0.0 && b >= 0.0 {
        return Contact::Never(Miss::Receding);
    }
    let disc = b * b - 4.0 * a * c;
    if disc.is_nan() || disc <= 0.0 {
        return Contact::Never(Miss::PathsMiss);
    }
    let t = (-b - disc.sqrt()) / (2.0 * a);
    if t.is_nan() { Contact::Never(Miss::PathsMiss) } else { Contact::At(t) }
}
