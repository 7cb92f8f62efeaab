//! Binary STL: 80-byte header, triangle count (u32), then per triangle the
//! unit normal, three vertices (f32 × 3 each, mm) and a zero attribute
//! (u16), all little-endian. The header never starts with `solid`, so no
//! reader takes the file for ASCII STL. Records are formatted on every
//! core in blocks and written in order (`text_blocks::write_blocks`).

use std::io::{self, Write};

use super::indexed::IndexedMesh;
use super::text_blocks::write_blocks;

/// Write `mesh` as binary STL; `name` goes into the header (truncated).
pub fn write_stl(mesh: &IndexedMesh, name: &str, w: &mut impl Write) -> io::Result<()> {
    let mut header = [b' '; 80];
    let text = format!("volcad binary STL: {name}");
    let n = text.len().min(80);
    header[..n].copy_from_slice(&text.as_bytes()[..n]);
    w.write_all(&header)?;
    let count = u32::try_from(mesh.triangles.len())
        .map_err(|_| io::Error::other("more than 2^32 triangles do not fit in STL"))?;
    w.write_all(&count.to_le_bytes())?;
    // Records formatted in parallel blocks, written in order.
    write_blocks(&mesh.triangles, w, |out, tri| {
        let mut rec = [0u8; 50];
        let corner = |k: usize| mesh.vertices[tri[k] as usize];
        let vals = [mesh.normal(*tri), corner(0), corner(1), corner(2)];
        for (dst, v) in rec.chunks_exact_mut(4).zip(vals.as_flattened()) {
            dst.copy_from_slice(&v.to_le_bytes());
        }
        out.extend_from_slice(&rec);
    })?;
    Ok(())
}

/// Bytes of a binary STL with `triangles` triangles.
pub fn stl_size(triangles: usize) -> u64 {
    84 + 50 * triangles as u64
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn layout_is_84_plus_50_per_triangle() {
        let m = IndexedMesh {
            vertices: vec![[0., 0., 0.], [1., 0., 0.], [0., 1., 0.]],
            triangles: vec![[0, 1, 2]],
        };
        let mut out = Vec::new();
        write_stl(&m, "x", &mut out).unwrap();
        assert_eq!(out.len() as u64, stl_size(1));
        assert!(out.starts_with(b"volcad binary STL: x"));
        assert_eq!(u32::from_le_bytes(out[80..84].try_into().unwrap()), 1);
        // Normal +Z, then the second vertex's x = 1.
        assert_eq!(f32::from_le_bytes(out[92..96].try_into().unwrap()), 1.0);
        assert_eq!(f32::from_le_bytes(out[108..112].try_into().unwrap()), 1.0);
        assert_eq!(&out[132..134], &[0, 0]);
    }
}
