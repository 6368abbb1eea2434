//! Proves every stored answer of the edge-case reference (`quadratic::reference`) with the
//! exact oracle, and keeps the table in `crates/quadratic/README.md` in sync with the data.
//!
//! If a stored answer is wrong the test fails and prints the correct Rust literal. If the
//! README table is stale it fails; `UPDATE_REFERENCE=1 cargo test --release -p quadratic
//! --test reference` rewrites it.

mod common;

use common::oracle::{exact_contact, exact_contact_growing, roots_rounded};
use quadratic::hex::format as hex;
use quadratic::reference::{CONTACT_CASES, GROWING_CASES, ROOT_CASES, describe_contact, describe_roots};
use quadratic::{Contact, Roots, contact_time, contact_time_growing, solve, textbook};

fn exact_roots(a: f64, b: f64, c: f64) -> Roots {
    match roots_rounded(a, b, c) {
        None => Roots::All,
        Some(v) => match v.as_slice() {
            [] => Roots::None,
            [x] => Roots::One(*x),
            [x, y] => Roots::Two(*x, *y),
            _ => unreachable!(),
        },
    }
}

fn literal(x: f64) -> String {
    format!("bits(0x{:016x})", x.to_bits())
}

#[test]
fn stored_exact_answers_are_exact() {
    let mut wrong = Vec::new();
    for case in ROOT_CASES {
        let exact = exact_roots(case.a, case.b, case.c);
        let same = match (exact, case.exact) {
            (Roots::One(x), Roots::One(y)) => x.to_bits() == y.to_bits(),
            (Roots::Two(x1, x2), Roots::Two(y1, y2)) => x1.to_bits() == y1.to_bits() && x2.to_bits() == y2.to_bits(),
            (x, y) => x == y,
        };
        if !same {
            let fix = match exact {
                Roots::One(x) => format!("Roots::One({})", literal(x)),
                Roots::Two(x, y) => format!("Roots::Two({}, {})", literal(x), literal(y)),
                other => format!("Roots::{other:?}"),
            };
            wrong.push(format!("{}: stored {:?}, exact: {fix}", case.name, case.exact));
        }
    }
    let mut check = |name: &str, stored: Contact, exact: common::oracle::ExactContact| {
        let exact = match exact.class {
            Contact::At(_) => Contact::At(exact.time_rounded()),
            other => other,
        };
        let same = match (exact, stored) {
            (Contact::At(x), Contact::At(y)) => x.to_bits() == y.to_bits(),
            (x, y) => x == y,
        };
        if !same {
            let fix = match exact {
                Contact::At(t) => format!("Contact::At({})", literal(t)),
                other => format!("Contact::{other:?}"),
            };
            wrong.push(format!("{name}: stored {stored:?}, exact: {fix}"));
        }
    };
    for case in CONTACT_CASES {
        check(case.name, case.exact, exact_contact(&case.first, &case.second));
    }
    for case in GROWING_CASES {
        check(case.name, case.exact, exact_contact_growing(&case.first, &case.second, case.rates));
    }
    assert!(wrong.is_empty(), "stored reference answers are wrong:\n{}", wrong.join("\n"));
}

#[test]
fn this_crate_agrees_with_every_reference_case() {
    let report = quadratic::reference::check_all();
    assert_eq!(report.failures, 0, "{}", report.text);
}

/// The Markdown table of the crate README, generated from the data.
fn table() -> String {
    let mark = |ok: bool| if ok { "" } else { " ✗" };
    let mut out = String::new();
    out.push_str("### Quadratic `a·x² + b·x + c = 0`\n\n");
    out.push_str(
        "| case | a, b, c | textbook formula | collide | exact (correctly rounded) |\n|---|---|---|---|---|\n",
    );
    for c in ROOT_CASES {
        let naive = textbook::solve(c.a, c.b, c.c);
        let got = solve(c.a, c.b, c.c).unwrap();
        out.push_str(&format!(
            "| {} | `{}`, `{}`, `{}` | `{}`{} | `{}` | `{}` |\n",
            c.name,
            hex(c.a),
            hex(c.b),
            hex(c.c),
            describe_roots(&naive),
            mark(quadratic::reference::roots_agree(&naive, &c.exact)),
            describe_roots(&got),
            describe_roots(&c.exact)
        ));
    }
    out.push_str("\n### Contact time of two disks\n\n");
    out.push_str("| case | r₁; v₁; R₁ | r₂; v₂; R₂ | textbook formula | collide | exact (correctly rounded) |\n|---|---|---|---|---|---|\n");
    let ball = |b: &quadratic::Ball<2>| {
        format!(
            "`({}, {})`; `({}, {})`; `{}`",
            hex(b.position[0]),
            hex(b.position[1]),
            hex(b.velocity[0]),
            hex(b.velocity[1]),
            hex(b.radius)
        )
    };
    for c in CONTACT_CASES {
        let naive = textbook::contact_time(&c.first, &c.second);
        let got = contact_time(&c.first, &c.second).unwrap();
        out.push_str(&format!(
            "| {} | {} | {} | {}{} | {} | {} |\n",
            c.name,
            ball(&c.first),
            ball(&c.second),
            describe_contact(&naive),
            mark(quadratic::reference::contacts_agree(&naive, &c.exact)),
            describe_contact(&got),
            describe_contact(&c.exact)
        ));
    }
    out.push_str("\n### Contact time of two growing disks (radius `R + g·t`)\n\n");
    out.push_str("| case | r₁; v₁; R₁ | r₂; v₂; R₂ | g₁, g₂ | textbook formula | collide | exact (correctly rounded) |\n|---|---|---|---|---|---|---|\n");
    for c in GROWING_CASES {
        let naive = textbook::contact_time_growing(&c.first, &c.second, c.rates);
        let got = contact_time_growing(&c.first, &c.second, c.rates).unwrap();
        out.push_str(&format!(
            "| {} | {} | {} | `{}`, `{}` | {}{} | {} | {} |\n",
            c.name,
            ball(&c.first),
            ball(&c.second),
            hex(c.rates[0]),
            hex(c.rates[1]),
            describe_contact(&naive),
            mark(quadratic::reference::contacts_agree(&naive, &c.exact)),
            describe_contact(&got),
            describe_contact(&c.exact)
        ));
    }
    out
}

#[test]
fn readme_table_matches_the_data() {
    const BEGIN: &str = "<!-- reference:begin (generated by tests/reference.rs) -->\n";
    const END: &str = "<!-- reference:end -->";
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("README.md");
    let readme = std::fs::read_to_string(&path).unwrap();
    let (start, stop) =
        (readme.find(BEGIN).expect("begin marker") + BEGIN.len(), readme.find(END).expect("end marker"));
    let fresh = table();
    if readme[start..stop] != fresh {
        if std::env::var_os("UPDATE_REFERENCE").is_some() {
            let updated = format!("{}{fresh}{}", &readme[..start], &readme[stop..]);
            std::fs::write(&path, updated).unwrap();
        } else {
            panic!("crates/quadratic/README.md's table is stale: rerun with UPDATE_REFERENCE=1");
        }
    }
}
