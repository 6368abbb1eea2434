//! The collision engine: particles in a box, events predicted (pure) and resolved (mutating),
//! one [`Simulation`] that owns them all, and a brute-force [`ReferenceSimulation`] to check
//! it against.
//!
//! * [`geometry`]: [`Particle`], [`SimBox`], [`Boundary`], minimum image.
//! * [`collision`]: the velocity update and the [`Impulse`] it reports.
//! * [`events`]: event types, their total order, the pure predictions.
//! * [`cells`]: the cell grid (following the particles, or of neighbour-list centres).
//! * [`neighbours`]: the grid that follows the particles, or neighbour lists with a skin.
//! * [`queue`]: one pending event per particle, in a calendar of time buckets or a tournament tree.
//! * [`cache`]: the level-2 cache's size, which sets where the lookahead starts.
//! * [`pages`]: huge pages for the large arrays (with `prefetch`, the crate's only `unsafe` code).
//! * `prefetch`: the cache hint of the lookahead.
//! * [`simulation`]: the event loop.
//! * [`reference`](mod@reference): the O(N²) reference.
//! * [`init`]: initial states (lattices, random placement, Maxwell or fixed-speed velocities).

pub mod cache;
pub mod cells;
pub mod collision;
pub mod events;
pub mod geometry;
pub mod init;
pub mod neighbours;
pub mod pages;
pub(crate) mod prefetch;
pub mod queue;
pub mod reference;
pub mod simulation;

pub use collision::{Body, Impulse, Restitution, RestitutionError, resolve_pair};
pub use geometry::{Boundary, Particle, SimBox};
pub use neighbours::{Neighbourhood, UnknownNeighbourhood};
pub use reference::ReferenceSimulation;
pub use simulation::{EventCounts, Outcome, OverlapAudit, SetupError, Simulation, SimulationState, check_box};
