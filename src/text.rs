//! Messages about a user's input: short, on one line, never echoing a whole value.
//!
//! A message may quote what it refuses, but a quoted value longer than [`QUOTE`] characters
//! is cut to its start and its length (a 50 MB string in a configuration once produced
//! 157 MB of error text), and the whole message is capped at [`MESSAGE`] characters.

/// The longest quotation kept whole.
pub const QUOTE: usize = 48;

/// The longest message.
pub const MESSAGE: usize = 600;

/// `text` if it is at most [`QUOTE`] characters, else its start, an ellipsis and its size.
pub fn excerpt(text: &str) -> String {
    if text.chars().count() <= QUOTE {
        return text.to_string();
    }
    let start: String = text.chars().take(QUOTE / 2).collect();
    format!("{start}… ({} bytes)", text.len())
}

/// `message` on one line, every quotation in it (between backticks, or double or single
/// quotes) cut with [`excerpt`], and the whole cut to [`MESSAGE`] characters.
pub fn shorten(message: &str) -> String {
    let one_line = message.trim_end().replace(['\n', '\r'], " ");
    let mut out = String::with_capacity(one_line.len().min(2 * MESSAGE));
    let mut rest = one_line.as_str();
    while let Some(open) = rest.find(['`', '"', '\'']) {
        let quote = rest[open..].chars().next().expect("found");
        out.push_str(&rest[..=open]);
        rest = &rest[open + 1..];
        match rest.find(quote) {
            Some(close) => {
                out.push_str(&excerpt(&rest[..close]));
                out.push(quote);
                rest = &rest[close + 1..];
            }
            None => {
                out.push_str(&excerpt(rest));
                rest = "";
            }
        }
        if out.len() > 4 * MESSAGE {
            break;
        }
    }
    out.push_str(rest);
    if out.chars().count() > MESSAGE {
        let cut: String = out.chars().take(MESSAGE).collect();
        return format!("{cut}… (message cut)");
    }
    out
}

/// `x` for a message: the shortest decimal that reads back to it, in scientific notation
/// when it is very small or very large (`1e-300`, not three hundred zeros).
pub fn num(x: f64) -> String {
    if x != 0.0 && x.is_finite() && (x.abs() < 1e-4 || x.abs() >= 1e16) { format!("{x:e}") } else { format!("{x}") }
}

/// Line and column (both from 1, columns in characters) of byte `offset` in `text`.
pub fn line_column(text: &str, offset: usize) -> (usize, usize) {
    let offset = offset.min(text.len());
    let offset = (0..=offset).rev().find(|&k| text.is_char_boundary(k)).unwrap_or(0);
    let before = &text[..offset];
    let line = before.matches('\n').count() + 1;
    let start = before.rfind('\n').map_or(0, |k| k + 1);
    (line, before[start..].chars().count() + 1)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn long_quotations_are_cut_and_short_ones_kept() {
        let long = "x".repeat(50_000_000);
        let message = format!("unknown variant `{long}`, expected `random`, `triangular` or `square`");
        let short = shorten(&message);
        assert!(short.len() < 200, "{} bytes", short.len());
        assert!(short.contains("(50000000 bytes)`") && short.contains("`random`"), "{short}");
        assert_eq!(shorten("a 'b' \"c\" `d`\nsecond line"), "a 'b' \"c\" `d` second line");
        assert!(shorten(&"y".repeat(10_000)).ends_with("… (message cut)"));
        assert_eq!(excerpt("ab"), "ab");
    }

    #[test]
    fn numbers_are_short_and_exact() {
        assert_eq!(num(1e-300), "1e-300");
        assert_eq!(num(0.1), "0.1");
        assert_eq!(num(-2.5e20), "-2.5e20");
        assert_eq!(num(f64::NAN), "NaN");
        assert_eq!(num(0.0), "0");
        assert_eq!(num(1e-9).parse::<f64>().unwrap(), 1e-9);
    }

    #[test]
    fn positions_are_lines_and_columns() {
        let text = "a = 1\nbé = 2\n";
        assert_eq!(line_column(text, 0), (1, 1));
        assert_eq!(line_column(text, 6), (2, 1));
        assert_eq!(line_column(text, 9), (2, 3));
        assert_eq!(line_column(text, 1000), (3, 1));
    }
}
