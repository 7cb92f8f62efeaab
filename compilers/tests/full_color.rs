//! Full-colour stacks end to end: the colour wheel example reproduced
//! region by region, byte-identical across thread counts, counts that sum
//! to the inside voxels; material colours and alpha without a `color`
//! attribute; a procedural texture; profiles; refusals.
// Test helpers fail the test with a message where a value is missing.
#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use std::collections::BTreeMap;
use std::sync::Arc;

use common::{decode, manifest, model, read_tree, run, tmp};
use glam::DVec3;
use volcad_compilers::color::{CHANNELS, ColorPlan, Ink, J750_COLOR_RESINS};
use volcad_compilers::png_stack::{PngParams, estimate, export_png_stack};
use volcad_compilers::{ExportError, Summary};
use volcad_core::Model;
use volcad_core::sampler::Grid;

/// Per region: the sum of the resins' points, of the wanted points, and
/// the voxel count.
type RegionSums = BTreeMap<(usize, usize), ([f64; CHANNELS], [f64; CHANNELS], f64)>;

const WHEEL: &str = include_str!("../../assets/examples/color_wheel.rhai");

fn params(voxel: f64) -> PngParams {
    PngParams {
        voxel: DVec3::splat(voxel),
        full_color: true,
        ..PngParams::default()
    }
}

fn export(m: &Arc<Model>, p: &PngParams, dest: &std::path::Path) -> Result<Summary, ExportError> {
    let (m, p) = (m.clone(), p.clone());
    run(dest, move |ctx| export_png_stack(&m, &p, ctx))
}

fn counts(s: &Summary) -> BTreeMap<String, u64> {
    s.counts.iter().cloned().collect()
}

/// Each voxel's resin, as a point, from the stack's slices (grid order:
/// x fastest, y from min Y, layer from the bottom; `None` for void).
fn voxel_inks(
    tree: &BTreeMap<String, Vec<u8>>,
    plan: &ColorPlan,
    dims: [usize; 3],
) -> Vec<Option<Ink>> {
    let [nx, ny, nz] = dims;
    let mut out = vec![None; nx * ny * nz];
    for z in 0..nz {
        let png = decode(&tree[&format!("slice_{z:05}.png")]);
        for j in 0..ny {
            for i in 0..nx {
                // Top view: row 0 is max Y.
                let o = ((ny - 1 - j) * nx + i) * 4;
                let px = &png.data[o..o + 4];
                if px[3] == 0 && px[..3] == [0, 0, 0] {
                    continue;
                }
                let r = plan
                    .resins
                    .iter()
                    .position(|r| r.rgba[..] == *px)
                    .expect("a resin colour");
                out[(z * ny + j) * nx + i] = Some(plan.inks()[r]);
            }
        }
    }
    out
}

/// Export `m` with `p` and read each voxel's resin back.
fn exported_inks(m: &Arc<Model>, p: &PngParams) -> (Grid, ColorPlan, Vec<Option<Ink>>) {
    let grid = estimate(m, p).unwrap().grid;
    let plan = ColorPlan::new(m, p).unwrap();
    let dir = tmp();
    export(m, p, &dir.path().join("out")).unwrap();
    let inks = voxel_inks(&read_tree(&dir.path().join("out")), &plan, grid.dims);
    (grid, plan, inks)
}

#[test]
fn colour_wheel_regions_average_to_the_wanted_colour() {
    let m = model(WHEEL);
    let (grid, plan, inks) = exported_inks(&m, &params(0.25));
    let [nx, ny, nz] = grid.dims;
    let index = m.attribute_index("color").unwrap();
    // Regions: 12 sectors of 30° by 4 rings of 4 mm, through every layer
    // (about 1,200 to 8,000 voxels each).
    let mut sums = RegionSums::new();
    let mut c = [0.0; 4];
    for z in 0..nz {
        for j in 0..ny {
            for i in 0..nx {
                let Some(got) = inks[(z * ny + j) * nx + i] else {
                    continue;
                };
                let q = grid.center(i, j, z);
                let (r, a) = (
                    q.x.hypot(q.y),
                    q.y.atan2(q.x).rem_euclid(std::f64::consts::TAU),
                );
                if !(2.0..18.0).contains(&r) {
                    continue;
                }
                m.attribute_at(index, q, &mut c).unwrap();
                let want = plan.wanted(c);
                let key = (
                    (a / (std::f64::consts::TAU / 12.0)) as usize,
                    ((r - 2.0) / 4.0) as usize,
                );
                let e = sums.entry(key).or_insert(([0.0; 4], [0.0; 4], 0.0));
                for k in 0..CHANNELS {
                    e.0[k] += f64::from(got[k]);
                    e.1[k] += f64::from(want[k]);
                }
                e.2 += 1.0;
            }
        }
    }
    assert_eq!(sums.len(), 48);
    let mut worst = 0.0f64;
    for (key, (got, want, n)) in &sums {
        let de = (0..CHANNELS)
            .map(|k| (got[k] / n - want[k] / n).powi(2))
            .sum::<f64>()
            .sqrt();
        worst = worst.max(de);
        // ΔE_ok 0.02 (about 2 in CIELAB ΔE units, near the threshold of a
        // visible difference for side-by-side patches): error diffusion
        // keeps the mean up to the error at a region's edge, a few
        // hundredths of the resin spacing spread over a region of
        // thousands of voxels.
        assert!(de < 0.02, "region {key:?} ({n} voxels): ΔE_ok {de:.4}");
    }
    eprintln!("worst region: ΔE_ok {worst:.4}");
    assert!(worst > 0.0);
}

#[test]
fn thread_counts_give_identical_bytes_and_counts_sum_to_the_inside() {
    let m = model(WHEEL);
    let mut trees = Vec::new();
    let mut s = None;
    for threads in [Some(1), Some(2)] {
        let dir = tmp();
        let p = PngParams {
            threads,
            per_material_bitmaps: true,
            ..params(0.4)
        };
        s = Some(export(&m, &p, &dir.path().join("out")).unwrap());
        trees.push((
            read_tree(&dir.path().join("out")),
            manifest(&dir.path().join("out")),
        ));
    }
    assert!(
        trees[0] == trees[1],
        "output differs between 1 and 2 threads"
    );
    let s = s.unwrap();
    let names: Vec<&str> = s.counts.iter().map(|(n, _)| n.as_str()).collect();
    assert_eq!(names, J750_COLOR_RESINS);
    // The same design as a material stack: its one material fills every
    // inside voxel.
    let dir = tmp();
    let plain = PngParams {
        voxel: DVec3::splat(0.4),
        ..PngParams::default()
    };
    let inside: u64 = export(&m, &plain, &dir.path().join("out"))
        .unwrap()
        .counts
        .iter()
        .map(|c| c.1)
        .sum();
    assert_eq!(s.counts.iter().map(|c| c.1).sum::<u64>(), inside);
    // Every resin's bitmaps hold its count.
    for (name, count) in &s.counts {
        let ones: u64 = trees[0]
            .0
            .iter()
            .filter(|(f, _)| f.starts_with(&format!("{name}/")))
            .map(|(_, b)| {
                decode(b)
                    .data
                    .iter()
                    .map(|x| u64::from(x.count_ones()))
                    .sum::<u64>()
            })
            .sum();
        assert_eq!(ones, *count, "{name}");
    }
}

#[test]
fn material_colours_mix_by_fraction_and_alpha_blends_toward_clear() {
    // No `color`: a 50/50 cyan/magenta grade is half of each resin.
    let m = model(
        r#"let m = default_materials();
FGrade(["0.5", "0.5"], [m.id("cyan"), m.id("magenta")], true, RectPrism(Vec3(0,0,0), Vec3(10,10,2), m.id("white")))"#,
    );
    let dir = tmp();
    let c = counts(&export(&m, &params(0.25), &dir.path().join("a")).unwrap());
    let total: u64 = c.values().sum();
    assert_eq!(total, 40 * 40 * 8);
    for name in ["VeroCyan", "VeroMgnt"] {
        assert!((c[name] as f64 / total as f64 - 0.5).abs() < 0.01, "{c:?}");
    }
    // White at alpha 0.25: three quarters clear.
    let m = model(
        r#"let m = default_materials();
let b = RectPrism(Vec3(0,0,0), Vec3(10,10,2), m.id("white"));
b.set_attribute("color", Vec4(1, 1, 1, 0.25));
b"#,
    );
    let c = counts(&export(&m, &params(0.25), &dir.path().join("b")).unwrap());
    let clear = c["VeroClear"] as f64 / c.values().sum::<u64>() as f64;
    assert!((clear - 0.75).abs() < 0.01, "{c:?}");
    assert_eq!(c["VeroPureWht"] + c["VeroClear"], 40 * 40 * 8);
}

/// No design function samples an image, so the "photo-textured" part is a
/// procedural texture: a checker of 5 mm squares, grey 0.2 and 0.8 in
/// sRGB, on a plate. Each square's lightness comes back.
#[test]
fn checker_texture_keeps_each_squares_lightness() {
    let m = model(
        r#"let m = default_materials();
let b = RectPrism(Vec3(0,0,0), Vec3(20,20,1), m.id("white"));
let g = "(floor(x / 5) + floor(y / 5)) % 2 == 0 ? 0.2 : 0.8";
b.set_attribute("color", [g, g, g, 1.0]);
b"#,
    );
    let (grid, plan, inks) = exported_inks(&m, &params(0.25));
    let [nx, ny, _] = grid.dims;
    for (sx, sy) in [(0, 0), (1, 0), (2, 3)] {
        let (mut sum, mut n) = (0.0, 0.0);
        for j in sy * 20..(sy + 1) * 20 {
            for i in sx * 20..(sx + 1) * 20 {
                for z in 0..grid.dims[2] {
                    sum += f64::from(inks[(z * ny + j) * nx + i].unwrap()[0]);
                    n += 1.0;
                }
            }
        }
        let g = if (sx + sy) % 2 == 0 { 0.2 } else { 0.8 };
        let want = plan.wanted([g, g, g, 1.0])[0] as f64;
        assert!(
            (sum / n - want).abs() < 0.02,
            "square ({sx}, {sy}): L {} for {want}",
            sum / n
        );
    }
}

#[test]
fn a_profile_steers_the_choice_and_bad_input_is_refused_first() {
    let dir = tmp();
    // Black and white only, measured: grey is black and white dots.
    let csv = dir.path().join("bw.csv");
    std::fs::write(&csv, "name,L,a,b\nVeroBlack,10,0,0\nVeroPureWht,95,0,-2\n").unwrap();
    let m = model(
        r#"let m = default_materials();
let b = RectPrism(Vec3(0,0,0), Vec3(4,4,1), m.id("white"));
b.set_attribute("color", Vec4(0.5, 0.5, 0.5, 1));
b"#,
    );
    let p = PngParams {
        color_profile: Some(csv.clone()),
        ..params(0.25)
    };
    let c = counts(&export(&m, &p, &dir.path().join("bw")).unwrap());
    assert_eq!(c.keys().collect::<Vec<_>>(), ["VeroBlack", "VeroPureWht"]);
    assert!(c["VeroBlack"] > 0 && c["VeroPureWht"] > 0);
    let err = |m: &Arc<Model>, p: &PngParams| {
        let dest = dir.path().join("refused");
        let e = export(m, p, &dest).unwrap_err().to_string();
        assert!(!dest.exists(), "nothing written for {e}");
        e
    };
    std::fs::write(&csv, "name,L,a,b\nVeroBlack,10,0,0\nVeroWhte,95,0,0\n").unwrap();
    let e = err(&m, &p);
    assert!(
        e.starts_with("--color-profile: ") && e.contains("bw.csv:3:1: \"VeroWhte\""),
        "{e}"
    );
    let e = err(
        &m,
        &PngParams {
            full_color: false,
            ..p.clone()
        },
    );
    assert!(e.contains("add --full-color"), "{e}");
    // A colour above 1 names the node, the point and the value.
    let over = model(
        r#"let m = default_materials();
let b = RectPrism(Vec3(0,0,0), Vec3(4,4,1), m.id("white"));
b.set_attribute("color", ["x / 2 + 1", 0, 0, 1]);
b"#,
    );
    let e = err(&over, &params(0.25));
    assert!(
        e.contains("RectPrism") && e.contains("\"color\"") && e.contains("0..1"),
        "{e}"
    );
}
