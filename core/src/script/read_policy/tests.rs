use std::fs;
use std::path::{Path, PathBuf};

use super::*;

/// A scratch tree: the listed folders and files (files get a line of text).
fn tree(dirs: &[&str], files: &[&str]) -> (tempfile::TempDir, PathBuf) {
    let t = tempfile::tempdir().unwrap();
    let root = t.path().canonicalize().unwrap();
    for d in dirs {
        fs::create_dir_all(root.join(d)).unwrap();
    }
    for f in files {
        fs::write(root.join(f), "a\n1\n").unwrap();
    }
    (t, root)
}

fn ok(name: &str, base: &Path, allowed: &[PathBuf], home: Option<&Path>) -> PathBuf {
    resolve(name, base, allowed, home).unwrap_or_else(|e| panic!("{name}: {e}"))
}

#[test]
fn a_git_folder_makes_the_project() {
    let (_t, r) = tree(
        &["p/.git", "p/scripts", "p/data/3d_models"],
        &["p/data/3d_models/part.stl"],
    );
    let got = ok(
        "../data/3d_models/part.stl",
        &r.join("p/scripts"),
        &[],
        None,
    );
    assert_eq!(got, r.join("p/data/3d_models/part.stl"));
    let p = project_of(&r.join("p/scripts"), None);
    assert_eq!(p.root, Some(r.join("p")));
    assert!(p.why.contains(".git"), "{}", p.why);
}

#[test]
fn a_volcad_toml_makes_the_project() {
    let (_t, r) = tree(&["p/a/b", "p/d"], &["p/volcad.toml", "p/d/x.csv"]);
    ok("../../d/x.csv", &r.join("p/a/b"), &[], None);
    assert!(
        project_of(&r.join("p/a/b"), None)
            .why
            .contains("volcad.toml")
    );
}

#[test]
fn without_a_marker_only_the_script_folder_and_the_allowed_ones() {
    let (_t, r) = tree(&["q/s/sub"], &["q/x.csv", "q/s/sub/y.csv"]);
    let base = r.join("q/s");
    ok("sub/y.csv", &base, &[], None);
    let e = resolve("../x.csv", &base, &[], None).unwrap_err();
    for part in [
        "\"../x.csv\"",
        &r.join("q/x.csv").display().to_string(),
        &format!("outside the project folder {}", base.display()),
        "holds .git or volcad.toml",
        &format!("--allow-read {}", r.join("q").display()),
    ] {
        assert!(e.contains(part), "{part} not in: {e}");
    }
    ok("../x.csv", &base, &[r.join("q")], None);
    // An allowed folder elsewhere does not open this one.
    assert!(resolve("../x.csv", &base, &[r.join("q/s/sub")], None).is_err());
}

#[test]
fn absolute_paths_are_refused_even_inside_the_project() {
    let (_t, r) = tree(&["p/.git"], &["p/x.csv"]);
    let abs = r.join("p/x.csv").display().to_string();
    let e = resolve(&abs, &r.join("p"), std::slice::from_ref(&r), None).unwrap_err();
    assert!(e.contains("relative to the script's folder"), "{e}");
}

#[cfg(unix)]
#[test]
fn symbolic_links_cannot_lead_out() {
    let (_t, r) = tree(&["p/.git", "out"], &["out/secret.csv", "p/inside.csv"]);
    let p = r.join("p");
    std::os::unix::fs::symlink(r.join("out/secret.csv"), p.join("link.csv")).unwrap();
    std::os::unix::fs::symlink(r.join("out"), p.join("linkdir")).unwrap();
    std::os::unix::fs::symlink(p.join("inside.csv"), p.join("ok.csv")).unwrap();
    for name in ["link.csv", "linkdir/secret.csv"] {
        let e = resolve(name, &p, &[], None).unwrap_err();
        assert!(
            e.contains(&r.join("out/secret.csv").display().to_string()),
            "{e}"
        );
        assert!(e.contains("outside the project folder"), "{e}");
    }
    assert_eq!(ok("ok.csv", &p, &[], None), p.join("inside.csv"));
}

#[test]
fn the_home_folder_is_never_a_project() {
    // A home kept in git: its .git must not make the whole home readable.
    let (_t, r) = tree(
        &[
            "home/.git",
            "home/.ssh",
            "home/Downloads",
            "home/proj/.git",
            "home/proj/s",
        ],
        &[
            "home/.ssh/id_ed25519",
            "home/Downloads/x.csv",
            "home/top.csv",
            "home/proj/d.csv",
        ],
    );
    let home = r.join("home");
    let dl = home.join("Downloads");
    assert_eq!(project_of(&dl, Some(&home)).root, Some(dl.clone()));
    ok("x.csv", &dl, &[], Some(&home));
    let e = resolve("../.ssh/id_ed25519", &dl, &[], Some(&home)).unwrap_err();
    assert!(e.contains("outside the project folder"), "{e}");
    // A project inside home is found as usual.
    ok("../d.csv", &home.join("proj/s"), &[], Some(&home));
    // A script saved in home itself reads nothing but allowed folders.
    let e = resolve("top.csv", &home, &[], Some(&home)).unwrap_err();
    assert!(e.contains("never a project"), "{e}");
    ok("top.csv", &home, std::slice::from_ref(&home), Some(&home));
    // Nor anything above home.
    assert_eq!(project_of(&r, Some(&home)).root, None);
}

#[test]
fn a_missing_file_names_where_it_was_looked_for() {
    let (_t, r) = tree(&["p/.git"], &[]);
    let e = resolve("nope.stl", &r.join("p"), &[], None).unwrap_err();
    assert!(
        e.contains(&r.join("p/nope.stl").display().to_string()),
        "{e}"
    );
}
