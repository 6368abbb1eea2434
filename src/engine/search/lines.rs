//! The neighbours' records, read as vectors: the first cache line of eight records (position,
//! velocity, time and radius lead a record, `2D + 2` f64), turned field by field into lanes
//! for the batch kernel.
//!
//! Read field by field, a chunk's gather was some hundred scalar loads, inserts and
//! shuffles — the largest part of a chunk's instructions after the filter's arithmetic, in a
//! kernel bound by how many vector operations it issues. With AVX-512 the eight lines are
//! eight loads and a transpose in 24 shuffles (`benches/HISTORY.md`). Elsewhere the fields
//! are read one by one. The values are the same either way (tested): any bits are a valid
//! f64, and only the leading `2D + 2` are used.

use crate::engine::geometry::Particle;

/// Lanes per read: one record per lane of the batch.
pub(super) const RECORDS: usize = 8;

// The fields the search reads lead the record, in this order, within its first 64 bytes.
const _: () = {
    assert!(size_of::<Particle<2>>() >= 64 && size_of::<Particle<3>>() >= 64);
    assert!(core::mem::offset_of!(Particle<3>, position) == 0);
    assert!(core::mem::offset_of!(Particle<3>, velocity) == 24);
    assert!(core::mem::offset_of!(Particle<3>, time) == 48);
    assert!(core::mem::offset_of!(Particle<3>, radius) == 56);
    assert!(core::mem::offset_of!(Particle<2>, position) == 0);
    assert!(core::mem::offset_of!(Particle<2>, velocity) == 16);
    assert!(core::mem::offset_of!(Particle<2>, time) == 32);
    assert!(core::mem::offset_of!(Particle<2>, radius) == 40);
};

/// The first line of eight records, field by field: `out[f][k]` is the `f`-th f64 of record
/// `k` — for `f < D` the position, then the velocity, the time (`f = 2D`) and the radius
/// (`2D + 1`); the rest of the line after (not to be used).
#[inline(always)]
pub(super) fn first_lines<const D: usize>(records: &[&Particle<D>; RECORDS]) -> [[f64; RECORDS]; 8] {
    const { assert!(D == 2 || D == 3, "the layout is checked for disks and spheres") };
    #[cfg(all(target_arch = "x86_64", target_feature = "avx512f"))]
    {
        vector::first_lines(records)
    }
    #[cfg(not(all(target_arch = "x86_64", target_feature = "avx512f")))]
    {
        first_lines_by_field(records)
    }
}

/// [`first_lines`], one field at a time, for any number of records `W` (the fields past the
/// radius are left at zero).
#[inline(always)]
pub(super) fn first_lines_by_field<const D: usize, const W: usize>(records: &[&Particle<D>; W]) -> [[f64; W]; 8] {
    let mut out = [[0.0; W]; 8];
    for (k, q) in records.iter().enumerate() {
        for a in 0..D {
            out[a][k] = q.position[a];
            out[D + a][k] = q.velocity[a];
        }
        out[2 * D][k] = q.time;
        out[2 * D + 1][k] = q.radius;
    }
    out
}

/// The AVX-512 read. The crate's third `unsafe` block: the loads take raw pointers.
#[cfg(all(target_arch = "x86_64", target_feature = "avx512f"))]
mod vector {
    use super::{Particle, RECORDS};
    use std::arch::x86_64::*;

    #[allow(unsafe_code)]
    #[inline(always)]
    pub(super) fn first_lines<const D: usize>(records: &[&Particle<D>; RECORDS]) -> [[f64; RECORDS]; 8] {
        // SAFETY: every record is at least 64 bytes (asserted in the module), so each load
        // reads inside a live record; the target feature is enabled for the whole build
        // (`cfg` above); the stores write the eight f64 of each output row.
        unsafe {
            let r: [__m512d; 8] = core::array::from_fn(|k| _mm512_loadu_pd((records[k] as *const Particle<D>).cast()));
            // Pairs of records interleaved (fields 0, 2, 4, 6 and 1, 3, 5, 7 of two records),
            // then 128-bit blocks gathered across four and across all eight records.
            let t = [
                _mm512_unpacklo_pd(r[0], r[1]),
                _mm512_unpackhi_pd(r[0], r[1]),
                _mm512_unpacklo_pd(r[2], r[3]),
                _mm512_unpackhi_pd(r[2], r[3]),
                _mm512_unpacklo_pd(r[4], r[5]),
                _mm512_unpackhi_pd(r[4], r[5]),
                _mm512_unpacklo_pd(r[6], r[7]),
                _mm512_unpackhi_pd(r[6], r[7]),
            ];
            let u = [
                _mm512_shuffle_f64x2::<0x88>(t[0], t[2]),
                _mm512_shuffle_f64x2::<0xDD>(t[0], t[2]),
                _mm512_shuffle_f64x2::<0x88>(t[1], t[3]),
                _mm512_shuffle_f64x2::<0xDD>(t[1], t[3]),
                _mm512_shuffle_f64x2::<0x88>(t[4], t[6]),
                _mm512_shuffle_f64x2::<0xDD>(t[4], t[6]),
                _mm512_shuffle_f64x2::<0x88>(t[5], t[7]),
                _mm512_shuffle_f64x2::<0xDD>(t[5], t[7]),
            ];
            let fields = [
                _mm512_shuffle_f64x2::<0x88>(u[0], u[4]),
                _mm512_shuffle_f64x2::<0x88>(u[2], u[6]),
                _mm512_shuffle_f64x2::<0x88>(u[1], u[5]),
                _mm512_shuffle_f64x2::<0x88>(u[3], u[7]),
                _mm512_shuffle_f64x2::<0xDD>(u[0], u[4]),
                _mm512_shuffle_f64x2::<0xDD>(u[2], u[6]),
                _mm512_shuffle_f64x2::<0xDD>(u[1], u[5]),
                _mm512_shuffle_f64x2::<0xDD>(u[3], u[7]),
            ];
            let mut out = [[0.0; RECORDS]; 8];
            for (row, v) in out.iter_mut().zip(fields) {
                _mm512_storeu_pd(row.as_mut_ptr(), v);
            }
            out
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::rngs::Xoshiro256PlusPlus;
    use rand::{RngExt, SeedableRng};

    fn records<const D: usize>(seed: u64) -> Vec<Particle<D>> {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
        let mut x = move || rng.random_range(-1e3..1e3f64);
        (0..32u32)
            .map(|k| Particle {
                position: core::array::from_fn(|_| x()).into(),
                velocity: core::array::from_fn(|_| x()).into(),
                time: x(),
                radius: x().abs() + 0.1,
                mass: x().abs() + 0.1,
                species: k % 3,
                events: k.wrapping_mul(7919),
            })
            .collect()
    }

    /// The vector read gives every record's fields in their lanes, as the field-by-field read
    /// does (the two are one function where AVX-512 is not built in).
    fn same_fields<const D: usize>() {
        let ps = records::<D>(D as u64);
        for start in 0..ps.len() - RECORDS {
            // Records in a scrambled order, some repeated (as padding lanes repeat the owner).
            let pick: [&Particle<D>; RECORDS] = core::array::from_fn(|k| &ps[(start + 5 * k * k) % ps.len()]);
            let (got, want) = (first_lines(&pick), first_lines_by_field(&pick));
            for f in 0..2 * D + 2 {
                for k in 0..RECORDS {
                    assert_eq!(got[f][k].to_bits(), want[f][k].to_bits(), "field {f}, lane {k}");
                }
            }
        }
    }

    #[test]
    fn the_vector_read_gives_the_fields_of_disks() {
        same_fields::<2>();
    }

    #[test]
    fn the_vector_read_gives_the_fields_of_spheres() {
        same_fields::<3>();
    }
}
