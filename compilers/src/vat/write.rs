//! Writing a vat stack: per layer, each vat's screen image from the
//! layer's material codes and gray values.

use std::io::Cursor;
use std::ops::Range;

use glam::DVec3;

use serde_json::json;
use volcad_core::Model;
use volcad_core::sampler::Grid;

use super::{Gray, VatEstimate, VatParams};
use crate::job::{ExportError, JobContext, Summary};
use crate::png_io::{self, PixelsPerMetre};
use crate::png_stack::{self, LayerOut, grid_span_note};
use crate::shard::Part;
use crate::slice_image::Orientation;

/// How every layer is written.
struct Layout<'a> {
    model: &'a Model,
    est: &'a VatEstimate,
    screen: [usize; 2],
    digits: usize,
    ext: &'static str,
    pixel: PixelsPerMetre,
    folders: Vec<String>,
}

pub(super) fn write_stack(
    model: &Model,
    p: &VatParams,
    est: &VatEstimate,
    ctx: &JobContext,
) -> Result<Summary, ExportError> {
    let nz = est.stack.grid.dims[2];
    let folders: Vec<String> = if est.vats > 1 {
        (1..=est.vats).map(|v| format!("vat{v}")).collect()
    } else {
        Vec::new()
    };
    for f in &folders {
        let dir = ctx.staging().join(f);
        std::fs::create_dir_all(&dir).map_err(|e| ExportError::io(&dir, e))?;
    }
    let layout = Layout {
        model,
        est,
        screen: p.printer.screen,
        digits: png_io::name_digits(nz),
        ext: if p.bmp { "bmp" } else { "png" },
        pixel: PixelsPerMetre::from_mm(p.printer.pixel[0], p.printer.pixel[1]),
        folders,
    };
    let out = png_stack::write_layers(
        model,
        &p.stack(),
        None,
        &est.stack,
        ctx,
        est.vats,
        |z, c| write_layer(&layout, ctx, z, c),
    )?;
    let (files, counts) = (out.files, out.counts);
    Ok(summary(model, p, est, files, counts))
}

/// The gray value of every voxel of layer `z` (0 outside).
fn layer_grays(
    model: &Model,
    grid: &Grid,
    gray: Gray,
    z: usize,
    codes: &[u8],
) -> Result<Vec<u8>, ExportError> {
    let nx = grid.dims[0];
    let k = model.materials().len();
    let mut out = vec![0u8; codes.len()];
    let mut fr = vec![0.0; k];
    let mut v = [0.0];
    let to_byte = |t: f64| {
        if t.is_nan() {
            0
        } else {
            (255.0 * t.clamp(0.0, 1.0)).round() as u8
        }
    };
    for (idx, (o, c)) in out.iter_mut().zip(codes).enumerate() {
        if *c == 0 {
            continue;
        }
        let p = grid.center(idx % nx, idx / nx, z);
        *o = match gray {
            Gray::Solid => 255,
            Gray::Attribute { index, lo, hi } => {
                model
                    .attribute_at(index, p, &mut v)
                    .map_err(|e| ExportError::param("--intensity", e.to_string()))?;
                to_byte((v[0] - lo) / (hi - lo))
            }
            Gray::Fraction { slot } => {
                model.fractions_inside(p, &mut fr);
                let sum: f64 = fr.iter().sum();
                to_byte(if sum > 0.0 { fr[slot] / sum } else { 0.0 })
            }
        };
    }
    Ok(out)
}

/// Each vat's screen image of layer `z`, encoded and written.
fn write_layer(
    l: &Layout<'_>,
    ctx: &JobContext,
    z: usize,
    codes: &[u8],
) -> Result<LayerOut, ExportError> {
    let grid = l.est.stack.grid;
    let [nx, ny, _] = grid.dims;
    let [w, h] = l.screen;
    let [c0, r0] = l.est.place;
    let grays = layer_grays(l.model, &grid, l.est.gray, z, codes)?;
    let o = Orientation::TopView;
    let name = format!("slice_{z:0digits$}.{}", l.ext, digits = l.digits);
    let mut files = Vec::new();
    let mut counts = vec![0u64; l.est.vats];
    let mut img = vec![0u8; w * h];
    for (v, count) in counts.iter_mut().enumerate() {
        img.fill(0);
        for (j, (row, g)) in codes
            .chunks_exact(nx)
            .zip(grays.chunks_exact(nx))
            .enumerate()
        {
            let r = r0 + o.row(j, ny);
            let out = &mut img[r * w + c0..r * w + c0 + nx];
            for (i, (c, g)) in row.iter().zip(g).enumerate() {
                if *c != 0 && usize::from(l.est.vat_of[*c as usize - 1]) == v {
                    out[o.col(i, nx)] = *g;
                    *count += 1;
                }
            }
        }
        let rel = match l.folders.get(v) {
            Some(f) => format!("{f}/{name}"),
            None => name.clone(),
        };
        let path = ctx.staging().join(&rel);
        let bytes = encode(&img, w, h, l.ext == "bmp", l.pixel)
            .map_err(|e| ExportError::Other(format!("{}: image encoding: {e}", path.display())))?;
        std::fs::write(&path, bytes).map_err(|e| ExportError::io(&path, e))?;
        files.push(rel);
    }
    Ok(LayerOut { files, counts })
}

/// An 8-bit grayscale image as PNG or BMP (the `image` crate's encoder: 8
/// bits a pixel with a gray palette), either with its pixel size: PNG's
/// `pHYs`, BMP's `biXPelsPerMeter` and `biYPelsPerMeter` (bytes 38 and 42
/// of the file: the 14-byte file header, then those fields at 24 and 28 of
/// the info header, where `image` writes 0).
fn encode(
    img: &[u8],
    w: usize,
    h: usize,
    bmp: bool,
    pixel: PixelsPerMetre,
) -> Result<Vec<u8>, String> {
    if !bmp {
        return png_io::encode_gray(w, h, img, Some(pixel)).map_err(|e| e.to_string());
    }
    let mut out = Cursor::new(Vec::with_capacity(img.len() + 1078));
    let (w, h) = (
        u32::try_from(w).map_err(|e| e.to_string())?,
        u32::try_from(h).map_err(|e| e.to_string())?,
    );
    image::codecs::bmp::BmpEncoder::new(&mut out)
        .encode(img, w, h, image::ExtendedColorType::L8)
        .map_err(|e| e.to_string())?;
    let mut bytes = out.into_inner();
    let PixelsPerMetre([x, y]) = pixel;
    if let Some(field) = bytes.get_mut(38..46) {
        field[..4].copy_from_slice(&x.to_le_bytes());
        field[4..].copy_from_slice(&y.to_le_bytes());
    }
    Ok(bytes)
}

fn summary(
    model: &Model,
    p: &VatParams,
    est: &VatEstimate,
    files: Vec<String>,
    counts: Vec<u64>,
) -> Summary {
    let g = est.stack.grid;
    let [nx, ny, nz] = g.dims;
    let [w, h] = p.printer.screen;
    let table = model.table();
    let vat_names: Vec<String> = (0..est.vats)
        .map(|v| {
            let mats: Vec<&str> = model
                .materials()
                .iter()
                .zip(&est.vat_of)
                .filter(|(_, o)| usize::from(**o) == v)
                .map(|(id, _)| table.name(*id))
                .collect();
            format!("vat{} ({})", v + 1, mats.join("+"))
        })
        .collect();
    let layers = &est.stack.layers;
    let mut notes = vec![
        layers_note(layers, nz),
        format!(
            "{w} × {h} px screen ({}), part {nx} × {ny} px at column {}, row {}",
            p.printer.name, est.place[0], est.place[1]
        ),
        "orientation: column 0 = min X, row 0 = max Y (top view), layer 0 = lowest Z".to_owned(),
        grid_span_note(&g, &model.bbox()),
    ];
    let named: Vec<(String, u64)> = vat_names
        .iter()
        .cloned()
        .zip(counts.iter().copied())
        .collect();
    notes.extend(count_notes(&named, g.voxel));
    let intensity = match &p.intensity {
        super::Intensity::Solid => json!("solid"),
        super::Intensity::Attribute { name, .. } => match est.gray {
            Gray::Attribute { lo, hi, .. } => json!({ "attribute": name, "range": [lo, hi] }),
            _ => json!({ "attribute": name }),
        },
        super::Intensity::Fraction(m) => json!({ "fraction": m }),
    };
    let mut parameters = json!({
        "printer": p.printer.name,
        "pixel_mm": p.printer.pixel,
        "screen_px": p.printer.screen,
        "layer_mm": p.printer.layer,
        "intensity": intensity,
        "vats": vat_names,
        "offset_mm": p.offset,
        "format": if p.bmp { "bmp" } else { "png" },
        "seed": p.seed,
        "dither": p.dither.name(),
        "layers": [layers.start, layers.end],
        "voxel_mm": g.voxel.to_array(),
        "grid": { "dims": [nx, ny, nz], "origin_mm": g.origin.to_array() },
        "place_px": est.place,
    });
    if let Some(s) = p.shard {
        parameters["shard"] = s.to_json();
    }
    Summary {
        kind: "vat".into(),
        files,
        counts: vat_names.into_iter().zip(counts).collect(),
        units: est.stack.voxels,
        unit: "voxels".into(),
        parameters,
        notes,
        seconds: 0.0,
    }
}

/// The first note: the layers written.
fn layers_note(layers: &Range<usize>, nz: usize) -> String {
    format!(
        "{} layer(s) {}..{} of {nz}",
        layers.len(),
        layers.start,
        layers.end
    )
}

/// One note per vat: its voxels and their volume.
fn count_notes(counts: &[(String, u64)], voxel: DVec3) -> Vec<String> {
    let voxel_mm3 = voxel.x * voxel.y * voxel.z;
    counts
        .iter()
        .map(|(n, c)| format!("{n}: {c} voxels = {:.3} mm³", *c as f64 * voxel_mm3))
        .collect()
}

/// The notes of `layers` holding `counts`, from those of `part` (a shard
/// of the same stack, see [`crate::shard`]); `None` when `part`'s notes
/// are not the ones this version writes.
pub(crate) fn merged_notes(
    part: &Part,
    layers: &Range<usize>,
    counts: &[(String, u64)],
) -> Option<Vec<String>> {
    let notes = &part.summary.notes;
    let own = count_notes(&part.summary.counts, part.voxel);
    let middle_end = notes.len().checked_sub(own.len())?;
    if notes.first()? != &layers_note(&part.layers, part.dims[2])
        || notes[middle_end..] != own[..]
        || middle_end < 1
    {
        return None;
    }
    let mut out = vec![layers_note(layers, part.dims[2])];
    out.extend(notes[1..middle_end].iter().cloned());
    out.extend(count_notes(counts, part.voxel));
    Some(out)
}
