//! The collision engine. Today: the velocity update of a colliding pair; the event loop,
//! cells, boundaries and the `Simulation` that owns them grow here (see ARCHITECTURE.md).

pub mod collision;

pub use collision::{Body, Impulse, Restitution, RestitutionError, resolve_pair};
