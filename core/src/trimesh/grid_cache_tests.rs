//! Tests of the on-disk grid cache: a read grid is the built one bit for
//! bit; corrupted, truncated, foreign and stale files are rebuilt.

use std::fs;
use std::path::{Path, PathBuf};

use glam::DVec3;

use super::super::tests::Rng;
use super::super::{TriangleMesh, formats};
use super::{key, trim};

const BUNNY: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../assets/examples/data/bunny.obj"
);

fn bunny_parts() -> (Vec<DVec3>, Vec<[u32; 3]>) {
    let l = formats::load(Path::new(BUNNY)).expect("bunny loads");
    (l.vertices, l.triangles)
}

fn build(dir: Option<&Path>) -> TriangleMesh {
    let (v, t) = bunny_parts();
    TriangleMesh::from_triangles_cached(v, t, dir).expect("bunny builds")
}

fn grid_files(dir: &Path) -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = fs::read_dir(dir)
        .map(|e| e.flatten().map(|e| e.path()).collect())
        .unwrap_or_default();
    v.sort();
    v
}

/// The grids, compared through their bits (`f64` NaN-safe).
fn same_grids(a: &TriangleMesh, b: &TriangleMesh) {
    let (ca, cb) = (
        a.coarse.as_ref().expect("coarse"),
        b.coarse.as_ref().expect("coarse"),
    );
    assert_eq!(ca.dims, cb.dims);
    assert_eq!(ca.origin, cb.origin);
    assert_eq!(ca.cell.to_bits(), cb.cell.to_bits());
    let bits = |d: &[f64]| d.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(&ca.d), bits(&cb.d));
    let (ga, gb) = (
        a.candidates.as_ref().expect("grid"),
        b.candidates.as_ref().expect("grid"),
    );
    assert_eq!(ga.records, gb.records);
    assert_eq!(ga.items, gb.items);
    assert_eq!((ga.slot_bits, ga.q_shift), (gb.slot_bits, gb.q_shift));
    assert_eq!(ga.inv_unit.to_bits(), gb.inv_unit.to_bits());
    assert_eq!(ga.tiny.to_bits(), gb.tiny.to_bits());
    assert_eq!(ga.cells.dims(), gb.cells.dims());
    // And the answers, near and far.
    let mut rng = Rng::new(38);
    let bbox = a.bbox().expand(3.0);
    for _ in 0..20_000 {
        let p = rng.in_box(&bbox);
        assert_eq!(
            a.signed_distance(p).to_bits(),
            b.signed_distance(p).to_bits(),
            "{p}"
        );
    }
}

#[test]
fn a_read_grid_is_the_built_grid() {
    let dir = tempfile::tempdir().expect("tempdir");
    let built = build(None);
    let first = build(Some(dir.path()));
    let files = grid_files(dir.path());
    assert_eq!(files.len(), 1, "{files:?}");
    let (v, t) = bunny_parts();
    assert_eq!(
        files[0].file_name().and_then(|n| n.to_str()),
        Some(&*format!("{:016x}.grid", key(&v, &t)))
    );
    let second = build(Some(dir.path()));
    same_grids(&built, &first);
    same_grids(&built, &second);
}

/// Every damaged variant is refused and rewritten whole.
#[test]
fn damaged_files_are_rebuilt_never_trusted() {
    let dir = tempfile::tempdir().expect("tempdir");
    let built = build(Some(dir.path()));
    let path = grid_files(dir.path()).remove(0);
    let good = fs::read(&path).expect("read");
    let mut flipped = good.clone();
    flipped[good.len() / 2] ^= 0x10;
    let mut head = good.clone();
    head[200] ^= 0x01;
    let mut lengths = good.clone();
    lengths[30] ^= 0x04;
    let mut bad_sum = good.clone();
    let last = bad_sum.len() - 1;
    bad_sum[last] ^= 1;
    let cases: Vec<(&str, Vec<u8>)> = vec![
        ("one bit flipped in the lists", flipped),
        ("one bit flipped in the head", head),
        ("a section length changed", lengths),
        ("checksum wrong", bad_sum),
        ("truncated", good[..good.len() - 1000].to_vec()),
        ("empty", Vec::new()),
        (
            "a different format",
            [b"VCADGRIX".as_slice(), &good[8..]].concat(),
        ),
    ];
    for (what, bytes) in cases {
        fs::write(&path, &bytes).expect("write");
        let again = build(Some(dir.path()));
        same_grids(&built, &again);
        assert_eq!(fs::read(&path).expect("read"), good, "{what}: rewritten");
    }
}

/// An inside-out mesh is flipped before its grids are built; its file is
/// named by the mesh as given, and read back as built.
#[test]
fn an_inside_out_meshs_grids_are_read_back() {
    let dir = tempfile::tempdir().expect("tempdir");
    let (v, t) = bunny_parts();
    let flipped: Vec<[u32; 3]> = t.iter().map(|&[a, b, c]| [a, c, b]).collect();
    let cached = |dir: Option<&Path>| {
        TriangleMesh::from_triangles_cached(v.clone(), flipped.clone(), dir).expect("builds")
    };
    let built = cached(None);
    let first = cached(Some(dir.path()));
    let files = grid_files(dir.path());
    assert_eq!(files.len(), 1, "{files:?}");
    let inode = |p: &Path| {
        #[cfg(unix)]
        return std::os::unix::fs::MetadataExt::ino(&fs::metadata(p).expect("metadata"));
        #[cfg(not(unix))]
        return fs::read(p).expect("read");
    };
    let before = inode(&files[0]);
    let second = cached(Some(dir.path()));
    assert!(!second.warnings().is_empty(), "the flip is reported");
    same_grids(&built, &first);
    same_grids(&built, &second);
    // Read, not rebuilt: a rewrite renames a new file into place.
    assert_eq!(grid_files(dir.path()), files);
    assert_eq!(inode(&files[0]), before);
}

/// A valid file of another mesh under this mesh's name (a hash collision)
/// is caught by the stored mesh.
#[test]
fn another_meshs_file_under_this_name_is_refused() {
    let dir = tempfile::tempdir().expect("tempdir");
    let (v, t) = bunny_parts();
    let moved: Vec<DVec3> = v.iter().map(|p| *p + DVec3::new(0.5, 0.0, 0.0)).collect();
    let other = TriangleMesh::from_triangles_cached(moved, t, Some(dir.path())).expect("builds");
    let other_file = grid_files(dir.path()).remove(0);
    let built = build(None);
    let (v, t) = bunny_parts();
    let name = dir.path().join(format!("{:016x}.grid", key(&v, &t)));
    fs::copy(&other_file, &name).expect("copy");
    let read = build(Some(dir.path()));
    same_grids(&built, &read);
    assert_ne!(
        other.signed_distance(DVec3::ZERO).to_bits(),
        read.signed_distance(DVec3::ZERO).to_bits()
    );
}

#[test]
fn the_folder_is_trimmed_oldest_first() {
    let dir = tempfile::tempdir().expect("tempdir");
    let names = ["a.grid", "b.grid", "c.grid", "keep.txt"];
    for (i, n) in names.iter().enumerate() {
        let f = fs::File::create(dir.path().join(n)).expect("create");
        f.set_len(1000).expect("len");
        let when = std::time::SystemTime::UNIX_EPOCH
            + std::time::Duration::from_secs(1_000_000 + i as u64);
        f.set_modified(when).expect("mtime");
    }
    trim(dir.path(), 2500);
    let left: Vec<String> = grid_files(dir.path())
        .iter()
        .filter_map(|p| p.file_name()?.to_str().map(String::from))
        .collect();
    assert_eq!(left, ["b.grid", "c.grid", "keep.txt"]);
}

/// Small meshes are not cached: building is faster than a file.
#[test]
fn small_meshes_write_nothing() {
    let dir = tempfile::tempdir().expect("tempdir");
    let v = vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z];
    let t = vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]];
    TriangleMesh::from_triangles_cached(v, t, Some(dir.path())).expect("tetrahedron");
    assert!(grid_files(dir.path()).is_empty());
}
