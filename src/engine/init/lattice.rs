//! Lattice placement: a triangular or square lattice of at least N sites, its shape chosen
//! for the box.
//!
//! The *canonical* shape is the near-square one (`nx = round(√(N·√3/2))` columns for the
//! triangular lattice, `⌈√N⌉` for the square one; an even number of rows where the rows
//! wrap periodically, so that the offset rows alternate across the seam). It is kept
//! whenever its sites are at least the largest diameter apart. Otherwise — a box of another
//! aspect, or a dense state the near-square shape cannot hold — every column count
//! `1 ≤ nx ≤ N` is tried (rows `⌈N/nx⌉`) and the shape whose nearest sites are farthest
//! apart wins (ties: fewer sites, then fewer columns). The distance between nearest sites
//! follows from the two spacings in closed form, so the search is O(N) arithmetic.
//!
//! Along a periodic axis the sites are the centres of `n` equal cells; between walls they
//! are spread from `r` to `L − r` (`r` the largest radius), so that every disk is inside.

use super::InitError;
use crate::engine::geometry::{Boundary, SimBox};
use nalgebra::SVector;

/// The two lattices.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Kind {
    /// Rows offset by half a spacing, every other row.
    Triangular,
    /// Rows aligned.
    Square,
}

impl Kind {
    fn name(self) -> &'static str {
        match self {
            Kind::Triangular => "triangular",
            Kind::Square => "square",
        }
    }

    /// The horizontal offset of odd rows, in spacings, and its largest value.
    fn max_offset(self) -> f64 {
        match self {
            Kind::Triangular => 0.5,
            Kind::Square => 0.0,
        }
    }
}

/// Columns and rows of a near-square triangular lattice with at least `n` sites (an even
/// number of rows when it must wrap periodically).
pub(super) fn triangular_shape(n: usize, even_rows: bool) -> (usize, usize) {
    let nx = ((n as f64 * 3f64.sqrt() / 2.0).sqrt().round() as usize).max(1);
    let mut ny = n.div_ceil(nx).max(1);
    if even_rows && ny % 2 == 1 {
        ny += 1;
    }
    (nx, ny)
}

/// The near-square shape of `kind` for `n` sites.
fn canonical(kind: Kind, n: usize, even_rows: bool) -> (usize, usize) {
    match kind {
        Kind::Triangular => triangular_shape(n, even_rows),
        Kind::Square => {
            let nx = ((n as f64).sqrt().ceil() as usize).max(1);
            (nx, n.div_ceil(nx))
        }
    }
}

/// The spacing of `count` sites along an axis of length `l` (see [`coordinate`]); +∞ for
/// one site between walls (it has no neighbour along the axis).
fn spacing(count: usize, l: f64, boundary: Boundary, r: f64, max_offset: f64) -> f64 {
    match boundary {
        Boundary::Periodic => l / count as f64,
        Boundary::Wall => {
            let span = count as f64 - 1.0 + max_offset;
            if span <= 0.0 { f64::INFINITY } else { (l - 2.0 * r) / span }
        }
    }
}

/// The distance between the nearest two sites of an `nx × ny` lattice (periodic images
/// included).
fn nearest(kind: Kind, (nx, ny): (usize, usize), sim_box: &SimBox<2>, r: f64) -> f64 {
    let [bx, by] = sim_box.boundary;
    let sx = spacing(nx, sim_box.lengths[0], bx, r, kind.max_offset());
    let sy = spacing(ny, sim_box.lengths[1], by, r, 0.0);
    // Along a row: the next column, or the site's own image across a periodic axis.
    let in_row = if nx >= 2 || bx == Boundary::Periodic { sx } else { f64::INFINITY };
    let periodic_y = by == Boundary::Periodic;
    let unless = |there: bool, d: f64| if there { d } else { f64::INFINITY };
    match kind {
        // The next row, or the site's own image across a periodic axis.
        Kind::Square => in_row.min(unless(ny >= 2 || periodic_y, sy)),
        // Adjacent rows are offset by half a spacing; rows two apart are aligned (with two
        // rows that wrap, the second is the site's own image). The rows wrap only in even
        // numbers (see `canonical`).
        Kind::Triangular => {
            let next = unless(ny >= 2, (0.5 * sx).hypot(sy));
            let second = unless(ny >= 3 || (periodic_y && ny >= 2), 2.0 * sy);
            in_row.min(next).min(second)
        }
    }
}

/// Coordinate of lattice index `k` (plus `offset` ∈ [0, 1)) along an axis of length `l`
/// with `count` sites: centred cells when periodic; spread from `r` to `l − r` between walls.
fn coordinate(k: usize, offset: f64, count: usize, l: f64, boundary: Boundary, r: f64, max_offset: f64) -> f64 {
    match boundary {
        Boundary::Periodic => (k as f64 + offset + 0.5) * l / count as f64,
        Boundary::Wall => {
            let span = count as f64 - 1.0 + max_offset;
            // Clamped: r + (n−1)·((l − 2r)/(n−1)) can round one ulp past l − r. The caller
            // has checked l ≥ 2r, so the interval is not empty.
            if span <= 0.0 { l / 2.0 } else { (r + (k as f64 + offset) * (l - 2.0 * r) / span).clamp(r, l - r) }
        }
    }
}

/// The sites of a lattice of `kind` with at least `n` sites in `sim_box`, row by row.
/// `rmax` and `rmin` are the largest and smallest radii; `eta` the packing fraction (for
/// the error). Fails when even the best shape puts two sites closer than the smallest
/// diameter (every pair of neighbours would overlap).
pub(super) fn sites<const D: usize>(
    kind: Kind,
    n: usize,
    sim_box: &SimBox<2>,
    rmax: f64,
    rmin: f64,
    eta: f64,
) -> Result<Vec<SVector<f64, D>>, InitError> {
    let even_rows = kind == Kind::Triangular && sim_box.boundary[1] == Boundary::Periodic;
    let diameter = 2.0 * rmax;
    let mut shape = canonical(kind, n, even_rows);
    let mut apart = nearest(kind, shape, sim_box, rmax);
    if !(apart >= diameter) {
        for nx in 1..=n {
            let mut ny = n.div_ceil(nx);
            if even_rows && ny % 2 == 1 {
                ny += 1;
            }
            let d = nearest(kind, (nx, ny), sim_box, rmax);
            let (sites, best) = (nx * ny, shape.0 * shape.1);
            if d > apart || (d == apart && sites < best) {
                (shape, apart) = ((nx, ny), d);
            }
        }
    }
    if !(apart >= 2.0 * rmin) {
        // Scaling the box by σ/d would make the nearest sites σ apart (exactly so in a
        // periodic box; about so between walls).
        let fits_up_to = eta * (apart / diameter).powi(2);
        return Err(InitError::LatticeDoesNotFit {
            lattice: kind.name(),
            columns: shape.0,
            rows: shape.1,
            spacing: apart,
            diameter,
            fits_up_to: (fits_up_to.is_finite() && fits_up_to > 0.0).then_some(fits_up_to),
        });
    }
    let (nx, ny) = shape;
    let mut out = Vec::with_capacity(nx * ny);
    for row in 0..ny {
        let offset = if kind == Kind::Triangular && row % 2 == 1 { 0.5 } else { 0.0 };
        let max_offset = kind.max_offset();
        let x = |col| coordinate(col, offset, nx, sim_box.lengths[0], sim_box.boundary[0], rmax, max_offset);
        let y = coordinate(row, 0.0, ny, sim_box.lengths[1], sim_box.boundary[1], rmax, 0.0);
        out.extend((0..nx).map(|col| SVector::from_fn(|a, _| [x(col), y, 0.0][a])));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector2;

    fn brute_nearest(sites: &[SVector<f64, 2>], sim_box: &SimBox<2>) -> f64 {
        let mut best = f64::INFINITY;
        for (a, p) in sites.iter().enumerate() {
            for q in &sites[a + 1..] {
                let d = q - p;
                best = best.min((d + sim_box.minimum_image_shift(&d)).norm());
            }
        }
        best
    }

    /// The closed form of the nearest-site distance agrees with a brute-force search over
    /// the sites, for both lattices, every boundary and many shapes (including one column,
    /// one row, and distorted boxes).
    #[test]
    fn the_nearest_distance_is_that_of_the_sites() {
        let boundaries = [
            [Boundary::Periodic; 2],
            [Boundary::Wall; 2],
            [Boundary::Periodic, Boundary::Wall],
            [Boundary::Wall, Boundary::Periodic],
        ];
        let mut checked = 0;
        for kind in [Kind::Triangular, Kind::Square] {
            for boundary in boundaries {
                for (lx, ly) in [(10.0, 10.0), (20.0, 5.0), (3.0, 40.0), (1.5, 7.0)] {
                    let sim_box = SimBox { lengths: Vector2::new(lx, ly), boundary };
                    for nx in 1..8 {
                        for ny in 1..8 {
                            if kind == Kind::Triangular && boundary[1] == Boundary::Periodic && ny % 2 == 1 {
                                continue;
                            }
                            let r = 0.25;
                            let mut sites = Vec::new();
                            for row in 0..ny {
                                let off = if kind == Kind::Triangular && row % 2 == 1 { 0.5 } else { 0.0 };
                                let y = coordinate(row, 0.0, ny, ly, boundary[1], r, 0.0);
                                for col in 0..nx {
                                    sites.push(Vector2::new(
                                        coordinate(col, off, nx, lx, boundary[0], r, kind.max_offset()),
                                        y,
                                    ));
                                }
                            }
                            // A site's own periodic image: the box length along a periodic axis.
                            let mut brute = brute_nearest(&sites, &sim_box);
                            for a in 0..2 {
                                if boundary[a] == Boundary::Periodic {
                                    brute = brute.min(sim_box.lengths[a]);
                                }
                            }
                            let formula = nearest(kind, (nx, ny), &sim_box, r);
                            assert!(
                                (formula - brute).abs() <= 1e-12 * brute.max(1.0)
                                    || (formula.is_infinite() && brute.is_infinite()),
                                "{kind:?} {boundary:?} {lx}×{ly} {nx}×{ny}: formula {formula}, sites {brute}"
                            );
                            checked += 1;
                        }
                    }
                }
            }
        }
        assert!(checked > 1000, "{checked}");
    }

    /// A box twice as tall as wide holds the lattice that a square box of the same area
    /// holds: the shape follows the box (the near-square shape would put rows 0.87 apart).
    #[test]
    fn the_shape_follows_the_aspect() {
        let n = 200;
        let area = n as f64 * std::f64::consts::PI * 0.25 / 0.4;
        let lx = (area / 2.0).sqrt();
        let sim_box = SimBox { lengths: Vector2::new(lx, 2.0 * lx), boundary: [Boundary::Periodic; 2] };
        assert!(nearest(Kind::Square, canonical(Kind::Square, n, false), &sim_box, 0.5) < 1.0);
        let sites = sites(Kind::Square, n, &sim_box, 0.5, 0.5, 0.4).expect("fits");
        assert!(brute_nearest(&sites, &sim_box) >= 1.0);
    }
}
