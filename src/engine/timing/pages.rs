//! Huge pages for the engine's large arrays.
//!
//! At large N nearly every access of an event's data goes to a random place in arrays of
//! tens of megabytes; with 4 KB pages it then misses the TLB as well as the cache, and the
//! page walk delays even the lookahead's prefetches. Linux backs memory with 2 MB pages when
//! asked (`madvise(MADV_HUGEPAGE)` where `/sys/kernel/mm/transparent_hugepage/enabled` is
//! `madvise`; unasked under `always`). The kernel chooses the page size when a page is first
//! written, so an array is built in an allocation advised before its first element is
//! written ([`HugePages`], the store the engine's structures are handed).
//!
//! The arrays moved are the particles, the neighbour lists and centres, the cells' links and
//! the tournament tree — about nine tenths of the engine's memory at large N. Where huge
//! pages are not available (another system, `never`, or no free 2 MB page), the request does
//! nothing and the pages stay small: the results are the same bit for bit either way, only
//! the speed differs.

use crate::engine::arrays::Store;

/// Arrays of fewer bytes keep ordinary pages: a few MB are within the reach of the TLB.
const FROM_BYTES: usize = 4 << 20;

/// The size of a huge page (x86-64 and aarch64 with 4 KB base pages).
const HUGE: usize = 2 << 20;

/// The store that backs the engine's large arrays with huge pages ([`collect`], [`filled`],
/// [`moved`]).
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct HugePages;

impl Store for HugePages {
    fn collect<T>(&self, items: impl ExactSizeIterator<Item = T>) -> Vec<T> {
        collect(items)
    }

    fn filled<T: Clone>(&self, n: usize, value: T) -> Vec<T> {
        filled(n, value)
    }

    fn moved<T>(&self, v: Vec<T>) -> Vec<T> {
        moved(v)
    }
}

/// `items` in a new vector whose memory was advised to be backed by huge pages before it
/// was written (when it is at least `FROM_BYTES`; else an ordinary vector).
pub fn collect<T>(items: impl ExactSizeIterator<Item = T>) -> Vec<T> {
    let mut v = Vec::with_capacity(items.len());
    advise(&v);
    v.extend(items);
    v
}

/// `n` copies of `value`, as [`collect`] builds them.
pub fn filled<T: Clone>(n: usize, value: T) -> Vec<T> {
    collect(std::iter::repeat_n(value, n))
}

/// `v`'s elements in memory advised as [`collect`]'s, and no spare capacity: a large vector
/// is moved into a new one (its pages were written already); a small one only shrinks.
pub fn moved<T>(mut v: Vec<T>) -> Vec<T> {
    if v.len() * size_of::<T>() < FROM_BYTES {
        v.shrink_to_fit();
        v
    } else {
        collect(v.into_iter())
    }
}

/// Asks the kernel to back the whole 2 MB pages inside `v`'s allocation with huge pages.
#[allow(unsafe_code)]
fn advise<T>(v: &Vec<T>) {
    let bytes = v.capacity() * size_of::<T>();
    if bytes < FROM_BYTES {
        return;
    }
    let start = v.as_ptr() as usize;
    let (first, end) = (start.next_multiple_of(HUGE), (start + bytes) / HUGE * HUGE);
    if first >= end {
        return;
    }
    #[cfg(target_os = "linux")]
    // SAFETY: the range lies inside `v`'s allocation (mapped, owned by `v`, not yet
    // written). `MADV_HUGEPAGE` only changes which page size the kernel backs it with; it
    // never changes the contents, the mapping or its permissions. Failure (an old kernel,
    // huge pages disabled) changes nothing, so the result is not needed.
    unsafe {
        libc::madvise(first as *mut libc::c_void, end - first, libc::MADV_HUGEPAGE);
    }
    #[cfg(not(target_os = "linux"))]
    let _ = (first, end);
}

/// Bytes of the process's anonymous memory in transparent huge pages (`AnonHugePages` of
/// `/proc/self/smaps_rollup`; `None` where that cannot be read).
pub fn huge_page_bytes() -> Option<u64> {
    let rollup = std::fs::read_to_string("/proc/self/smaps_rollup").ok()?;
    let line = rollup.lines().find(|l| l.starts_with("AnonHugePages:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The vectors hold what they were given, large or small, whatever the kernel did with
    /// the advice.
    #[test]
    fn vectors_hold_their_elements() {
        for n in [0, 1, 1000, FROM_BYTES / 8 + 12_345] {
            let v = collect((0..n).map(|k| (k as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15)));
            assert_eq!(v.len(), n);
            assert!(v.iter().enumerate().all(|(k, &x)| x == (k as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15)));
            let w = moved(v.clone());
            assert_eq!(w, v);
            assert_eq!(w.capacity(), n);
            assert_eq!(filled(n, 7u32), vec![7u32; n]);
        }
    }
}
