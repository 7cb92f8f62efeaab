//! `volcad eval`.

use glam::DVec3;

use super::DesignArgs;
use super::design::load_design;

/// `volcad eval DESIGN X Y Z`.
pub fn eval(args: &DesignArgs, x: f64, y: f64, z: f64) -> anyhow::Result<()> {
    for (axis, v) in [("X", x), ("Y", y), ("Z", z)] {
        if !v.is_finite() {
            anyhow::bail!("{axis} = {v}: give a finite coordinate in mm");
        }
    }
    let l = load_design(args)?;
    let (d, fracs) = l.model.eval_point(DVec3::new(x, y, z));
    outln!("distance: {d}");
    if fracs.is_empty() {
        outln!("outside: no material");
    }
    for (id, f) in &fracs {
        outln!("{}: {f}", l.model.table().name(*id));
    }
    // Attributes have values only inside (NaN, printed "none", outside).
    if !fracs.is_empty() {
        let p = DVec3::new(x, y, z);
        for (i, a) in l.model.attributes().iter().enumerate() {
            let mut v = [0.0; 4];
            let v = &mut v[..a.kind.width()];
            l.model.attribute_at(i, p, v)?;
            outln!(
                "attribute {}: {}",
                a.name,
                volcad_core::attribute::value_text(v)
            );
        }
    }
    Ok(())
}
