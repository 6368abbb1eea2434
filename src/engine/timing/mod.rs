//! The timing machinery, behind one wall: everything the engine does only to be fast on real
//! hardware — the lookahead that prefetches the next event's data, the cache hint itself,
//! huge pages for the large arrays, and the cache size that decides where the lookahead
//! starts. Nothing here changes a result: with every part of it on or off, the events are the
//! same bit for bit (tested), only the time differs.
//!
//! The engine meets it through [`Timing`] alone, at six points: the store its structures
//! build their large arrays in ([`Timing::store`]) and five places
//! in a step — before an event is resolved
//! ([`Timing::begin`]; [`Timing::leaving`] too when a particle leaves its skin), before a
//! search among a particle's neighbours ([`Timing::searching`]), between the
//! two predictions that follow a collision ([`Timing::middle`]) and after them
//! ([`Timing::end`]). It reads the engine's structures
//! through [`Reading`] and never writes them; the structures expose where their data lives,
//! never a hint of their own.

mod cache;
mod lookahead;
mod pages;
mod prefetch;

pub use lookahead::Ahead;
pub use pages::{collect, filled, huge_page_bytes, moved};
pub use prefetch::{prefetch, prefetch_address};

use super::arrays::{Plain, Store};
use super::geometry::Particle;
use super::neighbours::Neighbours;
use super::params::{EngineParams, Switch};
use super::queue::EventQueue;
use super::search::{NEAR, Search};

/// The store of [`Timing::store`].
#[derive(Clone, Copy, Debug)]
pub(crate) enum Arrays {
    /// Ordinary vectors.
    Plain(Plain),
    /// Huge pages for the arrays large enough.
    HugePages(pages::HugePages),
}

impl Store for Arrays {
    fn collect<T>(&self, items: impl ExactSizeIterator<Item = T>) -> Vec<T> {
        match self {
            Arrays::Plain(s) => s.collect(items),
            Arrays::HugePages(s) => s.collect(items),
        }
    }

    fn filled<T: Clone>(&self, n: usize, value: T) -> Vec<T> {
        match self {
            Arrays::Plain(s) => s.filled(n, value),
            Arrays::HugePages(s) => s.filled(n, value),
        }
    }

    fn moved<T>(&self, v: Vec<T>) -> Vec<T> {
        match self {
            Arrays::Plain(s) => s.moved(v),
            Arrays::HugePages(s) => s.moved(v),
        }
    }
}

/// What the timing room may read: the engine's structures, as a step leaves them.
pub(crate) struct Reading<'a, const D: usize> {
    /// The particle records.
    pub particles: &'a [Particle<D>],
    /// The pending events.
    pub queue: &'a EventQueue,
    /// The neighbour lists or cells.
    pub neighbours: &'a Neighbours<D>,
}

/// The timing machinery of one simulation (what [`EngineParams`] resolved to).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Timing {
    /// Prefetch the next event's data while processing one.
    pub(crate) lookahead: bool,
    /// Move the large arrays into huge pages.
    huge_pages: bool,
}

impl Timing {
    /// The machinery for `n` particles: the lookahead from where the engine's state leaves
    /// the level-2 cache ([`lookahead::pays`]), huge pages for the arrays large enough.
    pub(crate) fn new(params: &EngineParams, n: usize) -> Timing {
        Timing { lookahead: params.lookahead.resolve(lookahead::pays(n)), huge_pages: params.huge_pages != Switch::Off }
    }

    /// Where the engine's structures build their large arrays: in memory backed by huge
    /// pages (those of 4 MB or more), or in ordinary vectors when huge pages are off.
    pub(crate) fn store(&self) -> Arrays {
        if self.huge_pages { Arrays::HugePages(pages::HugePages) } else { Arrays::Plain(Plain) }
    }

    /// Before the event of `a` (and `b`, for a pair) is resolved: with the lookahead, the
    /// guess of the next event's owner, its data on its way (stage one); without it, the
    /// partners' rows, read right after the collision.
    #[inline(always)]
    pub(crate) fn begin<const D: usize>(&self, at: &Reading<'_, D>, a: usize, b: Option<usize>) -> Option<usize> {
        if self.lookahead {
            Some(lookahead::first_stage(at, a, b.unwrap_or(a)))
        } else {
            if let Some(b) = b {
                lookahead::own_rows(at, a, b);
            }
            None
        }
    }

    /// Before particle `a` leaves its skin at `t` (a rebuild): with the lookahead, the centres
    /// its rebuild's scan reads (stage two of the step before has asked for the rows of its
    /// old neighbours); without it, those rows (at small N the centres are in cache, and
    /// walking the cells twice measured slower).
    #[inline(always)]
    pub(crate) fn leaving<const D: usize>(&self, at: &Reading<'_, D>, a: usize, t: f64) {
        if self.lookahead {
            lookahead::scanned(at, a, t);
        } else {
            lookahead::old_rows(at, a);
        }
    }

    /// Before a search among the neighbours `near` (gathered from a list or the cells):
    /// without the lookahead, their records. The search reads them a chunk of
    /// [`LANES`](crate::engine::search::LANES) at a time, each chunk a long chain of
    /// arithmetic, so that the loads of one chunk would wait for the chain before them; asked
    /// for first, they arrive while the first chunk is computed. (With the lookahead, stage
    /// two of the step before has asked for them.)
    #[inline(always)]
    pub(crate) fn searching<const D: usize>(&self, at: &Reading<'_, D>, near: &[u32]) {
        if !self.lookahead {
            lookahead::records(at, near);
        }
    }

    /// After the brackets of a collision's two partners, before their candidates are timed:
    /// with the lookahead, the line of each candidate's record that holds its event count,
    /// which the candidate's event records (stage two of the step before asked for the first
    /// line of every neighbour's record only; a sphere's count is on the second). Asked for
    /// here, it arrives while stage two runs.
    #[inline(always)]
    pub(crate) fn candidates<const D: usize>(
        &self,
        at: &Reading<'_, D>,
        search: &Search<D>,
        near: [&[u32; NEAR]; 2],
        gathered: [usize; 2],
        bounds: [f64; 2],
    ) {
        if self.lookahead && lookahead::two_lines::<D>() {
            search.candidates(near, gathered, bounds, |j| lookahead::event_count(at, j));
        }
    }

    /// Between the two predictions after a collision, or before the one after any other
    /// event (stage two: the next owner's neighbourhood, its partner, its queue path).
    #[inline(always)]
    pub(crate) fn middle<const D: usize>(&self, at: &Reading<'_, D>, next: Option<usize>) -> Option<Ahead> {
        next.map(|next| lookahead::second_stage(at, next))
    }

    /// After the predictions (stage three: what stage two's loads point to).
    #[inline(always)]
    pub(crate) fn end<const D: usize>(&self, at: &Reading<'_, D>, ahead: Option<&Ahead>) {
        if let Some(ahead) = ahead {
            lookahead::third_stage(at, ahead);
        }
    }
}
