//! Wavefront OBJ: one object, `v x y z` lines (mm) then `f a b c` lines
//! (1-based vertex indices, counter-clockwise seen from outside). Numbers are
//! written with Rust's shortest round-trip formatting, so the text is the
//! same on every run and reads back to the same f32 values.

use std::io::{self, Write};

use super::indexed::IndexedMesh;

/// Write `mesh` as OBJ object `name`.
pub fn write_obj(mesh: &IndexedMesh, name: &str, w: &mut impl Write) -> io::Result<()> {
    writeln!(w, "# volcad segment mesh, millimetres")?;
    writeln!(
        w,
        "# {} vertices, {} triangles",
        mesh.vertices.len(),
        mesh.triangles.len()
    )?;
    writeln!(w, "o {name}")?;
    for [x, y, z] in &mesh.vertices {
        writeln!(w, "v {x} {y} {z}")?;
    }
    for [a, b, c] in &mesh.triangles {
        writeln!(w, "f {} {} {}", a + 1, b + 1, c + 1)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn writes_one_based_faces() {
        let m = IndexedMesh {
            vertices: vec![[0., 0., 0.], [1.5, 0., 0.], [0., 0.1, 0.]],
            triangles: vec![[0, 1, 2]],
        };
        let mut out = Vec::new();
        write_obj(&m, "seg", &mut out).unwrap();
        let text = String::from_utf8(out).unwrap();
        assert!(
            text.contains("o seg\nv 0 0 0\nv 1.5 0 0\nv 0 0.1 0\nf 1 2 3\n"),
            "{text}"
        );
    }
}
