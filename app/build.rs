//! Embeds `assets/examples/*.rhai` into the studio (its Examples menu), so
//! the binary works wherever it is copied. Writes `$OUT_DIR/examples.rs`.

use std::path::Path;

/// A failure here stops the build with cargo's report of the error.
fn main() -> std::io::Result<()> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../assets/examples");
    println!("cargo:rerun-if-changed={}", dir.display());
    let mut files: Vec<_> = std::fs::read_dir(&dir)
        .map(|d| d.filter_map(Result::ok).map(|e| e.path()).collect())
        .unwrap_or_default();
    files.retain(|p| p.extension().is_some_and(|e| e == "rhai"));
    files.sort();
    let mut out = String::from(
        "/// (file name, text) of each bundled example, sorted by name.\npub static EMBEDDED: &[(&str, &str)] = &[\n",
    );
    for p in &files {
        let name = p.file_name().and_then(|n| n.to_str()).unwrap_or_default();
        let abs = p.canonicalize().unwrap_or_else(|_| p.clone());
        out.push_str(&format!(
            "    ({name:?}, include_str!({:?})),\n",
            abs.display().to_string()
        ));
        println!("cargo:rerun-if-changed={}", p.display());
    }
    out.push_str("];\n");
    let out_dir = std::env::var("OUT_DIR")
        .map_err(|e| std::io::Error::other(format!("OUT_DIR (set by cargo): {e}")))?;
    let dest = Path::new(&out_dir).join("examples.rs");
    std::fs::write(&dest, out)
        .map_err(|e| std::io::Error::other(format!("writing {}: {e}", dest.display())))
}
