//! Sharded slice stacks end to end: the `deploy/` recipes run N
//! `volcad export png --shard K/N` and `volcad merge`, and the merged
//! folder is byte for byte the single export's; `volcad merge` refuses
//! shards that do not belong together, before writing anything.

// A failed setup step (a scratch folder, a file read) fails the test.
#![allow(clippy::unwrap_used, clippy::expect_used)]

mod cli_common;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;

use cli_common::{example, fails, ok, runtime_dir, tmp, volcad};

/// Graded bar at 0.25 mm: 60 × 40 × 20 voxels; diffusion and per-material
/// bitmaps, so a shard cut inside a diffusion block and every kind of
/// file are covered.
const OPTS: &[&str] = &[
    "--voxel",
    "0.25",
    "--seed",
    "7",
    "--dither",
    "diffusion",
    "--bitmaps",
];

fn design() -> String {
    example("graded_bar.rhai")
}

fn deploy(script: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../deploy")
        .join(script)
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// Every file under `dir` (relative name → bytes).
fn tree(dir: &Path) -> BTreeMap<String, Vec<u8>> {
    fn walk(root: &Path, dir: &Path, out: &mut BTreeMap<String, Vec<u8>>) {
        for e in std::fs::read_dir(dir).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                walk(root, &p, out);
            } else {
                let rel = p.strip_prefix(root).unwrap().display().to_string();
                out.insert(rel, std::fs::read(&p).unwrap());
            }
        }
    }
    let mut out = BTreeMap::new();
    walk(dir, dir, &mut out);
    out
}

/// `volcad export png` of the design with `OPTS` and `extra` into `out`.
fn export(out: &Path, extra: &[&str]) -> std::process::Output {
    export_with(out, OPTS, extra)
}

fn export_with(out: &Path, opts: &[&str], extra: &[&str]) -> std::process::Output {
    let d = design();
    let mut args = vec!["export", "png", d.as_str(), "--out", s(out)];
    args.extend_from_slice(opts);
    args.extend_from_slice(extra);
    volcad(&args)
}

fn assert_same_tree(merged: &Path, single: &Path) {
    let (m, s) = (tree(merged), tree(single));
    assert_eq!(
        m.keys().collect::<Vec<_>>(),
        s.keys().collect::<Vec<_>>(),
        "file names"
    );
    for (name, bytes) in &s {
        assert!(m[name] == *bytes, "{name} differs from the single export");
    }
    assert_eq!(
        s.len(),
        20 * 3 + 1,
        "20 layers × (RGBA + 2 bitmaps) + manifest"
    );
}

fn run_script(cmd: &mut Command) -> String {
    let o = cmd
        .env("VOLCAD", volcad_tests::bin("volcad"))
        .env("XDG_RUNTIME_DIR", runtime_dir())
        .output()
        .unwrap_or_else(|e| panic!("{cmd:?}: {e} (GNU parallel: apt-get install parallel)"));
    ok(&o)
}

#[test]
fn gnu_parallel_recipe_with_4_shards_matches_the_single_export() {
    let dir = tmp("shard-parallel");
    let single = dir.path().join("single");
    ok(&export(&single, &[]));
    let out = dir.path().join("merged");
    let mut cmd = Command::new(deploy("parallel.sh"));
    cmd.args(["4", s(&out), &design()]).args(OPTS);
    let said = run_script(&mut cmd);
    assert!(said.contains("png: 60 files in"), "{said}");
    assert_same_tree(&out, &single);
    // Each shard's manifest records its range, N, the seed and the hash.
    let hash = manifest(&single)["design_hash"].clone();
    for k in 1..=4 {
        let m = manifest(&dir.path().join(format!("merged.shards/{k}")));
        let p = &m["parameters"];
        assert_eq!(p["shard"], serde_json::json!({"index": k, "count": 4}));
        assert_eq!(p["layers"], serde_json::json!([(k - 1) * 5, k * 5]));
        assert_eq!(p["seed"], 7);
        assert_eq!(m["design_hash"], hash);
    }
}

/// The Slurm script's array-task and merge branches, run as Slurm runs
/// them (by their environment variables), on 3 shards of uneven length.
#[test]
fn slurm_script_tasks_and_merge_match_the_single_export() {
    let dir = tmp("shard-slurm");
    let single = dir.path().join("single");
    ok(&export(&single, &[]));
    let out = dir.path().join("merged");
    let script = deploy("slurm.sh");
    for k in ["3", "1", "2"] {
        let mut cmd = Command::new(&script);
        cmd.args(["3", s(&out), &design()])
            .args(OPTS)
            .env("SLURM_ARRAY_TASK_ID", k)
            .env("SLURM_CPUS_PER_TASK", "1");
        run_script(&mut cmd);
    }
    let mut cmd = Command::new(&script);
    cmd.args(["3", s(&out)]).env("VOLCAD_MERGE", "1");
    run_script(&mut cmd);
    assert_same_tree(&out, &single);
}

fn manifest(dir: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(dir.join("manifest.json")).unwrap()).unwrap()
}

/// `volcad merge OUT dirs...` fails; OUT and any staging folder are absent.
fn merge_fails(out: &Path, dirs: &[&Path]) -> String {
    let mut args = vec!["merge", s(out)];
    args.extend(dirs.iter().map(|d| s(d)));
    let err = fails(&volcad(&args));
    let parent = out.parent().unwrap();
    let left: Vec<String> = std::fs::read_dir(parent)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().to_string())
        .filter(|n| n.contains("out"))
        .collect();
    assert!(left.is_empty(), "left behind: {left:?}");
    err
}

#[test]
fn merge_refuses_shards_that_do_not_belong_together() {
    let dir = tmp("shard-refuse");
    let d = dir.path();
    let shard = |k: usize, opts: &[&str], extra: &[&str]| {
        let p = d.join(format!("s{k}{}", extra.join("").replace(['-', ' '], "")));
        let spec = format!("{k}/4");
        let mut a = vec!["--shard", spec.as_str()];
        a.extend_from_slice(extra);
        ok(&export_with(&p, opts, &a));
        p
    };
    let [s1, s2, s3, s4] = [1, 2, 3, 4].map(|k| shard(k, OPTS, &[]));
    let out = d.join("out");
    // Another seed for shard 2 (7 is OPTS' seed).
    let seed_8: Vec<&str> = OPTS
        .iter()
        .map(|a| if *a == "7" { "8" } else { a })
        .collect();
    let s2_seed = d.join("s2seed");
    ok(&export_with(&s2_seed, &seed_8, &["--shard", "2/4"]));
    let e = merge_fails(&out, &[&s1, &s2_seed, &s3, &s4]);
    assert!(
        e.contains("are not shards of one export: seed is 8 in") && e.contains("but 7 in"),
        "{e}"
    );
    // Shard 3 missing: its layers are named, and which shard holds them.
    let e = merge_fails(&out, &[&s1, &s2, &s4]);
    assert!(
        e.contains("layers 10..=14 are missing (shard 3/4: not given, or not finished)"),
        "{e}"
    );
    // Shard 2 twice: the overlap is named with both folders.
    let copy = d.join("s2copy");
    ok(&Command::new("cp")
        .args(["-r", s(&s2), s(&copy)])
        .output()
        .unwrap());
    let e = merge_fails(&out, &[&s1, &s2, &copy, &s3, &s4]);
    assert!(e.contains("layers 5..=9 are in both"), "{e}");
    assert!(e.contains("s2copy"), "{e}");
    // Another design parameter: another design hash.
    let d2 = shard(2, OPTS, &["--param", "length=16"]);
    let e = merge_fails(&out, &[&s1, &d2, &s3, &s4]);
    assert!(e.contains("design hash"), "{e}");
    // A listed file gone from a shard.
    std::fs::remove_file(copy.join("slice_00007.png")).unwrap();
    let e = merge_fails(&out, &[&s1, &copy, &s3, &s4]);
    assert!(
        e.contains("1 file(s) its manifest lists are missing") && e.contains("slice_00007.png"),
        "{e}"
    );
    // The output may not be (or hold) a shard folder.
    let e = fails(&volcad(&["merge", s(&s1), s(&s1), s(&s2), s(&s3), s(&s4)]));
    assert!(e.contains("would replace shard folder"), "{e}");
    assert!(s1.join("manifest.json").exists());
    // The good set merges, in any order.
    ok(&volcad(&["merge", s(&out), s(&s4), s(&s2), s(&s1), s(&s3)]));
    let single = d.join("single");
    ok(&export(&single, &[]));
    assert_same_tree(&out, &single);
}

#[test]
fn bad_shard_options_are_refused_before_any_work() {
    let dir = tmp("shard-options");
    let out = dir.path().join("out");
    for (spec, expected) in [
        ("0/4", "--shard: 0/4: K counts from 1 to N"),
        ("5/4", "the last 4/4"),
        ("2", "expected K/N"),
        ("a/4", "K \"a\" is not a whole number"),
        ("1/0", "N, the number of shards, must be at least 1"),
        ("1/21", "the grid has 20 layer(s), fewer than 21 shards"),
    ] {
        let e = fails(&export(&out, &["--shard", spec]));
        assert!(e.contains(expected), "{spec}: {e}");
    }
    let e = fails(&export(&out, &["--shard", "1/2", "--layers", "0..3"]));
    assert!(e.contains("give one of them"), "{e}");
    let d = design();
    let e = fails(&volcad(&[
        "export",
        "mesh",
        &d,
        "--voxel",
        "1",
        "--out",
        s(&out),
        "--shard",
        "1/2",
    ]));
    assert!(
        e.contains("--shard does not apply to `volcad export mesh`"),
        "{e}"
    );
    assert!(!out.exists());
    // A folder that is not a layer stack is not merged.
    let mesh = dir.path().join("mesh");
    ok(&volcad(&[
        "export",
        "mesh",
        &d,
        "--voxel",
        "1",
        "--formats",
        "stl",
        "--out",
        s(&mesh),
    ]));
    let e = merge_fails(&out, &[&mesh]);
    assert!(
        e.contains("a mesh export; only layer stacks (png, vat)"),
        "{e}"
    );
    let e = merge_fails(&out, &[dir.path()]);
    assert!(e.contains("holds no readable manifest.json"), "{e}");
}
