//! The collision engine: particles in a box, events predicted (pure) and resolved (mutating)
//! by their [`sources`], one [`Simulation`] that owns them all, and a brute-force
//! [`ReferenceSimulation`] to check it against.
//!
//! The rooms, in the order data flows through a step:
//!
//! * [`geometry`]: [`Particle`], [`SimBox`], [`Boundary`], minimum image; [`motion`]: the
//!   free-flight law, the one place that says where a particle is.
//! * [`sources`]: the one [`Event`] type and its total order, and one file per event source —
//!   pair collisions, walls, the neighbourhood, sampling — each a pure `predict` and a mutating
//!   `resolve`; what a resolved event reports ([`Outcome`]).
//! * [`collision`]: the collision rule and the [`Impulse`] it reports.
//! * `neighbours`: who can touch whom (the cell grid that follows the particles, or neighbour
//!   lists with a skin); `search`: a particle's earliest collision among its neighbours, fast;
//!   `queue`: one pending event per particle (a calendar, or a tournament tree).
//! * [`simulation`]: the event loop; [`params`]: its tunables ([`EngineParams`]); [`setup`]:
//!   what makes a valid start.
//! * `timing`: the speed machinery behind one wall (lookahead, prefetch, huge pages, cache
//!   size); nothing in it changes a result.
//! * [`reference`](mod@reference): the O(N²) reference; [`init`]: initial states.
//!
//! The internals the benchmarks time are reachable through [`internals`], which is not part
//! of the API.

pub(crate) mod arrays;
pub mod collision;
pub mod geometry;
pub mod init;
pub mod motion;
pub(crate) mod neighbours;
pub mod params;
pub(crate) mod queue;
pub mod reference;
pub(crate) mod search;
pub mod setup;
pub mod simulation;
pub mod sources;
pub(crate) mod timing;

pub use collision::{Body, Impulse, Restitution, RestitutionError, resolve_growing_pair, resolve_pair};
pub use geometry::{Boundary, Particle, SimBox};
pub use motion::Radii;
pub use neighbours::{
    GROWTH_STRETCH, LISTS_FROM, LISTS_FROM_3D, Neighbourhood, RANGE_HOLDS, RANGE_HOLDS_3D, UnknownNeighbourhood,
};
pub use params::{EngineParams, QueueChoice, Switch};
pub use reference::ReferenceSimulation;
pub use setup::{OverlapAudit, SetupError, check_box};
pub use simulation::divided::{Divided, Lead, Ordered, Side, Stop, Unordered};
pub use simulation::{Simulation, SimulationState};
pub use sources::growth::{Ending, Growth};
pub use sources::{Event, EventCounts, EventKind, MAX_PARTICLES, Outcome};

/// The engine's internals that the benchmarks time piece by piece (`benches/engine.rs`) and
/// the hardware's floor shares (huge pages). Not part of the API: hidden from the
/// documentation, and free to change with the engine.
#[doc(hidden)]
pub mod internals {
    pub use super::queue::{EventQueue, QueueKind};
    pub use super::search::{HALF, LANES, Lanes, bracket_half, bracket_neighbours};
    pub use super::sources::pair::{PairBracket, bracket as bracket_pair, positions as pair_positions};
    pub use super::timing::huge_page_bytes;

    /// Huge pages for the floor's arrays, as the engine's (see `engine/timing/pages.rs`).
    pub mod pages {
        pub use crate::engine::timing::{collect, filled, moved};
    }
    pub use super::timing::{prefetch, prefetch_address};
}
