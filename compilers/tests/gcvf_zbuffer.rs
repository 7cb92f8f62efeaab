//! The GCVF z-buffer on a part whose top varies in x and y (a ball on a
//! wedge): each pixel is the highest layer whose slice has that pixel
//! solid, 0 where none has, so the z-buffer and the slices agree pixel for
//! pixel in pyvcad's orientation.

// A failed setup step (a scratch folder, a file read) fails the test.
#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use std::io::{Cursor, Read};

use common::{decode, model, tmp};
use glam::DVec3;
use volcad_compilers::gcvf::{GcvfParams, PREFIX, export_gcvf};
use volcad_compilers::job;
use volcad_compilers::png_stack::Dither;

/// A ramp rising along x over a disc missing a quarter, and a ball beside
/// them: tops differ across x and y, and the bounding box's corners by the
/// ball are empty columns.
const PART: &str = r#"let m = j750_materials();
let c = m.id("VeroCyan");
let ramp = Difference(RectPrism(Vec3(0, 0, 1), Vec3(8, 6, 2), c), Rotate(0.0, 14.0, 0.0, Vec3(0, 0, 0), RectPrism(Vec3(0, 0, 3), Vec3(20, 20, 2), c)));
let notch = Difference(Cylinder(Vec3(0, 0, 0), 3.0, 0.5, c), RectPrism(Vec3(2, 2, 0), Vec3(4, 4, 2), c));
Union(false, [ramp, notch, Sphere(Vec3(-5.5, 2, 1.5), 1.2, c)])"#;

#[test]
fn each_pixel_is_the_top_solid_layer_of_its_column() {
    let m = model(PART);
    let p = GcvfParams {
        voxel: DVec3::new(0.1, 0.15, 0.1),
        seed: 1,
        dither: Dither::Random,
        map: Vec::new(),
        threads: Some(2),
        file_name: "part.gcvf".into(),
        liquid_keep_out: None,
    };
    let dir = tmp();
    let dest = dir.path().join("part.gcvf");
    let (m2, p2) = (m.clone(), p.clone());
    job::spawn_file(dest.clone(), "test".into(), move |ctx| {
        export_gcvf(&m2, &p2, ctx)
    })
    .join()
    .unwrap();
    let mut z = zip::ZipArchive::new(Cursor::new(std::fs::read(&dest).unwrap())).unwrap();
    let zb = {
        let mut out = Vec::new();
        z.by_name("Zbuffer.png")
            .unwrap()
            .read_to_end(&mut out)
            .unwrap();
        decode(&out)
    };
    let (w, h) = (zb.width as usize, zb.height as usize);
    let mut want = vec![0u16; w * h];
    let layers = (0..)
        .take_while(|k| z.by_name(&format!("{PREFIX}{k}.png")).is_ok())
        .count();
    assert!(layers > 20, "{layers} slices");
    let mut read = |name: &str| {
        let mut out = Vec::new();
        z.by_name(name).unwrap().read_to_end(&mut out).unwrap();
        decode(&out)
    };
    for k in 0..layers {
        let slice = read(&format!("{PREFIX}{k}.png"));
        for (t, px) in want.iter_mut().zip(slice.data.chunks_exact(4)) {
            if px[3] != 0 {
                *t = k as u16;
            }
        }
    }
    let got: Vec<u16> = zb
        .data
        .chunks_exact(2)
        .map(|v| u16::from_be_bytes([v[0], v[1]]))
        .collect();
    assert_eq!(got, want);
    // The tops do vary, and some columns are empty.
    let mut tops = want.clone();
    tops.sort_unstable();
    tops.dedup();
    assert!(tops.len() > 10 && tops[0] == 0, "{tops:?}");
}
