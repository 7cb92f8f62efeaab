//! `volcad sample`: batch evaluation of points from a CSV.

use std::path::Path;

use anyhow::{Context, bail};
use glam::DVec3;
use rayon::prelude::*;

use super::DesignArgs;
use super::design::load_design;
use super::output::{clip, read_input, target, write_output};

/// Read `x,y,z` rows (header required, column order free).
fn read_points(path: &Path) -> anyhow::Result<Vec<DVec3>> {
    let text = read_input(path, "points")?;
    let mut lines = text
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty());
    let Some((hi, header)) = lines.next() else {
        bail!("{}: empty file; expected a header `x,y,z`", path.display());
    };
    let cols: Vec<String> = header.split(',').map(|c| c.trim().to_lowercase()).collect();
    let find = |n: &str| {
        cols.iter().position(|c| c == n).with_context(|| {
            format!(
                "{}:{}: no column `{n}` in the header (expected x,y,z)",
                path.display(),
                hi + 1
            )
        })
    };
    let (ix, iy, iz) = (find("x")?, find("y")?, find("z")?);
    let mut pts = Vec::new();
    for (i, line) in lines {
        let cells: Vec<&str> = line.split(',').map(str::trim).collect();
        let get = |c: usize, name: &str| -> anyhow::Result<f64> {
            let s = cells.get(c).with_context(|| {
                format!("{}:{}: missing column `{name}`", path.display(), i + 1)
            })?;
            s.parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .with_context(|| {
                    format!(
                        "{}:{}: `{name}` = {:?} is not a finite number",
                        path.display(),
                        i + 1,
                        clip(s, 40)
                    )
                })
        };
        pts.push(DVec3::new(get(ix, "x")?, get(iy, "y")?, get(iz, "z")?));
    }
    Ok(pts)
}

/// `volcad sample DESIGN --points in.csv --out out.csv [--attributes a,b]`.
pub fn sample(
    args: &DesignArgs,
    points: &Path,
    out: &Path,
    attributes: &[String],
) -> anyhow::Result<()> {
    // A folder or socket as --out is refused before the work, not after.
    target(out, "--out")?;
    let pts = read_points(points)?;
    let l = load_design(args)?;
    let model = &l.model;
    let wanted = attributes
        .iter()
        .map(|a| model.require_attribute(a.trim()))
        .collect::<Result<Vec<usize>, _>>()
        .map_err(|e| anyhow::anyhow!("--attributes: {e}"))?;
    let k = model.materials().len();
    let width: usize = wanted
        .iter()
        .map(|&i| model.attributes()[i].kind.width())
        .sum();
    // Distance, fractions and attributes in one walk, a chunk at a time
    // (a math string runs over the chunk's points at once).
    let chunks: Vec<anyhow::Result<Vec<String>>> = pts
        .par_chunks(1024)
        .map(|chunk| -> anyhow::Result<Vec<String>> {
            let n = chunk.len();
            let (mut d, mut f, mut a) = (vec![0.0; n], vec![0.0; n * k], vec![0.0; n * width]);
            model.eval_with_attributes_batch(chunk, &mut d, &mut f, &wanted, &mut a)?;
            Ok((0..n)
                .map(|i| {
                    let p = chunk[i];
                    let mut s = format!("{},{},{},{}", p.x, p.y, p.z, d[i]);
                    let row = f[i * k..(i + 1) * k].iter();
                    for v in row.chain(&a[i * width..(i + 1) * width]) {
                        s.push(',');
                        s.push_str(&v.to_string());
                    }
                    s
                })
                .collect())
        })
        .collect();
    let mut rows = Vec::with_capacity(pts.len());
    // The first failing point in input order, whatever the threads did.
    for c in chunks {
        rows.extend(c?);
    }
    write_output(out, "--out", |w| {
        write!(w, "x,y,z,distance")?;
        for id in model.materials() {
            write!(w, ",{}", model.table().name(*id))?;
        }
        for &i in &wanted {
            for c in volcad_core::attribute::column_names(&model.attributes()[i]) {
                write!(w, ",{c}")?;
            }
        }
        writeln!(w)?;
        for r in &rows {
            writeln!(w, "{r}")?;
        }
        Ok(())
    })?;
    note!("{} points -> {}", rows.len(), out.display());
    Ok(())
}
