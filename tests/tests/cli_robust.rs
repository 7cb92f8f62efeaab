//! Issue 39's command-line reproducers (items 2, 8, 9): pipes and special
//! files, `--layers`, inputs that were accepted or hung, error places and
//! sizes, exit statuses and option values. Each failed on the command line
//! before the fix.

// A failed setup step (a scratch folder, a file read) fails the test.
#![allow(clippy::unwrap_used, clippy::expect_used)]

mod cli_common;

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use cli_common::{example, fails, ok, runtime_dir, tmp, volcad};

/// A one-material cube (10 mm, red), the cheapest design to load.
fn cube() -> String {
    example("hello_cube.rhai")
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// The entries of `dir`, sorted.
fn entries(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().to_string())
        .collect();
    v.sort();
    v
}

/// `volcad ARGS`, killed after `limit` (a hang is a failure, not a stuck test).
fn volcad_within(args: &[&str], limit: Duration) -> std::process::Output {
    let child = Command::new(volcad_tests::bin("volcad"))
        .args(args)
        .env("XDG_RUNTIME_DIR", runtime_dir())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let pid = child.id();
    let start = Instant::now();
    let watcher = std::thread::spawn(move || {
        while start.elapsed() < limit {
            std::thread::sleep(Duration::from_millis(50));
        }
        let _ = Command::new("kill").args(["-9", &pid.to_string()]).status();
    });
    let out = child.wait_with_output().unwrap();
    assert!(
        start.elapsed() < limit,
        "volcad {args:?} ran past {limit:?} (a hang)"
    );
    drop(watcher);
    out
}

#[cfg(unix)]
fn mkfifo(path: &Path) {
    let st = Command::new("mkfifo").arg(path).status().unwrap();
    assert!(st.success(), "mkfifo {}", path.display());
}

fn points(dir: &Path, text: &str) -> PathBuf {
    let p = dir.join("points.csv");
    std::fs::write(&p, text).unwrap();
    p
}

#[test]
fn a_closed_pipe_ends_every_command_quietly() {
    // The reader goes before volcad writes: every write meets EPIPE.
    let scratch = tmp("epipe");
    let pts = points(scratch.path(), "x,y,z\n0,0,0\n1,1,1\n");
    let bar = example("graded_bar.rhai");
    let runs: [Vec<&str>; 3] = [
        vec!["info", &bar],
        vec!["eval", &bar, "0", "0", "0"],
        vec!["sample", &bar, "--points", s(&pts), "--out", "-"],
    ];
    for args in runs {
        let mut child = Command::new(volcad_tests::bin("volcad"))
            .args(&args)
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        drop(child.stdout.take());
        let out = child.wait_with_output().unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(0), "{args:?}: {err}");
        assert!(
            !err.contains("panicked") && !err.contains("Broken pipe"),
            "{err}"
        );
    }
}

#[test]
fn out_dash_is_standard_output() {
    let scratch = tmp("stdout");
    let d = scratch.path();
    let pts = points(d, "x,y,z\n0,0,0\n");
    let o = Command::new(volcad_tests::bin("volcad"))
        .current_dir(d)
        .args(["sample", &cube(), "--points", "points.csv", "--out", "-"])
        .output()
        .unwrap();
    let out = ok(&o);
    assert_eq!(out, "x,y,z,distance,red\n0,0,0,-5,1\n");
    assert_eq!(entries(d), ["points.csv"], "no file named `-`");
    let _ = pts;
}

#[cfg(unix)]
#[test]
fn devices_pipes_and_their_symlinks_are_written_in_place() {
    let scratch = tmp("devices");
    let d = scratch.path();
    let pts = points(d, "x,y,z\n0,0,0\n");
    // A symlink stands in for /dev/stdout: it must stay a symlink.
    let null = d.join("stdout");
    std::os::unix::fs::symlink("/dev/null", &null).unwrap();
    ok(&volcad(&[
        "sample",
        &cube(),
        "--points",
        s(&pts),
        "--out",
        s(&null),
    ]));
    assert!(
        std::fs::symlink_metadata(&null)
            .unwrap()
            .file_type()
            .is_symlink()
    );
    // A FIFO gets the CSV through the pipe and stays a FIFO.
    let fifo = d.join("pipe");
    mkfifo(&fifo);
    let f2 = fifo.clone();
    let reader = std::thread::spawn(move || std::fs::read_to_string(f2).unwrap());
    ok(&volcad(&[
        "sample",
        &cube(),
        "--points",
        s(&pts),
        "--out",
        s(&fifo),
    ]));
    assert_eq!(reader.join().unwrap(), "x,y,z,distance,red\n0,0,0,-5,1\n");
    {
        use std::os::unix::fs::FileTypeExt;
        let t = std::fs::symlink_metadata(&fifo).unwrap().file_type();
        assert!(t.is_fifo());
    }
    // An export writes a folder: a device or pipe is refused, left as it was.
    for dest in [&null, &fifo] {
        let err = fails(&volcad_within(
            &["export", "mesh", &cube(), "--voxel", "2", "--out", s(dest)],
            Duration::from_secs(60),
        ));
        assert!(err.contains("is a device, pipe or socket"), "{err}");
    }
    assert!(
        std::fs::symlink_metadata(&null)
            .unwrap()
            .file_type()
            .is_symlink()
    );
    assert_eq!(entries(d), ["pipe", "points.csv", "stdout"]);
}

#[test]
fn layers_take_inclusive_ranges_and_say_which_are_written() {
    let scratch = tmp("layers");
    let d = scratch.path();
    let help = ok(&volcad(&["export", "--help"]));
    assert!(help.contains("A..=B"), "{help}");
    let out = d.join("png");
    let o = volcad(&[
        "export",
        "png",
        &cube(),
        "--voxel",
        "1",
        "--layers",
        "2..=4",
        "--out",
        s(&out),
    ]);
    ok(&o);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("layers 2 to 4 included (3 of "), "{err}");
    let pngs: Vec<String> = entries(&out)
        .into_iter()
        .filter(|f| f.ends_with(".png"))
        .collect();
    assert_eq!(pngs.len(), 3, "{pngs:?}");
    let err = fails(&volcad(&[
        "export",
        "png",
        &cube(),
        "--voxel",
        "1",
        "--layers",
        "4..4",
        "--out",
        s(&out),
    ]));
    assert!(err.contains("A..=B writes A to B"), "{err}");
}

#[cfg(unix)]
#[test]
fn a_fifo_or_folder_as_an_input_is_refused_not_waited_on() {
    let scratch = tmp("fifo-in");
    let d = scratch.path();
    let fifo = d.join("design.rhai");
    mkfifo(&fifo);
    let err = fails(&volcad_within(&["info", s(&fifo)], Duration::from_secs(30)));
    assert!(
        err.contains("is a pipe or device; give the design script as a regular file"),
        "{err}"
    );
    let err = fails(&volcad_within(
        &["sample", &cube(), "--points", s(d), "--out", "-"],
        Duration::from_secs(30),
    ));
    assert!(
        err.contains("is a folder; give the points as a regular file"),
        "{err}"
    );
}

#[test]
fn values_that_mean_nothing_are_refused() {
    let scratch = tmp("values");
    let d = scratch.path();
    let cube = cube();
    let missing = d.join("missing.rhai");
    // (command line, what the message must say); `OUT` is a path in `d`.
    let cases: [(&[&str], &str); 8] = [
        // Bricks are sized by --voxel: tet options would be ignored.
        (
            &["export", "fea", &cube, "--sizing", "0/0"],
            "--sizing does not apply to bricks",
        ),
        (
            &["export", "fea", &cube, "--min-cell", "1"],
            "--min-cell does not apply to bricks",
        ),
        // With tetrahedra, NaN sizes are refused as `--infill '0/0'` is.
        (
            &[
                "export",
                "fea",
                &cube,
                "--element",
                "c3d4",
                "--sizing",
                "0/0",
            ],
            "--sizing: \"0/0\" gives NaN at h = 0",
        ),
        // Negative numbers are values, and then refused for what they are.
        (
            &[
                "export",
                "fea",
                &cube,
                "--element",
                "c3d4",
                "--min-cell",
                "-1",
            ],
            "--min-cell: must be a length > 0 mm, got -1",
        ),
        (
            &["export", "png", &cube, "--voxel", "1e300"],
            "each voxel size must be within",
        ),
        (
            &["render", &cube, "--cut", "z=nan"],
            "--cut z=nan: \"nan\" is not a finite number",
        ),
        (
            &["bench", s(&missing), "--no-exports"],
            "1 design could not be measured",
        ),
        (
            &["eval", &cube, "-1", "nan", "0"],
            "Y = NaN: give a finite coordinate",
        ),
    ];
    let out = d.join("out");
    for (args, says) in cases {
        let mut a = args.to_vec();
        if a[0] != "bench" && a[0] != "eval" {
            a.extend(["--out", s(&out)]);
        }
        let err = fails(&volcad(&a));
        assert!(err.contains(says), "{a:?}: {err}");
    }
    assert_eq!(entries(d), Vec::<String>::new(), "nothing written");
}

#[test]
fn usage_errors_exit_2_and_help_says_so() {
    let o = volcad(&["info"]);
    assert_eq!(o.status.code(), Some(2));
    let help = ok(&volcad(&["--help"]));
    assert!(help.contains("2 for usage errors"), "{help}");
}

#[test]
fn a_failed_export_leaves_no_folder_behind() {
    let scratch = tmp("parent");
    let d = scratch.path();
    let out = d.join("a/b/out");
    let err = fails(&volcad(&[
        "export",
        "mesh",
        &example("graded_bar.rhai"),
        "--voxel",
        "0.5",
        "--infill",
        "0/0",
        "--out",
        s(&out),
    ]));
    assert!(err.contains("--infill"), "{err}");
    assert_eq!(entries(d), Vec::<String>::new(), "no a/b made");
}

#[test]
fn single_file_outputs_leave_nothing_on_failure() {
    let scratch = tmp("leftovers");
    let d = scratch.path();
    let pts = points(d, "x,y,z\n0,0,0\n");
    let folder = d.join("existing");
    std::fs::create_dir(&folder).unwrap();
    let err = fails(&volcad(&[
        "sample",
        &cube(),
        "--points",
        s(&pts),
        "--out",
        s(&folder),
    ]));
    assert!(err.contains("is a folder; give a file name in it"), "{err}");
    assert!(!err.contains("partial"), "{err}");
    let err = fails(&volcad(&["render", &cube(), "--out", s(&folder)]));
    assert!(err.contains("is a folder"), "{err}");
    // A result whose deck lacks a node: no CSV holding only the header.
    let frd = d.join("job.frd");
    std::fs::write(
        &frd,
        "    2C                                                                   1\n \
         -1         1 0.00000E+00 0.00000E+00 0.00000E+00\n \
         -1         2 1.00000E+00 0.00000E+00 0.00000E+00\n -3\n  \
         100C                                                                   1\n \
         -4  DISP        4    1\n \
         -1         1 1.00000E-03 0.00000E+00 0.00000E+00\n \
         -1         2 2.00000E-03 0.00000E+00 0.00000E+00\n -3\n",
    )
    .unwrap();
    let inp = d.join("job.inp");
    std::fs::write(&inp, "*NODE\n1, 0, 0, 0\n").unwrap();
    let csv = d.join("result.csv");
    let err = fails(&volcad(&[
        "fea-result",
        s(&frd),
        "--inp",
        s(&inp),
        "--out",
        s(&csv),
    ]));
    assert!(
        err.contains("node 2 has a result but no coordinates"),
        "{err}"
    );
    assert!(err.contains("job.inp: node 2"), "no line 0 named: {err}");
    assert_eq!(entries(d), ["existing", "job.frd", "job.inp", "points.csv"]);
    // The matching deck: the CSV, here on standard output.
    std::fs::write(&inp, "*NODE\n1, 0, 0, 0\n2, 1, 0, 0\n").unwrap();
    let out = ok(&volcad(&[
        "fea-result",
        s(&frd),
        "--inp",
        s(&inp),
        "--out",
        "-",
    ]));
    assert_eq!(
        out,
        "node_id,x,y,z,dx,dy,dz\n1,0,0,0,0.001,0,0\n2,1,0,0,0.002,0,0\n"
    );
}

#[test]
fn script_errors_give_the_right_advice_and_stay_short() {
    let scratch = tmp("advice");
    let d = scratch.path();
    let run = |name: &str, text: &str| {
        let p = d.join(name);
        std::fs::write(&p, text).unwrap();
        volcad(&["info", s(&p)])
    };
    let err = fails(&run(
        "method.rhai",
        "let m = default_materials();\nlet r = m.i(\"red\");\nSphere(Vec3(0,0,0), 1, r)\n",
    ));
    assert!(
        err.contains("method.rhai:2:") && err.contains("did you mean `id`?"),
        "{err}"
    );
    let err = fails(&run(
        "range.rhai",
        "let n = 0;\nfor i in 0.5..3 { n += 1; }\nSphere(Vec3(0,0,0), 1, 1)\n",
    ));
    assert!(
        err.contains("range.rhai:2:") && err.contains("takes integers"),
        "{err}"
    );
    assert!(!err.contains("did you mean"), "{err}");
    // A 1 MB unknown name is quoted in part, not whole.
    let long = "a".repeat(1_000_000);
    let err = fails(&run("long.rhai", &format!("let x = {long};\nx\n")));
    assert!(err.len() < 2_000, "{} bytes of error", err.len());
    let pts = points(d, &format!("x,y,z\n{long},0,0\n"));
    let err = fails(&volcad(&[
        "sample",
        &cube(),
        "--points",
        s(&pts),
        "--out",
        "-",
    ]));
    assert!(err.len() < 2_000 && err.contains("points.csv:2:"), "{err}");
}

#[test]
fn a_utf8_bom_is_accepted_in_scripts_csv_and_material_json() {
    let scratch = tmp("bom");
    let d = scratch.path();
    let json = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../assets/materials/default.json"),
    )
    .unwrap();
    std::fs::write(d.join("mats.json"), format!("\u{feff}{json}")).unwrap();
    let design = d.join("bom.rhai");
    std::fs::write(
        &design,
        "\u{feff}let m = load_materials(\"mats.json\");\nSphere(Vec3(0,0,0), 2, m.id(\"blue\"))\n",
    )
    .unwrap();
    let pts = points(d, "\u{feff}x,y,z\r\n0,0,0\r\n");
    let out = ok(&volcad(&[
        "sample",
        s(&design),
        "--points",
        s(&pts),
        "--out",
        "-",
    ]));
    assert_eq!(out, "x,y,z,distance,blue\n0,0,0,-2,1\n");
}
