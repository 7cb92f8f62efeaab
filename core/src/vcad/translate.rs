//! `.vcad` calls → the design tree. Each construct becomes the pyvcad node
//! that `pv.parse_vcad_text` builds for it, with the
//! node's origin set to the construct's line and column, so errors found
//! later (at prepare) also point into the `.vcad` file.

use std::sync::Arc;

use glam::DVec3;

use super::VcadError;
use super::parser::{ArgKind, Call, Pos};
use crate::expr::{COORD_VARS, Expr};
use crate::material::{MaterialId, MaterialTable, nearest_name};
use crate::node::{Node, NodeKind, Origin};
use crate::script::RunContext;

/// Every construct the translator takes, with the form it takes.
pub const CONSTRUCTS: &[(&str, &str)] = &[
    ("union", "union(){ ... }"),
    ("intersection", "intersection(){ ... }"),
    ("difference", "difference(){ A; B; }"),
    ("sphere", "sphere(radius, \"material\");"),
    ("rectprism", "rectprism((sx, sy, sz), \"material\");"),
    ("cylinder", "cylinder(radius, height, \"material\");"),
    (
        "strut",
        "strut((ax, ay, az), (bx, by, bz), radius, \"material\");",
    ),
    (
        "function",
        "function((min x, y, z), (max x, y, z), \"expression\", \"material\");",
    ),
    ("mesh", "mesh(\"path\", \"material\");"),
    ("translate", "translate(x, y, z){ child }"),
    ("rotate", "rotate(pitch, yaw, roll){ child }"),
    ("scale", "scale(x, y, z){ child }"),
    ("tile", "tile(x, y, z){ child }"),
    ("blend", "blend(radius){ child } or blend(x, y, z){ child }"),
    (
        "fgrade",
        "fgrade([\"expression\", ...], [\"material\", ...], \"prob\" or \"thresh\"){ child }",
    ),
];

/// Constructs of other OpenVCAD versions that pyvcad 2.3.4's `.vcad` reader
/// refuses, and what to write instead.
const NOT_TAKEN: &[(&str, &str)] = &[
    (
        "root",
        "the 2023 `root((min),(max),(voxel)){...}` header is gone: write `union(){...}` at the top",
    ),
    (
        "cube",
        "the 2023 `cube` is `rectprism((sx, sy, sz), \"material\");`",
    ),
    (
        "f_grade",
        "the 2023 `f_grade` is `fgrade([...], [...], \"prob\"){...}`",
    ),
    (
        "convolve",
        "`convolve` has no .vcad form in 2.3.4: use `blend(radius){...}`",
    ),
    (
        "convolution",
        "`convolution` has no .vcad form in 2.3.4: use `blend(radius){...}`",
    ),
    (
        "sum",
        "`sum` has no .vcad form: write the design as a .rhai script with `Sum(...)`",
    ),
    (
        "shell",
        "`shell` has no .vcad form: write the design as a .rhai script with `Shell(t, child)`",
    ),
    (
        "offset",
        "`offset` has no .vcad form: write the design as a .rhai script with `Offset(d, child)`",
    ),
    (
        "voxels",
        "`voxels` (VDB grids) is not provided: convert the grid to a mesh and use `mesh(\"path\", \"material\");`",
    ),
    (
        "cad",
        "STEP/IGES import is not provided: export the part as STL and use `mesh(\"path\", \"material\");`",
    ),
];

/// State of one translation.
pub(super) struct Translator<'a> {
    pub table: &'a MaterialTable,
    pub files: Option<RunContext>,
    pub warnings: Vec<String>,
}

fn err<T>(pos: Pos, message: String) -> Result<T, VcadError> {
    Err(VcadError::at(pos.line, pos.column, message))
}

fn form(name: &str) -> &'static str {
    CONSTRUCTS
        .iter()
        .find(|(n, _)| *n == name)
        .map_or("", |(_, f)| f)
}

fn origin(pos: Pos) -> Option<Origin> {
    Some(Origin {
        line: u32::try_from(pos.line).unwrap_or(u32::MAX),
        column: u32::try_from(pos.column).unwrap_or(u32::MAX),
    })
}

impl Translator<'_> {
    /// The top level: pyvcad takes exactly one `union(){...}` there.
    pub fn root(&mut self, c: &Call) -> Result<Node, VcadError> {
        if !c.name.eq_ignore_ascii_case("union") {
            return err(
                c.pos,
                format!(
                    "the top level of a .vcad file must be `union(){{ ... }}`, found `{}`: put it inside a union",
                    c.name
                ),
            );
        }
        self.node(c)
    }

    /// Translate one call and everything inside it.
    pub fn node(&mut self, c: &Call) -> Result<Node, VcadError> {
        let name = c.name.to_ascii_lowercase();
        let kind = match name.as_str() {
            "union" | "intersection" | "difference" => self.boolean(c, &name)?,
            "translate" | "rotate" | "scale" | "tile" | "blend" | "fgrade" => {
                self.unary(c, &name)?
            }
            "sphere" | "rectprism" | "cylinder" | "strut" | "function" | "mesh" => {
                if let Some(body) = &c.body {
                    let at = body.first().map_or(c.pos, |b| b.pos);
                    return err(
                        at,
                        format!(
                            "`{name}` takes no `{{ }}` body: end it with `;` as in `{}`",
                            form(&name)
                        ),
                    );
                }
                self.leaf(c, &name)?
            }
            _ => return self.unknown(c, &name),
        };
        Ok(Node::with_origin(kind, origin(c.pos)))
    }

    fn unknown<T>(&self, c: &Call, name: &str) -> Result<T, VcadError> {
        if let Some((_, why)) = NOT_TAKEN.iter().find(|(n, _)| *n == name) {
            return err(
                c.pos,
                format!("construct `{}` is not taken in .vcad files: {why}", c.name),
            );
        }
        let near = nearest_name(name, CONSTRUCTS.iter().map(|(n, _)| *n))
            .map_or(String::new(), |n| format!("did you mean `{}`? ", form(n)));
        let all: Vec<&str> = CONSTRUCTS.iter().map(|(n, _)| *n).collect();
        err(
            c.pos,
            format!(
                "unknown construct `{}`: {near}.vcad takes {}",
                c.name,
                all.join(", ")
            ),
        )
    }

    fn children(&mut self, c: &Call, name: &str) -> Result<Vec<Node>, VcadError> {
        let Some(body) = &c.body else {
            return err(
                c.pos,
                format!("`{name}` needs a `{{ }}` body: write `{}`", form(name)),
            );
        };
        body.iter().map(|b| self.node(b)).collect()
    }

    fn boolean(&mut self, c: &Call, name: &str) -> Result<NodeKind, VcadError> {
        if let Some(a) = c.args.first() {
            return err(
                a.pos,
                format!(
                    "`{name}` takes no arguments in .vcad (pyvcad 2.3.4 refuses `{name}(true)` and smooth forms): write `{}`",
                    form(name)
                ),
            );
        }
        let mut kids = self.children(c, name)?;
        if name == "difference" {
            if kids.len() != 2 {
                return err(
                    c.pos,
                    format!(
                        "`difference` needs exactly two parts (the body, then what to cut away), found {}: write `{}`",
                        kids.len(),
                        form(name)
                    ),
                );
            }
            let right = kids.pop();
            let left = kids.pop();
            return Ok(NodeKind::Difference {
                smooth: 0.0,
                left,
                right,
            });
        }
        if kids.is_empty() {
            return err(
                c.pos,
                format!("`{name}` has nothing inside its `{{ }}`: add at least one part"),
            );
        }
        Ok(if name == "union" {
            NodeKind::Union {
                smooth: 0.0,
                blend: false,
                children: kids,
            }
        } else {
            NodeKind::Intersection {
                smooth: 0.0,
                blend: false,
                children: kids,
            }
        })
    }

    fn unary(&mut self, c: &Call, name: &str) -> Result<NodeKind, VcadError> {
        let kids = self.children(c, name)?;
        let child = match kids.len() {
            1 => kids.into_iter().next(),
            n => {
                return err(
                    c.pos,
                    format!(
                        "`{name}` takes exactly one part inside its `{{ }}`, found {n}: wrap several in `union(){{ ... }}`"
                    ),
                );
            }
        };
        let a = Args { c, name };
        Ok(match name {
            "translate" => NodeKind::Translate {
                offset: a.three(false)?,
                child,
            },
            "scale" => NodeKind::Scale {
                factors: a.three(true)?,
                child,
            },
            "tile" => NodeKind::Tile {
                cell: Some(a.three(true)?),
                child,
            },
            "rotate" => {
                let v = a.three(false)?;
                NodeKind::Rotate {
                    pitch: v.x,
                    yaw: v.y,
                    roll: v.z,
                    around: DVec3::ZERO,
                    child,
                }
            }
            "blend" => NodeKind::Blend {
                radius: self.blend_radius(&a)?,
                child,
            },
            _ => self.fgrade(&a, child)?,
        })
    }

    /// `blend(r)` is our Blend radius in mm. pyvcad's `blend(x, y, z)` is a
    /// convolution kernel of x×y×z voxels that only its voxel compilers
    /// apply; it is taken as a radius of half the kernel's largest side in
    /// mm, with a warning, since the voxel size is not known here.
    fn blend_radius(&mut self, a: &Args) -> Result<f64, VcadError> {
        match a.c.args.len() {
            1 => a.positive(0, "radius"),
            3 => {
                let v = a.three(true)?;
                let r = v.max_element() / 2.0;
                self.warnings.push(format!(
                    "{}:{}: blend({}, {}, {}) is a voxel kernel in pyvcad; volcad blends over a radius of {r} mm (write blend(radius) to choose it)",
                    a.c.pos.line, a.c.pos.column, v.x, v.y, v.z
                ));
                Ok(r)
            }
            n => a.count_error(n),
        }
    }

    fn fgrade(&self, a: &Args, child: Option<Node>) -> Result<NodeKind, VcadError> {
        a.arity(3)?;
        let srcs = a.list(0, "expressions")?;
        let names = a.list(1, "materials")?;
        if srcs.len() != names.len() || srcs.is_empty() {
            return err(
                a.c.args[1].pos,
                format!(
                    "`fgrade` needs one material per expression and at least one of each, found {} expressions and {} materials",
                    srcs.len(),
                    names.len()
                ),
            );
        }
        let mut exprs = Vec::new();
        for (src, pos) in &srcs {
            exprs.push(expression(src, *pos, &COORD_VARS, "fgrade")?);
        }
        let mut materials = Vec::new();
        for (n, pos) in &names {
            materials.push(self.material_named(n, *pos)?);
        }
        let (mode, pos) = a.string(2, "mode")?;
        let prob = match mode.to_ascii_lowercase().as_str() {
            "prob" => true,
            "thresh" => false,
            _ => {
                return err(
                    pos,
                    format!("`fgrade` mode \"{mode}\": write \"prob\" or \"thresh\""),
                );
            }
        };
        Ok(NodeKind::FGrade {
            exprs,
            materials,
            prob,
            child,
        })
    }

    fn leaf(&mut self, c: &Call, name: &str) -> Result<NodeKind, VcadError> {
        let a = Args { c, name };
        Ok(match name {
            "sphere" => {
                a.arity(2)?;
                NodeKind::Sphere {
                    center: DVec3::ZERO,
                    radius: a.positive(0, "radius")?,
                    material: self.material(&a, 1)?,
                }
            }
            "rectprism" => {
                a.arity(2)?;
                NodeKind::RectPrism {
                    center: DVec3::ZERO,
                    size: a.point(0, "size", true)?,
                    material: self.material(&a, 1)?,
                }
            }
            "cylinder" => {
                a.arity(3)?;
                NodeKind::Cylinder {
                    center: DVec3::ZERO,
                    radius: a.positive(0, "radius")?,
                    height: a.positive(1, "height")?,
                    material: self.material(&a, 2)?,
                }
            }
            "strut" => {
                a.arity(4)?;
                NodeKind::Strut {
                    a: a.point(0, "start point", false)?,
                    b: a.point(1, "end point", false)?,
                    radius: a.positive(2, "radius")?,
                    material: self.material(&a, 3)?,
                }
            }
            "function" => self.function(&a)?,
            _ => self.mesh(&a)?,
        })
    }

    fn function(&self, a: &Args) -> Result<NodeKind, VcadError> {
        a.arity(4)?;
        let min = a.point(0, "min corner", false)?;
        let max = a.point(1, "max corner", false)?;
        if min.cmpge(max).any() {
            return err(
                a.c.args[1].pos,
                "`function`: the max corner must be above the min corner on every axis".into(),
            );
        }
        let (src, pos) = a.string(2, "expression")?;
        // pyvcad's Function has no `d` (that is FGrade's child distance).
        let expr = expression(&src, pos, &COORD_VARS[..8], "function")?;
        Ok(NodeKind::Function {
            expr,
            material: self.material(a, 3)?,
            min,
            max,
        })
    }

    fn mesh(&mut self, a: &Args) -> Result<NodeKind, VcadError> {
        a.arity(2)?;
        let (path, pos) = a.string(0, "path")?;
        let material = self.material(a, 1)?;
        let here = rhai::Position::new(
            u16::try_from(pos.line).unwrap_or(u16::MAX),
            u16::try_from(pos.column).unwrap_or(u16::MAX),
        );
        let full = match &self.files {
            Some(ctx) => ctx
                .resolve(&path, here)
                .or_else(|e| err(pos, crate::script::runtime_message(&e)))?,
            None => {
                return err(
                    pos,
                    format!(
                        "cannot read \"{path}\": save the design first; files are read relative to its folder"
                    ),
                );
            }
        };
        let mesh = crate::script::load_mesh(&full).or_else(|e| err(pos, e))?;
        for w in mesh.warnings() {
            self.warnings.push(format!(
                "{}:{}: mesh(\"{path}\"): {w}",
                pos.line, pos.column
            ));
        }
        Ok(NodeKind::Mesh { mesh, material })
    }

    fn material(&self, a: &Args, i: usize) -> Result<MaterialId, VcadError> {
        let arg = &a.c.args[i];
        match &arg.kind {
            ArgKind::Str(s) => self.material_named(s, arg.pos),
            _ => err(
                arg.pos,
                format!(
                    "`{}`: materials are named in .vcad files, found {}: write a name such as \"red\" (as in `{}`)",
                    a.name,
                    describe(&arg.kind),
                    form(a.name)
                ),
            ),
        }
    }

    fn material_named(&self, name: &str, pos: Pos) -> Result<MaterialId, VcadError> {
        self.table
            .id(name)
            .or_else(|e| err(pos, format!("material \"{name}\": {e}")))
    }
}

/// Compile a math string; a problem points at its column inside the string.
fn expression(src: &str, pos: Pos, vars: &[&str], what: &str) -> Result<Arc<Expr>, VcadError> {
    Expr::compile(src, vars).map(Arc::new).or_else(|e| {
        // The string's text starts one column after its opening quote.
        let column = pos.column + e.position;
        err(
            Pos {
                line: pos.line,
                column,
            },
            format!("`{what}` expression \"{src}\": {}", e.message),
        )
    })
}

/// What an argument is, for messages.
fn describe(k: &ArgKind) -> String {
    match k {
        ArgKind::Num(v) => format!("the number {v}"),
        ArgKind::Str(s) => format!("the string \"{s}\""),
        ArgKind::Tuple(v) => format!("a point of {} numbers", v.len()),
        ArgKind::List(v) => format!("a list of {}", v.len()),
        ArgKind::Bool(b) => format!("`{b}`"),
    }
}

/// The arguments of one call, read by position.
struct Args<'a> {
    c: &'a Call,
    name: &'a str,
}

impl Args<'_> {
    fn count_error<T>(&self, n: usize) -> Result<T, VcadError> {
        let at = self.c.args.get(n.min(self.c.args.len()).saturating_sub(1));
        err(
            at.map_or(self.c.pos, |a| a.pos),
            format!(
                "`{}` got {n} argument{}: write `{}`",
                self.name,
                if n == 1 { "" } else { "s" },
                form(self.name)
            ),
        )
    }

    fn arity(&self, n: usize) -> Result<(), VcadError> {
        if self.c.args.len() == n {
            Ok(())
        } else {
            self.count_error(self.c.args.len())
        }
    }

    fn wrong<T>(&self, i: usize, what: &str, want: &str) -> Result<T, VcadError> {
        let arg = &self.c.args[i];
        err(
            arg.pos,
            format!(
                "`{}` {what}: expected {want}, found {} (write `{}`)",
                self.name,
                describe(&arg.kind),
                form(self.name)
            ),
        )
    }

    fn number(&self, i: usize, what: &str) -> Result<f64, VcadError> {
        match &self.c.args[i].kind {
            ArgKind::Num(v) => Ok(*v),
            _ => self.wrong(i, what, "a number"),
        }
    }

    fn positive(&self, i: usize, what: &str) -> Result<f64, VcadError> {
        let v = self.number(i, what)?;
        if v > 0.0 {
            Ok(v)
        } else {
            self.wrong(i, what, "a number above 0")
        }
    }

    /// `x, y, z` as three separate numbers (transforms).
    fn three(&self, positive: bool) -> Result<DVec3, VcadError> {
        self.arity(3)?;
        let get = |i, what| {
            if positive {
                self.positive(i, what)
            } else {
                self.number(i, what)
            }
        };
        Ok(DVec3::new(get(0, "x")?, get(1, "y")?, get(2, "z")?))
    }

    /// `(x, y, z)` as one argument (points and sizes).
    fn point(&self, i: usize, what: &str, positive: bool) -> Result<DVec3, VcadError> {
        let want = if positive {
            "(x, y, z) with every value above 0"
        } else {
            "a point (x, y, z)"
        };
        match &self.c.args[i].kind {
            ArgKind::Tuple(v) if v.len() == 3 && (!positive || v.iter().all(|x| *x > 0.0)) => {
                Ok(DVec3::new(v[0], v[1], v[2]))
            }
            _ => self.wrong(i, what, want),
        }
    }

    fn string(&self, i: usize, what: &str) -> Result<(String, Pos), VcadError> {
        let arg = &self.c.args[i];
        match &arg.kind {
            ArgKind::Str(s) => Ok((s.clone(), arg.pos)),
            _ => self.wrong(i, what, "a \"string\""),
        }
    }

    /// `["a", "b"]`: strings with their positions.
    fn list(&self, i: usize, what: &str) -> Result<Vec<(String, Pos)>, VcadError> {
        let ArgKind::List(items) = &self.c.args[i].kind else {
            return self.wrong(i, what, "a [\"...\", ...] list of strings");
        };
        items
            .iter()
            .map(|a| match &a.kind {
                ArgKind::Str(s) => Ok((s.clone(), a.pos)),
                k => err(
                    a.pos,
                    format!(
                        "`{}` {what}: every item must be a \"string\", found {}",
                        self.name,
                        describe(k)
                    ),
                ),
            })
            .collect()
    }
}
