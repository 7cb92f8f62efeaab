//! `volcad render`: one view of a design to a PNG, through the same GPU
//! pipeline as the studio's viewport (offscreen).

use std::path::PathBuf;

use anyhow::{Context, bail};
use volcad_render::{Camera, CutPlane, StandardView, ViewMode, ViewSettings};

use super::DesignArgs;
use super::design::load_design;

/// `volcad render` options.
#[derive(clap::Args, Debug)]
pub struct RenderArgs {
    /// The design.
    #[command(flatten)]
    pub design: DesignArgs,
    /// Output PNG (`-` for standard output).
    #[arg(long)]
    pub out: PathBuf,
    /// Standard view: iso, top, front, side, bottom.
    #[arg(long, default_value = "iso")]
    pub view: String,
    /// Image size, WIDTHxHEIGHT.
    #[arg(long, default_value = "1024x768")]
    pub size: String,
    /// Cut plane, e.g. `z=0` or `x=-2.5` (keeps the part below the plane).
    #[arg(long)]
    pub cut: Option<String>,
    /// solid or volume.
    #[arg(long, default_value = "solid")]
    pub mode: String,
    /// Bake resolution (voxels along the longest side).
    #[arg(long, default_value_t = 256, allow_negative_numbers = true)]
    pub resolution: u32,
    /// Orthographic projection.
    #[arg(long)]
    pub ortho: bool,
    /// Hide a material by name (repeatable), e.g. `--hide clear` to see the
    /// bunny's struts through its clear body.
    #[arg(long = "hide", value_name = "MATERIAL")]
    pub hide: Vec<String>,
}

fn parse_view(v: &str) -> anyhow::Result<StandardView> {
    Ok(match v {
        "iso" => StandardView::Iso,
        "top" => StandardView::Top,
        "front" => StandardView::Front,
        "side" => StandardView::Side,
        "bottom" => StandardView::Bottom,
        _ => bail!("--view {v}: expected iso, top, front, side or bottom"),
    })
}

fn parse_size(s: &str) -> anyhow::Result<[u32; 2]> {
    let (w, h) = s
        .split_once('x')
        .with_context(|| format!("--size {s}: expected WIDTHxHEIGHT, e.g. 1024x768"))?;
    let w: u32 = w
        .parse()
        .with_context(|| format!("--size {s}: bad width"))?;
    let h: u32 = h
        .parse()
        .with_context(|| format!("--size {s}: bad height"))?;
    if !(16..=8192).contains(&w) || !(16..=8192).contains(&h) {
        bail!("--size {s}: width and height must be within 16..=8192");
    }
    Ok([w, h])
}

fn parse_cut(s: &str) -> anyhow::Result<CutPlane> {
    let (axis, off) = s
        .split_once('=')
        .with_context(|| format!("--cut {s}: expected AXIS=OFFSET, e.g. z=0"))?;
    let axis = match axis.trim() {
        "x" => 0,
        "y" => 1,
        "z" => 2,
        a => bail!("--cut {s}: axis {a:?} is not x, y or z"),
    };
    let offset: f32 = off
        .trim()
        .parse()
        .ok()
        .filter(|v: &f32| v.is_finite())
        .with_context(|| format!("--cut {s}: {off:?} is not a finite number of mm"))?;
    Ok(CutPlane {
        axis,
        offset,
        keep_below: true,
    })
}

/// Run `volcad render`.
pub fn render(a: &RenderArgs) -> anyhow::Result<()> {
    let view = parse_view(&a.view)?;
    let size = parse_size(&a.size)?;
    let cut = a.cut.as_deref().map(parse_cut).transpose()?;
    // A folder or socket as --out is refused before the work, not after.
    super::output::target(&a.out, "--out")?;
    let mode = match a.mode.as_str() {
        "solid" => ViewMode::Solid,
        "volume" => ViewMode::Volume,
        m => bail!("--mode {m}: expected solid or volume"),
    };
    let l = load_design(&a.design)?;
    let bbox = l.model.bbox();
    if !bbox.is_finite() {
        bail!("the design is unbounded; clip Tile or TPMS with Intersection and a bounded shape");
    }
    let mut camera = Camera::fit(&bbox, view);
    camera.orthographic = a.ortho;
    let mut material_opacity = vec![1.0; l.model.materials().len()];
    for name in &a.hide {
        let id = l
            .model
            .table()
            .id(name)
            .with_context(|| format!("--hide {name}"))?;
        let slot = l
            .model
            .materials()
            .iter()
            .position(|m| *m == id)
            .with_context(|| format!("--hide {name}: the design does not use this material"))?;
        material_opacity[slot] = 0.0;
    }
    let settings = ViewSettings {
        camera,
        mode,
        cut,
        material_opacity,
        ..ViewSettings::default()
    };
    let img = volcad_render::render_offscreen(&l.model, &settings, size, a.resolution)?;
    // The PNG encoder wants to seek: encode in memory, then write.
    let mut png = std::io::Cursor::new(Vec::new());
    img.write_to(&mut png, image::ImageFormat::Png)
        .context("cannot encode the PNG")?;
    super::output::write_output(&a.out, "--out", |w| w.write_all(png.get_ref()))?;
    note!("{} ({}x{}) written", a.out.display(), size[0], size[1]);
    Ok(())
}
