//! Where the engine's structures get their large arrays: from a [`Store`] they are handed.
//! The structures say what an array holds; the store — the timing room's, which backs large
//! arrays with huge pages, or [`Plain`] — says where it lives. The contents are the same
//! whichever store builds them, and an array is written once, where it stays.

/// Builds the large arrays of the engine's structures.
pub(crate) trait Store {
    /// `items` in a new vector.
    fn collect<T>(&self, items: impl ExactSizeIterator<Item = T>) -> Vec<T>;

    /// `n` copies of `value` in a new vector.
    fn filled<T: Clone>(&self, n: usize, value: T) -> Vec<T> {
        self.collect(std::iter::repeat_n(value, n))
    }

    /// `v`'s elements where this store keeps arrays, and no spare capacity (a vector built
    /// elsewhere, such as the particles handed to the engine).
    fn moved<T>(&self, v: Vec<T>) -> Vec<T>;
}

/// Ordinary vectors.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Plain;

impl Store for Plain {
    fn collect<T>(&self, items: impl ExactSizeIterator<Item = T>) -> Vec<T> {
        items.collect()
    }

    fn moved<T>(&self, mut v: Vec<T>) -> Vec<T> {
        v.shrink_to_fit();
        v
    }
}
