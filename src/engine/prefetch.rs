//! A cache hint: ask for the line holding a value before it is needed.
//!
//! The engine's lookahead (`Simulation`, from 3·2^14 particles on) uses it to load the next
//! event's data while the current one is processed. This is the crate's only `unsafe` code:
//! `_mm_prefetch` takes a raw pointer, although a prefetch cannot fault, reads nothing into
//! the program and writes nothing — results are the same bit for bit with or without it.

/// Starts loading the cache line that holds `x` into all cache levels, without waiting.
#[allow(unsafe_code)]
#[inline(always)]
pub fn prefetch<T>(x: &T) {
    #[cfg(target_arch = "x86_64")]
    // SAFETY: a prefetch is only a hint: it never faults, has no architectural effect, and
    // the address comes from a live reference anyway.
    unsafe {
        std::arch::x86_64::_mm_prefetch::<{ std::arch::x86_64::_MM_HINT_T0 }>((x as *const T).cast())
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = x;
}
