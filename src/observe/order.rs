//! Bond-orientational order of a state: is a dense packing a crystal or amorphous?
//!
//! Two particles are *bonded* when their centres are closer than `cutoff` times their contact
//! distance σᵢⱼ (1.2 by default, [`BOND_CUTOFF`]: past the first shell of a close-packed crystal,
//! whose neighbours sit at σ, and before its second, at √3·σ in a hexagonal layer and √2·σ in
//! fcc). Over the `B` bonds, with unit vectors `b̂` (minimum image):
//!
//! * **disks**, the global hexatic order `Ψ₆ = |(1/B) Σ_b exp(6iθ_b)|`, θ_b the bond's angle
//!   to the x axis: 1 for a perfect triangular crystal of one orientation;
//! * **spheres**, Steinhardt's global `Q₆` (Steinhardt, Nelson & Ronchetti, PRB 28, 784
//!   (1983)), `Q₆² = (4π/13) Σ_m |(1/B) Σ_b Y₆ₘ(b̂)|²`, computed through the addition theorem
//!   as `Q₆² = (1/B²) Σ_b Σ_b′ P₆(b̂·b̂′)` with the Legendre polynomial
//!   `P₆(x) = (231x⁶ − 315x⁴ + 105x² − 5)/16`: 0.5745 for fcc, 0.4848 for hcp (both with
//!   their 12 neighbours), 0.5106 for bcc (8).
//!
//! Both are even in `b̂`, so a bond's direction does not matter. For bonds of random
//! orientation each sum is a random walk and the order is about `1/√B` — a few hundredths for
//! hundreds of particles — so a crystal and an amorphous packing are told apart by far more
//! than their fluctuations. The pairs are searched exhaustively (O(N²)): meant for packings
//! of up to some thousands of particles, not for every event of a run.

use crate::engine::Simulation;
use nalgebra::SVector;
use serde::{Deserialize, Serialize};

/// The default bond cutoff, as a multiple of the contact distance.
pub const BOND_CUTOFF: f64 = 1.2;

/// The global bond-orientational order of a state.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct BondOrder {
    /// `Ψ₆` (disks) or `Q₆` (spheres); 0 when there is no bond.
    pub value: f64,
    /// Which one: `"psi6"` or `"q6"`.
    pub parameter: String,
    /// The number of bonds `B`.
    pub bonds: usize,
    /// The bond cutoff used (a multiple of the contact distance).
    pub cutoff: f64,
}

/// `P₆(x)`, the Legendre polynomial of degree 6.
pub fn legendre6(x: f64) -> f64 {
    let x2 = x * x;
    (((231.0 * x2 - 315.0) * x2 + 105.0) * x2 - 5.0) / 16.0
}

/// The unit vectors of the bonds of `sim`'s present state: pairs closer than `cutoff` times
/// their contact distance, at the present radii (grown ones included), minimum image.
pub fn bonds<const D: usize>(sim: &Simulation<D>, cutoff: f64) -> Vec<SVector<f64, D>> {
    let (t, radii, sim_box) = (sim.time(), sim.radii(), sim.sim_box());
    let particles = sim.particles();
    let positions: Vec<_> = particles.iter().map(|p| p.position_at(t)).collect();
    let mut out = Vec::new();
    for i in 0..particles.len() {
        let ri = radii.radius(particles[i].radius, t);
        for j in i + 1..particles.len() {
            let d = positions[j] - positions[i];
            let d = d + sim_box.minimum_image_shift(&d);
            let sigma = ri + radii.radius(particles[j].radius, t);
            let r = d.norm();
            if r < cutoff * sigma {
                out.push(d / r);
            }
        }
    }
    out
}

/// The global bond order of bond directions `bonds` (see the [module docs](self)): `Ψ₆` in
/// 2D, `Q₆` in 3D.
pub fn order_of<const D: usize>(bonds: &[SVector<f64, D>]) -> f64 {
    if bonds.is_empty() {
        return 0.0;
    }
    let b = bonds.len() as f64;
    if D == 2 {
        let (re, im) = bonds.iter().fold((0.0, 0.0), |(re, im), u| {
            let theta = u[1].atan2(u[0]);
            (re + (6.0 * theta).cos(), im + (6.0 * theta).sin())
        });
        re.hypot(im) / b
    } else {
        let sum: f64 = bonds.iter().map(|u| bonds.iter().map(|w| legendre6(u.dot(w))).sum::<f64>()).sum();
        // The double sum is |Σ Y₆ₘ|²-like, so ≥ 0 but for rounding.
        (sum.max(0.0)).sqrt() / b
    }
}

/// The global bond order of `sim`'s present state, bonds within `cutoff` contact distances.
pub fn bond_order<const D: usize>(sim: &Simulation<D>, cutoff: f64) -> BondOrder {
    let bonds = bonds(sim, cutoff);
    BondOrder {
        value: order_of(&bonds),
        parameter: if D == 2 { "psi6" } else { "q6" }.into(),
        bonds: bonds.len(),
        cutoff,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn v2(x: f64, y: f64) -> SVector<f64, 2> {
        SVector::<f64, 2>::new(x, y).normalize()
    }

    /// The 12 bonds of an fcc site, (±1, ±1, 0) and permutations, give Q₆ = 0.5745; the
    /// hcp site's (the upper three of fcc's rotated by 60° about the stacking axis) 0.4848;
    /// the triangular lattice's six Ψ₆ = 1, and bonds at right angles (square) Ψ₆ = 0.
    #[test]
    fn known_lattices() {
        let mut fcc = Vec::new();
        for (a, b) in [(1.0, 1.0), (1.0, -1.0), (-1.0, 1.0), (-1.0, -1.0)] {
            fcc.push(SVector::<f64, 3>::new(a, b, 0.0).normalize());
            fcc.push(SVector::<f64, 3>::new(a, 0.0, b).normalize());
            fcc.push(SVector::<f64, 3>::new(0.0, a, b).normalize());
        }
        assert!((order_of(&fcc) - 0.57452).abs() < 1e-4, "{}", order_of(&fcc));
        // hcp: in-plane hexagon, and three above and three below in eclipsed positions.
        let mut hcp = Vec::new();
        for k in 0..6 {
            let a = k as f64 * std::f64::consts::PI / 3.0;
            hcp.push(SVector::<f64, 3>::new(a.cos(), a.sin(), 0.0));
        }
        let (h, rho) = ((2.0f64 / 3.0).sqrt(), 1.0 / 3f64.sqrt());
        for k in 0..3 {
            let a = std::f64::consts::PI / 6.0 + k as f64 * 2.0 * std::f64::consts::PI / 3.0;
            hcp.push(SVector::<f64, 3>::new(rho * a.cos(), rho * a.sin(), h));
            hcp.push(SVector::<f64, 3>::new(rho * a.cos(), rho * a.sin(), -h));
        }
        assert!((order_of(&hcp) - 0.48476).abs() < 1e-4, "{}", order_of(&hcp));
        let triangular: Vec<_> =
            (0..6).map(|k| v2((k as f64 * 1.0471975511965976).cos(), (k as f64 * 1.0471975511965976).sin())).collect();
        assert!((order_of(&triangular) - 1.0).abs() < 1e-12);
        let square = [v2(1.0, 0.0), v2(0.0, 1.0)];
        assert!(order_of(&square) < 1e-12);
        assert_eq!(order_of::<2>(&[]), 0.0);
    }
}
