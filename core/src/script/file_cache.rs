//! Loaded meshes and FEA fields kept between script runs.
//!
//! The studio re-runs the script on every edit; rebuilding the bunny's
//! BVH, winding tree and candidate grid each time would cost a few tenths
//! of a second per keystroke. A file is reused while its path, length and
//! modification time are unchanged (an edited file is loaded again), so the
//! cache never returns stale data for a file saved on disk.

use std::any::Any;
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};
use std::time::SystemTime;

/// Most files kept; the oldest is dropped beyond that.
const CAPACITY: usize = 8;

type Stamp = (u64, Option<SystemTime>);

struct Entry {
    stamps: Vec<Stamp>,
    value: Arc<dyn Any + Send + Sync>,
    used: u64,
}

/// A use counter (for dropping the least recently used) and the entries.
type Cache = (u64, HashMap<Vec<PathBuf>, Entry>);

static CACHE: Mutex<Option<Cache>> = Mutex::new(None);

fn stamp(path: &Path) -> Option<Stamp> {
    let m = std::fs::metadata(path).ok()?;
    Some((m.len(), m.modified().ok()))
}

/// The value loaded from `paths` by `load`, reused while none of the files
/// changed. Errors are not cached.
pub fn cached<T: Any + Send + Sync, E>(
    paths: &[&Path],
    load: impl FnOnce() -> Result<T, E>,
) -> Result<Arc<T>, E> {
    let key: Vec<PathBuf> = paths.iter().map(|p| p.to_path_buf()).collect();
    let stamps: Option<Vec<Stamp>> = paths.iter().map(|p| stamp(p)).collect();
    if let Some(stamps) = &stamps {
        let mut guard = CACHE.lock().unwrap_or_else(|e| e.into_inner());
        let (clock, map) = guard.get_or_insert_with(Default::default);
        *clock += 1;
        if let Some(e) = map.get_mut(&key)
            && e.stamps == *stamps
            && let Ok(v) = e.value.clone().downcast::<T>()
        {
            e.used = *clock;
            return Ok(v);
        }
    }
    // Load outside the lock: other scripts may load other files meanwhile.
    let value = Arc::new(load()?);
    if let Some(stamps) = stamps {
        let mut guard = CACHE.lock().unwrap_or_else(|e| e.into_inner());
        let (clock, map) = guard.get_or_insert_with(Default::default);
        if map.len() >= CAPACITY && !map.contains_key(&key) {
            let oldest = map
                .iter()
                .min_by_key(|(_, e)| e.used)
                .map(|(k, _)| k.clone());
            if let Some(k) = oldest {
                map.remove(&k);
            }
        }
        map.insert(
            key,
            Entry {
                stamps,
                value: value.clone(),
                used: *clock,
            },
        );
    }
    Ok(value)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reuses_until_the_file_changes() {
        let dir = std::env::temp_dir().join(format!("volcad-cache-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let f = dir.join("a.txt");
        std::fs::write(&f, "one").unwrap();
        let load = || std::fs::read_to_string(&f).map(|s| s.len());
        let a = cached(&[&f], load).unwrap();
        let b = cached(&[&f], || -> Result<usize, ()> { panic!("must be cached") }).unwrap();
        assert!(Arc::ptr_eq(&a, &b));
        // A different length is a different file.
        std::fs::write(&f, "three").unwrap();
        let c = cached(&[&f], load).unwrap();
        assert_eq!(*c, 5);
        std::fs::remove_dir_all(&dir).ok();
    }
}
