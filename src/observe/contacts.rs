//! The contact network of a dense packing: contacts per particle, rattlers, isostaticity.
//!
//! A jammed hard-particle packing is held by its contacts. Two particles are *in contact*
//! when their gap `|rⱼ − rᵢ| − σᵢⱼ` is at most `tolerance·σᵢⱼ` (a particle and a wall, when
//! its gap is at most `tolerance` times its diameter). At a reduced pressure `Z` the typical
//! gap of a contact is about `d·φ/Z` diameters (free-volume theory), while a gap that is not
//! a contact stays of order one diameter: any tolerance between the two separates them, and
//! the result does not depend on it over decades (tested).
//!
//! *Rattlers* are the particles the network does not hold: caged but free to move. They are
//! removed one after another — any particle with fewer than `d + 1` contacts among the
//! remaining ones (a particle held in `d` dimensions needs at least `d + 1` contacts, not
//! all on one side) — until none is left to remove; removing one can free its neighbours.
//! The mean contact number of the rest, `z = 2·(contacts among them)/(their count)`
//! (a wall contact counts once, for its particle), is `2d` for an isostatic packing — the
//! number of constraints equals the number of degrees of freedom (Donev, Torquato &
//! Stillinger, PRE 71, 011105 (2005); O'Hern et al., PRE 68, 011306 (2003)); a finite
//! periodic packing has `z = 2d(1 − 1/N′)` plus one, as the global translations are free.

use crate::engine::Simulation;
use serde::{Deserialize, Serialize};

/// The contact network of a state.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Contacts {
    /// The gap tolerance used (a fraction of the contact distance).
    pub tolerance: f64,
    /// Contacts of each particle (pairs and walls), rattlers included.
    pub per_particle: Vec<u32>,
    /// The rattlers, in increasing order.
    pub rattlers: Vec<usize>,
    /// Contacts among the particles that are not rattlers (pairs), and of them with walls.
    pub held_contacts: usize,
    /// Mean contacts per particle that is not a rattler, `2·pairs + walls` over their count
    /// (0 when every particle rattles).
    pub contacts_per_particle: f64,
    /// The largest gap counted as a contact, and the smallest gap not counted (fractions of
    /// the contact distance; the gulf between them shows the tolerance is safe).
    pub largest_contact_gap: f64,
}

/// The contact network of `sim`'s present state (see the [module docs](self)).
pub fn contacts<const D: usize>(sim: &Simulation<D>, tolerance: f64) -> Contacts {
    let n = sim.particles().len();
    let (pairs, walls) = sim.near_contacts(tolerance);
    let mut per_particle = vec![0u32; n];
    for &(i, j, _) in &pairs {
        per_particle[i] += 1;
        per_particle[j] += 1;
    }
    for &(i, ..) in &walls {
        per_particle[i] += 1;
    }
    // Remove rattlers until none is left: a work list of particles whose count fell.
    let mut count = per_particle.clone();
    let mut removed = vec![false; n];
    let mut partners: Vec<Vec<usize>> = vec![Vec::new(); n];
    for &(i, j, _) in &pairs {
        partners[i].push(j);
        partners[j].push(i);
    }
    let held = D as u32 + 1;
    let mut work: Vec<usize> = (0..n).filter(|&i| count[i] < held).collect();
    while let Some(i) = work.pop() {
        if removed[i] {
            continue;
        }
        removed[i] = true;
        for &j in &partners[i] {
            if !removed[j] {
                count[j] -= 1;
                if count[j] < held {
                    work.push(j);
                }
            }
        }
    }
    let rattlers: Vec<usize> = (0..n).filter(|&i| removed[i]).collect();
    let kept = n - rattlers.len();
    let pair_contacts = pairs.iter().filter(|&&(i, j, _)| !removed[i] && !removed[j]).count();
    let wall_contacts = walls.iter().filter(|&&(i, ..)| !removed[i]).count();
    let largest_contact_gap =
        pairs.iter().map(|p| p.2).chain(walls.iter().map(|w| w.3)).fold(f64::NEG_INFINITY, f64::max);
    Contacts {
        tolerance,
        per_particle,
        rattlers,
        held_contacts: pair_contacts + wall_contacts,
        contacts_per_particle: if kept == 0 { 0.0 } else { (2 * pair_contacts + wall_contacts) as f64 / kept as f64 },
        largest_contact_gap,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::init::{Placement, Species, Velocities, box_for_packing_fraction, initial_particles};
    use crate::engine::{Boundary, Particle, SimBox};
    use nalgebra::SVector;

    fn lattice<const D: usize>(placement: Placement, eta: f64, n: usize) -> Simulation<D> {
        let species = vec![Species { count: n, radius: 0.5, mass: 1.0 }];
        let sim_box = box_for_packing_fraction(&species, eta, [Boundary::Periodic; D], placement, None);
        let particles = initial_particles(&species, &sim_box, placement, Velocities::Maxwell, 1.0, 1).unwrap();
        Simulation::new(particles, sim_box).unwrap()
    }

    /// Lattices a hair (10⁻¹⁰ in φ, gaps of some 10⁻¹¹σ) below their close packing have
    /// their coordination numbers: 6 (triangular), 4 (square), 12 (fcc); a lattice further
    /// below has none; and the answer holds from a tolerance of 10⁻⁹ to 10⁻³ (the gaps are
    /// tiny or of order one).
    #[test]
    fn lattices_have_their_coordination_numbers() {
        let hair = 1.0 - 1e-10;
        for tolerance in [1e-9, 1e-6, 1e-3] {
            let c = contacts(&lattice::<2>(Placement::Triangular, 0.9068996821171089 * hair, 100), tolerance);
            assert!(c.per_particle.iter().all(|&k| k == 6), "{:?}", &c.per_particle[..8]);
            assert_eq!((c.contacts_per_particle, c.rattlers.len()), (6.0, 0));
            let c = contacts(&lattice::<2>(Placement::Square, std::f64::consts::FRAC_PI_4 * hair, 64), tolerance);
            assert_eq!((c.contacts_per_particle, c.rattlers.len()), (4.0, 0));
            let c = contacts(&lattice::<3>(Placement::Fcc, 0.7404804896930611 * hair, 108), tolerance);
            assert_eq!((c.contacts_per_particle, c.rattlers.len()), (12.0, 0));
        }
        let c = contacts(&lattice::<2>(Placement::Triangular, 0.85, 100), 1e-6);
        assert!(c.per_particle.iter().all(|&k| k == 0));
        assert_eq!((c.rattlers.len(), c.contacts_per_particle), (100, 0.0));
    }

    /// A particle with two contacts in 2D is a rattler, and removing it can free another:
    /// a chain of three touching disks in a periodic box is all rattlers; a disk touching a
    /// wall counts the wall.
    #[test]
    fn rattlers_are_removed_until_none_is_left() {
        let disk = |x: f64, y: f64| Particle {
            position: SVector::from([x, y]),
            velocity: SVector::from([0.1, 0.0]),
            time: 0.0,
            radius: 0.5,
            mass: 1.0,
            species: 0,
            events: 0,
        };
        let periodic = SimBox { lengths: SVector::from([10.0, 10.0]), boundary: [Boundary::Periodic; 2] };
        let chain = vec![disk(2.0, 5.0), disk(3.0, 5.0), disk(4.0, 5.0)];
        let c = contacts(&Simulation::new(chain, periodic).unwrap(), 1e-9);
        assert_eq!(c.per_particle, vec![1, 2, 1]);
        assert_eq!(c.rattlers, vec![0, 1, 2]);
        // Touching the lower wall and two neighbours: three contacts; its neighbours have one.
        let walled = SimBox { lengths: SVector::from([10.0, 10.0]), boundary: [Boundary::Wall; 2] };
        let c = contacts(&Simulation::new(vec![disk(5.0, 0.5), disk(4.0, 0.5), disk(6.0, 0.5)], walled).unwrap(), 1e-9);
        assert_eq!(c.per_particle, vec![3, 2, 2]);
        assert_eq!(c.rattlers.len(), 3, "the neighbours rattle, and then so does the middle one");
    }
}
