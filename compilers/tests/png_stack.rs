//! Slice stacks end to end, through the job runner: material counts against
//! analytic volumes, byte-identical output across runs, thread counts and
//! layer ranges, orientation, 1-bit stacks, cancel and bad input.

mod common;

use std::sync::Arc;

use common::{colour_counts, decode, manifest, model, read_tree, run, tmp};
use glam::DVec3;
use volcad_compilers::ExportError;
use volcad_compilers::png_stack::{
    Dither, PngParams, estimate, export_png_stack, grid_span_note, preset,
};
use volcad_core::Model;

const RED: [u8; 4] = [255, 0, 0, 255];
const BLUE: [u8; 4] = [0, 0, 255, 255];
const VOID: [u8; 4] = [0, 0, 0, 0];

/// A 20 × 10 × 5 mm bar graded linearly in x from blue to red: half of
/// each by volume.
const GRADED_BAR: &str = r#"let m = default_materials();
FGrade(["x/20+0.5", "-x/20+0.5"], [m.id("red"), m.id("blue")], true, RectPrism(Vec3(0,0,0), Vec3(20,10,5), m.id("gray")))"#;

/// Two disjoint 8 × 6 × 4 mm boxes, red at x < 0 and blue at x > 0.
const TWO_BOXES: &str = r#"let m = default_materials();
Union(false, [RectPrism(Vec3(-6,0,0), Vec3(8,6,4), m.id("red")), RectPrism(Vec3(6,0,0), Vec3(8,6,4), m.id("blue"))])"#;

fn params(voxel: f64, dither: Dither) -> PngParams {
    PngParams {
        voxel: DVec3::splat(voxel),
        seed: 42,
        dither,
        ..PngParams::default()
    }
}

fn export(
    model: &Arc<Model>,
    p: &PngParams,
    dest: &std::path::Path,
) -> Result<volcad_compilers::Summary, ExportError> {
    let (m, p) = (model.clone(), p.clone());
    run(dest, move |ctx| export_png_stack(&m, &p, ctx))
}

fn within(count: u64, expected: f64, tol: f64) -> bool {
    (count as f64 - expected).abs() <= tol * expected
}

#[test]
fn an_empty_design_gives_blank_slices_and_says_so() {
    // A sphere minus a larger one: a bounding box, but nothing inside.
    let m = model(
        r#"let m = default_materials();
Difference(Sphere(Vec3(0,0,0), 5, m.id("red")), Sphere(Vec3(0,0,0), 6, m.id("red")))"#,
    );
    let dir = tmp();
    let s = export(&m, &params(0.5, Dither::Random), &dir.path().join("out")).unwrap();
    assert!(s.counts.iter().all(|c| c.1 == 0), "{:?}", s.counts);
    assert!(
        s.notes
            .iter()
            .any(|n| n.starts_with("warning: no voxel centre is inside")),
        "{:?}",
        s.notes
    );
    // A part with voxels has no such warning.
    let s = export(
        &model(TWO_BOXES),
        &params(0.5, Dither::Random),
        &dir.path().join("two"),
    )
    .unwrap();
    assert!(
        !s.notes.iter().any(|n| n.starts_with("warning")),
        "{:?}",
        s.notes
    );
}

#[test]
fn graded_bar_counts_are_half_and_half() {
    let m = model(GRADED_BAR);
    let voxel: f64 = 0.1;
    let expected = 20.0 * 10.0 * 5.0 / 2.0 / voxel.powi(3);
    for dither in [Dither::Random, Dither::Diffusion] {
        let dir = tmp();
        let s = export(&m, &params(voxel, dither), &dir.path().join("out")).unwrap();
        let counts: Vec<u64> = s.counts.iter().map(|c| c.1).collect();
        assert_eq!(
            s.counts.iter().map(|c| c.0.as_str()).collect::<Vec<_>>(),
            ["red", "blue"]
        );
        for c in &counts {
            assert!(
                within(*c, expected, 0.01),
                "{dither:?}: {counts:?} vs {expected}"
            );
        }
        // The PNG pixels say the same as the summary.
        let px = colour_counts(&read_tree(&dir.path().join("out")));
        assert_eq!(px.get(&RED).copied(), Some(counts[0]), "{dither:?}");
        assert_eq!(px.get(&BLUE).copied(), Some(counts[1]), "{dither:?}");
        assert_eq!(s.files.len(), 50);
        let manifest = std::fs::read_to_string(dir.path().join("out/manifest.json")).unwrap();
        assert!(
            manifest.contains("\"red\"") && manifest.contains(&counts[0].to_string()),
            "{manifest}"
        );
    }
}

#[test]
fn disjoint_boxes_counts_are_their_volumes() {
    let m = model(TWO_BOXES);
    let voxel: f64 = 0.1;
    let expected = 8.0 * 6.0 * 4.0 / voxel.powi(3);
    let dir = tmp();
    let s = export(&m, &params(voxel, Dither::Random), &dir.path().join("out")).unwrap();
    for (name, c) in &s.counts {
        assert!(within(*c, expected, 0.01), "{name}: {c} vs {expected}");
    }
}

#[test]
fn graded_sphere_with_diffusion_keeps_fractions_at_the_surface() {
    // 80/20 everywhere inside a sphere: counts are 80% and 20% of the inside.
    let m = model(
        r#"let m = default_materials(); FGrade(["0.8", "0.2"], [m.id("red"), m.id("blue")], true, Sphere(Vec3(0,0,0), 4, m.id("gray")))"#,
    );
    let voxel: f64 = 0.1;
    let sphere = 4.0 / 3.0 * std::f64::consts::PI * 64.0 / voxel.powi(3);
    for dither in [Dither::Random, Dither::Diffusion] {
        let dir = tmp();
        let s = export(&m, &params(voxel, dither), &dir.path().join("out")).unwrap();
        let (red, blue) = (s.counts[0].1, s.counts[1].1);
        assert!(
            within(red + blue, sphere, 0.01),
            "{dither:?}: {} vs {sphere}",
            red + blue
        );
        let share = red as f64 / (red + blue) as f64;
        assert!((share - 0.8).abs() < 0.008, "{dither:?}: red share {share}");
    }
}

#[test]
fn runs_and_thread_counts_give_identical_bytes() {
    let m = model(GRADED_BAR);
    for dither in [Dither::Random, Dither::Diffusion] {
        let (mut trees, mut manifests) = (Vec::new(), Vec::new());
        for threads in [None, None, Some(1), Some(2)] {
            let dir = tmp();
            let p = PngParams {
                threads,
                per_material_bitmaps: true,
                ..params(0.2, dither)
            };
            export(&m, &p, &dir.path().join("out")).unwrap();
            trees.push(read_tree(&dir.path().join("out")));
            manifests.push(manifest(&dir.path().join("out")));
        }
        assert!(
            manifests.windows(2).all(|w| w[0] == w[1]),
            "manifests differ"
        );
        assert_eq!(trees[0].len(), 25 * 3, "RGBA + two 1-bit stacks");
        for t in &trees[1..] {
            assert!(
                t == &trees[0],
                "{dither:?}: output differs between runs or thread counts"
            );
        }
    }
}

#[test]
fn layer_ranges_merge_into_the_full_stack() {
    let m = model(GRADED_BAR);
    for dither in [Dither::Random, Dither::Diffusion] {
        let p = PngParams {
            per_material_bitmaps: true,
            ..params(0.2, dither)
        };
        let full_dir = tmp();
        export(&m, &p, &full_dir.path().join("out")).unwrap();
        let full = read_tree(&full_dir.path().join("out"));
        let mut merged = std::collections::BTreeMap::new();
        // 25 layers; cut inside diffusion blocks (16) on purpose.
        for r in [0..7, 7..19, 19..25] {
            let dir = tmp();
            let part = PngParams {
                layers: Some(r.clone()),
                ..p.clone()
            };
            let s = export(&m, &part, &dir.path().join("out")).unwrap();
            assert_eq!(s.files.len(), r.len() * 3);
            merged.extend(read_tree(&dir.path().join("out")));
        }
        assert!(
            merged == full,
            "{dither:?}: merged parts differ from the full run"
        );
    }
}

#[test]
fn orientation_min_x_left_max_y_top_layer_0_lowest() {
    // Red fills x < 0; a blue cube sits in the +x, +y, +z corner.
    let m = model(
        r#"let m = default_materials();
Union(false, [RectPrism(Vec3(-2.5,0,0), Vec3(5,10,10), m.id("red")), RectPrism(Vec3(2.5,2.5,2.5), Vec3(5,5,5), m.id("blue"))])"#,
    );
    let dir = tmp();
    export(&m, &params(1.0, Dither::Random), &dir.path().join("out")).unwrap();
    let tree = read_tree(&dir.path().join("out"));
    let px = |name: &str, col: usize, row: usize| {
        let p = decode(&tree[name]);
        assert_eq!((p.width, p.height), (10, 10));
        let i = (row * p.width + col) * 4;
        [p.data[i], p.data[i + 1], p.data[i + 2], p.data[i + 3]]
    };
    let (bottom, top) = ("slice_00000.png", "slice_00009.png");
    assert_eq!(px(top, 0, 0), RED);
    assert_eq!(px(top, 9, 0), BLUE, "max X, max Y is column 9, row 0");
    assert_eq!(px(top, 9, 9), VOID, "max X, min Y is void");
    assert_eq!(
        px(bottom, 9, 0),
        VOID,
        "the blue cube is in the upper layers only"
    );
}

#[test]
fn one_bit_stacks_match_the_colour_stack() {
    let m = model(TWO_BOXES);
    let dir = tmp();
    let p = PngParams {
        per_material_bitmaps: true,
        ..params(0.5, Dither::Random)
    };
    let s = export(&m, &p, &dir.path().join("out")).unwrap();
    let tree = read_tree(&dir.path().join("out"));
    for (name, count) in &s.counts {
        let mut ones = 0u64;
        for (file, bytes) in tree
            .iter()
            .filter(|(f, _)| f.starts_with(&format!("{name}/")))
        {
            let png = decode(bytes);
            assert_eq!(
                (png.color, png.depth),
                (png::ColorType::Grayscale, png::BitDepth::One),
                "{file}"
            );
            ones += png
                .data
                .iter()
                .map(|b| u64::from(b.count_ones()))
                .sum::<u64>();
        }
        assert_eq!(ones, *count, "{name}");
    }
}

#[test]
fn cancel_leaves_no_output() {
    let m = model(GRADED_BAR);
    let dir = tmp();
    let dest = dir.path().join("out");
    let p = params(0.02, Dither::Diffusion);
    let mm = m.clone();
    let h = volcad_compilers::job::spawn(dest.clone(), "t".into(), move |ctx| {
        export_png_stack(&mm, &p, ctx)
    });
    // Wait for the first layers, then cancel.
    let first = h.progress.recv_timeout(std::time::Duration::from_secs(60));
    assert!(first.is_ok(), "no progress");
    h.cancel();
    assert!(matches!(h.join(), Err(ExportError::Cancelled)));
    assert!(!dest.exists());
    assert_eq!(
        std::fs::read_dir(dir.path()).unwrap().count(),
        0,
        "no staging folder left"
    );
}

#[test]
fn bad_input_is_refused_naming_the_parameter() {
    let m = model(GRADED_BAR);
    let err = |p: PngParams| estimate(&m, &p).unwrap_err().to_string();
    for v in [0.0, -0.1, f64::NAN] {
        assert!(
            err(params(v, Dither::Random)).starts_with("--voxel:"),
            "{v}"
        );
    }
    let e = err(params(1e-5, Dither::Random));
    assert!(e.starts_with("--voxel:") && e.contains("voxels"), "{e}");
    let e = err(PngParams {
        layers: Some(10..100),
        ..params(0.5, Dither::Random)
    });
    assert!(e.starts_with("--layers:") && e.contains("10 layers"), "{e}");
    let e = err(PngParams {
        layers: Some(3..3),
        ..params(0.5, Dither::Random)
    });
    assert!(e.starts_with("--layers:"), "{e}");
    // Under the voxel limit, but one layer's buffers cannot fit in memory.
    let e = err(PngParams {
        voxel: DVec3::new(1e-4, 1e-4, 5.0),
        ..params(1.0, Dither::Random)
    });
    assert!(
        e.starts_with("--voxel:") && e.contains("200000 × 100000") && e.contains("memory"),
        "{e}"
    );
    let tile = model(
        r#"let m = default_materials(); Tile(GraphLattice(LatticeType::BodyCenteredCubic, Vec3(5,5,5), 0.5, m.id("red")))"#,
    );
    let e = estimate(&tile, &params(0.5, Dither::Random))
        .unwrap_err()
        .to_string();
    assert!(e.starts_with("design:") && e.contains("unbounded"), "{e}");
    let dir = tmp();
    let p = PngParams {
        threads: Some(0),
        ..params(0.5, Dither::Random)
    };
    let e = export(&m, &p, &dir.path().join("out"))
        .unwrap_err()
        .to_string();
    assert!(e.starts_with("--threads:"), "{e}");
    assert!(!dir.path().join("out").exists());
}

#[test]
fn a_material_missing_from_the_table_is_an_error() {
    let d = volcad_core::script::run_script(GRADED_BAR, "t.rhai", &Default::default()).unwrap();
    let small = volcad_core::MaterialTable::from_json(
        r#"{"materials":[{"name":"only","r":1,"g":2,"b":3,"a":255}]}"#,
        "small.json",
    )
    .unwrap();
    let m = Arc::new(Model::prepare(&d.root, Arc::new(small)).unwrap());
    let dir = tmp();
    let e = export(&m, &params(0.5, Dither::Random), &dir.path().join("out"))
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with("materials:") && e.contains("small.json"),
        "{e}"
    );
    assert!(!dir.path().join("out").exists());
}

#[test]
fn j750_preset_estimate() {
    let m = model(GRADED_BAR);
    let p = PngParams {
        voxel: preset("j750").unwrap().voxel,
        ..PngParams::default()
    };
    let e = estimate(&m, &p).unwrap();
    // 20 mm / (25.4/600) = 472.4 → 473; 10 mm / (25.4/300) → 119; 5 / 0.027 → 186.
    assert_eq!(e.grid.dims, [473, 119, 186]);
    assert_eq!(e.layers, 0..186);
    assert_eq!(e.files, 186);
    assert!(e.memory_bytes > 0 && e.disk_bytes > 0);
}

/// Counts are `ceil(extent / voxel)` as in pyvcad, and the summary (and so
/// the manifest) says how far the stack reaches past the part.
#[test]
fn slice_counts_match_pyvcad_and_the_summary_gives_the_span() {
    // pyvcad 2.3.4's DirectMaterialCompiler, this bar at the J750 voxel:
    // 186 PNGs of 355 × 119 px.
    let m = model(r#"RectPrism(Vec3(0,0,0), Vec3(15,10,5), default_materials().id("gray"))"#);
    let p = PngParams {
        voxel: preset("j750").unwrap().voxel,
        ..PngParams::default()
    };
    let e = estimate(&m, &p).unwrap();
    assert_eq!(e.grid.dims, [355, 119, 186]);
    let note = grid_span_note(&e.grid, &m.bbox());
    // 119 × 25.4/300 = 10.0753 mm in Y for the 10 mm part.
    assert!(
        note.contains("× 10.0753 ×") && note.contains("15.0000 × 10.0000 × 5.0000 mm"),
        "{note}"
    );
}

/// The disk estimate codes and encodes a few layers as the export does:
/// a tiled lattice's layers (thin struts, many edges) compress far worse
/// than the rule of thumb for one material assumed, which said a tenth of
/// what the stack took.
#[test]
fn the_disk_estimate_is_close_to_the_stack() {
    let lattice = model(
        r#"let m = default_materials();
        let cell = GraphLattice(LatticeType::BodyCenteredCubic, Vec3(4, 4, 4), 0.4, m.id("gray"));
        Intersection(false, [Tile(cell), Sphere(Vec3(0, 0, 0), 8, m.id("gray"))])"#,
    );
    for (name, m) in [("lattice", &lattice), ("graded bar", &model(GRADED_BAR))] {
        let p = params(0.1, Dither::Random);
        let est = estimate(m, &p).unwrap().disk_bytes as f64;
        let dir = tmp();
        let dest = dir.path().join("s");
        export(m, &p, &dest).unwrap();
        let made: u64 = std::fs::read_dir(&dest)
            .unwrap()
            .flatten()
            .filter(|e| e.file_name().to_string_lossy().ends_with(".png"))
            .map(|e| e.metadata().unwrap().len())
            .sum();
        let ratio = est / made as f64;
        assert!((0.8..1.5).contains(&ratio), "{name}: {est} for {made}");
    }
}

/// A design of one material everywhere is sliced from signs alone (no
/// fractions, no picks): every pixel is that material exactly where the
/// voxel's centre is inside, with either dither.
#[test]
fn one_material_slices_are_the_inside_voxels() {
    let m = model(
        r#"let m = default_materials();
Intersection(false, [Tile(GraphLattice(LatticeType::BodyCenteredCubic, Vec3(4,4,4), 0.5, m.id("red"))), Sphere(Vec3(0,0,0), 5, m.id("red"))])"#,
    );
    for dither in [Dither::Random, Dither::Diffusion] {
        let p = params(0.2, dither);
        let g = estimate(&m, &p).unwrap().grid;
        let [nx, ny, nz] = g.dims;
        let dir = tmp();
        let out = dir.path().join("out");
        export(&m, &p, &out).unwrap();
        let tree = read_tree(&out);
        let slices: Vec<&String> = tree.keys().filter(|k| k.starts_with("slice_")).collect();
        assert_eq!(slices.len(), nz);
        let mut inside_count = 0;
        for (z, name) in slices.iter().enumerate() {
            let png = decode(&tree[*name]);
            assert_eq!((png.width, png.height), (nx, ny));
            for row in 0..ny {
                for x in 0..nx {
                    // Row 0 is the largest y.
                    let inside = m.distance(g.center(x, ny - 1 - row, z)) <= 0.0;
                    let i = (row * nx + x) * 4;
                    let want = if inside { RED } else { VOID };
                    assert_eq!(
                        png.data[i..i + 4],
                        want,
                        "{dither:?}: voxel ({x}, {}, {z})",
                        ny - 1 - row
                    );
                    inside_count += usize::from(inside);
                }
            }
        }
        assert!(inside_count > 10_000, "{inside_count}");
    }
}
