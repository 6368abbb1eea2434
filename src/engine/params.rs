//! The engine's tunables, apart from its results: how particles find their neighbours, which
//! queue holds the events, whether the timing machinery is used. Each has an automatic
//! default that is the fastest measured for the system's size and density; none changes a
//! trajectory — the events are the same bit for bit whatever is chosen (tested), only the
//! bookkeeping events and the speed differ.

pub use super::neighbours::Neighbourhood;
use serde::{Deserialize, Serialize};

/// How a [`Simulation`](super::Simulation) is built (faer's `*Params` style: every field has
/// an automatic default, [`EngineParams::default`]).
#[non_exhaustive]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct EngineParams {
    /// Neighbour lists or the cell grid that follows the particles.
    pub neighbourhood: Neighbourhood,
    /// The event queue's structure.
    pub queue: QueueChoice,
    /// Whether the next event's data is prefetched while one is processed.
    pub lookahead: Switch,
    /// Whether the large arrays ask for huge pages.
    pub huge_pages: Switch,
}

impl EngineParams {
    /// The defaults with the neighbourhood chosen.
    pub fn with_neighbourhood(neighbourhood: Neighbourhood) -> EngineParams {
        EngineParams { neighbourhood, ..EngineParams::default() }
    }
}

/// The event queue's structure.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum QueueChoice {
    /// The calendar while the engine's state fits the caches, the tournament tree beyond.
    #[default]
    Auto,
    /// Time buckets.
    Calendar,
    /// A 4-ary tournament tree.
    Tree,
}

/// On, off, or as the engine decides.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Switch {
    /// Where it pays (documented with each use).
    #[default]
    Auto,
    /// Always.
    On,
    /// Never.
    Off,
}

impl Switch {
    /// Whether it is on, given what `Auto` decides.
    pub fn resolve(self, auto: bool) -> bool {
        match self {
            Switch::Auto => auto,
            Switch::On => true,
            Switch::Off => false,
        }
    }
}
