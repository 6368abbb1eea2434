//! Lattice placement: a triangular or square lattice (2D), or an fcc or simple cubic one
//! (3D), of at least N sites, its shape chosen for the box.
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
//!
//! In 3D both lattices live on a grid of `nx × ny × nz` points: simple cubic takes every
//! point, fcc those with an even sum of indices (a grid of half a cubic cell), so that a
//! periodic axis of fcc holds an even number of points. The canonical shape follows the
//! box's proportions; when its nearest sites are closer than the largest diameter, every
//! `(nx, ny)` is tried, with the fewest layers `nz` that hold N sites.

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
    /// Grid points with an even sum of indices (3D).
    Fcc,
    /// Every grid point (3D).
    SimpleCubic,
}

impl Kind {
    fn name(self) -> &'static str {
        match self {
            Kind::Triangular => "triangular",
            Kind::Square => "square",
            Kind::Fcc => "fcc",
            Kind::SimpleCubic => "simple cubic",
        }
    }

    /// The horizontal offset of odd rows, in spacings, and its largest value.
    fn max_offset(self) -> f64 {
        match self {
            Kind::Triangular => 0.5,
            Kind::Square | Kind::Fcc | Kind::SimpleCubic => 0.0,
        }
    }
}

/// The sites of an fcc or simple cubic grid of `shape` points: all of them, or (fcc) those
/// whose indices add up to an even number.
fn count_3d(kind: Kind, [nx, ny, nz]: [usize; 3]) -> usize {
    let all = nx.saturating_mul(ny).saturating_mul(nz);
    match kind {
        Kind::Fcc if nx % 2 == 1 && ny % 2 == 1 && nz % 2 == 1 => all / 2 + 1,
        Kind::Fcc => all / 2,
        _ => all,
    }
}

/// The distance between the nearest two sites of an fcc or simple cubic grid of `shape`
/// points (periodic images included).
fn nearest_3d(kind: Kind, shape: [usize; 3], sim_box: &SimBox<3>, r: f64) -> f64 {
    let s: [f64; 3] = std::array::from_fn(|a| spacing(shape[a], sim_box.lengths[a], sim_box.boundary[a], r, 0.0));
    let periodic = |a: usize| sim_box.boundary[a] == Boundary::Periodic;
    let mut best = f64::INFINITY;
    for a in 0..3 {
        match kind {
            // The next point along an axis (or the site's own image across a periodic one).
            Kind::SimpleCubic if shape[a] >= 2 || periodic(a) => best = best.min(s[a]),
            Kind::Fcc => {
                // Two points along one axis (or the site's own image, two points away when
                // the axis wraps with two points).
                if shape[a] >= 3 || periodic(a) {
                    best = best.min(2.0 * s[a]);
                }
                // One point along each of two axes: the face diagonal of a cubic cell.
                for b in a + 1..3 {
                    if shape[a] >= 2 && shape[b] >= 2 {
                        best = best.min(s[a].hypot(s[b]));
                    }
                }
            }
            _ => {}
        }
    }
    best
}

/// The grid of `kind` whose nearest sites are farthest apart among those with at least `n`
/// sites (see the module docs).
fn shape_3d(kind: Kind, n: usize, sim_box: &SimBox<3>, r: f64) -> ([usize; 3], f64) {
    let even = |a: usize| kind == Kind::Fcc && sim_box.boundary[a] == Boundary::Periodic;
    let fix = |a: usize, count: usize| {
        let count = count.max(1);
        if even(a) && count % 2 == 1 { count + 1 } else { count }
    };
    // Points per unit length so that the grid holds n sites in this volume.
    let per_site = if kind == Kind::Fcc { 2.0 } else { 1.0 };
    let step = (sim_box.volume() / (per_site * n as f64)).cbrt();
    let mut shape: [usize; 3] = std::array::from_fn(|a| fix(a, (sim_box.lengths[a] / step).round() as usize));
    while count_3d(kind, shape) < n {
        // Refine the axis whose points are farthest apart.
        let a = (0..3)
            .max_by(|&a, &b| (sim_box.lengths[a] / shape[a] as f64).total_cmp(&(sim_box.lengths[b] / shape[b] as f64)))
            .unwrap_or(0);
        shape[a] = fix(a, shape[a] + 1);
    }
    let mut apart = nearest_3d(kind, shape, sim_box, r);
    if !(apart >= 2.0 * r) {
        let most = if kind == Kind::Fcc { 2 * n + 1 } else { n };
        for nx in (1..=most).map(|c| fix(0, c)) {
            for ny in (1..=most / nx + 1).map(|c| fix(1, c)) {
                let layer = count_3d(kind, [nx, ny, 2]) / 2;
                let mut nz = fix(2, n.div_ceil(layer.max(1)));
                while count_3d(kind, [nx, ny, nz]) < n {
                    nz = fix(2, nz + 1);
                }
                let d = nearest_3d(kind, [nx, ny, nz], sim_box, r);
                let (sites, best) = (count_3d(kind, [nx, ny, nz]), count_3d(kind, shape));
                if d > apart || (d == apart && sites < best) {
                    (shape, apart) = ([nx, ny, nz], d);
                }
            }
        }
    }
    (shape, apart)
}

/// The sites of an fcc or simple cubic lattice with at least `n` sites in `sim_box`, layer
/// by layer and row by row; `rmax`, `rmin` and `eta` as for [`sites`].
pub(super) fn sites_3d(
    kind: Kind,
    n: usize,
    sim_box: &SimBox<3>,
    rmax: f64,
    rmin: f64,
    eta: f64,
) -> Result<Vec<[f64; 3]>, InitError> {
    let (shape, apart) = shape_3d(kind, n, sim_box, rmax);
    if !(apart >= 2.0 * rmin) {
        let fits_up_to = eta * (apart / (2.0 * rmax)).powi(3);
        return Err(InitError::LatticeDoesNotFit {
            lattice: kind.name(),
            shape: shape.to_vec(),
            spacing: apart,
            diameter: 2.0 * rmax,
            fits_up_to: (fits_up_to.is_finite() && fits_up_to > 0.0).then_some(fits_up_to),
        });
    }
    let axis = |a: usize, k: usize| coordinate(k, 0.0, shape[a], sim_box.lengths[a], sim_box.boundary[a], rmax, 0.0);
    let mut out = Vec::with_capacity(count_3d(kind, shape));
    for k in 0..shape[2] {
        for j in 0..shape[1] {
            for i in 0..shape[0] {
                if kind == Kind::SimpleCubic || (i + j + k) % 2 == 0 {
                    out.push([axis(0, i), axis(1, j), axis(2, k)]);
                }
            }
        }
    }
    Ok(out)
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
        _ => {
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
        Kind::Square | Kind::Fcc | Kind::SimpleCubic => in_row.min(unless(ny >= 2 || periodic_y, sy)),
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
            shape: vec![shape.0, shape.1],
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

    fn brute_nearest_3d(sites: &[[f64; 3]], sim_box: &SimBox<3>) -> f64 {
        let mut best = f64::INFINITY;
        for (a, p) in sites.iter().enumerate() {
            for q in &sites[a + 1..] {
                let d = SVector::<f64, 3>::from_fn(|k, _| q[k] - p[k]);
                best = best.min((d + sim_box.minimum_image_shift(&d)).norm());
            }
        }
        // A site's own image across a periodic axis.
        for k in 0..3 {
            if sim_box.boundary[k] == Boundary::Periodic {
                best = best.min(sim_box.lengths[k]);
            }
        }
        best
    }

    /// In 3D too the closed form of the nearest-site distance is that of the sites, for fcc
    /// and simple cubic grids of every small shape (one point along an axis included), in
    /// periodic, walled and mixed boxes of several proportions; and the sites counted are
    /// the sites made.
    #[test]
    fn the_nearest_distance_in_three_dimensions_is_that_of_the_sites() {
        use Boundary::{Periodic as P, Wall as W};
        let mut checked = 0;
        for kind in [Kind::Fcc, Kind::SimpleCubic] {
            for boundary in [[P; 3], [W; 3], [P, W, P], [W, P, W]] {
                for lengths in [[6.0, 6.0, 6.0], [12.0, 4.0, 7.0], [2.5, 9.0, 3.0]] {
                    let sim_box = SimBox { lengths: SVector::from(lengths), boundary };
                    let r = 0.2;
                    for nx in 1..6 {
                        for ny in 1..6 {
                            for nz in 1..6 {
                                let shape = [nx, ny, nz];
                                if kind == Kind::Fcc && (0..3).any(|a| boundary[a] == P && shape[a] % 2 == 1) {
                                    continue;
                                }
                                let axis =
                                    |a: usize, k: usize| coordinate(k, 0.0, shape[a], lengths[a], boundary[a], r, 0.0);
                                let mut sites = Vec::new();
                                for k in 0..nz {
                                    for j in 0..ny {
                                        for i in 0..nx {
                                            if kind == Kind::SimpleCubic || (i + j + k) % 2 == 0 {
                                                sites.push([axis(0, i), axis(1, j), axis(2, k)]);
                                            }
                                        }
                                    }
                                }
                                assert_eq!(sites.len(), count_3d(kind, shape), "{kind:?} {shape:?}");
                                let brute = brute_nearest_3d(&sites, &sim_box);
                                let formula = nearest_3d(kind, shape, &sim_box, r);
                                assert!(
                                    (formula - brute).abs() <= 1e-12 * brute.max(1.0)
                                        || (formula.is_infinite() && brute.is_infinite()),
                                    "{kind:?} {boundary:?} {lengths:?} {shape:?}: formula {formula}, sites {brute}"
                                );
                                checked += 1;
                            }
                        }
                    }
                }
            }
        }
        assert!(checked > 1500, "{checked}");
    }

    /// N = 4k³ spheres in a periodic cube make a perfect fcc crystal, which holds them up to
    /// close packing π/√18: at η = 0.74 its nearest sites are a diameter apart (to rounding),
    /// and at 0.7405, past it, it does not fit and says where it would.
    #[test]
    fn a_perfect_fcc_crystal_reaches_close_packing() {
        let n: usize = 4 * 5 * 5 * 5;
        for (eta, fits) in [(0.74, true), (0.7405, false)] {
            let volume = n as f64 * std::f64::consts::PI / 6.0 / eta;
            let l = volume.cbrt();
            let sim_box = SimBox { lengths: SVector::from([l; 3]), boundary: [Boundary::Periodic; 3] };
            match sites_3d(Kind::Fcc, n, &sim_box, 0.5, 0.5, eta) {
                Ok(sites) => {
                    assert!(fits);
                    assert_eq!(sites.len(), n, "no vacancy");
                    let d = brute_nearest_3d(&sites, &sim_box);
                    assert!(d >= 1.0 && d < 1.0005, "{d}");
                }
                Err(InitError::LatticeDoesNotFit { shape, fits_up_to: Some(up_to), .. }) => {
                    assert!(!fits);
                    assert_eq!(shape, [10, 10, 10]);
                    let close = std::f64::consts::PI / 18f64.sqrt();
                    assert!((up_to - close).abs() < 1e-12, "{up_to}");
                }
                Err(e) => panic!("{e}"),
            }
        }
    }
}
