//! Property fields ("attributes", pyvcad 3's model): named scalar, vec3 and
//! vec4 values that any node of a design may carry beside its material
//! fractions (stiffness, hardness, infill, colour).
//!
//! `node.set_attribute(name, value)` stores a [`AttrDef`] on the script's
//! node ([`NodeAttributes`]); [`crate::Model::prepare`] builds a separate
//! evaluator (`prepared`) only when some node carries one, so the
//! distance and fraction paths of a design without attributes do not change.
//! The rules (pyvcad 3's getting-started, lesson 7): the topmost node on a
//! point's path that sets an attribute decides it (a parent overrides its
//! children, a child without one inherits its parent's); in a Union or
//! Intersection the first child containing the point that defines it wins,
//! unless the node names a resolver ([`Resolver`]); a smooth union blends by
//! its distance blend weight.

mod batch;
mod convert;
mod describe;
mod eval;
mod hint;
mod image_field;
mod mix;
mod moves;
mod names;
mod order;
mod pick_grid;
mod points;
mod prepared;
mod resolve;
mod to_fractions;

use std::sync::Arc;

pub use convert::{ConvMap, FRACTIONS, Table};
pub use describe::{column_names, describe_tree, value_text};
pub use image_field::{CHANNELS, ImageAxis, ImageChannel, ImageMap, MAX_PIXELS, Picture};
pub use mix::MixTable;
pub use names::{COMMON, Common, check_kind, range, range_text};
pub use points::{NEIGHBOURS, PointCloud};
pub use prepared::Evaluator;
pub use resolve::Resolver;
pub(crate) use to_fractions::{FractionSource, fraction_materials};

use crate::material::MaterialId;
use crate::node::Origin;
use crate::simfield::SimField;

/// What one value of an attribute is.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum AttributeKind {
    /// One number.
    Scalar,
    /// Three numbers (`Vec3`).
    Vec3,
    /// Four numbers (`Vec4`, an RGBA colour in 0-1).
    Vec4,
}

impl AttributeKind {
    /// Numbers per point: 1, 3 or 4.
    pub fn width(self) -> usize {
        match self {
            AttributeKind::Scalar => 1,
            AttributeKind::Vec3 => 3,
            AttributeKind::Vec4 => 4,
        }
    }

    /// The name a script writes for it.
    pub fn name(self) -> &'static str {
        match self {
            AttributeKind::Scalar => "number",
            AttributeKind::Vec3 => "Vec3",
            AttributeKind::Vec4 => "Vec4",
        }
    }
}

/// An attribute a prepared design carries.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct AttributeInfo {
    /// Its name, as the script gave it.
    pub name: String,
    /// Its type.
    pub kind: AttributeKind,
}

/// Why an attribute could not be prepared or evaluated.
#[derive(Debug, Clone, thiserror::Error, PartialEq)]
#[error("{node}: {message}")]
pub struct AttributeError {
    /// The node (with the script line that made it), or the call.
    pub node: String,
    /// What is wrong and what would fix it.
    pub message: String,
}

/// One component of a value: a number or a math string of the coordinate
/// variables and the node's other scalar attributes.
#[derive(Clone, Debug, PartialEq)]
pub enum Component {
    /// A constant.
    Const(f64),
    /// A math string, compiled at prepare (it may name attributes set later).
    Text(String),
}

/// Where an attribute's values come from.
#[derive(Clone, Debug)]
pub enum AttrSource {
    /// One component per number of the kind's width.
    Components(Vec<Component>),
    /// A column of an FEA result (SimulationField), interpolated in its
    /// tetrahedra; NaN outside its mesh.
    Data {
        /// The field.
        field: Arc<SimField>,
        /// The column's index in [`SimField::variable_names`].
        column: usize,
        /// The column's name, for messages.
        column_name: String,
    },
    /// A value column of scattered points (`PointsField`), interpolated by
    /// inverse-distance weighting of the nearest points.
    Points {
        /// The points.
        cloud: Arc<PointCloud>,
        /// The column's index in [`PointCloud::names`].
        column: usize,
    },
    /// A picture projected onto a rectangle (`ImageField`): its RGBA, or
    /// one channel as a scalar.
    Image {
        /// The placed picture.
        map: Arc<ImageMap>,
        /// The channel of a scalar attribute; `None`: RGBA (a Vec4).
        channel: Option<ImageChannel>,
    },
    /// Another scalar attribute mapped by a table or a math string
    /// (`Convert`): the node's own value of `from`, else the one below it.
    Convert {
        /// The input attribute.
        from: String,
        /// The mapping.
        map: ConvMap,
    },
}

/// One `set_attribute` call.
#[derive(Clone, Debug)]
pub struct AttrDef {
    /// The attribute's name.
    pub name: String,
    /// Its type.
    pub kind: AttributeKind,
    /// Its values.
    pub source: AttrSource,
    /// The script position of the call.
    pub origin: Option<Origin>,
}

/// The attributes and resolvers one script node carries.
#[derive(Clone, Debug, Default)]
pub struct NodeAttributes {
    /// Definitions, in the order first set (setting a name again replaces it).
    pub defs: Vec<AttrDef>,
    /// Overlap resolvers by attribute name.
    pub resolvers: Vec<(String, Resolver, Option<Origin>)>,
    /// Fractions from a scalar by a mix table (`Convert(child, from,
    /// fractions([a, b, ...]), table)`): they replace the child's fractions.
    pub to_fractions: Option<FracConv>,
}

/// A scalar -> fractions conversion a node carries.
#[derive(Clone, Debug)]
pub struct FracConv {
    /// The scalar attribute read from the child.
    pub from: String,
    /// The materials mixed (two: the table's share is the second's; more:
    /// the table's rows name each one's fraction).
    pub materials: Vec<MaterialId>,
    /// The mix table.
    pub table: Arc<MixTable>,
    /// The script position of the `Convert` call.
    pub origin: Option<Origin>,
}

impl NodeAttributes {
    /// Set (or replace) a definition.
    pub fn set(&mut self, def: AttrDef) {
        match self.defs.iter_mut().find(|d| d.name == def.name) {
            Some(d) => *d = def,
            None => self.defs.push(def),
        }
    }

    /// Set (or replace) the resolver of `name`.
    pub fn set_resolver(&mut self, name: &str, r: Resolver, origin: Option<Origin>) {
        match self.resolvers.iter_mut().find(|(n, ..)| n == name) {
            Some(e) => *e = (name.to_owned(), r, origin),
            None => self.resolvers.push((name.to_owned(), r, origin)),
        }
    }

    /// The definition of `name`, if this node sets it.
    pub fn get(&self, name: &str) -> Option<&AttrDef> {
        self.defs.iter().find(|d| d.name == name)
    }
}

#[cfg(test)]
mod tests;
/// Checks a table's map `f` at inputs: `(x, value, clamped)` rows.
#[cfg(test)]
fn assert_maps(f: impl Fn(f64) -> (f64, bool), rows: &[(f64, f64, bool)]) {
    for &(x, y, clamped) in rows {
        assert_eq!(f(x), (y, clamped), "at {x}");
    }
}
#[cfg(test)]
mod tests_fractions;
#[cfg(test)]
mod tests_hint;
#[cfg(test)]
mod tests_image;
#[cfg(test)]
mod tests_points;
