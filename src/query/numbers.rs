//! Numbers in and out, exactly.
//!
//! Input: a decimal (`0.1`, `-1e-300`) or a C99 hex float (`0x1.8p+1`), as text or as a JSON
//! number or string. Decimals go through Rust's `str::parse::<f64>`, which is correctly
//! rounded (round to nearest, ties to even) for any number of digits; hex floats through
//! [`quadratic::hex::parse`], also correctly rounded. Output: the shortest decimal that
//! round-trips (`ryu`, via serde_json), or an exact hex float.

use serde_json::Value;
use std::fmt;

/// How output numbers are written.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum NumberFormat {
    /// The shortest decimal that reads back to the same f64 (`0.1`, `1e-300`).
    #[default]
    Shortest,
    /// An exact C99 hex float (`0x1.999999999999ap-4`).
    Hex,
}

/// A number that could not be read.
#[derive(Clone, Debug, PartialEq)]
pub enum NumberError {
    /// Not a decimal or hex-float number.
    Malformed(String),
    /// Parsed, but NaN or infinite (an overflowing decimal such as `1e400` lands here too).
    NonFinite(String),
    /// A JSON value of the wrong type.
    NotANumber(String),
}

impl fmt::Display for NumberError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            NumberError::Malformed(s) => {
                write!(f, "'{s}' is not a number (expected a decimal such as 0.5 or a hex float such as 0x1p-1)")
            }
            NumberError::NonFinite(s) => write!(f, "'{s}' is not a finite f64"),
            NumberError::NotANumber(s) => write!(f, "{s} is not a number or a string holding one"),
        }
    }
}

impl std::error::Error for NumberError {}

/// Parses a decimal or hex-float literal, correctly rounded; rejects NaN and ±∞.
pub fn parse_text(text: &str) -> Result<f64, NumberError> {
    let t = text.trim();
    let body = t.strip_prefix(['-', '+']).unwrap_or(t);
    let value = if body.starts_with("0x") || body.starts_with("0X") {
        quadratic::hex::parse(t).map_err(|_| NumberError::Malformed(text.to_string()))?
    } else {
        // Rust also accepts "inf"/"nan"/"infinity": those are caught as non-finite below.
        t.parse::<f64>().map_err(|_| NumberError::Malformed(text.to_string()))?
    };
    if value.is_finite() { Ok(value) } else { Err(NumberError::NonFinite(text.to_string())) }
}

/// Reads a JSON number (its exact source text, thanks to serde_json's `arbitrary_precision`)
/// or a string holding a decimal or hex float.
pub fn parse_json(value: &Value) -> Result<f64, NumberError> {
    match value {
        Value::Number(n) => parse_text(&n.to_string()),
        Value::String(s) => parse_text(s),
        other => Err(NumberError::NotANumber(other.to_string())),
    }
}

/// Formats `x` as a JSON value's text: a bare number (shortest round-trip) or a quoted hex
/// string; `±∞` (an overflowing root or time) as the string `"inf"` or `"-inf"`, in either
/// format, since JSON has no infinity (`NaN` never arises: inputs are finite).
pub fn format_json(x: f64, format: NumberFormat) -> String {
    if x.is_infinite() {
        return if x > 0.0 { "\"inf\"".to_string() } else { "\"-inf\"".to_string() };
    }
    match format {
        NumberFormat::Shortest => format_plain(x),
        NumberFormat::Hex => format!("\"{}\"", quadratic::hex::format(x)),
    }
}

/// Formats `x` for plain text output: the shortest round-trip decimal, or a bare hex float.
pub fn format_text(x: f64, format: NumberFormat) -> String {
    match format {
        NumberFormat::Shortest => format_plain(x),
        NumberFormat::Hex => quadratic::hex::format(x),
    }
}

fn format_plain(x: f64) -> String {
    match serde_json::Number::from_f64(x) {
        Some(n) => n.to_string(),
        None => x.to_string(), // ±inf in plain text (JSON output never comes here)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn decimal_and_hex_inputs_are_correctly_rounded() {
        assert_eq!(parse_text("0.1").unwrap(), 0.1);
        assert_eq!(parse_text(" -0x1.8p+1 ").unwrap(), -3.0);
        // Halfway between 1 and 1 + 2⁻⁵², then a hair above: must round up.
        assert_eq!(parse_text("1.00000000000000011102230246251565404236316680908203125").unwrap(), 1.0);
        assert_eq!(
            parse_text("1.000000000000000111022302462515654042363166809082031250001").unwrap(),
            1.0 + f64::EPSILON
        );
        assert_eq!(parse_text("4.9406564584124654e-324").unwrap(), f64::from_bits(1));
        assert!(matches!(parse_text("1e400"), Err(NumberError::NonFinite(_))));
        assert!(matches!(parse_text("nan"), Err(NumberError::NonFinite(_))));
        assert!(matches!(parse_text("1,5"), Err(NumberError::Malformed(_))));
        assert!(matches!(parse_text("0xzz"), Err(NumberError::Malformed(_))));
    }

    #[test]
    fn json_numbers_keep_their_exact_text() {
        // A 17+ digit literal that a fast float parser may misround.
        let v: Value = serde_json::from_str("2.2250738585072011e-308").unwrap();
        assert_eq!(parse_json(&v).unwrap(), "2.2250738585072011e-308".parse::<f64>().unwrap());
        let v: Value = serde_json::from_str("\"0x1p-1074\"").unwrap();
        assert_eq!(parse_json(&v).unwrap(), f64::from_bits(1));
        assert!(matches!(parse_json(&Value::Bool(true)), Err(NumberError::NotANumber(_))));
    }

    #[test]
    fn output_is_shortest_round_trip_or_exact_hex() {
        assert_eq!(format_json(0.1, NumberFormat::Shortest), "0.1");
        assert_eq!(format_json(1e-300, NumberFormat::Shortest), "1e-300");
        assert_eq!(format_json(3.0, NumberFormat::Hex), "\"0x1.8p+1\"");
        for x in [0.1, 1.0 / 3.0, 5e-324, 1.7976931348623157e308, -2.5] {
            let s = format_json(x, NumberFormat::Shortest);
            assert_eq!(s.parse::<f64>().unwrap().to_bits(), x.to_bits(), "{s}");
        }
    }
}
