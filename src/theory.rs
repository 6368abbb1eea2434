//! Every formula from the literature that collide compares with or plans by, each cited with
//! its stated accuracy: the limits of a run estimate its length with them, and the
//! experiments check the dynamics against them. Reduced units unless an argument says
//! otherwise: diameter σ = 1, mass m = 1, kT = 1.
//!
//! | formula | dimension | where it holds |
//! |---|---|---|
//! | [`z_henderson`], [`g_henderson`] | 2 | to about 0.5 % up to η ≈ 0.5 |
//! | [`z_slhy`] | 2 | the whole fluid branch, diverging at close packing |
//! | [`z_virial`] | 2 | below η ≈ 0.2 (truncated after b₁₀) |
//! | [`z_carnahan_starling`], [`g_carnahan_starling`] | 3 | to about 0.3 % over the fluid branch |
//! | [`enskog_rate`] | 2, 3 | exact at low density, with g(σ) the contact value |
//! | [`mean_free_path_enskog`] | 2, 3 | with Enskog's rate |

use std::f64::consts::PI;

/// Close packing of equal disks, π/(2√3) (the triangular lattice; Thue 1910, Fejes Tóth 1940).
pub const ETA_CP_2D: f64 = 0.906_899_682_117_108_9;

/// Close packing of equal spheres, π/√18 (fcc and hcp; Hales, Ann. Math. 162, 1065 (2005)).
pub const ETA_CP_3D: f64 = 0.740_480_489_693_061_1;

/// The random sequential adsorption (jamming) limit of equal disks, θ∞ ≈ 0.547 (Hinrichsen,
/// Feder & Jøssang, J. Stat. Phys. 44, 793 (1986)).
pub const RSA_JAMMING_2D: f64 = 0.547;

/// Reduced virial coefficients b₂…b₁₀ of hard disks, `Z = 1 + Σ b_k η^(k−1)` (Clisby &
/// McCoy, J. Stat. Phys. 122, 15 (2006), Table 1, D = 2).
pub const VIRIAL_B_2D: [f64; 9] = [2.0, 3.128018, 4.257854, 5.336897, 6.36296, 7.35186, 8.31910, 9.27214, 10.2163];

/// Henderson's equation of state of hard disks, `Z = (1 + η²/8)/(1 − η)²` (Mol. Phys. 30, 971
/// (1975); good to about 0.5 % up to η ≈ 0.5).
pub fn z_henderson(eta: f64) -> f64 {
    (1.0 + eta * eta / 8.0) / (1.0 - eta).powi(2)
}

/// Henderson's contact value of hard disks, `g(σ) = (1 − 7η/16)/(1 − η)²`, i.e.
/// `(Z_H − 1)/(2η)` (Mol. Phys. 30, 971 (1975); good to about 0.5 % up to η ≈ 0.5).
pub fn g_henderson(eta: f64) -> f64 {
    (1.0 - 7.0 * eta / 16.0) / (1.0 - eta).powi(2)
}

/// The equation of state of Santos, López de Haro & Yuste for hard disks,
/// `Z = [1 − 2η + (2η_cp − 1)η²/η_cp²]⁻¹` (J. Chem. Phys. 103, 4622 (1995)).
pub fn z_slhy(eta: f64) -> f64 {
    1.0 / (1.0 - 2.0 * eta + (2.0 * ETA_CP_2D - 1.0) * eta * eta / (ETA_CP_2D * ETA_CP_2D))
}

/// The virial series of hard disks through b₁₀ ([`VIRIAL_B_2D`]); excellent below η ≈ 0.2,
/// where the first omitted term is about `b₁₁η¹⁰` with `b₁₁ ≈ 11`.
pub fn z_virial(eta: f64) -> f64 {
    1.0 + VIRIAL_B_2D.iter().enumerate().map(|(k, b)| b * eta.powi(k as i32 + 1)).sum::<f64>()
}

/// The Carnahan–Starling equation of state of hard spheres,
/// `Z = (1 + η + η² − η³)/(1 − η)³` (J. Chem. Phys. 51, 635 (1969); within about 0.3 % of
/// simulation over the stable fluid).
pub fn z_carnahan_starling(eta: f64) -> f64 {
    (1.0 + eta + eta * eta - eta.powi(3)) / (1.0 - eta).powi(3)
}

/// The Carnahan–Starling contact value of hard spheres, `g(σ) = (1 − η/2)/(1 − η)³`, i.e.
/// `(Z_CS − 1)/(4η)`.
pub fn g_carnahan_starling(eta: f64) -> f64 {
    (1.0 - 0.5 * eta) / (1.0 - eta).powi(3)
}

/// The contact value of `d`-dimensional hard spheres at packing fraction η, from the
/// equation of state of the dimension: Henderson's in 2D, Carnahan–Starling's in 3D.
pub fn contact_value(d: usize, eta: f64) -> f64 {
    if d == 2 { g_henderson(eta) } else { g_carnahan_starling(eta) }
}

/// Enskog's collision frequency per particle, `Γ = 2nσ·g·√(πkT/m)` in 2D and
/// `Γ = 4nσ²·g·√(πkT/m)` in 3D (Chapman & Cowling, *The Mathematical Theory of Non-uniform
/// Gases*, 3rd ed. (1970), §16.5; the physics reference sheet), at number density `n`,
/// diameter `sigma`, contact value `g`, temperature `kt` and mass `m`.
pub fn enskog_rate(d: usize, n: f64, sigma: f64, g: f64, kt: f64, m: f64) -> f64 {
    let surface = if d == 2 { 2.0 * sigma } else { 4.0 * sigma * sigma };
    surface * n * g * (PI * kt / m).sqrt()
}

/// Enskog's rate in 2D ([`enskog_rate`]).
pub fn enskog_rate_2d(n: f64, sigma: f64, g: f64, kt: f64, m: f64) -> f64 {
    2.0 * n * sigma * g * (PI * kt / m).sqrt()
}

/// Enskog's rate of hard disks in reduced units (σ = m = kT = 1, number density 4η/π) with
/// contact value `g`.
pub fn gamma_enskog(eta: f64, g: f64) -> f64 {
    enskog_rate_2d(4.0 * eta / PI, 1.0, g, 1.0, 1.0)
}

/// The mean free path of hard disks with Enskog's rate and Henderson's g(σ) in reduced units,
/// `λ = ⟨v⟩/Γ = 1/(2√2·n·g(σ))` with `⟨v⟩ = √(πkT/2m)` and `n = 4η/π`.
pub fn mean_free_path_enskog(eta: f64) -> f64 {
    1.0 / (2.0 * 2f64.sqrt() * 4.0 * eta / PI * g_henderson(eta))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each formula against values worked by hand from the printed expression, and the
    /// identities between them (a wrong coefficient fails one of these).
    #[test]
    fn the_formulas_are_those_of_the_papers() {
        assert_eq!(z_henderson(0.5), (1.0 + 0.25 / 8.0) / 0.25);
        assert!((g_henderson(0.3) - (z_henderson(0.3) - 1.0) / 0.6).abs() < 1e-15);
        assert!((g_carnahan_starling(0.3) - (z_carnahan_starling(0.3) - 1.0) / 1.2).abs() < 1e-14);
        assert!((z_carnahan_starling(0.49) - 1.612451 / 0.132651).abs() < 1e-12);
        assert!((ETA_CP_2D - PI / (2.0 * 3f64.sqrt())).abs() < 1e-16);
        assert!((ETA_CP_3D - PI / 18f64.sqrt()).abs() < 1e-16);
        // The virial series starts 1 + 2η + 3.128η² (b₂ = 2 is exact); b₄η³ = 4.26·10⁻⁹ next.
        let rest = z_virial(1e-3) - (1.0 + 2e-3 + 3.128018e-6);
        assert!((rest - 4.257854e-9).abs() < 1e-11, "{rest:e}");
        // SLHY diverges at close packing and agrees with Henderson at low density.
        assert!(z_slhy(ETA_CP_2D - 1e-9) > 1e6 && (z_slhy(0.05) / z_henderson(0.05) - 1.0).abs() < 1e-3);
        // Enskog's rate, 2D against the explicit form; 3D: 4nσ²g√π.
        assert_eq!(enskog_rate(2, 0.3, 1.0, 1.5, 1.0, 1.0), enskog_rate_2d(0.3, 1.0, 1.5, 1.0, 1.0));
        assert!((enskog_rate(3, 0.5, 1.0, 2.0, 1.0, 1.0) - 4.0 * PI.sqrt()).abs() < 1e-14);
        // Mean free path times rate is the mean speed √(π/2).
        let eta = 0.2;
        assert!((mean_free_path_enskog(eta) * gamma_enskog(eta, g_henderson(eta)) - (PI / 2.0).sqrt()).abs() < 1e-14);
    }
}
