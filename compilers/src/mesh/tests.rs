//! Tests of the segmented-mesh pipeline: estimates, uniform tiles, blocks.

use volcad_core::script::{ScriptOptions, model_of, model_of_file};

use super::*;
use crate::estimate::Look;
use std::sync::atomic::Ordering;

/// `src` after `let m = default_materials();`, run and prepared (shared
/// by the crate's test modules).
pub(crate) fn model(src: &str) -> Model {
    let src = format!("let m = default_materials();\n{src}");
    model_of(&src, "t.rhai", &ScriptOptions::default()).expect("design")
}

/// Segment meshes of `m` through a plan that `adjust` changes first (the
/// switches tests compare).
fn built(m: &Model, p: &MeshParams, adjust: impl Fn(&mut Plan)) -> Vec<SegmentMesh> {
    let mut pl = plan(m, p, Look::Coarse).expect("plan");
    adjust(&mut pl);
    build(m, p, &pl, &AtomicBool::new(false), &|_, _| {}).expect("build")
}

/// Meshes and voxel counts with and without label-uniform tiles.
fn both(m: &Model, p: &MeshParams) -> [Vec<SegmentMesh>; 2] {
    [true, false].map(|uniform| built(m, p, |pl| pl.uniform_tiles = uniform))
}

/// Parameters of a `segments`-segment export by `by` at `voxel` mm.
fn params(voxel: f64, by: SegmentBy, segments: usize) -> MeshParams {
    MeshParams {
        voxel: DVec3::splat(voxel),
        by,
        segments,
        ..MeshParams::default()
    }
}

/// The paper's bar (15 × 10 × 5 mm), graded red to blue along x.
fn graded_bar() -> Model {
    model(
        r#"FGrade(["x/15+0.5", "-x/15+0.5"], [m.id("red"), m.id("blue")], true, RectPrism(Vec3(0,0,0), Vec3(15,10,5), m.id("gray")))"#,
    )
}

/// `shape` graded between three materials (red and blue along x and y,
/// green constant) and rotated off every axis.
fn tilted_three_materials(shape: &str) -> Model {
    model(&format!(
        r#"Rotate(20, 35, 10, Vec3(0,0,0), FGrade(["x/8+0.5", "0.3", "-y/8+0.5"], [m.id("red"), m.id("green"), m.id("blue")], true, {shape}))"#
    ))
}

#[test]
fn triangle_estimates_are_within_twice_the_count() {
    let cube = model(r#"RectPrism(Vec3(0,0,0), Vec3(10,10,10), m.id("red"))"#);
    let bar = graded_bar();
    let ball = model(r#"Sphere(Vec3(0,0,0), 5, m.id("red"))"#);
    // Wires 0.12 mm across and 0.5 mm coarse cells: most of them fall
    // between the coarse grid's samples, which saw a seventh of the triangles
    // (and a fifth of the bunny lattice's), the sampled layers all of them.
    let wires = model(
        r#"let u = Union();
        for k in 0..20 {
            let y = -9.0 + k * 0.93;
            u.add_child(Strut(Vec3(-10.0, y, 0.0), Vec3(10.0, y, 0.0), 0.06, m.id("gray")));
        }
        u"#,
    );
    let red = bar.table().id("red").expect("red");
    let cancel = AtomicBool::new(false);
    for (name, m, by, segments, voxel) in [
        ("cube", &cube, SegmentBy::Dominant, 1, 0.1),
        ("bar", &bar, SegmentBy::Dominant, 1, 0.1),
        ("bar in 4", &bar, SegmentBy::Material(red), 4, 0.1),
        ("sphere", &ball, SegmentBy::Dominant, 1, 0.1),
        ("wires", &wires, SegmentBy::Dominant, 1, 0.04),
    ] {
        let p = params(voxel, by, segments);
        let est = estimate_mesh(m, &p).expect("estimate").triangles as f64;
        let made: usize = segment_meshes(m, &p, &cancel, |_, _| {})
            .expect("meshes")
            .iter()
            .map(|s| s.mesh.triangles.len())
            .sum();
        let ratio = est / made as f64;
        assert!((0.5..2.0).contains(&ratio), "{name}: {est} for {made}");
    }
}

#[test]
fn uniform_tiles_give_the_same_meshes() {
    let bar = graded_bar();
    let tilted = tilted_three_materials(r#"Sphere(Vec3(0,0,0), 4, m.id("gray"))"#);
    let red = bar.table().id("red").expect("red");
    let seat = model_of_file(
        &std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../assets/examples/bicycle_seat.rhai"),
    )
    .expect("seat");
    let cyan = seat.table().id("VeroCyan").expect("VeroCyan");
    // One label through a lattice: the contourer evaluates the corners the
    // sampler left unevaluated (see `Consumer::MeshContour`).
    let bcc = model_of_file(
        &std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../assets/examples/bcc_sphere.rhai"),
    )
    .expect("bcc sphere");
    let gray = bcc.table().id("gray").expect("gray");
    let cases = [
        (&bcc, SegmentBy::Material(gray), 1, 0.12),
        (&seat, SegmentBy::Material(cyan), 4, 2.0),
        (&bar, SegmentBy::Material(red), 4, 0.1),
        (&bar, SegmentBy::Dominant, 1, 0.1),
        (&tilted, SegmentBy::Material(red), 5, 0.1),
        (&tilted, SegmentBy::Dominant, 1, 0.1),
    ];
    for (m, by, segments, voxel) in cases {
        let p = params(voxel, by, segments);
        let [fast, plain] = both(m, &p);
        assert_eq!(fast.len(), plain.len());
        let nonempty = plain.iter().filter(|s| !s.mesh.triangles.is_empty());
        assert!(nonempty.count() >= segments.min(2), "too few segments");
        for (a, b) in fast.iter().zip(&plain) {
            assert_eq!(a.mesh, b.mesh, "{}: meshes differ", a.name);
            assert_eq!(a.voxels, b.voxels, "{}: voxel counts differ", a.name);
        }
    }
}

/// The flat regions' fallback takes its samples again from the design
/// (`Classifier::sample`): every region through it gives plain marching
/// tetrahedra's triangles at the same points, so those samples are the
/// planes' numbers, for distances, fraction ranges and dominant materials.
#[test]
fn the_fallback_samples_again_what_the_planes_held() {
    let bar = graded_bar();
    let tilted = tilted_three_materials(r#"RectPrism(Vec3(0,0,0), Vec3(6,5,4), m.id("gray"))"#);
    let red = bar.table().id("red").expect("red");
    for (name, m, by, segments) in [
        ("bar", &bar, SegmentBy::Dominant, 1),
        ("bar in 4", &bar, SegmentBy::Material(red), 4),
        ("tilted box", &tilted, SegmentBy::Dominant, 1),
    ] {
        let p = params(0.2, by, segments);
        let [merged, plain, fallback] = [Flat::Merge, Flat::Off, Flat::FallbackOnly]
            .map(|flat| built(m, &p, |pl| pl.flat = flat));
        for ((a, b), c) in fallback.iter().zip(&plain).zip(&merged) {
            assert!(a.mesh.is_watertight(), "{name} {}", a.name);
            assert!(!b.mesh.triangles.is_empty(), "{name} {}", b.name);
            // Regions merged, so the fallback had regions to take.
            assert!(
                c.mesh.triangles.len() < b.mesh.triangles.len(),
                "{name} {}: {} triangles merged, {} not",
                c.name,
                c.mesh.triangles.len(),
                b.mesh.triangles.len()
            );
            assert!(
                indexed::tri_set(&a.mesh) == indexed::tri_set(&b.mesh),
                "{name} {}: the fallback differs from marching tetrahedra",
                a.name
            );
        }
    }
}

/// `slab` with each solid rectangle's fractions written into its voxels
/// (`nx` voxels a row), as a sampler without rectangles writes them.
fn rects_written_out(slab: &Slab, nx: usize) -> Slab {
    let mut out = slab.clone();
    let (k, layer) = (slab.k, slab.dist.len() / slab.layers.max(1));
    for r in &slab.rects {
        let one = &slab.rect_fracs[r.at..r.at + k];
        for y in r.y0..r.y0 + r.h {
            let v = (r.z - slab.z0) * layer + y * nx + r.x0;
            volcad_core::sampler::fill_pattern(&mut out.fracs[v * k..(v + r.w) * k], one);
        }
    }
    out.rects.clear();
    out.rect_fracs.clear();
    out
}

#[test]
fn uniform_tiles_are_used_and_agree_on_labels() {
    let bar = graded_bar();
    let p = params(
        0.1,
        SegmentBy::Material(bar.table().id("red").expect("red")),
        4,
    );
    let pl = plan(&bar, &p, Look::Coarse).expect("plan");
    let dims = pl.grid.dims;
    let test = |b: &[volcad_core::interval::Interval]| pl.classifier.uniform(b);
    // One layer at a time: a mesh export's blocks through layers play no
    // part, so `a` (the rectangles written voxel by voxel) is what the
    // uniform tiles alone give.
    let rects = Sampler::new(&bar, pl.grid, Consumer::MeshContour(&test));
    let plain = Sampler::new(&bar, pl.grid, Consumer::ViewportBake);
    let cancel = AtomicBool::new(false);
    let (mut b, mut c) = (Slab::default(), Slab::default());
    // Stale fractions in the reused buffer must not matter.
    c.fracs = vec![f32::NAN; dims[0] * dims[1] * 3];
    let (mut filled, mut in_rects) = (0, 0);
    for z in 0..dims[2] {
        plain
            .sample_layers(z, z + 1, &mut b, &cancel)
            .expect("sample");
        rects
            .sample_layers(z, z + 1, &mut c, &cancel)
            .expect("sample");
        let a = rects_written_out(&c, dims[0]);
        let (la, ta) = pl.classifier.plane(&a, 0, dims, z);
        let (lb, tb) = pl.classifier.plane(&b, 0, dims, z);
        let (lc, tc) = pl.classifier.plane(&c, 0, dims, z);
        assert_eq!(la.label, lb.label, "labels of layer {z}");
        assert_eq!(ta.voxels, tb.voxels);
        // Rectangles classified once give the same labels and values
        // as their voxels one by one.
        assert_eq!(lc.label, la.label, "labels of layer {z}, rectangles");
        assert_eq!(lc.value, la.value, "values of layer {z}, rectangles");
        assert_eq!(lc.dist, la.dist);
        assert_eq!(tc.voxels, ta.voxels);
        in_rects += c.rects.iter().map(|r| r.w * r.h).sum::<usize>();
        let k = a.k;
        // (Outside voxels' fractions are not written for a mesh export.)
        filled += (0..a.dist.len())
            .filter(|v| {
                a.dist[*v] <= 0.0 && a.fracs[v * k..(v + 1) * k] != b.fracs[v * k..(v + 1) * k]
            })
            .count();
    }
    eprintln!(
        "graded bar at 0.1 mm: {filled} of {} voxels filled",
        dims[0] * dims[1] * dims[2]
    );
    // Most of the bar's voxels got their tile's centre fractions.
    assert!(
        filled > dims[0] * dims[1] * dims[2] / 4,
        "{filled} voxels filled"
    );
    assert!(in_rects >= filled, "{in_rects} voxels in rectangles");
}

/// Blocks through a slab of layers (one bound for many layers) give the
/// labels and counts of sampling every voxel, on a graded bar (uniform
/// blocks) and a tilted two-material part (fixed mixes, empty space).
#[test]
fn blocks_through_layers_agree_on_labels() {
    let designs = [
        (
            r#"FGrade(["x/15+0.5", "-x/15+0.5"], [m.id("red"), m.id("blue")], true, RectPrism(Vec3(0,0,0), Vec3(15,10,5), m.id("gray")))"#,
            SegmentBy::Dominant,
            0.04,
            10,
        ),
        (
            r#"Rotate(20, 10, 0, Vec3(0,0,0), Union(false, [Sphere(Vec3(0,0,0), 4, m.id("red")), RectPrism(Vec3(3,0,0), Vec3(4,6,6), m.id("blue"))]))"#,
            SegmentBy::Dominant,
            0.08,
            1000,
        ),
    ];
    // The last number: at least 1/n of the voxels lie in solid blocks
    // (rotated boxes bound loosely, so few of its blocks are proved).
    for (src, by, voxel, n) in designs {
        let m = model(src);
        let p = MeshParams {
            voxel: DVec3::splat(voxel),
            by,
            ..MeshParams::default()
        };
        let pl = plan(&m, &p, Look::Coarse).expect("plan");
        let dims = pl.grid.dims;
        let test = |b: &[volcad_core::interval::Interval]| pl.classifier.uniform(b);
        let plain = Sampler::new(&m, pl.grid, Consumer::ViewportBake);
        let blocks = Sampler::new(&m, pl.grid, Consumer::MeshContour(&test));
        let cancel = AtomicBool::new(false);
        let (mut a, mut b) = (Slab::default(), Slab::default());
        let mut z0 = 0;
        while z0 < dims[2] {
            let z1 = (z0 + 7).min(dims[2]);
            plain
                .sample_layers(z0, z1, &mut a, &cancel)
                .expect("sample");
            blocks
                .sample_layers(z0, z1, &mut b, &cancel)
                .expect("sample");
            for z in z0..z1 {
                let (la, ta) = pl.classifier.plane(&a, z - z0, dims, z);
                let (lb, tb) = pl.classifier.plane(&b, z - z0, dims, z);
                assert_eq!(la.label, lb.label, "{src}: labels of layer {z}");
                assert_eq!(ta.voxels, tb.voxels, "{src}: counts of layer {z}");
            }
            z0 = z1;
        }
        // Solid blocks were used (so the comparison tested them).
        let solid = blocks.stats.solid_blocks.load(Ordering::Relaxed) as usize;
        let all = dims[0] * dims[1] * dims[2];
        assert!(
            solid > all / n,
            "{src}: {solid} of {all} voxels in solid blocks"
        );
    }
}

/// A design of one fixed mix labels its planes from the distances' signs
/// (`segment::fixed_plane_into`) as voxel by voxel classification does:
/// the same labels and voxel counts, layer by layer, through the sampler
/// the export uses; a graded design does not take that path.
#[test]
fn fixed_mixes_label_planes_from_signs_alone() {
    let designs = [
        (
            r#"Intersection(false, [Tile(GraphLattice(LatticeType::BodyCenteredCubic, Vec3(5,5,5), 0.35, m.id("gray"))), Sphere(Vec3(0,0,0), 10, m.id("gray"))])"#,
            "gray",
            0.15,
        ),
        (
            r#"Rotate(20, 10, 0, Vec3(0,0,0), Union(false, [Sphere(Vec3(0,0,0), 4, m.id("red")), RectPrism(Vec3(3,0,0), Vec3(4,6,6), m.id("red"))]))"#,
            "red",
            0.08,
        ),
        (
            r#"FGrade(["0.3", "0.7"], [m.id("red"), m.id("blue")], false, Sphere(Vec3(0,0,0), 4, m.id("gray")))"#,
            "red",
            0.1,
        ),
    ];
    for (src, material, voxel) in designs {
        let m = model(src);
        let id = m.table().id(material).expect("material");
        let p = params(voxel, SegmentBy::Material(id), 1);
        let pl = plan(&m, &p, Look::Coarse).expect("plan");
        let class = pl.fixed.unwrap_or_else(|| panic!("{src}: no fixed class"));
        let dims = pl.grid.dims;
        let test = |b: &[volcad_core::interval::Interval]| pl.classifier.uniform(b);
        let sampler = Sampler::new(&m, pl.grid, Consumer::MeshContour(&test));
        let cancel = AtomicBool::new(false);
        let mut slab = Slab::default();
        let (mut z0, mut inside) = (0, 0);
        while z0 < dims[2] {
            let z1 = (z0 + 4).min(dims[2]);
            sampler
                .sample_layers(z0, z1, &mut slab, &cancel)
                .expect("sample");
            let dist = std::sync::Arc::new(slab.dist.clone());
            for z in z0..z1 {
                let l = z - z0;
                let (a, ta) = pl
                    .classifier
                    .plane_into(&slab, &dist, l, dims, z, Plane::default());
                // Into a reused plane, as the export does.
                let reuse = Plane {
                    label: vec![7; dims[0] * dims[1]],
                    ..Plane::default()
                };
                let (b, tb) = segment::fixed_plane_into(&dist, l, dims, z, reuse, class);
                assert_eq!(a.label, b.label, "{src}: labels of layer {z}");
                let words = dims[0].div_ceil(64);
                let mut bits = vec![0u64; words * dims[1]];
                for (v, l) in a.label.iter().enumerate() {
                    let (x, y) = (v % dims[0], v / dims[0]);
                    bits[y * words + x / 64] |= u64::from(*l != 0) << (x % 64);
                }
                assert_eq!(bits, b.bits, "{src}: label bits of layer {z}");
                assert_eq!(ta.voxels, tb.voxels, "{src}: counts of layer {z}");
                let (fa, fb) = (ta.sum_f[0], tb.sum_f[0]);
                assert!((fa - fb).abs() <= 1e-9 * fa.abs(), "{src}: {fa} vs {fb}");
                inside += ta.voxels[0];
            }
            z0 = z1;
        }
        assert!(inside > 1000, "{src}: {inside} voxels inside");
    }
    let bar = graded_bar();
    let red = bar.table().id("red").expect("red");
    let pl = plan(
        &bar,
        &params(0.2, SegmentBy::Material(red), 1),
        Look::Coarse,
    )
    .expect("plan");
    assert_eq!(pl.fixed, None, "a graded bar's labels need its fractions");
}

/// An estimate's counting contourer (no meshes built) counts the
/// triangles a building one makes, layer by layer, with one label and with
/// several.
#[test]
fn counting_contourers_count_what_building_ones_make() {
    let bar = graded_bar();
    let red = bar.table().id("red").expect("red");
    for segments in [1, 3] {
        let p = params(0.2, SegmentBy::Material(red), segments);
        let pl = plan(&bar, &p, Look::Coarse).expect("plan");
        let dims = pl.grid.dims;
        let sampler = sampler_for(&bar, pl.grid, None, None);
        let mut slab = Slab::default();
        let cancel = AtomicBool::new(false);
        sampler
            .sample_layers(0, dims[2], &mut slab, &cancel)
            .expect("sample");
        let dist = std::sync::Arc::new(std::mem::take(&mut slab.dist));
        let exact = |at: [usize; 3]| sampler.evaluate(at);
        let new = || Contourer::new(pl.grid, segments, pl.classifier.interface());
        let (mut build, mut count) = (new(), new().counting_only());
        for z in 0..dims[2] {
            let plane = || {
                label_plane(
                    &pl.classifier,
                    pl.fixed,
                    &slab,
                    &dist,
                    [z, z],
                    dims,
                    Plane::default(),
                )
                .0
            };
            build.push_plane(z, plane(), &exact);
            count.push_plane(z, plane(), &exact);
            assert_eq!(
                count.triangles(),
                build.triangles(),
                "{segments} segments, layer {z}"
            );
        }
        assert!(build.triangles() > 1000, "{} triangles", build.triangles());
    }
}
