//! Every shader the GPU is given parses and validates with naga (no GPU
//! needed), and is made of the WGSL files: the full-screen triangle
//! (`fullscreen.wgsl`, also valid alone) prepended to each pass's file.

use std::path::Path;

use wgpu::naga;

fn validate(src: &str, path: &str) {
    let module = naga::front::wgsl::parse_str(src)
        .unwrap_or_else(|e| panic!("{}", e.emit_to_string_with_path(src, path)));
    let mut validator = naga::valid::Validator::new(
        naga::valid::ValidationFlags::all(),
        naga::valid::Capabilities::empty(),
    );
    if let Err(e) = validator.validate(&module) {
        panic!("{}", e.emit_to_string_with_path(src, path));
    }
}

#[test]
fn every_shader_validates() {
    validate(
        volcad_render::RENDER_SHADER,
        "fullscreen.wgsl + raymarch.wgsl",
    );
    validate(volcad_render::BLIT_SHADER, "fullscreen.wgsl + blit.wgsl");
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("src/shaders");
    let full = std::fs::read_to_string(dir.join("fullscreen.wgsl")).unwrap();
    validate(&full, "fullscreen.wgsl");
}

#[test]
fn the_embedded_shaders_are_the_files() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("src/shaders");
    let read = |name: &str| std::fs::read_to_string(dir.join(name)).unwrap();
    let full = read("fullscreen.wgsl");
    assert_eq!(
        format!("{full}{}", read("raymarch.wgsl")),
        volcad_render::RENDER_SHADER
    );
    assert_eq!(
        format!("{full}{}", read("blit.wgsl")),
        volcad_render::BLIT_SHADER
    );
    let mut files: Vec<String> = std::fs::read_dir(&dir)
        .expect("shader folder")
        .map(|e| {
            e.expect("dir entry")
                .file_name()
                .to_string_lossy()
                .into_owned()
        })
        .filter(|n| n.ends_with(".wgsl"))
        .collect();
    files.sort();
    assert_eq!(
        files,
        ["blit.wgsl", "fullscreen.wgsl", "raymarch.wgsl"],
        "a new WGSL file is validated only once a shader embeds it"
    );
}
