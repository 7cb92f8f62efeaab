//! Bake and frame timings (plain timers, `harness = false`):
//!
//! `cargo bench -p volcad-render` prints, per example and test design, the bake time at
//! 64/128/256 voxels, the time to a first coarse image (bake 64 + upload +
//! one frame), and the frame time at 1280×800 in Solid and Volume modes;
//! then the thin-feature coverage of the BCC sphere with and without the
//! bias. Images go to `target/bench-images/`. Set `VOLCAD_BENCH_QUICK=1` to
//! skip the 256 level; `cargo bench -p volcad-render -- bunny` runs only
//! the designs whose name contains `bunny`.

// A failed setup step fails the benchmark run.
#![allow(clippy::unwrap_used, clippy::expect_used)]

#[path = "../tests/common/mod.rs"]
mod common;

use std::time::Instant;

use common::*;
use glam::Vec3;
use volcad_core::Model;
use volcad_render::{Camera, Offscreen, StandardView, ViewMode, ViewSettings, bake_blocking};

const FRAME: [u32; 2] = [1280, 800];
const FRAMES: usize = 3;

/// The same sphere as `SPHERE` as a union of 200 identical spheres: the
/// geometry (so the baked textures) are identical, the node count is not.
fn many_node_sphere() -> String {
    let spheres = vec!["Sphere(Vec3(0,0,0), 10, m.id(\"blue\"))"; 200];
    format!(
        "let m = default_materials(); Union(false, [{}])",
        spheres.join(", ")
    )
}

/// The examples in `assets/examples`, run from their files (they read data
/// beside them), sorted by name.
fn examples() -> Vec<(String, Model)> {
    let dir = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../assets/examples");
    let mut files: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e == "rhai"))
        .collect();
    files.sort();
    files
        .iter()
        .map(|path| {
            let src = std::fs::read_to_string(path).unwrap();
            let name = path.file_stem().unwrap().to_string_lossy().to_string();
            let opts = volcad_core::script::ScriptOptions::for_file(path);
            let d = volcad_core::script::run_script(&src, &name, &opts).unwrap();
            (name, Model::prepare(&d.root, d.materials.clone()).unwrap())
        })
        .collect()
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(|a, b| a.total_cmp(b));
    v[v.len() / 2]
}

fn main() {
    let quick = std::env::var_os("VOLCAD_BENCH_QUICK").is_some();
    let levels: &[u32] = if quick { &[64, 128] } else { &[64, 128, 256] };
    let out = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../target/bench-images");
    std::fs::create_dir_all(&out).unwrap();
    let mut off = Offscreen::new(FRAME).expect("a GPU adapter (lavapipe) is required");
    println!(
        "adapter: {}; {} rayon threads",
        off.adapter(),
        rayon::current_num_threads()
    );

    // Every example (optionally filtered by a name fragment), then the
    // 1-node / 200-node sphere pair that shows frame time does not depend
    // on node count.
    let filter = std::env::args().skip(1).find(|a| !a.starts_with('-'));
    let mut designs: Vec<(String, Model)> = examples()
        .into_iter()
        .chain([
            ("sphere_1_node".to_owned(), model(SPHERE)),
            ("sphere_200_nodes".to_owned(), model(&many_node_sphere())),
        ])
        .collect();
    if let Some(f) = &filter {
        designs.retain(|(n, _)| n.contains(f.as_str()));
    }
    println!(
        "{:<18} {:>6} {:>9} {:>10} {:>10} {:>10} {:>10} {:>10}",
        "design", "level", "bake s", "voxels", "solid ms", "half ms", "volume ms", "iso ms"
    );
    let mut reference: Vec<Vec<u16>> = Vec::new();
    for (name, model) in &designs {
        let name = name.as_str();
        let solid = ViewSettings {
            camera: Camera::fit(&model.bbox(), StandardView::Iso),
            ..Default::default()
        };
        first_image(&mut off, name, model, &solid);
        for &level in levels {
            let b = bake_blocking(model, level).unwrap();
            off.upload(&b);
            let volume = ViewSettings {
                mode: ViewMode::Volume,
                ..solid.clone()
            };
            off.draw_timed(&solid).unwrap(); // warm-up
            let s_ms = median(
                (0..FRAMES)
                    .map(|_| off.draw_timed(&solid).unwrap() * 1e3)
                    .collect(),
            );
            let v_ms = median(
                (0..FRAMES)
                    .map(|_| off.draw_timed(&volume).unwrap() * 1e3)
                    .collect(),
            );
            let half = ViewSettings {
                render_scale: 0.5,
                ..solid.clone()
            };
            let h_ms = median(
                (0..FRAMES)
                    .map(|_| off.draw_timed(&half).unwrap() * 1e3)
                    .collect(),
            );
            let iso = ViewSettings {
                mode: ViewMode::Iso {
                    material_index: 0,
                    level: 0.5,
                },
                ..solid.clone()
            };
            let i_ms = median(
                (0..FRAMES)
                    .map(|_| off.draw_timed(&iso).unwrap() * 1e3)
                    .collect(),
            );
            println!(
                "{name:<18} {level:>6} {:>9.3} {:>10} {s_ms:>10.1} {h_ms:>10.1} {v_ms:>10.1} {i_ms:>10.1}",
                b.bake_seconds,
                b.voxel_count()
            );
            if name == "sphere_1_node" {
                reference.push(b.distance.clone());
            } else if name == "sphere_200_nodes" {
                let same = reference.get(levels.iter().position(|l| *l == level).unwrap())
                    == Some(&b.distance);
                println!(
                    "{:<18} {level:>6} distance texture identical to sphere_1_node: {same}",
                    ""
                );
            }
            if level == 128 {
                off.render(&solid)
                    .unwrap()
                    .save(out.join(format!("{name}_solid.png")))
                    .unwrap();
                off.render(&volume)
                    .unwrap()
                    .save(out.join(format!("{name}_volume.png")))
                    .unwrap();
            }
        }
    }

    if filter.is_some() {
        return;
    }
    thin_feature_coverage(&mut off, levels, &out);
    println!("images in {}", out.display());
}

/// The time to a first coarse image (bake 64 + upload + one frame and its
/// readback), at full and at half render scale.
fn first_image(off: &mut Offscreen, name: &str, model: &Model, solid: &ViewSettings) {
    // Coarse first image: bake 64 + upload + one frame.
    let t = Instant::now();
    let b = bake_blocking(model, 64).unwrap();
    let t_bake = t.elapsed().as_secs_f64();
    off.upload(&b);
    let t_upload = t.elapsed().as_secs_f64();
    off.render(solid).unwrap();
    let first = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let b = bake_blocking(model, 64).unwrap();
    off.upload(&b);
    off.render(&ViewSettings {
        render_scale: 0.5,
        ..solid.clone()
    })
    .unwrap();
    let first_half = t.elapsed().as_secs_f64();
    println!(
        "{name:<18} first coarse image (bake 64 + upload + 1280x800 frame + readback): {first:.3} s (bake {t_bake:.3}, upload {:.3}, frame {:.3}), at render_scale 0.5: {first_half:.3} s",
        t_upload - t_bake,
        first - t_upload
    );
}

/// Thin features: coverage of the BCC sphere's disk (front, orthographic)
/// by level and bias. The finest level without bias is the reference.
fn thin_feature_coverage(off: &mut Offscreen, levels: &[u32], out: &std::path::Path) {
    let model = model(BCC_SPHERE);
    let mut cam = Camera::fit(&model.bbox(), StandardView::Front);
    cam.orthographic = true;
    let s = ViewSettings::plain(cam);
    let bg = bg_bytes(s.background);
    let (cx, cy) = project(&cam, Vec3::ZERO, FRAME);
    let (ex, _) = project(&cam, Vec3::X * 10.0, FRAME);
    let r = (ex as f32 - cx as f32).abs() * 0.95;
    println!("BCC sphere (0.35 mm struts, 20 mm sphere): coverage of the disk, front view");
    for &level in levels {
        let b = bake_blocking(&model, level).unwrap();
        off.upload(&b);
        for bias in [0.0, volcad_render::THIN_BIAS_VOXELS, 0.35] {
            off.renderer_mut().set_thin_bias_voxels(bias);
            let img = off.render(&s).unwrap();
            let (mut inside, mut hit) = (0u32, 0u32);
            for y in 0..FRAME[1] {
                for x in 0..FRAME[0] {
                    if ((x as f32 - cx as f32).powi(2) + (y as f32 - cy as f32).powi(2)).sqrt() < r
                    {
                        inside += 1;
                        hit += is_fg(&img, x, y, bg) as u32;
                    }
                }
            }
            println!(
                "  level {level:>3} (voxel {:.3} mm) bias {bias:.2} voxel: {:.1} %",
                b.voxel_size_mm,
                100.0 * hit as f32 / inside as f32
            );
            img.save(out.join(format!(
                "bcc_front_{level}_bias{:02}.png",
                (bias * 100.0) as u32
            )))
            .unwrap();
        }
        off.renderer_mut()
            .set_thin_bias_voxels(volcad_render::THIN_BIAS_VOXELS);
    }
}
