//! One 3MF holding every segment as a part of one object, with per-part
//! print settings that PrusaSlicer reads (checked by slicing it with
//! PrusaSlicer and opening it in lib3mf's strict reader,
//! `compilers/tests/conformance.rs`).
//!
//! Package: `[Content_Types].xml`, `_rels/.rels`, `3D/3dmodel.model` (one
//! `<object id="1">` whose mesh holds every part's vertices and triangles in
//! one contiguous block per part) and `Metadata/Slic3r_PE_model.config`
//! (one `<volume firstid lastid>` per part: 0-based inclusive triangle
//! indices, with `name` and the part's settings). Values use PrusaSlicer's
//! `.ini` syntax: `fill_density` must carry `%`. Vertices are world
//! coordinates in millimetres; no transform.
//!
//! Conformance (3MF core 1.3 and OPC): every part has a content type (the
//! `.config` part is plain XML, so `text/xml`), and `<item>` carries only
//! core attributes; PrusaSlicer's own `printable` is left out because
//! lib3mf's strict reader refuses unknown attributes in the core namespace,
//! and PrusaSlicer reads a missing `printable` as printable.
//!
//! The ZIP is written by [`crate::zip_writer`]: entries deflated (level 1)
//! on every core with a fixed 1980-01-01 time stamp, so the bytes repeat run
//! to run and on any thread count. The model XML is formatted in parallel
//! too (`text_blocks`); on a curved design it
//! is hundreds of megabytes, and one core formatting and deflating it made
//! the 3MF the slowest file of a mesh export.

use std::io::{self, Seek, Write};

use super::indexed::IndexedMesh;
use super::text_blocks::{Floats, Ints, push_line, write_blocks};
use crate::zip_writer::ZipOut;

/// One part (volume) of the object.
pub struct Part<'a> {
    /// Shown in the slicer's object list.
    pub name: &'a str,
    /// Its closed mesh.
    pub mesh: &'a IndexedMesh,
    /// PrusaSlicer settings for this part (`("fill_density", "40%")`).
    pub settings: Vec<(&'static str, String)>,
}

const CONTENT_TYPES: &str = r#"<?xml version="1.0" encoding="UTF-8"?>
<Types xmlns="http://schemas.openxmlformats.org/package/2006/content-types">
 <Default Extension="rels" ContentType="application/vnd.openxmlformats-package.relationships+xml"/>
 <Default Extension="model" ContentType="application/vnd.ms-package.3dmanufacturing-3dmodel+xml"/>
 <Default Extension="config" ContentType="text/xml"/>
</Types>
"#;

const RELS: &str = r#"<?xml version="1.0" encoding="UTF-8"?>
<Relationships xmlns="http://schemas.openxmlformats.org/package/2006/relationships">
 <Relationship Target="/3D/3dmodel.model" Id="rel0" Type="http://schemas.microsoft.com/3dmanufacturing/2013/01/3dmodel"/>
</Relationships>
"#;

/// `s` with XML's five special characters escaped.
pub fn xml_escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            c => out.push(c),
        }
    }
    out
}

/// Write the package for object `object_name` made of `parts` (each
/// non-empty) to `w`.
pub fn write_3mf<W: Write + Seek>(parts: &[Part<'_>], object_name: &str, w: W) -> io::Result<()> {
    let triangles: usize = parts.iter().map(|p| p.mesh.triangles.len()).sum();
    let mut zip = ZipOut::new(w);
    zip.entry("[Content_Types].xml", false, |z| {
        z.write_all(CONTENT_TYPES.as_bytes())
    })?;
    zip.entry("_rels/.rels", false, |z| z.write_all(RELS.as_bytes()))?;
    // About 50 bytes a triangle and 60 a vertex: past 4 GiB of XML near
    // 40 million triangles; Zip64 from 10 million keeps a wide margin.
    zip.entry("3D/3dmodel.model", triangles > 10_000_000, |z| {
        write_model(parts, object_name, z)
    })?;
    zip.entry("Metadata/Slic3r_PE_model.config", false, |z| {
        write_config(parts, object_name, z)
    })?;
    zip.finish()?;
    Ok(())
}

fn write_model(parts: &[Part<'_>], object_name: &str, m: &mut impl Write) -> io::Result<()> {
    writeln!(m, r#"<?xml version="1.0" encoding="UTF-8"?>"#)?;
    writeln!(
        m,
        r#"<model unit="millimeter" xml:lang="en-US" xmlns="http://schemas.microsoft.com/3dmanufacturing/core/2015/02" xmlns:slic3rpe="http://schemas.slic3r.org/3mf/2017/06">"#
    )?;
    writeln!(m, r#" <metadata name="slic3rpe:Version3mf">1</metadata>"#)?;
    writeln!(m, " <resources>")?;
    writeln!(
        m,
        r#"  <object id="1" name="{}" type="model">"#,
        xml_escape(object_name)
    )?;
    writeln!(m, "   <mesh>\n    <vertices>")?;
    for p in parts {
        write_blocks(&p.mesh.vertices, m, |out, v| {
            let glue: [&[u8]; 4] = [b"     <vertex x=\"", b"\" y=\"", b"\" z=\"", b"\"/>\n"];
            push_line(out, glue, Floats::new().format(*v));
        })?;
    }
    writeln!(m, "    </vertices>\n    <triangles>")?;
    let mut base = 0u64;
    for p in parts {
        write_blocks(&p.mesh.triangles, m, |out, t| {
            let glue: [&[u8]; 4] = [b"     <triangle v1=\"", b"\" v2=\"", b"\" v3=\"", b"\"/>\n"];
            push_line(
                out,
                glue,
                Ints::new().format(t.map(|v| base + u64::from(v))),
            );
        })?;
        base += p.mesh.vertices.len() as u64;
    }
    writeln!(
        m,
        "    </triangles>\n   </mesh>\n  </object>\n </resources>"
    )?;
    writeln!(m, " <build>\n  <item objectid=\"1\"/>\n </build>\n</model>")?;
    Ok(())
}

fn write_config(parts: &[Part<'_>], object_name: &str, c: &mut impl Write) -> io::Result<()> {
    writeln!(c, r#"<?xml version="1.0" encoding="UTF-8"?>"#)?;
    writeln!(c, "<config>")?;
    writeln!(c, r#" <object id="1" instances_count="1">"#)?;
    writeln!(
        c,
        r#"  <metadata type="object" key="name" value="{}"/>"#,
        xml_escape(object_name)
    )?;
    let mut first = 0usize;
    for p in parts {
        let last = first + p.mesh.triangles.len() - 1;
        writeln!(c, r#"  <volume firstid="{first}" lastid="{last}">"#)?;
        writeln!(
            c,
            r#"   <metadata type="volume" key="name" value="{}"/>"#,
            xml_escape(p.name)
        )?;
        for (k, v) in &p.settings {
            writeln!(
                c,
                r#"   <metadata type="volume" key="{}" value="{}"/>"#,
                xml_escape(k),
                xml_escape(v)
            )?;
        }
        writeln!(c, "  </volume>")?;
        first = last + 1;
    }
    writeln!(c, " </object>\n</config>")?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::{Cursor, Read};

    fn tri(z: f32) -> IndexedMesh {
        IndexedMesh {
            vertices: vec![[0., 0., z], [1., 0., z], [0., 1., z]],
            triangles: vec![[0, 1, 2]],
        }
    }

    #[test]
    fn package_has_parts_with_ranges_and_settings() {
        let (a, b) = (tri(0.0), tri(1.0));
        let parts = [
            Part {
                name: "s0",
                mesh: &a,
                settings: vec![("fill_density", "10%".into())],
            },
            Part {
                name: "s<1>",
                mesh: &b,
                settings: vec![("fill_density", "90%".into())],
            },
        ];
        let mut buf = Cursor::new(Vec::new());
        write_3mf(&parts, "part", &mut buf).unwrap();
        let bytes = buf.into_inner();
        let mut again = Cursor::new(Vec::new());
        write_3mf(&parts, "part", &mut again).unwrap();
        assert_eq!(bytes, again.into_inner(), "deterministic");
        let mut z = zip::ZipArchive::new(Cursor::new(bytes)).unwrap();
        let names: Vec<String> = z.file_names().map(String::from).collect();
        assert_eq!(names.len(), 4, "{names:?}");
        let mut model = String::new();
        z.by_name("3D/3dmodel.model")
            .unwrap()
            .read_to_string(&mut model)
            .unwrap();
        assert!(
            model.contains(r#"<triangle v1="3" v2="4" v3="5"/>"#),
            "{model}"
        );
        let mut cfg = String::new();
        z.by_name("Metadata/Slic3r_PE_model.config")
            .unwrap()
            .read_to_string(&mut cfg)
            .unwrap();
        assert!(cfg.contains(r#"<volume firstid="1" lastid="1">"#), "{cfg}");
        assert!(cfg.contains(r#"value="s&lt;1&gt;""#), "{cfg}");
        assert!(cfg.contains(r#"key="fill_density" value="90%""#), "{cfg}");
    }
}
