//! Xorshift64 (Marsaglia 2003, shifts 13, 7, 17): the small deterministic
//! generator of the benchmark's points and of randomized tests. Not for
//! material choices (those use a counter-based hash keyed by voxel index).

/// The generator state (never zero).
#[derive(Clone, Debug)]
pub struct XorShift(u64);

impl XorShift {
    /// A generator from `state` (zero, which would stay zero, becomes one).
    pub fn new(state: u64) -> Self {
        Self(state.max(1))
    }

    /// Uniform in [0, 1), from the top 53 bits of the next state.
    pub fn next_f64(&mut self) -> f64 {
        let mut s = self.0;
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        self.0 = s;
        (s >> 11) as f64 / (1u64 << 53) as f64
    }
}
