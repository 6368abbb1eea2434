//! The JSON-lines query protocol: one request per input line, one answer per line out.
//!
//! * `roots`: `{"id": <any>, "a": <num>, "b": <num>, "c": <num>}` →
//!   `{"id": <same>, "roots": [x1, x2]}` (ascending; `[]` for none; one element for one root)
//!   or `{"id": <same>, "all": true}` when every x solves `0 = 0`.
//! * `contact-time`: `{"id": <any>, "r1": [x, y], "v1": [..], "R1": <num>, "r2": [..],
//!   "v2": [..], "R2": <num>}` (2 or 3 components, the same for all four vectors), and
//!   optionally `"g1"`, `"g2"`: the growth rates of `R1` and `R2` (radius `R + g·t`, default
//!   0, each ≥ 0) → `{"id": <same>, "t": <num or null>}` (`null` = never, `0` = now).
//!   With growth the answer is [`quadratic::contact_time_growing`]'s; without, it is
//!   [`quadratic::contact_time`]'s, bit for bit.
//!
//! `<num>` is a JSON number or a string holding a decimal or hex float, read exactly
//! ([`super::numbers`]). An output number beyond the f64 range (a root or a time that
//! overflows) is the string `"inf"` (or `"-inf"`): JSON has no infinity, and every line
//! out is strict JSON. `id` is echoed verbatim, as its source text (`null` if absent).
//!
//! A line that cannot be answered — not UTF-8, longer than [`MAX_LINE`] bytes, malformed
//! JSON, a duplicate, unknown or missing key, a non-finite number, a negative radius or
//! growth rate —
//! produces no output line and one short message on the error stream naming its line
//! number; every other line is still answered. Blank lines are skipped.

use super::numbers::{NumberFormat, format_json, parse_json};
use crate::text::shorten;
use quadratic::{Ball, Roots};
use serde_json::Value;
use serde_json::value::RawValue;
use std::io::{self, BufRead, Write};

/// The longest input line answered, bytes (a request is a few hundred).
pub const MAX_LINE: usize = 1 << 20;

/// The keys of one request, each with its value's source text, in order; a key given twice
/// is refused (JSON leaves duplicates undefined, and serde_json would keep the last).
struct Fields<'a>(Vec<(String, &'a RawValue)>);

impl<'de: 'a, 'a> serde::Deserialize<'de> for Fields<'a> {
    fn deserialize<D: serde::Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        struct Object;
        impl<'de> serde::de::Visitor<'de> for Object {
            type Value = Fields<'de>;
            fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                f.write_str("a JSON object")
            }
            fn visit_map<M: serde::de::MapAccess<'de>>(self, mut map: M) -> Result<Fields<'de>, M::Error> {
                let mut fields: Vec<(String, &'de RawValue)> = Vec::new();
                while let Some(key) = map.next_key::<String>()? {
                    if fields.iter().any(|(k, _)| *k == key) {
                        return Err(serde::de::Error::custom(format!("key '{key}' given twice")));
                    }
                    fields.push((key, map.next_value()?));
                }
                Ok(Fields(fields))
            }
        }
        deserializer.deserialize_map(Object)
    }
}

impl Fields<'_> {
    fn raw(&self, key: &str) -> Option<&RawValue> {
        self.0.iter().find(|(k, _)| k == key).map(|(_, v)| *v)
    }

    fn get(&self, key: &str) -> Result<Value, String> {
        let raw = self.raw(key).ok_or_else(|| format!("missing key '{key}'"))?;
        serde_json::from_str(raw.get()).map_err(|e| format!("{key}: {e}"))
    }
}

/// Reads one line into `buf` (without its end), keeping at most `cap` bytes; returns the
/// bytes read (0 at the end of the input) and whether the line was longer than `cap`.
fn read_line<R: BufRead>(input: &mut R, buf: &mut Vec<u8>, cap: usize) -> io::Result<(usize, bool)> {
    buf.clear();
    let (mut read, mut long) = (0, false);
    loop {
        let chunk = match input.fill_buf() {
            Ok(chunk) => chunk,
            Err(e) if e.kind() == io::ErrorKind::Interrupted => continue,
            Err(e) => return Err(e),
        };
        if chunk.is_empty() {
            break;
        }
        let (take, end) = match chunk.iter().position(|&b| b == b'\n') {
            Some(k) => (k + 1, true),
            None => (chunk.len(), false),
        };
        let room = cap.saturating_sub(buf.len());
        buf.extend_from_slice(&chunk[..take.min(room)]);
        long |= take > room;
        read += take;
        input.consume(take);
        if end {
            break;
        }
    }
    while buf.last().is_some_and(|&b| b == b'\n' || b == b'\r') {
        buf.pop();
    }
    Ok((read, long))
}

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
    let mut buf = Vec::new();
    let mut input = input;
    for index in 1.. {
        let (read, long) = read_line(&mut input, &mut buf, MAX_LINE)?;
        if read == 0 {
            break;
        }
        let answer = if long {
            Err(format!("longer than {MAX_LINE} bytes (a request is a few hundred)"))
        } else {
            match std::str::from_utf8(&buf) {
                Err(e) => Err(format!("not valid UTF-8 (byte {})", e.valid_up_to() + 1)),
                Ok(line) if line.trim().is_empty() => continue,
                Ok(line) => answer_line(query, line, format),
            }
        };
        match answer {
            Ok(text) => writeln!(output, "{text}")?,
            Err(problem) => {
                failed += 1;
                writeln!(errors, "line {index}: {}", shorten(&problem))?;
            }
        }
    }
    output.flush()?;
    Ok(failed)
}

fn answer_line(query: Query, line: &str, format: NumberFormat) -> Result<String, String> {
    let fields: Fields = serde_json::from_str(line).map_err(|e| format!("not valid JSON ({e})"))?;
    match query {
        Query::Roots => answer_roots(&fields, format),
        Query::ContactTime => answer_contact(&fields, format),
    }
}

fn check_keys(fields: &Fields, allowed: &[&str]) -> Result<(), String> {
    for (key, _) in &fields.0 {
        if !allowed.contains(&key.as_str()) {
            return Err(format!("unknown key '{key}' (allowed: {})", allowed.join(", ")));
        }
    }
    Ok(())
}

fn number(fields: &Fields, key: &str) -> Result<f64, String> {
    parse_json(&fields.get(key)?).map_err(|e| format!("{key}: {e}"))
}

/// The id's source text, exactly as given (`null` if absent).
fn id_text(fields: &Fields) -> String {
    fields.raw("id").map_or_else(|| "null".to_string(), |raw| raw.get().trim().to_string())
}

fn answer_roots(fields: &Fields, format: NumberFormat) -> Result<String, String> {
    check_keys(fields, &["id", "a", "b", "c"])?;
    let (a, b, c) = (number(fields, "a")?, number(fields, "b")?, number(fields, "c")?);
    let roots = quadratic::solve(a, b, c).map_err(|e| e.to_string())?;
    let id = id_text(fields);
    Ok(match roots {
        Roots::All => format!("{{\"id\":{id},\"all\":true}}"),
        other => {
            let list: Vec<String> = other.as_vec().into_iter().map(|x| format_json(x, format)).collect();
            format!("{{\"id\":{id},\"roots\":[{}]}}", list.join(","))
        }
    })
}

fn vector(fields: &Fields, key: &str) -> Result<Vec<f64>, String> {
    let value = fields.get(key)?;
    let items = value.as_array().ok_or_else(|| format!("{key}: expected an array like [x, y], found {value}"))?;
    items.iter().enumerate().map(|(i, v)| parse_json(v).map_err(|e| format!("{key}[{i}]: {e}"))).collect()
}

fn answer_contact(fields: &Fields, format: NumberFormat) -> Result<String, String> {
    check_keys(fields, &["id", "r1", "v1", "R1", "r2", "v2", "R2", "g1", "g2"])?;
    let first =
        DynBall { position: vector(fields, "r1")?, velocity: vector(fields, "v1")?, radius: number(fields, "R1")? };
    let second =
        DynBall { position: vector(fields, "r2")?, velocity: vector(fields, "v2")?, radius: number(fields, "R2")? };
    let rate = |key: &str| if fields.raw(key).is_some() { number(fields, key) } else { Ok(0.0) };
    let rates = [rate("g1")?, rate("g2")?];
    let time = contact_time_dyn(&first, &second, rates).map_err(|e| e.to_string())?;
    let t = time.map_or_else(|| "null".to_string(), |t| format_json(t, format));
    Ok(format!("{{\"id\":{},\"t\":{t}}}", id_text(fields)))
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

/// Why two balls given at run time have no contact time.
#[non_exhaustive]
#[derive(Clone, Debug, PartialEq)]
pub enum QueryError {
    /// A vector with another number of components than `r1`'s.
    Components {
        /// The vector (`v1`, `r2` or `v2`).
        field: &'static str,
        /// Its components.
        found: usize,
        /// `r1`'s.
        expected: usize,
    },
    /// Neither 2 nor 3 components.
    Dimension {
        /// `r1`'s components.
        found: usize,
    },
    /// The kernel refused the balls (a negative or non-finite radius or growth rate, a
    /// non-finite coordinate).
    Contact(quadratic::ContactError),
}

impl std::fmt::Display for QueryError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            QueryError::Components { field, found, expected } => {
                write!(f, "{field} has {found} components but r1 has {expected}; all vectors need the same")
            }
            QueryError::Dimension { found } => {
                write!(f, "vectors must have 2 (disks) or 3 (spheres) components, r1 has {found}")
            }
            QueryError::Contact(e) => write!(f, "{e}"),
        }
    }
}

impl std::error::Error for QueryError {}

/// The contact time of two balls given at run time, 2 or 3 components, all the same length,
/// whose radii grow at `rates` (`[0.0, 0.0]`: rigid balls, [`quadratic::contact_time`] bit for
/// bit). `Ok(None)` is "never"; `Ok(Some(0.0))` is "now".
pub fn contact_time_dyn(first: &DynBall, second: &DynBall, rates: [f64; 2]) -> Result<Option<f64>, QueryError> {
    let d = first.position.len();
    for (field, v) in [("v1", &first.velocity), ("r2", &second.position), ("v2", &second.velocity)] {
        if v.len() != d {
            return Err(QueryError::Components { field, found: v.len(), expected: d });
        }
    }
    fn fixed<const D: usize>(b: &DynBall) -> Ball<D> {
        let arr = |s: &[f64]| -> [f64; D] { s.try_into().expect("length checked") };
        Ball { position: arr(&b.position), velocity: arr(&b.velocity), radius: b.radius }
    }
    let contact = match d {
        2 => quadratic::contact_time_growing(&fixed::<2>(first), &fixed::<2>(second), rates),
        3 => quadratic::contact_time_growing(&fixed::<3>(first), &fixed::<3>(second), rates),
        _ => return Err(QueryError::Dimension { found: d }),
    };
    contact.map(|c| c.time()).map_err(QueryError::Contact)
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

    #[test]
    fn growth_rates_are_optional_keys() {
        let input = concat!(
            // At rest 3 apart, σ = 1 + t: t = 2; the same without rates: never.
            "{\"id\": 1, \"r1\": [0, 0], \"v1\": [0, 0], \"R1\": 0.5, \"r2\": [3, 0], \"v2\": [0, 0], \"R2\": 0.5, \"g1\": 0.5, \"g2\": \"0x1p-1\"}\n",
            "{\"id\": 2, \"r1\": [0, 0], \"v1\": [0, 0], \"R1\": 0.5, \"r2\": [3, 0], \"v2\": [0, 0], \"R2\": 0.5}\n",
            // Spheres, one growing: 2 − 1 = t at t = 1.
            "{\"id\": 3, \"r1\": [0, 0, 0], \"v1\": [0, 0, 0], \"R1\": 0.5, \"r2\": [0, 0, 2], \"v2\": [0, 0, 0], \"R2\": 0.5, \"g2\": 1}\n",
            "{\"id\": 4, \"r1\": [0, 0], \"v1\": [0, 0], \"R1\": 0.5, \"r2\": [3, 0], \"v2\": [0, 0], \"R2\": 0.5, \"g2\": -1}\n",
            "{\"id\": 5, \"r1\": [0, 0], \"v1\": [0, 0], \"R1\": 0.5, \"r2\": [3, 0], \"v2\": [0, 0], \"R2\": 0.5, \"g1\": \"nan\"}\n",
            "{\"id\": 6, \"r1\": [0, 0], \"v1\": [0, 0], \"R1\": 0.5, \"r2\": [3, 0], \"v2\": [0, 0], \"R2\": 0.5, \"g3\": 1}\n",
        );
        let (out, err, failed) = run(Query::ContactTime, input, NumberFormat::Shortest);
        assert_eq!(out, "{\"id\":1,\"t\":2.0}\n{\"id\":2,\"t\":null}\n{\"id\":3,\"t\":1.0}\n");
        assert_eq!(failed, 3);
        assert!(err.contains("line 4: g2 = -1 is negative; a growth rate must be ≥ 0"), "{err}");
        assert!(err.contains("line 5: g1: "), "{err}");
        assert!(err.contains("line 6: unknown key 'g3' (allowed: id, r1, v1, R1, r2, v2, R2, g1, g2)"), "{err}");
    }
}
