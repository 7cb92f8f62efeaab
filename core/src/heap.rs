//! A counting global allocator, so that a script which allocates without
//! bound stops with an error instead of taking the machine's memory.
//!
//! A loop that doubles a string or an array (`for i in 0..60 { s += s; }`)
//! reaches gigabytes in a few dozen operations, and an allocation that
//! fails aborts a Rust process: the studio would be gone, and on Linux the
//! kernel may kill it (or another program) first. Rhai's own size limits
//! (`set_max_string_size`, `set_max_array_size`) cannot serve: once any is
//! set, every call that mutates an array walks the whole array, so building
//! a list with `push` becomes quadratic.
//!
//! Instead the binaries install [`CountingAllocator`], which keeps the
//! number of live heap bytes in one relaxed atomic, and a running script
//! reads it at every operation (the progress hook it already has for
//! cancel). It stops when the heap has grown by more than its budget since
//! the script started (`ScriptOptions::max_heap`). Growth by doubling is
//! caught one doubling after the budget, so the peak stays within about
//! three budgets. One single enormous allocation happens inside one
//! operation: Rhai's functions that allocate by count (`pad`, `blob`) are
//! replaced by ones that check the budget first (`script/bulk.rs`).
//!
//! Where no counting allocator is installed (a library user's program),
//! [`live_bytes`] is `None` and scripts run without the check.

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};

/// Live heap bytes, as counted by [`CountingAllocator`] (0 when it is not
/// the global allocator).
static LIVE: AtomicUsize = AtomicUsize::new(0);

/// The system allocator, counting live bytes. Install it in a binary:
///
/// ```ignore
/// #[global_allocator]
/// static HEAP: volcad_core::heap::CountingAllocator = volcad_core::heap::CountingAllocator;
/// ```
pub struct CountingAllocator;

// SAFETY: every call is forwarded to `System` with the same arguments; the
// counter is bookkeeping only and never affects the returned memory.
unsafe impl GlobalAlloc for CountingAllocator {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        // SAFETY: forwarded unchanged (the caller upholds `alloc`'s contract).
        let p = unsafe { System.alloc(layout) };
        if !p.is_null() {
            LIVE.fetch_add(layout.size(), Ordering::Relaxed);
        }
        p
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        // SAFETY: forwarded unchanged.
        let p = unsafe { System.alloc_zeroed(layout) };
        if !p.is_null() {
            LIVE.fetch_add(layout.size(), Ordering::Relaxed);
        }
        p
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: forwarded unchanged.
        unsafe { System.dealloc(ptr, layout) };
        LIVE.fetch_sub(layout.size(), Ordering::Relaxed);
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        // SAFETY: forwarded unchanged.
        let p = unsafe { System.realloc(ptr, layout, new_size) };
        if !p.is_null() {
            let old = layout.size();
            if new_size >= old {
                LIVE.fetch_add(new_size - old, Ordering::Relaxed);
            } else {
                LIVE.fetch_sub(old - new_size, Ordering::Relaxed);
            }
        }
        p
    }
}

/// Live heap bytes of the whole process, or `None` when
/// [`CountingAllocator`] is not the global allocator (nothing was counted).
#[inline]
pub fn live_bytes() -> Option<usize> {
    match LIVE.load(Ordering::Relaxed) {
        0 => None,
        n => Some(n),
    }
}

/// Bytes of memory available to new allocations (`MemAvailable` from
/// `/proc/meminfo`), or `None` where that is not known.
pub fn available_memory() -> Option<u64> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = text.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024)
}

/// The environment variable that sets a script's heap budget in MiB.
pub(crate) const BUDGET_VAR: &str = "VOLCAD_SCRIPT_MEMORY_MB";

/// The budget [`BUDGET_VAR`] asks for, in bytes: `Ok(None)` when it is not
/// set, an error naming it when it is not a whole number of MiB above 0.
pub(crate) fn budget_from_env() -> Result<Option<u64>, String> {
    let Some(v) = std::env::var_os(BUDGET_VAR) else {
        return Ok(None);
    };
    let text = v.to_string_lossy();
    match text.trim().parse::<u64>() {
        Ok(mb) if mb > 0 => Ok(Some(mb.saturating_mul(1 << 20))),
        _ => Err(format!(
            "{BUDGET_VAR}={text}: give the script's memory budget as a whole number of MiB above 0"
        )),
    }
}

/// Bytes the process may still map before it reaches its address-space
/// limit (`ulimit -v`, `RLIMIT_AS`): the limit less the virtual size it
/// has now (`VmSize`, which counts the allocator's reserved arenas and the
/// thread stacks too). `None` when there is no limit or it is not known.
pub fn address_space_left() -> Option<u64> {
    let limit = rustix::process::getrlimit(rustix::process::Resource::As).current?;
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmSize:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(limit.saturating_sub(kib * 1024))
}

/// The default heap budget of a script: [`BUDGET_VAR`] when set, else a
/// quarter of the memory available when it starts, or 4 GiB where that is
/// not known; either way at most a quarter of the address space the
/// process has left under `ulimit -v` (an allocation past that limit
/// fails, and a failed allocation aborts a Rust process). A design script
/// needs megabytes; the budget only has to stop a runaway while its peak
/// (about three budgets, see the module doc) still fits.
pub(crate) fn default_script_budget() -> u64 {
    let budget = match budget_from_env() {
        Ok(Some(b)) => b,
        _ => available_memory().map_or(4 << 30, |a| a / 4),
    };
    match address_space_left() {
        Some(left) => budget.min(left / 4),
        None => budget,
    }
}

/// `n` bytes for people: "1.5 GiB", "12 MiB", "300 B".
pub fn human_bytes(n: u64) -> String {
    const UNITS: [&str; 5] = ["B", "KiB", "MiB", "GiB", "TiB"];
    let mut v = n as f64;
    let mut u = 0;
    while v >= 1024.0 && u + 1 < UNITS.len() {
        v /= 1024.0;
        u += 1;
    }
    if u == 0 {
        format!("{n} B")
    } else if v < 10.0 {
        format!("{v:.1} {}", UNITS[u])
    } else {
        format!("{v:.0} {}", UNITS[u])
    }
}
