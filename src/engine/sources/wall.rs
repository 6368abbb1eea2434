//! Hard walls: when a particle reaches one, and the reflection when it does.
//!
//! Along a walled axis of length `L` a particle of radius `R` moves between `R` and `L − R`.
//! *Predict* (pure): the first of those planes its flight reaches. *Resolve* (mutating): the
//! normal velocity reversed — an impulse `2m|v⊥|` on the wall, which the wall-pressure
//! observers sum.
//!
//! While the radii grow at `g` ([`Radii::Growing`]) the planes move in, `R(t)` and
//! `L − R(t)`, at speed `g`: a particle reaches the upper one when `v + g > 0`, after
//! `(L − R − x)/(v + g)`, and the lower one when `v − g < 0`, after `(R − x)/(v − g)` —
//! either may come first, even at rest. The reflection reverses the closing speed relative to
//! the plane: `v' = −v − 2g` at the upper wall, `−v + 2g` at the lower one.

use crate::engine::geometry::{Boundary, Particle, SimBox};
use crate::engine::motion::{self, Radii};

/// The first wall particle `p` hits: `(time, axis, upper)`. A particle already touching or
/// beyond a wall (by round-off) and moving into it hits it now (at its own update time).
pub fn predict<const D: usize>(p: &Particle<D>, sim_box: &SimBox<D>, radii: Radii) -> Option<(f64, usize, bool)> {
    if radii.growing() {
        return predict_growing(p, sim_box, radii);
    }
    let mut best: Option<(f64, usize, bool)> = None;
    for a in 0..D {
        if sim_box.boundary[a] != Boundary::Wall || p.velocity[a] == 0.0 {
            continue;
        }
        let upper = p.velocity[a] > 0.0;
        let contact = if upper { sim_box.lengths[a] - p.radius } else { p.radius };
        let dt = motion::time_to(p.position[a], p.velocity[a], contact).max(0.0);
        if best.is_none_or(|(b, _, _)| dt < b) {
            best = Some((dt, a, upper));
        }
    }
    best.map(|(dt, a, upper)| (p.time + dt, a, upper))
}

/// [`predict`] while the radii grow: both planes of every walled axis, the earliest (the
/// lower axis, then the lower wall, at equal times).
fn predict_growing<const D: usize>(p: &Particle<D>, sim_box: &SimBox<D>, radii: Radii) -> Option<(f64, usize, bool)> {
    let (r, g) = (radii.radius(p.radius, p.time), radii.speed(p.radius));
    let mut best: Option<(f64, usize, bool)> = None;
    for a in 0..D {
        if sim_box.boundary[a] != Boundary::Wall {
            continue;
        }
        let v = p.velocity[a];
        for (upper, closing, plane) in [(false, g - v, r), (true, v + g, sim_box.lengths[a] - r)] {
            if closing > 0.0 {
                let speed = if upper { closing } else { -closing };
                let dt = motion::time_to(p.position[a], speed, plane).max(0.0);
                if best.is_none_or(|(b, _, _)| dt < b) {
                    best = Some((dt, a, upper));
                }
            }
        }
    }
    best.map(|(dt, a, upper)| (p.time + dt, a, upper))
}

/// Resolves particle `p` hitting the `upper` or lower wall of `axis` at time `t`: advanced,
/// the normal velocity reversed if it moves into the wall, the counter incremented. Returns
/// the impulse |Δp| = 2m|v⊥| (0 if it was not moving into the wall). While the radii grow,
/// the closing speed relative to the moving plane is reversed (see the module docs), an
/// impulse `2m·(v ± g)`.
pub fn resolve<const D: usize>(p: &mut Particle<D>, axis: usize, upper: bool, t: f64, radii: Radii) -> f64 {
    if radii.growing() {
        p.advance(t);
        p.events = p.events.wrapping_add(1);
        let (v, g) = (p.velocity[axis], radii.speed(p.radius));
        let closing = if upper { v + g } else { g - v };
        if closing <= 0.0 {
            return 0.0;
        }
        p.velocity[axis] = if upper { -v - 2.0 * g } else { 2.0 * g - v };
        return 2.0 * p.mass * closing;
    }
    p.advance(t);
    let v = p.velocity[axis];
    p.events = p.events.wrapping_add(1);
    if v != 0.0 && (v > 0.0) == upper {
        p.velocity[axis] = -v;
        2.0 * p.mass * v.abs()
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::SVector;

    fn walled() -> SimBox<1> {
        SimBox { lengths: SVector::from([10.0]), boundary: [Boundary::Wall] }
    }

    fn particle(x: f64, v: f64) -> Particle<1> {
        Particle {
            position: SVector::from([x]),
            velocity: SVector::from([v]),
            time: 0.0,
            radius: 1.0,
            mass: 2.0,
            species: 0,
            events: 0,
        }
    }

    /// Growing radius `1 + t/2` (rate ½ from origin 0): the planes move in at ½. At rest at 3,
    /// the lower plane `1 + t/2` arrives first, at t = 4; the reflection leaves at `2g = 1`
    /// with an impulse `2m·g = 2`; the next wall is then the upper one, not the same one again.
    #[test]
    fn growing_walls_close_in_and_reflect_the_closing_speed() {
        let radii = Radii::Growing { rate: 0.5, origin: 0.0 };
        let mut p = particle(3.0, 0.0);
        assert_eq!(predict(&p, &walled(), radii), Some((4.0, 0, false)));
        assert_eq!(resolve(&mut p, 0, false, 4.0, radii), 2.0);
        assert_eq!(p.velocity[0], 1.0);
        // Now at 3 with radius 3 (touching), moving up at 1: the upper plane 10 − (3 + u/2)
        // meets 3 + u at u = 8/3.
        let (t, axis, upper) = predict(&p, &walled(), radii).unwrap();
        assert!(upper && axis == 0 && (t - (4.0 + 8.0 / 3.0)).abs() < 1e-14, "{t}");
        // Moving away from the upper wall faster than it closes in: only the lower one.
        let q = particle(5.0, -2.0);
        assert_eq!(predict(&q, &walled(), radii).map(|(_, _, upper)| upper), Some(false));
        // Fixed radii: the wall in the direction of motion only, at (L − R − x)/v.
        let r = particle(5.0, 2.0);
        assert_eq!(predict(&r, &walled(), Radii::Fixed), Some((2.0, 0, true)));
        assert_eq!(predict(&particle(5.0, 0.0), &walled(), Radii::Fixed), None);
        // The upper wall with growth: v' = −v − 2g.
        let mut s = particle(8.0, 1.0);
        assert_eq!(resolve(&mut s, 0, true, 0.0, radii), 2.0 * 2.0 * 1.5);
        assert_eq!(s.velocity[0], -2.0);
    }
}
