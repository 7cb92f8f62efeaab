//! The working memory a mesh export estimates (printed before it starts,
//! and checked against what is free) covers what it holds at its peak.
//! This test binary counts live heap bytes, as the `volcad` binary does.

mod common;

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::time::Duration;

use common::model;
use glam::DVec3;
use volcad_compilers::mesh::{MeshParams, estimate_mesh, segment_meshes};
use volcad_compilers::resources::MemoryGuard;
use volcad_core::heap::{CountingAllocator, live_bytes};

#[global_allocator]
static HEAP: CountingAllocator = CountingAllocator;

/// The tests read the one process-wide heap count: one at a time.
static ONE_AT_A_TIME: std::sync::Mutex<()> = std::sync::Mutex::new(());

#[test]
fn the_estimate_covers_the_flat_faces_kept_to_the_end() {
    let _one = ONE_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner());
    // A box is all flat faces. Their voxels are kept (to be merged into
    // few triangles at the end), so what the export holds grows with their
    // area in voxels, not with a slab: at 0.001 mm the graded bar's faces
    // took more than this machine's 24 GB while the estimate said 8 GB.
    let m = model(
        r#"let m = default_materials(); RectPrism(Vec3(0,0,0), Vec3(10,10,10), m.id("red"))"#,
    );
    let p = MeshParams {
        voxel: DVec3::splat(0.03),
        ..MeshParams::default()
    };
    let estimate = estimate_mesh(&m, &p).expect("estimate").memory_bytes as usize;
    let base = live_bytes().expect("the counting allocator is installed");
    let peak = Arc::new(AtomicUsize::new(0));
    let done = Arc::new(AtomicBool::new(false));
    let watch = {
        let (peak, done) = (peak.clone(), done.clone());
        std::thread::spawn(move || {
            while !done.load(Ordering::Relaxed) {
                let live = live_bytes().unwrap_or(0);
                peak.fetch_max(live.saturating_sub(base), Ordering::Relaxed);
                std::thread::sleep(Duration::from_micros(200));
            }
        })
    };
    let meshes = segment_meshes(&m, &p, &AtomicBool::new(false), |_, _| {}).expect("meshes");
    done.store(true, Ordering::Relaxed);
    watch.join().unwrap();
    let peak = peak.load(Ordering::Relaxed);
    assert_eq!(meshes.iter().filter(|s| !s.mesh.is_empty()).count(), 1);
    // 670 thousand flat cubes (some 40 bytes each): tens of MB, far above
    // the slabs and planes (about 14 MB).
    assert!(peak > 20 << 20, "peak {peak} bytes");
    assert!(
        peak <= estimate,
        "peak {peak} bytes above the estimate of {estimate}"
    );
}

#[test]
fn the_guard_stops_an_export_that_outgrows_its_limit() {
    let _one = ONE_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner());
    // Estimates can miss (the size estimate does not see parts thinner than
    // its cells); the mesh export checks the heap after every slab.
    let g = MemoryGuard::with_limit(8 << 20).expect("the counting allocator is installed");
    assert!(g.check(|| "at the start".into()).is_ok());
    let big = std::hint::black_box(vec![1u8; 16 << 20]);
    let e = g
        .check(|| "meshing after layer 4 of 10".into())
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with("--voxel: stopped meshing after layer 4 of 10"),
        "{e}"
    );
    assert!(e.contains("use a larger voxel size"), "{e}");
    drop(big);
    assert!(g.check(|| "later".into()).is_ok());
}
