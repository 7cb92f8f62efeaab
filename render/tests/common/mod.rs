//! Shared helpers for the render tests and benchmarks: test designs, image
//! output, pixel lookups.
#![allow(dead_code)]
// A failed setup step (a scratch folder, a file read) fails the test.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::PathBuf;

use glam::{Vec3, Vec4Swizzles};
use volcad_core::Model;
use volcad_render::Camera;

/// Prepare a model from a Rhai script.
pub fn model(src: &str) -> Model {
    let d = volcad_core::script::run_script(
        src,
        "t.rhai",
        &volcad_core::script::ScriptOptions::default(),
    )
    .unwrap_or_else(|e| panic!("script failed: {e}"));
    Model::prepare(&d.root, d.materials.clone()).expect("prepare")
}

/// 15 × 10 × 5 bar, red at +x, blue at −x.
pub const GRADED_BAR: &str = r#"let m = default_materials();
FGrade(["x/15+0.5", "-x/15+0.5"], [m.id("red"), m.id("blue")], true,
       RectPrism(Vec3(0,0,0), Vec3(15,10,5), m.id("gray")))"#;

/// A BCC lattice (0.35 mm struts, 5 mm cells) clipped by a 20 mm sphere.
pub const BCC_SPHERE: &str = r#"let m = default_materials();
Intersection(false, [Tile(GraphLattice(LatticeType::BodyCenteredCubic, Vec3(5,5,5), 0.175, m.id("red"))),
                     Sphere(Vec3(0,0,0), 10, m.id("blue"))])"#;

/// One sphere (a design with one node, for the node-count comparison).
pub const SPHERE: &str = r#"let m = default_materials(); Sphere(Vec3(0,0,0), 10, m.id("blue"))"#;

/// Expected (cyan, magenta, white) fractions of calibration swatch (i, j).
pub fn swatch_fractions(i: usize, j: usize) -> (f64, f64, f64) {
    let c = i as f64 / 11.0;
    let mg = (1.0 - c) * j as f64 / 11.0;
    (c, mg, 1.0 - c - mg)
}

/// 12 × 12 swatches of 25 × 25 × 10 mm graded cyan/magenta/white.
pub fn calibration_sheet() -> String {
    let mut parts = Vec::new();
    for i in 0..12 {
        for j in 0..12 {
            let (c, mg, w) = swatch_fractions(i, j);
            parts.push(format!(
                "FGrade([\"{c:.6}\", \"{mg:.6}\", \"{w:.6}\"], [cyan, magenta, white], true, RectPrism(Vec3({x}, {y}, 0), Vec3(25,25,10), white))",
                x = (i as f64 - 5.5) * 25.0,
                y = (j as f64 - 5.5) * 25.0
            ));
        }
    }
    format!(
        "let m = default_materials(); let cyan = m.id(\"cyan\"); let magenta = m.id(\"magenta\"); let white = m.id(\"white\");\nUnion(false, [{}])",
        parts.join(",\n")
    )
}

/// Where test images go: `$VOLCAD_TEST_OUT`, else `target/test-images/`.
pub fn out_dir() -> PathBuf {
    let dir = std::env::var_os("VOLCAD_TEST_OUT")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../target/test-images"));
    std::fs::create_dir_all(&dir).expect("create test image folder");
    dir
}

/// Save an image for inspection; returns its path.
pub fn save(img: &image::RgbaImage, name: &str) -> PathBuf {
    let path = out_dir().join(name);
    img.save(&path)
        .unwrap_or_else(|e| panic!("save {}: {e}", path.display()));
    eprintln!("wrote {}", path.display());
    path
}

/// Pixel (x right, y down) of world point `p`.
pub fn project(cam: &Camera, p: Vec3, size: [u32; 2]) -> (u32, u32) {
    let aspect = size[0] as f32 / size[1] as f32;
    let c = cam.view_proj(aspect) * p.extend(1.0);
    let ndc = c.xy() / c.w;
    let x = ((ndc.x * 0.5 + 0.5) * size[0] as f32)
        .floor()
        .clamp(0.0, size[0] as f32 - 1.0);
    let y = ((0.5 - ndc.y * 0.5) * size[1] as f32)
        .floor()
        .clamp(0.0, size[1] as f32 - 1.0);
    (x as u32, y as u32)
}

/// Mean RGB (0-255) of the 3 × 3 pixels around (x, y).
pub fn mean3(img: &image::RgbaImage, x: u32, y: u32) -> [f32; 3] {
    let mut s = [0.0f32; 3];
    let mut n = 0.0;
    for yy in y.saturating_sub(1)..(y + 2).min(img.height()) {
        for xx in x.saturating_sub(1)..(x + 2).min(img.width()) {
            let p = img.get_pixel(xx, yy).0;
            for c in 0..3 {
                s[c] += p[c] as f32;
            }
            n += 1.0;
        }
    }
    s.map(|v| v / n)
}

/// Background colour as the bytes the target stores.
pub fn bg_bytes(bg: [f32; 4]) -> [u8; 3] {
    [bg[0], bg[1], bg[2]].map(|c| (c * 255.0).round() as u8)
}

/// True when the pixel differs from the background by more than 3 levels.
pub fn is_fg(img: &image::RgbaImage, x: u32, y: u32, bg: [u8; 3]) -> bool {
    let p = img.get_pixel(x, y).0;
    (0..3).any(|c| (p[c] as i32 - bg[c] as i32).abs() > 3)
}
