//! The watchdog: a run whose clock stops, or that would need an absurd number of events to
//! reach its end, is stopped with a diagnostic instead of spinning.
//!
//! Every [`Limits::watchdog_events`] events it compares the simulated time and the fraction
//! of the phase done with what they were at its last look. The run is *stalled* if
//! - the clock did not move at all (a disk exactly as wide as a walled gap, a speed the
//!   clock cannot resolve: events at the same instant forever), or
//! - the fraction done did not grow, or grew so little that finishing would take more than
//!   [`Limits::max_projected_events`] events at that pace (a disk bouncing between walls one
//!   ulp apart; a run that asks for pair collisions in a system where none happen).
//!
//! A look costs nothing between looks but a counter; a stalled run ends with the
//! [`Stall`] in its summary.

use super::limits::Limits;
use crate::engine::{EventCounts, Outcome};
use serde::{Deserialize, Serialize};
use std::fmt;

/// Why a run was stopped.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Stall {
    /// Events between the two looks.
    pub events: u64,
    /// The clock at the first look.
    pub from: f64,
    /// The clock at the second.
    pub to: f64,
    /// The events between them, by kind.
    pub by_kind: EventCounts,
    /// The fraction of the phase done at the second look.
    pub done: f64,
    /// The events that finishing would take at this pace (+∞: no progress).
    pub projected: f64,
    /// The last event, in words.
    pub last: String,
}

impl fmt::Display for Stall {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let k = &self.by_kind;
        let kinds = format!(
            "{} pair collisions, {} wall collisions, {} neighbourhood updates, {} samples",
            k.pair, k.wall, k.rebuild, k.sample
        );
        if self.to <= self.from {
            write!(
                f,
                "the run is stuck: simulated time stayed at t = {:e} over {} events ({kinds}); the last was {}. A walled axis barely wider than a diameter, or a speed too high for the clock's resolution, does this",
                self.to, self.events, self.last
            )
        } else {
            write!(
                f,
                "the run is not getting anywhere: over {} events ({kinds}) simulated time went from {:e} to {:e} and the run got to {:.3e} of its length; at this pace it would need about {:.1e} more events; the last was {}",
                self.events, self.from, self.to, self.done, self.projected, self.last
            )
        }
    }
}

/// The watchdog's memory between looks.
#[derive(Clone, Debug)]
pub struct Watchdog {
    left: u64,
    time: f64,
    done: f64,
    counts: EventCounts,
}

impl Watchdog {
    /// Starts watching at clock `time` with `done` of the phase done.
    pub fn new(limits: &Limits, time: f64, done: f64, counts: EventCounts) -> Watchdog {
        Watchdog { left: limits.watchdog_events.max(1), time, done, counts }
    }

    /// Called after every event: whether it is time to [`look`](Self::look) (every
    /// [`Limits::watchdog_events`] events). Only a counter, so that the loop pays nothing
    /// more between looks.
    #[inline(always)]
    pub fn due(&mut self) -> bool {
        self.left -= 1;
        self.left == 0
    }

    /// Compares the clock and the fraction `done` with the last look; the stall, if any.
    #[cold]
    pub fn look<const D: usize>(
        &mut self,
        limits: &Limits,
        time: f64,
        done: f64,
        counts: EventCounts,
        last: &Outcome<D>,
    ) -> Option<Stall> {
        let events = limits.watchdog_events.max(1);
        let gained = done - self.done;
        let projected = if gained > 0.0 { (1.0 - done) / gained * events as f64 } else { f64::INFINITY };
        let stall = (time <= self.time || !(projected <= limits.max_projected_events)).then(|| Stall {
            events,
            from: self.time,
            to: time,
            by_kind: counts.since(&self.counts),
            done,
            projected,
            last: last.to_string(),
        });
        *self = Watchdog { left: events, time, done, counts };
        stall
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::Outcome;

    fn limits() -> Limits {
        Limits { watchdog_events: 4, max_projected_events: 1e6, ..Limits::default() }
    }

    fn look(dog: &mut Watchdog, time: f64, done: f64) -> Option<Stall> {
        let wall = Outcome::<2>::Wall { i: 3, axis: 0, upper: true, impulse: 0.0 };
        let mut stall = None;
        for _ in 0..4 {
            stall = if dog.due() { dog.look(&limits(), time, done, EventCounts::default(), &wall) } else { None };
        }
        stall
    }

    /// A clock that does not move is a stall, however much else happens; so is progress too
    /// slow to finish within the projected events; a run that advances is left alone.
    #[test]
    fn a_stuck_or_crawling_run_is_stopped_and_a_moving_one_is_not() {
        let mut dog = Watchdog::new(&limits(), 1.0, 0.1, EventCounts::default());
        assert_eq!(look(&mut dog, 1.5, 0.2), None);
        let stuck = look(&mut dog, 1.5, 0.3).expect("the clock stayed at 1.5");
        assert!(stuck.to_string().contains("stuck: simulated time stayed at t = 1.5e0"), "{stuck}");
        assert!(stuck.to_string().contains("particle 3"), "{stuck}");
        // 4 events for 10⁻⁹ of the run: 4·10⁹ more events, beyond 10⁶.
        let crawl = look(&mut dog, 2.0, 0.3 + 1e-9).expect("too slow");
        assert!(crawl.projected > 1e9 && crawl.to_string().contains("not getting anywhere"), "{crawl}");
        assert_eq!(look(&mut dog, 2.5, 0.5), None);
        // No progress at all, with the clock moving: a run that asks for what never comes.
        assert!(look(&mut dog, 3.0, 0.5).is_some_and(|s| s.projected == f64::INFINITY));
    }
}
