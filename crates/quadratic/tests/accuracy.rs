//! The accuracy contracts, proved family by family against the exact oracle, and the
//! seed's textbook formula measured on the same cases for comparison.
//!
//! Each family runs as a proptest property with a fixed seed (`common::runner`): a
//! violation of the contract fails the test with the shrunk counterexample. While the
//! properties run, the same cases are scored for the table printed at the end (and written
//! to `target/tmp/accuracy-<title>.md`): misclassifications and max ulp error, for collide
//! and for the textbook formula. The table documents; only collide's columns are asserted.

mod common;

use common::families::{Grow, contact_families, contact_families_3d, growing_families, quadratic_families};
use common::oracle::{ExactContact, check_roots, class3, exact_contact, exact_contact_growing};
use common::runner;
use proptest::prelude::*;
use proptest::strategy::BoxedStrategy;
use proptest::test_runner::TestCaseError;
use quadratic::{Ball, BallLanes, Bracket, Contact, textbook};
use std::cell::RefCell;

/// Cases per family. The contract is a worst-case claim, so more is better; 20 000 per
/// family keeps the whole file to a few seconds in release.
const CASES: u32 = 20_000;

#[derive(Default, Clone)]
struct Score {
    cases: usize,
    wrong: usize,
    max_ulps: f64,
    textbook_wrong: usize,
    textbook_over_1ulp: usize,
    textbook_max_ulps: f64,
}

fn row(name: &str, s: &Score) -> String {
    format!(
        "| {name} | {} | {} | {:.3} | {} ({:.1} %) | {} | {} |",
        s.cases,
        s.wrong,
        s.max_ulps,
        s.textbook_wrong,
        100.0 * s.textbook_wrong as f64 / s.cases as f64,
        s.textbook_over_1ulp,
        fmt_ulps(s.textbook_max_ulps)
    )
}

fn fmt_ulps(u: f64) -> String {
    if u.is_infinite() {
        "∞".into()
    } else if u >= 1e4 {
        format!("{u:.1e}")
    } else {
        format!("{u:.2}")
    }
}

const HEADER: &str = "| family | cases | collide: wrong count/class | collide: max ulp | textbook: wrong count/class | textbook: > 1 ulp | textbook: max ulp |\n|---|---|---|---|---|---|---|";

fn publish(title: &str, rows: &[String]) {
    let table = format!("### {title}\n\n{HEADER}\n{}\n", rows.join("\n"));
    println!("{table}");
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR"));
    let slug: String =
        title.to_lowercase().chars().filter(|c| c.is_alphanumeric() || *c == ' ').collect::<String>().replace(' ', "-");
    let path = dir.join(format!("accuracy-{slug}.md"));
    std::fs::write(path, &table).unwrap();
}

#[test]
fn quadratic_solver_contract_on_every_family() {
    let mut rows = Vec::new();
    for (name, strategy) in quadratic_families() {
        let score = RefCell::new(Score::default());
        let result = runner(CASES).run(&strategy, |(a, b, c)| {
            let got = quadratic::solve(a, b, c).expect("finite inputs");
            let check = check_roots(a, b, c, &got);
            let naive = check_roots(a, b, c, &textbook::solve(a, b, c));
            let mut s = score.borrow_mut();
            s.cases += 1;
            s.wrong += usize::from(!check.count_ok);
            s.max_ulps = s.max_ulps.max(if check.count_ok { check.max_ulps } else { 0.0 });
            if naive.count_ok {
                s.textbook_over_1ulp += usize::from(!(naive.max_ulps <= 1.0));
                s.textbook_max_ulps = s.textbook_max_ulps.max(naive.max_ulps);
            } else {
                s.textbook_wrong += 1;
            }
            drop(s);
            prop_assert!(check.count_ok, "wrong root count for ({a:e}, {b:e}, {c:e}): {got:?}");
            prop_assert!(
                check.max_ulps <= 1.0,
                "({a:e}, {b:e}, {c:e}) → {got:?}: {} ulp from the exact root",
                check.max_ulps
            );
            Ok(())
        });
        if let Err(e) = result {
            panic!("family '{name}': {e}");
        }
        rows.push(row(name, &score.into_inner()));
    }
    publish("Quadratic solver", &rows);
}

/// Scores a contact kernel on its families: for each case, `answer` gives the kernel's
/// answer, its exact path's, the oracle's and the textbook formula's. The kernel must agree
/// with its exact path bit for bit, classify exactly and be within one ulp.
fn score<T: std::fmt::Debug + Clone>(
    families: Vec<(&'static str, BoxedStrategy<T>)>,
    answer: impl Fn(&T) -> (Contact, Contact, ExactContact, Contact),
) -> Vec<String> {
    let mut rows = Vec::new();
    for (name, strategy) in families {
        let score = RefCell::new(Score::default());
        let result = runner(CASES).run(&strategy, |case| {
            let (got, slow, exact, naive) = answer(&case);
            prop_assert_eq!(got, slow, "filter and exact path disagree for {:?}", case);
            let ulps = |c: &Contact| match *c {
                Contact::At(t) => exact.ulps(t),
                _ => 0.0,
            };
            let class_ok = std::mem::discriminant(&got) == std::mem::discriminant(&exact.class)
                && (matches!(got, Contact::At(_)) || got == exact.class);
            let u = if class_ok { ulps(&got) } else { 0.0 };
            let mut s = score.borrow_mut();
            s.cases += 1;
            s.wrong += usize::from(!class_ok);
            s.max_ulps = s.max_ulps.max(u);
            if class3(&naive) == class3(&exact.class) {
                let nu = ulps(&naive);
                s.textbook_over_1ulp += usize::from(!(nu <= 1.0));
                s.textbook_max_ulps = s.textbook_max_ulps.max(nu);
            } else {
                s.textbook_wrong += 1;
            }
            drop(s);
            prop_assert!(class_ok, "{case:?}: got {got:?}, exact {:?}", exact.class);
            prop_assert!(u <= 1.0, "{case:?}: {got:?} is {u} ulp from the exact time");
            Ok(())
        });
        if let Err(e) = result {
            panic!("family '{name}': {e}");
        }
        rows.push(row(name, &score.into_inner()));
    }
    rows
}

fn score_contacts<const D: usize>(families: Vec<(&'static str, BoxedStrategy<(Ball<D>, Ball<D>)>)>) -> Vec<String> {
    score(families, |(p, q)| {
        (
            quadratic::contact_time(p, q).expect("valid inputs"),
            quadratic::contact_time_exact_path(p, q),
            exact_contact(p, q),
            textbook::contact_time(p, q),
        )
    })
}

#[test]
fn contact_time_contract_on_every_family_2d() {
    publish("Contact time (2D)", &score_contacts(contact_families()));
}

#[test]
fn contact_time_contract_on_every_family_3d() {
    publish("Contact time (3D)", &score_contacts(contact_families_3d()));
}

fn score_growing<const D: usize>(families: Vec<(&'static str, BoxedStrategy<Grow<D>>)>) -> Vec<String> {
    score(families, |(p, q, rates)| {
        (
            quadratic::contact_time_growing(p, q, *rates).expect("valid inputs"),
            quadratic::contact_time_growing_exact_path(p, q, *rates),
            exact_contact_growing(p, q, *rates),
            textbook::contact_time_growing(p, q, *rates),
        )
    })
}

#[test]
fn growing_contact_contract_on_every_family_2d() {
    publish("Growing contact (2D)", &score_growing(growing_families::<2>()));
}

#[test]
fn growing_contact_contract_on_every_family_3d() {
    publish("Growing contact (3D)", &score_growing(growing_families::<3>()));
}

/// Without growth the growing kernel is the rigid one, bit for bit — through its public
/// entry (which says so by construction) and through its own exact path (the general
/// formulas with `G = 0`: the same exact values, rounded the same way), on every rigid family.
#[test]
fn growing_kernel_without_growth_is_the_rigid_kernel() {
    fn check<const D: usize>(families: Vec<(&'static str, BoxedStrategy<(Ball<D>, Ball<D>)>)>) {
        for (name, strategy) in families {
            let result = runner(CASES / 4).run(&strategy, |(p, q)| {
                let rigid = quadratic::contact_time(&p, &q).expect("valid inputs");
                for rates in [[0.0, 0.0], [-0.0, 0.0], [0.0, -0.0]] {
                    let grown = quadratic::contact_time_growing(&p, &q, rates).expect("valid inputs");
                    prop_assert_eq!(format!("{grown:?}"), format!("{rigid:?}"));
                }
                let general = quadratic::contact_time_growing_exact_path(&p, &q, [0.0, 0.0]);
                prop_assert_eq!(format!("{general:?}"), format!("{rigid:?}"), "{:?} {:?}", p, q);
                Ok(())
            });
            if let Err(e) = result {
                panic!("family '{name}': {e}");
            }
        }
    }
    check(contact_families());
    check(contact_families_3d());
}

/// `contact_time_within` and `contact_bracket` may drop a pair only when its exact contact
/// time is later than the horizon; otherwise `contact_time_within` gives exactly
/// `contact_time`'s answer, and `contact_bracket` either that answer or an interval that holds
/// the time `contact_time` returns; `contact_brackets` (the batch kernel) brackets every lane's
/// answer and matches `contact_bracket`'s certified intervals bit for bit. Horizons sit at, one
/// ulp either side of, and well before and after each contact time (and at 0, −1, ±∞).
fn within_contract<const D: usize>(families: Vec<(&'static str, BoxedStrategy<(Ball<D>, Ball<D>)>)>) {
    use common::families::nudge;
    for (name, strategy) in families {
        let (hits, dropped_early) = (RefCell::new(0usize), RefCell::new(0usize));
        let (brackets, tight) = (RefCell::new(0usize), RefCell::new(0usize));
        let result = runner(CASES / 4).run(&strategy, |(p, q)| {
            let got = quadratic::contact_time(&p, &q).expect("valid inputs");
            let exact = exact_contact(&p, &q);
            let t = got.time().unwrap_or(1.0);
            let horizons =
                [t, nudge(t, -1), nudge(t, 1), 0.49 * t, 2.0 * t, 0.0, -1.0, f64::INFINITY, f64::NEG_INFINITY];
            for (k, &h) in horizons.iter().enumerate() {
                match quadratic::contact_time_within(&p, &q, h) {
                    Some(c) => prop_assert_eq!(c, got, "{:?} {:?} horizon {:e}", p, q, h),
                    None => {
                        let later = match got {
                            Contact::At(_) => exact.exceeds(h),
                            Contact::Now => false,
                            Contact::Never(_) => true,
                        };
                        prop_assert!(later, "{:?} {:?}: dropped at horizon {:e} but {:?}", p, q, h, got);
                    }
                }
                match quadratic::contact_bracket(&p, &q, h) {
                    Bracket::Known(c) => prop_assert_eq!(c, got, "{:?} {:?} horizon {:e}", p, q, h),
                    Bracket::Beyond => {
                        let later = match got {
                            Contact::At(_) => exact.exceeds(h),
                            Contact::Now => false,
                            Contact::Never(_) => true,
                        };
                        prop_assert!(later, "{:?} {:?}: bracket beyond {:e} but {:?}", p, q, h, got);
                    }
                    Bracket::Between { lo, hi } => {
                        let Contact::At(t) = got else {
                            return Err(TestCaseError::fail(format!("{p:?} {q:?}: bracket for {got:?}")));
                        };
                        prop_assert!(lo <= t && t <= hi && lo <= h, "{:?} {:?}: {} not in [{}, {}]", p, q, t, lo, hi);
                        if k == 7 {
                            *brackets.borrow_mut() += 1;
                            if hi - lo <= 1e-12 * hi {
                                *tight.borrow_mut() += 1;
                            }
                        }
                    }
                }
                if k == 7 {
                    // The batch kernel on the same pair (lane 0), the pair swapped (lane 1)
                    // and copies: every lane brackets its own answer, and a certified contact
                    // gets exactly `contact_bracket`'s interval.
                    let (mut first, mut second) = (BallLanes::<D, 8>::default(), BallLanes::<D, 8>::default());
                    for lane in 0..8 {
                        let (x, y) = if lane % 2 == 0 { (&p, &q) } else { (&q, &p) };
                        first.set(lane, x);
                        second.set(lane, y);
                    }
                    let (mut lo, mut hi) = ([0.0; 8], [0.0; 8]);
                    quadratic::contact_brackets(&first, &second, &mut lo, &mut hi);
                    for lane in 0..8 {
                        let (x, y) = if lane % 2 == 0 { (&p, &q) } else { (&q, &p) };
                        let want = quadratic::contact_time(x, y).expect("valid inputs");
                        let t = want.time().unwrap_or(f64::INFINITY);
                        prop_assert!(
                            lo[lane] <= t && t <= hi[lane],
                            "{:?} {:?}: lane {} has [{:e}, {:e}] for {:?}",
                            x,
                            y,
                            lane,
                            lo[lane],
                            hi[lane],
                            want
                        );
                        if let Bracket::Between { lo: l, hi: h } = quadratic::contact_bracket(x, y, h) {
                            prop_assert_eq!((lo[lane].to_bits(), hi[lane].to_bits()), (l.to_bits(), h.to_bits()));
                        }
                    }
                    // The same lanes moved to the frame of the first ball (the second's
                    // position rounded to the difference): `contact_brackets_from_origin`,
                    // which never reads the first positions (NaN here), gives the brackets
                    // `contact_brackets` gives with them at +0, bit for bit.
                    let mut origin = BallLanes::<D, 8>::default();
                    let mut ignored = BallLanes::<D, 8>::default();
                    for lane in 0..8 {
                        let (x, y) = if lane % 2 == 0 { (&p, &q) } else { (&q, &p) };
                        let moved = Ball { position: core::array::from_fn(|i| y.position[i] - x.position[i]), ..*y };
                        second.set(lane, &moved);
                        origin.set(lane, &Ball { position: [0.0; D], ..*x });
                        ignored.set(lane, &Ball { position: [f64::NAN; D], ..*x });
                    }
                    let (mut lo0, mut hi0) = ([0.0; 8], [0.0; 8]);
                    quadratic::contact_brackets(&origin, &second, &mut lo, &mut hi);
                    quadratic::contact_brackets_from_origin(&ignored, &second, &mut lo0, &mut hi0);
                    for lane in 0..8 {
                        prop_assert_eq!(
                            (lo[lane].to_bits(), hi[lane].to_bits()),
                            (lo0[lane].to_bits(), hi0[lane].to_bits()),
                            "{:?} {:?}: lane {}",
                            p,
                            q,
                            lane
                        );
                    }
                }
                if k == 3 && matches!(got, Contact::At(_)) {
                    *hits.borrow_mut() += 1;
                    if quadratic::contact_time_within(&p, &q, h).is_none() {
                        *dropped_early.borrow_mut() += 1;
                    }
                }
            }
            Ok(())
        });
        if let Err(e) = result {
            panic!("family '{name}': {e}");
        }
        // The bound c/(−2b) is at least half the contact time, so a horizon of 0.49·t is always
        // beaten whenever the filter decides; on ordinary fluid pairs it decides nearly always.
        if name.contains("dense-fluid") {
            let (h, d) = (hits.into_inner(), dropped_early.into_inner());
            assert!(h > 100 && d as f64 >= 0.95 * h as f64, "{name}: only {d} of {h} hits dropped at 0.49·t");
            // And its brackets are narrow (relative width ≤ 1e-12) for nearly every hit.
            let (b, t) = (brackets.into_inner(), tight.into_inner());
            assert!(b as f64 >= 0.95 * h as f64 && t as f64 >= 0.95 * b as f64, "{name}: {t} of {b} brackets tight");
        }
    }
}

#[test]
fn contact_time_within_drops_only_later_contacts_2d() {
    within_contract(contact_families());
}

#[test]
fn contact_time_within_drops_only_later_contacts_3d() {
    within_contract(contact_families_3d());
}

/// `contact_clear_until_from_origin` may clear a lane only when its pair never touches or
/// its exact contact time is later than the horizon: every lane of a batch is checked against
/// the exact oracle of its own pair (the second ball moved to the first's frame, as the
/// engine forms it), at horizons at, one ulp either side of, and well before and after the
/// contact time (and at 0, −1, ±∞). On dense-fluid hits the tangent test clears nearly every
/// horizon of 0.49·t (it is at least half the time), so the check is not vacuous.
fn clear_until_contract<const D: usize>(families: Vec<(&'static str, BoxedStrategy<(Ball<D>, Ball<D>)>)>) {
    use common::families::nudge;
    for (name, strategy) in families {
        let (hits, cleared_early) = (RefCell::new(0usize), RefCell::new(0usize));
        let result = runner(CASES / 4).run(&strategy, |(p, q)| {
            // Lane 0 the pair, lane 1 swapped, lanes 2.. copies: the frame of the first ball.
            let (mut first, mut second) = (BallLanes::<D, 4>::default(), BallLanes::<D, 4>::default());
            let mut pairs = Vec::new();
            for lane in 0..4 {
                let (x, y) = if lane % 2 == 0 { (&p, &q) } else { (&q, &p) };
                let origin = Ball { position: [0.0; D], ..*x };
                let moved = Ball { position: core::array::from_fn(|i| y.position[i] - x.position[i]), ..*y };
                // The first positions are never read (NaN here).
                first.set(lane, &Ball { position: [f64::NAN; D], ..*x });
                second.set(lane, &moved);
                pairs.push((origin, moved));
            }
            let (origin, moved) = pairs[0];
            let t = quadratic::contact_time(&origin, &moved).expect("valid inputs").time().unwrap_or(1.0);
            let horizons =
                [t, nudge(t, -1), nudge(t, 1), 0.49 * t, 2.0 * t, 0.0, -1.0, f64::INFINITY, f64::NEG_INFINITY];
            for (k, &h) in horizons.iter().enumerate() {
                let clear = quadratic::contact_clear_until_from_origin(&first, &second, &[h; 4]);
                for (lane, (x, y)) in pairs.iter().enumerate() {
                    if !clear[lane] {
                        continue;
                    }
                    let got = quadratic::contact_time(x, y).expect("valid inputs");
                    let later = match got {
                        Contact::At(_) => exact_contact(x, y).exceeds(h),
                        Contact::Now => false,
                        Contact::Never(_) => true,
                    };
                    prop_assert!(later, "{:?} {:?}: cleared until {:e} but {:?}", x, y, h, got);
                }
                if k == 3 && matches!(quadratic::contact_time(&origin, &moved), Ok(Contact::At(_))) {
                    *hits.borrow_mut() += 1;
                    *cleared_early.borrow_mut() += clear[0] as usize;
                }
            }
            Ok(())
        });
        if let Err(e) = result {
            panic!("family '{name}': {e}");
        }
        if name.contains("dense-fluid") {
            let (h, c) = (hits.into_inner(), cleared_early.into_inner());
            assert!(h > 100 && c as f64 >= 0.95 * h as f64, "{name}: only {c} of {h} hits cleared at 0.49·t");
        }
    }
}

#[test]
fn clear_until_drops_only_later_contacts_2d() {
    clear_until_contract(contact_families());
}

#[test]
fn clear_until_drops_only_later_contacts_3d() {
    clear_until_contract(contact_families_3d());
}

/// The oracle itself must be able to fail: answers moved by 2 ulps, or misclassified,
/// are caught.
#[test]
fn oracle_detects_wrong_answers() {
    use common::families::nudge;
    // x² − 3x + 2: roots 1, 2. Two ulps off is 2 ulps off; a missing root is a count error.
    let c = check_roots(1.0, -3.0, 2.0, &quadratic::Roots::Two(1.0, nudge(2.0, 2)));
    assert!(c.count_ok && c.max_ulps >= 1.9, "{c:?}");
    assert!(!check_roots(1.0, -3.0, 2.0, &quadratic::Roots::One(1.0)).count_ok);
    // Double root at 3: one root expected, two is wrong.
    assert!(!check_roots(1.0, -6.0, 9.0, &quadratic::Roots::Two(3.0, 3.0)).count_ok);
    // A head-on contact at t = 1: t ± 2 ulps is caught, and the class is exact.
    let p = Ball { position: [0.0, 0.0], velocity: [1.0, 0.0], radius: 0.5 };
    let q = Ball { position: [3.0, 0.0], velocity: [-1.0, 0.0], radius: 0.5 };
    let exact = exact_contact(&p, &q);
    assert_eq!(class3(&exact.class), 2);
    assert!(exact.ulps(1.0) < 1e-9);
    assert!(exact.ulps(nudge(1.0, 2)) >= 1.9);
    assert!(exact.ulps(nudge(1.0, -2)) >= 1.9);
    // Growing disks at rest 3 apart, σ(t) = 1 + t: t = 2 (A < 0); 2 ± 2 ulps is caught.
    let (p, q) = (Ball { velocity: [0.0, 0.0], ..p }, Ball { velocity: [0.0, 0.0], ..q });
    let exact = exact_contact_growing(&p, &q, [0.5, 0.5]);
    assert_eq!(class3(&exact.class), 2);
    assert!(exact.ulps(2.0) < 1e-9 && exact.ulps(nudge(2.0, 2)) >= 1.9 && exact.ulps(nudge(2.0, -2)) >= 1.9);
    // Head on at |Δv| = G = 1 (A = 0): 3 − t = 1 + t at t = 1, the linear root.
    let q = Ball { velocity: [-1.0, 0.0], ..q };
    let exact = exact_contact_growing(&p, &q, [0.5, 0.5]);
    assert!(exact.ulps(1.0) < 1e-9 && exact.ulps(nudge(1.0, 2)) >= 1.9);
    // Receding at 2 against a growth of 1 (A > 0, b > 0): never, not a contact.
    let q = Ball { velocity: [2.0, 0.0], ..q };
    assert_eq!(exact_contact_growing(&p, &q, [0.5, 0.5]).class, Contact::Never(quadratic::Miss::Receding));
}

/// The brackets of near-contact pairs are tight: some tens of ulps of the contact time, not
/// hundreds. Dense-fluid neighbours approach from gaps of 10⁻⁵σ to 10⁻¹σ, within 30° of head-on,
/// at coordinates up to 100σ from the origin (so the differences of positions round). Over
/// this family the bracket is at most `β`-, `δ`- and rounding-terms wide: `2β/(−b)` ≤ 24u
/// (the angle keeps `Σ|hᵢgᵢ| ≤ 2|b|`), `δ/D` ≤ 64u (it keeps `D ≥ ¾|Δv|²σ²` near contact),
/// 16u of margins, and the compensated `c`'s `2γ/c` ≈ 4u — about 115u in all, so 160u bounds
/// it. A bracket computed with the plain f64 `c` (error ~7u·(|Δr|² + σ²)) would be wider than
/// 160u for every gap below about 10⁻¹ (≈ 14u/gap from `γ` alone): this fails if the
/// compensation is lost. Also checks that every bracket holds the contact time.
#[test]
fn brackets_are_tight_near_contact() {
    // xorshift64*, fixed seed: the family is deterministic.
    let mut state = 0x9E37_79B9_7F4A_7C15u64;
    let mut unit = move || {
        state ^= state >> 12;
        state ^= state << 25;
        state ^= state >> 27;
        (state.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11) as f64 / (1u64 << 53) as f64
    };
    let u = f64::EPSILON / 2.0;
    let (mut between, mut worst) = (0, 0.0f64);
    for _ in 0..20_000 {
        let (r1, r2) = (0.3 + 0.4 * unit(), 0.3 + 0.4 * unit());
        let sigma = r1 + r2;
        let gap = 10f64.powf(-5.0 + 4.0 * unit());
        let phi = std::f64::consts::TAU * unit();
        let theta = (unit() - 0.5) * std::f64::consts::FRAC_PI_3;
        let speed = 0.5 + 1.5 * unit();
        let origin = [200.0 * unit() - 100.0, 200.0 * unit() - 100.0];
        let d = sigma * (1.0 + gap);
        let position = [origin[0] + d * phi.cos(), origin[1] + d * phi.sin()];
        let v1 = [unit() - 0.5, unit() - 0.5];
        let dv = [-speed * (phi + theta).cos(), -speed * (phi + theta).sin()];
        let first = Ball { position: origin, velocity: v1, radius: r1 };
        let second = Ball { position, velocity: [v1[0] + dv[0], v1[1] + dv[1]], radius: r2 };
        let Bracket::Between { lo, hi } = quadratic::contact_bracket(&first, &second, f64::INFINITY) else {
            continue;
        };
        between += 1;
        let Contact::At(t) = quadratic::contact_time(&first, &second).expect("valid balls") else {
            panic!("a bracket without a contact: {first:?} {second:?}");
        };
        assert!(lo <= t && t <= hi, "[{lo:e}, {hi:e}] misses {t:e}");
        worst = worst.max((hi - lo) / (u * t));
    }
    assert!(between > 19_000, "only {between} brackets");
    assert!(worst <= 160.0, "widest bracket {worst:.1} u·t");
    assert!(worst > 20.0, "suspiciously narrow: {worst:.1} u·t");
}

/// `narrow_contact` may only return `Some(n)` when `contact_time` gives `At(t)` with `t` equal
/// to `n.lo()` or `n.hi()`, adjacent doubles, and the exact root strictly between them — for
/// any guess: the answer itself, a few and a thousand ulps off, the middle of the bracket, far
/// off, and nonsense (0, −1, ∞, NaN). For everything else (never, now) it must say `None`.
/// `n.time()`, when it answers, must be `t` to the bit. On the dense-fluid family, from the
/// middle of the bracket (the engine's guess), both must also be useful: they answer for
/// nearly every contact (so a version that says `None` to stay safe fails here).
fn narrow_contract<const D: usize>(families: Vec<(&'static str, BoxedStrategy<(Ball<D>, Ball<D>)>)>) {
    use common::families::nudge;
    for (name, strategy) in families {
        let (contacts, pinned) = (RefCell::new(0usize), RefCell::new(0usize));
        let result = runner(CASES / 4).run(&strategy, |(p, q)| {
            let got = quadratic::contact_time(&p, &q).expect("valid inputs");
            let exact = exact_contact(&p, &q);
            let t = got.time().unwrap_or(1.0);
            let middle = match quadratic::contact_bracket(&p, &q, f64::INFINITY) {
                Bracket::Between { lo, hi } => Some(lo + 0.5 * (hi - lo)),
                _ => None,
            };
            let guesses = [
                t,
                nudge(t, -3),
                nudge(t, 3),
                nudge(t, -1000),
                nudge(t, 1000),
                middle.unwrap_or(t),
                0.5 * t,
                4.0 * t,
                0.0,
                -1.0,
                f64::INFINITY,
                f64::NAN,
            ];
            for (k, &guess) in guesses.iter().enumerate() {
                let Some(narrowed) = quadratic::narrow_contact(&p, &q, guess) else {
                    continue;
                };
                let (x1, x2) = (narrowed.lo(), narrowed.hi());
                let Contact::At(t) = got else {
                    return Err(TestCaseError::fail(format!("{p:?} {q:?}: narrowed to [{x1:e}, {x2:e}] for {got:?}")));
                };
                prop_assert!(x1 <= t && t <= x2, "{:?} {:?}: {:e} not in [{:e}, {:e}]", p, q, t, x1, x2);
                prop_assert_eq!(x2, x1.next_up());
                prop_assert!(exact.exceeds(x1) && !exact.exceeds(x2), "{:?} {:?}: exact root outside", p, q);
                let exactly = narrowed.time();
                if let Some(time) = exactly {
                    prop_assert_eq!(time.to_bits(), t.to_bits(), "{:?} {:?}: pinned {:e}, kernel {:e}", p, q, time, t);
                }
                if k == 5 && middle.is_some() && exactly.is_some() {
                    *pinned.borrow_mut() += 1;
                }
            }
            if middle.is_some() {
                *contacts.borrow_mut() += 1;
            }
            Ok(())
        });
        if let Err(e) = result {
            panic!("family '{name}': {e}");
        }
        if name.contains("dense-fluid") {
            let (c, p) = (contacts.into_inner(), pinned.into_inner());
            assert!(c > 100 && p as f64 >= 0.99 * c as f64, "{name}: pinned {p} of {c} bracketed contacts");
        }
    }
}

#[test]
fn narrowed_contacts_hold_the_answer_2d() {
    narrow_contract(contact_families());
}

#[test]
fn narrowed_contacts_hold_the_answer_3d() {
    narrow_contract(contact_families_3d());
}
