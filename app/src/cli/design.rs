//! Loading a design script from disk for a CLI command.

use std::collections::HashMap;
use std::sync::Arc;
use std::time::{Duration, Instant};

use anyhow::{Context, bail};
use volcad_core::Model;
use volcad_core::script::{Design, ScriptOptions, run_script};

use super::DesignArgs;

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
        let Some((k, v)) = p.split_once('=') else {
            bail!("--param {p}: expected NAME=VALUE");
        };
        let v: f64 = v
            .trim()
            .parse()
            .with_context(|| format!("--param {p}: {v:?} is not a number"))?;
        out.insert(k.trim().to_owned(), v);
    }
    Ok(out)
}

/// Run and prepare the design named by `args`; warnings go to stderr.
pub fn load_design(args: &DesignArgs) -> anyhow::Result<Loaded> {
    let source = std::fs::read_to_string(&args.design)
        .with_context(|| format!("cannot read {}", args.design.display()))?;
    let mut opts = ScriptOptions::for_file(&args.design);
    opts.params = parse_params(&args.params)?;
    let name = args.design.display().to_string();
    let start = Instant::now();
    let design = run_script(&source, &name, &opts)?;
    let script_time = start.elapsed();
    for line in &design.log {
        eprintln!("[script] {line}");
    }
    for w in &design.warnings {
        eprintln!("warning: {w}");
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
