//! The size of the processor's level-2 cache, which sets where the lookahead pays
//! ([`Simulation`](crate::engine::Simulation) prefetches the next event's data only once the engine's
//! state has left that cache). Timing only: the events are the same bit for bit whatever it
//! is, and wherever it cannot be read.

use std::sync::OnceLock;

/// The size in bytes of the first CPU's unified level-2 cache, as Linux reports it under
/// `/sys/devices/system/cpu/cpu0/cache/index*/` (`level`, `type`, `size`); `None` on other
/// systems or when it cannot be read. Read once per process.
pub(crate) fn level2_bytes() -> Option<usize> {
    static SIZE: OnceLock<Option<usize>> = OnceLock::new();
    *SIZE.get_or_init(|| {
        let read = |dir: &std::path::Path, file: &str| std::fs::read_to_string(dir.join(file)).ok();
        let entries = std::fs::read_dir("/sys/devices/system/cpu/cpu0/cache").ok()?;
        entries.filter_map(Result::ok).map(|e| e.path()).find_map(|dir| {
            let level2 = read(&dir, "level")?.trim() == "2";
            let unified = read(&dir, "type")?.trim() == "Unified";
            if level2 && unified { parse_size(read(&dir, "size")?.trim()) } else { None }
        })
    })
}

/// A cache size as sysfs writes it: bytes, or a number with `K`, `M` or `G` (powers of 1024).
pub(crate) fn parse_size(text: &str) -> Option<usize> {
    let (digits, unit) = match text.char_indices().last()? {
        (at, 'K') => (&text[..at], 1 << 10),
        (at, 'M') => (&text[..at], 1 << 20),
        (at, 'G') => (&text[..at], 1 << 30),
        _ => (text, 1),
    };
    digits.parse::<usize>().ok()?.checked_mul(unit).filter(|&bytes| bytes > 0)
}

#[cfg(test)]
mod tests {
    use super::parse_size;

    /// The forms sysfs uses, and what is not a size.
    #[test]
    fn sizes_parse_as_sysfs_writes_them() {
        assert_eq!(parse_size("2048K"), Some(2 << 20));
        assert_eq!(parse_size("307200K"), Some(300 << 20));
        assert_eq!(parse_size("1M"), Some(1 << 20));
        assert_eq!(parse_size("1G"), Some(1 << 30));
        assert_eq!(parse_size("65536"), Some(65536));
        for bad in ["", "K", "0K", "-1K", "2 MB", "1.5M", "x"] {
            assert_eq!(parse_size(bad), None, "{bad:?}");
        }
    }
}
