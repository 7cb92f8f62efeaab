//! The bake's colour volume from an attribute instead of the materials.
//!
//! The shader reads one colour volume for the surface and the cut plane;
//! in attribute mode [`shade`] fills it from the attribute's values at the
//! inside voxels: a scalar through a colour map over a fixed or automatic
//! range (automatic = the smallest and largest baked value), a vec3 by its
//! magnitude the same way, a vec4 (`color`) as its own RGBA. Inside voxels
//! where no node defines the attribute are drawn [`UNDEFINED`] grey, so a
//! part without it stands out instead of taking the lowest colour.

use std::sync::atomic::{AtomicBool, Ordering};

use rayon::prelude::*;
use volcad_core::Points;
use volcad_core::sampler::Grid;

use crate::bake::BakeError;
use crate::colormap::ColorMap;

/// Colour of inside voxels where the attribute has no value.
pub const UNDEFINED: [u8; 4] = [118, 118, 118, 255];

/// Which attribute colours the bake, and how.
#[derive(Clone, Debug, PartialEq)]
pub struct AttributeShading {
    /// Index into `Model::attributes()`.
    pub index: usize,
    /// Values per point: 1 scalar, 3 vec3 (shaded by magnitude), 4 RGBA.
    pub width: usize,
    /// Range mapped onto the colour map; `None`: the baked values' own.
    pub range: Option<[f64; 2]>,
    /// The colour map for scalars and magnitudes.
    pub map: ColorMap,
}

/// Evaluates the attribute for a batch of points: `width` values per
/// point into the output, NaN where it is not defined; an error message
/// for a value out of its range.
pub type AttributeEval<'a> = dyn Fn(Points<'_>, &mut [f64]) -> Result<(), String> + Sync + 'a;

/// Per-row buffers: the inside voxels' coordinates, indices and values.
#[derive(Default)]
struct RowBuf {
    x: Vec<f64>,
    y: Vec<f64>,
    z: Vec<f64>,
    at: Vec<usize>,
    out: Vec<f64>,
}

/// Fill `color` (one texel per voxel of `grid`) from the attribute at the
/// voxels `inside` says are inside; outside voxels keep their colour.
/// Returns the range the scalars were mapped over (`None` for colours, or
/// when no voxel had a value).
pub fn shade(
    grid: &Grid,
    inside: &(dyn Fn(usize) -> bool + Sync),
    shading: &AttributeShading,
    eval: &AttributeEval<'_>,
    color: &mut [[u8; 4]],
    cancel: &AtomicBool,
) -> Result<Option<[f64; 2]>, BakeError> {
    let nx = grid.dims[0];
    let width = shading.width.clamp(1, 4);
    let row = |row: usize, b: &mut RowBuf| {
        if cancel.load(Ordering::Relaxed) {
            b.at.clear();
            return Ok(());
        }
        eval_row(grid, inside, eval, width, row, b)
    };
    if width == 4 {
        let failed = by_rows(color, nx, &row, |c, i, x| c[i] = rgba(x), 4);
        return finish(failed, cancel).map(|_| None);
    }
    // Scalars (or magnitudes) first, then the range, then the colours.
    let mut value = vec![f32::NAN; color.len()];
    let failed = by_rows(
        &mut value,
        nx,
        &row,
        |v, i, x| v[i] = scalar_of(x) as f32,
        width,
    );
    finish(failed, cancel)?;
    let range = shading.range.or_else(|| auto_range(&value));
    let Some([lo, hi]) = range else {
        color
            .par_iter_mut()
            .enumerate()
            .filter(|(v, _)| inside(*v))
            .for_each(|(_, c)| *c = UNDEFINED);
        return Ok(None);
    };
    color
        .par_iter_mut()
        .zip(value.par_iter())
        .enumerate()
        .for_each(|(v, (c, x))| {
            if !x.is_nan() {
                *c = shading.map.color_in(*x as f64, lo, hi);
            } else if inside(v) {
                *c = UNDEFINED;
            }
        });
    Ok(range)
}

/// Evaluates the rows of `out` (`nx` voxels each) in parallel with `row`,
/// then hands each evaluated voxel's `width` numbers to `put(row of out,
/// its index in the row, numbers)`: the first failing row and its error.
fn by_rows<T: Send>(
    out: &mut [T],
    nx: usize,
    row: &(impl Fn(usize, &mut RowBuf) -> Result<(), (usize, String)> + Sync),
    put: impl Fn(&mut [T], usize, &[f64]) + Sync,
    width: usize,
) -> Option<(usize, String)> {
    out.par_chunks_mut(nx)
        .enumerate()
        .map_init(RowBuf::default, |b, (r, o)| {
            row(r, b)?;
            for (n, &i) in b.at.iter().enumerate() {
                put(o, i, &b.out[n * width..(n + 1) * width]);
            }
            Ok(())
        })
        .filter_map(Result::err)
        .min_by_key(|(r, _)| *r)
}

/// Cancelled, or the first row's error, or fine.
fn finish(failed: Option<(usize, String)>, cancel: &AtomicBool) -> Result<(), BakeError> {
    if cancel.load(Ordering::Relaxed) {
        return Err(BakeError::Cancelled);
    }
    match failed {
        Some((_, e)) => Err(BakeError::Attribute(e)),
        None => Ok(()),
    }
}

/// Evaluate row `row` (voxels `row·nx ..`) at its inside voxels into `b`.
fn eval_row(
    grid: &Grid,
    inside: &(dyn Fn(usize) -> bool + Sync),
    eval: &AttributeEval<'_>,
    width: usize,
    row: usize,
    b: &mut RowBuf,
) -> Result<(), (usize, String)> {
    let [nx, ny, _] = grid.dims;
    let (j, k) = (row % ny, row / ny);
    b.x.clear();
    b.y.clear();
    b.z.clear();
    b.at.clear();
    b.out.clear();
    for i in 0..nx {
        if inside(row * nx + i) {
            let p = grid.center(i, j, k);
            b.x.push(p.x);
            b.y.push(p.y);
            b.z.push(p.z);
            b.at.push(i);
        }
    }
    if b.at.is_empty() {
        return Ok(());
    }
    b.out.resize(b.at.len() * width, f64::NAN);
    let pts = Points {
        x: &b.x,
        y: &b.y,
        z: &b.z,
    };
    eval(pts, &mut b.out).map_err(|e| (row, e))
}

/// A scalar as it is, a vector by its magnitude (NaN stays NaN).
fn scalar_of(x: &[f64]) -> f64 {
    match x {
        [v] => *v,
        _ => x.iter().map(|c| c * c).sum::<f64>().sqrt(),
    }
}

/// The smallest and largest value that is not NaN.
fn auto_range(value: &[f32]) -> Option<[f64; 2]> {
    let (lo, hi) = value
        .par_iter()
        .filter(|v| !v.is_nan())
        .fold(
            || (f32::INFINITY, f32::NEG_INFINITY),
            |(lo, hi), v| (lo.min(*v), hi.max(*v)),
        )
        .reduce(
            || (f32::INFINITY, f32::NEG_INFINITY),
            |a, b| (a.0.min(b.0), a.1.max(b.1)),
        );
    (lo <= hi).then_some([lo as f64, hi as f64])
}

/// An RGBA value (0-1 per channel) as a texel; undefined (NaN) as grey.
fn rgba(v: &[f64]) -> [u8; 4] {
    if v.iter().any(|c| c.is_nan()) {
        return UNDEFINED;
    }
    [v[0], v[1], v[2], v[3]].map(|c| (c * 255.0).round().clamp(0.0, 255.0) as u8)
}
