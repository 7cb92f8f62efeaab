//! A per-thread memory of the last answer of the few most recently used
//! indexes: the nearest triangle of a mesh, the tetrahedron that held the
//! last point. Samplers visit neighbouring points in turn, so the last
//! answer is a good first guess. Keys are the index's data address; a stale
//! key (a dropped index whose memory was reused) only gives a poor guess.

use std::cell::Cell;

/// Indexes remembered per thread (the least recently used is replaced).
const WAYS: usize = 4;

/// Last slots of the most recently used indexes, most recent first. Each
/// user keeps its own in a `thread_local!`.
pub(crate) struct RecentSlots(Cell<[(usize, u32); WAYS]>);

impl RecentSlots {
    /// Nothing remembered.
    pub(crate) const fn new() -> Self {
        RecentSlots(Cell::new([(0, 0); WAYS]))
    }

    /// The remembered slot for index `key`.
    #[inline]
    pub(crate) fn get(&self, key: usize) -> Option<u32> {
        self.0.get().iter().find(|e| e.0 == key).map(|e| e.1)
    }

    /// Remembers `slot` for index `key` (most recent first).
    #[inline]
    pub(crate) fn set(&self, key: usize, slot: u32) {
        let mut a = self.0.get();
        let i = a.iter().position(|e| e.0 == key).unwrap_or(WAYS - 1);
        a.copy_within(0..i, 1);
        a[0] = (key, slot);
        self.0.set(a);
    }
}
