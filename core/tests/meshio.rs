//! Mesh files: every format read by content gives the bunny's distances,
//! 3MF objects, components, transforms and units, open meshes with and
//! without validation, and each kind of bad file with its message.
//!
//! `cargo test -p volcad-core --test meshio`

// A test crate: its helper functions stop on a failed setup as its tests do.
#![allow(clippy::unwrap_used, clippy::expect_used)]

#[path = "meshio/writers.rs"]
mod writers;

#[path = "meshio/bad_input.rs"]
mod bad_input;

use std::path::{Path, PathBuf};

use glam::DVec3;
use volcad_core::Model;
use volcad_core::script::{ScriptOptions, run_script};
use volcad_core::trimesh::TriangleMesh;

const BUNNY: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../assets/examples/data/bunny.obj"
);

fn write(dir: &Path, name: &str, bytes: impl AsRef<[u8]>) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, bytes).unwrap();
    p
}

/// Points around and inside the bunny (bbox ±30.8 × ±23.4 × ±30 mm).
fn probe_points() -> Vec<DVec3> {
    let mut pts = Vec::new();
    for i in 0..5 {
        for j in 0..4 {
            for k in 0..5 {
                pts.push(DVec3::new(
                    -36.0 + 18.0 * i as f64,
                    -27.0 + 18.0 * j as f64,
                    -33.0 + 16.5 * k as f64,
                ));
            }
        }
    }
    pts.push(DVec3::new(0.0, 0.0, 0.0));
    pts.push(DVec3::new(1.5, -2.0, 10.0));
    pts
}

#[test]
fn bunny_in_every_format_gives_the_same_distances() {
    let reference = TriangleMesh::load(Path::new(BUNNY)).unwrap();
    assert!(reference.is_closed_manifold());
    let v = reference.vertices().to_vec();
    let t = reference.triangles().to_vec();
    let polys: Vec<Vec<u32>> = t.iter().map(|t| t.to_vec()).collect();
    let dir = tempfile::tempdir().unwrap();
    let model = writers::model(
        "millimeter",
        &format!(
            "<object id=\"7\" type=\"model\">{}</object>",
            writers::threemf_mesh(&v, &t)
        ),
        "<item objectid=\"7\"/>",
    );
    // Names that say nothing (or the wrong thing): the content decides.
    let files: Vec<(&str, Vec<u8>, f64)> = vec![
        ("a.mesh", writers::obj(&v, &polys).into_bytes(), 0.0),
        ("b.stl", writers::ply_ascii(&v, &polys).into_bytes(), 0.0),
        ("c.obj", writers::ply_binary(&v, &polys, false), 0.0),
        ("d.dat", writers::ply_binary(&v, &polys, true), 0.0),
        ("e.ply", writers::off(&v, &polys).into_bytes(), 0.0),
        ("f", writers::stl_ascii(&v, &t).into_bytes(), 0.0),
        ("g.off", writers::threemf(&model), 0.0),
        // f32 corners: distances move by the rounding of the coordinates.
        ("h.obj", writers::stl_binary(&v, &t), 1e-5),
    ];
    let pts = probe_points();
    for (name, bytes, tol) in files {
        let path = write(dir.path(), name, &bytes);
        let m = TriangleMesh::load(&path).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(m.triangle_count(), t.len(), "{name}");
        assert!(m.is_closed_manifold(), "{name}: {:?}", m.warnings());
        assert!(m.warnings().is_empty(), "{name}: {:?}", m.warnings());
        for &p in &pts {
            let (a, b) = (reference.signed_distance(p), m.signed_distance(p));
            assert!((a - b).abs() <= tol, "{name} at {p}: {a} vs {b}");
        }
    }
}

#[test]
fn polygons_and_extra_ply_elements_are_read() {
    let (v, q) = writers::cube_quads();
    let dir = tempfile::tempdir().unwrap();
    let files = [
        ("quads.ply", writers::ply_ascii(&v, &q).into_bytes()),
        ("quads_le.ply", writers::ply_binary(&v, &q, false)),
        ("quads_be.ply", writers::ply_binary(&v, &q, true)),
        ("quads.off", writers::off(&v, &q).into_bytes()),
        ("quads.obj", writers::obj(&v, &q).into_bytes()),
    ];
    for (name, bytes) in files {
        let m = TriangleMesh::load(&write(dir.path(), name, bytes)).unwrap();
        assert_eq!(m.triangle_count(), 12, "{name}");
        assert!(m.is_closed_manifold(), "{name}: {:?}", m.warnings());
        assert!((m.volume() - 8.0).abs() < 1e-12, "{name}: {}", m.volume());
        assert!((m.signed_distance(DVec3::new(0.0, 0.0, 3.0)) - 2.0).abs() < 1e-12);
        assert!((m.signed_distance(DVec3::ZERO) + 1.0).abs() < 1e-12);
    }
}

/// A unit cube `[0, 1]³` as a 3MF object's mesh.
fn unit_cube_mesh() -> String {
    let (v, q) = writers::cube_quads();
    let v: Vec<DVec3> = v.iter().map(|p| (*p + 1.0) * 0.5).collect();
    let t = writers::split_quads(&q);
    writers::threemf_mesh(&v, &t)
}

#[test]
fn threemf_objects_components_transforms_and_unit() {
    // In centimetres: object 1 a unit cube, object 2 the same cube through a
    // component scaled by 2 and mirrored in x; three build items.
    let objects = format!(
        "<object id=\"1\" type=\"model\">{}</object>\n\
         <object id=\"2\" type=\"model\"><components>\
         <component objectid=\"1\" transform=\"-2 0 0 0 2 0 0 0 2 0 0 0\"/>\
         </components></object>",
        unit_cube_mesh()
    );
    let items = "<item objectid=\"1\"/>\n\
         <item objectid=\"1\" transform=\"1 0 0 0 1 0 0 0 1 3 0 0\"/>\n\
         <item objectid=\"2\" transform=\"0 1 0 -1 0 0 0 0 1 0 10 0\"/>";
    let model = writers::model("centimeter", &objects, items);
    let dir = tempfile::tempdir().unwrap();
    let path = write(dir.path(), "parts.3mf", writers::threemf(&model));
    let m = TriangleMesh::load(&path).unwrap();
    assert_eq!(m.triangle_count(), 36);
    assert!(m.is_closed_manifold(), "{:?}", m.warnings());
    // 1 cm³ + 1 cm³ + 8 cm³, in mm³.
    assert!((m.volume() - 10_000.0).abs() < 1e-6, "{}", m.volume());
    // Item 1: [0, 10]³ mm; item 2: x in [30, 40]. Item 3: the component
    // gives x in [-2, 0], y and z in [0, 2] cm; the item's row-vector
    // transform maps (x, y, z) to (-y, x + 10, z): x in [-20, 0] mm,
    // y in [80, 100], z in [0, 20].
    let b = m.bbox();
    assert!(
        (b.min - DVec3::new(-20.0, 0.0, 0.0)).abs().max_element() < 1e-9,
        "{b:?}"
    );
    assert!(
        (b.max - DVec3::new(40.0, 100.0, 20.0)).abs().max_element() < 1e-9,
        "{b:?}"
    );
    assert!((m.signed_distance(DVec3::new(5.0, 5.0, 5.0)) + 5.0).abs() < 1e-12);
    assert!((m.signed_distance(DVec3::new(35.0, 5.0, 3.0)) + 3.0).abs() < 1e-12);
    assert!((m.signed_distance(DVec3::new(20.0, 5.0, 5.0)) - 10.0).abs() < 1e-12);
    // Inside the third item, 10 mm from its faces.
    assert!((m.signed_distance(DVec3::new(-10.0, 90.0, 10.0)) + 10.0).abs() < 1e-12);
    assert!((m.signed_distance(DVec3::new(-10.0, 90.0, 25.0)) - 5.0).abs() < 1e-12);

    // pyvcad 2.3.4 (Assimp) on the unit cube in millimetres gives
    // -0.5000001192092896 at its centre (an f32 grid value) and reads the
    // same file in centimetres, or moved by a build item, unchanged: it
    // ignores `unit` and build transforms, which the 3MF spec requires.
    let model = writers::model("millimeter", &objects, "<item objectid=\"1\"/>");
    let path = write(dir.path(), "cube.3mf", writers::threemf(&model));
    let m = TriangleMesh::load(&path).unwrap();
    let pyvcad = -0.5000001192092896;
    assert!((m.signed_distance(DVec3::splat(0.5)) - pyvcad).abs() < 1e-6);
}

/// The cube `[-1, 1]³` without its top (+z) face, as OBJ.
fn open_cube_obj() -> String {
    let (v, mut q) = writers::cube_quads();
    q.remove(1);
    writers::obj(&v, &q)
}

/// Runs a script in `dir` (as if saved there) and prepares its model.
fn run_in(dir: &Path, src: &str) -> Result<(Model, Vec<String>), String> {
    let path = dir.join("design.rhai");
    std::fs::write(&path, src).unwrap();
    let d = run_script(src, "design.rhai", &ScriptOptions::for_file(&path))
        .map_err(|e| e.to_string())?;
    let m = Model::prepare(&d.root, d.materials.clone()).map_err(|e| e.to_string())?;
    Ok((m, d.warnings))
}

#[test]
fn open_mesh_is_refused_unless_validation_is_disabled() {
    let dir = tempfile::tempdir().unwrap();
    write(dir.path(), "open.obj", open_cube_obj());
    let e = run_in(dir.path(), "Mesh(\"open.obj\")").err().unwrap();
    assert!(
        e.contains("open.obj: mesh is not closed: 4 open edges"),
        "{e}"
    );
    // The missing face: 4 edges around (0, 0, 1), 2√2 mm across.
    assert!(
        e.contains("the largest gap, 4 edges around (0.000, 0.000, 1.000), spans 2.828 mm"),
        "{e}"
    );
    assert!(e.contains("Mesh(\"open.obj\", m, true)"), "{e}");
    assert!(e.starts_with("design.rhai:1:1: "), "{e}");
    let e2 = run_in(dir.path(), "let m = 1;\nMesh(\"open.obj\", m, false)")
        .err()
        .unwrap();
    assert!(
        e2.starts_with("design.rhai:2:1: ") && e2.contains("not closed"),
        "{e2}"
    );

    // Disabled: inside/outside by the winding number (5/6 at the centre).
    for src in [
        "Mesh(\"open.obj\", 1, true)",
        "Mesh(\"open.obj\", Vec3(0.1, 0.1, 0.1), 1, true)",
    ] {
        let (m, warnings) = run_in(dir.path(), src).unwrap();
        assert!((m.distance(DVec3::ZERO) + 1.0).abs() < 1e-12, "{src}");
        assert!(
            (m.distance(DVec3::new(0.0, 0.0, -3.0)) - 2.0).abs() < 1e-12,
            "{src}"
        );
        // Above the hole the nearest surface is the rim, √5 away.
        assert!(
            (m.distance(DVec3::new(0.0, 0.0, 3.0)) - 5f64.sqrt()).abs() < 1e-12,
            "{src}"
        );
        assert!(m.distance(DVec3::new(0.5, 0.5, 0.9)) < 0.0, "{src}");
        assert!(
            warnings
                .iter()
                .any(|w| w.contains("not closed: 4 boundary edges")),
            "{warnings:?}"
        );
    }
}

#[test]
fn mesh_script_forms() {
    let dir = tempfile::tempdir().unwrap();
    let (v, q) = writers::cube_quads();
    write(dir.path(), "cube.off", writers::off(&v, &q));
    let red = "let mats = default_materials();\nlet red = mats.id(\"red\");\n";
    for call in [
        "Mesh(\"cube.off\")",
        "Mesh(\"cube.off\", red)",
        "Mesh(\"cube.off\", red, false)",
        "Mesh(\"cube.off\", Vec3(0.5, 0.5, 0.5))",
        "Mesh(\"cube.off\", Vec3(0.5, 0.5, 0.5), red)",
        "Mesh(\"cube.off\", Vec3(0.5, 0.5, 0.5), red, true)",
    ] {
        let (m, _) =
            run_in(dir.path(), &format!("{red}{call}")).unwrap_or_else(|e| panic!("{call}: {e}"));
        assert!(
            (m.distance(DVec3::new(0.0, 0.0, 2.5)) - 1.5).abs() < 1e-12,
            "{call}"
        );
    }
    let bad = [
        (
            "Mesh(\"cube.off\", 1, 2)",
            "Mesh: argument 3 is disable_validation and must be true or false, got an integer",
        ),
        (
            "Mesh(\"cube.off\", \"red\")",
            "Mesh: argument 2 (the material): material must be an id",
        ),
        (
            "Mesh(\"cube.off\", 1, true, false)",
            "Mesh: with 4 arguments the second is the sample size, a Vec3; got an integer",
        ),
        (
            "Mesh(\"cube.off\", Vec3(0, 1, 1), 1)",
            "Mesh: sample_size (argument 2) must be positive in x, y and z, got Vec3(0, 1, 1)",
        ),
        (
            "Mesh(\"cube.off\", Vec3(1, 1, 1), 1, 0)",
            "Mesh: argument 4 is disable_validation and must be true or false, got an integer",
        ),
    ];
    for (src, want) in bad {
        let e = run_in(dir.path(), src)
            .err()
            .unwrap_or_else(|| panic!("{src} ran"));
        assert!(e.contains(want), "{src}: {e}");
    }
}
