//! Helpers shared by the export tests: models from script text, jobs run
//! through the real job runner, output folders read back.
#![allow(dead_code)]
// A failed setup step (a scratch folder, a file read) fails the test.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::collections::BTreeMap;
use std::io::Cursor;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::Arc;

use volcad_compilers::job::{self, JobContext};
use volcad_compilers::mesh::{MeshFormats, MeshParams, export_meshes};
use volcad_compilers::{ExportError, Summary};
use volcad_core::Model;
use volcad_core::script::{ScriptOptions, model_of};

/// The prepared model of a Rhai design.
pub fn model(src: &str) -> Arc<Model> {
    Arc::new(model_of(src, "t.rhai", &ScriptOptions::default()).expect("design prepares"))
}

/// A design of one mesh from the test data (`tests/data/NAME`).
pub fn mesh_design(name: &str) -> Arc<Model> {
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/t.rhai");
    let src = format!(r#"Mesh("{name}", default_materials().id("gray"))"#);
    Arc::new(model_of(&src, "t.rhai", &ScriptOptions::for_file(&script)).expect("design prepares"))
}

/// A mesh export of `m` at `voxel` mm, STL files only, into `dir`.
pub fn mesh_stl(m: &Arc<Model>, voxel: f64, dir: &Path) -> Summary {
    let (m, p) = (
        m.clone(),
        MeshParams {
            voxel: glam::DVec3::splat(voxel),
            formats: MeshFormats {
                stl: true,
                obj: false,
                threemf: false,
            },
            ..MeshParams::default()
        },
    );
    run(dir, move |ctx| export_meshes(&m, &p, ctx)).expect("mesh export")
}

/// Run `work` as a job writing to `dest`, and wait.
pub fn run<F>(dest: &Path, work: F) -> Result<Summary, ExportError>
where
    F: FnOnce(&JobContext) -> Result<Summary, ExportError> + Send + 'static,
{
    job::spawn(dest.to_path_buf(), "test".into(), work).join()
}

/// Every file under `dir` but the manifest (which holds timings), by
/// relative path.
/// The bytes of `dir/manifest.json` (compared on their own: a layer range's
/// manifest differs from the full stack's, its files do not).
pub fn manifest(dir: &Path) -> Vec<u8> {
    std::fs::read(dir.join("manifest.json")).expect("every output has a manifest")
}

pub fn read_tree(dir: &Path) -> BTreeMap<String, Vec<u8>> {
    let mut out = BTreeMap::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).expect("readable folder") {
            let p = e.expect("entry").path();
            if p.is_dir() {
                stack.push(p);
            } else {
                let rel = p
                    .strip_prefix(dir)
                    .unwrap()
                    .to_string_lossy()
                    .replace('\\', "/");
                if rel != "manifest.json" {
                    out.insert(rel, std::fs::read(&p).expect("readable file"));
                }
            }
        }
    }
    out
}

/// A decoded PNG: width, height, colour type, bit depth, pixel bytes.
pub struct Png {
    pub width: usize,
    pub height: usize,
    pub color: png::ColorType,
    pub depth: png::BitDepth,
    pub data: Vec<u8>,
}

pub fn decode(bytes: &[u8]) -> Png {
    let mut r = png::Decoder::new(Cursor::new(bytes))
        .read_info()
        .expect("png header");
    let mut buf = vec![0; r.output_buffer_size().expect("size")];
    let info = r.next_frame(&mut buf).expect("png data");
    buf.truncate(info.buffer_size());
    Png {
        width: info.width as usize,
        height: info.height as usize,
        color: info.color_type,
        depth: info.bit_depth,
        data: buf,
    }
}

/// Pixels per RGBA colour over every `slice_*.png` at the top of a tree.
pub fn colour_counts(files: &BTreeMap<String, Vec<u8>>) -> BTreeMap<[u8; 4], u64> {
    let mut counts = BTreeMap::new();
    for (name, bytes) in files {
        if name.starts_with("slice_") {
            let png = decode(bytes);
            assert_eq!(
                (png.color, png.depth),
                (png::ColorType::Rgba, png::BitDepth::Eight),
                "{name}"
            );
            for px in png.data.chunks_exact(4) {
                *counts.entry([px[0], px[1], px[2], px[3]]).or_insert(0) += 1;
            }
        }
    }
    counts
}

/// A path that does not exist yet (an export's destination) inside a
/// scratch folder that is removed when the test ends, passed or failed.
pub fn scratch(name: &str) -> (tempfile::TempDir, PathBuf) {
    let t = tmp();
    let d = t.path().join(name);
    (t, d)
}

/// A fresh temporary folder (removed on drop).
pub fn tmp() -> tempfile::TempDir {
    tempfile::tempdir().expect("temp dir")
}

/// Run `ccx -i <job>` in `dir`; false when ccx is absent and skipping is allowed.
pub fn run_ccx(dir: &Path, job: &str) -> bool {
    let out = Command::new("ccx")
        .arg("-i")
        .arg(job)
        .current_dir(dir)
        .env("OMP_NUM_THREADS", "1")
        .output();
    match out {
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            if std::env::var("VOLCAD_SKIP_CCX").as_deref() == Ok("1") {
                eprintln!("ccx not found; skipped (VOLCAD_SKIP_CCX=1)");
                return false;
            }
            panic!(
                "ccx (CalculiX) is not installed: install calculix-ccx, or set VOLCAD_SKIP_CCX=1 to skip"
            );
        }
        Err(e) => panic!("running ccx: {e}"),
        Ok(o) => {
            let text = String::from_utf8_lossy(&o.stdout);
            assert!(
                o.status.success(),
                "ccx failed ({}):\n{text}\n{}",
                o.status,
                String::from_utf8_lossy(&o.stderr)
            );
            assert!(!text.contains("*ERROR"), "ccx reported an error:\n{text}");
            assert!(
                dir.join(format!("{job}.frd")).exists(),
                "no {job}.frd:\n{text}"
            );
            true
        }
    }
}

/// `total force (fx,fy,fz) for set NBOTTOM` from the `.dat`.
pub fn reaction(dat: &Path) -> Option<[f64; 3]> {
    let text = std::fs::read_to_string(dat).ok()?;
    let mut lines = text.lines();
    while let Some(l) = lines.next() {
        if l.contains("total force") {
            let v: Vec<f64> = lines
                .by_ref()
                .find(|l| !l.trim().is_empty())?
                .split_whitespace()
                .filter_map(|t| t.parse().ok())
                .collect();
            return (v.len() >= 3).then(|| [v[0], v[1], v[2]]);
        }
    }
    None
}

/// A segment mesh is empty or closed (every edge shared by two triangles);
/// the message gives the edge report.
pub fn assert_closed(seg: &volcad_compilers::mesh::SegmentMesh) {
    assert!(
        seg.mesh.is_empty() || seg.mesh.is_watertight(),
        "{}: {:?}",
        seg.name,
        seg.mesh.edge_report()
    );
}
