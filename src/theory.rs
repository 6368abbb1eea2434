//! Formulas from the literature used by more than one room: the limits of a run estimate
//! its length with them, and the experiments check the dynamics against them.

use std::f64::consts::PI;

/// Henderson's contact value of hard disks, `g(σ) = (1 − 7η/16)/(1 − η)²`, i.e.
/// `(Z_H − 1)/(2η)` with Henderson's equation of state (Mol. Phys. 30, 971 (1975); good to
/// about 0.5 % up to η ≈ 0.5).
pub fn g_henderson(eta: f64) -> f64 {
    (1.0 - 7.0 * eta / 16.0) / (1.0 - eta).powi(2)
}

/// Enskog's collision frequency per particle in 2D, `Γ = 2nσ·g·√(πkT/m)`, at number
/// density `n`, diameter `sigma`, contact value `g`, temperature `kt` and mass `m`.
pub fn enskog_rate_2d(n: f64, sigma: f64, g: f64, kt: f64, m: f64) -> f64 {
    2.0 * n * sigma * g * (PI * kt / m).sqrt()
}
