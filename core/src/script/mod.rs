//! Design scripts: Rhai with pyvcad's node names (the paper's listings
//! translate line by line).
//!
//! `run_script(text) → Design { root node, material table, parameters, log }`.
//! The engine is built per run with the run's context (script folder,
//! parameter overrides, cancel flag), compiled once and evaluated once; it is
//! `Send + Sync` (Rhai's `sync` feature) so runs happen on worker threads. A
//! runaway script stops at an operation limit, at its heap budget (where the
//! binary counts the heap, `crate::heap`), or when its cancel flag is set.
//! The design is the script's final value, or else a variable named `root`.

/// Registers the constructor `$name` twice, as pyvcad overloads it: with
/// the arguments `$arg…` (the last one left to its default) and with one
/// more, `$last`. `$f(&ctx, &arg…, Option<&last>)` builds the node.
macro_rules! register_optional_last {
    ($engine:expr, $name:literal, $f:ident($($arg:ident),+; $last:ident)) => {
        $engine.register_fn($name, move |c: Ctx, $($arg: Dynamic),+| $f(&c, $(&$arg),+, None));
        $engine.register_fn($name, move |c: Ctx, $($arg: Dynamic),+, $last: Dynamic| {
            $f(&c, $(&$arg),+, Some(&$last))
        });
    };
}

mod arith;
mod attribute_api;
mod bulk;
mod errors;
mod file_cache;
mod files_api;
mod fractions_api;
mod image_api;
mod leaves_api;
mod nodes_api;
mod one_shot;
pub mod param_sets;
mod points_api;
mod query_api;
pub(crate) mod read_policy;
pub mod reference;
mod shapes_api;
mod text_api;
mod toplevel;
mod values;

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};

use rhai::{Dynamic, Engine, EvalAltResult, NativeCallContext as Ctx, Position, Scope};

use crate::material::MaterialTable;
use crate::node::{LatticeType, Node};
pub use attribute_api::Vec4;
pub use errors::clip;
use errors::{HEAP_STOP, MAX_MESSAGE, to_script_error};
pub use fractions_api::FractionsTarget;
pub use image_api::ImageValue;
pub use one_shot::{DesignError, model_of, model_of_file};
pub use points_api::PointsValue;
pub use values::Vec3;
use values::{RResult, fail};

/// A slider a script declares with `param(name, default, min, max)`.
#[derive(Clone, Debug, PartialEq)]
pub struct Param {
    /// Name shown beside the slider.
    pub name: String,
    /// The value the script ran with.
    pub value: f64,
    /// The declared default.
    pub default: f64,
    /// Lower end of the slider.
    pub min: f64,
    /// Upper end of the slider.
    pub max: f64,
}

/// How to run a script.
#[derive(Clone, Debug)]
pub struct ScriptOptions {
    /// Folder that relative file names (CSV, meshes, tables) resolve in
    /// (the script's folder); the script may read files inside its project
    /// (the nearest folder above it holding `.git` or `volcad.toml`, else
    /// its own folder; never the home folder or one above it). `None`: no
    /// file access.
    pub base_dir: Option<PathBuf>,
    /// More folders the script may read (`--allow-read DIR`, the studio's
    /// read folders).
    pub allow_read: Vec<PathBuf>,
    /// The user's home folder: never part of a project (default: `$HOME`).
    pub home: Option<PathBuf>,
    /// Values for `param(...)` by name, overriding defaults (clamped to range).
    pub params: HashMap<String, f64>,
    /// Set to stop the script at its next operation.
    pub cancel: Option<Arc<AtomicBool>>,
    /// Operation limit (a runaway loop stops with an error).
    pub max_operations: u64,
    /// Most bytes the process heap may grow by while the script runs (a
    /// runaway allocation stops with an error; see [`crate::heap`]).
    /// Checked only where the binary installs the counting allocator.
    pub max_heap: u64,
}

/// The default operation limit. Scripts run 10 to 20 million operations a
/// second (the studio's live runs and the CLI alike), so an endless loop
/// stops within a few seconds; the bundled examples need well under a
/// tenth of it (a loop over a 3,286-strut list included).
pub const DEFAULT_MAX_OPERATIONS: u64 = 50_000_000;

impl Default for ScriptOptions {
    fn default() -> Self {
        Self {
            base_dir: None,
            allow_read: Vec::new(),
            home: read_policy::home_dir(),
            params: HashMap::new(),
            cancel: None,
            max_operations: DEFAULT_MAX_OPERATIONS,
            max_heap: crate::heap::default_script_budget(),
        }
    }
}

impl ScriptOptions {
    /// Options for a script file: files resolve in its folder.
    pub fn for_file(path: &Path) -> Self {
        Self {
            base_dir: path.parent().map(|p| {
                if p.as_os_str().is_empty() {
                    PathBuf::from(".")
                } else {
                    p.to_path_buf()
                }
            }),
            ..Self::default()
        }
    }
}

/// What a script built.
#[derive(Clone, Debug)]
pub struct Design {
    /// The root node.
    pub root: Node,
    /// The material table the script used (pyvcad's default if none).
    pub materials: Arc<MaterialTable>,
    /// Parameters the script declared, in order.
    pub params: Vec<Param>,
    /// Lines the script printed.
    pub log: Vec<String>,
    /// Warnings (for example an open mesh).
    pub warnings: Vec<String>,
}

/// A script failed: where and why.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{file}:{}: {message}", location(.line, .column))]
pub struct ScriptError {
    /// Script name (file name or `<editor>`).
    pub file: String,
    /// 1-based line, if known.
    pub line: Option<usize>,
    /// 1-based column, if known.
    pub column: Option<usize>,
    /// What went wrong, in the script's words.
    pub message: String,
}

fn location(line: &Option<usize>, column: &Option<usize>) -> String {
    match (line, column) {
        (Some(l), Some(c)) => format!("{l}:{c}"),
        (Some(l), None) => format!("{l}"),
        _ => "?".into(),
    }
}

/// Mutable state of one run, shared with the registered functions.
#[derive(Default)]
pub(crate) struct RunState {
    pub table: Option<Arc<MaterialTable>>,
    pub params: Vec<Param>,
    pub log: Vec<String>,
    pub warnings: Vec<String>,
}

/// Context the registered functions read.
#[derive(Clone)]
pub(crate) struct RunContext {
    pub base_dir: Option<PathBuf>,
    pub allow_read: Arc<Vec<PathBuf>>,
    pub home: Option<PathBuf>,
    pub overrides: Arc<HashMap<String, f64>>,
    pub state: Arc<Mutex<RunState>>,
}

impl RunContext {
    /// The context of one run with `opts`: its folders, parameter
    /// overrides and a fresh state.
    pub fn from_options(opts: &ScriptOptions) -> Self {
        RunContext {
            base_dir: opts.base_dir.clone(),
            allow_read: Arc::new(opts.allow_read.clone()),
            home: opts.home.clone(),
            overrides: Arc::new(opts.params.clone()),
            state: Arc::new(Mutex::new(RunState::default())),
        }
    }

    /// Resolve `name` relative to the script's folder, refusing anything
    /// outside its project and the allowed folders.
    pub fn resolve(&self, name: &str, pos: Position) -> RResult<PathBuf> {
        let Some(base) = &self.base_dir else {
            return fail(
                pos,
                format!(
                    "cannot read \"{name}\": save the script first; files are read relative to its folder"
                ),
            );
        };
        read_policy::resolve(name, base, &self.allow_read, self.home.as_deref())
            .or_else(|m| fail(pos, m))
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, RunState> {
        // A panic in another registered function cannot leave the state
        // half-written in a way that matters: take it anyway.
        self.state.lock().unwrap_or_else(|e| e.into_inner())
    }
}

/// The message of an error a registered function raised (without Rhai's
/// position suffix), for readers of other languages (`crate::vcad`).
pub(crate) fn runtime_message(e: &EvalAltResult) -> String {
    match e {
        EvalAltResult::ErrorRuntime(v, _) => v.to_string(),
        other => other.to_string(),
    }
}

/// A mesh file, loaded once while it is unchanged (the cache scripts use).
pub(crate) fn load_mesh(full: &Path) -> Result<Arc<crate::trimesh::TriangleMesh>, String> {
    file_cache::cached(&[full], || crate::trimesh::TriangleMesh::load(full))
        .map_err(|e| e.to_string())
}

/// Run a design script.
pub fn run_script(source: &str, name: &str, opts: &ScriptOptions) -> Result<Design, ScriptError> {
    // Some editors start UTF-8 files with a byte-order mark; it is not code.
    let source = source.strip_prefix('\u{feff}').unwrap_or(source);
    let ctx = RunContext::from_options(opts);
    if let Err(message) = crate::heap::budget_from_env() {
        return Err(ScriptError {
            file: name.to_owned(),
            line: None,
            column: None,
            message,
        });
    }
    let top = toplevel::scan(source);
    let mut scope = Scope::new();
    let cells = toplevel::seed(&mut scope, &top.names);
    let mut engine = build_engine(&ctx, opts);
    toplevel::resolve_in_functions(&mut engine, cells);
    let err = |e: &EvalAltResult| to_script_error(e, name, &engine, opts.max_heap);
    let ast = engine.compile(&top.source).map_err(|e| {
        let pos = e.position();
        ScriptError {
            file: name.to_owned(),
            line: pos.line(),
            column: pos.position(),
            message: clip(&e.err_type().to_string(), MAX_MESSAGE),
        }
    })?;
    let value: Dynamic = engine
        .eval_ast_with_scope(&mut scope, &ast)
        .map_err(|e| err(&e))?;
    let root = match value.try_cast::<Node>() {
        Some(n) => n,
        None => match scope.get_value::<Node>("root") {
            Some(n) => n,
            None => {
                return Err(ScriptError {
                    file: name.to_owned(),
                    line: None,
                    column: None,
                    message: "the script built no design: end it with a node (for example `Union(false, [a, b])`) or assign one to `root`".into(),
                });
            }
        },
    };
    let state = std::mem::take(&mut *ctx.lock());
    let table = state
        .table
        .unwrap_or_else(|| Arc::new(MaterialTable::default_table()));
    check_materials(&root, &table, name)?;
    Ok(Design {
        root,
        materials: table,
        params: state.params,
        log: state.log,
        warnings: state.warnings,
    })
}

/// The names of every function the script engine registers (sorted,
/// once each): the language reference is checked against them.
#[cfg(test)]
pub(crate) fn registered_functions() -> Vec<String> {
    let opts = ScriptOptions::default();
    let ctx = RunContext::from_options(&opts);
    let engine = build_engine(&ctx, &opts);
    let mut names: Vec<String> = engine
        .gen_fn_signatures(false)
        .iter()
        .filter_map(|s| s.split('(').next().map(str::to_owned))
        .collect();
    names.sort();
    names.dedup();
    names
}

fn check_materials(root: &Node, table: &MaterialTable, name: &str) -> Result<(), ScriptError> {
    let mut seen = std::collections::HashSet::new();
    let mut stack = vec![root];
    while let Some(n) = stack.pop() {
        if !seen.insert(n.ptr()) {
            continue;
        }
        for &id in n.kind().own_materials() {
            if let Err(e) = table.check_id(id as i64) {
                let o = n.origin();
                return Err(ScriptError {
                    file: name.to_owned(),
                    line: o.map(|o| o.line as usize),
                    column: o.map(|o| o.column as usize),
                    message: format!("{}: {e} ({})", n.kind().type_name(), table.origin()),
                });
            }
        }
        stack.extend(n.kind().children());
    }
    Ok(())
}

fn build_engine(ctx: &RunContext, opts: &ScriptOptions) -> Engine {
    let mut engine = Engine::new();
    engine.set_max_call_levels(256);
    engine.set_max_expr_depths(512, 256);
    engine.set_max_operations(opts.max_operations);
    // Every operation: cancel, and the heap budget (where counted).
    let cancel = opts.cancel.clone();
    let heap_limit =
        crate::heap::live_bytes().map(|live| (live as u64).saturating_add(opts.max_heap) as usize);
    if cancel.is_some() || heap_limit.is_some() {
        engine.on_progress(move |_| {
            if cancel.as_ref().is_some_and(|c| c.load(Ordering::Relaxed)) {
                return Some(Dynamic::UNIT);
            }
            let limit = heap_limit?;
            crate::heap::live_bytes()
                .is_some_and(|live| live > limit)
                .then(|| Dynamic::from(HEAP_STOP))
        });
    }
    let log = ctx.clone();
    engine.on_print(move |s| log.lock().log.push(s.to_owned()));
    let dbg = ctx.clone();
    engine.on_debug(move |s, _, pos| dbg.lock().log.push(format!("[{pos}] {s}")));

    arith::register(&mut engine);
    register_vec3(&mut engine);
    register_materials(&mut engine, ctx);
    register_lattice_types(&mut engine);
    leaves_api::register_leaves(&mut engine);
    nodes_api::register_composites(&mut engine);
    shapes_api::register_shapes(&mut engine);
    nodes_api::register_methods(&mut engine);
    attribute_api::register(&mut engine, ctx);
    fractions_api::register(&mut engine, ctx);
    points_api::register(&mut engine, ctx);
    image_api::register(&mut engine, ctx);
    files_api::register(&mut engine, ctx);
    query_api::register(&mut engine, ctx);
    text_api::register(&mut engine, ctx);
    bulk::register(&mut engine, opts.max_heap);

    let params = ctx.clone();
    engine.register_fn(
        "param",
        move |c: Ctx, name: &str, default: Dynamic, min: Dynamic, max: Dynamic| -> RResult<f64> {
            let p = c.call_position();
            let default = values::finite(&default, "param: default", p)?;
            let (min, max) = (
                values::finite(&min, "param: min", p)?,
                values::finite(&max, "param: max", p)?,
            );
            if min > max || default < min || default > max {
                return fail(
                    p,
                    format!(
                        "param \"{name}\": need min ≤ default ≤ max, got {min} ≤ {default} ≤ {max}"
                    ),
                );
            }
            let value = params
                .overrides
                .get(name)
                .map_or(default, |v| v.clamp(min, max));
            let mut st = params.lock();
            if st.params.iter().any(|q| q.name == name) {
                return fail(p, format!("param \"{name}\" is declared twice"));
            }
            st.params.push(Param {
                name: name.to_owned(),
                value,
                default,
                min,
                max,
            });
            Ok(value)
        },
    );
    engine
}

fn register_vec3(engine: &mut Engine) {
    use glam::DVec3;
    engine.register_type_with_name::<Vec3>("Vec3");
    engine.register_fn(
        "Vec3",
        |c: Ctx, x: Dynamic, y: Dynamic, z: Dynamic| -> RResult<Vec3> {
            let p = c.call_position();
            Ok(Vec3(DVec3::new(
                values::finite(&x, "Vec3: x", p)?,
                values::finite(&y, "Vec3: y", p)?,
                values::finite(&z, "Vec3: z", p)?,
            )))
        },
    );
    engine.register_fn("Vec3", || Vec3(DVec3::ZERO));
    engine.register_get("x", |v: &mut Vec3| v.0.x);
    engine.register_get("y", |v: &mut Vec3| v.0.y);
    engine.register_get("z", |v: &mut Vec3| v.0.z);
    engine.register_fn("+", |a: Vec3, b: Vec3| Vec3(a.0 + b.0));
    engine.register_fn("-", |a: Vec3, b: Vec3| Vec3(a.0 - b.0));
    engine.register_fn("-", |a: Vec3| Vec3(-a.0));
    engine.register_fn("*", |a: Vec3, s: f64| Vec3(a.0 * s));
    engine.register_fn("*", |s: f64, a: Vec3| Vec3(a.0 * s));
    engine.register_fn("*", |a: Vec3, s: i64| Vec3(a.0 * s as f64));
    engine.register_fn("/", |a: Vec3, s: f64| Vec3(a.0 / s));
    engine.register_fn("/", |a: Vec3, s: i64| Vec3(a.0 / s as f64));
    engine.register_fn("*", |s: i64, a: Vec3| Vec3(a.0 * s as f64));
    engine.register_fn("length", |a: &mut Vec3| a.0.length());
    engine.register_fn("distance", |a: Vec3, b: Vec3| a.0.distance(b.0));
    engine.register_fn("to_string", |a: &mut Vec3| {
        format!("Vec3({}, {}, {})", a.0.x, a.0.y, a.0.z)
    });
    engine.register_fn("to_debug", |a: &mut Vec3| {
        format!("Vec3({}, {}, {})", a.0.x, a.0.y, a.0.z)
    });
}

/// `materials.id("red")` and friends on a shared table.
#[derive(Clone)]
struct MaterialDefs(Arc<MaterialTable>);

fn register_materials(engine: &mut Engine, ctx: &RunContext) {
    engine.register_type_with_name::<MaterialDefs>("MaterialDefs");
    let set = |ctx: &RunContext, t: Arc<MaterialTable>| {
        let mut st = ctx.lock();
        let previous = st.table.as_ref().map(|o| o.origin().to_owned());
        if let Some(old) = previous
            && old != t.origin()
        {
            st.warnings.push(format!(
                "the script made two material tables ({old} and {}); the design uses the last",
                t.origin()
            ));
        }
        st.table = Some(t.clone());
        MaterialDefs(t)
    };
    let c1 = ctx.clone();
    engine.register_fn("default_materials", move || {
        set(&c1, Arc::new(MaterialTable::default_table()))
    });
    let c2 = ctx.clone();
    engine.register_fn("j750_materials", move || {
        set(&c2, Arc::new(MaterialTable::j750()))
    });
    let c3 = ctx.clone();
    engine.register_fn(
        "load_materials",
        move |c: Ctx, path: &str| -> RResult<MaterialDefs> {
            let p = c.call_position();
            let full = c3.resolve(path, p)?;
            let t = MaterialTable::load(&full).or_else(|e| fail(p, e.to_string()))?;
            Ok(set(&c3, Arc::new(t)))
        },
    );
    engine.register_fn(
        "id",
        |c: Ctx, m: &mut MaterialDefs, name: &str| -> RResult<i64> {
            m.0.id(name)
                .map(i64::from)
                .or_else(|e| fail(c.call_position(), e.to_string()))
        },
    );
    engine.register_fn(
        "name",
        |c: Ctx, m: &mut MaterialDefs, id: i64| -> RResult<String> {
            let id =
                m.0.check_id(id)
                    .or_else(|e| fail(c.call_position(), e.to_string()))?;
            Ok(m.0.name(id).to_owned())
        },
    );
    engine.register_fn("contains", |m: &mut MaterialDefs, name: &str| {
        m.0.id(name).is_ok()
    });
    engine.register_fn("num_materials", |m: &mut MaterialDefs| m.0.len() as i64 - 1);
    engine.register_fn(
        "color",
        |c: Ctx, m: &mut MaterialDefs, id: i64| -> RResult<rhai::Array> {
            let id =
                m.0.check_id(id)
                    .or_else(|e| fail(c.call_position(), e.to_string()))?;
            let rgba = m.0.get(id).map(|m| m.rgba()).unwrap_or_default();
            Ok(rgba.iter().map(|v| Dynamic::from(*v as i64)).collect())
        },
    );
}

fn register_lattice_types(engine: &mut Engine) {
    shapes_api::register_enum(
        engine,
        "LatticeType",
        [
            ("BodyCenteredCubic", LatticeType::BodyCenteredCubic),
            ("FaceCenteredCubic", LatticeType::FaceCenteredCubic),
            ("Cubic", LatticeType::Cubic),
            ("KelvinCell", LatticeType::KelvinCell),
            ("Octet", LatticeType::Octet),
        ],
    );
}

#[cfg(test)]
mod tests;
#[cfg(test)]
mod tests_forms;
#[cfg(test)]
mod tests_python;
