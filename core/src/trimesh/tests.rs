//! Tests of [`crate::trimesh`]: brute-force agreement on the bunny, a cube with
//! known distances, STL/OBJ reading and errors, open meshes.

use std::path::PathBuf;

use glam::DVec3;

use super::{MeshError, TriangleMesh};

/// The format writers of the integration tests (`core/tests/meshio`).
#[allow(dead_code)]
#[path = "../../tests/meshio/writers.rs"]
mod writers;
use crate::aabb::Aabb;

const BUNNY: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../assets/examples/data/bunny.obj"
);

/// Deterministic generator (SplitMix64) so failures reproduce.
pub(crate) struct Rng(u64);
impl Rng {
    pub(crate) fn new(seed: u64) -> Rng {
        Rng(seed)
    }
    pub(crate) fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    /// Uniform in [0, 1).
    pub(crate) fn f64(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }
    pub(crate) fn in_box(&mut self, b: &Aabb) -> DVec3 {
        let t = DVec3::new(self.f64(), self.f64(), self.f64());
        b.min + (b.max - b.min) * t
    }
}

/// Reference distance: projection onto the plane if it falls inside the
/// triangle, else the nearest of the three edges. Independent of Ericson.
fn brute_triangle_distance(p: DVec3, a: DVec3, b: DVec3, c: DVec3) -> f64 {
    let seg = |s: DVec3, e: DVec3| {
        let d = e - s;
        let t = if d.length_squared() > 0.0 {
            ((p - s).dot(d) / d.length_squared()).clamp(0.0, 1.0)
        } else {
            0.0
        };
        (s + d * t).distance(p)
    };
    let mut best = seg(a, b).min(seg(b, c)).min(seg(c, a));
    let n = (b - a).cross(c - a);
    if n.length_squared() > 0.0 {
        let n = n.normalize();
        let q = p - n * n.dot(p - a);
        if [(a, b), (b, c), (c, a)]
            .iter()
            .all(|&(s, e)| (e - s).cross(q - s).dot(n) >= 0.0)
        {
            best = best.min(q.distance(p));
        }
    }
    best
}

/// Exact generalised winding number: Σ solid angles / 4π (Van Oosterom &
/// Strackee 1983), written out independently of the library.
fn brute_winding(mesh: &TriangleMesh, q: DVec3) -> f64 {
    let v = mesh.vertices();
    let mut sum = 0.0;
    for t in mesh.triangles() {
        let [a, b, c] = t.map(|i| v[i as usize] - q);
        let (la, lb, lc) = (a.length(), b.length(), c.length());
        let num = a.dot(b.cross(c));
        let den = la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb;
        sum += 2.0 * num.atan2(den);
    }
    sum / (4.0 * std::f64::consts::PI)
}

fn brute_distance(mesh: &TriangleMesh, p: DVec3) -> f64 {
    let v = mesh.vertices();
    mesh.triangles()
        .iter()
        .map(|t| brute_triangle_distance(p, v[t[0] as usize], v[t[1] as usize], v[t[2] as usize]))
        .fold(f64::INFINITY, f64::min)
}

pub(crate) fn bunny() -> TriangleMesh {
    TriangleMesh::load(std::path::Path::new(BUNNY)).expect("bunny loads")
}

#[test]
fn bunny_loads_closed_with_known_volume() {
    let m = bunny();
    assert_eq!(m.triangle_count(), 3674);
    assert_eq!(m.vertices().len(), 1839);
    assert_eq!(m.boundary_edge_count(), 0);
    assert!(m.is_closed_manifold(), "{:?}", m.warnings());
    assert!(m.warnings().is_empty(), "{:?}", m.warnings());
    assert!((m.volume() - 46585.7).abs() < 0.5, "volume {}", m.volume());
    let b = m.bbox();
    assert!((b.max.z - 30.0).abs() < 1e-4 && (b.min.z + 30.0).abs() < 1e-4);
    assert!((b.max.x - 30.7748).abs() < 1e-3, "{b:?}");
}

#[test]
fn bunny_matches_brute_force() {
    let m = bunny();
    let region = m.bbox().expand(5.0);
    let mut rng = Rng::new(2024);
    let mut inside = 0;
    let mut maxerr: f64 = 0.0;
    for i in 0..2000 {
        let p = rng.in_box(&region);
        let exact = brute_distance(&m, p);
        let d = m.signed_distance(p);
        assert!(
            (d.abs() - exact).abs() < 1e-5,
            "point {i} {p}: {d} vs {exact}"
        );
        assert!((m.distance(p) - exact).abs() < 1e-5);
        if exact > 1e-6 {
            let w = brute_winding(&m, p);
            assert_eq!(m.is_inside(p), w > 0.5, "point {i} {p}: d {d}, w {w}");
            assert_eq!(d < 0.0, w > 0.5);
            // Hierarchical approximation (β = 2): small error, never near ½.
            let fast = m.winding_number(p);
            assert!((fast - w).abs() < 0.1, "point {i} {p}: fast {fast} vs {w}");
            maxerr = maxerr.max((fast - w).abs());
            inside += (w > 0.5) as usize;
        }
    }
    println!("largest error of the fast winding number: {maxerr:.4}");
    // The bunny fills roughly a third of its grown box: both signs occur.
    assert!(inside > 200 && inside < 1800, "{inside}");
}

#[test]
fn bunny_near_surface_signs_match_winding() {
    // Points very close to the surface stress the feature classification.
    let m = bunny();
    let mut rng = Rng::new(7);
    let v = m.vertices().to_vec();
    let tris = m.triangles().to_vec();
    for i in 0..2000 {
        let t = tris[(rng.next_u64() % tris.len() as u64) as usize];
        let (mut u, mut w) = (rng.f64(), rng.f64());
        if u + w > 1.0 {
            (u, w) = (1.0 - u, 1.0 - w);
        }
        // Some points exactly on edges and vertices.
        match i % 4 {
            0 => u = 0.0,
            1 => (u, w) = (0.0, 0.0),
            _ => {}
        }
        let s = v[t[0] as usize] * (1.0 - u - w) + v[t[1] as usize] * u + v[t[2] as usize] * w;
        let dir = DVec3::new(rng.f64() - 0.5, rng.f64() - 0.5, rng.f64() - 0.5).normalize();
        let p = s + dir * (1e-3 + rng.f64() * 0.1);
        let exact = brute_distance(&m, p);
        if exact < 1e-6 {
            continue;
        }
        let wn = brute_winding(&m, p);
        assert_eq!(m.is_inside(p), wn > 0.5, "point {i} {p}: w {wn}");
        assert!((m.signed_distance(p).abs() - exact).abs() < 1e-9);
    }
}

/// A point within `reach` (per axis, half of it) of a random point on a
/// random triangle.
fn near_surface(rng: &mut Rng, v: &[DVec3], tris: &[[u32; 3]], reach: f64) -> DVec3 {
    let t = tris[(rng.next_u64() % tris.len() as u64) as usize];
    let (u, w) = (rng.f64() * 0.5, rng.f64() * 0.5);
    let s = v[t[0] as usize] * (1.0 - u - w) + v[t[1] as usize] * u + v[t[2] as usize] * w;
    let dir = DVec3::new(rng.f64() - 0.5, rng.f64() - 0.5, rng.f64() - 0.5);
    s + dir * reach * rng.f64()
}

#[test]
fn candidate_grid_matches_the_bvh() {
    // The per-cell lists must give the nearest distance of the full BVH
    // search and the same side, near and on the surface. Bit for bit but
    // for ties: a neighbour that the certificate bits skip may tie with the
    // answer to within rounding, or be nearer by at most their tolerance
    // (10⁻¹² of the mesh box; see `certificate`).
    let m = bunny();
    let g = m
        .candidates
        .as_ref()
        .expect("the bunny gets a candidate grid");
    let mut rng = Rng::new(5);
    let region = m.bbox().expand(3.0);
    let (v, tris) = (m.vertices().to_vec(), m.triangles().to_vec());
    let (mut used, mut near, mut differ) = (0, 0, 0);
    for i in 0..20000 {
        // Half uniform in the box, half within 1 mm of a random surface point.
        let p = if i % 2 == 0 {
            rng.in_box(&region)
        } else {
            near += 1;
            near_surface(&mut rng, &v, &tris, 2.0)
        };
        let Some((slot, d2, side)) = g.nearest(&m, p) else {
            continue;
        };
        used += 1;
        let (bvh_slot, bvh_d2) = m.nearest_any(p).expect("finite point");
        let gap = (d2.sqrt() - bvh_d2.sqrt()).abs();
        assert!(
            gap <= 1e-10,
            "point {i} {p}: {d2} vs {bvh_d2}, slots {slot} vs {bvh_slot}"
        );
        differ += usize::from(d2 != bvh_d2);
        if d2 > 0.0 {
            let s = if side != 0 {
                f64::from(side)
            } else {
                m.sign_at(p, slot)
            };
            assert_eq!(s, m.sign_at(p, bvh_slot), "point {i} {p}");
        }
    }
    // The lists serve (at least) the points near the surface.
    assert!(used >= near, "{used} of {near}");
    // Rounding ties only: a handful of points, not a pattern.
    assert!(differ * 1000 < used, "{differ} of {used} differ");
}

#[test]
fn candidate_lists_are_every_triangle_within_reach() {
    // A cell's list is, by definition (see `candidates`), every triangle t
    // with d(c, t) ≤ u + 2r, u the exact distance at the cell's centre c
    // and r its half diagonal (widened by 10⁻⁹ and 10⁻¹² of the box, as
    // the build does), first a nearest one; its side is c's when u > r.
    // The build tests exactly only the triangles its block bounds let
    // through: this compares with all 3,674 at every fifth cell each way.
    let m = bunny();
    let g = m.candidates.as_ref().expect("candidate grid");
    let extent = m.bbox().size().max_element();
    let dims = g.dims();
    let (mut checked, mut sided) = (0, 0);
    for z in (0..dims[2]).step_by(5) {
        for y in (0..dims[1]).step_by(5) {
            for x in (0..dims[0]).step_by(5) {
                let (slots, side, c, r) = g.cell_list([x, y, z]);
                if slots.is_empty() {
                    continue; // far, or too many: the BVH answers
                }
                let d2: Vec<f64> = m.tris.iter().map(|t| t.distance_squared(c)).collect();
                let (mut u2, mut near) = (f64::INFINITY, 0);
                for (i, &d) in d2.iter().enumerate() {
                    if d < u2 {
                        (u2, near) = (d, i);
                    }
                }
                let u = u2.sqrt();
                let reach = (u + 2.0 * r) * (1.0 + 1e-9) + 1e-12 * extent;
                let want: Vec<u32> = (0u32..)
                    .zip(&d2)
                    .filter(|(_, d)| **d <= reach * reach)
                    .map(|(i, _)| i)
                    .collect();
                let mut got = slots.clone();
                got.sort_unstable();
                assert_eq!(got, want, "cell {x} {y} {z}");
                let first = d2[slots[0] as usize].sqrt();
                assert!(
                    first - u <= 1e-6 * (1.0 + u),
                    "cell {x} {y} {z}: {first} {u}"
                );
                if u > r * (1.0 + 1e-9) {
                    assert_eq!(f64::from(side), m.sign_at(c, near), "cell {x} {y} {z}");
                    sided += 1;
                } else {
                    assert_eq!(side, 0, "cell {x} {y} {z}");
                }
                checked += 1;
            }
        }
    }
    assert!(checked > 1000 && sided > 500, "{checked} {sided}");
}

#[test]
fn contains_agrees_with_the_signed_distance() {
    // `contains` answers from the cell's side where it can; it must say
    // what the exact signed distance says, near the surface and far.
    let m = bunny();
    let g = m.candidates.as_ref().expect("candidate grid");
    let mut rng = Rng::new(11);
    let region = m.bbox().expand(2.0);
    let (v, tris) = (m.vertices().to_vec(), m.triangles().to_vec());
    let (mut by_side, mut inside) = (0, 0);
    for i in 0..20000 {
        let p = if i % 4 == 0 {
            rng.in_box(&region)
        } else {
            near_surface(&mut rng, &v, &tris, 3.0)
        };
        let exact = m.signed_distance(p);
        assert_eq!(m.contains(p), exact <= 0.0, "point {i} {p}: {exact}");
        by_side += usize::from(g.side(p).is_some());
        inside += usize::from(exact <= 0.0);
    }
    // Both sides occur, and the side answers a good share (2,885 here).
    assert!(inside > 2000 && inside < 18000, "{inside}");
    assert!(by_side > 1500, "{by_side}");
    assert!(!m.contains(DVec3::NAN));
}

/// Cube [-1, 1]³ as 12 outward triangles; `skip` drops the two triangles of
/// face `skip` (0..6).
pub(crate) fn cube(skip: Option<usize>) -> (Vec<DVec3>, Vec<[u32; 3]>) {
    let vertices: Vec<DVec3> = (0..8)
        .map(|i| {
            let s = |bit: u32| if i & bit != 0 { 1.0 } else { -1.0 };
            DVec3::new(s(1), s(2), s(4))
        })
        .collect();
    let mut triangles = Vec::new();
    for (face, (axis, side)) in [(0, 0), (0, 1), (1, 0), (1, 1), (2, 0), (2, 1)]
        .into_iter()
        .enumerate()
    {
        if skip == Some(face) {
            continue;
        }
        let bit = 1u32 << axis;
        let others: Vec<u32> = (0..3).filter(|&a| a != axis).map(|a| 1 << a).collect();
        let base = if side == 1 { bit } else { 0 };
        let q = [
            base,
            base | others[0],
            base | others[0] | others[1],
            base | others[1],
        ];
        for mut t in [[q[0], q[1], q[2]], [q[0], q[2], q[3]]] {
            let [a, b, c] = t.map(|i| vertices[i as usize]);
            if (b - a).cross(c - a).dot(a + b + c) < 0.0 {
                t.swap(1, 2);
            }
            triangles.push(t);
        }
    }
    (vertices, triangles)
}

#[test]
fn cube_known_distances() {
    let (v, t) = cube(None);
    let m = TriangleMesh::from_triangles(v, t).unwrap();
    assert!(m.is_closed_manifold());
    assert!((m.volume() - 8.0).abs() < 1e-12);
    let cases = [
        (DVec3::ZERO, -1.0),
        (DVec3::new(0.5, 0.2, 0.1), -0.5),
        (DVec3::new(0.9, 0.95, -0.2), -0.05),
        (DVec3::new(2.0, 0.0, 0.0), 1.0),
        (DVec3::new(0.3, -3.0, 0.2), 2.0),
        (DVec3::new(2.0, 2.0, 0.0), 2f64.sqrt()),
        (DVec3::new(2.0, 2.0, 2.0), 3f64.sqrt()),
        (DVec3::new(-2.0, 2.0, -3.0), 6f64.sqrt()),
        (DVec3::new(1.0, 1.0, 1.0), 0.0),
        (DVec3::new(1.0, 0.0, 0.0), 0.0),
    ];
    for (p, expected) in cases {
        let d = m.signed_distance(p);
        assert!((d - expected).abs() < 1e-12, "{p}: {d} vs {expected}");
    }
    assert!(m.is_inside(DVec3::splat(0.99)));
    assert!(!m.is_inside(DVec3::splat(1.01)));
    assert!((m.winding_number(DVec3::ZERO) - 1.0).abs() < 1e-12);
    assert!(m.winding_number(DVec3::splat(5.0)).abs() < 1e-3);
    let (c, _) = m.closest_point(DVec3::new(3.0, 0.5, 0.0)).unwrap();
    assert!((c - DVec3::new(1.0, 0.5, 0.0)).length() < 1e-12);
}

#[test]
fn inside_out_cube_is_flipped() {
    let (v, mut t) = cube(None);
    for tri in &mut t {
        tri.swap(0, 1);
    }
    let m = TriangleMesh::from_triangles(v, t).unwrap();
    assert!(m.warnings().iter().any(|w| w.contains("inside out")));
    assert!((m.signed_distance(DVec3::ZERO) + 1.0).abs() < 1e-12);
}

#[test]
fn open_cube_uses_winding_number() {
    let (v, t) = cube(Some(5));
    let m = TriangleMesh::from_triangles(v, t).unwrap();
    assert_eq!(m.triangle_count(), 10);
    assert_eq!(m.boundary_edge_count(), 4);
    assert!(!m.is_closed_manifold());
    assert!(
        m.warnings()
            .iter()
            .any(|w| w == "mesh is not closed: 4 boundary edges"),
        "{:?}",
        m.warnings()
    );
    let w = m.winding_number(DVec3::ZERO);
    assert!((w - 5.0 / 6.0).abs() < 1e-9, "{w}");
    assert!(m.is_inside(DVec3::ZERO));
    assert!((m.signed_distance(DVec3::ZERO) + 1.0).abs() < 1e-12);
    assert!(!m.is_inside(DVec3::new(0.0, 0.0, 3.0)));
    assert!(!m.is_inside(DVec3::new(3.0, 0.0, 0.0)));
}

#[test]
fn from_triangles_rejects_bad_input() {
    let (v, _) = cube(None);
    assert!(matches!(
        TriangleMesh::from_triangles(v.clone(), vec![]),
        Err(MeshError::NoTriangles)
    ));
    let e = TriangleMesh::from_triangles(v.clone(), vec![[0, 1, 8]]).unwrap_err();
    assert!(
        matches!(
            e,
            MeshError::BadIndex {
                triangle: 0,
                index: 8,
                ..
            }
        ),
        "{e}"
    );
    let mut bad = v;
    bad[2].y = f64::NAN;
    let e = TriangleMesh::from_triangles(bad, vec![[0, 1, 2]]).unwrap_err();
    assert!(
        matches!(e, MeshError::NonFiniteVertex { index: 2, .. }),
        "{e}"
    );
}

#[test]
fn degenerate_triangle_falls_back_to_winding() {
    let (mut v, mut t) = cube(None);
    // A sliver on top of face +z: its vertex lies in the face.
    v.push(DVec3::new(0.0, 0.0, 1.0));
    t.push([0, 1, 8]);
    let m = TriangleMesh::from_triangles(v, t).unwrap();
    assert!(!m.is_closed_manifold());
    assert!(m.is_inside(DVec3::new(0.1, 0.2, 0.3)));
    assert!(!m.is_inside(DVec3::new(0.1, 0.2, 1.3)));
}

/// CPU time of this thread in seconds (Linux `/proc`, 10 ms resolution),
/// so throughput numbers hold on a busy machine; `None` elsewhere.
pub(crate) fn thread_cpu_seconds() -> Option<f64> {
    let s = std::fs::read_to_string("/proc/thread-self/stat").ok()?;
    let f: Vec<&str> = s.rsplit(')').next()?.split_whitespace().collect();
    let ticks = f.get(11)?.parse::<f64>().ok()? + f.get(12)?.parse::<f64>().ok()?;
    Some(ticks / 100.0)
}

/// Runs `f` over `pts` and prints points per second (wall and CPU time).
pub(crate) fn throughput(label: &str, pts: &[DVec3], mut f: impl FnMut(DVec3) -> f64) {
    let (t0, c0) = (std::time::Instant::now(), thread_cpu_seconds());
    let mut acc = 0.0;
    for &p in pts {
        acc += f(p);
    }
    let wall = t0.elapsed().as_secs_f64();
    let cpu = thread_cpu_seconds().zip(c0).map(|(b, a)| b - a);
    let m = pts.len() as f64 / 1e6;
    println!(
        "{label}: {} points, {:.2} M/s wall, {} (1 thread) [{acc:.1}]",
        pts.len(),
        m / wall,
        cpu.filter(|&c| c > 0.0)
            .map_or("no CPU time".into(), |c| format!(
                "{:.2} M/s CPU time",
                m / c
            )),
    );
}

/// A unique temporary file path.
pub(crate) fn temp_path(name: &str) -> PathBuf {
    use std::sync::atomic::{AtomicU32, Ordering};
    static N: AtomicU32 = AtomicU32::new(0);
    std::env::temp_dir().join(format!(
        "volcad_mesh_{}_{}_{name}",
        std::process::id(),
        N.fetch_add(1, Ordering::Relaxed)
    ))
}

#[test]
fn stl_ascii_and_binary_load_and_weld() {
    let (v, t) = cube(None);
    let a = temp_path("cube_ascii.stl");
    let b = temp_path("cube_binary.STL");
    std::fs::write(&a, writers::stl_ascii(&v, &t)).unwrap();
    std::fs::write(&b, writers::stl_binary(&v, &t)).unwrap();
    for path in [&a, &b] {
        let m = TriangleMesh::load(path).unwrap();
        assert_eq!(m.triangle_count(), 12);
        assert_eq!(m.vertices().len(), 8, "welded");
        assert_eq!(m.boundary_edge_count(), 0);
        assert!(m.is_closed_manifold());
        assert!((m.signed_distance(DVec3::new(0.0, 0.0, 3.0)) - 2.0).abs() < 1e-12);
        assert!((m.signed_distance(DVec3::ZERO) + 1.0).abs() < 1e-12);
    }
    // Open cube as STL: boundary edges are counted after welding.
    let (v, t) = cube(Some(0));
    std::fs::write(&a, writers::stl_ascii(&v, &t)).unwrap();
    let m = TriangleMesh::load(&a).unwrap();
    assert_eq!(m.boundary_edge_count(), 4);
    assert!(m.is_inside(DVec3::ZERO));
    for p in [a, b] {
        let _ = std::fs::remove_file(p);
    }
}

#[test]
fn broken_files_report_line_or_size() {
    let (v, t) = cube(None);
    let path = temp_path("broken.stl");
    let text = writers::stl_ascii(&v, &t).replacen("vertex -1 -1 -1", "vertex -1 abc -1", 1);
    let line = text.lines().position(|l| l.contains("abc")).unwrap() + 1;
    let col = text.lines().nth(line - 1).unwrap().find("abc").unwrap() + 1;
    std::fs::write(&path, &text).unwrap();
    let e = TriangleMesh::load(&path).unwrap_err();
    match &e {
        MeshError::Parse {
            line: l,
            column,
            msg,
            ..
        } => {
            assert_eq!((*l, *column), (line, col));
            assert_eq!(msg, "`abc` is not a number");
        }
        other => panic!("{other}"),
    }
    assert!(
        e.to_string().contains(&format!("broken.stl:{line}:")),
        "{e}"
    );

    let mut bin = writers::stl_binary(&v, &t);
    bin.truncate(bin.len() - 7);
    std::fs::write(&path, &bin).unwrap();
    let e = TriangleMesh::load(&path).unwrap_err();
    assert!(matches!(e, MeshError::BinaryStl { .. }), "{e}");
    assert!(e.to_string().contains("announces 12 triangles"), "{e}");

    std::fs::write(&path, "solid empty\nendsolid empty\n").unwrap();
    assert!(matches!(
        TriangleMesh::load(&path),
        Err(MeshError::Empty { .. })
    ));
    let _ = std::fs::remove_file(&path);

    let obj = temp_path("broken.obj");
    std::fs::write(&obj, "v 0 0 0\nv 1 0 0\nv 0 1 x\nf 1 2 3\n").unwrap();
    let e = TriangleMesh::load(&obj).unwrap_err();
    assert!(matches!(e, MeshError::Parse { line: 3, .. }), "{e}");
    std::fs::write(&obj, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n").unwrap();
    let e = TriangleMesh::load(&obj).unwrap_err();
    assert!(matches!(e, MeshError::Parse { line: 4, .. }), "{e}");
    let _ = std::fs::remove_file(&obj);

    let e = TriangleMesh::load(&temp_path("missing.obj")).unwrap_err();
    assert!(matches!(e, MeshError::Io { .. }), "{e}");
    // Binary bytes of no format, whatever the name says.
    let junk = temp_path("mesh.ply");
    std::fs::write(&junk, [0u8, 1, 2, 3, 0xff, 0xfe, 7, 0]).unwrap();
    let e = TriangleMesh::load(&junk).unwrap_err();
    assert!(matches!(e, MeshError::UnknownFormat { .. }), "{e}");
    let _ = std::fs::remove_file(&junk);
}

/// Throughput of `signed_distance` on the bunny for points within 2 mm of
/// the surface (release build):
/// `cargo test -p volcad-core --release --lib trimesh::tests::perf -- --ignored --nocapture`
#[test]
#[ignore]
fn perf_bunny_band() {
    // Build time: load, weld, BVH, winding tree, coarse and candidate grids.
    let t = std::time::Instant::now();
    let m = bunny();
    println!(
        "bunny load and build ({} triangles, all threads): {:.3} s",
        m.triangle_count(),
        t.elapsed().as_secs_f64()
    );
    let mut rng = Rng::new(1);
    let v = m.vertices().to_vec();
    let tris = m.triangles().to_vec();
    let random: Vec<DVec3> = (0..1_000_000)
        .map(|_| {
            let t = tris[(rng.next_u64() % tris.len() as u64) as usize];
            let (mut u, mut w) = (rng.f64(), rng.f64());
            if u + w > 1.0 {
                (u, w) = (1.0 - u, 1.0 - w);
            }
            let s = v[t[0] as usize] * (1.0 - u - w) + v[t[1] as usize] * u + v[t[2] as usize] * w;
            let dir =
                DVec3::new(rng.f64() - 0.5, rng.f64() - 0.5, rng.f64() - 0.5).normalize_or_zero();
            s + dir * (2.0 * rng.f64())
        })
        .collect();
    // Grid points in scan order (what a sampler does), kept if |d| < 2.
    let b = m.bbox().expand(2.0);
    let h = 0.25;
    let mut grid = Vec::new();
    let n = ((b.max - b.min) / h).ceil().as_uvec3();
    for k in 0..n.z {
        for j in 0..n.y {
            for i in 0..n.x {
                let p = b.min + DVec3::new(i as f64, j as f64, k as f64) * h;
                if m.signed_distance_bound(p, 2.0).abs() < 2.0 {
                    grid.push(p);
                }
            }
        }
    }
    for (name, pts) in [("random band", &random), ("grid band", &grid)] {
        throughput(&format!("bunny signed_distance, {name}"), pts, |p| {
            m.signed_distance(p)
        });
        throughput(
            &format!("bunny signed_distance_bound(1 mm), {name}"),
            pts,
            |p| m.signed_distance_bound(p, 1.0),
        );
    }
    let inbox: Vec<DVec3> = (0..200_000).map(|_| rng.in_box(&m.bbox())).collect();
    throughput("bunny winding_number, uniform in bbox", &inbox, |p| {
        m.winding_number(p)
    });
    throughput("bunny signed_distance, uniform in bbox", &inbox, |p| {
        m.signed_distance(p)
    });
    throughput(
        "bunny signed_distance_bound(1 mm), uniform in bbox",
        &inbox,
        |p| m.signed_distance_bound(p, 1.0),
    );
}
