//! The query commands `collide roots` and `collide contact-time`: exact numbers in and out
//! ([`numbers`]: decimal or C99 hex floats, correctly rounded), and the JSON-lines protocol
//! that answers one request per line ([`protocol`]). The kernel underneath is
//! [`quadratic`]; nothing here knows particles or files.

pub mod numbers;
pub mod protocol;

pub use protocol::{DynBall, Query, QueryError, answer_lines, contact_time_dyn};
