//! Shards merged in process: the manifest notes the merge rebuilds (the
//! design's thin-feature warnings, the blank-stack warning) read as the
//! single export's, byte for byte.

mod common;

use common::{manifest, model, read_tree, run, tmp};
use glam::DVec3;
use volcad_compilers::png_stack::{Dither, PngParams, export_png_stack};
use volcad_compilers::shard::{Shard, plan_merge};

/// Two 0.1 mm walls 0.8 mm apart (blank at 0.5 mm voxels: the two voxel
/// centres across them, ±0.25 mm, miss both), and a bar with a 0.3 mm fin
/// (a thin-feature warning, with voxels inside).
const DESIGNS: [(&str, &str); 2] = [
    (
        "every slice is blank",
        r#"let m = default_materials();
Union(false, [RectPrism(Vec3(-0.4,0,0), Vec3(0.1,6,4), m.id("red")), RectPrism(Vec3(0.4,0,0), Vec3(0.1,6,4), m.id("red"))])"#,
    ),
    (
        "narrower than two cells",
        r#"let m = default_materials();
Union(false, [RectPrism(Vec3(0,0,0), Vec3(6,6,4), m.id("red")), RectPrism(Vec3(4,0,0), Vec3(0.3,6,4), m.id("blue"))])"#,
    ),
];

#[test]
fn merged_notes_match_the_single_export_with_warnings() {
    for (warning, src) in DESIGNS {
        let m = model(src);
        let p = PngParams {
            voxel: DVec3::splat(0.5),
            seed: 3,
            dither: Dither::Random,
            ..PngParams::default()
        };
        let dir = tmp();
        let single = dir.path().join("single");
        let (mm, pp) = (m.clone(), p.clone());
        let s = run(&single, move |ctx| export_png_stack(&mm, &pp, ctx)).unwrap();
        assert!(
            s.notes
                .iter()
                .any(|n| n.starts_with("warning") && n.contains(warning)),
            "{:?}",
            s.notes
        );
        let parts: Vec<_> = (1..=3)
            .map(|index| {
                let d = dir.path().join(format!("part{index}"));
                let (mm, pp) = (
                    m.clone(),
                    PngParams {
                        shard: Some(Shard { index, count: 3 }),
                        ..p.clone()
                    },
                );
                run(&d, move |ctx| export_png_stack(&mm, &pp, ctx)).unwrap();
                d
            })
            .collect();
        let plan = plan_merge(&parts).unwrap();
        let merged = dir.path().join("merged");
        run(&merged, move |ctx| plan.run(ctx)).unwrap();
        assert_eq!(read_tree(&merged), read_tree(&single));
        assert_eq!(
            String::from_utf8(manifest(&merged)).unwrap(),
            String::from_utf8(manifest(&single)).unwrap()
        );
    }
}
