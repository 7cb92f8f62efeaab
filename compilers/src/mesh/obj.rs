//! Wavefront OBJ: one object, `v x y z` lines (mm) then `f a b c` lines
//! (1-based vertex indices, counter-clockwise seen from outside). Numbers are
//! written with the shortest round-trip formatting (ryu), so the text is the
//! same on every run and reads back to the same f32 values.

use std::io::{self, Write};

use super::indexed::IndexedMesh;
use super::text_blocks::write_blocks;

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
    write_blocks(&mesh.vertices, w, |out, [x, y, z]| {
        let mut f = ryu::Buffer::new();
        out.extend_from_slice(b"v ");
        out.extend_from_slice(f.format(*x).as_bytes());
        out.push(b' ');
        out.extend_from_slice(f.format(*y).as_bytes());
        out.push(b' ');
        out.extend_from_slice(f.format(*z).as_bytes());
        out.push(b'\n');
    })?;
    write_blocks(&mesh.triangles, w, |out, [a, b, c]| {
        let mut i = itoa::Buffer::new();
        out.extend_from_slice(b"f ");
        out.extend_from_slice(i.format(a + 1).as_bytes());
        out.push(b' ');
        out.extend_from_slice(i.format(b + 1).as_bytes());
        out.push(b' ');
        out.extend_from_slice(i.format(c + 1).as_bytes());
        out.push(b'\n');
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
