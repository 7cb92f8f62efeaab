//! Bad and borderline mesh files: each refusal names the file, the line and
//! column (or byte, or element) and what to write instead; borderline files
//! that a user may well have load.

use std::path::Path;

use glam::DVec3;
use volcad_core::trimesh::{MeshError, TriangleMesh};

use super::{write, writers};

fn load_err(dir: &Path, name: &str, bytes: impl AsRef<[u8]>) -> MeshError {
    let path = write(dir, name, bytes);
    TriangleMesh::load(&path)
        .err()
        .unwrap_or_else(|| panic!("{name} loaded"))
}

/// OBJ text: `n` valid numbered lines of mixed statements before `line`.
fn obj_with_vertex_at(bad: &str, at_line: usize) -> String {
    let mut s = String::new();
    let mut n = 0;
    while n + 1 < at_line {
        s += match n % 4 {
            0 => "v 1 2 3\n",
            1 => "vt 0.5 0.5\n",
            2 => "\n",
            _ => "# a comment\n",
        };
        n += 1;
    }
    s.push_str(&format!("v {bad} 0 0\nf 1 2 3\n"));
    s
}

#[test]
fn obj_coordinates_are_blamed_at_their_line_and_column() {
    let dir = tempfile::tempdir().unwrap();
    let cases = [
        (
            "nan",
            "`nan` is not a number (NaN); write a finite coordinate",
        ),
        ("inf", "`inf` is infinite"),
        (
            "1e39",
            "`1e39` is out of range: mesh coordinates must lie within ±1e12",
        ),
        (
            "1e400",
            "`1e400` overflows: it is out of the range of a 64-bit float",
        ),
        ("1,5", "`1,5` is not a number"),
    ];
    for (bad, want) in cases {
        let e = load_err(dir.path(), "bad.obj", obj_with_vertex_at(bad, 105));
        match &e {
            MeshError::Parse {
                line, column, msg, ..
            } => {
                assert_eq!((*line, *column), (105, 3), "{bad}: {e}");
                assert!(msg.starts_with(want), "{bad}: {msg}");
            }
            other => panic!("{bad}: {other}"),
        }
        assert!(e.to_string().contains("bad.obj:105:3: "), "{e}");
    }
    let e = load_err(
        dir.path(),
        "f.obj",
        "v 0 0 0\nv 1 0 0 # x\nv 0 1 0\nf 1 2 4\n",
    );
    assert!(e.to_string().ends_with("f.obj:4:7: face vertex 4 does not exist: the file has 3 vertices (write 1..=3, or -1 for the last one read before the face)"), "{e}");
    // A 10 MB line is quoted by its start only.
    let long = format!(
        "v 0 0 0\nv 1 0 0\nv {} 0\nf 1 2 3\n",
        "7".repeat(10_000_000)
    );
    let e = load_err(dir.path(), "long.obj", long).to_string();
    assert!(
        e.contains(&format!(
            "long.obj:3:1: expected `v x y z` with 3 numbers, found `v {}…`",
            "7".repeat(58)
        )),
        "{}",
        &e[..200]
    );
    assert!(e.len() < 300, "{}", e.len());
    let e = load_err(dir.path(), "g.obj", "v 0 0 0\nf 1 2\n");
    assert!(matches!(e, MeshError::Parse { line: 2, .. }), "{e}");
}

#[test]
fn byte_order_marks_and_trailing_comments_are_accepted() {
    let dir = tempfile::tempdir().unwrap();
    let (v, q) = writers::cube_quads();
    let t = writers::split_quads(&q);
    let bom = |s: String| [b"\xEF\xBB\xBF".as_slice(), s.as_bytes()].concat();
    for (name, bytes) in [
        ("bom.obj", bom(writers::obj(&v, &q))),
        ("bom.stl", bom(writers::stl_ascii(&v, &t))),
        ("bom.off", bom(writers::off(&v, &q))),
        ("bom.ply", bom(writers::ply_ascii(&v, &q))),
    ] {
        let m =
            TriangleMesh::load(&write(dir.path(), name, bytes)).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(m.triangle_count(), 12, "{name}");
        assert!((m.volume() - 8.0).abs() < 1e-12, "{name}");
    }
}

#[test]
fn repeated_triangles_load_fast_with_a_count() {
    let dir = tempfile::tempdir().unwrap();
    let v = [DVec3::ZERO, DVec3::X, DVec3::Y];
    let copies: Vec<[u32; 3]> = vec![[0, 1, 2]; 200_000];
    let path = write(dir.path(), "copies.stl", writers::stl_binary(&v, &copies));
    let t0 = std::time::Instant::now();
    let m = TriangleMesh::load(&path).unwrap();
    assert_eq!(m.triangle_count(), 1);
    assert!(
        m.warnings()
            .iter()
            .any(|w| w.starts_with("removed 199999 duplicate triangles")),
        "{:?}",
        m.warnings()
    );
    let mut obj = String::from("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 0\n");
    obj += &"f 1 2 3\n".repeat(1_000_000);
    obj += "f 1 2 4\nf 3 2 1\n"; // a repeated corner after welding; the reverse stays
    let m = TriangleMesh::load(&write(dir.path(), "faces.obj", obj)).unwrap();
    assert_eq!(m.triangle_count(), 2);
    let w = m.warnings();
    assert!(
        w.iter()
            .any(|w| w.starts_with("removed 1 degenerate triangles")),
        "{w:?}"
    );
    assert!(
        w.iter()
            .any(|w| w.starts_with("removed 999999 duplicate triangles")),
        "{w:?}"
    );
    // Minutes before duplicates were dropped; seconds now even unoptimised.
    eprintln!(
        "two meshes of repeated triangles: {:.1} s",
        t0.elapsed().as_secs_f64()
    );
    let e = load_err(
        dir.path(),
        "flat.off",
        "OFF\n3 2 0\n0 0 0\n1 0 0\n0 0 0\n3 0 1 2\n3 2 1 0\n",
    );
    assert_eq!(
        e.to_string(),
        format!(
            "{}: all 2 triangles of the file have a repeated corner: there is no surface",
            dir.path().join("flat.off").display()
        )
    );
}

#[test]
fn special_empty_and_oversized_files_are_refused_before_reading() {
    let dir = tempfile::tempdir().unwrap();
    let e = TriangleMesh::load(dir.path()).unwrap_err();
    assert!(
        e.to_string().contains("is a folder, not a regular file"),
        "{e}"
    );
    #[cfg(unix)]
    {
        let fifo = dir.path().join("pipe.stl");
        let ok = std::process::Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .unwrap()
            .success();
        assert!(ok);
        // Opening a FIFO for reading would block this test forever.
        let e = TriangleMesh::load(&fifo).unwrap_err();
        assert!(e.to_string().ends_with("pipe.stl: is a FIFO (named pipe), not a regular file; give the path of a mesh file (STL, OBJ, PLY, OFF or 3MF)"), "{e}");
    }
    let e = load_err(dir.path(), "empty.obj", "");
    assert!(
        e.to_string().ends_with(
            "empty.obj: the file is empty (0 bytes); expected a mesh (STL, OBJ, PLY, OFF or 3MF)"
        ),
        "{e}"
    );
    // A binary STL header that claims a billion triangles, and nothing else.
    let mut head = vec![0u8; 80];
    head.extend_from_slice(&1_000_000_000u32.to_le_bytes());
    let e = load_err(dir.path(), "huge.stl", &head);
    assert!(e.to_string().contains("header announces 1000000000 triangles, i.e. 84 + 50·1000000000 = 50000000084 bytes, but the file has 84 bytes (truncated"), "{e}");
    let e = load_err(dir.path(), "huge.bin", &head);
    assert!(matches!(e, MeshError::UnknownFormat { .. }), "{e}");
    assert!(
        e.to_string().contains("announces 1000000000 triangles"),
        "{e}"
    );
    let mut ply = b"ply\nformat binary_little_endian 1.0\nelement vertex 4000000000\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n".to_vec();
    ply.extend_from_slice(&[0u8; 30]);
    let e = load_err(dir.path(), "huge.ply", ply);
    assert!(
        e.to_string()
            .contains("PLY: the file ends inside element `vertex` 3 of 4000000000: truncated?"),
        "{e}"
    );
    // An element without properties takes no bytes, whatever its count.
    let ply = "ply\nformat ascii 1.0\nelement junk 4000000000\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n";
    let e = load_err(dir.path(), "junk.ply", ply);
    assert!(
        e.to_string()
            .contains("PLY: the file ends inside element `face` 1 of 1: truncated?"),
        "{e}"
    );
}

#[test]
fn truncated_files_say_where_they_end() {
    let dir = tempfile::tempdir().unwrap();
    let (v, q) = writers::cube_quads();
    let t = writers::split_quads(&q);
    let cut = |b: Vec<u8>, keep: f64| b[..(b.len() as f64 * keep) as usize].to_vec();
    let stl = writers::stl_ascii(&v, &t);
    let stl = &stl[..stl.find("endloop").unwrap()];
    let off = writers::off(&v, &q);
    let off_lines: String = off.lines().take(12).map(|l| format!("{l}\n")).collect();
    let cases: Vec<(&str, Vec<u8>, &str)> = vec![
        (
            "t.stl",
            stl.into(),
            "file ends inside a facet (`outer loop` without `endloop`): truncated?",
        ),
        (
            "t.ply",
            cut(writers::ply_binary(&v, &q, false), 0.9),
            "PLY: the file ends inside element `face`",
        ),
        (
            "t.off",
            off_lines.into(),
            "t.off:12: file ends after 1 of the 6 faces the header announces: truncated?",
        ),
        (
            "t.3mf",
            cut(writers::threemf(&writers::model("millimeter", "", "")), 0.5),
            "3MF: not a readable zip archive",
        ),
        (
            "t.obj",
            cut(writers::obj(&v, &q).into_bytes(), 0.2),
            "t.obj:4:1: expected `v x y z` with 3 numbers, found `v 1 -1`",
        ),
        (
            "h.ply",
            b"ply\nformat ascii 1.0\nelement vertex 3\n".to_vec(),
            "the header has no `end_header` line: truncated?",
        ),
    ];
    for (name, bytes, want) in cases {
        let e = load_err(dir.path(), name, bytes);
        assert!(e.to_string().contains(want), "{name}: {e}");
    }
}

#[test]
fn threemf_errors_name_the_part_line_and_column() {
    let dir = tempfile::tempdir().unwrap();
    let obj = "<object id=\"1\"><mesh><vertices><vertex x=\"0\" y=\"0\" z=\"0\"/></vertices>\n<triangles>\n  <triangle v1=\"0\" v2=\"1\" v3=\"2\"/></triangles></mesh></object>";
    let model = writers::model("millimeter", obj, "<item objectid=\"1\"/>");
    let e = load_err(dir.path(), "bad.3mf", writers::threemf(&model));
    let want = "bad.3mf (in `3D/3dmodel.model` line 6, column 3): <triangle> `v2` = 1, but the object has 1 vertices before it (0-based: 0..1)";
    assert!(e.to_string().ends_with(want), "{e}");
    let obj = "<object id=\"1\"><mesh><vertices><vertex x=\"0\" y=\"0\" z=\"0\"/><vertex x=\"1\" y=\"0\" z=\"0\"/><vertex x=\"0\" y=\"1\" z=\"0\"/></vertices><triangles><triangle v1=\"0\" v2=\"1\" v3=\"2\"/></triangles></mesh></object>";
    let cases = [
        (
            "furlong",
            "<item objectid=\"1\"/>",
            "unknown unit `furlong`; the 3MF core spec allows micron, millimeter",
        ),
        (
            "millimeter",
            "<item objectid=\"9\"/>",
            "refers to object 9, which the <resources> do not define",
        ),
        ("millimeter", "", "the model's <build> has no <item>"),
    ];
    for (unit, items, want) in cases {
        let model = writers::model(unit, obj, items);
        let e = load_err(dir.path(), "case.3mf", writers::threemf(&model));
        assert!(e.to_string().contains(want), "{e}");
    }
}
