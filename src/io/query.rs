//! The JSON-lines query protocol: one request per input line, one answer per line out.
//!
//! * `roots`: `{"id": <any>, "a": <num>, "b": <num>, "c": <num>}` →
//!   `{"id": <same>, "roots": [x1, x2]}` (ascending; `[]` for none; one element for one root)
//!   or `{"id": <same>, "all": true}` when every x solves `0 = 0`.
//! * `contact-time`: `{"id": <any>, "r1": [x, y], "v1": [..], "R1": <num>, "r2": [..],
//!   "v2": [..], "R2": <num>}` (2 or 3 components, the same for all four vectors) →
//!   `{"id": <same>, "t": <num or null>}` (`null` = never, `0` = now).
//!
//! `<num>` is a JSON number or a string holding a decimal or hex float, read exactly
//! ([`crate::io::numbers`]). `id` is echoed verbatim (`null` if absent). A line that cannot
//! be answered — malformed JSON, an unknown or missing key, a non-finite number, a negative
//! radius — produces no output line and one message on the error stream naming its line
//! number; every other line is still answered. Blank lines are skipped.

use super::numbers::{NumberFormat, format_json, parse_json};
use quadratic::{Ball, Roots};
use serde_json::{Map, Value};
use std::io::{self, BufRead, Write};

/// Which query a JSON-lines stream carries.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Query {
    /// Roots of a·x² + b·x + c.
    Roots,
    /// Contact time of two disks or spheres.
    ContactTime,
}

/// Answers every line of `input` on `output`, reporting bad lines on `errors`.
/// Returns how many lines could not be answered.
pub fn answer_lines<R: BufRead, W: Write, E: Write>(
    query: Query,
    input: R,
    mut output: W,
    mut errors: E,
    format: NumberFormat,
) -> io::Result<usize> {
    let mut failed = 0;
    for (index, line) in input.lines().enumerate() {
        let line = line?;
        if line.trim().is_empty() {
            continue;
        }
        let answer = serde_json::from_str::<Value>(&line)
            .map_err(|e| format!("not valid JSON ({e})"))
            .and_then(|v| match v {
                Value::Object(map) => Ok(map),
                other => Err(format!("expected a JSON object, found {other}")),
            })
            .and_then(|map| match query {
                Query::Roots => answer_roots(&map, format),
                Query::ContactTime => answer_contact(&map, format),
            });
        match answer {
            Ok(text) => writeln!(output, "{text}")?,
            Err(problem) => {
                failed += 1;
                writeln!(errors, "line {}: {problem}", index + 1)?;
            }
        }
    }
    output.flush()?;
    Ok(failed)
}

fn check_keys(map: &Map<String, Value>, allowed: &[&str]) -> Result<(), String> {
    for key in map.keys() {
        if !allowed.contains(&key.as_str()) {
            return Err(format!("unknown key '{key}' (allowed: {})", allowed.join(", ")));
        }
    }
    Ok(())
}

fn number(map: &Map<String, Value>, key: &str) -> Result<f64, String> {
    let value = map.get(key).ok_or_else(|| format!("missing key '{key}'"))?;
    parse_json(value).map_err(|e| format!("{key}: {e}"))
}

fn id_text(map: &Map<String, Value>) -> String {
    map.get("id").map_or_else(|| "null".to_string(), Value::to_string)
}

fn answer_roots(map: &Map<String, Value>, format: NumberFormat) -> Result<String, String> {
    check_keys(map, &["id", "a", "b", "c"])?;
    let (a, b, c) = (number(map, "a")?, number(map, "b")?, number(map, "c")?);
    let roots = quadratic::solve(a, b, c).map_err(|e| e.to_string())?;
    let id = id_text(map);
    Ok(match roots {
        Roots::All => format!("{{\"id\":{id},\"all\":true}}"),
        other => {
            let list: Vec<String> = other.as_vec().into_iter().map(|x| format_json(x, format)).collect();
            format!("{{\"id\":{id},\"roots\":[{}]}}", list.join(","))
        }
    })
}

fn vector(map: &Map<String, Value>, key: &str) -> Result<Vec<f64>, String> {
    let value = map.get(key).ok_or_else(|| format!("missing key '{key}'"))?;
    let items = value.as_array().ok_or_else(|| format!("{key}: expected an array like [x, y], found {value}"))?;
    items.iter().enumerate().map(|(i, v)| parse_json(v).map_err(|e| format!("{key}[{i}]: {e}"))).collect()
}

fn answer_contact(map: &Map<String, Value>, format: NumberFormat) -> Result<String, String> {
    check_keys(map, &["id", "r1", "v1", "R1", "r2", "v2", "R2"])?;
    let first = DynBall { position: vector(map, "r1")?, velocity: vector(map, "v1")?, radius: number(map, "R1")? };
    let second = DynBall { position: vector(map, "r2")?, velocity: vector(map, "v2")?, radius: number(map, "R2")? };
    let time = contact_time_dyn(&first, &second)?;
    let t = time.map_or_else(|| "null".to_string(), |t| format_json(t, format));
    Ok(format!("{{\"id\":{},\"t\":{t}}}", id_text(map)))
}

/// A disk (or sphere) whose dimension is known only at run time.
#[derive(Clone, Debug, PartialEq)]
pub struct DynBall {
    /// Position, 2 or 3 components.
    pub position: Vec<f64>,
    /// Velocity, as many components as the position.
    pub velocity: Vec<f64>,
    /// Radius.
    pub radius: f64,
}

/// The contact time of two balls given at run time: 2 or 3 components, all the same length.
/// `Ok(None)` is "never"; `Ok(Some(0.0))` is "now".
pub fn contact_time_dyn(first: &DynBall, second: &DynBall) -> Result<Option<f64>, String> {
    let d = first.position.len();
    for (name, v) in [("v1", &first.velocity), ("r2", &second.position), ("v2", &second.velocity)] {
        if v.len() != d {
            return Err(format!("{name} has {} components but r1 has {d}; all vectors need the same", v.len()));
        }
    }
    fn fixed<const D: usize>(b: &DynBall) -> Ball<D> {
        let arr = |s: &[f64]| -> [f64; D] { s.try_into().expect("length checked") };
        Ball { position: arr(&b.position), velocity: arr(&b.velocity), radius: b.radius }
    }
    let contact = match d {
        2 => quadratic::contact_time(&fixed::<2>(first), &fixed::<2>(second)),
        3 => quadratic::contact_time(&fixed::<3>(first), &fixed::<3>(second)),
        _ => return Err(format!("vectors must have 2 (disks) or 3 (spheres) components, r1 has {d}")),
    };
    contact.map(|c| c.time()).map_err(|e| e.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run(query: Query, input: &str, format: NumberFormat) -> (String, String, usize) {
        let mut out = Vec::new();
        let mut err = Vec::new();
        let failed = answer_lines(query, input.as_bytes(), &mut out, &mut err, format).unwrap();
        (String::from_utf8(out).unwrap(), String::from_utf8(err).unwrap(), failed)
    }

    #[test]
    fn roots_lines_are_answered_and_bad_lines_reported() {
        let input = concat!(
            "{\"id\": 1, \"a\": 1, \"b\": -3, \"c\": 2}\n",
            "{\"id\": \"two\", \"a\": \"0x1p0\", \"b\": \"-6\", \"c\": 9}\n",
            "not json\n",
            "\n",
            "{\"id\": [3], \"a\": 0, \"b\": 0, \"c\": 0}\n",
            "{\"id\": 4, \"a\": 1, \"b\": 0, \"c\": 1}\n",
            "{\"id\": 5, \"a\": 1, \"b\": 0}\n",
            "{\"id\": 6, \"a\": 1e999, \"b\": 0, \"c\": 1}\n",
            "{\"id\": 7, \"a\": 1, \"b\": 0, \"c\": 1, \"d\": 2}\n",
            "{\"id\": 1.50, \"a\": 0, \"b\": 2, \"c\": -1}\n",
        );
        let (out, err, failed) = run(Query::Roots, input, NumberFormat::Shortest);
        assert_eq!(
            out,
            concat!(
                "{\"id\":1,\"roots\":[1.0,2.0]}\n",
                "{\"id\":\"two\",\"roots\":[3.0]}\n",
                "{\"id\":[3],\"all\":true}\n",
                "{\"id\":4,\"roots\":[]}\n",
                "{\"id\":1.50,\"roots\":[0.5]}\n",
            )
        );
        assert_eq!(failed, 4);
        let lines: Vec<&str> = err.lines().collect();
        assert!(lines[0].starts_with("line 3: not valid JSON"), "{err}");
        assert_eq!(lines[1], "line 7: missing key 'c'");
        assert!(lines[2].starts_with("line 8: a: '1e") && lines[2].ends_with("999' is not a finite f64"), "{err}");
        assert!(lines[3].starts_with("line 9: unknown key 'd'"), "{err}");
    }

    #[test]
    fn contact_lines_in_2d_and_3d_with_hex_output() {
        let input = concat!(
            "{\"id\": 1, \"r1\": [0, 0], \"v1\": [1, 0], \"R1\": 0.5, \"r2\": [3, 0], \"v2\": [-1, 0], \"R2\": 0.5}\n",
            "{\"id\": 2, \"r1\": [0, 0, 0], \"v1\": [0, 0, 0], \"R1\": 1, \"r2\": [5, 0, 0], \"v2\": [1, 0, 0], \"R2\": 1}\n",
            "{\"id\": 3, \"r1\": [0, 0], \"v1\": [1, 0], \"R1\": 1, \"r2\": [1, 0], \"v2\": [0, 0], \"R2\": 1}\n",
            "{\"id\": 4, \"r1\": [0, 0], \"v1\": [1, 0], \"R1\": -1, \"r2\": [1, 0], \"v2\": [0, 0], \"R2\": 1}\n",
            "{\"id\": 5, \"r1\": [0, 0], \"v1\": [1, 0, 0], \"R1\": 1, \"r2\": [1, 0], \"v2\": [0, 0], \"R2\": 1}\n",
        );
        let (out, err, failed) = run(Query::ContactTime, input, NumberFormat::Hex);
        assert_eq!(out, "{\"id\":1,\"t\":\"0x1p+0\"}\n{\"id\":2,\"t\":null}\n{\"id\":3,\"t\":\"0x0p+0\"}\n");
        assert_eq!(failed, 2);
        assert!(err.contains("line 4: R1 = -1 is negative"), "{err}");
        assert!(err.contains("line 5: v1 has 3 components but r1 has 2"), "{err}");
    }
}
