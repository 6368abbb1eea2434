//! C99 hexadecimal floating-point literals (`0x1.8p+1` = 3): exact text for f64.
//!
//! [`format`](fn@format) writes the shortest exact form (`printf("%a")` style, normalised, subnormals as
//! `0x0.…p-1022`); [`parse`] reads any C99 hex literal, correctly rounded to nearest-even.

use core::fmt;

/// Why a hex-float literal was rejected.
#[non_exhaustive]
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum HexError {
    /// The text is not of the form `[±]0x<hex digits>[.<hex digits>][p[±]<decimal>]`.
    Malformed(String),
}

impl fmt::Display for HexError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            HexError::Malformed(s) => {
                write!(f, "'{s}' is not a hex float (expected e.g. 0x1.8p+1)")
            }
        }
    }
}

impl std::error::Error for HexError {}

/// `x` as an exact C99 hex literal: `0x1.8p+1`, `-0x1p-1074` is written `-0x0.0000000000001p-1022`,
/// `0x0p+0`, `inf`, `nan`.
pub fn format(x: f64) -> String {
    if x.is_nan() {
        return "nan".into();
    }
    let sign = if x.is_sign_negative() { "-" } else { "" };
    if x.is_infinite() {
        return format!("{sign}inf");
    }
    let bits = x.to_bits();
    let biased = ((bits >> 52) & 0x7ff) as i32;
    let frac = bits & ((1u64 << 52) - 1);
    if biased == 0 && frac == 0 {
        return format!("{sign}0x0p+0");
    }
    let (lead, exp) = if biased == 0 { (0, -1022) } else { (1, biased - 1023) };
    let mut digits = format!("{frac:013x}");
    while digits.ends_with('0') {
        digits.pop();
    }
    let dot = if digits.is_empty() { String::new() } else { format!(".{digits}") };
    format!("{sign}0x{lead}{dot}p{exp:+}")
}

/// Parses a C99 hex literal, correctly rounded (ties to even); overflow gives ±∞.
pub fn parse(text: &str) -> Result<f64, HexError> {
    let bad = || HexError::Malformed(text.to_string());
    let s = text.trim();
    let (neg, s) = match s.as_bytes().first() {
        Some(b'-') => (true, &s[1..]),
        Some(b'+') => (false, &s[1..]),
        _ => (false, s),
    };
    let s = s.strip_prefix("0x").or_else(|| s.strip_prefix("0X")).ok_or_else(bad)?;
    let (mant, exp) = match s.find(['p', 'P']) {
        Some(i) => (&s[..i], &s[i + 1..]),
        None => (s, "0"),
    };
    let exp: i64 = {
        let e = exp.strip_prefix('+').unwrap_or(exp);
        if e.is_empty() || !e.trim_start_matches('-').bytes().all(|b| b.is_ascii_digit()) {
            return Err(bad());
        }
        e.parse::<i64>().unwrap_or(if e.starts_with('-') { i64::MIN / 4 } else { i64::MAX / 4 })
    };
    let (int, frac) = match mant.find('.') {
        Some(i) => (&mant[..i], &mant[i + 1..]),
        None => (mant, ""),
    };
    if int.is_empty() && frac.is_empty() {
        return Err(bad());
    }
    // Accumulate up to 60 significant bits; everything beyond is a sticky bit.
    let mut m: u64 = 0;
    let mut bin_exp: i64 = exp;
    let mut sticky = false;
    for (i, ch) in int.chars().chain(frac.chars()).enumerate() {
        let d = ch.to_digit(16).ok_or_else(bad)? as u64;
        let in_frac = i >= int.len();
        if m >> 56 == 0 {
            m = (m << 4) | d;
            if in_frac {
                bin_exp -= 4;
            }
        } else {
            sticky |= d != 0;
            if !in_frac {
                bin_exp += 4;
            }
        }
    }
    let value = if m == 0 { 0.0 } else { round_to_f64(m, sticky, bin_exp) };
    Ok(if neg { -value } else { value })
}

/// The f64 nearest to `(m + ε)·2^e` where `ε ∈ (0, 1)` iff `sticky`, `m > 0`.
fn round_to_f64(m: u64, sticky: bool, e: i64) -> f64 {
    let top = 63 - m.leading_zeros() as i64; // value in [2^(top+e), 2^(top+e+1))
    let exp = top + e;
    if exp > 1023 {
        return f64::INFINITY;
    }
    // Bits kept: 53 for normals, fewer for subnormals (lsb weight 2^-1074).
    let lsb_exp = (exp - 52).max(-1074);
    let shift = lsb_exp - e; // how many low bits of m drop
    let (mut q, rem_half, rem_rest) = if shift <= 0 {
        (m << (-shift).min(63), false, sticky)
    } else if shift > 64 {
        (0, false, true)
    } else {
        let q = if shift == 64 { 0 } else { m >> shift };
        let dropped = if shift == 64 { m } else { m & ((1u64 << shift) - 1) };
        let half = 1u64 << (shift - 1);
        (q, dropped & half != 0, (dropped & (half - 1)) != 0 || sticky)
    };
    if rem_half && (rem_rest || q & 1 == 1) {
        q += 1;
    }
    // q·2^lsb_exp, q < 2^54: exact unless it overflows.
    crate::exact::scale2(q as f64, lsb_exp as i32)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trips_and_known_values() {
        for x in [1.0, 3.0, 0.1, -2.5e-300, f64::MAX, f64::MIN_POSITIVE, f64::from_bits(1), 1e-310] {
            assert_eq!(parse(&format(x)).unwrap().to_bits(), x.to_bits(), "{}", format(x));
        }
        assert_eq!(format(3.0), "0x1.8p+1");
        assert_eq!(format(f64::from_bits(1)), "0x0.0000000000001p-1022");
        assert_eq!(parse("0x1p-1074").unwrap(), f64::from_bits(1));
        assert_eq!(parse("0x1p-1075").unwrap(), 0.0); // tie to even
        assert_eq!(parse("0x1.8p-1074").unwrap(), f64::from_bits(2)); // tie to even
        assert_eq!(parse("0x1.00000000000008p+0").unwrap(), 1.0); // tie to even
        assert_eq!(parse("0x1.000000000000080000001p+0").unwrap(), 1.0 + f64::EPSILON);
        assert_eq!(parse("-0X.8P1").unwrap(), -1.0);
        assert_eq!(parse("0x1p1024").unwrap(), f64::INFINITY);
        assert!(parse("1.5").is_err());
        assert!(parse("0x").is_err());
        assert!(parse("0x1.g").is_err());
    }
}
