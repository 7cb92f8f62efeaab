//! Scratch a contouring task reuses band after band: slot arrays stamped
//! with the band that set them (so nothing is cleared between bands), and
//! the pool tasks borrow them from (so a plane does not allocate and zero
//! fresh ones).

use std::sync::Mutex;

/// One `u32` per slot, stamped with the band it was set in: a slot set in
/// an earlier band reads as unset.
#[derive(Default)]
pub(super) struct Stamped {
    /// `band << 32 | value`; [`NEVER`] before the first set.
    slot: Vec<u64>,
    band: u64,
}

/// A fresh slot: band `u32::MAX`, which [`Stamped::begin`] never reaches.
/// Not 0, so the array is written when made: a slot's first touch is a
/// read ([`Stamped::get`]), and a read of a zeroed allocation's untouched
/// page maps the kernel's shared zero page, whose first write then faults
/// again and flushes the page from the other cores' TLBs (an interrupt to
/// each, costly in a virtual machine).
const NEVER: u64 = u64::MAX;

impl Stamped {
    /// Start a band of `len` slots, none set.
    pub fn begin(&mut self, len: usize) {
        if self.slot.len() != len || self.band + 1 >= NEVER >> 32 {
            self.slot = Vec::new();
            self.slot = vec![NEVER; len];
            self.band = 0;
        }
        self.band += 1;
    }

    /// Slots (set or not).
    pub fn slots(&self) -> usize {
        self.slot.len()
    }

    /// Slot `s`'s value, when set in this band.
    #[inline]
    pub fn get(&self, s: usize) -> Option<u32> {
        let set = self.slot[s];
        (set >> 32 == self.band).then_some(set as u32)
    }

    /// Set slot `s` for this band.
    #[inline]
    pub fn set(&mut self, s: usize, value: u32) {
        self.slot[s] = self.band << 32 | u64::from(value);
    }

    /// Slot `s`'s value, or `add()`'s, set in this band.
    #[inline]
    pub fn find_or(&mut self, s: usize, add: impl FnOnce() -> u32) -> u32 {
        self.get(s).unwrap_or_else(|| {
            let v = add();
            self.set(s, v);
            v
        })
    }
}

/// Band scratch not in use: a contouring task
/// borrows one ([`Pool::lend`]) and gives it back when done, so a plane
/// does not allocate and zero fresh ones.
pub(super) struct Pool<T: Default>(Mutex<Vec<T>>);

impl<T: Default> Default for Pool<T> {
    fn default() -> Self {
        Self(Mutex::new(Vec::new()))
    }
}

impl<T: Default> Pool<T> {
    /// One for a task (fresh when none is free), back in the pool when the
    /// loan is dropped.
    pub fn lend(&self) -> Loan<'_, T> {
        let item = self
            .0
            .lock()
            .ok()
            .and_then(|mut free| free.pop())
            .unwrap_or_default();
        Loan { item, pool: self }
    }
}

/// What a [`Pool`] lent.
pub(super) struct Loan<'a, T: Default> {
    item: T,
    pool: &'a Pool<T>,
}

impl<T: Default> std::ops::Deref for Loan<'_, T> {
    type Target = T;
    fn deref(&self) -> &T {
        &self.item
    }
}

impl<T: Default> std::ops::DerefMut for Loan<'_, T> {
    fn deref_mut(&mut self) -> &mut T {
        &mut self.item
    }
}

impl<T: Default> Drop for Loan<'_, T> {
    fn drop(&mut self) {
        // (A poisoned pool only means the next task allocates afresh.)
        if let Ok(mut free) = self.pool.0.lock() {
            free.push(std::mem::take(&mut self.item));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Slots read unset until set in the current band, and again after the
    /// next `begin`; a band count near the fresh slots' stamp starts over.
    #[test]
    fn slots_are_set_for_one_band() {
        let mut s = Stamped::default();
        s.begin(5);
        assert_eq!((0..5).map(|i| s.get(i)).collect::<Vec<_>>(), [None; 5]);
        s.set(2, 7);
        assert_eq!(s.get(2), Some(7));
        assert_eq!(s.find_or(2, || 9), 7);
        assert_eq!(s.find_or(3, || 9), 9);
        s.begin(5);
        assert_eq!((s.get(2), s.get(3)), (None, None));
        s.band = (NEVER >> 32) - 1;
        s.begin(5);
        assert_eq!(s.band, 1);
        assert_eq!((0..5).map(|i| s.get(i)).collect::<Vec<_>>(), [None; 5]);
    }
}
