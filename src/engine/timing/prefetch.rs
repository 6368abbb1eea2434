//! The cache hint: ask for the line holding a value before it is needed.
//!
//! One of the crate's three `unsafe` blocks (with the huge-page request and the search's
//! vector read of records): `_mm_prefetch` takes a raw pointer, although a prefetch cannot
//! fault, reads nothing into the program and writes nothing — results are the same bit for
//! bit with or without it.

/// Starts loading the cache line at `address` into all cache levels, without waiting.
#[allow(unsafe_code)]
#[inline(always)]
pub fn prefetch_address(address: *const u8) {
    #[cfg(target_arch = "x86_64")]
    // SAFETY: a prefetch is only a hint: it never faults and has no architectural effect,
    // whatever the address (every address given here comes from a live reference anyway).
    unsafe {
        std::arch::x86_64::_mm_prefetch::<{ std::arch::x86_64::_MM_HINT_T0 }>(address.cast())
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = address;
}

/// Starts loading the cache line that holds `x`.
#[inline(always)]
pub fn prefetch<T>(x: &T) {
    prefetch_address((x as *const T).cast());
}
