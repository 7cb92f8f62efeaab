//! Segmented meshes end to end: watertight meshes with analytic volumes,
//! segments that cover the part once with shared interfaces, the 3MF
//! structure, deterministic bytes, cancel and bad input.

// A failed setup step (a scratch folder, a file read) fails the test.
#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use std::collections::HashMap;
use std::io::{Cursor, Read};
use std::sync::Arc;
use std::sync::atomic::AtomicBool;

use common::{manifest, model, read_tree, run, tmp};
use glam::DVec3;
use volcad_compilers::ExportError;
use volcad_compilers::mesh::{
    IndexedMesh, MeshFormats, MeshParams, SegmentBy, SegmentMesh, estimate_mesh, export_meshes,
    marching_cubes, segment_meshes,
};
use volcad_core::Model;
use volcad_core::sampler::Grid;

const GRADED_BAR: &str = r#"let m = default_materials();
FGrade(["x/20+0.5", "-x/20+0.5"], [m.id("red"), m.id("blue")], true, RectPrism(Vec3(0,0,0), Vec3(20,10,5), m.id("gray")))"#;
const RED: u8 = 1;

fn params(voxel: f64, segments: usize, by: SegmentBy) -> MeshParams {
    MeshParams {
        voxel: DVec3::splat(voxel),
        segments,
        by,
        ..MeshParams::default()
    }
}

fn meshes(m: &Model, p: &MeshParams) -> Vec<SegmentMesh> {
    segment_meshes(m, p, &AtomicBool::new(false), |_, _| {}).unwrap()
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

#[test]
fn sphere_and_box_are_watertight_with_analytic_volume() {
    let sphere = model(r#"let m = default_materials(); Sphere(Vec3(0,0,0), 10, m.id("red"))"#);
    let s = meshes(&sphere, &params(0.2, 1, SegmentBy::Material(RED)));
    assert_eq!(s.len(), 1);
    let v = 4.0 / 3.0 * std::f64::consts::PI * 1000.0;
    assert!(s[0].mesh.is_watertight(), "{:?}", s[0].mesh.edge_report());
    assert!(
        rel(s[0].mesh.volume(), v) < 0.01,
        "sphere {} vs {v}",
        s[0].mesh.volume()
    );
    let bx =
        model(r#"let m = default_materials(); RectPrism(Vec3(1,2,3), Vec3(20,10,5), m.id("red"))"#);
    let s = meshes(&bx, &params(0.25, 1, SegmentBy::Dominant));
    assert!(s[0].mesh.is_watertight(), "{:?}", s[0].mesh.edge_report());
    assert!(
        rel(s[0].mesh.volume(), 1000.0) < 0.01,
        "box {}",
        s[0].mesh.volume()
    );
}

#[test]
fn marching_cubes_of_an_analytic_field() {
    let grid = Grid::covering(
        &volcad_core::Aabb::new(DVec3::splat(-6.0), DVec3::splat(6.0)),
        DVec3::splat(0.25),
        1 << 30,
    )
    .unwrap();
    let [nx, ny, nz] = grid.dims;
    let mut values = Vec::with_capacity(nx * ny * nz);
    for k in 0..nz {
        for j in 0..ny {
            for i in 0..nx {
                values.push((grid.center(i, j, k).length() - 5.0) as f32);
            }
        }
    }
    let m = marching_cubes(&grid, &values);
    assert!(m.is_watertight(), "{:?}", m.edge_report());
    let v = 4.0 / 3.0 * std::f64::consts::PI * 125.0;
    assert!(rel(m.volume(), v) < 0.01, "{} vs {v}", m.volume());
    assert!(
        rel(m.area(), 4.0 * std::f64::consts::PI * 25.0) < 0.02,
        "area {}",
        m.area()
    );
}

#[test]
fn marching_cubes_of_noise_is_closed_with_every_case() {
    // Independent random samples meet every one of the 256 cube cases and
    // both ambiguous faces many times over: the one-label contour must
    // still close (every edge in two triangles, opposite directions), with
    // flat merging on and off.
    let grid = Grid::covering(
        &volcad_core::Aabb::new(DVec3::splat(0.0), DVec3::splat(6.0)),
        DVec3::splat(0.25),
        1 << 30,
    )
    .unwrap();
    let [nx, ny, nz] = grid.dims;
    let mut state = 0x9e37_79b9_7f4a_7c15u64;
    let values: Vec<f32> = (0..nx * ny * nz)
        .map(|_| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 40) as f32 / (1u64 << 24) as f32 - 0.45
        })
        .collect();
    let m = marching_cubes(&grid, &values);
    assert!(m.is_watertight(), "{:?}", m.edge_report());
    assert!(m.volume() > 0.0, "outward: volume {}", m.volume());
    let (angle, _) = m.shape();
    assert!(angle > 0.0, "smallest angle {angle}");
}

/// Triangle key by positions, rotation-independent (starts at the smallest
/// corner), orientation kept.
fn tri_key(p: [[f32; 3]; 3]) -> [u32; 9] {
    let bits = p.map(|v| v.map(f32::to_bits));
    let i = (0..3).min_by_key(|i| bits[*i]).unwrap();
    let r = [bits[i], bits[(i + 1) % 3], bits[(i + 2) % 3]];
    [
        r[0][0], r[0][1], r[0][2], r[1][0], r[1][1], r[1][2], r[2][0], r[2][1], r[2][2],
    ]
}

fn positions(m: &IndexedMesh, t: usize) -> [[f32; 3]; 3] {
    m.triangles[t].map(|i| m.vertices[i as usize])
}

/// Checks that segments cover the part once: no triangle twice, every
/// triangle either an interface (its reverse is in another segment) or on
/// the outer surface, and the outer surface alone is closed with the
/// segments' total volume. Returns that volume.
fn check_cover(segs: &[SegmentMesh]) -> f64 {
    let mut owner: HashMap<[u32; 9], usize> = HashMap::new();
    for (s, seg) in segs.iter().enumerate() {
        common::assert_closed(seg);
        for t in 0..seg.mesh.triangles.len() {
            assert!(
                owner.insert(tri_key(positions(&seg.mesh, t)), s).is_none(),
                "{}: triangle repeated",
                seg.name
            );
        }
    }
    // The outer surface: triangles whose reverse no other segment has.
    let mut outer = IndexedMesh::default();
    let mut index: HashMap<[u32; 3], u32> = HashMap::new();
    let mut interface = 0;
    for (s, seg) in segs.iter().enumerate() {
        for t in 0..seg.mesh.triangles.len() {
            let p = positions(&seg.mesh, t);
            match owner.get(&tri_key([p[0], p[2], p[1]])) {
                Some(o) => {
                    assert_ne!(*o, s, "{}: a triangle and its reverse", seg.name);
                    interface += 1;
                }
                None => {
                    let idx = p.map(|v| {
                        *index.entry(v.map(f32::to_bits)).or_insert_with(|| {
                            outer.vertices.push(v);
                            (outer.vertices.len() - 1) as u32
                        })
                    });
                    outer.triangles.push(idx);
                }
            }
        }
    }
    assert!(
        segs.iter().filter(|s| !s.mesh.is_empty()).count() < 2 || interface > 0,
        "segments share no interface"
    );
    assert!(
        outer.is_watertight(),
        "outer surface: {:?}",
        outer.edge_report()
    );
    let total: f64 = segs.iter().map(|s| s.mesh.volume()).sum();
    assert!(
        rel(outer.volume(), total) < 1e-6,
        "outer {} vs segments {total}",
        outer.volume()
    );
    total
}

#[test]
fn fraction_segments_cover_the_part_once_with_analytic_volumes() {
    let m = model(GRADED_BAR);
    let whole = meshes(&m, &params(0.25, 1, SegmentBy::Material(RED)));
    let segs = meshes(&m, &params(0.25, 4, SegmentBy::Material(RED)));
    assert_eq!(segs.len(), 4);
    let total = check_cover(&segs);
    assert!(
        rel(total, whole[0].mesh.volume()) < 0.002,
        "segments {total} vs whole {}",
        whole[0].mesh.volume()
    );
    assert!(rel(total, 1000.0) < 0.01, "{total}");
    // red = x/20 + 0.5: the range boundaries are the planes x = -5, 0, 5.
    for s in &segs {
        assert!(
            rel(s.mesh.volume(), 250.0) < 0.01,
            "{}: {}",
            s.name,
            s.mesh.volume()
        );
    }
    assert_eq!(segs[0].name, "seg00_red_0.000-0.250");
    assert_eq!(
        segs.iter().map(|s| s.infill_percent).collect::<Vec<_>>(),
        [20.0, 40.0, 60.0, 80.0]
    );
    // The other material splits the same bar mirrored.
    let blue = meshes(&m, &params(0.25, 4, SegmentBy::Material(3)));
    assert!(rel(blue[0].mesh.volume(), segs[3].mesh.volume()) < 1e-3);
}

#[test]
fn thin_segments_and_dominant_materials_stay_watertight() {
    // 40 ranges on a 20 mm bar at 0.5 mm voxels: segments one voxel thick,
    // so tets with void and up to three segments are everywhere.
    let m = model(GRADED_BAR);
    let segs = meshes(&m, &params(0.5, 40, SegmentBy::Material(RED)));
    let total = check_cover(&segs);
    assert!(rel(total, 1000.0) < 0.02, "{total}");
    // Three materials meeting along lines, by dominant material.
    let three = model(
        r#"let m = default_materials();
FGrade(["x/20+0.4", "-x/20+0.4", "0.2 + y/10"], [m.id("red"), m.id("blue"), m.id("green")], true, Sphere(Vec3(0,0,0), 8, m.id("gray")))"#,
    );
    let segs = meshes(&three, &params(0.3, 0, SegmentBy::Dominant));
    assert_eq!(segs.len(), 3);
    assert!(segs.iter().all(|s| !s.mesh.is_empty()));
    let total = check_cover(&segs);
    assert!(
        rel(total, 4.0 / 3.0 * std::f64::consts::PI * 512.0) < 0.01,
        "{total}"
    );
}

#[test]
fn lattice_sphere_is_watertight() {
    let m = model(
        r#"let m = default_materials();
Intersection(false, [Tile(GraphLattice(LatticeType::BodyCenteredCubic, Vec3(5,5,5), 0.5, m.id("red"))), Sphere(Vec3(0,0,0), 6, m.id("blue"))])"#,
    );
    let segs = meshes(&m, &params(0.1, 1, SegmentBy::Dominant));
    assert!(
        segs.iter()
            .all(|s| s.mesh.is_empty() || s.mesh.is_watertight())
    );
    assert!(segs.iter().any(|s| !s.mesh.is_empty()));
}

fn export(
    m: &Arc<Model>,
    p: &MeshParams,
    dest: &std::path::Path,
) -> Result<volcad_compilers::Summary, ExportError> {
    let (m, p) = (m.clone(), p.clone());
    run(dest, move |ctx| export_meshes(&m, &p, ctx))
}

fn attr<'a>(line: &'a str, key: &str) -> &'a str {
    let start = line.find(&format!("{key}=\"")).unwrap() + key.len() + 2;
    &line[start..start + line[start..].find('"').unwrap()]
}

#[test]
fn files_and_3mf_structure() {
    let m = model(GRADED_BAR);
    let dir = tmp();
    let out = dir.path().join("out");
    let s = export(&m, &params(0.5, 4, SegmentBy::Material(RED)), &out).unwrap();
    assert_eq!(s.files.len(), 4 * 2 + 1, "{:?}", s.files);
    let segs = meshes(&m, &params(0.5, 4, SegmentBy::Material(RED)));
    let tree = read_tree(&out);
    for seg in &segs {
        let stl = &tree[&format!("{}.stl", seg.name)];
        assert_eq!(stl.len(), 84 + 50 * seg.mesh.triangles.len());
        let obj = String::from_utf8(tree[&format!("{}.obj", seg.name)].clone()).unwrap();
        assert_eq!(
            obj.lines().filter(|l| l.starts_with("v ")).count(),
            seg.mesh.vertices.len()
        );
        assert_eq!(
            obj.lines().filter(|l| l.starts_with("f ")).count(),
            seg.mesh.triangles.len()
        );
    }
    let mut zip = zip::ZipArchive::new(Cursor::new(tree["segments.3mf"].clone())).unwrap();
    let mut read = |name: &str| {
        let mut s = String::new();
        zip.by_name(name).unwrap().read_to_string(&mut s).unwrap();
        s
    };
    let model_xml = read("3D/3dmodel.model");
    let config = read("Metadata/Slic3r_PE_model.config");
    read("[Content_Types].xml");
    read("_rels/.rels");
    assert_eq!(model_xml.matches("<object ").count(), 1);
    let vertices = model_xml.matches("<vertex ").count();
    let triangles: Vec<[usize; 3]> = model_xml
        .lines()
        .filter(|l| l.contains("<triangle "))
        .map(|l| [attr(l, "v1"), attr(l, "v2"), attr(l, "v3")].map(|v| v.parse().unwrap()))
        .collect();
    assert_eq!(
        vertices,
        segs.iter().map(|s| s.mesh.vertices.len()).sum::<usize>()
    );
    assert_eq!(
        triangles.len(),
        segs.iter().map(|s| s.mesh.triangles.len()).sum::<usize>()
    );
    // One volume per segment: contiguous triangle ranges covering all, each
    // using only its own vertex block, named, with fill_density in percent.
    let volumes: Vec<&str> = config.split("<volume ").skip(1).collect();
    assert_eq!(volumes.len(), 4);
    let (mut next_tri, mut vbase) = (0, 0);
    for (v, seg) in volumes.iter().zip(&segs) {
        let (first, last): (usize, usize) = (
            attr(v, "firstid").parse().unwrap(),
            attr(v, "lastid").parse().unwrap(),
        );
        assert_eq!(first, next_tri);
        assert_eq!(last + 1 - first, seg.mesh.triangles.len());
        let vend = vbase + seg.mesh.vertices.len();
        assert!(
            triangles[first..=last]
                .iter()
                .flatten()
                .all(|i| (vbase..vend).contains(i)),
            "{}",
            seg.name
        );
        assert!(
            v.contains(&format!(r#"key="name" value="{}""#, seg.name)),
            "{v}"
        );
        assert!(
            v.contains(&format!(
                r#"key="fill_density" value="{}%""#,
                seg.infill_percent
            )),
            "{v}"
        );
        next_tri = last + 1;
        vbase = vend;
    }
    assert_eq!(next_tri, triangles.len());
    assert!(config.contains(r#"<object id="1""#) && model_xml.contains(r#"<object id="1""#));
}

#[test]
fn runs_and_thread_counts_give_identical_bytes() {
    let m = model(GRADED_BAR);
    let (mut trees, mut manifests) = (Vec::new(), Vec::new());
    for threads in [None, None, Some(1), Some(2)] {
        let dir = tmp();
        let p = MeshParams {
            threads,
            infill_expr: Some("5 + 90*f^2".into()),
            ..params(0.5, 3, SegmentBy::Material(RED))
        };
        export(&m, &p, &dir.path().join("out")).unwrap();
        trees.push(read_tree(&dir.path().join("out")));
        manifests.push(manifest(&dir.path().join("out")));
    }
    assert_eq!(trees[0].len(), 7);
    for t in &trees[1..] {
        assert!(
            t == &trees[0],
            "output differs between runs or thread counts"
        );
    }
    assert!(
        manifests.windows(2).all(|w| w[0] == w[1]),
        "manifests differ"
    );
}

#[test]
fn cancel_leaves_no_output() {
    let m = model(r#"let m = default_materials(); Sphere(Vec3(0,0,0), 10, m.id("red"))"#);
    let dir = tmp();
    let dest = dir.path().join("out");
    let p = params(0.04, 1, SegmentBy::Dominant);
    let h = volcad_compilers::job::spawn(dest.clone(), "t".into(), move |ctx| {
        export_meshes(&m, &p, ctx)
    });
    assert!(
        h.progress
            .recv_timeout(std::time::Duration::from_secs(60))
            .is_ok(),
        "no progress"
    );
    h.cancel();
    assert!(matches!(h.join(), Err(ExportError::Cancelled)));
    assert!(!dest.exists());
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
}

#[test]
fn bad_input_is_refused_naming_the_parameter() {
    let m = model(GRADED_BAR);
    let err = |p: MeshParams| estimate_mesh(&m, &p).unwrap_err().to_string();
    assert!(err(params(0.0, 2, SegmentBy::Dominant)).starts_with("--voxel:"));
    assert!(err(params(0.5, 2, SegmentBy::Material(0))).starts_with("--material:"));
    assert!(err(params(0.5, 2, SegmentBy::Material(200))).starts_with("--material:"));
    assert!(err(params(0.5, 0, SegmentBy::Material(RED))).starts_with("--segments:"));
    let e = err(MeshParams {
        infill_expr: Some("10 + 80*".into()),
        ..params(0.5, 2, SegmentBy::Material(RED))
    });
    assert!(e.starts_with("--infill:"), "{e}");
    let e = err(MeshParams {
        formats: MeshFormats {
            stl: false,
            obj: false,
            threemf: false,
        },
        ..params(0.5, 2, SegmentBy::Dominant)
    });
    assert!(e.starts_with("--format:"), "{e}");
    // 40 billion voxels a layer: refused for memory, without sampling
    // layers for the estimate first.
    let plate = model(
        r#"let m = default_materials(); RectPrism(Vec3(0,0,0), Vec3(2000, 2000, 1), m.id("red"))"#,
    );
    let e = estimate_mesh(&plate, &params(0.01, 2, SegmentBy::Dominant))
        .unwrap_err()
        .to_string();
    assert!(e.starts_with("--voxel:") && e.contains("memory"), "{e}");
    let tile = model(
        r#"let m = default_materials(); Tile(GraphLattice(LatticeType::BodyCenteredCubic, Vec3(5,5,5), 0.5, m.id("red")))"#,
    );
    assert!(
        estimate_mesh(&tile, &params(0.5, 2, SegmentBy::Dominant))
            .unwrap_err()
            .to_string()
            .starts_with("design:")
    );
    // A material from the table that the design does not use: f = 0, one segment.
    let dir = tmp();
    let s = export(
        &m,
        &params(0.5, 2, SegmentBy::Material(5)),
        &dir.path().join("out"),
    )
    .unwrap();
    assert!(
        s.notes.iter().any(|n| n.contains("not in the design")),
        "{:?}",
        s.notes
    );
    assert_eq!(s.counts[1].1, 0);
}
