//! Loading a design script from disk for a CLI command.

use std::collections::HashMap;
use std::sync::Arc;
use std::time::{Duration, Instant};

use anyhow::{Context, bail};
use volcad_core::Model;
use volcad_core::material::nearest_name;
use volcad_core::script::param_sets::ParamSets;
use volcad_core::script::{Design, Param, ScriptOptions};
use volcad_core::vcad::run_design;

use super::DesignArgs;
use super::output::clip;

/// A loaded, prepared design with its timings.
pub struct Loaded {
    /// What the script built.
    pub design: Design,
    /// The prepared model.
    pub model: Arc<Model>,
    /// The script text (for hashes).
    pub source: String,
    /// Script run time.
    pub script_time: Duration,
}

/// Parse `name=value` parameter overrides.
fn parse_params(params: &[String]) -> anyhow::Result<HashMap<String, f64>> {
    let mut out = HashMap::new();
    for p in params {
        let shown = clip(p, 60);
        let Some((k, v)) = p.split_once('=') else {
            bail!("--param {shown}: expected NAME=VALUE");
        };
        let v: f64 = v
            .trim()
            .parse()
            .with_context(|| format!("--param {shown}: {:?} is not a number", clip(v, 40)))?;
        out.insert(k.trim().to_owned(), v);
    }
    Ok(out)
}

/// Every `--param` must name a parameter the design declares, with a value
/// in its range. The script itself ignores unknown names and clamps values
/// to the range (right for the studio's sliders); on the command line a
/// typo or a value out of range would give files that are not what was
/// asked for, so it is refused.
fn check_params(given: &HashMap<String, f64>, declared: &[Param]) -> anyhow::Result<()> {
    let mut names: Vec<&String> = given.keys().collect();
    names.sort();
    for name in names {
        let v = given[name];
        match declared.iter().find(|p| &p.name == name) {
            Some(p) if !(p.min..=p.max).contains(&v) => bail!(
                "--param {name}={v}: outside the range {}..={} that the design declares",
                p.min,
                p.max
            ),
            Some(_) => {}
            None => {
                let near = nearest_name(name, declared.iter().map(|p| p.name.as_str()));
                let hint = near.map_or(String::new(), |n| format!("; did you mean `{n}`?"));
                let list: Vec<&str> = declared.iter().map(|p| p.name.as_str()).collect();
                let name = clip(name, 60);
                bail!(
                    "--param {name}: the design declares no parameter `{name}`{hint} (its parameters: {})",
                    if list.is_empty() {
                        "none".to_string()
                    } else {
                        list.join(", ")
                    }
                );
            }
        }
    }
    Ok(())
}

/// The values of `--params FILE --set NAME` (none without them).
fn set_params(args: &DesignArgs) -> anyhow::Result<HashMap<String, f64>> {
    let (Some(file), Some(name)) = (&args.params_file, &args.set) else {
        return Ok(HashMap::new());
    };
    let sets = ParamSets::load(file).map_err(|e| anyhow::anyhow!("--params {e}"))?;
    sets.values(name)
        .map_err(|e| anyhow::anyhow!("--set {name}: {e} ({})", file.display()))
}

/// Each `--allow-read DIR` must be a folder that exists: a typo would
/// otherwise surface only as a refused file later.
fn allowed_folders(dirs: &[std::path::PathBuf]) -> anyhow::Result<Vec<std::path::PathBuf>> {
    dirs.iter()
        .map(|d| {
            if d.is_dir() {
                Ok(d.clone())
            } else {
                bail!("--allow-read {}: no such folder", d.display())
            }
        })
        .collect()
}

/// Run and prepare the design named by `args`; warnings go to stderr.
pub fn load_design(args: &DesignArgs) -> anyhow::Result<Loaded> {
    let source = super::output::read_input(&args.design, "design script")?;
    let mut opts = ScriptOptions::for_file(&args.design);
    opts.params = set_params(args)?;
    opts.params.extend(parse_params(&args.params)?);
    opts.allow_read = allowed_folders(&args.allow_read)?;
    let name = args.design.display().to_string();
    let start = Instant::now();
    // `.vcad` files are legacy OpenVCAD text designs; anything else is Rhai.
    let design = run_design(&source, &name, &opts)?;
    let script_time = start.elapsed();
    check_params(&opts.params, &design.params)?;
    for line in &design.log {
        note!("[script] {line}");
    }
    for w in &design.warnings {
        note!("warning: {w}");
    }
    let model = Model::prepare(&design.root, design.materials.clone())
        .with_context(|| format!("{name}: cannot prepare the design"))?;
    Ok(Loaded {
        design,
        model: Arc::new(model),
        source,
        script_time,
    })
}
