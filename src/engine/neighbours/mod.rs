//! Who can touch whom: neighbour lists with a skin for dense, large systems, or a cell grid
//! that follows the particles everywhere else ([`Neighbourhood`] chooses; the collisions are
//! the same either way). With the grid, a particle's neighbours are the members of the cells
//! around its own, and crossing into the next cell is the event that keeps that true. The
//! rest of this overview is about the lists.
//!
//! Each particle `i` has a *centre* `cᵢ` — where it was when its list was last built — and a
//! list of every particle `j` whose centre lies within the range `R = reach + s` of `cᵢ`
//! (minimum image; `reach` the largest contact distance, `s` the skin). While both stay
//! within `s/2` of their centres, `|rᵢ − rⱼ| ≥ |cᵢ − cⱼ| − s`, so two particles not in each
//! other's lists cannot touch. A particle leaving its skin (`|rᵢ − cᵢ|` reaching
//! `h = (s/2)(1 − 2⁻²⁰)`, a margin far above the rounding of positions and times) is an
//! event: its centre moves to where it is and its list is rebuilt
//! ([`Neighbours::rebuild`]).
//!
//! The relation "within range" is symmetric, and so are the lists: when `i` rebuilds, it
//! leaves the lists of its old neighbours and joins those of its new ones. The simulation
//! relies on this — a particle that changes course predicts only against its own list, so
//! every particle that can reach it must be on it. The separation of two centres is
//! computed as the exact negative from either side (`cⱼ − cᵢ = −(cᵢ − cⱼ)` in floating
//! point, and the image count is `round(d/L)`, odd in `d`), so both sides agree.
//!
//! A list holds at most [`CAPACITY`](lists::CAPACITY) neighbours a row in 32-byte blocks (contiguous
//! rows, read by the batch kernel eight lanes at a time): one row for a disk, two for a
//! sphere ([`rows_for`](lists::rows_for)). A particle with more is *crowded*: it keeps
//! no list and searches the cell grid around its centre instead, which holds everyone in
//! range (cells are `R` wide); it gets a list again at its next rebuild if the neighbours
//! then fit. With short periodic axes (several images of one pair in range), and for
//! [`Neighbourhood::Auto`] below [`LISTS_FROM`] ([`LISTS_FROM_3D`] for spheres), no lists
//! are kept and the grid follows the particles.
//!
//! With lists, the cell grid ([`Cells`]) holds each particle by its centre, so a particle
//! changes cell only when it rebuilds, with no crossing events.
//!
//! While the radii grow (a compression), `reach` is the largest contact distance at the end
//! of the present stretch ([`GROWTH_STRETCH`]); the simulation builds everything again
//! there.

pub(crate) mod cells;
pub(crate) mod lists;
mod undo;

use crate::engine::arrays::Store;
use crate::engine::geometry::{Boundary, Particle, SimBox};
use cells::{Cells, Coord};
pub use lists::{LISTS_FROM, LISTS_FROM_3D, RANGE_HOLDS, RANGE_HOLDS_3D};
use lists::{List, NONE, Rows, skin_for};
use nalgebra::SVector;
use serde::{Deserialize, Serialize};

/// During a compression the neighbourhood is built for radii this many times the present
/// ones and rebuilt when they get there: cells and lists stay sized for the radii of the
/// moment (never for the final ones from the start), and a periodic axis counts as short
/// only once the present radii make it so. A rebuild costs about one prediction per
/// particle; 5 % growth between them makes them rare even near jamming, where the radii
/// barely grow, and keeps the cells at most 5 % wider than they need be.
pub const GROWTH_STRETCH: f64 = 1.05;

/// How [`Simulation`](super::Simulation) finds the particles that can touch one another.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Neighbourhood {
    /// Lists where they pay (from [`LISTS_FROM`]), the grid elsewhere.
    #[default]
    Auto,
    /// A grid of cells one contact distance wide following the particles (an event at each
    /// cell boundary).
    Grid,
    /// Neighbour lists with a skin, where they can be kept (no short periodic axis);
    /// elsewhere the grid.
    Lists,
}

impl Neighbourhood {
    /// The names [`FromStr`](std::str::FromStr) accepts (as in the saved state).
    pub const NAMES: [&'static str; 3] = ["auto", "grid", "lists"];

    /// The name (as in the saved state).
    pub fn name(self) -> &'static str {
        match self {
            Neighbourhood::Auto => "auto",
            Neighbourhood::Grid => "grid",
            Neighbourhood::Lists => "lists",
        }
    }
}

impl std::fmt::Display for Neighbourhood {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// A neighbourhood name that is none of [`Neighbourhood::NAMES`].
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct UnknownNeighbourhood(pub String);

impl std::fmt::Display for UnknownNeighbourhood {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "unknown neighbourhood {:?}: expected one of {}", self.0, Neighbourhood::NAMES.join(", "))
    }
}

impl std::error::Error for UnknownNeighbourhood {}

impl std::str::FromStr for Neighbourhood {
    type Err = UnknownNeighbourhood;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        [Neighbourhood::Auto, Neighbourhood::Grid, Neighbourhood::Lists]
            .into_iter()
            .find(|n| n.name() == s)
            .ok_or_else(|| UnknownNeighbourhood(s.to_string()))
    }
}

/// The squared distance from centre `a` to the nearest image of centre `b` in `sim_box`.
/// The image count per periodic axis is `round(x/L)`, as `x·(1/L)` rounded half to even: one
/// instruction, where [`SimBox::minimum_image_shift`]'s comparisons and branches would
/// dominate a rebuild's scan of some two dozen centres. Which image wins where `x/L` is
/// within an ulp of a half does not matter: the range is under half of every periodic length
/// ([`skin_for`]). The same number from either side (the count is an odd function of `x`,
/// and `x` negates exactly), which keeps the lists symmetric.
#[inline(always)]
fn apart2<const D: usize>(sim_box: &SimBox<D>, a: &SVector<f64, D>, b: &SVector<f64, D>) -> f64 {
    let mut r2 = 0.0;
    for k in 0..D {
        let mut x = b[k] - a[k];
        if sim_box.boundary[k] == Boundary::Periodic {
            let l = sim_box.lengths[k];
            x -= (x * (1.0 / l)).round_ties_even() * l;
        }
        r2 += x * x;
    }
    r2
}

/// The centres, the lists and the grid of centres — or the grid that follows the particles.
#[derive(Clone, Debug)]
pub struct Neighbours<const D: usize> {
    cells: Cells<D>,
    /// Whether lists are kept (else the grid follows the particles).
    listed: bool,
    /// Lists: one per particle (else empty).
    centres: Vec<SVector<f64, D>>,
    /// Lists: `ROWS` rows per particle, particle `i`'s at `i·ROWS` (else empty).
    lists: Vec<List>,
    /// `R²`, the list range squared.
    range2: f64,
    /// `h²`, the skin's exit radius squared.
    exit2: f64,
    /// `(s/2)²`: how far from its centre a particle may be.
    bound2: f64,
    sim_box: SimBox<D>,
    /// A rebuild's new neighbours (kept, so that no rebuild allocates once warmed up).
    scratch: Vec<u32>,
    /// The changes made since recording began, when asked for ([`Neighbours::record`]).
    log: Option<Vec<undo::Undo<D>>>,
}

/// How a saved [`Neighbours`] is restored: the grid's unwrapped cell coordinates, or the
/// list centres and which particles are crowded.
#[derive(Clone, Debug)]
pub enum Saved<const D: usize> {
    /// Following: one unwrapped cell coordinate per particle.
    Cells(Vec<[i64; D]>),
    /// Lists: one centre per particle, and the crowded particles in increasing order. A
    /// particle stays crowded until its next rebuild even when neighbours leave its range
    /// (a crowded particle keeps no list to leave), so whether it is crowded is state: it
    /// decides which stale predictions it makes, and a restored run must make the same.
    Centres(Vec<SVector<f64, D>>, Vec<u32>),
}

impl<const D: usize> Neighbours<D> {
    /// Rows of a particle's list.
    const ROWS: usize = lists::rows_for(D);

    /// Particle `i`'s rows.
    #[inline(always)]
    fn rows(&self, i: usize) -> &[List] {
        &self.lists[i * Self::ROWS..(i + 1) * Self::ROWS]
    }

    /// Particle `i`'s rows, to change.
    #[inline(always)]
    fn rows_mut(&mut self, i: usize) -> &mut [List] {
        &mut self.lists[i * Self::ROWS..(i + 1) * Self::ROWS]
    }

    /// Whether particle `i` (with lists) is crowded.
    #[inline]
    pub(crate) fn is_crowded(&self, i: usize) -> bool {
        lists::crowded(self.rows(i))
    }

    /// Lists (centred where the particles are at `time`) or a grid following the particles,
    /// as `skin_for` decides; `allow_lists` is false with short periodic axes. The large
    /// arrays are built in `store`.
    pub(crate) fn new(
        sim_box: &SimBox<D>,
        reach: f64,
        particles: &[Particle<D>],
        time: f64,
        allow_lists: bool,
        choice: Neighbourhood,
        store: &impl Store,
    ) -> Self {
        match skin_for(sim_box, reach, particles.len(), allow_lists, choice) {
            Some(skin) => {
                let centres = store.collect(particles.iter().map(|p| p.position_at(time)));
                Self::listed_from(sim_box, reach, skin, centres, &[], store)
            }
            None => Self::following(sim_box, reach, particles, store),
        }
    }

    /// A grid of cells `reach` wide following the particles, no lists.
    pub(crate) fn following(sim_box: &SimBox<D>, reach: f64, particles: &[Particle<D>], store: &impl Store) -> Self {
        Self::bare(sim_box, Cells::follow(sim_box, reach, particles.iter().map(|p| p.position_at(p.time)), store))
    }

    /// The grid alone, no lists.
    fn bare(sim_box: &SimBox<D>, cells: Cells<D>) -> Self {
        Neighbours {
            cells,
            listed: false,
            centres: Vec::new(),
            lists: Vec::new(),
            range2: 0.0,
            exit2: 0.0,
            bound2: 0.0,
            sim_box: *sim_box,
            scratch: Vec::new(),
            log: None,
        }
    }

    /// Rebuilds from a saved state, its large arrays in `store`; `Err` says what does not fit
    /// (the wrong kind for this box and density, or the wrong count).
    pub(crate) fn restore(
        sim_box: &SimBox<D>,
        reach: f64,
        n: usize,
        allow_lists: bool,
        choice: Neighbourhood,
        saved: Saved<D>,
        store: &impl Store,
    ) -> Result<Self, String> {
        // Under `Auto`, the kind saved is the kind kept: a run resumes with the neighbourhood
        // it had (whether a particle is crowded decides which stale predictions it makes),
        // even where a later version of `Auto`'s rule would choose the other.
        let choice = match (choice, &saved) {
            (Neighbourhood::Auto, Saved::Centres(..)) => Neighbourhood::Lists,
            (Neighbourhood::Auto, Saved::Cells(..)) => Neighbourhood::Grid,
            (choice, _) => choice,
        };
        let skin = skin_for(sim_box, reach, n, allow_lists, choice);
        let empty = |cells| Self::bare(sim_box, cells);
        match (skin, saved) {
            (None, Saved::Cells(coords)) if coords.len() == n => {
                Ok(empty(Cells::from_coords(sim_box, reach, coords, store)))
            }
            (Some(skin), Saved::Centres(centres, crowded)) if centres.len() == n => {
                if let Some(&k) = crowded.iter().find(|&&k| k as usize >= n) {
                    return Err(format!("crowded particle {k} of {n}"));
                }
                if crowded.windows(2).any(|w| w[0] >= w[1]) {
                    return Err("the crowded particles are not listed in increasing order".into());
                }
                Ok(Self::listed_from(sim_box, reach, skin, store.moved(centres), &crowded, store))
            }
            (skin, _) => Err(format!(
                "{n} {} expected",
                if skin.is_some() { "neighbour-list centres" } else { "cell coordinates" }
            )),
        }
    }

    /// Lists with a skin `skin` around `centres` (already in `store`), the `crowded`
    /// particles (in increasing order) searching the grid.
    fn listed_from(
        sim_box: &SimBox<D>,
        reach: f64,
        skin: f64,
        centres: Vec<SVector<f64, D>>,
        crowded: &[u32],
        store: &impl Store,
    ) -> Self {
        let n = centres.len();
        let range = reach + skin;
        let half = 0.5 * skin * (1.0 - f64::EPSILON * (1u64 << 32) as f64);
        let mut neighbours = Self::bare(sim_box, Cells::new(sim_box, range, centres.iter().copied()));
        neighbours.centres = centres;
        neighbours.listed = true;
        neighbours.range2 = range * range;
        neighbours.exit2 = half * half;
        neighbours.bound2 = 0.25 * skin * skin;
        let rows = Self::ROWS;
        let mut list = [List::EMPTY; lists::MAX_ROWS];
        neighbours.lists = store.collect((0..n * rows).map(|k| {
            if k % rows == 0 {
                neighbours.scan(k / rows);
                lists::fill(&mut list[..rows], &neighbours.scratch);
            }
            list[k % rows]
        }));
        for &k in crowded {
            lists::set_crowded(neighbours.rows_mut(k as usize));
        }
        neighbours
    }

    /// What [`restore`](Self::restore) takes back.
    pub fn save(&self) -> Saved<D> {
        match self.listed() {
            true => Saved::Centres(
                self.centres.clone(),
                (0..self.centres.len() as u32).filter(|&k| self.is_crowded(k as usize)).collect(),
            ),
            false => Saved::Cells(self.cells.coords().to_vec()),
        }
    }

    /// Heap bytes held (capacities).
    pub fn memory_bytes(&self) -> usize {
        self.cells.memory_bytes()
            + self.centres.capacity() * size_of::<SVector<f64, D>>()
            + self.lists.capacity() * size_of::<List>()
            + self.scratch.capacity() * size_of::<u32>()
    }

    /// Cells per axis of the grid of centres.
    pub fn cell_counts(&self) -> [usize; D] {
        self.cells.counts()
    }

    /// Whether lists are kept (else every search goes through the grid).
    pub fn listed(&self) -> bool {
        self.listed
    }

    /// Particle `i`'s cell.
    #[inline]
    fn cell(&self, i: usize) -> Coord<D> {
        if self.listed() { self.cells.locate(&self.centres[i]) } else { self.cells.wrapped(i) }
    }

    /// Whether the centres of `i` and `j` are within range (minimum image): the lists'
    /// definition, checked by [`check`](Self::check).
    #[inline]
    fn within(&self, i: usize, j: usize) -> bool {
        apart2(&self.sim_box, &self.centres[i], &self.centres[j]) < self.range2
    }

    /// Lists in `scratch` everyone within range of `i`'s centre. Whether a centre is in range
    /// is a coin toss for the branch predictor (about a third of those walked past are), so
    /// each is written and counted without a branch, into a buffer with room for one more.
    fn scan(&mut self, i: usize) {
        let mut found = std::mem::take(&mut self.scratch);
        // The box, the range and the centres in locals: through `self`, the compiler read
        // them again for every member, after each write to `found`.
        let (sim_box, range2, centres) = (self.sim_box, self.range2, &self.centres[..]);
        let c = centres[i];
        // Only the cells that can hold a centre in range: the members of the others would
        // all be walked past. The same members found, in the same order (the walk takes
        // the cells' lists round by round, and a dropped cell adds none).
        let around = self.cells.around_within(&self.cell(i), &c, range2);
        let mut len = 0;
        self.cells.for_each_member_side_by_side(
            around.as_slice(),
            #[inline(always)]
            |j| {
                if len == found.len() {
                    found.resize(2 * len + 8, 0);
                }
                found[len] = j;
                len += ((j as usize != i) & (apart2(&sim_box, &c, &centres[j as usize]) < range2)) as usize;
            },
        );
        found.truncate(len);
        self.scratch = found;
    }

    /// Particle `p` (number `i`) has reached the time `t` of its
    /// [`exit_time`](Self::exit_time). With lists, its centre moves to where it is, and it
    /// leaves the lists of the particles no longer in range and joins those newly in range.
    /// Following, it moves to the next cell (the crossing found again: the same pure function
    /// of the same state).
    pub fn rebuild(&mut self, i: usize, p: &Particle<D>, t: f64) {
        let Some((old, from)) = self.recentre(i, p, t) else { return };
        let old = Rows(&old[..Self::ROWS]);
        self.scan(i);
        let found = std::mem::take(&mut self.scratch);
        if old.crowded() {
            // A crowded particle does not know its old neighbours: everyone in the cells
            // around its old centre is asked, and `drop` ignores those without it.
            let rows = Self::ROWS;
            for j in self.cells.neighbours(from) {
                if j != i {
                    let row = &mut self.lists[j * rows..(j + 1) * rows];
                    undo::note_holding(&mut self.log, j, row, i);
                    lists::drop(row, i as u32);
                }
            }
            for &j in &found {
                self.note_rows(j as usize);
                lists::add(self.rows_mut(j as usize), i as u32);
            }
        } else {
            // Membership in a row-sized block of entries is one vector compare; a particle
            // crowded from now on has more new neighbours than that, compared one by one.
            let new = lists::block(found.iter().copied());
            for j in old.members() {
                let stays =
                    if found.len() <= new.len() { new.contains(&(j as u32)) } else { found.contains(&(j as u32)) };
                if !stays {
                    self.note_rows(j);
                    lists::drop(self.rows_mut(j), i as u32);
                }
            }
            let before = lists::block(old.entries());
            for &j in &found {
                if !before.contains(&j) {
                    self.note_rows(j as usize);
                    lists::add(self.rows_mut(j as usize), i as u32);
                }
            }
        }
        self.note_rows(i);
        lists::fill(self.rows_mut(i), &found);
        self.scratch = found;
    }

    /// [`rebuild`](Self::rebuild) in a replica that holds only some of the particles
    /// exactly, the `mine` ones' rows and every centre within reach of them: with lists, the
    /// particles within range of the new centre are `given` (what the rebuild of the same
    /// particle at the same time found in a replica that holds every centre it reads,
    /// [`found`](Self::found)) instead of scanned for, and only the `mine` rows take the
    /// change — every other row of this replica is left as it was, out of date. So whether
    /// `i` joins a row of `mine` is asked of that row, not of `i`'s old list, whose other
    /// entries may be out of date; which rows of `mine` it leaves is asked of the old list,
    /// which lists at least every particle of `mine` whose row holds `i`: each row of `mine`
    /// gains a particle at its own rebuild (which puts it into that particle's list too), at
    /// the other's (here, the list filled with it), or when it becomes one of `mine` — `i`
    /// does when it `joins` (its rebuild takes it into this replica's slab), and then every
    /// member's row takes it. An entry of `mine` out of date in another's list only makes
    /// `i` leave a row that does not hold it, which changes nothing. Following the
    /// particles, `given` is not read.
    pub(crate) fn rebuild_told(
        &mut self,
        i: usize,
        p: &Particle<D>,
        t: f64,
        given: impl IntoIterator<Item = u32>,
        mine: impl Fn(usize) -> bool,
        joins: bool,
    ) {
        let Some((old, from)) = self.recentre(i, p, t) else { return };
        let old = Rows(&old[..Self::ROWS]);
        let mut found = std::mem::take(&mut self.scratch);
        found.clear();
        found.extend(given);
        if old.crowded() {
            let rows = Self::ROWS;
            for j in self.cells.neighbours(from) {
                if j != i && mine(j) {
                    let row = &mut self.lists[j * rows..(j + 1) * rows];
                    undo::note_holding(&mut self.log, j, row, i);
                    lists::drop(row, i as u32);
                }
            }
        } else {
            for j in old.members() {
                if mine(j) && !found.contains(&(j as u32)) {
                    self.note_rows(j);
                    lists::drop(self.rows_mut(j), i as u32);
                }
            }
        }
        for &j in &found {
            let j = j as usize;
            if (joins || mine(j)) && !Rows(self.rows(j)).entries().any(|k| k == i as u32) {
                self.note_rows(j);
                lists::add(self.rows_mut(j), i as u32);
            }
        }
        self.note_rows(i);
        lists::fill(self.rows_mut(i), &found);
        self.scratch = found;
    }

    /// The first half of a rebuild: following the particles, the move to the next cell
    /// (then `None`, nothing more to do); with lists, the centre moved to where the particle
    /// is at `t` (and its cell with it), returning its rows and cell before.
    #[inline(always)]
    fn recentre(&mut self, i: usize, p: &Particle<D>, t: f64) -> Option<([List; lists::MAX_ROWS], Coord<D>)> {
        if !self.listed {
            let (_, axis, up) =
                self.cells.next_crossing(&self.cells.coord(i), &p.position, &p.velocity).expect("a crossing");
            self.note(undo::Undo::Shift { k: i as u32, axis: axis as u8, up });
            self.cells.shift(i, axis, up);
            return None;
        }
        // The new neighbours are found first (by the caller), then `i` leaves the lists of
        // the old neighbours no longer in range and joins those of the new ones not in
        // range before (neither changes what the scan reads): the scan's walk of the cells
        // gives the old neighbours' rows, asked for before the event (`Timing::leaving`),
        // time to arrive. A particle leaves its skin having moved half a skin, and most of
        // its neighbours stay: their rows are left alone (leaving and joining again would
        // only move `i` to the row's end, and which entry of a row holds whom changes no
        // search).
        let mut old = [List::EMPTY; lists::MAX_ROWS];
        old[..Self::ROWS].copy_from_slice(self.rows(i));
        let from = self.cell(i);
        self.note(undo::Undo::Centre { k: i as u32, centre: self.centres[i] });
        let centre = p.position_at(t);
        let to = self.cells.locate(&centre);
        if from != to {
            self.cells.remove(i, &from);
            self.cells.insert(i, &to);
        }
        self.centres[i] = centre;
        Some((old, from))
    }

    /// With lists: the particles within range of the centre of the last
    /// [`rebuild`](Self::rebuild)'s particle (its list before any cap), until the next.
    pub(crate) fn found(&self) -> &[u32] {
        &self.scratch
    }

    /// When particle `p` (number `i`) next has to [`rebuild`](Self::rebuild), as an absolute
    /// time no earlier than `now`: following, when it leaves its cell; with lists, when it
    /// reaches the skin's exit radius (it is inside from its own time `tₚ` on, until it
    /// rebuilds): `max(tₚ + τ, now)`, `τ` the larger root of `|d + vτ|² = h²`,
    /// `d = r(tₚ) − cᵢ`, taken in the form without cancellation. Measured from the
    /// particle's own time, not `now`, the time depends on `now` only through that floor:
    /// a re-prediction whose result is no earlier than some clock gives the same bits from
    /// any earlier clock, which the ordered two-thread schedule relies on (docs/engine.md,
    /// "Two threads in the order of time").
    /// Velocities are scaled first by the power of two that brings their largest component
    /// into `[1, 2)` (or as near as the exponent range allows), so that neither `|v|²` nor
    /// `d·v` overflows or underflows; a power of two, so that scaling and unscaling are exact
    /// multiplications, not divisions (this chain of a square root and a division sits at
    /// the head of every prediction, so every division saved shortens it). The time only has to be within
    /// the exit radius's margin of 2³² ulps of the skin, which some ulps of rounding are far
    /// from. `None` at rest, or never.
    #[inline]
    pub fn exit_time(&self, i: usize, p: &Particle<D>, now: f64) -> Option<f64> {
        if !self.listed() {
            let m = self.cells.coord(i);
            return self.cells.next_crossing(&m, &p.position, &p.velocity).map(|(dt, ..)| (p.time + dt).max(now));
        }
        let c = &self.centres[i];
        let scale = p.velocity.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        if scale == 0.0 {
            return None;
        }
        // 2^−E for scale = m·2^E (1 ≤ m < 2); a subnormal scale takes 2^1022 (its components
        // then scale to below 1), the largest binade 2^−1022 (they scale to below 4).
        let biased = ((scale.to_bits() >> 52) as i64).clamp(1, 2045);
        let inverse = f64::from_bits(((2046 - biased) as u64) << 52);
        let (mut a, mut b, mut dd) = (0.0, 0.0, 0.0);
        for k in 0..D {
            let d = p.position[k] - c[k];
            let u = p.velocity[k] * inverse;
            a += u * u;
            b += d * u;
            dd += d * d;
        }
        // Inside at `tₚ` but for rounding at the instant of leaving (the constant term ≤ 0),
        // or, when `tₚ` is before the last rebuild, perhaps outside and bound to come in:
        // then the constant term is positive and the line meets the sphere, but for
        // rounding when it grazes (the discriminant held at 0).
        let c0 = dd - self.exit2;
        let root = (b * b - a * c0).max(0.0).sqrt();
        // The larger root without cancellation, in whichever form the sign of `b` allows.
        // Moving toward or away from the centre is a coin toss for the branch predictor, and
        // a miss here would stall behind the square root: both forms are selected, then
        // divided once.
        let toward = b <= 0.0;
        let numerator = std::hint::select_unpredictable(toward, root - b, -c0);
        let denominator = std::hint::select_unpredictable(toward, a, b + root);
        let tau = numerator / denominator * inverse;
        let t = (p.time + tau.max(0.0)).max(now);
        t.is_finite().then_some(t)
    }

    /// Whether particle `p` (number `i`) is where its bookkeeping says at `t` (a saved
    /// state must be): within half a skin of its centre with lists; following, in its cell
    /// (up to 10⁻⁹ of a cell width, the rounding of a crossing's position). Anything else
    /// would hide neighbours from its searches.
    pub fn inside(&self, i: usize, p: &Particle<D>, t: f64) -> bool {
        if self.listed() {
            return (p.position_at(t) - self.centres[i]).norm_squared() <= self.bound2;
        }
        let (r, m, counts) = (p.position_at(t), self.cells.coord(i), self.cells.counts());
        (0..D).all(|a| {
            let w = self.cells.width(a);
            let slack = 1e-9 * w;
            let within = r[a] >= m[a] as f64 * w - slack && r[a] <= (m[a] + 1) as f64 * w + slack;
            let on_grid = self.sim_box.boundary[a] == Boundary::Periodic || (0..counts[a] as i64).contains(&m[a]);
            within && on_grid
        })
    }

    /// Writes particle `i`'s neighbours but `skip` into `out` and returns how many: its
    /// list — or, if it is crowded, the members of the cells around its centre (`None` if
    /// they do not fit).
    ///
    /// The list is copied whole (its rows are packed: members, then `NONE`), its members
    /// counted and `skip` found by vector compares, and `skip`, if there, replaced by the last
    /// member (which entry holds whom changes no search). Written entry by entry, each at
    /// the count so far, the copy was a chain of sixteen dependent steps.
    #[inline]
    pub fn gather(&self, i: usize, skip: usize, out: &mut [u32]) -> Option<usize> {
        if !self.listed || self.is_crowded(i) {
            return self.gather_cells(i, skip, out);
        }
        let (mut len, mut at) = (0, usize::MAX);
        for r in 0..Self::ROWS {
            let row = self.lists[i * Self::ROWS + r].entries();
            out[r * lists::CAPACITY..(r + 1) * lists::CAPACITY].copy_from_slice(row);
            for (k, &j) in row.iter().enumerate() {
                len += (j != NONE) as usize;
                at = if j as usize == skip { r * lists::CAPACITY + k } else { at };
            }
        }
        if at != usize::MAX {
            len -= 1;
            out[at] = out[len];
        }
        Some(len)
    }

    /// [`gather`](Self::gather) from the cells around `i`: out of line, so that the list's
    /// copy stays a few instructions where it is inlined.
    #[inline(never)]
    fn gather_cells(&self, i: usize, skip: usize, out: &mut [u32]) -> Option<usize> {
        if self.listed { self.gather_crowded(i, skip, out) } else { self.cells.gather(&self.cell(i), i, skip, out) }
    }

    /// [`gather`](Self::gather) for a crowded particle: the members of the cells around its
    /// centre whose centres are within range — its list, had the rows room for it. Only
    /// they can touch it before either rebuilds; the others' predictions would be overtaken
    /// by a rebuild, and reading them would make a crowded particle's reads reach two cell
    /// widths where a list's reach one range (the divided box's zone is the lists' reach).
    #[inline]
    fn gather_crowded(&self, i: usize, skip: usize, out: &mut [u32]) -> Option<usize> {
        let len = self.cells.gather(&self.cell(i), i, skip, out)?;
        let mut kept = 0;
        for k in 0..len {
            let j = out[k];
            out[kept] = j;
            kept += self.within(i, j as usize) as usize;
        }
        Some(kept)
    }

    /// The particles in the cells around `i` (with lists, `i`'s list instead unless it is
    /// crowded), `i` included: every particle that can touch `i` before it next rebuilds,
    /// and, crowded or following, some that cannot. For checks and audits, which read
    /// everyone there.
    pub fn candidates(&self, i: usize) -> impl Iterator<Item = usize> + '_ {
        let list = self.row(i).filter(|list| !list.crowded());
        let listed = list.into_iter().flat_map(|list| list.members());
        let grid = list.is_none().then(|| self.cells.neighbours(self.cell(i))).into_iter().flatten();
        listed.chain(grid)
    }

    /// Whether the searches read candidate `j` of `i` ([`candidates`](Self::candidates)):
    /// all of them, but a crowded particle's only those whose centres are within range —
    /// the same set the batch search sees through [`gather`](Self::gather).
    #[inline(never)]
    pub(crate) fn searches(&self, i: usize, j: usize) -> bool {
        !self.listed || self.within(i, j)
    }

    /// The flat index of particle `i`'s cell (its centre's, with lists).
    pub(crate) fn cell_index(&self, i: usize) -> usize {
        self.cells.flat(&self.cell(i))
    }

    /// The flat indices of the cells around `i`'s: where every particle whose searches or
    /// rebuilds can read `i` has its own.
    pub(crate) fn cells_around(&self, i: usize) -> cells::Around {
        self.cells.around(&self.cell(i))
    }

    /// How many cells the grid has.
    pub(crate) fn cell_count(&self) -> usize {
        self.cells.counts().iter().product()
    }

    /// How far along `axis` from where a particle last updated its neighbourhood (its list's
    /// centre, or where it entered its cell) the particles its predictions and rebuilds read
    /// last updated theirs, at most. With lists, `R + s/2`: a prediction reads the members
    /// (centres within the range `R`, a crowded particle's too), and a rebuild those within
    /// `R` of its new centre, at most half a skin `s` from the old; a rebuild's walk of the
    /// cells reads centres further out, but only to find them out of range, which a far
    /// centre out of date still is. Following the particles, everyone in the cells around
    /// its own: two cell widths. A hundredth of a skin (a quarter of a width) more against
    /// rounding.
    pub(crate) fn read_reach(&self, axis: usize) -> f64 {
        if self.listed {
            let half_skin = self.bound2.sqrt();
            self.range2.sqrt() + 1.02 * half_skin
        } else {
            2.25 * self.cells.width(axis)
        }
    }

    /// The cell grid (of centres with lists; following the particles without).
    #[inline]
    pub(crate) fn cells(&self) -> &Cells<D> {
        &self.cells
    }

    /// Particle `i`'s list rows, with lists.
    #[inline]
    pub(crate) fn row(&self, i: usize) -> Option<Rows<'_>> {
        self.listed.then(|| Rows(self.rows(i)))
    }

    /// The list centres (empty without lists).
    #[inline]
    pub(crate) fn centres(&self) -> &[SVector<f64, D>] {
        &self.centres
    }

    /// Checks the lists against their definition: `j` is on `i`'s list exactly when their
    /// centres are within range (for the particles that are not crowded); for tests.
    #[cfg(test)]
    pub fn check(&self) {
        self.check_among(|_| true);
    }

    /// [`check`](Self::check) for the rows of the `mine` particles only (the rows a
    /// replica of the divided box keeps exact); for tests.
    #[cfg(test)]
    pub(crate) fn check_among(&self, mine: impl Fn(usize) -> bool) {
        for i in 0..self.centres.len() {
            if self.is_crowded(i) || !mine(i) {
                continue;
            }
            let mut listed: Vec<u32> = Rows(self.rows(i)).members().map(|j| j as u32).collect();
            listed.sort_unstable();
            let mut expected: Vec<u32> =
                (0..self.centres.len()).filter(|&j| j != i && self.within(i, j)).map(|j| j as u32).collect();
            expected.sort_unstable();
            assert_eq!(listed, expected, "particle {i}");
        }
    }

    /// How many particles are crowded (for tests and the benchmark's notes).
    pub fn crowded(&self) -> usize {
        (0..self.centres.len()).filter(|&i| self.is_crowded(i)).count()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::rngs::Xoshiro256PlusPlus;
    use rand::{RngExt, SeedableRng};

    /// The exit time puts the particle on the exit radius — early by no more than rounding,
    /// and never outside half the skin — for speeds over the whole exponent range (tiny,
    /// subnormal, huge), for directions toward and away from the centre, and from an own
    /// time before the clock at which the particle was still outside, coming in. The exit
    /// radius sits 2³² ulps inside half the skin, and one rounding's worth either way is
    /// about 10⁻¹⁵ of it. (Any scale cancels out exactly; what can go wrong is a scale that
    /// leaves the exponent range — 0 or ∞ past the largest binade, checked by breaking the
    /// clamp — or a time left unscaled.)
    #[test]
    fn exit_times_land_on_the_exit_radius_at_every_speed() {
        let side = 12;
        let (spacing, radius) = (1.0, 0.4);
        let l = side as f64 * spacing;
        let particles: Vec<Particle<2>> = (0..side * side)
            .map(|k| Particle {
                position: SVector::from([(k % side) as f64 + 0.5, (k / side) as f64 + 0.5]),
                velocity: SVector::zeros(),
                time: 0.0,
                radius,
                mass: 1.0,
                species: 0,
                events: 0,
            })
            .collect();
        let sim_box = SimBox { lengths: SVector::from([l, l]), boundary: [Boundary::Periodic; 2] };
        let neighbours = Neighbours::new(
            &sim_box,
            2.0 * radius,
            &particles,
            0.0,
            true,
            Neighbourhood::Lists,
            &crate::engine::arrays::Plain,
        );
        assert!(neighbours.listed());
        let (exit, bound) = (neighbours.exit2.sqrt(), neighbours.bound2.sqrt());
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(5);
        let (mut checked, mut earlier) = (0, 0);
        for exponent in (-1074..=1023).step_by(7).chain([-1074, -1023, -1022, 1022, 1023]) {
            for _ in 0..20 {
                let i = rng.random_range(0..particles.len());
                let angle = rng.random_range(0.0..std::f64::consts::TAU);
                let speed = 2f64.powi(exponent) * rng.random_range(1.0..2.0);
                // Both components near the scale, or (one time in five) one far below it.
                let (x, y) = (angle.cos(), angle.sin() * if rng.random_bool(0.2) { 1e-200 } else { 1.0 });
                let velocity = SVector::from([x * speed, y * speed]);
                if !velocity.iter().all(|v| v.is_finite()) || velocity == SVector::<f64, 2>::zeros() {
                    continue;
                }
                let offset = rng.random_range(0.0..0.9) * exit;
                let at = rng.random_range(0.0..std::f64::consts::TAU);
                // One time in three the particle's own time is well before the clock (0),
                // where it was outside the exit radius (as when it rebuilt since it last
                // changed course): 1 to 3 exit radii back along its path.
                let back = rng.random_range(1.0..3.0) * exit / speed;
                let back = if rng.random_bool(1.0 / 3.0) && back.is_finite() { back } else { 0.0 };
                let p = Particle {
                    position: neighbours.centres[i] + SVector::from([at.cos(), at.sin()]) * offset - velocity * back,
                    velocity,
                    time: -back,
                    ..particles[i].clone()
                };
                let Some(t) = neighbours.exit_time(i, &p, 0.0) else {
                    // Only a time past the largest double is no exit time.
                    assert!((exit / speed) > 1e300, "no exit time at speed {speed:e}");
                    continue;
                };
                let d = (p.position_at(t) - neighbours.centres[i]).norm();
                assert!(t >= 0.0, "before the clock at speed {speed:e}: {t}");
                assert!(d <= bound, "outside the skin at speed {speed:e}: {d} > {bound}");
                assert!(d >= exit * (1.0 - 1e-12), "early at speed {speed:e} ({back:e} back): {d} < {exit}");
                checked += 1;
                earlier += usize::from(back > 0.0);
            }
        }
        assert!(checked > 2500 && earlier > 500, "{checked}, {earlier} from an earlier own time");
    }

    /// Lists stay what they are defined to be through thousands of rebuilds of spheres that
    /// jump anywhere (a rebuild leaves and joins only the rows that change, and must still
    /// leave every row it is no longer in range of and join every new one), in a box dense
    /// enough that some particles have more neighbours than their rows hold (crowded) and
    /// come back from it.
    #[test]
    fn rebuilds_keep_the_lists_true_with_crowds() {
        let n = 400;
        let l = 9.0;
        let sim_box = SimBox { lengths: SVector::from([l; 3]), boundary: [Boundary::Periodic; 3] };
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(11);
        let anywhere = |rng: &mut Xoshiro256PlusPlus| SVector::from(std::array::from_fn(|_| rng.random_range(0.0..l)));
        let particles: Vec<Particle<3>> = (0..n)
            .map(|_| Particle {
                position: anywhere(&mut rng),
                velocity: SVector::zeros(),
                time: 0.0,
                radius: 0.5,
                mass: 1.0,
                species: 0,
                events: 0,
            })
            .collect();
        let mut neighbours =
            Neighbours::new(&sim_box, 1.0, &particles, 0.0, true, Neighbourhood::Lists, &crate::engine::arrays::Plain);
        assert!(neighbours.listed());
        neighbours.check();
        let (mut most_crowded, mut least_crowded) = (0, n);
        for round in 0..3000 {
            let i = rng.random_range(0..n);
            // Mostly a short step (most neighbours stay), sometimes a jump anywhere.
            let position = if round % 5 == 0 {
                anywhere(&mut rng)
            } else {
                neighbours.centres[i] + SVector::from(std::array::from_fn(|_| rng.random_range(-0.4..0.4)))
            };
            let p = Particle { position, ..particles[i].clone() };
            neighbours.rebuild(i, &p, 0.0);
            if round % 50 == 0 {
                neighbours.check();
                most_crowded = most_crowded.max(neighbours.crowded());
                least_crowded = least_crowded.min(neighbours.crowded());
            }
        }
        neighbours.check();
        assert!(most_crowded > 0, "no particle was ever crowded");
        assert!(least_crowded < most_crowded, "crowds never changed: {least_crowded}");
    }

    /// `Auto` keeps lists for dense equal disks and spheres and for a dense 1 : 1.4 mixture,
    /// and not for a 1 : 10 mixture, whose range would hold dozens of small particles per
    /// large one (every list crowded); `Lists` keeps them there all the same.
    #[test]
    fn auto_keeps_no_lists_where_they_would_all_be_crowded() {
        use std::f64::consts::PI;
        let square = |area: f64| SimBox { lengths: SVector::from([area.sqrt(); 2]), boundary: [Boundary::Periodic; 2] };
        // 1000 equal disks of diameter 1 at η = 0.8; 500 + 500 of diameters 1 and 1.4 at 0.84.
        let equal = square(1000.0 * PI / 4.0 / 0.8);
        assert!(skin_for(&equal, 1.0, 1000, true, Neighbourhood::Auto).is_some());
        let mixed = square(500.0 * PI / 4.0 * (1.0 + 1.96) / 0.84);
        assert!(skin_for(&mixed, 1.4, 1000, true, Neighbourhood::Auto).is_some());
        // 20 of diameter 1 among 400 of 0.1 at η = 0.85: the reach is 1, the density that of
        // the small disks.
        let asymmetric = square((20.0 + 400.0 * 0.01) * PI / 4.0 / 0.85);
        assert_eq!(skin_for(&asymmetric, 1.0, 420, true, Neighbourhood::Auto), None);
        assert!(skin_for(&asymmetric, 1.0, 420, true, Neighbourhood::Lists).is_some());
        // Spheres: 1000 equal at η = 0.6.
        let cube = SimBox {
            lengths: SVector::from([(1000.0 * PI / 6.0 / 0.6f64).cbrt(); 3]),
            boundary: [Boundary::Periodic; 3],
        };
        assert!(skin_for(&cube, 1.0, 1000, true, Neighbourhood::Auto).is_some());
    }
}
