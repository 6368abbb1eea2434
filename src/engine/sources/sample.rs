//! Sampling: scheduled instants at which the observers close a sample (a row of the time
//! series). A global event — it belongs to no particle — so the engine keeps it beside the
//! queue and compares it with the queue's earliest in the one total order.
//!
//! *Predict* (pure): the next instant. *Resolve* (mutating): the clock moves there and the
//! next instant is scheduled. An interval below the clock's resolution (`t + Δt = t`) would
//! sample at the same instant forever; sampling stops instead.

use serde::{Deserialize, Serialize};

/// The sampling schedule.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Sampling {
    /// Time between samples (`None`: no sampling).
    pub interval: Option<f64>,
    /// The next sampling instant, if any.
    pub next: Option<f64>,
}

impl Sampling {
    /// Every `interval`, the first at `now + interval`.
    pub fn every(now: f64, interval: f64) -> Sampling {
        Sampling { interval: Some(interval), next: Some(now + interval) }
    }

    /// The next sampling instant.
    #[inline]
    pub fn predict(&self) -> Option<f64> {
        self.next
    }

    /// The instant `t` is reached: schedules the next one.
    pub fn resolve(&mut self, t: f64) {
        self.next = self.interval.map(|dt| t + dt).filter(|&next| next > t);
    }
}
