//! `volcad sample`: batch evaluation of points from a CSV.

use std::io::{BufWriter, Write};
use std::path::Path;

use anyhow::{Context, bail};
use glam::DVec3;
use rayon::prelude::*;

use super::DesignArgs;
use super::design::load_design;

/// Read `x,y,z` rows (header required, column order free).
fn read_points(path: &Path) -> anyhow::Result<Vec<DVec3>> {
    let text =
        std::fs::read_to_string(path).with_context(|| format!("cannot read {}", path.display()))?;
    let mut lines = text
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty());
    let Some((_, header)) = lines.next() else {
        bail!("{}: empty file; expected a header `x,y,z`", path.display());
    };
    let cols: Vec<String> = header.split(',').map(|c| c.trim().to_lowercase()).collect();
    let find = |n: &str| {
        cols.iter().position(|c| c == n).with_context(|| {
            format!(
                "{}:1: no column `{n}` in the header (expected x,y,z)",
                path.display()
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
                        "{}:{}: `{name}` = {s:?} is not a finite number",
                        path.display(),
                        i + 1
                    )
                })
        };
        pts.push(DVec3::new(get(ix, "x")?, get(iy, "y")?, get(iz, "z")?));
    }
    Ok(pts)
}

/// `volcad sample DESIGN --points in.csv --out out.csv`.
pub fn sample(args: &DesignArgs, points: &Path, out: &Path) -> anyhow::Result<()> {
    let pts = read_points(points)?;
    let l = load_design(args)?;
    let model = &l.model;
    let k = model.materials().len();
    let rows: Vec<String> = pts
        .par_iter()
        .map_init(
            || vec![0.0; k],
            |f, p| {
                let d = model.eval_into(*p, f);
                let mut s = format!("{},{},{},{}", p.x, p.y, p.z, d);
                for v in f.iter() {
                    s.push(',');
                    s.push_str(&v.to_string());
                }
                s
            },
        )
        .collect();
    let tmp = out.with_extension("csv.partial");
    let write = || -> std::io::Result<()> {
        let mut w = BufWriter::new(std::fs::File::create(&tmp)?);
        write!(w, "x,y,z,distance")?;
        for id in model.materials() {
            write!(w, ",{}", model.table().name(*id))?;
        }
        writeln!(w)?;
        for r in &rows {
            writeln!(w, "{r}")?;
        }
        w.into_inner().map_err(|e| e.into_error())?.sync_all()?;
        std::fs::rename(&tmp, out)
    };
    write().with_context(|| format!("cannot write {}", out.display()))?;
    eprintln!("{} points -> {}", rows.len(), out.display());
    Ok(())
}
