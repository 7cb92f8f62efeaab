//! Small writers for the mesh formats, so the tests make their files from
//! the bunny and from hand-made shapes instead of committing binaries.

use std::io::Write;

use glam::DVec3;

/// OBJ with a comment after every vertex and a polygon per face.
pub fn obj(v: &[DVec3], polys: &[Vec<u32>]) -> String {
    let mut s = String::from("# written by the meshio tests\no bunny\n");
    for (i, p) in v.iter().enumerate() {
        s += &format!("v {} {} {} # vertex {}\n", p.x, p.y, p.z, i + 1);
    }
    for f in polys {
        s += "f";
        for &i in f {
            // `i//i` form: position and normal index (normals unused).
            s += &format!(" {}//{}", i + 1, i + 1);
        }
        s += "\n";
    }
    s
}

pub fn stl_ascii(v: &[DVec3], t: &[[u32; 3]]) -> String {
    let mut s = String::from("solid test\n");
    for tri in t {
        s += "  facet normal 0 0 0\n    outer loop\n";
        for &i in tri {
            let p = v[i as usize];
            s += &format!("      vertex {} {} {}\n", p.x, p.y, p.z);
        }
        s += "    endloop\n  endfacet\n";
    }
    s + "endsolid test\n"
}

/// Binary STL whose header starts with `solid`, as many exporters write.
pub fn stl_binary(v: &[DVec3], t: &[[u32; 3]]) -> Vec<u8> {
    let mut b = b"solid but binary".to_vec();
    b.resize(80, b' ');
    b.extend_from_slice(&(t.len() as u32).to_le_bytes());
    for tri in t {
        b.extend_from_slice(&[0u8; 12]);
        for &i in tri {
            let p = v[i as usize];
            for x in [p.x, p.y, p.z] {
                b.extend_from_slice(&(x as f32).to_le_bytes());
            }
        }
        b.extend_from_slice(&[0u8; 2]);
    }
    b
}

/// PLY header with extra properties (a normal, a colour) and an extra
/// element after the faces, which the reader must read past.
fn ply_header(format: &str, nv: usize, nf: usize) -> String {
    format!(
        "ply\nformat {format} 1.0\ncomment written by the meshio tests\n\
         element vertex {nv}\nproperty float nx\nproperty double x\nproperty double y\nproperty double z\nproperty uchar red\n\
         element face {nf}\nproperty list uchar int vertex_indices\nproperty ushort flags\n\
         element edge 1\nproperty int vertex1\nproperty int vertex2\nend_header\n"
    )
}

pub fn ply_ascii(v: &[DVec3], polys: &[Vec<u32>]) -> String {
    let mut s = ply_header("ascii", v.len(), polys.len());
    for p in v {
        s += &format!("0.5 {} {} {} 200\n", p.x, p.y, p.z);
    }
    for f in polys {
        s += &format!("{} 7\n", counted(f));
    }
    s + "0 1\n"
}

pub fn ply_binary(v: &[DVec3], polys: &[Vec<u32>], big: bool) -> Vec<u8> {
    let format = if big {
        "binary_big_endian"
    } else {
        "binary_little_endian"
    };
    let mut b = ply_header(format, v.len(), polys.len()).into_bytes();
    macro_rules! put {
        ($x:expr) => {
            if big {
                b.extend_from_slice(&$x.to_be_bytes())
            } else {
                b.extend_from_slice(&$x.to_le_bytes())
            }
        };
    }
    for p in v {
        put!(0.5f32);
        put!(p.x);
        put!(p.y);
        put!(p.z);
        put!(200u8);
    }
    for f in polys {
        put!(f.len() as u8);
        for &i in f {
            put!(i as i32);
        }
        put!(7u16);
    }
    put!(0i32);
    put!(1i32);
    b
}

/// OFF with comments and the counts on their own line.
pub fn off(v: &[DVec3], polys: &[Vec<u32>]) -> String {
    let mut s = format!(
        "OFF\n# written by the meshio tests\n{} {} 0\n",
        v.len(),
        polys.len()
    );
    for p in v {
        s += &format!("{} {} {}\n", p.x, p.y, p.z);
    }
    for f in polys {
        s += &counted(f);
        s += "\n";
    }
    s
}

/// `n i0 … i(n-1)`: a polygon as PLY and OFF write it.
fn counted(f: &[u32]) -> String {
    let mut s = f.len().to_string();
    for i in f {
        s += &format!(" {i}");
    }
    s
}

/// A 3MF object's `<mesh>`.
pub fn threemf_mesh(v: &[DVec3], t: &[[u32; 3]]) -> String {
    let mut s = String::from("<mesh><vertices>\n");
    for p in v {
        s += &format!("<vertex x=\"{}\" y=\"{}\" z=\"{}\"/>\n", p.x, p.y, p.z);
    }
    s += "</vertices><triangles>\n";
    for [a, b, c] in t {
        s += &format!("<triangle v1=\"{a}\" v2=\"{b}\" v3=\"{c}\"/>\n");
    }
    s + "</triangles></mesh>"
}

/// A 3MF package around a model part's XML.
pub fn threemf(model: &str) -> Vec<u8> {
    let mut zip = zip::ZipWriter::new(std::io::Cursor::new(Vec::new()));
    let opts = zip::write::SimpleFileOptions::default();
    let parts = [
        (
            "[Content_Types].xml",
            r#"<?xml version="1.0" encoding="UTF-8"?><Types xmlns="http://schemas.openxmlformats.org/package/2006/content-types"><Default Extension="rels" ContentType="application/vnd.openxmlformats-package.relationships+xml"/><Default Extension="model" ContentType="application/vnd.ms-package.3dmanufacturing-3dmodel+xml"/></Types>"#,
        ),
        (
            "_rels/.rels",
            r#"<?xml version="1.0" encoding="UTF-8"?><Relationships xmlns="http://schemas.openxmlformats.org/package/2006/relationships"><Relationship Target="/3D/3dmodel.model" Id="rel0" Type="http://schemas.microsoft.com/3dmanufacturing/2013/01/3dmodel"/></Relationships>"#,
        ),
        ("3D/3dmodel.model", model),
    ];
    for (name, text) in parts {
        zip.start_file(name, opts).unwrap();
        zip.write_all(text.as_bytes()).unwrap();
    }
    zip.finish().unwrap().into_inner()
}

/// A model part: `unit`, the objects' XML and the build items' XML.
pub fn model(unit: &str, objects: &str, items: &str) -> String {
    format!(
        "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<model unit=\"{unit}\" xml:lang=\"en-US\" xmlns=\"http://schemas.microsoft.com/3dmanufacturing/core/2015/02\">\n<resources>\n{objects}\n</resources>\n<build>\n{items}\n</build>\n</model>\n"
    )
}

/// The cube `[-1, 1]³` as 8 vertices and 6 outward quads.
pub fn cube_quads() -> (Vec<DVec3>, Vec<Vec<u32>>) {
    let v = (0..8)
        .map(|i| {
            DVec3::new(
                if i & 1 == 0 { -1.0 } else { 1.0 },
                if i & 2 == 0 { -1.0 } else { 1.0 },
                if i & 4 == 0 { -1.0 } else { 1.0 },
            )
        })
        .collect();
    let q = vec![
        vec![0, 2, 3, 1], // -z
        vec![4, 5, 7, 6], // +z
        vec![0, 1, 5, 4], // -y
        vec![2, 6, 7, 3], // +y
        vec![0, 4, 6, 2], // -x
        vec![1, 3, 7, 5], // +x
    ];
    (v, q)
}

/// Quads cut into two triangles each.
pub fn split_quads(q: &[Vec<u32>]) -> Vec<[u32; 3]> {
    q.iter()
        .flat_map(|f| [[f[0], f[1], f[2]], [f[0], f[2], f[3]]])
        .collect()
}
