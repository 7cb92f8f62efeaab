//! `volcad export vat DESIGN --out DIR`: grayscale slice stacks for vat
//! photopolymer printers, one image of the whole screen per layer (and per
//! vat), from a printer preset or a custom screen.

use anyhow::{Context, bail};
use volcad_compilers::plan::VatText;
use volcad_compilers::plan::text::parse_pair;
use volcad_compilers::vat::{Intensity, VatParams, VatPrinter, vat_preset};
use volcad_core::Model;

use super::export::{ExportArgs, parse_dither};

/// `volcad export vat` options (boxed in [`ExportArgs`]: they would make
/// every command's arguments larger).
#[derive(clap::Args, Debug)]
pub struct VatArgs {
    /// vat: gray value from a scalar attribute (its name) or a material's fraction (fraction:NAME); default 255 inside.
    #[arg(long)]
    pub intensity: Option<String>,
    /// vat: the attribute values shown as black and white, LO,HI (default: the attribute's bound over the design).
    #[arg(long, allow_hyphen_values = true)]
    pub range: Option<String>,
    /// vat: number of vats (1, 2 or 4): one image per vat per layer, each voxel in one vat.
    #[arg(long)]
    pub vats: Option<usize>,
    /// vat: the materials of each vat in order, e.g. a,b (a+c,b for several in one vat).
    #[arg(long)]
    pub vat_materials: Option<String>,
    /// vat, custom printer: pixel pitch in um, one value or X,Y.
    #[arg(long)]
    pub pixel: Option<String>,
    /// vat, custom printer: screen size in pixels, WxH.
    #[arg(long)]
    pub screen: Option<String>,
    /// vat: layer thickness in um (default: the preset's).
    #[arg(long)]
    pub layer: Option<f64>,
    /// vat: move the part's centre from the screen's by X,Y mm.
    #[arg(long, allow_hyphen_values = true)]
    pub offset: Option<String>,
    /// vat: write 8-bit BMP images instead of PNG.
    #[arg(long)]
    pub bmp: bool,
}

impl VatArgs {
    /// The vat options given (for refusing them on other exports).
    pub fn given(&self) -> Vec<&'static str> {
        super::export::given_names(&[
            ("--intensity", self.intensity.is_some()),
            ("--range", self.range.is_some()),
            ("--vats", self.vats.is_some()),
            ("--vat-materials", self.vat_materials.is_some()),
            ("--pixel", self.pixel.is_some()),
            ("--screen", self.screen.is_some()),
            ("--layer", self.layer.is_some()),
            ("--offset", self.offset.is_some()),
            ("--bmp", self.bmp),
        ])
    }
}

/// The printer: a preset (with `--layer` overriding its layer) or a custom
/// screen from `--pixel`, `--screen` and `--layer`.
fn printer(a: &ExportArgs) -> anyhow::Result<VatPrinter> {
    let v = &a.vat;
    if let Some(name) = &a.preset {
        if v.pixel.is_some() || v.screen.is_some() {
            bail!(
                "--preset {name} sets the pixel and the screen; leave out --pixel and --screen, or --preset for a custom printer"
            );
        }
        let mut p = vat_preset(name)?;
        if let Some(l) = v.layer {
            p = VatPrinter::custom([p.pixel[0] * 1000.0, p.pixel[1] * 1000.0], p.screen, l).map(
                |c| VatPrinter {
                    name: p.name.clone(),
                    layer: c.layer,
                    ..p.clone()
                },
            )?;
        }
        return Ok(p);
    }
    let (Some(px), Some(sc)) = (&v.pixel, &v.screen) else {
        bail!(
            "vat needs a printer: --preset saturn-4-ultra (or photon-mono-m7-pro), or a custom screen with --pixel UM --screen WxH --layer UM"
        );
    };
    let pixel = if px.contains(',') {
        parse_pair("--pixel", px, "19,24")?
    } else {
        let u: f64 = px
            .trim()
            .parse()
            .with_context(|| format!("--pixel {px}: not a number of um"))?;
        [u, u]
    };
    let (w, h) = sc
        .split_once(['x', 'X'])
        .with_context(|| format!("--screen {sc}: expected WxH in pixels, e.g. 11520x5120"))?;
    let dim = |t: &str| {
        t.trim()
            .parse::<usize>()
            .with_context(|| format!("--screen {sc}: {t:?} is not a pixel count"))
    };
    let layer = v
        .layer
        .context("a custom vat printer needs --layer UM (e.g. --layer 50)")?;
    Ok(VatPrinter::custom(pixel, [dim(w)?, dim(h)?], layer)?)
}

/// The materials of each vat: `--vat-materials` groups (`a+c,b`), or with
/// `--vats N` alone the design's materials in order when it has N, or
/// every material in one vat.
fn vat_groups(a: &ExportArgs, model: &Model) -> anyhow::Result<Vec<Vec<String>>> {
    let v = &a.vat;
    let groups: Option<Vec<Vec<String>>> = v.vat_materials.as_deref().map(|s| {
        s.split(',')
            .map(|g| {
                g.split('+')
                    .map(|m| m.trim().to_owned())
                    .filter(|m| !m.is_empty())
                    .collect()
            })
            .collect()
    });
    let names: Vec<String> = model
        .materials()
        .iter()
        .map(|id| model.table().name(*id).to_owned())
        .collect();
    match (v.vats, groups) {
        (Some(n), Some(g)) if g.len() != n => bail!(
            "--vat-materials {}: {} group(s) for --vats {n}; give one group per vat",
            v.vat_materials.as_deref().unwrap_or(""),
            g.len()
        ),
        (_, Some(g)) => Ok(g),
        (None | Some(1), None) => Ok(Vec::new()),
        (Some(n), None) if names.len() == n => Ok(names.into_iter().map(|m| vec![m]).collect()),
        (Some(n), None) => bail!(
            "--vats {n}: the design has {} material(s) ({}); say which go to each vat with --vat-materials, e.g. --vat-materials {}",
            names.len(),
            names.join(", "),
            names.join(",")
        ),
    }
}

/// The vat stack's parameters from the options.
pub(super) fn vat_params(a: &ExportArgs, model: &Model) -> anyhow::Result<VatParams> {
    if a.voxel.is_some() {
        bail!(
            "--voxel does not apply to vat: the printer's pixel and layer are the voxel (--preset, or --pixel/--screen/--layer)"
        );
    }
    let v = &a.vat;
    let mut intensity = match v.intensity.as_deref() {
        None => Intensity::Solid,
        Some(s) => match s.strip_prefix("fraction:") {
            Some(m) => Intensity::Fraction(m.trim().to_owned()),
            None => Intensity::Attribute {
                name: s.trim().to_owned(),
                range: None,
            },
        },
    };
    let chosen = VatText {
        layers: a.layers.as_deref(),
        shard: a.shard.as_deref(),
        offset: v.offset.as_deref(),
        range: v.range.as_deref(),
    }
    .apply(&mut intensity)?;
    Ok(VatParams {
        printer: printer(a)?,
        intensity,
        vats: vat_groups(a, model)?,
        offset: chosen.offset,
        bmp: v.bmp,
        seed: a.seed,
        dither: parse_dither(a.dither.as_deref())?,
        layers: chosen.layers,
        shard: chosen.shard,
        threads: a.threads,
    })
}
