//! Initial states in 2D: where the disks start and how fast.
//!
//! Placement: a triangular or square lattice (dense states, up to η ≈ 0.72 and beyond
//! without overlap), or random sequential placement with rejection (dilute states).
//! Velocities: Maxwell–Boltzmann (each component normal with variance kT/m), or one speed
//! per species in uniformly random directions (`|v| = √(2kT/m)` in 2D, for relaxation
//! experiments). Then the total momentum is removed along periodic axes, and all
//! velocities are scaled so that `2K / dof` equals the target kT exactly (to rounding).
//! Everything random comes from one seeded `Xoshiro256PlusPlus` (portable and
//! reproducible; rand documents `StdRng` and `SmallRng` as not portable).

use super::geometry::{Boundary, Particle, SimBox};
use nalgebra::{SVector, Vector2};
use rand::rngs::Xoshiro256PlusPlus;
use rand::seq::SliceRandom;
use rand::{RngExt, SeedableRng};
use rand_distr::{Distribution, Normal};
use serde::{Deserialize, Serialize};
use std::f64::consts::{PI, TAU};
use std::fmt;

/// One kind of disk.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Species {
    /// How many.
    pub count: usize,
    /// Radius (σ/2 for a disk of diameter σ).
    pub radius: f64,
    /// Mass.
    pub mass: f64,
}

/// Where the disks start.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Placement {
    /// Random sequential placement with rejection (dilute states).
    Random,
    /// Triangular lattice (vacancies chosen at random when N does not fill it).
    Triangular,
    /// Square lattice.
    Square,
}

/// How the disks start moving.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Velocities {
    /// Maxwell–Boltzmann at kT.
    Maxwell,
    /// One speed per species, √(2kT/m), random directions.
    FixedSpeed,
}

/// Why an initial state could not be built.
#[non_exhaustive]
#[derive(Clone, Debug, PartialEq)]
pub enum InitError {
    /// Random placement gave up: the density is too high for it.
    CannotPlace {
        /// Particles placed before giving up.
        placed: usize,
        /// Particles requested.
        requested: usize,
    },
    /// A periodic box with all axes periodic needs two particles for a temperature (the
    /// momentum is removed).
    TooFewForTemperature,
}

impl fmt::Display for InitError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            InitError::CannotPlace { placed, requested } => write!(
                f,
                "random placement gave up after {placed} of {requested} disks: the density is too high for it (use placement = \"triangular\" or \"square\")"
            ),
            InitError::TooFewForTemperature => {
                write!(f, "a fully periodic box needs at least 2 particles (the total momentum is removed)")
            }
        }
    }
}

impl std::error::Error for InitError {}

/// Total disk area Σ πRᵢ².
pub fn disk_area(species: &[Species]) -> f64 {
    species.iter().map(|s| s.count as f64 * PI * s.radius * s.radius).sum()
}

/// The box with packing fraction `eta` for these species. For a triangular lattice in a
/// periodic box the aspect ratio is the lattice's own (so the lattice is perfect and
/// wraps without defects); otherwise it is `aspect = Ly/Lx`.
pub fn box_for_packing_fraction(
    species: &[Species],
    eta: f64,
    boundary: [Boundary; 2],
    placement: Placement,
    aspect: f64,
) -> SimBox<2> {
    let n: usize = species.iter().map(|s| s.count).sum();
    let area = disk_area(species) / eta;
    let aspect = if placement == Placement::Triangular && boundary == [Boundary::Periodic; 2] {
        let (nx, ny) = triangular_shape(n, true);
        ny as f64 * 3f64.sqrt() / 2.0 / nx as f64
    } else {
        aspect
    };
    let lx = (area / aspect).sqrt();
    SimBox { lengths: Vector2::new(lx, lx * aspect), boundary }
}

/// Columns and rows of a near-square triangular lattice with at least `n` sites (an even
/// number of rows when it must wrap periodically).
fn triangular_shape(n: usize, even_rows: bool) -> (usize, usize) {
    let nx = ((n as f64 * 3f64.sqrt() / 2.0).sqrt().round() as usize).max(1);
    let mut ny = n.div_ceil(nx).max(1);
    if even_rows && ny % 2 == 1 {
        ny += 1;
    }
    (nx, ny)
}

/// Coordinate of lattice index `k` (plus `offset` ∈ [0, 1)) along an axis of length `l`
/// with `count` sites: centred cells when periodic; spread from `r` to `l − r` between walls.
fn lattice_coordinate(k: usize, offset: f64, count: usize, l: f64, boundary: Boundary, r: f64, max_offset: f64) -> f64 {
    match boundary {
        Boundary::Periodic => (k as f64 + offset + 0.5) * l / count as f64,
        Boundary::Wall => {
            let span = count as f64 - 1.0 + max_offset;
            // Clamped: r + (n−1)·((l − 2r)/(n−1)) can round one ulp past l − r.
            if span <= 0.0 { l / 2.0 } else { (r + (k as f64 + offset) * (l - 2.0 * r) / span).clamp(r, l - r) }
        }
    }
}

/// Builds the initial particles.
pub fn initial_particles(
    species: &[Species],
    sim_box: &SimBox<2>,
    placement: Placement,
    velocities: Velocities,
    kt: f64,
    seed: u64,
) -> Result<Vec<Particle<2>>, InitError> {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    // Species of each particle, in a random order.
    let mut kinds: Vec<usize> = species.iter().enumerate().flat_map(|(k, s)| std::iter::repeat_n(k, s.count)).collect();
    kinds.shuffle(&mut rng);
    let n = kinds.len();
    let rmax = species.iter().map(|s| s.radius).fold(0.0, f64::max);
    let positions = match placement {
        Placement::Random => random_positions(&kinds, species, sim_box, &mut rng)?,
        Placement::Triangular | Placement::Square => {
            let triangular = placement == Placement::Triangular;
            let (nx, ny) = if triangular {
                triangular_shape(n, sim_box.boundary[1] == Boundary::Periodic)
            } else {
                let nx = (n as f64).sqrt().ceil() as usize;
                (nx, n.div_ceil(nx))
            };
            let mut sites = Vec::with_capacity(nx * ny);
            for row in 0..ny {
                let offset = if triangular && row % 2 == 1 { 0.5 } else { 0.0 };
                let max_offset = if triangular { 0.5 } else { 0.0 };
                let x = |col| {
                    lattice_coordinate(col, offset, nx, sim_box.lengths[0], sim_box.boundary[0], rmax, max_offset)
                };
                let y = lattice_coordinate(row, 0.0, ny, sim_box.lengths[1], sim_box.boundary[1], rmax, 0.0);
                sites.extend((0..nx).map(|col| Vector2::new(x(col), y)));
            }
            if sites.len() > n {
                sites.shuffle(&mut rng);
                sites.truncate(n);
                // Keep a spatial order (row-major) for cache locality; vacancies stay random.
                sites.sort_by(|a, b| a[1].total_cmp(&b[1]).then(a[0].total_cmp(&b[0])));
            }
            sites
        }
    };
    let mut particles: Vec<Particle<2>> = positions
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
                let normal = Normal::new(0.0, (kt / p.mass).sqrt()).expect("kT and m are positive");
                Vector2::new(normal.sample(&mut rng), normal.sample(&mut rng))
            }
            Velocities::FixedSpeed => {
                let theta: f64 = rng.random_range(0.0..TAU);
                Vector2::new(theta.cos(), theta.sin()) * (2.0 * kt / p.mass).sqrt()
            }
        };
    }
    set_temperature(&mut particles, sim_box, kt)?;
    Ok(particles)
}

/// Removes the total momentum along periodic axes, then scales every velocity so that
/// `2K/dof = kt` (dof = 2N less one per periodic axis).
pub fn set_temperature(particles: &mut [Particle<2>], sim_box: &SimBox<2>, kt: f64) -> Result<(), InitError> {
    let total_mass: f64 = particles.iter().map(|p| p.mass).sum();
    let momentum: SVector<f64, 2> = particles.iter().map(|p| p.velocity * p.mass).sum();
    for a in 0..2 {
        if sim_box.boundary[a] == Boundary::Periodic {
            let drift = momentum[a] / total_mass;
            for p in particles.iter_mut() {
                p.velocity[a] -= drift;
            }
        }
    }
    let dof = (2 * particles.len() - sim_box.periodic_axes()) as f64;
    let kinetic: f64 = particles.iter().map(Particle::kinetic_energy).sum();
    if dof <= 0.0 || kinetic <= 0.0 {
        return Err(InitError::TooFewForTemperature);
    }
    let scale = (kt * dof / (2.0 * kinetic)).sqrt();
    for p in particles.iter_mut() {
        p.velocity *= scale;
    }
    Ok(())
}

/// Random sequential placement: each disk at a uniformly random accessible position,
/// rejected if it overlaps one already placed (minimum image); up to 10⁴ tries per disk.
fn random_positions(
    kinds: &[usize],
    species: &[Species],
    sim_box: &SimBox<2>,
    rng: &mut Xoshiro256PlusPlus,
) -> Result<Vec<SVector<f64, 2>>, InitError> {
    const TRIES: usize = 10_000;
    let mut placed: Vec<(SVector<f64, 2>, f64)> = Vec::with_capacity(kinds.len());
    for &k in kinds {
        let r = species[k].radius;
        let mut ok = false;
        for _ in 0..TRIES {
            let mut x = SVector::<f64, 2>::zeros();
            for a in 0..2 {
                let (lo, hi) = match sim_box.boundary[a] {
                    Boundary::Periodic => (0.0, sim_box.lengths[a]),
                    Boundary::Wall => (r, sim_box.lengths[a] - r),
                };
                x[a] = if hi > lo { rng.random_range(lo..hi) } else { lo };
            }
            let clear = placed.iter().all(|(y, s)| {
                let d = y - x;
                let d = d + sim_box.minimum_image_shift(&d);
                d.norm() >= r + s
            });
            if clear {
                placed.push((x, r));
                ok = true;
                break;
            }
        }
        if !ok {
            return Err(InitError::CannotPlace { placed: placed.len(), requested: kinds.len() });
        }
    }
    Ok(placed.into_iter().map(|(x, _)| x).collect())
}
