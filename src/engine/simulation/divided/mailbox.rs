//! What one side's thread hands the other's: batches of changes, in the order they were
//! sent, each taken whole.
//!
//! The sender appends a batch under a lock; the receiver takes everything sent so far by
//! swapping its own (emptied) buffers in, so neither allocates once the buffers have grown,
//! and a receiver with nothing waiting reads one flag and takes no lock.

use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, Ordering};

/// Batches sent and not yet taken: their items end to end, and where each batch ends.
#[derive(Debug)]
pub(crate) struct Batches<T> {
    items: Vec<T>,
    ends: Vec<usize>,
}

impl<T> Default for Batches<T> {
    fn default() -> Self {
        Batches { items: Vec::new(), ends: Vec::new() }
    }
}

impl<T> Batches<T> {
    /// Each batch in the order sent.
    pub(crate) fn each(&self) -> impl Iterator<Item = &[T]> {
        let starts = std::iter::once(0).chain(self.ends.iter().copied());
        starts.zip(&self.ends).map(|(from, &to)| &self.items[from..to])
    }

    /// How many batches.
    pub(crate) fn len(&self) -> usize {
        self.ends.len()
    }

    /// Batch `i`.
    pub(crate) fn get(&self, i: usize) -> &[T] {
        let from = if i == 0 { 0 } else { self.ends[i - 1] };
        &self.items[from..self.ends[i]]
    }

    pub(crate) fn clear(&mut self) {
        self.items.clear();
        self.ends.clear();
    }
}

/// A mailbox from one thread to another.
#[derive(Debug)]
pub(crate) struct Mailbox<T> {
    waiting: Mutex<Batches<T>>,
    /// Whether `waiting` holds a batch (read without the lock).
    any: AtomicBool,
}

impl<T> Default for Mailbox<T> {
    fn default() -> Self {
        Mailbox { waiting: Mutex::new(Batches::default()), any: AtomicBool::new(false) }
    }
}

impl<T: Clone> Mailbox<T> {
    /// Sends `batch` (nothing, if it is empty).
    pub(crate) fn send(&self, batch: &[T]) {
        if batch.is_empty() {
            return;
        }
        let mut waiting = self.waiting.lock().unwrap_or_else(|e| e.into_inner());
        waiting.items.extend_from_slice(batch);
        let end = waiting.items.len();
        waiting.ends.push(end);
        // Release: whoever sees the flag sees the batch (and takes the lock anyway).
        self.any.store(true, Ordering::Release);
    }

    /// Whether a batch is waiting to be taken.
    pub(crate) fn waiting(&self) -> bool {
        self.any.load(Ordering::Acquire)
    }

    /// Takes every batch sent so far into `into` (emptied first); false if there was none.
    pub(crate) fn take(&self, into: &mut Batches<T>) -> bool {
        into.clear();
        if !self.waiting() {
            return false;
        }
        let mut waiting = self.waiting.lock().unwrap_or_else(|e| e.into_inner());
        std::mem::swap(&mut *waiting, into);
        self.any.store(false, Ordering::Relaxed);
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every batch arrives whole, once, in the order sent, across threads; an empty batch
    /// is not one.
    #[test]
    fn batches_arrive_whole_and_in_order() {
        let mailbox = Mailbox::<u64>::default();
        let sent = 20_000u64;
        let received = std::thread::scope(|scope| {
            scope.spawn(|| {
                for k in 0..sent {
                    // Batch k holds k % 5 + 1 items, k·10 + 0, 1, …, and an empty one
                    // follows every seventh.
                    let batch: Vec<u64> = (0..k % 5 + 1).map(|m| k * 10 + m).collect();
                    mailbox.send(&batch);
                    if k % 7 == 0 {
                        mailbox.send(&[]);
                    }
                }
            });
            let (mut into, mut got) = (Batches::default(), Vec::new());
            while got.len() < sent as usize {
                if mailbox.take(&mut into) {
                    got.extend(into.each().map(<[u64]>::to_vec));
                }
            }
            assert!(!mailbox.take(&mut into), "nothing left");
            got
        });
        for (k, batch) in received.iter().enumerate() {
            let k = k as u64;
            assert_eq!(batch, &(0..k % 5 + 1).map(|m| k * 10 + m).collect::<Vec<_>>(), "batch {k}");
        }
    }
}
