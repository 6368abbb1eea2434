//! Resolving a collision: the mass-weighted 1D elastic (or inelastic) rule applied along the
//! line of centres (seed eq. 8–14).
//!
//! With `n = r₂ − r₁` at contact, `w = v₁ − v₂`, reduced mass `μ = m₁m₂/(m₁ + m₂)` and
//! restitution `e`, the impulse on body 2 is
//!
//! `J = (1 + e)·μ·(⟨w | n⟩ / |n|²)·n`,   `v₁' = v₁ − J/m₁`,   `v₂' = v₂ + J/m₂`.
//!
//! For `e = 1` this is seed eq. 13–14: `v₁' = v₁ − 2m₂/(m₁+m₂)·⟨v₁−v₂|r₁−r₂⟩/|r₁−r₂|²·(r₁−r₂)`.
//! Only the normal component changes; the tangential components are untouched; the normal
//! relative velocity is reversed and scaled by `e`. Momentum is conserved exactly in exact
//! arithmetic (one `J` is added to one body and taken from the other), kinetic energy too
//! for `e = 1`; in f64 both to a few ulps of their scale (tested).
//!
//! The returned [`Impulse`] is what the observers need: the collision virial term
//! `⟨r₁₂ | Δp⟩ = σ·|Δp|` for the pressure.

use nalgebra::SVector;
use std::fmt;

/// The kinematic state a collision changes: position (at contact), velocity, mass.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Body<const D: usize> {
    /// Position of the centre at the instant of contact.
    pub position: SVector<f64, D>,
    /// Velocity, updated in place by [`resolve_pair`].
    pub velocity: SVector<f64, D>,
    /// Mass (> 0).
    pub mass: f64,
}

/// A coefficient of normal restitution `e ∈ [0, 1]`: 1 is elastic (the default), 0 perfectly
/// inelastic along the normal.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Restitution(f64);

/// A restitution coefficient outside `[0, 1]` (or NaN).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RestitutionError(pub f64);

impl fmt::Display for RestitutionError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "restitution coefficient {} is outside [0, 1]", self.0)
    }
}

impl std::error::Error for RestitutionError {}

impl Restitution {
    /// Elastic collisions, `e = 1`.
    pub const ELASTIC: Restitution = Restitution(1.0);

    /// `e`, validated to lie in `[0, 1]`.
    pub fn new(e: f64) -> Result<Self, RestitutionError> {
        if (0.0..=1.0).contains(&e) { Ok(Restitution(e)) } else { Err(RestitutionError(e)) }
    }

    /// The value of `e`.
    pub fn value(self) -> f64 {
        self.0
    }
}

impl Default for Restitution {
    fn default() -> Self {
        Restitution::ELASTIC
    }
}

/// What a resolved collision reports to the observers.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Impulse<const D: usize> {
    /// Momentum change of the second body, `J`; the first body's is `−J`.
    pub on_second: SVector<f64, D>,
    /// The line of centres at contact, `r₂ − r₁` (its length is the contact distance σ).
    pub normal: SVector<f64, D>,
}

impl<const D: usize> Impulse<D> {
    /// The collision virial term `⟨r₂ − r₁ | J⟩ = σ·|J| ≥ 0` (J is along the normal).
    pub fn virial(&self) -> f64 {
        self.normal.dot(&self.on_second)
    }
}

/// Applies the collision rule to two touching bodies and returns the impulse.
///
/// Bodies that are not approaching along the normal (`⟨v₁ − v₂ | r₂ − r₁⟩ ≤ 0`) are left
/// unchanged and a zero impulse is returned: a hard-core contact pushes, it never pulls.
///
/// ```
/// use collide::engine::{Body, Restitution, resolve_pair};
/// use nalgebra::vector;
/// // Equal masses, head on: the velocities are exchanged.
/// let mut a = Body { position: vector![0.0, 0.0], velocity: vector![1.0, 0.0], mass: 1.0 };
/// let mut b = Body { position: vector![1.0, 0.0], velocity: vector![-2.0, 0.0], mass: 1.0 };
/// let j = resolve_pair(&mut a, &mut b, Restitution::ELASTIC);
/// assert_eq!((a.velocity, b.velocity), (vector![-2.0, 0.0], vector![1.0, 0.0]));
/// assert_eq!(j.virial(), 3.0); // σ·|Δp| = 1 · 3
/// ```
pub fn resolve_pair<const D: usize>(first: &mut Body<D>, second: &mut Body<D>, e: Restitution) -> Impulse<D> {
    resolve_growing_pair(first, second, e, 0.0)
}

/// [`resolve_pair`] for bodies whose contact distance grows at `growth` (the sum of the two
/// radii's growth speeds, ≥ 0; Lubachevsky–Stillinger compression): the rule acts on the
/// *gap's* closing speed `⟨w | n̂⟩ + G` instead of `⟨w | n̂⟩`,
///
/// `J = (1 + e)·μ·((⟨w | n⟩ + G·|n|) / |n|²)·n`,
///
/// so that afterwards the normal relative velocity `u = ⟨v₂ − v₁ | n̂⟩` is
/// `u' = G + e·(G − u)`: for `e = 1` the pair separates at `2G − u ≥ G`, at least as fast
/// as it grows (Donev, Torquato & Stillinger, J. Comput. Phys. 202, 737 (2005)), and kinetic
/// energy is injected (a compression holds kT with a thermostat). A pair whose gap is not
/// closing is left alone. With `G = 0` the impulse is [`resolve_pair`]'s.
///
/// ```
/// use collide::engine::{Body, Restitution, resolve_growing_pair};
/// use nalgebra::vector;
/// // Equal masses at rest, touching, the gap closing at G = 1: they leave at ±1.
/// let mut a = Body { position: vector![0.0, 0.0], velocity: vector![0.0, 0.0], mass: 1.0 };
/// let mut b = Body { position: vector![1.0, 0.0], velocity: vector![0.0, 0.0], mass: 1.0 };
/// resolve_growing_pair(&mut a, &mut b, Restitution::ELASTIC, 1.0);
/// assert_eq!((a.velocity, b.velocity), (vector![-1.0, 0.0], vector![1.0, 0.0]));
/// ```
pub fn resolve_growing_pair<const D: usize>(
    first: &mut Body<D>,
    second: &mut Body<D>,
    e: Restitution,
    growth: f64,
) -> Impulse<D> {
    let normal = second.position - first.position;
    let n2 = normal.norm_squared();
    let approach = (first.velocity - second.velocity).dot(&normal);
    // Without growth the approach itself, bit for bit (and no square root).
    let closing = if growth == 0.0 { approach } else { approach + growth * n2.sqrt() };
    if closing <= 0.0 || n2 == 0.0 {
        return Impulse { on_second: SVector::zeros(), normal };
    }
    let (m1, m2) = (first.mass, second.mass);
    let mu = m1 * m2 / (m1 + m2);
    let j = normal * ((1.0 + e.0) * mu * closing / n2);
    first.velocity -= j / m1;
    second.velocity += j / m2;
    Impulse { on_second: j, normal }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Vector2, Vector3, vector};
    use proptest::prelude::*;
    use proptest::test_runner::{Config, RngAlgorithm, TestRng, TestRunner};

    const EPS: f64 = f64::EPSILON;

    fn body2(p: [f64; 2], v: [f64; 2], m: f64) -> Body<2> {
        Body { position: Vector2::from(p), velocity: Vector2::from(v), mass: m }
    }

    #[test]
    fn unequal_masses_head_on_match_the_1d_formula() {
        // Seed eq. 8: v₁' = ((m₁ − m₂)v₁ + 2m₂v₂)/(m₁ + m₂), v₂' = ((m₂ − m₁)v₂ + 2m₁v₁)/(m₁ + m₂).
        let (m1, m2, u1, u2) = (3.0, 1.0, 2.0, -1.0);
        let mut a = body2([0.0, 0.0], [u1, 0.0], m1);
        let mut b = body2([1.0, 0.0], [u2, 0.0], m2);
        resolve_pair(&mut a, &mut b, Restitution::ELASTIC);
        assert_eq!(a.velocity.x, ((m1 - m2) * u1 + 2.0 * m2 * u2) / (m1 + m2));
        assert_eq!(b.velocity.x, ((m2 - m1) * u2 + 2.0 * m1 * u1) / (m1 + m2));
    }

    #[test]
    fn oblique_collision_changes_only_the_normal_component() {
        // Normal along (1, 1)/√2: the tangential component (along (1, −1)) is conserved.
        let mut a = body2([0.0, 0.0], [1.0, 0.0], 1.0);
        let mut b = body2([0.5, 0.5], [0.0, 0.0], 1.0);
        resolve_pair(&mut a, &mut b, Restitution::ELASTIC);
        assert_eq!(a.velocity, vector![0.5, -0.5]);
        assert_eq!(b.velocity, vector![0.5, 0.5]);
    }

    #[test]
    fn restitution_scales_the_normal_relative_velocity() {
        for e in [0.0, 0.25, 0.9] {
            let mut a = body2([0.0, 0.0], [1.0, 0.3], 2.0);
            let mut b = body2([1.0, 0.0], [-1.0, 0.1], 5.0);
            resolve_pair(&mut a, &mut b, Restitution::new(e).unwrap());
            let after = b.velocity.x - a.velocity.x;
            assert!((after - e * 2.0).abs() <= 4.0 * EPS, "e = {e}: {after}");
            assert_eq!((a.velocity.y, b.velocity.y), (0.3, 0.1));
        }
        assert!(Restitution::new(1.5).is_err());
        assert!(Restitution::new(f64::NAN).is_err());
    }

    /// With growth the gap's closing speed is reversed: unequal masses, oblique, a few
    /// restitutions; the normal relative velocity after is `G + e·(G − u)`, the tangential
    /// components are untouched, momentum is conserved, and a gap opening faster than `G`
    /// is left alone.
    #[test]
    fn growing_pairs_separate_at_least_at_the_growth_speed() {
        let n = vector![0.6, 0.8];
        for (e, g) in [(1.0, 0.5), (1.0, 3.0), (0.5, 0.25), (0.0, 1.0)] {
            let mut a = body2([0.0, 0.0], [0.3, -0.2], 2.0);
            let mut b = body2([0.6, 0.8], [-0.1, 0.4], 3.0);
            let u = (b.velocity - a.velocity).dot(&n);
            let (pa, pb) = (a.velocity * 2.0 + b.velocity * 3.0, (a.velocity - b.velocity).dot(&vector![0.8, -0.6]));
            resolve_growing_pair(&mut a, &mut b, Restitution::new(e).unwrap(), g);
            let after = (b.velocity - a.velocity).dot(&n);
            assert!((after - (g + e * (g - u))).abs() <= 8.0 * EPS * (g + u.abs()), "e = {e}, G = {g}: {after}");
            assert!(after >= g * (1.0 - 8.0 * EPS) || e < 1.0);
            assert!(((a.velocity - b.velocity).dot(&vector![0.8, -0.6]) - pb).abs() <= 8.0 * EPS);
            assert!((a.velocity * 2.0 + b.velocity * 3.0 - pa).norm() <= 16.0 * EPS);
        }
        // Receding at 2 > G = 1: untouched.
        let mut a = body2([0.0, 0.0], [-1.0, 0.0], 1.0);
        let mut b = body2([1.0, 0.0], [1.0, 0.0], 1.0);
        assert_eq!(resolve_growing_pair(&mut a, &mut b, Restitution::ELASTIC, 1.0).virial(), 0.0);
        // Receding at 1/2 < G = 1: pushed apart to 2G − u = 3/2.
        let mut a = body2([0.0, 0.0], [-0.25, 0.0], 1.0);
        let mut b = body2([1.0, 0.0], [0.25, 0.0], 1.0);
        resolve_growing_pair(&mut a, &mut b, Restitution::ELASTIC, 1.0);
        assert_eq!(b.velocity.x - a.velocity.x, 1.5);
    }

    #[test]
    fn receding_pair_is_untouched() {
        let mut a = body2([0.0, 0.0], [-1.0, 0.0], 1.0);
        let mut b = body2([1.0, 0.0], [1.0, 0.0], 1.0);
        let j = resolve_pair(&mut a, &mut b, Restitution::ELASTIC);
        assert_eq!(j.virial(), 0.0);
        assert_eq!((a.velocity.x, b.velocity.x), (-1.0, 1.0));
    }

    /// Momentum and (for e = 1) energy over random 3D collisions with mass ratios up to 10³.
    ///
    /// Tolerances, from first-order rounding analysis (u = ε/2 per operation): each velocity
    /// component is updated by one rounded `J/m` and one rounded addition, so the momentum
    /// error per component is ≤ 2u·(m₁|v₁| + m₂|v₂| + 2|J|) plus the check's own two
    /// products and sum, ≤ 3u·(m₁|v₁'| + m₂|v₂'|); 8ε over the sum of these scales covers it.
    /// The energy error is ≤ a few u of Σ m|v|² + |J|²/μ; 16ε of that scale covers it.
    #[test]
    fn momentum_and_energy_are_conserved_to_rounding() {
        let config = Config { cases: 20_000, failure_persistence: None, ..Config::default() };
        let mut runner = TestRunner::new_with_rng(config, TestRng::deterministic_rng(RngAlgorithm::ChaCha));
        let vec3 = || proptest::array::uniform3(-10.0..10.0f64);
        let strategy = (vec3(), vec3(), vec3(), -3.0..3.0f64, -3.0..3.0f64, 0.0..=1.0f64);
        runner
            .run(&strategy, |(dir, v1, v2, lm1, lm2, e)| {
                let n = Vector3::from(dir);
                prop_assume!(n.norm() > 1e-3);
                let (m1, m2) = (10f64.powf(lm1), 10f64.powf(lm2));
                let mut a = Body { position: Vector3::zeros(), velocity: Vector3::from(v1), mass: m1 };
                let mut b = Body { position: n, velocity: Vector3::from(v2), mass: m2 };
                let before = (a, b);
                let j = resolve_pair(&mut a, &mut b, Restitution::new(e).unwrap());
                let p0 = before.0.velocity * m1 + before.1.velocity * m2;
                let p1 = a.velocity * m1 + b.velocity * m2;
                let jn = j.on_second.norm();
                for k in 0..3 {
                    let scale = m1 * (before.0.velocity[k].abs() + a.velocity[k].abs())
                        + m2 * (before.1.velocity[k].abs() + b.velocity[k].abs())
                        + 2.0 * jn;
                    prop_assert!((p1[k] - p0[k]).abs() <= 8.0 * EPS * scale, "momentum {k}: {p0} → {p1}");
                }
                let ke = |x: &Body<3>| 0.5 * x.mass * x.velocity.norm_squared();
                let (k0, k1) = (ke(&before.0) + ke(&before.1), ke(&a) + ke(&b));
                let mu = m1 * m2 / (m1 + m2);
                if e == 1.0 {
                    let scale = k0 + jn * jn / mu;
                    prop_assert!((k1 - k0).abs() <= 16.0 * EPS * scale, "energy {k0} → {k1}");
                } else {
                    // Inelastic: energy never increases (beyond rounding).
                    prop_assert!(k1 <= k0 + 16.0 * EPS * (k0 + jn * jn / mu));
                }
                prop_assert!(j.virial() >= 0.0);
                Ok(())
            })
            .unwrap();
    }
}
