//! Initial states in `D` dimensions: where the particles start and how fast.
//!
//! Placement ([`Placement`]): in 2D a triangular or square lattice whose shape follows the
//! box (`lattice`; dense states, up to η ≈ 0.9 for the triangular lattice); in any dimension
//! random sequential placement with rejection, largest particles first, in expected O(N)
//! (`random`; dilute states and size-asymmetric mixtures). When a placement cannot work, the
//! error says how far it got and what would.
//!
//! Velocities: Maxwell–Boltzmann (each component normal with variance kT/m), or one speed
//! per species in uniformly random directions (`|v| = √(D·kT/m)`, for relaxation
//! experiments). Then the total momentum is removed along periodic axes, and all
//! velocities are scaled so that `2K / dof` equals the target kT exactly (to rounding).
//! Everything random comes from one seeded `Xoshiro256PlusPlus` (portable and
//! reproducible; rand documents `StdRng` and `SmallRng` as not portable).

mod lattice;
mod random;

use super::geometry::{Boundary, Particle, SimBox};
use crate::theory::{RSA_JAMMING_2D, RSA_JAMMING_3D};
use nalgebra::{SVector, Vector2};
use rand::rngs::Xoshiro256PlusPlus;
use rand::seq::SliceRandom;
use rand::{RngExt, SeedableRng};
use rand_distr::{Distribution, Normal, UnitSphere};
use serde::{Deserialize, Serialize};
use std::f64::consts::{PI, TAU};
use std::fmt;

/// One kind of disk.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Species {
    /// How many.
    pub count: usize,
    /// Radius (σ/2 for a disk of diameter σ).
    pub radius: f64,
    /// Mass.
    pub mass: f64,
}

/// Where the particles start.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Placement {
    /// Random sequential placement with rejection (dilute states; any dimension).
    Random,
    /// Triangular lattice (vacancies chosen at random when N does not fill it; 2D).
    Triangular,
    /// Square lattice (2D).
    Square,
    /// Face-centred cubic lattice, four sites per cubic cell (vacancies at random; 3D).
    Fcc,
    /// Simple cubic lattice (3D).
    SimpleCubic,
}

impl Placement {
    /// Its name in a configuration.
    pub fn name(self) -> &'static str {
        match self {
            Placement::Random => "random",
            Placement::Triangular => "triangular",
            Placement::Square => "square",
            Placement::Fcc => "fcc",
            Placement::SimpleCubic => "simple_cubic",
        }
    }

    /// Whether it can place particles in `d` dimensions.
    pub fn exists_in(self, d: usize) -> bool {
        match self {
            Placement::Random => true,
            Placement::Triangular | Placement::Square => d == 2,
            Placement::Fcc | Placement::SimpleCubic => d == 3,
        }
    }

    /// The placements of `d` dimensions, as a configuration names them.
    pub fn allowed_in(d: usize) -> &'static str {
        match d {
            2 => r#"placement = "triangular", "square" or "random""#,
            3 => r#"placement = "fcc", "simple_cubic" or "random""#,
            _ => r#"placement = "random""#,
        }
    }
}

/// How the disks start moving.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Velocities {
    /// Maxwell–Boltzmann at kT.
    Maxwell,
    /// One speed per species, √(D·kT/m), random directions.
    FixedSpeed,
}

/// Why an initial state could not be built.
#[non_exhaustive]
#[derive(Clone, Debug, PartialEq)]
pub enum InitError {
    /// Random placement gave up: no room was found for a particle in 10⁴ tries.
    CannotPlace {
        /// The dimension of the run (what the message calls a disk or a sphere).
        dimension: usize,
        /// Disks placed before giving up.
        placed: usize,
        /// Disks requested.
        requested: usize,
        /// The species of the disk that found no room.
        species: usize,
        /// Its radius.
        radius: f64,
        /// The packing fraction of the disks placed.
        reached: f64,
        /// The packing fraction asked for.
        requested_eta: f64,
        /// The packing fraction up to which a lattice of this dimension holds these species
        /// with its sites a largest diameter apart ([`lattice_limit`]).
        lattice_fits_up_to: Option<f64>,
    },
    /// A lattice placement asked for in a dimension it does not exist in.
    NotInDimension {
        /// The placement.
        placement: Placement,
        /// The dimension of the run.
        dimension: usize,
    },
    /// Even the best lattice shape puts its sites closer than the smallest diameter.
    LatticeDoesNotFit {
        /// "triangular", "square", "fcc" or "simple cubic".
        lattice: &'static str,
        /// The best shape: grid points along each axis (columns, rows, layers; for fcc the
        /// points of the cubic grid of half a cell, every other one a site).
        shape: Vec<usize>,
        /// The distance between its nearest sites.
        spacing: f64,
        /// The largest diameter.
        diameter: f64,
        /// The packing fraction at which the same lattice in a box of the same shape
        /// would fit, if it can be said.
        fits_up_to: Option<f64>,
    },
    /// A box edge shorter than the largest diameter.
    BoxTooSmall {
        /// The axis.
        axis: usize,
        /// Its length.
        length: f64,
        /// The largest diameter.
        diameter: f64,
    },
    /// No temperature can be set: a box with all axes periodic needs two particles (the
    /// momentum is removed), and there must be a finite, non-zero kinetic energy to scale.
    TooFewForTemperature,
}

impl fmt::Display for InitError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            InitError::CannotPlace {
                dimension,
                placed,
                requested,
                species,
                radius,
                reached,
                requested_eta,
                lattice_fits_up_to,
            } => {
                let (particle, lattice, a_lattice, rsa) = if *dimension == 3 {
                    ("sphere", "fcc", "an fcc", RSA_JAMMING_3D)
                } else {
                    ("disk", "triangular", "a triangular", RSA_JAMMING_2D)
                };
                write!(
                    f,
                    "random placement found no room for {particle} {} of {requested} (species {species}, radius {radius}) in {} tries, at packing fraction {reached:.4} of the {requested_eta:.4} asked for (random sequential placement jams near η ≈ {rsa} for equal {particle}s, and gives up before): ",
                    placed + 1,
                    random::TRIES
                )?;
                match lattice_fits_up_to {
                    Some(fits) if fits >= requested_eta => {
                        write!(f, "use placement = \"{lattice}\", which holds these {particle}s up to η ≈ {fits:.4}")
                    }
                    Some(fits) => write!(
                        f,
                        "no placement reaches it: {a_lattice} lattice holds these {particle}s up to η ≈ {fits:.4}, random placement got to {reached:.4}; start at or below {:.4}",
                        fits.max(*reached)
                    ),
                    None => write!(f, "random placement got to {reached:.4}; start at or below it"),
                }
            }
            InitError::NotInDimension { placement, dimension } => write!(
                f,
                "placement = \"{}\" is not a lattice of {dimension}D; use {}",
                placement.name(),
                Placement::allowed_in(*dimension)
            ),
            InitError::LatticeDoesNotFit { lattice, shape, spacing, diameter, fits_up_to } => {
                let shape = shape.iter().map(|n| n.to_string()).collect::<Vec<_>>().join(" × ");
                let what = if *lattice == "fcc" { "grid points" } else { "sites" };
                write!(
                    f,
                    "a {lattice} lattice does not fit: its best shape in this box, {shape} {what}, puts them {spacing:.6} apart, less than the diameter {diameter}"
                )?;
                match fits_up_to {
                    Some(eta) => write!(
                        f,
                        "; in a box of this shape it fits up to packing fraction ≈ {eta:.4}, or give a box nearer the lattice's own shape"
                    ),
                    None => write!(f, "; make the box larger"),
                }
            }
            InitError::BoxTooSmall { axis, length, diameter } => {
                write!(f, "box edge {axis} = {length} is shorter than the largest diameter {diameter}")
            }
            InitError::TooFewForTemperature => write!(
                f,
                "no temperature can be set: a fully periodic box needs at least 2 moving particles (the total momentum is removed, which leaves one alone at rest), and the kinetic energy must be a finite number"
            ),
        }
    }
}

impl std::error::Error for InitError {}

/// The volume of a ball of radius `r` in `D` dimensions (an area in 2D): `πr²`, `4πr³/3`.
pub fn ball_volume<const D: usize>(r: f64) -> f64 {
    match D {
        1 => 2.0 * r,
        2 => PI * r * r,
        3 => 4.0 / 3.0 * PI * r * r * r,
        _ => unreachable!("particles live in 1 to 3 dimensions"),
    }
}

/// The total volume of the particles (their area in 2D), `Σ N_s·V(R_s)`.
pub fn particle_volume<const D: usize>(species: &[Species]) -> f64 {
    species
        .iter()
        .map(|s| match D {
            // Written out in 2D: the order of the products is that of every earlier release,
            // so that boxes built from a packing fraction are the same to the bit.
            2 => s.count as f64 * PI * s.radius * s.radius,
            _ => s.count as f64 * ball_volume::<D>(s.radius),
        })
        .sum()
}

/// The packing fraction up to which a perfect densest lattice of N sites holds these
/// species with nearest sites one largest diameter apart: `Σ V(Rᵢ) / (N·v_site)`, with the
/// volume per site `v_site = (√3/2)·σ_max²` of the triangular lattice in 2D and `σ_max³/√2`
/// of fcc in 3D.
pub fn lattice_limit<const D: usize>(species: &[Species]) -> Option<f64> {
    let n: f64 = species.iter().map(|s| s.count as f64).sum();
    let sigma = 2.0 * species.iter().map(|s| s.radius).fold(0.0, f64::max);
    match D {
        2 => Some(particle_volume::<2>(species) / (n * 0.5 * 3f64.sqrt() * sigma * sigma)),
        3 => Some(particle_volume::<3>(species) / (n * sigma * sigma * sigma / 2f64.sqrt())),
        _ => None,
    }
}

/// The box with packing fraction `eta` for these species, its edges in the proportions
/// `edges` (`[1, Ly/Lx, …]`, any scale). Without them, a triangular lattice in a periodic box
/// takes its own aspect (so that it is perfect and wraps without defects), and every other
/// start a square or cubic box (in which N = 4k³ spheres make a perfect fcc crystal).
pub fn box_for_packing_fraction<const D: usize>(
    species: &[Species],
    eta: f64,
    boundary: [Boundary; D],
    placement: Placement,
    edges: Option<[f64; D]>,
) -> SimBox<D> {
    let n: usize = species.iter().map(|s| s.count).sum();
    let volume = particle_volume::<D>(species) / eta;
    let edges = match edges {
        Some(edges) => edges,
        None if D == 2 && placement == Placement::Triangular && boundary.iter().all(|&b| b == Boundary::Periodic) => {
            let (nx, ny) = lattice::triangular_shape(n, true);
            std::array::from_fn(|a| if a == 1 { ny as f64 * 3f64.sqrt() / 2.0 / nx as f64 } else { 1.0 })
        }
        None => [1.0; D],
    };
    // In 2D with edges [1, a] this is √(V/a) and a·√(V/a), as every earlier release computed
    // it (boxes from a packing fraction are the same to the bit).
    let product: f64 = edges.iter().product();
    let unit = match D {
        2 => (volume / product).sqrt(),
        _ => (volume / product).cbrt(),
    };
    SimBox { lengths: SVector::from_fn(|a, _| unit * edges[a]), boundary }
}

/// Builds the initial particles.
pub fn initial_particles<const D: usize>(
    species: &[Species],
    sim_box: &SimBox<D>,
    placement: Placement,
    velocities: Velocities,
    kt: f64,
    seed: u64,
) -> Result<Vec<Particle<D>>, InitError> {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    // Species of each particle, in a random order.
    let mut kinds: Vec<usize> = species.iter().enumerate().flat_map(|(k, s)| std::iter::repeat_n(k, s.count)).collect();
    kinds.shuffle(&mut rng);
    let n = kinds.len();
    let rmax = species.iter().map(|s| s.radius).fold(0.0, f64::max);
    let rmin = species.iter().map(|s| s.radius).fold(f64::INFINITY, f64::min);
    for axis in 0..D {
        let length = sim_box.lengths[axis];
        if !(length >= 2.0 * rmax) {
            return Err(InitError::BoxTooSmall { axis, length, diameter: 2.0 * rmax });
        }
    }
    if !placement.exists_in(D) {
        return Err(InitError::NotInDimension { placement, dimension: D });
    }
    let positions: Vec<SVector<f64, D>> = match placement {
        Placement::Random => random::positions(&kinds, species, sim_box, &mut rng)?,
        Placement::Fcc | Placement::SimpleCubic => {
            let kind = if placement == Placement::Fcc { lattice::Kind::Fcc } else { lattice::Kind::SimpleCubic };
            let eta = particle_volume::<D>(species) / sim_box.volume();
            let space = SimBox {
                lengths: SVector::<f64, 3>::from_fn(|a, _| sim_box.lengths[a]),
                boundary: std::array::from_fn(|a| sim_box.boundary[a]),
            };
            let mut sites = lattice::sites_3d(kind, n, &space, rmax, rmin, eta)?;
            if sites.len() > n {
                sites.shuffle(&mut rng);
                sites.truncate(n);
                // Keep a spatial order (layer by layer, row by row) for cache locality.
                sites.sort_by(|a, b| a[2].total_cmp(&b[2]).then(a[1].total_cmp(&b[1])).then(a[0].total_cmp(&b[0])));
            }
            sites.into_iter().map(|s| SVector::from_fn(|a, _| s[a])).collect()
        }
        Placement::Triangular | Placement::Square => {
            let kind =
                if placement == Placement::Triangular { lattice::Kind::Triangular } else { lattice::Kind::Square };
            let eta = particle_volume::<D>(species) / sim_box.volume();
            let plane = SimBox {
                lengths: Vector2::new(sim_box.lengths[0], sim_box.lengths[1]),
                boundary: [sim_box.boundary[0], sim_box.boundary[1]],
            };
            let mut sites = lattice::sites(kind, n, &plane, rmax, rmin, eta)?;
            if sites.len() > n {
                sites.shuffle(&mut rng);
                sites.truncate(n);
                // Keep a spatial order (row-major) for cache locality; vacancies stay random.
                sites.sort_by(|a, b| a[1].total_cmp(&b[1]).then(a[0].total_cmp(&b[0])));
            }
            sites
        }
    };
    let mut particles: Vec<Particle<D>> = positions
        .into_iter()
        .zip(&kinds)
        .map(|(position, &k)| Particle {
            position,
            velocity: SVector::zeros(),
            time: 0.0,
            radius: species[k].radius,
            mass: species[k].mass,
            species: k as u32,
            events: 0,
        })
        .collect();
    for p in &mut particles {
        p.velocity = match velocities {
            Velocities::Maxwell => {
                let normal = Normal::new(0.0, (kt / p.mass).sqrt()).map_err(|_| InitError::TooFewForTemperature)?;
                // One draw per axis, in axis order.
                SVector::from_fn(|_, _| normal.sample(&mut rng))
            }
            Velocities::FixedSpeed => direction::<D>(&mut rng) * (D as f64 * kt / p.mass).sqrt(),
        };
    }
    set_temperature(&mut particles, sim_box, kt)?;
    Ok(particles)
}

/// A uniformly random direction: an angle in 2D, a point of the unit sphere in 3D.
fn direction<const D: usize>(rng: &mut Xoshiro256PlusPlus) -> SVector<f64, D> {
    match D {
        2 => {
            let theta: f64 = rng.random_range(0.0..TAU);
            SVector::from_fn(|a, _| if a == 0 { theta.cos() } else { theta.sin() })
        }
        3 => {
            let x: [f64; 3] = UnitSphere.sample(rng);
            SVector::from_fn(|a, _| x[a])
        }
        _ => SVector::from_fn(|_, _| if rng.random_bool(0.5) { 1.0 } else { -1.0 }),
    }
}

/// Removes the total momentum along periodic axes, then scales every velocity so that
/// `2K/dof = kt` (dof = D·N less one per periodic axis).
pub fn set_temperature<const D: usize>(
    particles: &mut [Particle<D>],
    sim_box: &SimBox<D>,
    kt: f64,
) -> Result<(), InitError> {
    let total_mass: f64 = particles.iter().map(|p| p.mass).sum();
    let momentum: SVector<f64, D> = particles.iter().map(|p| p.velocity * p.mass).sum();
    for a in 0..D {
        if sim_box.boundary[a] == Boundary::Periodic {
            let drift = momentum[a] / total_mass;
            for p in particles.iter_mut() {
                p.velocity[a] -= drift;
            }
        }
    }
    let dof = (D * particles.len()).saturating_sub(sim_box.periodic_axes()) as f64;
    let kinetic: f64 = particles.iter().map(Particle::kinetic_energy).sum();
    if dof <= 0.0 || !(kinetic > 0.0 && kinetic.is_finite()) {
        return Err(InitError::TooFewForTemperature);
    }
    let scale = (kt * dof / (2.0 * kinetic)).sqrt();
    for p in particles.iter_mut() {
        p.velocity *= scale;
    }
    Ok(())
}
