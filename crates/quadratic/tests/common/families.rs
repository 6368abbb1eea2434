//! Adversarial input families, as proptest strategies. Each family targets one way the
//! textbook formula fails; together they are the test bed of the accuracy contract.

#![allow(dead_code)]

use proptest::prelude::*;
use quadratic::Ball;
use quadratic::exact::scale2;

/// A mantissa in [1, 2) with random low bits.
pub fn mant() -> impl Strategy<Value = f64> {
    (0u64..(1u64 << 52)).prop_map(|f| f64::from_bits((1023u64 << 52) | f))
}

/// ±m·2^e with m ∈ [1, 2), e ∈ [lo, hi].
pub fn float_exp(lo: i32, hi: i32) -> impl Strategy<Value = f64> {
    (mant(), lo..=hi, any::<bool>()).prop_map(|(m, e, neg)| {
        let x = scale2(m, e);
        if neg { -x } else { x }
    })
}

/// Any finite f64: uniform bit patterns (so uniform exponents), subnormals, and zeros.
pub fn any_finite() -> impl Strategy<Value = f64> {
    prop_oneof![
        6 => any::<u64>().prop_map(f64::from_bits).prop_filter("finite", |x| x.is_finite()),
        2 => (1u64..(1u64 << 52), any::<bool>()).prop_map(|(b, n)| {
            let x = f64::from_bits(b);
            if n { -x } else { x }
        }),
        1 => Just(0.0),
        1 => Just(-0.0),
    ]
}

/// `x` moved by `k` ulps (through its bit pattern; stays on the same side of zero).
pub fn nudge(x: f64, k: i64) -> f64 {
    let bits = x.to_bits() as i64 + k;
    f64::from_bits(bits.max(0) as u64)
}

pub type Coeffs = (f64, f64, f64);

/// Quadratic families: (name, strategy).
pub fn quadratic_families() -> Vec<(&'static str, BoxedStrategy<Coeffs>)> {
    vec![
        (
            // b² ≫ |4ac|: the textbook small root cancels to garbage or to 0.
            "cancellation b²≫|4ac|",
            (float_exp(-40, 40), float_exp(30, 700), float_exp(-40, 40)).boxed(),
        ),
        (
            // c = b²/4a nudged by a few ulps: the sign of b² − 4ac lives in the last bits.
            "near-double root",
            (float_exp(-60, 60), float_exp(-60, 60), -6i64..=6)
                .prop_map(|(a, b, k)| {
                    let c = b * b / (4.0 * a);
                    (a, b, if c.is_finite() && c != 0.0 { nudge(c, k) } else { 1.0 })
                })
                .boxed(),
        ),
        (
            // (m·x − n)² scaled: b² = 4ac exactly, with 52-bit products.
            "exact double root",
            (1u64..(1 << 26), 1u64..(1 << 26), any::<bool>(), -400i32..=400, -200i32..=200)
                .prop_map(|(m, n, neg, p, q)| {
                    let (m, n) = (m as f64, n as f64);
                    let b = if neg { 2.0 * m * n } else { -2.0 * m * n };
                    (scale2(m * m, p), scale2(b, p + q), scale2(n * n, p + 2 * q))
                })
                .boxed(),
        ),
        (
            // Kahan's Fibonacci cases: F(n+1)x² − 2F(n)x + F(n−1), Δ = ±4 (Cassini), scaled.
            "Kahan-Fibonacci",
            (10usize..=74, -300i32..=300, any::<bool>())
                .prop_map(|(n, p, flip)| {
                    let f = fibonacci(n + 1);
                    let (a, b, c) = (f[n + 1] as f64, -2.0 * f[n] as f64, f[n - 1] as f64);
                    let s = if flip { -1.0 } else { 1.0 };
                    (s * scale2(a, p), s * scale2(b, p), s * scale2(c, p))
                })
                .boxed(),
        ),
        (
            // Coefficients anywhere in the f64 range, subnormals and zeros included.
            "tiny/huge/subnormal",
            (any_finite(), any_finite(), any_finite()).boxed(),
        ),
        (
            // Every combination of 0, −0 and a random coefficient.
            "zero coefficients",
            (zero_or(), zero_or(), zero_or()).boxed(),
        ),
        ("random moderate", (float_exp(-60, 60), float_exp(-60, 60), float_exp(-60, 60)).boxed()),
    ]
}

fn zero_or() -> impl Strategy<Value = f64> {
    prop_oneof![Just(0.0), Just(-0.0), float_exp(-1074, 1023).prop_filter("finite", |x| x.is_finite())]
}

pub fn fibonacci(n: usize) -> Vec<u64> {
    let mut f = vec![0u64, 1];
    while f.len() <= n {
        let k = f.len();
        f.push(f[k - 1] + f[k - 2]);
    }
    f
}

pub type Pair2 = (Ball<2>, Ball<2>);
pub type Pair3 = (Ball<3>, Ball<3>);

fn unit(theta: f64) -> [f64; 2] {
    [theta.cos(), theta.sin()]
}

fn ball<const D: usize>(position: [f64; D], velocity: [f64; D], radius: f64) -> Ball<D> {
    Ball { position, velocity, radius }
}

/// Contact-time families in 2D.
pub fn contact_families() -> Vec<(&'static str, BoxedStrategy<Pair2>)> {
    let angle = || 0.0..std::f64::consts::TAU;
    let radius = || 0.25..1.0f64;
    vec![
        (
            // Centres σ(1 ± k·2⁻⁵²) apart: c ≈ 0, the textbook smaller root cancels.
            "near contact",
            (radius(), radius(), angle(), -8i64..=8, -10.0..10.0f64, angle(), 0.1..2.0f64)
                .prop_map(|(r1, r2, th, k, x0, phi, speed)| {
                    let d = (r1 + r2) * (1.0 + k as f64 * f64::EPSILON);
                    let u = unit(th);
                    let p = [x0, -x0];
                    let q = [p[0] + d * u[0], p[1] + d * u[1]];
                    let w = unit(phi);
                    (ball(p, [0.0, 0.0], r1), ball(q, [speed * w[0], speed * w[1]], r2))
                })
                .boxed(),
        ),
        (
            // Impact parameter σ(1 + k·2⁻⁵²) at 10⁰–10¹² diameters: hit or miss in the last bits.
            "grazing (axis-aligned)",
            (radius(), 0.0..12.0f64, -4i64..=4, -100.0..100.0f64, 0.5..2.0f64)
                .prop_map(|(r, lg, k, x0, speed)| {
                    let sigma = 2.0 * r;
                    let d = sigma * 10f64.powf(lg) + 3.0 * sigma;
                    let y = nudge(sigma, k);
                    let p = [x0, x0];
                    let q = [x0 + d, x0 + y];
                    (ball(p, [0.0, 0.0], r), ball(q, [-speed, 0.0], r))
                })
                .boxed(),
        ),
        (
            // The same, rotated by a random angle (rounded): grazing within ~ulp(d)/σ.
            "grazing (rotated, far)",
            (radius(), 0.0..12.0f64, -4i64..=4, angle(), 0.5..2.0f64)
                .prop_map(|(r, lg, k, th, speed)| {
                    let sigma = 2.0 * r;
                    let d = sigma * 10f64.powf(lg) + 3.0 * sigma;
                    let y = nudge(sigma, k);
                    let (c, s) = (th.cos(), th.sin());
                    let q = [c * d - s * y, s * d + c * y];
                    (ball([0.0, 0.0], [0.0, 0.0], r), ball(q, [-speed * c, -speed * s], r))
                })
                .boxed(),
        ),
        (
            // Δv = 0 exactly, or a few ulps of one component.
            "zero/tiny relative velocity",
            (radius(), angle(), 1.0..5.0f64, float_exp(-3, 3), float_exp(-3, 3), -3i64..=3, any::<bool>())
                .prop_map(|(r, th, dist, vx, vy, k, which)| {
                    let u = unit(th);
                    let v1 = [vx, vy];
                    let v2 = if which { [nudge(vx, k), vy] } else { [vx, nudge(vy, k)] };
                    (ball([0.0, 0.0], v1, r), ball([dist * u[0], dist * u[1]], v2, r))
                })
                .boxed(),
        ),
        (
            // Parallel motion along x at different speeds, lateral offset near σ.
            "parallel offset",
            (radius(), -4i64..=4, 1.0..1e6f64, 0.5..2.0f64, 0.5..2.0f64, any::<bool>())
                .prop_map(|(r, k, dx, s1, s2, graze)| {
                    let sigma = 2.0 * r;
                    let y = if graze { nudge(sigma, k) } else { sigma * (0.5 + k as f64 / 8.0) };
                    (ball([0.0, 0.0], [s1 + s2, 0.0], r), ball([dx + sigma, y], [s1, 0.0], r))
                })
                .boxed(),
        ),
        (
            // 10⁶–10¹² apart at 10⁶–10¹² speed, aimed within 1.5σ.
            "far and fast",
            (radius(), 6.0..12.0f64, 6.0..12.0f64, angle(), 0.0..1.5f64, angle())
                .prop_map(|(r, ld, lv, th, bfrac, phi)| {
                    let (d, v) = (10f64.powf(ld), 10f64.powf(lv));
                    let u = unit(th);
                    let n = [-u[1], u[0]];
                    let b = bfrac * 2.0 * r;
                    let q = [d * u[0] + b * n[0], d * u[1] + b * n[1]];
                    let w = unit(phi);
                    let v1 = [v * w[0] * 1e-3, v * w[1] * 1e-3];
                    (ball([0.0, 0.0], v1, r), ball(q, [v1[0] - v * u[0], v1[1] - v * u[1]], r))
                })
                .boxed(),
        ),
        (
            // Overlap of 0–8 ulps; approaching, separating, or exactly tangential.
            "overlap by ulps",
            (radius(), radius(), 0i64..=8, -50.0..50.0f64, -50.0..50.0f64, 0u8..3, 0.1..2.0f64)
                .prop_map(|(r1, r2, k, x, y, mode, s)| {
                    let sigma = r1 + r2;
                    let len = (x * x + y * y).sqrt().max(1e-3);
                    let f = sigma * (1.0 - k as f64 * f64::EPSILON) / len;
                    let d = [x * f, y * f];
                    let v = match mode {
                        0 => [-d[0] * s, -d[1] * s], // approaching
                        1 => [d[0] * s, d[1] * s],   // separating
                        _ => [-d[1] * s, d[0] * s],  // tangential: ⟨v|d⟩ = 0 exactly
                    };
                    (ball([0.0, 0.0], [0.0, 0.0], r1), ball(d, v, r2))
                })
                .boxed(),
        ),
        (
            // |r| ~ 10⁶–10⁹ with R ~ 1: the neighbours' separation loses bits in r₂ − r₁.
            "large coordinates",
            (6.0..9.0f64, angle(), 1.0..3.0f64, angle(), angle(), 0.4..0.6f64)
                .prop_map(|(lr, th, dist, phi1, phi2, r)| {
                    let base = 10f64.powf(lr);
                    let p = [base * th.cos(), base * th.sin()];
                    let u = unit(phi1);
                    let q = [p[0] + dist * u[0], p[1] + dist * u[1]];
                    let w = unit(phi2);
                    (ball(p, [0.0, 0.0], r), ball(q, [w[0] - u[0], w[1] - u[1]], r))
                })
                .boxed(),
        ),
        (
            // Radii 2⁻¹⁰⁰⁰…2⁻¹⁰⁰ on a near head-on course: σ² underflows in f64.
            "tiny radii",
            (float_exp(-1000, -100), angle(), 1.0..4.0f64, -3i64..=3)
                .prop_map(|(r, th, dist, k)| {
                    let r = r.abs();
                    let u = unit(th);
                    let q = [dist * u[0], dist * u[1]];
                    let v = [nudge(-u[0], k), -u[1]];
                    (ball([0.0, 0.0], [0.0, 0.0], r), ball(q, v, r))
                })
                .boxed(),
        ),
        (
            // A dense-fluid pair with lengths scaled by 2^p and velocities by 2^q, |p|,|q| ≤ 500.
            "scaled 2^±500",
            (dense_pair(), -500i32..=500, -500i32..=500)
                .prop_map(|((p, q), lp, lv)| {
                    let s = |b: Ball<2>| Ball {
                        position: b.position.map(|x| scale2(x, lp)),
                        velocity: b.velocity.map(|x| scale2(x, lv)),
                        radius: scale2(b.radius, lp),
                    };
                    (s(p), s(q))
                })
                .boxed(),
        ),
        ("dense-fluid pairs", dense_pair().boxed()),
    ]
}

/// A pair as it occurs in a dense fluid: positions in a 100σ box, separation 1–2.5σ,
/// velocity components in [−2, 2] (the benchmark's "realistic" inputs).
pub fn dense_pair() -> impl Strategy<Value = Pair2> {
    (0.0..100.0f64, 0.0..100.0f64, 1.0..2.5f64, 0.0..std::f64::consts::TAU, proptest::array::uniform4(-2.0..2.0f64))
        .prop_map(|(x, y, dist, th, v)| {
            let p = [x, y];
            let q = [x + dist * th.cos(), y + dist * th.sin()];
            (ball(p, [v[0], v[1]], 0.5), ball(q, [v[2], v[3]], 0.5))
        })
}

/// Contact-time families in 3D (the kernel is generic over the dimension).
pub fn contact_families_3d() -> Vec<(&'static str, BoxedStrategy<Pair3>)> {
    vec![
        (
            "3D grazing (far)",
            (0.25..1.0f64, 0.0..9.0f64, -4i64..=4, 0.5..2.0f64, -10.0..10.0f64)
                .prop_map(|(r, lg, k, speed, z)| {
                    let sigma = 2.0 * r;
                    let d = sigma * 10f64.powf(lg) + 3.0 * sigma;
                    let y = nudge(sigma, k);
                    (ball([0.0, 0.0, z], [0.0; 3], r), ball([d, y, z], [-speed, 0.0, 0.0], r))
                })
                .boxed(),
        ),
        (
            "3D near contact / random",
            (
                proptest::array::uniform3(-10.0..10.0f64),
                proptest::array::uniform3(-1.0..1.0f64),
                proptest::array::uniform3(-2.0..2.0f64),
                0.25..1.0f64,
                -8i64..=8,
            )
                .prop_map(|(p, dir, v, r, k)| {
                    let n = (dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]).sqrt().max(1e-3);
                    let d = 2.0 * r * (1.0 + k as f64 * f64::EPSILON) / n;
                    let q = [p[0] + dir[0] * d, p[1] + dir[1] * d, p[2] + dir[2] * d];
                    (ball(p, [0.0; 3], r), ball(q, v, r))
                })
                .boxed(),
        ),
    ]
}

/// Two balls and their growth rates `[g₁, g₂]`.
pub type Grow<const D: usize> = (Ball<D>, Ball<D>, [f64; 2]);

/// The first `D` components.
fn take<const D: usize>(v: [f64; 3]) -> [f64; D] {
    core::array::from_fn(|i| v[i])
}

/// A unit vector in `D` dimensions from three uniform numbers (the x axis if degenerate).
fn direction<const D: usize>(v: [f64; 3]) -> [f64; D] {
    let v: [f64; D] = take(v);
    let n = v.iter().map(|x| x * x).sum::<f64>().sqrt();
    if n < 1e-3 { core::array::from_fn(|i| if i == 0 { 1.0 } else { 0.0 }) } else { v.map(|x| x / n) }
}

/// Integer vectors with an integer length: Pythagorean triples (2D) and quadruples (3D).
fn pythagorean<const D: usize>(k: usize) -> ([f64; D], f64) {
    const TRIPLES: [([f64; 3], f64); 5] = [
        ([3.0, 4.0, 0.0], 5.0),
        ([5.0, 12.0, 0.0], 13.0),
        ([8.0, 15.0, 0.0], 17.0),
        ([7.0, 24.0, 0.0], 25.0),
        ([20.0, 21.0, 0.0], 29.0),
    ];
    const QUADRUPLES: [([f64; 3], f64); 5] = [
        ([1.0, 2.0, 2.0], 3.0),
        ([2.0, 3.0, 6.0], 7.0),
        ([1.0, 4.0, 8.0], 9.0),
        ([4.0, 4.0, 7.0], 9.0),
        ([2.0, 6.0, 9.0], 11.0),
    ];
    let (v, n) = if D == 2 { TRIPLES[k % 5] } else { QUADRUPLES[k % 5] };
    (take(v), n)
}

/// A relative velocity of exactly length `G = g₁ + g₂` (so `A = 0` exactly): a Pythagorean
/// vector with random signs, scaled by 2^e, added to a dyadic `v₁` (so `v₂ − v₁` is exact);
/// the rates split `G` dyadically. `nudge_g2` then moves `g₂` by that many ulps.
fn exact_a_zero<const D: usize>() -> impl Strategy<Value = ([f64; D], [f64; D], [f64; 2])> {
    (0usize..5, proptest::array::uniform3(any::<bool>()), -3i32..=3, proptest::array::uniform3(-16i32..=16), 1u32..8)
        .prop_map(|(k, signs, e, v1, split)| {
            let (v, n) = pythagorean::<D>(k);
            let scale = scale2(1.0, e);
            let dv: [f64; D] = core::array::from_fn(|i| if signs[i] { -v[i] } else { v[i] } * scale);
            let v1: [f64; D] = core::array::from_fn(|i| v1[i] as f64 / 8.0);
            let v2: [f64; D] = core::array::from_fn(|i| v1[i] + dv[i]);
            let grow = n * scale;
            let g1 = grow * split as f64 / 8.0;
            (v1, v2, [g1, grow - g1])
        })
}

/// Growing-contact families in `D` dimensions: each targets a way the growing quadratic is
/// hard (`A` of any sign and near zero, growth-dominated pairs, jammed gaps, overlaps by
/// ulps, extreme scales).
pub fn growing_families<const D: usize>() -> Vec<(&'static str, BoxedStrategy<Grow<D>>)> {
    let radius = || 0.25..1.0f64;
    let coordinates = || proptest::array::uniform3(-10.0..10.0f64);
    let unit3 = || proptest::array::uniform3(-1.0..1.0f64);
    vec![
        (
            // |Δv| = G exactly: f is linear, or the pair overlaps; apart by 0.5–4σ.
            "A = 0 exactly (relative speed = G)",
            (exact_a_zero::<D>(), coordinates(), unit3(), 0.5..4.0f64, radius(), radius())
                .prop_map(|((v1, v2, rates), p, dir, dist, r1, r2)| {
                    let p: [f64; D] = take(p);
                    let u: [f64; D] = direction(dir);
                    let q = core::array::from_fn(|i| p[i] + dist * (r1 + r2) * u[i]);
                    (ball(p, v1, r1), ball(q, v2, r2), rates)
                })
                .boxed(),
        ),
        (
            // The same with g₂ moved by ±1…6 ulps: A a few ulps of G² either side of 0.
            "A within ulps of 0",
            (exact_a_zero::<D>(), coordinates(), unit3(), 1.0..4.0f64, radius(), radius(), 1i64..=6, any::<bool>())
                .prop_map(|((v1, v2, rates), p, dir, dist, r1, r2, k, down)| {
                    let p: [f64; D] = take(p);
                    let u: [f64; D] = direction(dir);
                    let q = core::array::from_fn(|i| p[i] + dist * (r1 + r2) * u[i]);
                    (ball(p, v1, r1), ball(q, v2, r2), [rates[0], nudge(rates[1], if down { -k } else { k })])
                })
                .boxed(),
        ),
        (
            // Full-precision velocities whose difference rounds, G the f64 length of the
            // rounded difference moved by −3…3 ulps: A is a few ulps of G² from 0 and its
            // f64 evaluation is off in the last bits (the filter must not trust it).
            "A within ulps of 0 (rounded Δv)",
            (
                proptest::array::uniform3(-2.0..2.0f64),
                unit3(),
                0.1..2.0f64,
                -3i64..=3,
                0.5..1.0f64,
                coordinates(),
                unit3(),
                1.0..4.0f64,
                radius(),
            )
                .prop_map(|(v1, w, speed, k, split, p, dir, dist, r)| {
                    let v1: [f64; D] = take(v1);
                    let w: [f64; D] = direction(w);
                    let v2: [f64; D] = core::array::from_fn(|i| v1[i] + speed * w[i]);
                    let grow = nudge((0..D).map(|i| (v2[i] - v1[i]).powi(2)).sum::<f64>().sqrt(), k);
                    // g₂ = G − g₁ is exact (Sterbenz: g₁ within a factor 2 of G), so g₁ + g₂ = G.
                    let g1 = grow * split;
                    let p: [f64; D] = take(p);
                    let u: [f64; D] = direction(dir);
                    let q = core::array::from_fn(|i| p[i] + dist * 2.0 * r * u[i]);
                    (ball(p, v1, r), ball(q, v2, r), [g1, grow - g1])
                })
                .boxed(),
        ),
        (
            // |Δv| = 10⁻⁸…10⁻¹ of G, any direction: A < 0, contact whether approaching or not.
            "growth-dominated",
            (coordinates(), unit3(), unit3(), 1.0..3.0f64, -8.0..-1.0f64, 0.01..2.0f64, 0.0..1.0f64, radius())
                .prop_map(|(p, dir, w, dist, lv, grow, split, r)| {
                    let p: [f64; D] = take(p);
                    let u: [f64; D] = direction(dir);
                    let w: [f64; D] = direction(w);
                    let q = core::array::from_fn(|i| p[i] + dist * 2.0 * r * u[i]);
                    let speed = grow * 10f64.powf(lv);
                    (ball(p, [0.0; D], r), ball(q, w.map(|x| x * speed), r), [grow * split, grow * (1.0 - split)])
                })
                .boxed(),
        ),
        (
            // Gaps of 10⁻¹⁴…10⁻⁶σ, velocities 10⁻³…1, growth 10⁻⁴…10⁻¹: a pair near jamming,
            // approaching, receding, or sliding.
            "jammed gaps 1e-14..1e-6",
            (coordinates(), unit3(), unit3(), -14.0..-6.0f64, -3.0..0.0f64, -4.0..-1.0f64, radius(), radius())
                .prop_map(|(p, dir, w, lgap, lv, lg, r1, r2)| {
                    let p: [f64; D] = take(p);
                    let u: [f64; D] = direction(dir);
                    let w: [f64; D] = direction(w);
                    let d = (r1 + r2) * (1.0 + 10f64.powf(lgap));
                    let q = core::array::from_fn(|i| p[i] + d * u[i]);
                    let speed = 10f64.powf(lv);
                    let g = 10f64.powf(lg);
                    (ball(p, [0.0; D], r1), ball(q, w.map(|x| x * speed), r2), [g * r1, g * r2])
                })
                .boxed(),
        ),
        (
            // Overlap of 0–8 ulps of σ, approaching, separating or tangential, with growth
            // (proportional to the radii) or without.
            "overlap by ulps, with and without growth",
            (radius(), radius(), 0i64..=8, unit3(), 0u8..3, 0.1..2.0f64, prop_oneof![Just(0.0), 1e-6..1.0f64])
                .prop_map(|(r1, r2, k, dir, mode, s, g)| {
                    let u: [f64; D] = direction(dir);
                    let f = (r1 + r2) * (1.0 - k as f64 * f64::EPSILON);
                    let d: [f64; D] = u.map(|x| x * f);
                    let v: [f64; D] = match mode {
                        0 => d.map(|x| -x * s),
                        1 => d.map(|x| x * s),
                        // ⟨v|d⟩ = 0 up to the roundings of v: (−d₁, d₀, 0)·s.
                        _ => core::array::from_fn(|i| match i {
                            0 => -d[1] * s,
                            1 => d[0] * s,
                            _ => 0.0,
                        }),
                    };
                    (ball([0.0; D], [0.0; D], r1), ball(d, v, r2), [g * r1, g * r2])
                })
                .boxed(),
        ),
        (
            // A random pair 1–2.5σ apart with growth, lengths scaled by 2^p and velocities
            // and rates by 2^q, |p|, |q| ≤ 500.
            "scaled 2^±500",
            (growing_pair::<D>(), -500i32..=500, -500i32..=500)
                .prop_map(|((p, q, rates), lp, lv)| {
                    let s = |b: Ball<D>| Ball {
                        position: b.position.map(|x| scale2(x, lp)),
                        velocity: b.velocity.map(|x| scale2(x, lv)),
                        radius: scale2(b.radius, lp),
                    };
                    (s(p), s(q), rates.map(|g| scale2(g, lv)))
                })
                .boxed(),
        ),
        ("compressing-fluid pairs", growing_pair::<D>().boxed()),
    ]
}

/// A pair as it occurs in a compression: positions in a 100σ box, 1–2.5σ apart, velocity
/// components in [−2, 2], radii 0.5 growing at 0…0.5 of themselves per unit time.
pub fn growing_pair<const D: usize>() -> impl Strategy<Value = Grow<D>> {
    (proptest::array::uniform3(0.0..100.0f64), proptest::array::uniform3(-1.0..1.0f64), 1.0..2.5f64)
        .prop_flat_map(|(p, dir, dist)| {
            (Just((p, dir, dist)), proptest::array::uniform6(-2.0..2.0f64), 0.0..0.5f64, 0.5..2.0f64)
        })
        .prop_map(|((p, dir, dist), v, rate, ratio)| {
            let p: [f64; D] = take(p);
            let u: [f64; D] = direction(dir);
            let q = core::array::from_fn(|i| p[i] + dist * u[i]);
            let (r1, r2) = (0.5, 0.5 * ratio);
            let (v1, v2) = (take([v[0], v[1], v[2]]), take([v[3], v[4], v[5]]));
            (ball(p, v1, r1), ball(q, v2, r2), [rate * r1, rate * r2])
        })
}
