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
    /// Its statistical error (one standard error; NaN when not applicable).
    pub error: f64,
    /// The expected value (or the limit, for `at most` checks).
    pub expected: f64,
    /// The allowed |measured − expected| (or 0 for `at most` checks).
    pub tolerance: f64,
    /// `"within"`: |measured − expected| ≤ tolerance; `"at most"`: measured ≤ expected.
    pub kind: String,
    /// Where the tolerance comes from.
    pub why: String,
    /// The verdict.
    pub pass: bool,
}

impl Check {
    /// Passes when |measured − expected| ≤ tolerance.
    pub fn within(name: &str, measured: f64, error: f64, expected: f64, tolerance: f64, why: &str) -> Check {
        let pass = (measured - expected).abs() <= tolerance;
        Check { name: name.into(), measured, error, expected, tolerance, kind: "within".into(), why: why.into(), pass }
    }

    /// Passes when measured ≤ limit.
    pub fn at_most(name: &str, measured: f64, error: f64, limit: f64, why: &str) -> Check {
        let pass = measured <= limit;
        Check {
            name: name.into(),
            measured,
            error,
            expected: limit,
            tolerance: 0.0,
            kind: "at most".into(),
            why: why.into(),
            pass,
        }
    }

    /// Deviation in units of the tolerance (for tables): ≤ 1 passes.
    pub fn score(&self) -> f64 {
        if self.kind == "within" {
            (self.measured - self.expected).abs() / self.tolerance
        } else {
            self.measured / self.expected
        }
    }
}

/// A plain-text verdict table.
pub fn table(experiment: &str, checks: &[Check]) -> String {
    let mut out = String::new();
    writeln!(out, "{experiment}").unwrap();
    for c in checks {
        let verdict = if c.pass { "PASS" } else { "FAIL" };
        let expectation = if c.kind == "within" {
            format!("{:.6} ± {:.2e}", c.expected, c.tolerance)
        } else {
            format!("≤ {:.6}", c.expected)
        };
        writeln!(out, "  [{verdict}] {}: {:.6} (±{:.1e}) vs {expectation}", c.name, c.measured, c.error).unwrap();
    }
    out
}
