use glam::DVec3;

use super::*;
use crate::script::{ScriptOptions, run_script};

fn model(src: &str) -> Model {
    let d = run_script(src, "t", &ScriptOptions::default()).expect("script runs");
    Model::prepare(&d.root, d.materials).expect("model prepares")
}

/// Every layer of `grid` sampled by `s`, and the voxels it evaluated.
fn sample_all(s: &Sampler<'_>) -> (Slab, u64) {
    let mut slab = Slab::default();
    let nz = s.grid().dims[2];
    s.sample_layers(0, nz, &mut slab, &AtomicBool::new(false))
        .expect("not cancelled");
    (slab, s.stats.evaluated.load(Ordering::Relaxed))
}

#[test]
fn signs_only_keeps_signs_and_fractions_and_evaluates_less() {
    // A graded tiled lattice: thin struts, so most tiles are near a surface.
    let m = model(
        r#"let m = default_materials();
        let cell = GraphLattice(LatticeType::FaceCenteredCubic, Vec3(4, 4, 4), 0.3, m.id("gray"));
        let body = RectPrism(Vec3(0, 0, 0), Vec3(8, 8, 8), m.id("gray"));
        FGrade(["clamp(0, x/8 + 0.5, 1)", "1 - clamp(0, x/8 + 0.5, 1)"],
               [m.id("cyan"), m.id("white")], true, Intersection(false, [Tile(cell), body]))"#,
    );
    let grid = Grid::covering(&m.bbox(), DVec3::splat(0.1), 1 << 30).unwrap();
    let (plain, plain_evaluated) = sample_all(&Sampler::new(&m, grid, Consumer::ViewportBake));
    let (signs, signs_evaluated) = sample_all(&Sampler::new(&m, grid, Consumer::PngStackDiffusion));
    let k = plain.k;
    let mut inside = 0;
    for v in 0..plain.dist.len() {
        let (a, b) = (plain.dist[v], signs.dist[v]);
        assert_eq!(a <= 0.0, b <= 0.0, "sign of voxel {v}: {a} vs {b}");
        if a <= 0.0 {
            inside += 1;
            let fa = &plain.fracs[v * k..(v + 1) * k];
            let fb = &signs.fracs[v * k..(v + 1) * k];
            assert_eq!(fa, fb, "fractions of voxel {v}");
        }
    }
    assert!(inside > 10_000, "{inside}");
    // The point of the option: fewer voxels evaluated (4 M → 2.9 M on the
    // lattice_per_cell example).
    assert!(
        (signs_evaluated as f64) < 0.85 * plain_evaluated as f64,
        "{signs_evaluated} of {plain_evaluated}"
    );
}

#[test]
fn shared_fractions_are_the_evaluated_ones() {
    // Graded per cell (constant over most tiles), one material (fixed
    // everywhere), and graded smoothly (never constant): every inside
    // voxel's fractions are exactly what evaluating it gives.
    let lattice = |grade: &str| {
        format!(
            r#"let m = default_materials();
            let cell = GraphLattice(LatticeType::FaceCenteredCubic, Vec3(4, 4, 4), 0.3, m.id("gray"));
            let body = RectPrism(Vec3(0, 0, 0), Vec3(8, 8, 8), m.id("gray"));
            let part = Intersection(false, [Tile(cell), body]);
            {grade}"#
        )
    };
    let per_cell = "let f = `clamp(0, (floor((x + 4)/4) + 0.5)/2, 1)`;
        FGrade([f, `1 - ${f}`], [m.id(\"cyan\"), m.id(\"white\")], true, part)";
    let smooth = "FGrade([\"clamp(0, x/8 + 0.5, 1)\", \"1 - clamp(0, x/8 + 0.5, 1)\"],
        [m.id(\"cyan\"), m.id(\"white\")], true, part)";
    for (src, spares) in [
        (lattice(per_cell), true),
        (lattice("part"), true),
        (lattice(smooth), false),
    ] {
        let m = model(&src);
        let grid = Grid::covering(&m.bbox(), DVec3::splat(0.1), 1 << 30).unwrap();
        let s = Sampler::new(&m, grid, Consumer::PngStackDiffusion);
        let (slab, _) = sample_all(&s);
        let k = slab.k;
        let mut f = vec![0.0; k];
        let mut inside = 0;
        for z in 0..grid.dims[2] {
            for y in 0..grid.dims[1] {
                for x in 0..grid.dims[0] {
                    let v = (z * grid.dims[1] + y) * grid.dims[0] + x;
                    if slab.dist[v] > 0.0 {
                        continue;
                    }
                    inside += 1;
                    m.eval_into(grid.center(x, y, z), &mut f);
                    let want: Vec<u32> = f.iter().map(|v| (*v as f32).to_bits()).collect();
                    let got: Vec<u32> = slab.fracs_of(v).iter().map(|v| v.to_bits()).collect();
                    assert_eq!(got, want, "voxel ({x}, {y}, {z})");
                }
            }
        }
        assert!(inside > 10_000, "{inside}");
        let spared = s.stats.shared.load(Ordering::Relaxed);
        assert_eq!(spared > inside / 10, spares, "{spared} of {inside} spared");
    }
}

#[test]
fn tiles_of_one_exact_distance_store_what_evaluating_gives() {
    // Flat faces parallel to the layers (a box's, a cylinder's caps, also
    // translated and in a union with a curved part): layers through them
    // have tiles whose bound is one number.
    for src in [
        r#"RectPrism(Vec3(0, 0, 0), Vec3(10, 10, 10), 1)"#,
        r#"Cylinder(Vec3(0.3, 0, 0), 4, 6, 1)"#,
        r#"Union(false, [Translate(0.25, 0, 0.5, RectPrism(Vec3(0, 0, 0), Vec3(8, 6, 4), 1)),
                         Sphere(Vec3(3, 0, 3), 2, 1)])"#,
        r#"Rotate(0, 0, 30, Vec3(0, 0, 0), RectPrism(Vec3(0, 0, 0), Vec3(8, 6, 4), 1))"#,
    ] {
        let m = model(src);
        let grid = Grid::covering(&m.bbox().expand(0.3), DVec3::splat(0.11), 1 << 30).unwrap();
        let margin = grid.voxel.length();
        for consumer in [Consumer::SurfaceContour, Consumer::ViewportBake] {
            let with_fracs = matches!(consumer, Consumer::ViewportBake);
            let s = Sampler::new(&m, grid, consumer);
            let (slab, _) = sample_all(&s);
            for z in 0..grid.dims[2] {
                for y in 0..grid.dims[1] {
                    for x in 0..grid.dims[0] {
                        let v = (z * grid.dims[1] + y) * grid.dims[0] + x;
                        let d = m.distance(grid.center(x, y, z));
                        if d.abs() > margin {
                            continue;
                        }
                        assert_eq!(
                            slab.dist[v].to_bits(),
                            (d as f32).to_bits(),
                            "{src}: voxel ({x}, {y}, {z}), fractions {with_fracs}"
                        );
                        if with_fracs {
                            let want: &[f32] = if d <= 0.0 { &[1.0] } else { &[0.0] };
                            assert_eq!(slab.fracs_of(v), want, "{src}: ({x}, {y}, {z})");
                        }
                    }
                }
            }
            // Without one-number tiles every voxel of the first layer
            // inside the box's bottom face is evaluated (all are within
            // the margin of the face).
            if src.starts_with("RectPrism") {
                let [nx, ny, _] = grid.dims;
                let z = (0..grid.dims[2])
                    .find(|&z| m.distance(grid.center(nx / 2, ny / 2, z)) <= 0.0)
                    .expect("a layer inside");
                let one = Sampler::new(&m, grid, consumer);
                let mut layer = Slab::default();
                one.sample_layers(z, z + 1, &mut layer, &AtomicBool::new(false))
                    .expect("not cancelled");
                let evaluated = one.stats.evaluated.load(Ordering::Relaxed);
                assert!(
                    evaluated * 5 < (nx * ny) as u64,
                    "{evaluated} of {} evaluated in layer {z}",
                    nx * ny
                );
            }
        }
    }
}

/// The leaves' Lipschitz bounds (see `leaf`): on a tiled BCC lattice in a
/// sphere (a `Tile` known to be Lipschitz) and a grading, a mesh contour's
/// and a slice stack's samples keep every sign and every inside voxel's
/// fractions; the mesh contour's distances within one voxel diagonal of the
/// surface are the evaluated ones bit for bit, and beyond it every stored
/// value is a bound (`|stored| ≤ |d|`, beyond the margin); and fewer voxels
/// are evaluated than without the bounds.
#[test]
fn leaf_bounds_keep_what_consumers_read() {
    let m = model(
        r#"let m = default_materials();
        let cell = GraphLattice(LatticeType::BodyCenteredCubic, Vec3(2, 2, 2), 0.25, m.id("gray"));
        FGrade(["clamp(0, x/8 + 0.5, 1)", "1 - clamp(0, x/8 + 0.5, 1)"],
               [m.id("cyan"), m.id("white")], true,
               Intersection(false, [Tile(cell), Sphere(Vec3(0, 0, 0), 3.5, m.id("gray"))]))"#,
    );
    assert!(
        m.distance_is_bound(),
        "a tiled symmetric lattice is Lipschitz"
    );
    let grid = Grid::covering(&m.bbox(), DVec3::new(0.07, 0.05, 0.06), 1 << 30).unwrap();
    let margin = grid.voxel.length() as f32;
    let (plain, _) = sample_all(&Sampler::new(&m, grid, Consumer::ViewportBake));
    let any = |_: &[Interval]| false;
    let mesh = Sampler::new(&m, grid, Consumer::MeshContour(&any));
    let (mine, _) = sample_all(&mesh);
    let signs = Sampler::new(&m, grid, Consumer::PngStackDiffusion);
    let (stack, _) = sample_all(&signs);
    let k = plain.k;
    let (mut bounded, mut unevaluated) = (0, 0);
    for v in 0..plain.dist.len() {
        let (a, b, c) = (plain.dist[v], mine.dist[v], stack.dist[v]);
        assert_eq!(a <= 0.0, b <= 0.0, "mesh sign of voxel {v}: {a} vs {b}");
        assert_eq!(a <= 0.0, c <= 0.0, "stack sign of voxel {v}: {a} vs {c}");
        if a <= 0.0 {
            let fa = &plain.fracs[v * k..(v + 1) * k];
            assert_eq!(fa, &stack.fracs[v * k..(v + 1) * k], "voxel {v}");
        }
        if b.is_infinite() {
            // Left for the contourer, which evaluates what it reads.
            unevaluated += 1;
        } else if a.abs() <= margin {
            assert_eq!(a.to_bits(), b.to_bits(), "voxel {v} near the surface");
        } else if a != b {
            assert!(
                b.abs() <= a.abs() && b.abs() > margin * 0.999,
                "{v}: {b} for {a}"
            );
            bounded += 1;
        }
    }
    assert!(bounded > 0, "no voxel took a bound");
    assert!(
        unevaluated > 0,
        "no voxel near the surface was left unevaluated"
    );
    let evaluated = |s: &Sampler<'_>| s.stats.evaluated.load(Ordering::Relaxed);
    let mut off = Sampler::new(&m, grid, Consumer::PngStackDiffusion);
    off.lipschitz_skip = false;
    let (again, _) = sample_all(&off);
    assert_eq!(
        again.dist.iter().filter(|d| **d <= 0.0).count(),
        stack.dist.iter().filter(|d| **d <= 0.0).count()
    );
    assert!(
        evaluated(&signs) < evaluated(&off),
        "{} vs {}",
        evaluated(&signs),
        evaluated(&off)
    );
}

#[test]
fn mesh_contour_signs_writes_the_fixed_mix_distances_without_fractions() {
    // One material (a fixed mix): a mesh export of one segment labels by
    // signs, and its sampler must write the distances the fraction-writing
    // one does, bit for bit, through blocks, leaves and settled tiles.
    let m = model(
        r#"let m = default_materials();
        let cell = GraphLattice(LatticeType::BodyCenteredCubic, Vec3(4, 4, 4), 0.4, m.id("gray"));
        Intersection(false, [Tile(cell), Sphere(Vec3(0, 0, 0), 6)])"#,
    );
    let grid = Grid::covering(&m.bbox(), DVec3::splat(0.12), 1 << 30).unwrap();
    let always = |_: &[Interval]| true;
    let (with, with_evaluated) =
        sample_all(&Sampler::new(&m, grid, Consumer::MeshContour(&always)));
    let (signs, signs_evaluated) = sample_all(&Sampler::new(&m, grid, Consumer::MeshContourSigns));
    assert!(with.k > 0 && signs.k == 0, "k {} and {}", with.k, signs.k);
    assert!(signs.fracs.is_empty() && signs.rects.is_empty());
    assert_eq!(with.dist.len(), signs.dist.len());
    let differ = (with.dist.iter().zip(&signs.dist))
        .filter(|(a, b)| a.to_bits() != b.to_bits())
        .count();
    assert_eq!(differ, 0, "voxels whose distance bits differ");
    assert_eq!(with_evaluated, signs_evaluated);
    assert!(
        signs.dist.iter().any(|d| d.is_infinite()),
        "no unevaluated voxel"
    );
    assert!(signs.dist.iter().filter(|d| **d <= 0.0).count() > 10_000);
}
