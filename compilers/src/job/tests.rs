use super::*;

/// An export destination that does not exist yet, in a scratch folder
/// removed when the test ends (passed or failed).
fn destination() -> (tempfile::TempDir, PathBuf) {
    let scratch = tempfile::tempdir().unwrap();
    let dest = scratch.path().join("out");
    (scratch, dest)
}

#[test]
fn success_renames_and_writes_manifest() {
    let (_scratch, dest) = destination();
    let h = spawn(dest.clone(), "abc".into(), |ctx| {
        std::fs::write(ctx.staging().join("a.txt"), "x").unwrap();
        ctx.progress("writing", 1, 1, "files", 1.0);
        Ok(Summary {
            kind: "test".into(),
            files: vec!["a.txt".into()],
            ..Summary::default()
        })
    });
    let s = h.join().unwrap();
    assert_eq!(s.files, vec!["a.txt"]);
    assert!(dest.join("a.txt").exists());
    let m = std::fs::read_to_string(dest.join("manifest.json")).unwrap();
    assert!(m.contains("\"design_hash\": \"abc\""), "{m}");
    let parent = dest.parent().unwrap();
    assert_eq!(
        std::fs::read_dir(parent).unwrap().count(),
        1,
        "no staging folder left"
    );
}

#[test]
fn cancel_leaves_nothing() {
    let (_scratch, dest) = destination();
    let h = spawn(dest.clone(), "abc".into(), |ctx| {
        std::fs::write(ctx.staging().join("a.txt"), "x").unwrap();
        loop {
            ctx.check_cancel()?;
            std::thread::sleep(Duration::from_millis(1));
        }
    });
    h.cancel();
    assert!(matches!(h.join(), Err(ExportError::Cancelled)));
    assert!(!dest.exists());
    assert_eq!(
        std::fs::read_dir(dest.parent().unwrap()).unwrap().count(),
        0
    );
}

#[test]
fn panic_is_an_error_and_leaves_nothing() {
    let (_scratch, dest) = destination();
    let h = spawn(dest.clone(), "abc".into(), |_| panic!("boom"));
    let e = h.join().unwrap_err().to_string();
    assert!(e.contains("boom"), "{e}");
    assert!(!dest.exists());
}

#[test]
fn refuses_to_replace_foreign_folders() {
    let (_scratch, dest) = destination();
    std::fs::create_dir_all(&dest).unwrap();
    std::fs::write(dest.join("precious.txt"), "x").unwrap();
    let h = spawn(dest.clone(), "abc".into(), |_| Ok(Summary::default()));
    assert!(matches!(h.join(), Err(ExportError::DestinationExists(_))));
    assert!(dest.join("precious.txt").exists());
}

#[cfg(unix)]
#[test]
fn staging_of_dead_processes_is_removed() {
    let scratch = tempfile::tempdir().unwrap();
    let dir = scratch.path();
    // A process that has ended: its id names no process now.
    let mut child = std::process::Command::new("true").spawn().unwrap();
    let dead = child.id();
    child.wait().unwrap();
    let stale = dir.join(format!(".out.partial-{dead}"));
    std::fs::create_dir_all(&stale).unwrap();
    std::fs::write(stale.join("layer_0001.png"), "x").unwrap();
    // This process is alive, and another destination's folder is not ours.
    let alive = dir.join(".out.partial-1");
    let other = dir.join(format!(".other.partial-{dead}"));
    std::fs::create_dir_all(&alive).unwrap();
    std::fs::create_dir_all(&other).unwrap();
    let h = spawn(dir.join("out"), "abc".into(), |_| Ok(Summary::default()));
    h.join().unwrap();
    assert!(!stale.exists());
    assert!(alive.exists() && other.exists());
    assert!(dir.join("out/manifest.json").exists());
}

#[cfg(target_os = "linux")]
#[test]
fn a_folder_that_refuses_the_export_is_named() {
    // /proc takes no new folders, not even from root.
    let h = spawn(PathBuf::from("/proc/volcad-out"), "abc".into(), |_| {
        Ok(Summary::default())
    });
    let e = h.join().unwrap_err().to_string();
    assert!(
        e.starts_with("/proc: cannot write /proc/volcad-out in this folder"),
        "{e}"
    );
    assert!(!e.contains(".partial"), "{e}");
}

#[test]
fn write_errors_name_the_destination_not_the_staging_folder() {
    let (_scratch, dest) = destination();
    let h = spawn(dest.clone(), "abc".into(), |ctx| {
        let path = ctx.staging().join("slice_00001.png");
        Err(ExportError::io(&path, std::io::Error::other("disk full")))
    });
    let e = h.join().unwrap_err().to_string();
    let expected = format!("{}: disk full", dest.join("slice_00001.png").display());
    assert_eq!(e, expected);
    assert!(!dest.exists());
}

#[test]
fn a_file_in_the_path_is_named() {
    let scratch = tempfile::tempdir().unwrap();
    let dir = scratch.path();
    let file = dir.join("plain.txt");
    std::fs::write(&file, "x").unwrap();
    let h = spawn(file.join("out"), "abc".into(), |_| Ok(Summary::default()));
    let e = h.join().unwrap_err().to_string();
    assert!(e.contains("plain.txt: is a file, not a folder"), "{e}");
    assert_eq!(std::fs::read_to_string(&file).unwrap(), "x");
}

#[cfg(unix)]
#[test]
fn devices_and_pipes_are_refused_and_folder_links_followed() {
    let scratch = tempfile::tempdir().unwrap();
    let dir = scratch.path();
    // A symlink stands in for /dev/stdout: refused, and left a symlink.
    let null = dir.join("stdout");
    std::os::unix::fs::symlink("/dev/null", &null).unwrap();
    let fifo = dir.join("pipe");
    assert!(
        std::process::Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .unwrap()
            .success()
    );
    for dest in [&null, &fifo] {
        let h = spawn(dest.clone(), "abc".into(), |_| Ok(Summary::default()));
        let e = h.join().unwrap_err().to_string();
        assert!(e.contains("is a device, pipe or socket"), "{e}");
    }
    assert!(
        std::fs::symlink_metadata(&null)
            .unwrap()
            .file_type()
            .is_symlink()
    );
    // A symlink to an empty folder: the export goes into the folder.
    let real = dir.join("real");
    std::fs::create_dir(&real).unwrap();
    let link = dir.join("link");
    std::os::unix::fs::symlink(&real, &link).unwrap();
    spawn(link.clone(), "abc".into(), |_| Ok(Summary::default()))
        .join()
        .unwrap();
    assert!(
        std::fs::symlink_metadata(&link)
            .unwrap()
            .file_type()
            .is_symlink()
    );
    assert!(real.join("manifest.json").exists());
}

#[test]
fn a_failed_export_removes_the_folders_it_made() {
    let (scratch, _) = destination();
    let dest = scratch.path().join("a/b/out");
    let h = spawn(dest, "abc".into(), |_| {
        Err(ExportError::param("--infill", "gives NaN"))
    });
    assert!(h.join().is_err());
    assert_eq!(std::fs::read_dir(scratch.path()).unwrap().count(), 0);
}
