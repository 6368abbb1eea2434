//! Every formula from the literature that collide compares with or plans by, each cited with
//! its stated accuracy: the limits of a run estimate its length with them, and the
//! experiments check the dynamics against them. Reduced units unless an argument says
//! otherwise: diameter σ = 1, mass m = 1, kT = 1.
//!
//! | formula | dimension | where it holds |
//! |---|---|---|
//! | [`z_liu_disks`], [`g_liu_disks`] | 2 | the stable fluid, η ≤ 0.70; adopted accuracy 10⁻³·Z |
//! | [`z_henderson`], [`g_henderson`] | 2 | to about 0.5 % up to η ≈ 0.5 |
//! | [`z_slhy`] | 2 | the whole fluid branch, diverging at close packing |
//! | [`z_virial`] | 2 | below η ≈ 0.2 (truncated after b₁₀) |
//! | [`z_hansen_goos`], [`g_hansen_goos`] | 3 | the stable fluid, η ≤ 0.49; accuracy 10⁻⁴·Z |
//! | [`z_speedy_fcc`] | 3 | the fcc crystal, η = 0.545–0.72; accuracy 10⁻³·Z |
//! | [`z_carnahan_starling`], [`g_carnahan_starling`] | 3 | to about 0.3 % over the fluid branch |
//! | [`enskog_rate`] | 2, 3 | exact at low density, with g(σ) the contact value |
//! | [`mean_free_path_enskog`] | 2, 3 | with Enskog's rate |
//! | [`enskog_diffusion`], [`enskog_viscosity`] | 2, 3 | exact at low density (first Sonine approximation) |
//! | [`tail_amplitude`] | 2, 3 | the VACF at times long against the mean free time, short against L/c |
//! | [`sound_speed`] | 2, 3 | with the equation of state given |

use std::f64::consts::PI;

/// Close packing of equal disks, π/(2√3) (the triangular lattice; Thue 1910, Fejes Tóth 1940).
pub const ETA_CP_2D: f64 = 0.906_899_682_117_108_9;

/// Close packing of equal spheres, π/√18 (fcc and hcp; Hales, Ann. Math. 162, 1065 (2005)).
pub const ETA_CP_3D: f64 = 0.740_480_489_693_061_1;

/// The random sequential adsorption (jamming) limit of equal disks, θ∞ ≈ 0.547 (Hinrichsen,
/// Feder & Jøssang, J. Stat. Phys. 44, 793 (1986)).
pub const RSA_JAMMING_2D: f64 = 0.547;

/// The random sequential addition (jamming) limit of equal spheres, φ∞ = 0.384130(2)
/// (Torquato, Uche & Stillinger, Phys. Rev. E 74, 061308 (2006)).
pub const RSA_JAMMING_3D: f64 = 0.3841;

/// Reduced virial coefficients b₂…b₁₀ of hard disks, `Z = 1 + Σ b_k η^(k−1)` (Clisby &
/// McCoy, J. Stat. Phys. 122, 15 (2006), Table 1, D = 2).
pub const VIRIAL_B_2D: [f64; 9] = [2.0, 3.128018, 4.257854, 5.336897, 6.36296, 7.35186, 8.31910, 9.27214, 10.2163];

/// Liu's equation of state of the stable hard-disk fluid,
/// `Z = (1 + η²/8 + η³/18 − 4η⁴/21)/(1 − η)²` (H. Liu, "Global equation of state and phase
/// transitions of the hard disc systems", arXiv:2010.10624 (2020), Eq. 1), built to reproduce
/// the high-precision simulation data of the stable fluid (Kolafa & Rottner, Mol. Phys. 104,
/// 3435 (2006), among them) up to the liquid–hexatic transition. Liu states no single
/// accuracy; [`Z_LIU_DISKS_ACCURACY`] is the one adopted here.
pub fn z_liu_disks(eta: f64) -> f64 {
    (1.0 + eta * eta / 8.0 + eta.powi(3) / 18.0 - 4.0 * eta.powi(4) / 21.0) / (1.0 - eta).powi(2)
}

/// The relative accuracy adopted for [`z_liu_disks`] in the stable fluid (η ≤ 0.70): 10⁻³.
/// It is ten times the largest difference between Liu's Z and the virial series through b₁₀
/// where that series has converged (η ≤ 0.15, [`z_virial`]), and a fifth of Henderson's 0.5 %,
/// which Liu's fit corrects by −0.48 % at η = 0.5.
pub const Z_LIU_DISKS_ACCURACY: f64 = 1e-3;

/// The contact value from Liu's equation of state, `g(σ) = (Z − 1)/(2η)` (2D).
pub fn g_liu_disks(eta: f64) -> f64 {
    (z_liu_disks(eta) - 1.0) / (2.0 * eta)
}

/// Hansen-Goos' equation of state of the hard-sphere fluid,
/// `Z = 8·ln(1 − η)/η + Σ_{k=0}^{7} b_k η^k / (1 − η)³` with `b = (9, −19, 47/3, −2.635232,
/// −1.265575, 0.041212, 0.248245, −0.096495)` (J. Chem. Phys. 144, 164506 (2016), Eq. 6 and
/// Table I), built from the compressibility of the molecular-dynamics data of Kolafa, Labík &
/// Malijevský (Phys. Chem. Chem. Phys. 6, 2335 (2004); relative inaccuracy below 4·10⁻⁵ at the
/// 95 % level for η ≤ 0.53).
pub fn z_hansen_goos(eta: f64) -> f64 {
    const B: [f64; 8] = [9.0, -19.0, 47.0 / 3.0, -2.635232, -1.265575, 0.041212, 0.248245, -0.096495];
    let poly = B.iter().rev().fold(0.0, |acc, b| acc * eta + b);
    8.0 * (-eta).ln_1p() / eta + poly / (1.0 - eta).powi(3)
}

/// The relative accuracy of [`z_hansen_goos`] in the stable fluid (η ≤ 0.49): 10⁻⁴, two and a
/// half times the stated 95 % accuracy of the data it reproduces (4·10⁻⁵, Kolafa, Labík &
/// Malijevský 2004) and more than twice its largest difference there from Liu's independent fit
/// of the hard-sphere fluid (arXiv:2010.14357 (2020)), 3.9·10⁻⁵ at η = 0.49.
pub const Z_HANSEN_GOOS_ACCURACY: f64 = 1e-4;

/// The relative accuracy of [`z_hansen_goos`] in the metastable fluid, 0.49 < η ≤ 0.53 (the
/// densest Kolafa–Labík–Malijevský data it was built on, ρσ³ ≤ 1.01, still accurate to 4·10⁻⁵):
/// 2·10⁻⁴, twice its largest difference there from Liu's fit (9.6·10⁻⁵ at η = 0.53).
pub const Z_HANSEN_GOOS_METASTABLE_ACCURACY: f64 = 2e-4;

/// The densest metastable fluid [`z_hansen_goos`] is trusted for.
pub const ETA_HANSEN_GOOS_METASTABLE: f64 = 0.53;

/// The contact value from Hansen-Goos' equation of state, `g(σ) = (Z − 1)/(4η)` (3D).
pub fn g_hansen_goos(eta: f64) -> f64 {
    (z_hansen_goos(eta) - 1.0) / (4.0 * eta)
}

/// Speedy's equation of state of the hard-sphere fcc crystal,
/// `Z = 3/(1 − z) − a(z − b)/(z − c)`, `z = η/η_cp`, with a = 0.5921, b = 0.7072, c = 0.601
/// (R. J. Speedy, J. Phys.: Condens. Matter 10, 4387 (1998), Eq. 2 and Table 1), a fit to
/// molecular-dynamics pressures of the crystal from melting (η ≈ 0.545) to close packing.
pub fn z_speedy_fcc(eta: f64) -> f64 {
    let (a, b, c) = (0.5921, 0.7072, 0.601);
    let z = eta / ETA_CP_3D;
    3.0 / (1.0 - z) - a * (z - b) / (z - c)
}

/// The relative accuracy adopted for [`z_speedy_fcc`] (η = 0.545–0.72): 10⁻³, above the
/// largest difference (6·10⁻⁴, at melting) between Speedy's fcc coefficients and the refit of
/// the same form to newer data (a = 0.620735, b = 0.708194, c = 0.591663), and above its
/// difference at melting from the coexistence pressure βPσ³ = 11.5727(10) at η_s = 0.5433
/// (Fernández et al., Phys. Rev. Lett. 108, 165701 (2012)), 0.1 %.
pub const Z_SPEEDY_FCC_ACCURACY: f64 = 1e-3;

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

/// `g(r)` of hard disks (`d` = 2) or spheres (3) of unit diameter at number density `n` to
/// first order in the density, exact as `n → 0`: `g(r) = 1 + n·X(r)` for `r ≥ 1`, `X(r)` the
/// area (volume) common to two disks (spheres) of radius 1 whose centres are `r` apart —
/// `2·acos(r/2) − (r/2)·√(4 − r²)` in 2D, `(π/12)(4 + r)(2 − r)²` in 3D, 0 beyond `r = 2` —
/// the Mayer term `∫f(r₁₃)f(r₂₃)dr₃` (Nijboer & van Hove, Phys. Rev. 85, 777 (1952), who
/// also give the next, O(n²), term for spheres). At contact it is `1 + (b₃/2^(d−1))·η`.
pub fn g_first_order(d: usize, n: f64, r: f64) -> f64 {
    if r >= 2.0 {
        return 1.0;
    }
    let overlap = if d == 2 {
        2.0 * (0.5 * r).acos() - 0.5 * r * (4.0 - r * r).sqrt()
    } else {
        PI / 12.0 * (4.0 + r) * (2.0 - r).powi(2)
    };
    1.0 + n * overlap
}

/// The coefficient `c₂` of η² in the contact value's density expansion `g(σ⁺) = 1 + c₁η +
/// c₂η² + …`, `b₄/2^(d−1)` of the virial series (exact: disks `b₄` = 4.257854, [`VIRIAL_B_2D`];
/// spheres `b₄` = 18.3648, from `B₄/B₂³ = 0.2869495`): the size of the term
/// [`g_first_order`] leaves out, at contact.
pub fn contact_second_order(d: usize) -> f64 {
    if d == 2 { VIRIAL_B_2D[2] / 2.0 } else { 18.3648 / 4.0 }
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

/// Enskog's self-diffusion coefficient of `d`-dimensional hard spheres at number density `n`
/// with contact value `g` (σ = m = kT = 1; first Sonine approximation): `D_E = D₀/g`,
/// `D₀ = 1/(2n)·√(1/π)` in 2D and `3/(8n)·√(1/π)` in 3D (Chapman & Cowling, 3rd ed. (1970),
/// §16.5; Gass, J. Chem. Phys. 54, 1898 (1971) for disks).
pub fn enskog_diffusion(d: usize, n: f64, g: f64) -> f64 {
    let d0 = if d == 2 { 1.0 / (2.0 * n) } else { 3.0 / (8.0 * n) } / PI.sqrt();
    d0 / g
}

/// Enskog's shear viscosity of `d`-dimensional hard spheres at packing fraction `eta` with
/// contact value `g` (σ = m = kT = 1; first Sonine approximation): `η_E/η₀ =
/// (1/g)(1 + 2^d·η·g/(d + 2))² + d/(d + 2)·2^(2d+2)/(π(d + 2))·η²g`, with `η₀ = 1/(2√π)` in 2D
/// and `5/(16√π)` in 3D — the elastic limit of Garzó & Dufty, Phys. Rev. E 59, 5895 (1999),
/// Eqs. 40–44; in 3D it is Enskog's `1/g + 3.2η + 12.34η²g` (Chapman & Cowling §16.41), in
/// 2D Gass's `1/g + 2η + (1 + 8/π)η²g`.
pub fn enskog_viscosity(d: usize, eta: f64, g: f64) -> f64 {
    let df = d as f64;
    let eta0 = if d == 2 { 0.5 } else { 5.0 / 16.0 } / PI.sqrt();
    let kinetic = (1.0 + 2f64.powi(d as i32) * eta * g / (df + 2.0)).powi(2) / g;
    let bulk = df / (df + 2.0) * 2f64.powi(2 * d as i32 + 2) / (PI * (df + 2.0)) * eta * eta * g;
    eta0 * (kinetic + bulk)
}

/// The amplitude `A` of the velocity autocorrelation's long-time tail,
/// `C(t)/C(0) ≈ A·t^(−d/2)`, by mode coupling: `A = (d − 1)/(d·n)·[4π(D + ν)]^(−d/2)`, `ν =
/// η_s/(mn)` the kinematic viscosity (Ernst, Hauge & van Leeuwen, Phys. Rev. A 4, 2055
/// (1971); Dorfman & Cohen, Phys. Rev. A 6, 776 (1972)); σ = m = kT = 1.
pub fn tail_amplitude(d: usize, n: f64, diffusion: f64, viscosity: f64) -> f64 {
    let df = d as f64;
    (df - 1.0) / (df * n) * (4.0 * PI * (diffusion + viscosity / n)).powf(-df / 2.0)
}

/// The adiabatic sound speed of hard particles with equation of state `Z(η)`:
/// `c² = (kT/m)[d(ηZ)/dη + (2/d)Z²]` (`∂P/∂n` at fixed T plus the heat term of a gas of
/// `d/2·k` heat capacity per particle), from `z` and its derivative `dz` at `eta`.
pub fn sound_speed(d: usize, eta: f64, z: f64, dz: f64) -> f64 {
    (z + eta * dz + 2.0 / d as f64 * z * z).sqrt()
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
        // Enskog's viscosity in 3D is 1/g + 3.2η + (4/25)(1 + 12/π)·16η²g times η₀; in 2D
        // 1/g + 2η + (1 + 8/π)η²g times η₀ = 1/(2√π).
        let (eta, g) = (0.3, 2.5);
        let e3 = 5.0 / 16.0 / PI.sqrt() * (1.0 / g + 3.2 * eta + 0.16 * (1.0 + 12.0 / PI) * 16.0 * eta * eta * g);
        assert!((enskog_viscosity(3, eta, g) - e3).abs() < 1e-13 * e3);
        let e2 = 0.5 / PI.sqrt() * (1.0 / g + 2.0 * eta + (1.0 + 8.0 / PI) * eta * eta * g);
        assert!((enskog_viscosity(2, eta, g) - e2).abs() < 1e-13 * e2);
        // The 2D tail: 1/(8πn(D + ν)).
        assert!((tail_amplitude(2, 0.4, 0.3, 0.2) - 1.0 / (8.0 * PI * 0.4 * 0.8)).abs() < 1e-15);
        // An ideal gas (Z = 1): c² = (1 + 2/d)kT/m, γ = (d + 2)/d.
        assert!((sound_speed(3, 0.1, 1.0, 0.0) - (5.0f64 / 3.0).sqrt()).abs() < 1e-15);
        // Mean free path times rate is the mean speed √(π/2).
        let eta = 0.2;
        assert!((mean_free_path_enskog(eta) * gamma_enskog(eta, g_henderson(eta)) - (PI / 2.0).sqrt()).abs() < 1e-14);
    }

    /// The accurate equations of state: each starts 1 + b₂η + b₃η² with the exact virial
    /// coefficients of its dimension (2D: b₂ = 2, b₃ = 3.128; 3D: b₂ = 4, b₃ = 10), at a hand-worked
    /// value, within its adopted accuracy of the independent references named in its docs.
    #[test]
    fn the_accurate_equations_of_state_are_those_of_the_papers() {
        // Liu (disks) at η = 0.5: (1 + 1/32 + 1/144 − 4/336)/0.25.
        assert!((z_liu_disks(0.5) - (1.0 + 1.0 / 32.0 + 1.0 / 144.0 - 4.0 / 336.0) / 0.25).abs() < 1e-14);
        let e = 1e-4;
        assert!(((z_liu_disks(e) - 1.0 - 2.0 * e) / (e * e) - 3.125).abs() < 1e-3);
        // Liu agrees with the converged virial series to a tenth of its adopted accuracy.
        for eta in [0.05, 0.1, 0.15] {
            let rel = (z_liu_disks(eta) / z_virial(eta) - 1.0).abs();
            assert!(rel < 0.1 * Z_LIU_DISKS_ACCURACY, "η = {eta}: {rel:e}");
        }
        assert!((g_liu_disks(0.3) - (z_liu_disks(0.3) - 1.0) / 0.6).abs() < 1e-15);
        // Hansen-Goos: 1 + 4η + 10η² at low density; within 4·10⁻⁵ of Liu's sphere fit to 0.49.
        let e = 1e-3;
        assert!(((z_hansen_goos(e) - 1.0 - 4.0 * e) / (e * e) - 10.0).abs() < 0.05);
        let liu = |e: f64| (1.0 + e + e * e - 8.0 / 13.0 * e.powi(3) - e.powi(4) + 0.5 * e.powi(5)) / (1.0 - e).powi(3);
        for eta in [0.1, 0.2, 0.3, 0.4, 0.45, 0.49] {
            let rel = (liu(eta) / z_hansen_goos(eta) - 1.0).abs();
            assert!(rel < 0.4 * Z_HANSEN_GOOS_ACCURACY, "η = {eta}: {rel:e}");
        }
        for eta in [0.5, 0.51, 0.52, 0.53] {
            let rel = (liu(eta) / z_hansen_goos(eta) - 1.0).abs();
            assert!(rel < 0.5 * Z_HANSEN_GOOS_METASTABLE_ACCURACY, "η = {eta}: {rel:e}");
        }
        // Carnahan–Starling is 0.2–0.3 % low of it at η = 0.3–0.45.
        assert!((z_carnahan_starling(0.4) / z_hansen_goos(0.4) - 1.0 + 0.00275).abs() < 1e-4);
        // Speedy's fcc at melting against the coexistence pressure: βPσ³ = (6η/π)·Z.
        let eta_s = 0.5433;
        let pressure = 6.0 * eta_s / PI * z_speedy_fcc(eta_s);
        assert!((pressure / 11.5727 - 1.0).abs() < Z_SPEEDY_FCC_ACCURACY, "{pressure}");
        let refit = |e: f64| {
            let z = e / ETA_CP_3D;
            3.0 / (1.0 - z) - 0.620735 * (z - 0.708194) / (z - 0.591663)
        };
        for eta in [0.545, 0.56, 0.6, 0.65, 0.7, 0.72] {
            assert!((refit(eta) / z_speedy_fcc(eta) - 1.0).abs() < Z_SPEEDY_FCC_ACCURACY, "η = {eta}");
        }
    }

    /// The first-order `g(r)` at contact is the virial series' `1 + (b₃/2^(d−1))η` (b₃ = 3.128018
    /// for disks, 10 for spheres); it falls to 1 continuously at `r = 2`; the overlap at
    /// `r = √2` (2D: a quarter of each disk less a triangle, `π/2 − 1`) and `r = 1` in 3D
    /// (`5π/12`) by hand.
    #[test]
    fn the_first_order_pair_distribution_matches_the_virial_series_and_geometry() {
        let n2 = |eta: f64| 4.0 * eta / PI;
        let n3 = |eta: f64| 6.0 * eta / PI;
        let eta = 0.01;
        assert!(((g_first_order(2, n2(eta), 1.0) - 1.0) / eta - VIRIAL_B_2D[1] / 2.0).abs() < 1e-6);
        assert!(((g_first_order(3, n3(eta), 1.0) - 1.0) / eta - 2.5).abs() < 1e-12);
        assert!((g_first_order(2, 1.0, 2f64.sqrt()) - 1.0 - (PI / 2.0 - 1.0)).abs() < 1e-14);
        assert!((g_first_order(3, 1.0, 1.0) - 1.0 - 5.0 * PI / 12.0).abs() < 1e-14);
        for d in [2, 3] {
            assert!(g_first_order(d, 1.0, 2.0 - 1e-9) - 1.0 < 1e-12);
            assert_eq!(g_first_order(d, 1.0, 2.5), 1.0);
        }
        assert!((contact_second_order(2) - 2.128927).abs() < 1e-6 && (contact_second_order(3) - 4.5912).abs() < 1e-12);
    }
}
