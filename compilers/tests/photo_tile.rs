//! The photo tile example (`ImageField` colour) as a J750 full-colour
//! stack: a layer near the top, read back through the resins' colours,
//! reproduces the photograph block by block; byte-identical on one and
//! two threads.
// Test helpers fail the test with a message where a value is missing.
#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use std::collections::BTreeMap;
use std::path::PathBuf;
use std::sync::Arc;

use common::{decode, read_tree, run, tmp};
use volcad_compilers::color::{CHANNELS, ColorPlan};
use volcad_compilers::png_stack::{self, PngParams, estimate, export_png_stack};
use volcad_core::Model;
use volcad_core::script::{ScriptOptions, model_of};

/// Photo pixels per side of a block compared.
const BLOCK: u32 = 16;

fn examples() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../assets/examples")
}

fn tile() -> Arc<Model> {
    let path = examples().join("photo_tile.rhai");
    let src = std::fs::read_to_string(&path).unwrap();
    Arc::new(model_of(&src, "photo_tile.rhai", &ScriptOptions::for_file(&path)).unwrap())
}

/// The J750 grid in full colour, `layers` only.
fn params(m: &Model, top_layers: usize, threads: Option<usize>) -> PngParams {
    let mut p = PngParams {
        voxel: png_stack::preset("j750").unwrap().voxel,
        full_color: true,
        threads,
        ..PngParams::default()
    };
    let nz = estimate(m, &p).unwrap().grid.dims[2];
    // Layers a few below the top face (z about 1.3 of 1.5 mm): the flat
    // top, clear of the rounded edge's narrowing.
    p.layers = Some(nz - 5 - top_layers..nz - 5);
    p
}

fn export(m: &Arc<Model>, p: &PngParams) -> BTreeMap<String, Vec<u8>> {
    let dir = tmp();
    let (m2, p2) = (m.clone(), p.clone());
    run(&dir.path().join("out"), move |ctx| {
        export_png_stack(&m2, &p2, ctx)
    })
    .unwrap();
    read_tree(&dir.path().join("out"))
}

/// Pearson correlation of two series.
fn correlation(a: &[f64], b: &[f64]) -> f64 {
    let n = a.len() as f64;
    let (ma, mb) = (a.iter().sum::<f64>() / n, b.iter().sum::<f64>() / n);
    let cov: f64 = a.iter().zip(b).map(|(x, y)| (x - ma) * (y - mb)).sum();
    let va: f64 = a.iter().map(|x| (x - ma).powi(2)).sum();
    let vb: f64 = b.iter().map(|y| (y - mb).powi(2)).sum();
    cov / (va * vb).sqrt()
}

#[test]
fn a_top_layer_reproduces_the_photo_block_by_block() {
    let m = tile();
    let p = params(&m, 3, None);
    let grid = estimate(&m, &p).unwrap().grid;
    let plan = ColorPlan::new(&m, &p).unwrap();
    let files = export(&m, &p);
    let photo = image::open(examples().join("data/astronaut.png"))
        .unwrap()
        .to_rgba8();
    let side = photo.width() / BLOCK;
    // Per block: sums of the printed resins' OKLab points and counts.
    let mut got = vec![([0.0f64; CHANNELS], 0.0f64); (side * side) as usize];
    let [nx, ny, _] = grid.dims;
    for z in p.layers.clone().unwrap() {
        let png = decode(&files[&format!("slice_{z:05}.png")]);
        for j in 0..ny {
            for i in 0..nx {
                // Top view: row 0 is max Y.
                let o = ((ny - 1 - j) * nx + i) * 4;
                let px = &png.data[o..o + 4];
                let Some(r) = plan.resins.iter().position(|r| r.rgba[..] == *px) else {
                    assert!(px == [0, 0, 0, 0], "pixel {px:?} is no resin");
                    continue;
                };
                // The voxel's place on the photo (40 mm over its pixels,
                // row 0 at y = +20).
                let c = grid.center(i, j, z);
                let u = (c.x + 20.0) / 40.0 * f64::from(photo.width());
                let v = (20.0 - c.y) / 40.0 * f64::from(photo.height());
                let (bu, bv) = ((u / f64::from(BLOCK)) as u32, (v / f64::from(BLOCK)) as u32);
                let e = &mut got[(bv * side + bu) as usize];
                for (s, k) in e.0.iter_mut().zip(plan.inks()[r]) {
                    *s += f64::from(k);
                }
                e.1 += 1.0;
            }
        }
    }
    let (mut got_l, mut want_l) = (Vec::new(), Vec::new());
    let mut worst = 0.0f64;
    // The blocks inside the outer ring (the tile's rounded edge leaves the
    // outer blocks partly void).
    for bv in 1..side - 1 {
        for bu in 1..side - 1 {
            let mut want = [0.0f64; CHANNELS];
            for y in bv * BLOCK..(bv + 1) * BLOCK {
                for x in bu * BLOCK..(bu + 1) * BLOCK {
                    let rgba = photo.get_pixel(x, y).0.map(|c| f64::from(c) / 255.0);
                    for (w, k) in want.iter_mut().zip(plan.wanted(rgba)) {
                        *w += f64::from(k) / f64::from(BLOCK * BLOCK);
                    }
                }
            }
            let (sum, n) = got[(bv * side + bu) as usize];
            assert!(n > 1000.0, "block {bu}, {bv}: {n} voxels");
            let mean: Vec<f64> = sum.iter().map(|s| s / n).collect();
            let de = mean
                .iter()
                .zip(want)
                .map(|(g, w)| (g - w).powi(2))
                .sum::<f64>()
                .sqrt();
            worst = worst.max(de);
            // ΔE_ok 0.03 (about 3 CIELAB units): error diffusion keeps a
            // block's mean to a few hundredths; the rest is the block's
            // edge, where the diffused error of its neighbours spills in.
            assert!(de < 0.03, "block {bu}, {bv}: ΔE_ok {de:.4}");
            got_l.push(mean[0]);
            want_l.push(want[0]);
        }
    }
    let r = correlation(&got_l, &want_l);
    eprintln!("worst block ΔE_ok {worst:.4}, lightness correlation {r:.4}");
    assert!(r > 0.98, "lightness correlation {r}");
}

#[test]
fn one_and_two_threads_write_the_same_bytes() {
    let m = tile();
    let one = export(&m, &params(&m, 2, Some(1)));
    let two = export(&m, &params(&m, 2, Some(2)));
    assert_eq!(one.len(), 2);
    assert!(one == two, "output differs between 1 and 2 threads");
}
