//! The engine's large arrays, as their owners list them: a structure hands each of its large
//! arrays to a [`Visitor`] (the timing room's, which moves them into memory backed by huge
//! pages; the elements, their order and the length stay as they were).

/// Something that wants to see every large array of a structure.
pub(crate) trait Visitor {
    /// One array.
    fn array<T>(&mut self, v: &mut Vec<T>);
}
