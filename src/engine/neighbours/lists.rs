//! Neighbour lists: one fixed-size row per particle, and when lists are kept and how wide
//! their skin is ([`skin_for`]). The bookkeeping that keeps the rows true — centres, rebuilds,
//! exit times — is [`Neighbours`](super::Neighbours)'.

use super::Neighbourhood;
use crate::engine::geometry::{Boundary, SimBox};

/// The most neighbours a list holds (a crowded particle searches the grid).
pub const CAPACITY: usize = 8;

/// An unused entry (lists are packed at the front).
pub(crate) const NONE: u32 = u32::MAX;

/// The first entry of a crowded particle's list.
pub(crate) const CROWDED: u32 = u32::MAX - 1;

/// One particle's neighbours, `NONE` after the last; `[CROWDED, ..]` for a crowded particle.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(32))]
pub(crate) struct List([u32; CAPACITY]);

impl List {
    pub(crate) const EMPTY: List = List([NONE; CAPACITY]);
    pub(crate) const CROWDED: List = {
        let mut list = List::EMPTY;
        list.0[0] = CROWDED;
        list
    };

    /// Whether the particle has more neighbours in range than a row holds (it then searches
    /// the grid of centres instead).
    #[inline]
    pub(crate) fn crowded(&self) -> bool {
        self.0[0] == CROWDED
    }

    /// The entries, members first (`NONE` after the last; `[CROWDED, ..]` when crowded).
    #[inline]
    pub(crate) fn entries(&self) -> &[u32; CAPACITY] {
        &self.0
    }

    /// The members (none when crowded).
    #[inline]
    pub(crate) fn members(&self) -> impl Iterator<Item = usize> + '_ {
        let skip = if self.crowded() { CAPACITY } else { 0 };
        self.0[skip..].iter().take_while(|&&j| j != NONE).map(|&j| j as usize)
    }

    /// Takes `i` out, moving the last entry into its place (no-op if crowded or absent).
    pub(crate) fn drop(&mut self, i: u32) {
        if self.crowded() {
            return;
        }
        // Members first, then `NONE`s: count the members and find `i` without branches.
        let (mut len, mut at) = (0, CAPACITY);
        for (k, &j) in self.0.iter().enumerate() {
            len += (j != NONE) as usize;
            at = if j == i { k } else { at };
        }
        if at < CAPACITY {
            self.0[at] = self.0[len - 1];
            self.0[len - 1] = NONE;
        }
    }

    /// Puts `i` in; a full list becomes crowded.
    pub(crate) fn add(&mut self, i: u32) {
        if self.crowded() {
            return;
        }
        let len = self.0.iter().filter(|&&j| j != NONE).count();
        match len {
            CAPACITY => *self = List::CROWDED,
            _ => self.0[len] = i,
        }
    }

    /// A row holding `members`, or a crowded one if they do not fit.
    pub(crate) fn from_members(members: &[u32]) -> List {
        if members.len() > CAPACITY {
            return List::CROWDED;
        }
        let mut list = List::EMPTY;
        list.0[..members.len()].copy_from_slice(members);
        list
    }
}

/// Lists are kept (by [`Neighbourhood::Auto`]) from this packing fraction on,
/// `n·π(reach/2)²` with `n` the number density, at every N. Lists save the walk through the
/// cell lists around a particle (and, at large N, most of the cache misses around a
/// collision); at lower densities a particle leaves its skin so often that the rebuilds cost
/// more. The crossover was measured with alternating runs of both neighbourhoods over N and
/// η (`benches/HISTORY.md`).
pub const LISTS_FROM: f64 = 0.63;

/// The mean number of particles the list range is sized to hold, `n·πR²`: a longer range
/// means fewer rebuilds but longer rows and more crowded particles (which search the grid
/// instead); this one makes the skin about 0.8 of a contact distance at η = 0.65, the
/// fastest of the skins measured (`benches/HISTORY.md`).
pub const RANGE_HOLDS: f64 = 8.4;

/// The skin for lists, or `None` for the grid that follows the particles: lists only in 2D
/// (in 3D a list of [`CAPACITY`] holds fewer than a dense fluid's neighbours), with no short
/// periodic axis (`allow`), and for [`Neighbourhood::Auto`] from [`LISTS_FROM`] on. The skin
/// makes the range hold [`RANGE_HOLDS`] particles, within
/// `[reach/4, reach]`, and short enough that a range plus a skin stays under half of every
/// periodic box length (one image of a pair in range).
pub(crate) fn skin_for<const D: usize>(
    sim_box: &SimBox<D>,
    reach: f64,
    n: usize,
    allow: bool,
    choice: Neighbourhood,
) -> Option<f64> {
    let density = n as f64 / sim_box.volume();
    let eta = density * std::f64::consts::PI * 0.25 * reach * reach;
    let wanted = match choice {
        Neighbourhood::Auto => eta >= LISTS_FROM,
        Neighbourhood::Grid => false,
        Neighbourhood::Lists => true,
    };
    if D != 2 || !allow || !wanted {
        return None;
    }
    let range = (RANGE_HOLDS / (std::f64::consts::PI * density)).sqrt();
    let mut skin = (range - reach).clamp(0.25 * reach, reach);
    for a in 0..D {
        if sim_box.boundary[a] == Boundary::Periodic {
            skin = skin.min(0.45 * (0.5 * sim_box.lengths[a] - reach));
        }
    }
    Some(skin)
}
