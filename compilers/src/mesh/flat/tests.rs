use std::collections::HashSet;

use glam::DVec3;
use volcad_core::sampler::Grid;

use super::super::contour::{Contourer, Plane};
use super::super::field::{border_void, contour_field};
use super::super::indexed::{IndexedMesh, tri_set};
use super::super::interface::{Cube, Interface};
use super::{FlatKey, FlatMemo, KeptCubes, KeyId, Regions, flat_key};

/// A 24³ grid of 0.5 mm voxels sampling `f`.
fn sample(f: impl Fn(DVec3) -> f64) -> (Grid, Vec<f32>) {
    let grid = Grid {
        origin: DVec3::splat(-6.0),
        voxel: DVec3::splat(0.5),
        dims: [24, 24, 24],
    };
    let mut v = Vec::new();
    for k in 0..24 {
        for j in 0..24 {
            for i in 0..24 {
                v.push(f(grid.center(i, j, k)) as f32);
            }
        }
    }
    (grid, v)
}

/// Meshes merged, unmerged and through the fallback.
fn three(f: impl Fn(DVec3) -> f64) -> [IndexedMesh; 3] {
    let (g, v) = sample(f);
    let c = || Contourer::new(g, 1, Interface::Midpoint);
    [
        contour_field(c(), &g, &v),
        contour_field(c().with_flat_merge(false), &g, &v),
        contour_field(c().with_fallback_only(), &g, &v),
    ]
}

fn box_sdf(p: DVec3, half: DVec3) -> f64 {
    ((p - DVec3::new(0.1, -0.2, 0.15)).abs() - half).max_element()
}

fn check(f: impl Fn(DVec3) -> f64) -> [IndexedMesh; 3] {
    let [merged, plain, fallback] = three(f);
    for m in [&merged, &plain, &fallback] {
        assert!(m.is_watertight(), "{:?}", m.edge_report());
    }
    let (vm, vp) = (merged.volume(), plain.volume());
    assert!((vm - vp).abs() < 1e-5 * vp, "{vm} vs {vp}");
    // Merging drops points: every vertex is a marching point, but for
    // the few added beside the point clusters of faces through samples.
    let points: HashSet<[u32; 3]> = plain.vertices.iter().map(|v| v.map(f32::to_bits)).collect();
    let added = merged
        .vertices
        .iter()
        .filter(|v| !points.contains(&v.map(f32::to_bits)))
        .count();
    assert!(
        added * 4 < plain.vertices.len(),
        "{added} added, {} marching points",
        plain.vertices.len()
    );
    // The fallback is marching tetrahedra, triangle for triangle.
    assert_eq!(tri_set(&fallback), tri_set(&plain));
    [merged, plain, fallback]
}

#[test]
fn a_box_merges_into_few_triangles_with_the_same_surface() {
    let half = DVec3::new(3.3, 2.7, 4.1);
    let [merged, plain, _] = check(|p| box_sdf(p, half));
    let exact = 8.0 * half.x * half.y * half.z;
    assert!(
        (merged.volume() - exact).abs() < 0.02 * exact,
        "{}",
        merged.volume()
    );
    assert!(
        merged.triangles.len() * 2 < plain.triangles.len(),
        "{} vs {}",
        merged.triangles.len(),
        plain.triangles.len()
    );
}

#[test]
fn faces_through_samples_merge_too() {
    // Faces at x = −2.75 and 3.25 (and y, z alike) pass through sample
    // centres: g = 0 there, and the clamp keeps the points flat. The
    // points cluster around the samples on each face's rim, so each
    // face gets a point inside beside every cluster (no needles).
    let [merged, plain, _] = check(|p| (p - DVec3::splat(0.25)).abs().max_element() - 3.0);
    assert!(
        merged.triangles.len() * 2 < plain.triangles.len(),
        "{} vs {}",
        merged.triangles.len(),
        plain.triangles.len()
    );
}

#[test]
fn tilted_planes_and_holes_stay_closed() {
    // A box cut by an oblique plane, with a round hole through it: the
    // oblique face is one region, the top face a region with a hole.
    let n = DVec3::new(1.0, 2.0, 3.0).normalize();
    let [merged, plain, _] = check(|p| {
        let hole = 1.5 - (p.x * p.x + p.y * p.y).sqrt();
        box_sdf(p, DVec3::new(4.2, 4.4, 4.3))
            .max(n.dot(p) - 2.1)
            .max(hole)
    });
    assert!(merged.triangles.len() < plain.triangles.len());
}

/// A box split where a value crosses 0.5 into two segments (fraction
/// ranges with n = 2, or the dominant of two materials `f` and
/// `1 − f`): meshes merged, unmerged and through the fallback, each
/// checked closed, with the same volumes, and the fallback's triangles
/// the unmerged ones.
fn two_segments(iface: Interface) -> [Vec<IndexedMesh>; 3] {
    let (g, dist) = sample(|p| box_sdf(p, DVec3::new(4.1, 3.9, 4.4)));
    let value = |p: DVec3| (0.5 + 0.04 * (p.x + 0.5 * p.y - 0.37)) as f32;
    let run = |mut c: Contourer| {
        let [nx, ny, nz] = g.dims;
        for z in 0..nz {
            let d = dist[z * nx * ny..(z + 1) * nx * ny].to_vec();
            let f: Vec<f32> = (0..nx * ny)
                .map(|i| value(g.center(i % nx, i / nx, z)))
                .collect();
            let label = border_void(&d, [nx, ny, nz], z, |_| 1)
                .iter()
                .zip(d.iter().zip(&f))
                .map(|(l, (d, f))| match iface {
                    _ if *l == 0 || *d > 0.0 => 0,
                    // Range [0.5, 1] is segment 2; a tie goes to slot 0.
                    Interface::Dominant { .. } => 1 + u16::from(*f < 0.5),
                    _ => 1 + u16::from(*f >= 0.5),
                })
                .collect();
            let value = match iface {
                Interface::Dominant { .. } => f.iter().flat_map(|f| [*f, 1.0 - f]).collect(),
                _ => f,
            };
            c.push_plane(
                z,
                Plane {
                    label,
                    dist: d.into(),
                    value,
                    bits: Vec::new(),
                },
                &|[i, j, k]| dist[(k * ny + j) * nx + i],
            );
        }
        // Samples again, as the planes had them.
        c.finish(&|[i, j, k], out| {
            let f = value(g.center(i, j, k));
            match iface {
                Interface::Dominant { .. } => out.copy_from_slice(&[f, 1.0 - f]),
                _ => out[0] = f,
            }
            dist[(k * nx * ny) + j * nx + i]
        })
    };
    let c = || Contourer::new(g, 2, iface);
    let [merged, plain, fallback] = [
        run(c()),
        run(c().with_flat_merge(false)),
        run(c().with_fallback_only()),
    ];
    for s in 0..2 {
        for m in [&merged[s], &plain[s], &fallback[s]] {
            assert!(m.is_watertight(), "{s}: {:?}", m.edge_report());
        }
        let (vm, vp) = (merged[s].volume(), plain[s].volume());
        assert!((vm - vp).abs() < 1e-5 * vp, "{s}: {vm} vs {vp}");
        assert_eq!(tri_set(&fallback[s]), tri_set(&plain[s]));
        // The tilted interface passes through samples: the contourer's
        // clamp (`T_MIN`) moves the points around them off its plane,
        // and regions whose projected outline then crosses itself fall
        // back to marching tetrahedra; the box's faces still merge.
        assert!(merged[s].triangles.len() < plain[s].triangles.len());
    }
    [merged, plain, fallback]
}

#[test]
fn two_segments_share_their_merged_interface() {
    let [merged, _, _] = two_segments(Interface::Ranges { n: 2 });
    // The interface: triangles of 1 whose reverse 2 has.
    let two: HashSet<[[u32; 3]; 3]> = tri_set(&merged[1]).into_iter().collect();
    let shared = tri_set(&merged[0])
        .into_iter()
        .filter(|[a, b, c]| {
            let r = [*a, *c, *b];
            let k = (0..3).min_by_key(|i| r[*i]).unwrap_or(0);
            two.contains(&[r[k], r[(k + 1) % 3], r[(k + 2) % 3]])
        })
        .count();
    assert!(shared > 0);
}

#[test]
fn dominant_materials_fall_back_like_plain_contouring() {
    // Two interface values a sample, both kept for the fallback; the
    // checks are in `two_segments`.
    two_segments(Interface::Dominant { k: 2 });
}

#[test]
fn keys_are_interned_in_order_of_first_use() {
    let key = |x, normal| FlatKey { x, y: 0, normal };
    let (a, b, c) = (
        key(1, [0, 0, 1024]),
        key(1, [0, 0, -1024]),
        key(2, [0, 0, 1024]),
    );
    let mut r = Regions::new(0);
    let kept = |n| {
        let mut k = KeptCubes::with_capacity(n, [4, 4, 4]);
        (0..n).for_each(|i| k.push([i % 3, 1, 2], i as u8));
        k
    };
    assert_eq!(r.add_band([a, a, b, a].into_iter(), kept(4)), 0);
    assert_eq!(r.add_band([c, b].into_iter(), kept(2)), 4);
    let ids: Vec<KeyId> = (0..6).map(|i| r.key_id(i)).collect();
    assert_eq!(ids, [0, 0, 1, 0, 2, 1]);
    let keys: Vec<FlatKey> = (0..6).map(|i| r.key(i)).collect();
    assert_eq!(keys, [a, a, b, a, c, b]);
    // Kept places and masks come back as pushed.
    let k = kept(4);
    assert_eq!(k.get(2), ([2, 1, 2], 2));
    assert_eq!(k.get(3), ([0, 1, 2], 3));
}

#[test]
fn curved_surfaces_keep_their_points() {
    // Only single cubes whose eight samples happen to be affine merge
    // here (same points, fewer triangles); `check` compares the rest.
    let [merged, plain, _] = check(|p| p.length() - 4.7);
    assert!(merged.triangles.len() <= plain.triangles.len());
    assert!(merged.vertices.len() <= plain.vertices.len());
}

/// The memo answers exactly as `flat_key`: for repeated and alternating
/// cubes, for the same distances under other labels, and for cubes
/// between two segments (never memoised: their values count).
#[test]
fn the_flat_memo_answers_as_flat_key() {
    let voxel = DVec3::splat(0.1);
    let iface = Interface::Dominant { k: 2 };
    let plane_z = |c: usize, off: f32| if c & 4 == 0 { -0.03 + off } else { 0.07 + off };
    let plane_x = |c: usize| if c & 1 == 0 { 0.02 } else { -0.08 };
    let bent = |c: usize| [0.05, -0.05, 0.04, -0.06, 0.05, -0.05, 0.04, -0.02][c];
    let cube = |label: [u16; 8], dist: [f32; 8], v: &'static [[f32; 2]; 8]| Cube {
        base: [0, 0, 0],
        label,
        dist,
        value: std::array::from_fn(|c| &v[c][..]),
    };
    let lz = |x: u16| std::array::from_fn(|c| if c & 4 == 0 { x } else { 0 });
    let lx = |x: u16| std::array::from_fn(|c| if c & 1 == 0 { 0 } else { x });
    static V: [[f32; 2]; 8] = [[0.9, 0.1]; 8];
    static W: [[f32; 2]; 8] = [[0.2, 0.8]; 8];
    let two: [u16; 8] = std::array::from_fn(|c| if c & 1 == 0 { 1 } else { 2 });
    let cubes = [
        cube(lz(1), std::array::from_fn(|c| plane_z(c, 0.0)), &V),
        cube(lx(1), std::array::from_fn(plane_x), &V),
        cube(lz(1), std::array::from_fn(|c| plane_z(c, 0.0)), &V),
        cube(lx(1), std::array::from_fn(plane_x), &V),
        // Same distances, another label: another key.
        cube(lz(2), std::array::from_fn(|c| plane_z(c, 0.0)), &V),
        cube(lz(1), std::array::from_fn(|c| plane_z(c, 0.01)), &V),
        // Not flat: the memo keeps `None` too.
        cube(lx(1), std::array::from_fn(bent), &V),
        cube(lx(1), std::array::from_fn(bent), &V),
        // Between two segments the memo is not asked (values count).
        cube(two, [-0.1; 8], &V),
        cube(two, [-0.1; 8], &W),
    ];
    let mut memo = FlatMemo::default();
    let keys: Vec<Option<FlatKey>> = cubes
        .iter()
        .map(|c| {
            let k = memo.key(voxel, iface, c);
            assert_eq!(k, flat_key(voxel, iface, c));
            k
        })
        .collect();
    assert!(keys[0].is_some() && keys[1].is_some() && keys[0] != keys[1]);
    assert!(keys[4].is_some() && keys[4] != keys[0]);
    assert_eq!(keys[6], None);
}
