//! `volcad info`.

use super::DesignArgs;
use super::design::load_design;

/// `volcad info DESIGN`.
pub fn info(args: &DesignArgs) -> anyhow::Result<()> {
    let l = load_design(args)?;
    let m = &l.model;
    let b = m.bbox();
    outln!("design:      {}", args.design.display());
    outln!("root:        {}", l.design.root.kind().type_name());
    outln!("nodes:       {}", m.node_count());
    outln!(
        "bbox (mm):   [{:.4}, {:.4}, {:.4}] .. [{:.4}, {:.4}, {:.4}]",
        b.min.x,
        b.min.y,
        b.min.z,
        b.max.x,
        b.max.y,
        b.max.z
    );
    let s = b.size();
    outln!("size (mm):   {:.4} x {:.4} x {:.4}", s.x, s.y, s.z);
    let names: Vec<String> = m
        .materials()
        .iter()
        .map(|id| format!("{} ({id})", m.table().name(*id)))
        .collect();
    outln!("materials:   {}", names.join(", "));
    outln!("table:       {}", m.table().origin());
    for p in &l.design.params {
        outln!(
            "param:       {} = {} (default {}, range {}..{})",
            p.name,
            p.value,
            p.default,
            p.min,
            p.max
        );
    }
    for line in volcad_core::attribute::describe_tree(&l.design.root, m.table()) {
        outln!("attribute:   {line}");
    }
    outln!("script time: {:.3} s", l.script_time.as_secs_f64());
    outln!("prepare:     {:.3} s", m.prepare_time().as_secs_f64());
    Ok(())
}
