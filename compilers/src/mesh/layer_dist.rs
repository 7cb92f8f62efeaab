//! A mesh plane's signed distances as a view into its slab's buffer.
//!
//! The sampler writes a slab's distances into one buffer, layer after
//! layer; rather than each plane copying its layer out, the buffer is
//! shared: every plane of the slab holds it and its layer's
//! range, and the buffer goes back to the sampler once the contourer has
//! retired all of them ([`DistPool`]). The contourer keeps the last plane
//! of a slab while the next slab is contoured and the one after is sampled,
//! so three buffers circulate (checked in debug builds by `build`).

use std::ops::Deref;
use std::sync::Arc;

/// One layer of a shared distance buffer, read as a slice.
#[derive(Clone, Debug, Default)]
pub struct LayerDist {
    buf: Arc<Vec<f32>>,
    start: usize,
    len: usize,
}

impl LayerDist {
    /// Layer `range` of `buf`.
    pub fn new(buf: &Arc<Vec<f32>>, range: std::ops::Range<usize>) -> Self {
        assert!(range.end <= buf.len(), "layer beyond the buffer");
        Self {
            buf: Arc::clone(buf),
            start: range.start,
            len: range.len(),
        }
    }
}

impl Deref for LayerDist {
    type Target = [f32];

    fn deref(&self) -> &[f32] {
        &self.buf[self.start..self.start + self.len]
    }
}

impl From<Vec<f32>> for LayerDist {
    /// A buffer of one layer, not shared.
    fn from(v: Vec<f32>) -> Self {
        let len = v.len();
        Self {
            buf: Arc::new(v),
            start: 0,
            len,
        }
    }
}

impl PartialEq for LayerDist {
    fn eq(&self, other: &Self) -> bool {
        **self == **other
    }
}

/// Slab distance buffers handed out to planes, taken back when free.
#[derive(Default)]
pub struct DistPool {
    out: Vec<Arc<Vec<f32>>>,
    /// Buffers made new (the rest came back).
    fresh: usize,
}

impl DistPool {
    /// A buffer no plane holds any more (its old contents), or a new one.
    pub fn take(&mut self) -> Vec<f32> {
        match self.out.iter().position(|b| Arc::strong_count(b) == 1) {
            Some(i) => Arc::try_unwrap(self.out.swap_remove(i)).unwrap_or_default(),
            None => {
                self.fresh += 1;
                Vec::new()
            }
        }
    }

    /// How many buffers [`Self::take`] had to make new.
    pub fn fresh(&self) -> usize {
        self.fresh
    }

    /// Share `buf` (a sampled slab's distances) with its planes.
    pub fn share(&mut self, buf: Vec<f32>) -> Arc<Vec<f32>> {
        let shared = Arc::new(buf);
        self.out.push(Arc::clone(&shared));
        shared
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn layers_read_their_range_and_buffers_come_back_when_free() {
        let mut pool = DistPool::default();
        let shared = pool.share((0..6).map(|v| v as f32).collect());
        let (a, b) = (LayerDist::new(&shared, 0..3), LayerDist::new(&shared, 3..6));
        drop(shared);
        assert_eq!(*b, [3.0, 4.0, 5.0]);
        // Held by planes: not handed out again.
        assert!(pool.take().is_empty());
        drop(a);
        assert!(pool.take().is_empty());
        drop(b);
        assert_eq!(pool.take(), vec![0.0, 1.0, 2.0, 3.0, 4.0, 5.0]);
        assert!(pool.take().is_empty(), "given out once");
        assert_eq!(pool.fresh(), 3, "three takes found nothing free");
    }
}
