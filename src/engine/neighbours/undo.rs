//! Undo records of the neighbourhood: what a rebuild changed, kept (when asked for) so that
//! the neighbourhood can be taken back to an earlier time exactly — who is in which list
//! and cell, every list's entries in their order, and every centre.
//!
//! A rebuild (or a rebuild told by the other side of a divided box) changes the moved
//! particle's centre, cell and rows, and the rows of the particles it leaves or joins; a
//! move of the grid that follows the particles, one particle's cell. Each change is
//! recorded before it is made, and [`Neighbours::undo_to`] takes them back latest first.
//! Where a particle sits within its cell's chain is not restored (a particle put back goes
//! first): no search depends on it (which partner comes first is decided by the total order
//! of events, never by the walk), and the divided box's tests check the events replayed
//! after an undo bit for bit.

// Taken back by the tests today, and by the two-thread schedule that keeps the order of
// time once it lands.
#![cfg_attr(not(test), allow(dead_code))]

use super::Neighbours;
use super::lists::{List, MAX_ROWS};
use nalgebra::SVector;

/// One change of the neighbourhood, as it was before.
#[derive(Clone, Debug)]
pub(crate) enum Undo<const D: usize> {
    /// Particle `k`'s rows held these entries.
    Rows { k: u32, rows: [List; MAX_ROWS] },
    /// With lists: particle `k`'s centre (and so its cell) was here.
    Centre { k: u32, centre: SVector<f64, D> },
    /// Following: particle `k` moved one cell along `axis`, up or down.
    Shift { k: u32, axis: u8, up: bool },
}

impl<const D: usize> Neighbours<D> {
    /// Starts (or stops and forgets) recording the changes of every rebuild.
    pub(crate) fn record(&mut self, on: bool) {
        self.log = on.then(Vec::new);
    }

    /// How many changes are recorded: a mark to [`undo_to`](Self::undo_to).
    pub(crate) fn recorded(&self) -> usize {
        self.log.as_ref().map_or(0, Vec::len)
    }

    /// Forgets the first `mark` changes recorded (they can no longer be undone).
    pub(crate) fn forget(&mut self, mark: usize) {
        if let Some(log) = &mut self.log {
            log.drain(..mark);
        }
    }

    /// Records particle `k`'s rows before they change.
    #[inline]
    pub(super) fn note_rows(&mut self, k: usize) {
        if let Some(log) = &mut self.log {
            log.push(Undo::rows(k, &self.lists[k * Self::ROWS..(k + 1) * Self::ROWS]));
        }
    }

    /// Records a change, if recording.
    #[inline]
    pub(super) fn note(&mut self, undo: Undo<D>) {
        if let Some(log) = &mut self.log {
            log.push(undo);
        }
    }

    /// Takes the neighbourhood back to when [`recorded`](Self::recorded) gave `mark`, undoing
    /// the later changes latest first.
    pub(crate) fn undo_to(&mut self, mark: usize) {
        let Some(mut log) = self.log.take() else { return };
        for undo in log.drain(mark..).rev() {
            match undo {
                Undo::Rows { k, rows } => {
                    let n = Self::ROWS;
                    self.rows_mut(k as usize).copy_from_slice(&rows[..n]);
                }
                Undo::Centre { k, centre } => {
                    let k = k as usize;
                    let (from, to) = (self.cell(k), self.cells.locate(&centre));
                    if from != to {
                        self.cells.remove(k, &from);
                        self.cells.insert(k, &to);
                    }
                    self.centres[k] = centre;
                }
                Undo::Shift { k, axis, up } => self.cells.shift(k as usize, axis as usize, !up),
            }
        }
        self.log = Some(log);
    }
}

/// Records particle `k`'s rows `rows` before `i` is dropped from them, if recording and
/// they hold `i` (a crowded particle's rebuild asks everyone around it, most of whom do
/// not).
#[inline]
pub(super) fn note_holding<const D: usize>(log: &mut Option<Vec<Undo<D>>>, k: usize, rows: &[List], i: usize) {
    if let Some(log) = log
        && rows.iter().any(|row| row.entries().contains(&(i as u32)))
    {
        log.push(Undo::rows(k, rows));
    }
}

impl<const D: usize> Undo<D> {
    /// Particle `k`'s rows `rows`, as they are.
    fn rows(k: usize, rows: &[List]) -> Self {
        let mut saved = [List::EMPTY; MAX_ROWS];
        saved[..rows.len()].copy_from_slice(rows);
        Undo::Rows { k: k as u32, rows: saved }
    }
}
