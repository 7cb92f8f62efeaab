//! The reference's table of script functions, in reference order: one
//! `f!` entry a function (name, group, forms, summary, completion
//! skeleton, example).

use super::{FnDoc, Group};

macro_rules! f {
    ($name:literal, $group:ident, [$($form:literal),+], $summary:literal, $skeleton:literal, $example:literal) => {
        FnDoc {
            name: $name,
            group: Group::$group,
            forms: &[$($form),+],
            summary: $summary,
            skeleton: $skeleton,
            example: $example,
        }
    };
}

/// Every script function, in reference order.
pub static FUNCTIONS: &[FnDoc] = &[
    f!(
        "Sphere",
        Geometry,
        ["Sphere(center: Vec3, radius: float, material: int)"],
        "A ball: exact distance |p − c| − r.",
        "Sphere(Vec3(0, 0, 0), 5.0, m.id(\"red\"))",
        "let m = default_materials(); Sphere(Vec3(0, 0, 0), 5.0, m.id(\"red\"))"
    ),
    f!(
        "RectPrism",
        Geometry,
        ["RectPrism(center: Vec3, size: Vec3, material: int)"],
        "A box with full side lengths `size` (exact Euclidean distance).",
        "RectPrism(Vec3(0, 0, 0), Vec3(10, 10, 10), m.id(\"red\"))",
        "let m = default_materials(); RectPrism(Vec3(0, 0, 0), Vec3(15, 10, 5), m.id(\"gray\"))"
    ),
    f!(
        "Cylinder",
        Geometry,
        ["Cylinder(center: Vec3, radius: float, height: float, material: int)"],
        "A cylinder along z, centred on `center`.",
        "Cylinder(Vec3(0, 0, 0), 5.0, 10.0, m.id(\"red\"))",
        "let m = default_materials(); Cylinder(Vec3(0, 0, 0), 5.0, 10.0, m.id(\"blue\"))"
    ),
    f!(
        "Strut",
        Geometry,
        [
            "Strut(start: Vec3, end: Vec3, radius: float, material: int)",
            "Strut(start: Vec3, end: Vec3, start_radius: float, end_radius: float[, start_cap: CapMode[, end_cap: CapMode]][, material: int])"
        ],
        "A capsule around the segment from `start` to `end`, or tapered between two radii with CapMode::Sphere, HemiSphere or Butt ends.",
        "Strut(Vec3(0, 0, 0), Vec3(0, 0, 10), 1.0, m.id(\"red\"))",
        "let m = default_materials(); Strut(Vec3(0, 0, 0), Vec3(0, 0, 10), 1.0, m.id(\"red\"))"
    ),
    f!(
        "Cone",
        Geometry,
        [
            "Cone(angle: float, height: float)",
            "Cone(angle: float, height: float, material: int)"
        ],
        "A cone with its apex at the origin opening down to z = −height; `angle` is the half-angle in radians.",
        "Cone(0.5, 10.0, m.id(\"red\"))",
        "let m = default_materials(); Cone(0.5, 10.0, m.id(\"red\"))"
    ),
    f!(
        "Torus",
        Geometry,
        [
            "Torus()",
            "Torus(r1: float, r2: float)",
            "Torus(r1: float, r2: float, material: int)"
        ],
        "A ring about the z axis: major radius r1, tube radius r2.",
        "Torus(10.0, 2.0, m.id(\"red\"))",
        "let m = default_materials(); Torus(10.0, 2.0, m.id(\"red\"))"
    ),
    f!(
        "PolygonRevolve",
        Geometry,
        [
            "PolygonRevolve(profile: [Vec3], axis_start: Vec3, axis_end: Vec3, sweep_degrees: float)",
            "PolygonRevolve(profile: [Vec3], axis_start: Vec3, axis_end: Vec3, sweep_degrees: float, material: int)",
            "PolygonRevolve()"
        ],
        "A profile (x = radius, z = height) revolved about an axis by a sweep angle.",
        "PolygonRevolve([Vec3(2, 0, 0), Vec3(5, 0, 0), Vec3(5, 0, 4), Vec3(2, 0, 4)], Vec3(0, 0, 0), Vec3(0, 0, 1), 360.0, m.id(\"red\"))",
        "let m = default_materials(); PolygonRevolve([Vec3(2, 0, 0), Vec3(5, 0, 0), Vec3(5, 0, 4), Vec3(2, 0, 4)], Vec3(0, 0, 0), Vec3(0, 0, 1), 360.0, m.id(\"red\"))"
    ),
    f!(
        "Mirror",
        Transform,
        [
            "Mirror(axis: string, offset: float, child: Node)",
            "Mirror(point: Vec3, normal: Vec3, child: Node)",
            "Mirror(p0: Vec3, p1: Vec3, p2: Vec3, child: Node)",
            "Mirror()"
        ],
        "Its child reflected in a plane (the original is not kept).",
        "Mirror(\"x\", 0.0, child)",
        "let m = default_materials(); Mirror(\"x\", 0.0, Sphere(Vec3(5, 0, 0), 2.0, m.id(\"red\")))"
    ),
    f!(
        "Identity",
        Transform,
        ["Identity(child: Node)", "Identity()"],
        "Its child unchanged: a local frame of its own for the expressions below it.",
        "Identity(child)",
        "let m = default_materials(); Identity(Sphere(Vec3(0, 0, 0), 2.0, m.id(\"red\")))"
    ),
    f!(
        "Sum",
        Boolean,
        [
            "Sum(iso: float, children: [Node])",
            "Sum(iso: float)",
            "Sum()"
        ],
        "pyvcad's Sum: the children's distances added plus `iso` (a blobby merge, not a distance).",
        "Sum(0.0, [a, b])",
        "let m = default_materials(); Sum(2.0, [Sphere(Vec3(0, 0, 0), 3.0, m.id(\"red\")), Sphere(Vec3(4, 0, 0), 3.0, m.id(\"red\"))])"
    ),
    f!(
        "Text",
        Geometry,
        [
            "Text(text: string, height: float, depth: float)",
            "Text(text: string, height: float, depth: float, material: int, aspect: FontAspect, font: string, h_align: HorizontalAlignment, v_align: VerticalAlignment)"
        ],
        "Text in a real font (family name; DejaVu Sans built in), extruded by `depth` centred on z = 0; `height` is the font size, `\\n` starts a line. FontAspect::Regular/Bold/Italic/BoldItalic, HorizontalAlignment::Left/Center/Right, VerticalAlignment::Bottom/Center/Top/Top_First_Line.",
        "Text(\"Label\", 10.0, 2.0, m.id(\"red\"))",
        "let m = default_materials(); Text(\"Volcad\", 10.0, 2.0, m.id(\"red\"))"
    ),
    f!(
        "PolygonExtrude",
        Geometry,
        ["PolygonExtrude(points: [Vec3], height: float, symmetric: bool, material: int)"],
        "A polygon in the xy plane extruded along z (from 0, or centred when symmetric).",
        "PolygonExtrude([Vec3(0, 0, 0), Vec3(10, 0, 0), Vec3(0, 10, 0)], 5.0, false, m.id(\"red\"))",
        "let m = default_materials(); PolygonExtrude([Vec3(0, 0, 0), Vec3(10, 0, 0), Vec3(0, 10, 0)], 5.0, false, m.id(\"red\"))"
    ),
    f!(
        "Function",
        Geometry,
        [
            "Function(expr: string)",
            "Function(expr: string, material: int)",
            "Function(expr: string, material: int, min: Vec3, max: Vec3)"
        ],
        "The solid where a math string of x, y, z is ≤ 0, clipped to its box.",
        "Function(\"x^2 + y^2 + z^2 - 25\", m.id(\"red\"), Vec3(-6, -6, -6), Vec3(6, 6, 6))",
        "let m = default_materials(); Function(\"x^2 + y^2 + z^2 - 25\", m.id(\"red\"), Vec3(-6, -6, -6), Vec3(6, 6, 6))"
    ),
    f!(
        "Mesh",
        Data,
        [
            "Mesh(path: string)",
            "Mesh(path: string, material: int)",
            "Mesh(path: string, material: int, disable_validation: bool)",
            "Mesh(path: string, sample_size: Vec3, material: int, disable_validation: bool)"
        ],
        "A triangle mesh (STL, OBJ, PLY, OFF, 3MF, told by content) as exact signed distance; an open one is refused unless validation is disabled (then the winding number decides inside).",
        "Mesh(\"part.obj\", m.id(\"red\"))",
        ""
    ),
    f!(
        "SimulationField",
        Data,
        ["SimulationField(inp: string, csv: string, exprs: [string], materials: [int])"],
        "FEA results on a tetrahedral mesh (.inp + nodal CSV) graded into fractions by math strings.",
        "SimulationField(\"mesh.inp\", \"result.csv\", [\"len\", \"1 - len\"], [m.id(\"red\"), m.id(\"blue\")])",
        ""
    ),
    f!(
        "read_csv",
        Data,
        ["read_csv(path: string) -> [map]"],
        "Rows of a CSV file beside the design, each a map by column name.",
        "read_csv(\"data.csv\")",
        ""
    ),
    f!(
        "Gyroid",
        Lattice,
        ["Gyroid(cell: float or Vec3, wall: float, material: int)"],
        "Schoen's gyroid sheet of wall thickness `wall` (infinite: clip it).",
        "Gyroid(10.0, 1.0, m.id(\"red\"))",
        "let m = default_materials(); Intersection(false, [Gyroid(10.0, 1.0, m.id(\"red\")), Sphere(Vec3(0, 0, 0), 10.0, m.id(\"red\"))])"
    ),
    f!(
        "SchwarzP",
        Lattice,
        ["SchwarzP(cell: float or Vec3, wall: float, material: int)"],
        "Schwarz P sheet (infinite: clip it).",
        "SchwarzP(10.0, 1.0, m.id(\"red\"))",
        "let m = default_materials(); Intersection(false, [SchwarzP(10.0, 1.0, m.id(\"red\")), Sphere(Vec3(0, 0, 0), 10.0, m.id(\"red\"))])"
    ),
    f!(
        "Diamond",
        Lattice,
        ["Diamond(cell: float or Vec3, wall: float, material: int)"],
        "Schwarz D (diamond) sheet (infinite: clip it).",
        "Diamond(10.0, 1.0, m.id(\"red\"))",
        "let m = default_materials(); Intersection(false, [Diamond(10.0, 1.0, m.id(\"red\")), Sphere(Vec3(0, 0, 0), 10.0, m.id(\"red\"))])"
    ),
    f!(
        "GraphLattice",
        Lattice,
        [
            "GraphLattice(type: LatticeType, cell: Vec3, radius: float, material: int)",
            "GraphLattice(edges: [[Vec3, Vec3]], radius: float, material: int)"
        ],
        "One unit cell of struts (LatticeType::BodyCenteredCubic, FaceCenteredCubic, Cubic, KelvinCell, Octet) or of your own edges; Tile repeats it.",
        "GraphLattice(LatticeType::BodyCenteredCubic, Vec3(5, 5, 5), 0.5, m.id(\"red\"))",
        "let m = default_materials(); GraphLattice(LatticeType::BodyCenteredCubic, Vec3(5, 5, 5), 0.5, m.id(\"red\"))"
    ),
    f!(
        "Tile",
        Lattice,
        [
            "Tile(child: Node)",
            "Tile(cx: float, cy: float, cz: float, child: Node)",
            "Tile()"
        ],
        "Repeats its child periodically (cell = the child's box, or cx, cy, cz); clip it with Intersection.",
        "Tile(5.0, 5.0, 5.0, cell)",
        "let m = default_materials(); let cell = GraphLattice(LatticeType::Cubic, Vec3(5, 5, 5), 0.5, m.id(\"red\")); Intersection(false, [Tile(cell), Sphere(Vec3(0, 0, 0), 10.0, m.id(\"red\"))])"
    ),
    f!(
        "Union",
        Boolean,
        [
            "Union(blend: bool, children: [Node])",
            "Union(k: float, blend: bool, children: [Node])",
            "Union()"
        ],
        "The children together; `blend` averages fractions where they overlap (else the first child's); `k` rounds the joins.",
        "Union(false, [a, b])",
        "let m = default_materials(); Union(false, [Sphere(Vec3(0, 0, 0), 5.0, m.id(\"red\")), Sphere(Vec3(6, 0, 0), 5.0, m.id(\"blue\"))])"
    ),
    f!(
        "BBoxUnion",
        Boolean,
        ["BBoxUnion(children: [Node])", "BBoxUnion()"],
        "pyvcad's name for `Union(false, children)` (an exact distance everywhere).",
        "BBoxUnion([a, b])",
        "let m = default_materials(); BBoxUnion([Sphere(Vec3(0, 0, 0), 2.0, m.id(\"red\")), Sphere(Vec3(5, 0, 0), 2.0, m.id(\"blue\"))])"
    ),
    f!(
        "BBoxIntersection",
        Boolean,
        ["BBoxIntersection(children: [Node])", "BBoxIntersection()"],
        "`Intersection(false, children)` under pyvcad's bounding-box name.",
        "BBoxIntersection([a, b])",
        "let m = default_materials(); BBoxIntersection([Sphere(Vec3(0, 0, 0), 3.0, m.id(\"red\")), RectPrism(Vec3(0, 0, 0), Vec3(4, 4, 4), m.id(\"red\"))])"
    ),
    f!(
        "Intersection",
        Boolean,
        [
            "Intersection(blend: bool, children: [Node])",
            "Intersection(k: float, blend: bool, children: [Node])",
            "Intersection()"
        ],
        "Where every child is; fractions of the first child (or averaged with `blend`).",
        "Intersection(false, [a, b])",
        "let m = default_materials(); Intersection(false, [Sphere(Vec3(0, 0, 0), 5.0, m.id(\"red\")), RectPrism(Vec3(0, 0, 0), Vec3(8, 8, 8), m.id(\"red\"))])"
    ),
    f!(
        "Difference",
        Boolean,
        [
            "Difference(left: Node, right: Node)",
            "Difference(k: float, left: Node, right: Node)",
            "Difference()"
        ],
        "`left` with `right` removed (`k` rounds the edge).",
        "Difference(a, b)",
        "let m = default_materials(); Difference(RectPrism(Vec3(0, 0, 0), Vec3(10, 10, 10), m.id(\"red\")), Sphere(Vec3(0, 0, 0), 6.0, m.id(\"red\")))"
    ),
    f!(
        "Translate",
        Transform,
        [
            "Translate(x: float, y: float, z: float, child: Node)",
            "Translate(offset: Vec3, child: Node)",
            "Translate()"
        ],
        "Moves its child.",
        "Translate(0.0, 0.0, 10.0, child)",
        "let m = default_materials(); Translate(0.0, 0.0, 10.0, Sphere(Vec3(0, 0, 0), 5.0, m.id(\"red\")))"
    ),
    f!(
        "Scale",
        Transform,
        [
            "Scale(sx: float, sy: float, sz: float, child: Node)",
            "Scale(s: Vec3, child: Node)",
            "Scale()"
        ],
        "Scales its child about the origin (distances stay a valid bound).",
        "Scale(2.0, 1.0, 1.0, child)",
        "let m = default_materials(); Scale(2.0, 1.0, 1.0, Sphere(Vec3(0, 0, 0), 5.0, m.id(\"red\")))"
    ),
    f!(
        "Rotate",
        Transform,
        [
            "Rotate(pitch: float, yaw: float, roll: float, around: Vec3, child: Node)",
            "Rotate(pitch: float, yaw: float, roll: float, child: Node)",
            "Rotate()"
        ],
        "Rotates its child (degrees about x, y, z) around a point.",
        "Rotate(0.0, 0.0, 45.0, Vec3(0, 0, 0), child)",
        "let m = default_materials(); Rotate(0.0, 0.0, 45.0, Vec3(0, 0, 0), RectPrism(Vec3(0, 0, 0), Vec3(10, 4, 2), m.id(\"red\")))"
    ),
    f!(
        "Offset",
        Transform,
        [
            "Offset(distance: float, child: Node)",
            "Offset(distance: float)",
            "Offset()"
        ],
        "Grows (> 0) or shrinks (< 0) its child by a distance.",
        "Offset(1.0, child)",
        "let m = default_materials(); Offset(1.0, RectPrism(Vec3(0, 0, 0), Vec3(10, 10, 10), m.id(\"red\")))"
    ),
    f!(
        "Shell",
        Transform,
        [
            "Shell(thickness: float, child: Node)",
            "Shell(thickness: float)",
            "Shell()"
        ],
        "A wall of `thickness` inside its child's surface.",
        "Shell(1.0, child)",
        "let m = default_materials(); Shell(1.0, Sphere(Vec3(0, 0, 0), 5.0, m.id(\"red\")))"
    ),
    f!(
        "FGrade",
        Material,
        [
            "FGrade(exprs: [string], materials: [int], prob: bool, child: Node)",
            "FGrade(exprs: [string], materials: [int], prob: bool)"
        ],
        "Grades its child: one math string per material gives its fraction (normalised); `prob` keeps mixes, else the largest wins.",
        "FGrade([\"x/15+0.5\", \"-x/15+0.5\"], [m.id(\"red\"), m.id(\"blue\")], true, child)",
        "let m = default_materials(); FGrade([\"x/15+0.5\", \"-x/15+0.5\"], [m.id(\"red\"), m.id(\"blue\")], true, RectPrism(Vec3(0, 0, 0), Vec3(15, 10, 5), m.id(\"gray\")))"
    ),
    f!(
        "Blend",
        Material,
        ["Blend(radius: float, child: Node)", "Blend(radius: float)"],
        "Smooths its child's fractions over a neighbourhood of `radius`.",
        "Blend(1.0, child)",
        "let m = default_materials(); Blend(1.0, Union(false, [RectPrism(Vec3(-2.5, 0, 0), Vec3(5, 5, 5), m.id(\"red\")), RectPrism(Vec3(2.5, 0, 0), Vec3(5, 5, 5), m.id(\"blue\"))]))"
    ),
    f!(
        "default_materials",
        Material,
        ["default_materials() -> Materials"],
        "pyvcad's default table of named colours.",
        "default_materials()",
        "let m = default_materials(); Sphere(Vec3(0, 0, 0), 1.0, m.id(\"red\"))"
    ),
    f!(
        "j750_materials",
        Material,
        ["j750_materials() -> Materials"],
        "The Stratasys J750 resin table.",
        "j750_materials()",
        "let m = j750_materials(); Sphere(Vec3(0, 0, 0), 1.0, m.id(\"VeroCyan\"))"
    ),
    f!(
        "load_materials",
        Material,
        ["load_materials(path: string) -> Materials"],
        "A material table from a pyvcad JSON file beside the design.",
        "load_materials(\"materials.json\")",
        ""
    ),
    f!(
        "id",
        Method,
        ["materials.id(name: string) -> int"],
        "A material's id by name (an unknown name lists the nearest).",
        "m.id(\"red\")",
        "let m = default_materials(); Sphere(Vec3(0, 0, 0), 1.0, m.id(\"red\"))"
    ),
    f!(
        "name",
        Method,
        ["materials.name(id: int) -> string"],
        "A material's name by id.",
        "m.name(1)",
        "let m = default_materials(); let n = m.name(m.id(\"red\")); Sphere(Vec3(0, 0, 0), 1.0, m.id(n))"
    ),
    f!(
        "color",
        Method,
        ["materials.color(id: int) -> [int]"],
        "A material's RGBA colour.",
        "m.color(m.id(\"red\"))",
        "let m = default_materials(); let c = m.color(m.id(\"red\")); Sphere(Vec3(0, 0, 0), 1.0, m.id(\"red\"))"
    ),
    f!(
        "contains",
        Method,
        ["materials.contains(name: string) -> bool"],
        "Whether the table has a material of that name.",
        "m.contains(\"red\")",
        "let m = default_materials(); let k = if m.contains(\"red\") { \"red\" } else { \"blue\" }; Sphere(Vec3(0, 0, 0), 1.0, m.id(k))"
    ),
    f!(
        "num_materials",
        Method,
        ["materials.num_materials() -> int"],
        "How many materials the table holds (void not counted).",
        "m.num_materials()",
        "let m = default_materials(); let n = m.num_materials(); Sphere(Vec3(0, 0, 0), 1.0, m.id(\"red\"))"
    ),
    f!(
        "add_child",
        Method,
        ["node.add_child(child: Node) -> bool"],
        "Appends a child to a Union, Intersection or Tile.",
        "u.add_child(child)",
        "let m = default_materials(); let u = Union(false, []); u.add_child(Sphere(Vec3(0, 0, 0), 1.0, m.id(\"red\"))); u"
    ),
    f!(
        "set_child",
        Method,
        ["node.set_child(child: Node)"],
        "Sets the child of a one-child node (transforms, FGrade, Blend, ...).",
        "n.set_child(child)",
        "let m = default_materials(); let t = Translate(); t.set_child(Sphere(Vec3(0, 0, 0), 1.0, m.id(\"red\"))); t"
    ),
    f!(
        "set_left",
        Method,
        ["node.set_left(child: Node)"],
        "Sets the left operand of a Difference.",
        "d.set_left(child)",
        "let m = default_materials(); let d = Difference(); d.set_left(Sphere(Vec3(0, 0, 0), 5.0, m.id(\"red\"))); d.set_right(Sphere(Vec3(3, 0, 0), 3.0, m.id(\"red\"))); d"
    ),
    f!(
        "set_attribute",
        Method,
        [
            "node.set_attribute(name: string, value: float | string | Vec3 | Vec4 | array)",
            "node.set_attribute(name: string, field: SimulationField, column: string)",
            "node.set_attribute(name: string, points: PointsField)",
            "node.set_attribute(name: string, image: ImageField)"
        ],
        "Sets a property field (modulus MPa, poissons_ratio, density g/cm^3, shore_hardness, infill_density %, temperature, color Vec4, or any name): a number, a math string of x y z rho phic r theta phis d and the node's other attributes, a vector, or an FEA column; a parent's overrides its children's.",
        "n.set_attribute(\"modulus\", 2850.0)",
        "let m = default_materials(); let s = Sphere(Vec3(0, 0, 0), 5.0, m.id(\"red\")); s.set_attribute(\"modulus\", \"1000 + 100*z\"); s.set_attribute(\"color\", Vec4(1, 0, 0, 1)); s"
    ),
    f!(
        "Convert",
        Material,
        [
            "Convert(child: Node, from: string, to: string, table: [[float, float]] | string)",
            "Convert(child: Node, \"fractions\", to: string, rule: \"voigt\" | \"reuss\", values: [[int, float]])",
            "Convert(child: Node, from: string, to: Fractions, table: [[float, float]] | string)"
        ],
        "Sets attribute `to` from `from` below it (pyvcad 3's AttributeModifier): a piecewise-linear table of [input, output] rows (inline or a two-column .csv; inputs rising; clamped at the ends, counted in a warning) or a math string of x y z ... d and `from`; from \"fractions\", a Voigt or Reuss mix of one value per material.",
        "Convert(part, \"shore_hardness\", \"modulus\", [[30, 1.0], [85, 20.0]])",
        "let m = default_materials(); let s = Sphere(Vec3(0, 0, 0), 5.0, m.id(\"red\")); s.set_attribute(\"shore_hardness\", \"60 + 4*x\"); Convert(s, \"shore_hardness\", \"modulus\", [[30, 1.0], [85, 20.0]])"
    ),
    f!(
        "fractions",
        Material,
        ["fractions(materials: [int, int]) -> Fractions"],
        "The two materials a Convert to fractions mixes: its table's rows are [share of the second material 0..1, value], inverted for the child's value of `from`; these fractions replace the child's.",
        "fractions([m.id(\"a\"), m.id(\"b\")])",
        "let m = default_materials(); let s = Sphere(Vec3(0, 0, 0), 5.0, m.id(\"red\")); s.set_attribute(\"shore_hardness\", \"60 + 4*x\"); Convert(s, \"shore_hardness\", fractions([m.id(\"red\"), m.id(\"blue\")]), [[0, 30], [1, 95]])"
    ),
    f!(
        "PointsField",
        Data,
        ["PointsField(csv: string, column: string) -> PointsField"],
        "A value column of scattered points (CSV columns x, y, z and named values) for set_attribute: inverse-distance weighting of the 8 nearest points.",
        "PointsField(\"points.csv\", \"temperature\")",
        ""
    ),
    f!(
        "ImageField",
        Data,
        [
            "ImageField(file: string, axis: \"x\" | \"y\" | \"z\", rect: [float; 4]) -> ImageField",
            "ImageField(file: string, axis: string, rect: [float; 4], channel: \"r\" | \"g\" | \"b\" | \"a\" | \"luminance\") -> ImageField"
        ],
        "A PNG or JPEG picture (at most 4096 x 4096 px) projected along an axis onto the rectangle [u0, v0, u1, v1] of the plane across it in the node's frame (z: x across, y up; x: y, z; y: x, z), for set_attribute: its sRGB colour 0-1 as a Vec4 (\"color\"), or one channel as a number; bilinear between pixel centres, the edge pixels beyond.",
        "ImageField(\"photo.png\", \"z\", [-20, -20, 20, 20])",
        ""
    ),
    f!(
        "set_attribute_conflict_resolver",
        Method,
        ["node.set_attribute_conflict_resolver(name: string, resolver: string)"],
        "How a Union, Intersection or Sum combines an attribute where children overlap: \"first\" (default), \"average\", \"min\", \"max\", \"sum\", or a math string of a and b.",
        "u.set_attribute_conflict_resolver(\"modulus\", \"average\")",
        "let m = default_materials(); let a = Sphere(Vec3(0, 0, 0), 5.0, m.id(\"red\")); a.set_attribute(\"modulus\", 10.0); let b = Sphere(Vec3(3, 0, 0), 5.0, m.id(\"red\")); b.set_attribute(\"modulus\", 20.0); let u = Union(false, [a, b]); u.set_attribute_conflict_resolver(\"modulus\", \"max\"); u"
    ),
    f!(
        "set_right",
        Method,
        ["node.set_right(child: Node)"],
        "Sets the right operand of a Difference (what is removed).",
        "d.set_right(child)",
        "let m = default_materials(); let d = Difference(); d.set_left(Sphere(Vec3(0, 0, 0), 5.0, m.id(\"red\"))); d.set_right(Sphere(Vec3(3, 0, 0), 3.0, m.id(\"red\"))); d"
    ),
    f!(
        "evaluate",
        Method,
        ["node.evaluate(x: float, y: float, z: float) -> float"],
        "The signed distance at a point (negative inside), of the tree as it is at that line.",
        "n.evaluate(0.0, 0.0, 0.0)",
        "let m = default_materials(); let s = Sphere(Vec3(0, 0, 0), 2.0, m.id(\"red\")); let d = s.evaluate(0.0, 0.0, 0.0); s"
    ),
    f!(
        "distribution",
        Method,
        ["node.distribution(x: float, y: float, z: float) -> [float]"],
        "The fractions at a point, indexed by material id (`f[m.id(\"red\")]`); all 0 outside.",
        "n.distribution(0.0, 0.0, 0.0)",
        "let m = default_materials(); let s = Sphere(Vec3(0, 0, 0), 2.0, m.id(\"red\")); let f = s.distribution(0.0, 0.0, 0.0); s"
    ),
    f!(
        "bounding_box",
        Method,
        ["node.bounding_box() -> [Vec3, Vec3]"],
        "The node's box as [min, max].",
        "n.bounding_box()",
        "let m = default_materials(); let s = Sphere(Vec3(0, 0, 0), 2.0, m.id(\"red\")); let b = s.bounding_box(); s"
    ),
    f!(
        "prepare",
        Method,
        ["node.prepare(voxel: Vec3, interior: float, exterior: float)"],
        "Accepted for pyvcad scripts; does nothing (designs are prepared when used).",
        "n.prepare(Vec3(0.1, 0.1, 0.1), 1.0, 1.0)",
        "let m = default_materials(); let s = Sphere(Vec3(0, 0, 0), 2.0, m.id(\"red\")); s.prepare(Vec3(0.1, 0.1, 0.1), 1.0, 1.0); s"
    ),
    f!(
        "num_children",
        Method,
        ["node.num_children() -> int"],
        "How many children a node has.",
        "u.num_children()",
        "let m = default_materials(); let u = Union(false, [Sphere(Vec3(0, 0, 0), 1.0, m.id(\"red\"))]); let n = u.num_children(); u"
    ),
    f!(
        "type",
        Method,
        ["node.type() -> string"],
        "The node's type name (\"Sphere\", \"Union\", ...).",
        "n.type()",
        "let m = default_materials(); let s = Sphere(Vec3(0, 0, 0), 1.0, m.id(\"red\")); let t = s.type(); s"
    ),
    f!(
        "Vec4",
        Value,
        ["Vec4(r: float, g: float, b: float, a: float)"],
        "Four numbers, such as an RGBA colour in 0-1 for the color attribute; `.r .g .b .a`.",
        "Vec4(1, 0, 0, 1)",
        "let m = default_materials(); let s = Sphere(Vec3(0, 0, 0), 1.0, m.id(\"red\")); s.set_attribute(\"color\", Vec4(1, 0.5, 0, 1)); s"
    ),
    f!(
        "Vec3",
        Value,
        ["Vec3(x: float, y: float, z: float)", "Vec3()"],
        "A point or vector in millimetres; `+ - *` and `.x .y .z`.",
        "Vec3(0, 0, 0)",
        "let m = default_materials(); let c = Vec3(1, 2, 3) + Vec3(1, 0, 0) * 2.0; Sphere(c, 1.0, m.id(\"red\"))"
    ),
    f!(
        "length",
        Value,
        ["v.length() -> float"],
        "A vector's length.",
        "v.length()",
        "let m = default_materials(); let r = Vec3(3, 4, 0).length(); Sphere(Vec3(0, 0, 0), r, m.id(\"red\"))"
    ),
    f!(
        "distance",
        Value,
        ["distance(a: Vec3, b: Vec3) -> float"],
        "The distance between two points.",
        "distance(a, b)",
        "let m = default_materials(); let r = distance(Vec3(0, 0, 0), Vec3(3, 4, 0)); Sphere(Vec3(0, 0, 0), r, m.id(\"red\"))"
    ),
    f!(
        "floor_div",
        Value,
        [
            "floor_div(a: int, b: int) -> int",
            "floor_div(a: float, b: float) -> float"
        ],
        "Python's `a // b` (`//` starts a comment in scripts); `/` is true division as in Python.",
        "floor_div(a, b)",
        "let m = default_materials(); let n = floor_div(7, 2); Sphere(Vec3(0, 0, 0), n * 1.0, m.id(\"red\"))"
    ),
    f!(
        "param",
        Value,
        ["param(name: string, default: float, min: float, max: float) -> float"],
        "A slider in the studio (and `--param name=value` on the command line).",
        "param(\"radius\", 5.0, 1.0, 10.0)",
        "let m = default_materials(); let r = param(\"radius\", 5.0, 1.0, 10.0); Sphere(Vec3(0, 0, 0), r, m.id(\"red\"))"
    ),
    f!(
        "pad",
        Value,
        ["pad(array, length: int, value)"],
        "Rhai's array padding, checked against the script's memory budget first.",
        "a.pad(10, 0)",
        "let m = default_materials(); let a = []; a.pad(3, 1.0); Sphere(Vec3(0, 0, 0), a[0], m.id(\"red\"))"
    ),
    f!(
        "blob",
        Value,
        ["blob(length: int) -> Blob"],
        "Rhai's byte buffer, checked against the script's memory budget first.",
        "blob(16)",
        "let m = default_materials(); let b = blob(4); Sphere(Vec3(0, 0, 0), 1.0, m.id(\"red\"))"
    ),
];
