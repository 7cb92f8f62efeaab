//! Wavefront OBJ: one object, `v x y z` lines (mm) then `f a b c` lines
//! (1-based vertex indices, counter-clockwise seen from outside). Numbers are
//! written with the shortest round-trip formatting (ryu), so the text is the
//! same on every run and reads back to the same f32 values.

use std::io::{self, Write};

use super::indexed::IndexedMesh;
use super::text_blocks::{Floats, Ints, push_line, write_blocks};

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
    // ryu/itoa: millions of numbers; `{}` formatting dominated the export.
    write_blocks(&mesh.vertices, w, |out, v| {
        push_line(out, [b"v ", b" ", b" ", b"\n"], Floats::new().format(*v));
    })?;
    write_blocks(&mesh.triangles, w, |out, t| {
        let t = t.map(|i| u64::from(i) + 1);
        push_line(out, [b"f ", b" ", b" ", b"\n"], Ints::new().format(t));
    })
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
            text.contains("o seg\nv 0.0 0.0 0.0\nv 1.5 0.0 0.0\nv 0.0 0.1 0.0\nf 1 2 3\n"),
            "{text}"
        );
    }
}
