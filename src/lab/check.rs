//! Checks: a measured value against an expectation, with a tolerance that says why.

use serde::{Deserialize, Serialize};
use std::fmt::Write as _;

/// One physics check and its verdict.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Check {
    /// What is checked.
    pub name: String,
    /// The measured value.
    pub measured: f64,
    /// Its statistical error (one standard error; NaN when not applicable, written as
    /// `null` in result.json since JSON has no NaN, and read back as NaN).
    #[serde(deserialize_with = "nan_when_null")]
    pub error: f64,
    /// The expected value (or the limit, for `at most` checks).
    pub expected: f64,
    /// The allowed |measured − expected| (or 0 for `at most` checks).
    pub tolerance: f64,
    /// `"within"`: |measured − expected| ≤ tolerance; `"at most"`: measured ≤ expected;
    /// `"at least"`: measured ≥ expected.
    pub kind: String,
    /// Where the tolerance comes from.
    pub why: String,
    /// The verdict.
    pub pass: bool,
}

/// JSON writes a NaN as `null`; reading it back gives the NaN again, so a result.json
/// round-trips to the same checks.
fn nan_when_null<'de, D: serde::Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
    Ok(Option::<f64>::deserialize(d)?.unwrap_or(f64::NAN))
}

impl Check {
    /// Passes when |measured − expected| ≤ tolerance.
    pub fn within(name: &str, measured: f64, error: f64, expected: f64, tolerance: f64, why: &str) -> Check {
        let pass = (measured - expected).abs() <= tolerance;
        Check { name: name.into(), measured, error, expected, tolerance, kind: "within".into(), why: why.into(), pass }
    }

    /// Passes when measured ≤ limit.
    pub fn at_most(name: &str, measured: f64, error: f64, limit: f64, why: &str) -> Check {
        Check::bound(name, measured, error, limit, "at most", measured <= limit, why)
    }

    /// Passes when measured ≥ limit.
    pub fn at_least(name: &str, measured: f64, error: f64, limit: f64, why: &str) -> Check {
        Check::bound(name, measured, error, limit, "at least", measured >= limit, why)
    }

    /// A one-sided check against `limit` (no tolerance).
    fn bound(name: &str, measured: f64, error: f64, limit: f64, kind: &str, pass: bool, why: &str) -> Check {
        Check {
            name: name.into(),
            measured,
            error,
            expected: limit,
            tolerance: 0.0,
            kind: kind.into(),
            why: why.into(),
            pass,
        }
    }

    /// The expectation as text: `expected ± tolerance`, `≤ limit` or `≥ limit`.
    pub fn expectation(&self, digits: usize) -> String {
        match self.kind.as_str() {
            "within" => format!("{} ± {:.digits$e}", number(self.expected), self.tolerance),
            "at least" => format!("≥ {}", number(self.expected)),
            _ => format!("≤ {}", number(self.expected)),
        }
    }

    /// Deviation in units of the tolerance (for tables): ≤ 1 passes.
    pub fn score(&self) -> f64 {
        match self.kind.as_str() {
            "within" => (self.measured - self.expected).abs() / self.tolerance,
            "at least" => self.expected / self.measured,
            _ => self.measured / self.expected,
        }
    }
}

/// A number for a table: six decimals, or six significant digits when that would hide it.
pub fn number(x: f64) -> String {
    if x != 0.0 && x.abs() < 1e-3 { format!("{x:.5e}") } else { format!("{x:.6}") }
}

/// A plain-text verdict table.
pub fn table(experiment: &str, checks: &[Check]) -> String {
    let mut out = String::new();
    writeln!(out, "{experiment}").unwrap();
    for c in checks {
        let verdict = if c.pass { "PASS" } else { "FAIL" };
        let expectation = c.expectation(2);
        writeln!(out, "  [{verdict}] {}: {} (±{:.1e}) vs {expectation}", c.name, number(c.measured), c.error).unwrap();
    }
    out
}
