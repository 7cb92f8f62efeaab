//! The `volcad` binary end to end: every command, and bad input giving a
//! clear message and a non-zero exit (never a panic).

// A failed setup step (a scratch folder, a file read) fails the test.
#![allow(clippy::unwrap_used, clippy::expect_used)]

mod cli_common;

use std::path::Path;
use std::process::Command;

use cli_common::{example, fails, ok, runtime_dir, tmp, volcad};

#[test]
fn info_reports_box_materials_and_params() {
    let out = ok(&volcad(&["info", &example("graded_bar.rhai")]));
    assert!(
        out.contains("[-7.5000, -5.0000, -2.5000] .. [7.5000, 5.0000, 2.5000]"),
        "{out}"
    );
    assert!(out.contains("red (1), blue (3)"), "{out}");
    assert!(out.contains("param:       length = 15"), "{out}");
    let out = ok(&volcad(&[
        "info",
        &example("graded_bar.rhai"),
        "--param",
        "length=30",
    ]));
    assert!(out.contains("[-15.0000"), "{out}");
}

/// A legacy OpenVCAD `.vcad` design runs like a script: `info` and an
/// export, and a bad one names its line and column.
#[test]
fn legacy_vcad_designs_info_and_export() {
    let design = example("legacy.vcad");
    let out = ok(&volcad(&["info", &design]));
    assert!(out.contains("root:        Union"), "{out}");
    assert!(
        out.contains("[-20.0000, -12.0000, -2.0000] .. [20.0000, 12.0000, 15.0000]"),
        "{out}"
    );
    assert!(
        out.contains("red (1)") && out.contains("magenta (7)"),
        "{out}"
    );
    let scratch = tmp("vcad");
    let png = scratch.path().join("png");
    let out = ok(&volcad(&[
        "export",
        "png",
        &design,
        "--out",
        png.to_str().unwrap(),
        "--voxel",
        "1",
    ]));
    assert!(out.contains("red") && out.contains("yellow"), "{out}");
    let slices = files_in(&png)
        .iter()
        .filter(|f| f.ends_with(".png"))
        .count();
    assert_eq!(slices, 17, "17 mm tall at 1 mm layers");

    let bad = scratch.path().join("bad.vcad");
    std::fs::write(
        &bad,
        "union(){\n  sphere(1, \"red\");\n  cube((1,1,1), \"red\");\n}\n",
    )
    .unwrap();
    let err = fails(&volcad(&["info", bad.to_str().unwrap()]));
    assert!(
        err.contains("bad.vcad:3:3: construct `cube` is not taken"),
        "{err}"
    );
}

#[test]
fn eval_prints_distance_and_fractions_by_name() {
    let out = ok(&volcad(&[
        "eval",
        &example("graded_bar.rhai"),
        "3.75",
        "0",
        "0",
    ]));
    assert!(out.contains("distance: -2.5"), "{out}");
    assert!(out.contains("red: 0.75"), "{out}");
    assert!(out.contains("blue: 0.25"), "{out}");
    let out = ok(&volcad(&[
        "eval",
        &example("graded_bar.rhai"),
        "--",
        "-20",
        "0",
        "0",
    ]));
    assert!(out.contains("outside"), "{out}");
}

#[test]
fn sample_writes_one_column_per_material() {
    let scratch = tmp("sample");
    let d = scratch.path();
    let pts = d.join("in.csv");
    std::fs::write(&pts, "x,y,z\n0,0,0\n7.5,0,0\n100,0,0\n").unwrap();
    let out = d.join("out.csv");
    ok(&volcad(&[
        "sample",
        &example("graded_bar.rhai"),
        "--points",
        pts.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]));
    let text = std::fs::read_to_string(&out).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines[0], "x,y,z,distance,red,blue");
    assert_eq!(lines[1], "0,0,0,-2.5,0.5,0.5");
    assert!(lines[2].starts_with("7.5,0,0,0,1,0"), "{}", lines[2]);
    assert!(lines[3].ends_with(",0,0"), "outside is 0: {}", lines[3]);
}

#[test]
fn bad_input_is_a_clear_error() {
    let err = fails(&volcad(&["info", "/no/such/design.rhai"]));
    assert!(err.contains("cannot read /no/such/design.rhai"), "{err}");

    let scratch = tmp("bad");
    let d = scratch.path();
    let bad = d.join("bad.rhai");
    std::fs::write(
        &bad,
        "let m = default_materials();\nSphere(Vec3(0,0,0), 1, m.id(\"rde\"))\n",
    )
    .unwrap();
    let err = fails(&volcad(&["info", bad.to_str().unwrap()]));
    assert!(err.contains("bad.rhai:2:"), "{err}");
    assert!(err.contains("did you mean \"red\""), "{err}");

    // A script whose data doubles in a loop stops at its memory budget
    // (here 64 MiB) with an error, instead of exhausting the machine.
    let runaway = d.join("runaway.rhai");
    std::fs::write(
        &runaway,
        "let m = default_materials();\nlet s = \"ab\";\nfor i in 0..60 { s += s; }\nSphere(Vec3(0,0,0), 1, m.id(\"red\"))\n",
    )
    .unwrap();
    let run = |budget: &str| {
        Command::new(volcad_tests::bin("volcad"))
            .args(["info", runaway.to_str().unwrap()])
            .env("VOLCAD_SCRIPT_MEMORY_MB", budget)
            .output()
            .expect("run volcad")
    };
    let err = fails(&run("64"));
    assert!(err.contains("runaway.rhai:3:"), "{err}");
    assert!(err.contains("grew past 64 MiB of memory"), "{err}");
    // It says where the budget comes from.
    assert!(
        err.contains("the budget is VOLCAD_SCRIPT_MEMORY_MB"),
        "{err}"
    );
    let err = fails(&run("lots"));
    assert!(
        err.contains("VOLCAD_SCRIPT_MEMORY_MB=lots: give the script's memory budget"),
        "{err}"
    );

    // Parameters: a typo or a value outside the declared range is refused,
    // not ignored or clamped.
    let lattice = example("bcc_sphere.rhai");
    let err = fails(&volcad(&["info", &lattice, "--param", "strut_radiu=0.3"]));
    assert!(
        err.contains("declares no parameter `strut_radiu`; did you mean `strut_radius`?"),
        "{err}"
    );
    let err = fails(&volcad(&["info", &lattice, "--param", "strut_radius=9"]));
    assert!(
        err.contains("--param strut_radius=9: outside the range"),
        "{err}"
    );
    let err = fails(&volcad(&[
        "eval",
        &example("hello_cube.rhai"),
        "nan",
        "0",
        "0",
    ]));
    assert!(err.contains("X = NaN: give a finite coordinate"), "{err}");

    let pts = d.join("pts.csv");
    std::fs::write(&pts, "x,y,z\n1,2,3\n1,oops,3\n").unwrap();
    let err = fails(&volcad(&[
        "sample",
        &example("hello_cube.rhai"),
        "--points",
        pts.to_str().unwrap(),
        "--out",
        d.join("o.csv").to_str().unwrap(),
    ]));
    assert!(
        err.contains("pts.csv:3: `y` = \"oops\" is not a finite number"),
        "{err}"
    );

    let err = fails(&volcad(&[
        "export",
        "png",
        &example("hello_cube.rhai"),
        "--out",
        d.join("x").to_str().unwrap(),
        "--voxel",
        "-1",
    ]));
    assert!(err.contains("--voxel -1: voxel sizes must be > 0"), "{err}");
    assert!(!d.join("x").exists());

    let err = fails(&volcad(&[
        "export",
        "png",
        &example("gyroid.rhai"),
        "--out",
        d.join("y").to_str().unwrap(),
        "--voxel",
        "0.5",
        "--param",
        "cell",
    ]));
    assert!(err.contains("expected NAME=VALUE"), "{err}");

    // A step larger than the part (the graded bar is 5 mm tall) is refused
    // before anything is written; zero is allowed with a note.
    let fea = |step: &str, out: &Path| {
        volcad(&[
            "export",
            "fea",
            &example("graded_bar.rhai"),
            "--out",
            out.to_str().unwrap(),
            "--voxel",
            "1",
            "--step",
            step,
        ])
    };
    let err = fails(&fea("1e300", &d.join("f1")));
    assert!(
        err.contains("--step") && err.contains("not smaller than the part's height (5.0000 mm)"),
        "{err}"
    );
    assert!(!d.join("f1").exists());
    let text = ok(&fea("0", &d.join("f2")));
    assert!(
        text.contains("--step 0: the top is held in place"),
        "{text}"
    );
    let text = ok(&fea("-1", &d.join("f3")));
    assert!(text.contains("20 % of the part's height"), "{text}");
}

#[test]
fn unbounded_design_refuses_to_export() {
    let scratch = tmp("unbounded");
    let d = scratch.path();
    let s = d.join("tile.rhai");
    std::fs::write(&s, "Tile(4, 4, 4, Sphere(Vec3(0,0,0), 1, 1))").unwrap();
    // Every export words it alike, the tetrahedra (which need no voxel
    // grid) included.
    for kind in [
        &["png"][..],
        &["mesh"],
        &["fea"],
        &["fea", "--element", "c3d4"],
        &["fea", "--element", "c3d4", "--voxel", "0.5"],
    ] {
        let out = d.join("o");
        let mut args = vec!["export"];
        args.extend_from_slice(kind);
        args.extend([s.to_str().unwrap(), "--out", out.to_str().unwrap()]);
        if kind.len() < 3 {
            args.extend(["--voxel", "0.5"]);
        }
        let err = fails(&volcad(&args));
        assert!(
            err.contains("design: the design is unbounded (bounding box"),
            "{kind:?}: {err}"
        );
        assert!(!out.exists(), "{kind:?}");
    }
}

fn files_in(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().to_string())
        .collect();
    v.sort();
    v
}

#[test]
fn export_png_mesh_and_fea() {
    let scratch = tmp("export");
    let d = scratch.path();
    let png = d.join("png");
    let out = ok(&volcad(&[
        "export",
        "png",
        &example("graded_bar.rhai"),
        "--out",
        png.to_str().unwrap(),
        "--voxel",
        "0.5",
        "--seed",
        "3",
    ]));
    assert!(out.contains("red") && out.contains("blue"), "{out}");
    let files = files_in(&png);
    assert!(files.contains(&"manifest.json".to_string()));
    assert_eq!(
        files.iter().filter(|f| f.ends_with(".png")).count(),
        10,
        "5 mm / 0.5 mm layers: {files:?}"
    );

    let mesh = d.join("mesh");
    ok(&volcad(&[
        "export",
        "mesh",
        &example("graded_bar.rhai"),
        "--out",
        mesh.to_str().unwrap(),
        "--voxel",
        "0.5",
        "--segments",
        "2",
        "--by",
        "red",
    ]));
    let files = files_in(&mesh);
    assert!(files.iter().any(|f| f.ends_with(".3mf")), "{files:?}");
    assert!(
        files.iter().filter(|f| f.ends_with(".stl")).count() >= 2,
        "{files:?}"
    );
    // Only the formats asked for; a bad list is refused before any work.
    let only = d.join("mesh_3mf");
    ok(&volcad(&[
        "export",
        "mesh",
        &example("graded_bar.rhai"),
        "--out",
        only.to_str().unwrap(),
        "--voxel",
        "0.5",
        "--formats",
        "3mf",
    ]));
    let files = files_in(&only);
    assert!(files.iter().any(|f| f.ends_with(".3mf")), "{files:?}");
    assert!(
        !files
            .iter()
            .any(|f| f.ends_with(".stl") || f.ends_with(".obj")),
        "{files:?}"
    );
    // Bad mesh options are refused before any work, with what was wrong.
    let bar = example("graded_bar.rhai");
    let bad_dir = d.join("bad");
    let refused = |extra: &[&str]| {
        let mut args = vec!["export", "mesh", &bar, "--out", bad_dir.to_str().unwrap()];
        args.extend(["--voxel", "0.5"]);
        args.extend(extra);
        let out = volcad(&args);
        assert!(!out.status.success(), "{extra:?}");
        assert!(!bad_dir.exists(), "{extra:?}");
        String::from_utf8_lossy(&out.stderr).to_string()
    };
    assert!(refused(&["--formats", "stl,ply"]).contains("unknown format `ply`"));
    // A range count without a material to split by would be ignored.
    let err = refused(&["--segments", "4"]);
    assert!(
        err.contains("--segments 4") && err.contains("--by red"),
        "{err}"
    );
    // Options of another export kind would be ignored: refused, by name.
    let err = refused(&["--dither", "diffusion", "--element", "c3d4"]);
    assert!(
        err.contains("--dither, --element do not apply to `volcad export mesh`"),
        "{err}"
    );

    let fea = d.join("fea");
    ok(&volcad(&[
        "export",
        "fea",
        &example("graded_bar.rhai"),
        "--out",
        fea.to_str().unwrap(),
        "--voxel",
        "1",
        "--step",
        "-0.1",
    ]));
    let inp = std::fs::read_to_string(fea.join("model.inp")).unwrap();
    assert!(
        inp.contains("*ELEMENT") || inp.contains("*Element"),
        "{inp}"
    );
    assert!(inp.to_uppercase().contains("NSET=NBOTTOM"));
}

#[test]
fn bench_reports_evaluation_and_export_rates() {
    let out = ok(&volcad(&[
        "bench",
        &example("graded_bar.rhai"),
        "--points",
        "2000",
        "--voxels",
        "200000",
    ]));
    assert!(
        out.contains("png voxels/s") && out.contains("mesh voxels/s"),
        "{out}"
    );
    // The first line says what the figures are of.
    assert!(
        out.starts_with("points/s: 2000 points within 2 mm")
            && out.lines().next().unwrap().contains("about 200000 voxels"),
        "{out}"
    );
    // The second, which machine and how many threads.
    let machine = out.lines().nth(1).unwrap_or_default();
    assert!(
        machine.starts_with("machine: ") && machine.contains(" thread"),
        "{out}"
    );
    let row = out
        .lines()
        .find(|l| l.starts_with("graded_bar.rhai"))
        .unwrap_or_else(|| panic!("no row: {out}"));
    // nodes, prepare, random, Z-order, voxel, png, mesh: all numbers > 0.
    let numbers: Vec<f64> = row
        .split_whitespace()
        .skip(1)
        .map(|w| {
            w.parse()
                .unwrap_or_else(|_| panic!("not a number: {w} in {row}"))
        })
        .collect();
    assert_eq!(numbers.len(), 7, "{row}");
    assert!(numbers[2..].iter().all(|v| *v > 0.0), "{row}");
    // The voxel gives about the asked grid: (15·10·5 / 2e5)^(1/3) mm.
    assert!((numbers[4] - (750.0f64 / 2e5).cbrt()).abs() < 1e-3, "{row}");
    // Evaluation alone: no export columns.
    let out = ok(&volcad(&[
        "bench",
        &example("graded_bar.rhai"),
        "--points",
        "2000",
        "--no-exports",
    ]));
    let row = out
        .lines()
        .find(|l| l.starts_with("graded_bar.rhai"))
        .unwrap();
    assert_eq!(row.split_whitespace().count(), 5, "{row}");
}

/// Ctrl-C (SIGINT), `kill` (SIGTERM) and a closed terminal (SIGHUP) cancel
/// an export cleanly: the process ends soon with an error, and neither the
/// destination nor the hidden staging folder is left.
#[cfg(unix)]
#[test]
fn signals_cancel_exports_and_leave_nothing() {
    use std::time::{Duration, Instant};
    for signal in ["INT", "TERM", "HUP"] {
        let scratch = tmp(&format!("signal_{signal}"));
        let d = scratch.path();
        let dest = d.join("stack");
        // Fine enough to run for many seconds: a debug build at 0.01 mm.
        let mut child = Command::new(volcad_tests::bin("volcad"))
            .args(["export", "png", &example("graded_bar.rhai"), "--out"])
            .arg(&dest)
            .args(["--voxel", "0.01"])
            .env("XDG_RUNTIME_DIR", runtime_dir())
            .stdout(std::process::Stdio::null())
            .stderr(std::process::Stdio::piped())
            .spawn()
            .unwrap();
        let staging = || {
            std::fs::read_dir(d).unwrap().flatten().any(|e| {
                e.file_name()
                    .to_string_lossy()
                    .starts_with(".stack.partial-")
            })
        };
        let start = Instant::now();
        while !staging() {
            assert!(
                start.elapsed() < Duration::from_secs(60),
                "no staging folder"
            );
            assert!(
                child.try_wait().unwrap().is_none(),
                "the export ended early"
            );
            std::thread::sleep(Duration::from_millis(20));
        }
        let sent = Command::new("kill")
            .args([&format!("-{signal}"), &child.id().to_string()])
            .status()
            .unwrap();
        assert!(sent.success());
        let start = Instant::now();
        let status = loop {
            if let Some(s) = child.try_wait().unwrap() {
                break s;
            }
            assert!(
                start.elapsed() < Duration::from_secs(30),
                "SIG{signal}: still running"
            );
            std::thread::sleep(Duration::from_millis(20));
        };
        let mut err = String::new();
        std::io::Read::read_to_string(&mut child.stderr.take().unwrap(), &mut err).unwrap();
        assert_eq!(status.code(), Some(1), "SIG{signal}: {status:?} {err}");
        assert!(err.contains("cancel"), "SIG{signal}: {err}");
        assert!(!dest.exists(), "SIG{signal}");
        assert!(!staging(), "SIG{signal}: staging left");
    }
}

#[test]
fn scripts_read_inside_their_project_and_allow_read_adds_folders() {
    let t = tmp("allow-read");
    let root = t.path();
    // The home folder elsewhere: a folder above home is never a project.
    let home = tmp("allow-read-home");
    for d in ["p/designs", "data"] {
        std::fs::create_dir_all(root.join(d)).unwrap();
    }
    std::fs::write(root.join("data/r.csv"), "r\n2\n").unwrap();
    let design = root.join("p/designs/d.rhai");
    std::fs::write(
        &design,
        "r = read_csv(\"../../data/r.csv\")[0].r;\nroot = Sphere(Vec3(0, 0, 0), r, 1);\n",
    )
    .unwrap();
    let run = |extra: &[&str]| {
        let mut args = vec!["info", design.to_str().unwrap()];
        args.extend_from_slice(extra);
        Command::new(volcad_tests::bin("volcad"))
            .args(&args)
            .env("XDG_RUNTIME_DIR", runtime_dir())
            .env("HOME", home.path())
            .output()
            .expect("run volcad")
    };
    // No .git or volcad.toml above the script: its own folder only.
    let err = fails(&run(&[]));
    assert!(err.contains("d.rhai:1:"), "{err}");
    assert!(err.contains("outside the project folder"), "{err}");
    assert!(err.contains("--allow-read"), "{err}");
    let data = root.join("data");
    let out = ok(&run(&["--allow-read", data.to_str().unwrap()]));
    assert!(out.contains("[-2.0000, -2.0000, -2.0000]"), "{out}");
    let err = fails(&run(&["--allow-read", "/no/such/folder"]));
    assert!(
        err.contains("--allow-read /no/such/folder: no such folder"),
        "{err}"
    );
    // A volcad.toml at the top makes the whole tree one project.
    std::fs::write(root.join("volcad.toml"), "").unwrap();
    ok(&run(&[]));
}

/// `--params FILE --set NAME` applies a set the studio saved beside the
/// design (`--param` still wins); an unknown set lists the ones there are.
#[test]
fn parameter_sets_apply_on_the_command_line() {
    let scratch = tmp("param-sets");
    let dir = scratch.path();
    let design = dir.join("plate.rhai");
    std::fs::write(
        &design,
        "let m = default_materials();\nlet w = param(\"width\", 15.0, 5.0, 30.0);\nRectPrism(Vec3(0, 0, 0), Vec3(w, 10, 5), m.id(\"gray\"))\n",
    )
    .unwrap();
    let sets = dir.join("plate.params.json");
    std::fs::write(
        &sets,
        r#"{"fileFormatVersion": "1", "parameterSets": {"wide": {"width": "22"}}}"#,
    )
    .unwrap();
    let (d, s) = (design.to_str().unwrap(), sets.to_str().unwrap());
    let out = ok(&volcad(&["info", d, "--params", s, "--set", "wide"]));
    assert!(out.contains("size (mm):   22.0000 x"), "{out}");
    let out = ok(&volcad(&[
        "info", d, "--params", s, "--set", "wide", "--param", "width=9",
    ]));
    assert!(out.contains("size (mm):   9.0000 x"), "{out}");
    let err = fails(&volcad(&["info", d, "--params", s, "--set", "narrow"]));
    assert!(
        err.contains("no parameter set \"narrow\"; the file has wide"),
        "{err}"
    );
}

#[test]
fn a_finished_export_is_replaced_only_with_force_and_other_folders_never() {
    let scratch = tmp("replace");
    let d = scratch.path();
    let bar = example("graded_bar.rhai");
    let out = d.join("bar_png");
    let export = |voxel: &str, extra: &[&str]| {
        let mut args = vec!["export", "png", &bar, "--out", out.to_str().unwrap()];
        args.extend(["--voxel", voxel]);
        args.extend(extra);
        volcad(&args)
    };
    ok(&export("1", &[]));
    let manifest = std::fs::read_to_string(out.join("manifest.json")).unwrap();
    assert!(
        manifest.contains("\"design\": \"graded_bar.rhai\""),
        "{manifest}"
    );
    // Five 1 mm layers; a second export at 0.5 mm would replace them.
    assert_eq!(files_in(&out).len(), 6);
    let err = fails(&export("0.5", &[]));
    assert!(
        err.contains("holds a finished export, a png export of graded_bar.rhai (6 files")
            && err.contains("add --force to replace it"),
        "{err}"
    );
    assert_eq!(files_in(&out).len(), 6, "the finished export is kept");
    ok(&export("0.5", &["--force"]));
    assert_eq!(files_in(&out).len(), 11, "replaced: ten layers");
    // A folder of other files is never replaced, --force or not, and the
    // refusal names what is in it.
    let mine = d.join("mine");
    std::fs::create_dir(&mine).unwrap();
    for n in ["notes.txt", "photo.jpg"] {
        std::fs::write(mine.join(n), "x").unwrap();
    }
    for force in [&[][..], &["--force"]] {
        let mut args = vec!["export", "png", &bar, "--out", mine.to_str().unwrap()];
        args.extend(["--voxel", "1"]);
        args.extend(force);
        let err = fails(&volcad(&args));
        assert!(
            err.contains("holds other files (notes.txt, photo.jpg) and no export manifest"),
            "{err}"
        );
        assert_eq!(files_in(&mine), ["notes.txt", "photo.jpg"]);
    }
    // A GrabCAD package is one file: the same rule.
    let gcvf = d.join("bar.gcvf");
    let package = |extra: &[&str]| {
        let mut args = vec!["export", "gcvf", &bar, "--out", gcvf.to_str().unwrap()];
        args.extend(["--voxel", "1", "--map", "red=VeroMgnt,blue=VeroCyan"]);
        args.extend(extra);
        volcad(&args)
    };
    ok(&package(&[]));
    let first = std::fs::read(&gcvf).unwrap();
    let err = fails(&package(&["--seed", "7"]));
    assert!(
        err.contains("is already there; add --force to replace it"),
        "{err}"
    );
    assert_eq!(std::fs::read(&gcvf).unwrap(), first, "the package is kept");
    ok(&package(&["--seed", "7", "--force"]));
}
