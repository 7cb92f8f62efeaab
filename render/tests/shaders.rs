//! Every WGSL file parses and validates with naga (no GPU needed).

use std::path::Path;

use wgpu::naga;

fn validate(path: &Path) {
    let src =
        std::fs::read_to_string(path).unwrap_or_else(|e| panic!("read {}: {e}", path.display()));
    let module = naga::front::wgsl::parse_str(&src).unwrap_or_else(|e| {
        panic!(
            "{}",
            e.emit_to_string_with_path(&src, path.to_string_lossy().as_ref())
        )
    });
    let mut validator = naga::valid::Validator::new(
        naga::valid::ValidationFlags::all(),
        naga::valid::Capabilities::empty(),
    );
    if let Err(e) = validator.validate(&module) {
        panic!(
            "{}",
            e.emit_to_string_with_path(&src, path.to_string_lossy().as_ref())
        );
    }
}

#[test]
fn every_wgsl_file_validates() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("src/shaders");
    let mut count = 0;
    for entry in std::fs::read_dir(&dir).expect("shader folder") {
        let path = entry.expect("dir entry").path();
        if path.extension().is_some_and(|e| e == "wgsl") {
            validate(&path);
            count += 1;
        }
    }
    assert!(count >= 1, "no .wgsl files in {}", dir.display());
}

#[test]
fn the_embedded_shaders_are_the_files() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("src/shaders");
    let read = |name: &str| std::fs::read_to_string(dir.join(name)).unwrap();
    assert_eq!(read("raymarch.wgsl"), volcad_render::RENDER_SHADER);
    assert_eq!(read("blit.wgsl"), volcad_render::BLIT_SHADER);
}
