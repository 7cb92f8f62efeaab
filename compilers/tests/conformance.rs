//! The files read by the programs users open them in: lib3mf's strict
//! reader opens `segments.3mf`, PrusaSlicer slices it keeping each part's
//! infill, and meshio reads the deck's `EALL` as every element.
//!
//! The Python checks run `$VOLCAD_PYTHON` (default `python3`) with the
//! scripts in `tests/data/`; lib3mf and meshio come from pip (`pip install
//! lib3mf meshio`), PrusaSlicer from Debian (`prusa-slicer`). A missing
//! program fails the test, as a missing `ccx` does, unless
//! `VOLCAD_SKIP_CONFORMANCE=1`.

// A failed setup step (a scratch folder, a file read) fails the test.
#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use std::io::{Cursor, Read};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::sync::Arc;

use common::{model, run, scratch};
use glam::DVec3;
use volcad_compilers::fea::{Element, FeaParams, export_fea};
use volcad_compilers::mesh::{MeshFormats, MeshParams, SegmentBy, export_meshes};
use volcad_core::Model;

/// Red grows along x: the four segments by red fraction are the quarters
/// of x in [−20, 20], with infill 20, 40, 60 and 80 %. Large enough that
/// PrusaSlicer keeps sparse infill: 12 mm tall (its default 0.3 mm layers
/// leave room between the solid top and bottom layers), and 10 × 20 mm per
/// part (regions under `solid_infill_below_area`, 70 mm², are filled solid).
const GRADED_BAR: &str = r#"let m = default_materials();
FGrade(["x/40+0.5", "-x/40+0.5"], [m.id("red"), m.id("blue")], true, RectPrism(Vec3(0,0,0), Vec3(40,20,12), m.id("gray")))"#;
const RED: u8 = 1;

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

fn skip_allowed(what: &str, install: &str) -> bool {
    if std::env::var("VOLCAD_SKIP_CONFORMANCE").as_deref() == Ok("1") {
        eprintln!("{what} not available; skipped (VOLCAD_SKIP_CONFORMANCE=1)");
        return true;
    }
    panic!("{what} is not installed: {install}, or set VOLCAD_SKIP_CONFORMANCE=1 to skip");
}

/// Run `program args`; `None` when it is missing and skipping is allowed.
fn tool(program: &str, args: &[&std::ffi::OsStr], install: &str) -> Option<Output> {
    match Command::new(program).args(args).output() {
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            skip_allowed(program, install);
            None
        }
        Err(e) => panic!("running {program}: {e}"),
        Ok(o) => Some(o),
    }
}

/// Run one of the Python checks on `file`; its stdout, or `None` when
/// skipped. Exit 3 from the script means its module is missing.
fn python_check(script: &str, module: &str, file: &Path) -> Option<String> {
    let python = std::env::var("VOLCAD_PYTHON").unwrap_or_else(|_| "python3".into());
    let install = format!("pip install {module} (or point VOLCAD_PYTHON at a Python that has it)");
    let o = tool(
        &python,
        &[data(script).as_os_str(), file.as_os_str()],
        &install,
    )?;
    let text = String::from_utf8_lossy(&o.stdout).into_owned();
    if o.status.code() == Some(3) {
        skip_allowed(&format!("the Python module {module}"), &install);
        return None;
    }
    assert!(
        o.status.success(),
        "{script} failed on {}:\n{text}\n{}",
        file.display(),
        String::from_utf8_lossy(&o.stderr)
    );
    Some(text)
}

/// The graded bar's segment meshes (3MF only) in `dir`.
fn segments_3mf(dir: &Path) {
    let m = model(GRADED_BAR);
    let p = MeshParams {
        voxel: DVec3::splat(0.5),
        segments: 4,
        by: SegmentBy::Material(RED),
        formats: MeshFormats {
            stl: false,
            obj: false,
            threemf: true,
        },
        ..MeshParams::default()
    };
    run(dir, move |ctx| export_meshes(&m, &p, ctx)).expect("mesh export");
}

/// The text of `entry` in the ZIP at `path`.
fn zip_entry(path: &Path, entry: &str) -> String {
    let bytes = std::fs::read(path).expect("zip file");
    let mut zip = zip::ZipArchive::new(Cursor::new(bytes)).expect("zip");
    let mut text = String::new();
    zip.by_name(entry)
        .expect("entry")
        .read_to_string(&mut text)
        .expect("utf-8");
    text
}

#[test]
fn lib3mf_strict_reader_opens_segments_3mf() {
    let (_t, dir) = scratch("mesh");
    segments_3mf(&dir);
    let Some(text) = python_check("check_3mf.py", "lib3mf", &dir.join("segments.3mf")) else {
        return;
    };
    assert!(text.contains("objects 1"), "{text}");
}

/// The `fill_density` of each `<volume>` in a PrusaSlicer model config.
fn volume_infills(config: &str) -> Vec<String> {
    config
        .split("<volume ")
        .skip(1)
        .map(|v| {
            let key = r#"key="fill_density" value=""#;
            let start = v.find(key).map(|i| i + key.len()).unwrap_or(0);
            v[start..].split('"').next().unwrap_or("").to_string()
        })
        .collect()
}

#[test]
fn prusaslicer_slices_segments_3mf_keeping_each_parts_infill() {
    let (t, dir) = scratch("mesh");
    segments_3mf(&dir);
    let src = dir.join("segments.3mf");
    let want = volume_infills(&zip_entry(&src, "Metadata/Slic3r_PE_model.config"));
    assert!(
        want.len() == 4 && want.windows(2).any(|w| w[0] != w[1]),
        "the test needs segments with different infill: {want:?}"
    );
    let rt = t.path().join("rt.3mf");
    let gcode = t.path().join("out.gcode");
    let install = "install prusa-slicer (Debian package)";
    let args = |a: &[&Path]| -> Vec<std::ffi::OsString> {
        a.iter().map(|p| p.as_os_str().to_owned()).collect()
    };
    let mut export_3mf = vec!["--dont-arrange".into(), "--export-3mf".into(), "-o".into()];
    export_3mf.extend(args(&[&rt, &src]));
    let refs: Vec<&std::ffi::OsStr> = export_3mf.iter().map(|s| s.as_os_str()).collect();
    let Some(o) = tool("prusa-slicer", &refs, install) else {
        return;
    };
    let log = |o: &Output| {
        format!(
            "{}\n{}",
            String::from_utf8_lossy(&o.stdout),
            String::from_utf8_lossy(&o.stderr)
        )
    };
    assert!(o.status.success(), "prusa-slicer --export-3mf: {}", log(&o));
    let config = zip_entry(&rt, "Metadata/Slic3r_PE_model.config");
    assert_eq!(volume_infills(&config), want, "{config}");
    let mut slice = vec![
        "--dont-arrange".into(),
        "--use-relative-e-distances".into(),
        "--export-gcode".into(),
        "-o".into(),
    ];
    slice.extend(args(&[&gcode, &src]));
    let refs: Vec<&std::ffi::OsStr> = slice.iter().map(|s| s.as_os_str()).collect();
    let o = tool("prusa-slicer", &refs, install).expect("ran above");
    assert!(
        o.status.success(),
        "prusa-slicer --export-gcode: {}",
        log(&o)
    );
    let g = std::fs::read_to_string(&gcode).expect("g-code");
    let (low, high) = infill_by_side(&g);
    // 20 % against 80 % sparse infill over the same area.
    assert!(
        low > 0.0 && high > 2.5 * low,
        "internal infill filament: x < -10: {low:.1} mm, x > 10: {high:.1} mm"
    );
}

/// Filament (mm of E, relative distances) of `;TYPE:Internal infill` moves
/// ending in the first quarter (x < −10) and in the last (x > 10).
fn infill_by_side(gcode: &str) -> (f64, f64) {
    let (mut infill, mut low, mut high) = (false, 0.0, 0.0);
    for line in gcode.lines() {
        if let Some(t) = line.strip_prefix(";TYPE:") {
            infill = t == "Internal infill";
            continue;
        }
        if !(infill && line.starts_with("G1 ")) {
            continue;
        }
        let word = |c: char| -> Option<f64> {
            line.split_whitespace()
                .find_map(|w| w.strip_prefix(c))
                .and_then(|v| v.parse().ok())
        };
        if let (Some(x), Some(e)) = (word('X'), word('E'))
            && e > 0.0
        {
            if x < -10.0 {
                low += e;
            } else if x > 10.0 {
                high += e;
            }
        }
    }
    (low, high)
}

fn two_material_deck(dir: &Path) -> Arc<Model> {
    let m = model(
        r#"let m = j750_materials();
FGrade(["x/6+0.5", "-x/6+0.5"], [m.id("VeroCyan"), m.id("Agilus30")], true, RectPrism(Vec3(0,0,0), Vec3(6,4,3), m.id("VeroCyan")))"#,
    );
    let (m2, p) = (
        m.clone(),
        FeaParams {
            element: Element::C3D8R,
            voxel: 0.5,
            ..FeaParams::default()
        },
    );
    run(dir, move |ctx| export_fea(&m2, &p, ctx)).expect("fea export");
    m
}

#[test]
fn meshio_reads_eall_as_every_element() {
    let (_t, dir) = scratch("fea");
    two_material_deck(&dir);
    let Some(text) = python_check("check_inp.py", "meshio", &dir.join("model.inp")) else {
        return;
    };
    let count = |name: &str| -> usize {
        text.lines()
            .find_map(|l| l.strip_prefix(&format!("{name} ")))
            .unwrap_or_else(|| panic!("no {name} in:\n{text}"))
            .parse()
            .expect("a count")
    };
    let cells = count("cells");
    assert!(
        count("E_VeroCyan") > 0 && count("E_Agilus30Clr") > 0,
        "{text}"
    );
    assert_eq!(
        count("E_VeroCyan") + count("E_Agilus30Clr"),
        cells,
        "{text}"
    );
    assert_eq!(count("EALL"), cells, "{text}");
}
