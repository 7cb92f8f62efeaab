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
    for (id, f) in fracs {
        outln!("{}: {f}", l.model.table().name(id));
    }
    Ok(())
}
