//! Results other crates compute from a prepared model alone, kept with it
//! so that a second request costs a lookup (an export's coarse look is
//! asked for by its estimate and again by its job).

use std::any::Any;
use std::sync::{Arc, Mutex, PoisonError};

/// Results kept at most, the oldest dropped first: a studio session asks
/// for a new key at each voxel size it estimates.
const KEPT: usize = 16;

/// Derived results by type and key, shared by a model's clones (see
/// [`crate::Model::derived`]).
#[derive(Clone, Default)]
pub(crate) struct Derived(Arc<Mutex<Vec<Arc<dyn Any + Send + Sync>>>>);

impl std::fmt::Debug for Derived {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let kept = self.0.lock().unwrap_or_else(PoisonError::into_inner).len();
        write!(f, "Derived({kept} kept)")
    }
}

impl Derived {
    /// The kept `T` for `key`, else `make()` (run without the lock held:
    /// it may sample on every core), kept.
    pub(crate) fn get_or<K, T>(&self, key: K, make: impl FnOnce() -> T) -> T
    where
        K: PartialEq + Send + Sync + 'static,
        T: Clone + Send + Sync + 'static,
    {
        let kept = || self.0.lock().unwrap_or_else(PoisonError::into_inner);
        let found = kept().iter().find_map(|e| {
            let (k, v) = e.downcast_ref::<(K, T)>()?;
            (*k == key).then(|| v.clone())
        });
        if let Some(v) = found {
            return v;
        }
        let v = make();
        let mut kept = kept();
        if kept.len() >= KEPT {
            kept.remove(0);
        }
        kept.push(Arc::new((key, v.clone())));
        v
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn kept_by_type_and_key_and_shared_by_clones() {
        let d = Derived::default();
        let clone = d.clone();
        let mut made = 0;
        let mut get = |d: &Derived, key: u32| {
            d.get_or(key, || {
                made += 1;
                f64::from(key) * 2.0
            })
        };
        assert_eq!(get(&d, 3), 6.0);
        assert_eq!(get(&clone, 3), 6.0);
        assert_eq!(get(&d, 4), 8.0);
        assert_eq!(made, 2);
        // Another result type under the same key is its own entry.
        assert_eq!(d.get_or(3u32, || "three"), "three");
        for key in 10..10 + KEPT as u32 {
            d.get_or(key, || 0.0);
        }
        // The oldest went first.
        assert_eq!(d.get_or(3u32, || -1.0), -1.0);
    }
}
