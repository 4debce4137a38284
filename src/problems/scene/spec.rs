//! A scene as data: the grid, the bodies and their materials, the supports, the loads and the
//! measures, in any dimension (2 or 3), with the checks that name the key of every bad value
//! (`bodies[1].box.max[0]`). The study file's `problem = "scene"` sections deserialise into
//! these types (`studies/README.md`, "Scenes").

use crate::basis::DomainUpdate;
use crate::discretise::ghost::GhostSettings;
use crate::material::constitutive::Material;
use crate::solver::error::{shortest, InputError};
use crate::solver::linear::LinearSolver;
use crate::solver::newton::NewtonSettings;
use crate::solver::ramp::Ramp;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

pub use super::geometry::AXES;
pub use super::measures::{ClosedForm, Measure, MeasureKind, Reference};

/// The background grid: its lower corner and its extent along each axis. The element size h
/// of a case divides every extent.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GridSection {
    pub origin: Vec<f64>,
    pub extent: Vec<f64>,
}

/// An axis-aligned box `[min, max]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Bounds {
    pub min: Vec<f64>,
    pub max: Vec<f64>,
}

/// The plane `axis = at`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Plane {
    /// `x`, `y` or `z`.
    pub axis: String,
    pub at: f64,
}

/// A body: a box, or in 2D a convex polygon of 3 or 4 vertices, of material filled with
/// points (or meshed, for FEM).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Body {
    pub name: String,
    /// The body's box; its sides are whole multiples of h / points per cell.
    #[serde(default, rename = "box", skip_serializing_if = "Option::is_none")]
    pub bounds: Option<Bounds>,
    /// Or a convex polygon (2D): the points fill the lattice cells of h / points per cell
    /// that it cuts, each with the volume and centroid of its part inside
    /// ([`super::geometry::clip_square`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub polygon: Option<Vec<[f64; 2]>>,
    /// The name of a `[materials.<name>]` table.
    pub material: String,
    /// Mass per unit initial volume (default 1).
    #[serde(default = "one")]
    pub density: f64,
    /// The Cauchy stress the body starts in (absent: unstressed), held elastically; the
    /// loads must balance it from the first step ([`super::initial_stress`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub initial_stress: Option<super::initial_stress::StressComponents>,
}

fn one() -> f64 {
    1.0
}

/// A body's shape.
#[derive(Debug, Clone, Copy)]
pub enum Shape<'a> {
    Box(&'a Bounds),
    /// Counter-clockwise or clockwise vertices, convex (checked).
    Polygon(&'a [[f64; 2]]),
}

impl Body {
    /// The body's shape (validation makes exactly one of `box` and `polygon` present).
    pub fn shape(&self) -> Shape<'_> {
        match (&self.bounds, &self.polygon) {
            (Some(b), _) => Shape::Box(b),
            (None, Some(p)) => Shape::Polygon(p),
            (None, None) => unreachable!("a validated body has a box or a polygon"),
        }
    }

    /// The smallest box holding the body.
    pub fn bounding_box(&self) -> Bounds {
        match self.shape() {
            Shape::Box(b) => b.clone(),
            Shape::Polygon(p) => Bounds {
                min: (0..2)
                    .map(|a| p.iter().map(|v| v[a]).fold(f64::INFINITY, f64::min))
                    .collect(),
                max: (0..2)
                    .map(|a| p.iter().map(|v| v[a]).fold(f64::NEG_INFINITY, f64::max))
                    .collect(),
            },
        }
    }

    /// The coordinate along `axis` of the body's face on `side` (±1) of its bounding box.
    pub fn face_at(&self, axis: usize, side: f64) -> f64 {
        let b = self.bounding_box();
        if side > 0.0 {
            b.max[axis]
        } else {
            b.min[axis]
        }
    }

    /// Does the body hold `x` (within `tol`)?
    pub fn contains(&self, x: &[f64], tol: f64) -> bool {
        match self.shape() {
            Shape::Box(b) => b.contains(x, tol),
            Shape::Polygon(p) => super::geometry::polygon_contains(p, x, tol),
        }
    }

    /// The body's outline as a convex polygon (2D).
    pub fn outline(&self) -> Vec<[f64; 2]> {
        match self.shape() {
            Shape::Polygon(p) => p.to_vec(),
            Shape::Box(b) => vec![
                [b.min[0], b.min[1]],
                [b.max[0], b.min[1]],
                [b.max[0], b.max[1]],
                [b.min[0], b.max[1]],
            ],
        }
    }
}

/// Grid (or mesh) nodes on a plane or in a box with some of their components fixed at zero.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Support {
    pub name: String,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub plane: Option<Plane>,
    #[serde(default, rename = "box", skip_serializing_if = "Option::is_none")]
    pub bounds: Option<Bounds>,
    /// The fixed components: `["x"]` a roller, `["x", "y"]` full fixity in 2D.
    pub fix: Vec<String>,
}

/// What a load is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum LoadKind {
    /// A body force per unit mass, `vector`, on every body.
    Gravity,
    /// A prescribed displacement of the nodes on a plane or in a box (`displacement`, the
    /// components moved; the others stay free): a smooth platen moves one component, a rough
    /// one all.
    Displacement,
    /// A uniform dead traction (`vector`, force per unit initial area, fixed in direction)
    /// on one face of a box body (`body`, `face` = `x-`, `x+`, `y-`, …), reached linearly:
    /// FEM takes the consistent nodal forces of the face's elements; material points carry
    /// it as point loads, each the traction times its domain's share of the face.
    Traction,
}

/// Prescribed displacement components (absent: free).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Components {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub x: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub y: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub z: Option<f64>,
}

impl Components {
    /// (axis, value) of the given components.
    pub fn given(&self) -> Vec<(usize, f64)> {
        [self.x, self.y, self.z]
            .iter()
            .enumerate()
            .filter_map(|(a, v)| v.map(|v| (a, v)))
            .collect()
    }
}

/// One load at the end of the analysis, reached over the load steps by its `ramp`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Load {
    pub kind: LoadKind,
    /// A displacement load's name (measures of reactions name it).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    /// Gravity: the acceleration vector.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub vector: Option<Vec<f64>>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub plane: Option<Plane>,
    #[serde(default, rename = "box", skip_serializing_if = "Option::is_none")]
    pub bounds: Option<Bounds>,
    /// Displacement: the prescribed components at full load.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub displacement: Option<Components>,
    /// Traction: the loaded body and its face (`x-`, `x+`, `y-`, `y+`, `z-`, `z+`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub body: Option<String>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub face: Option<String>,
    /// `"linear"` (default) or `{ table = [[0.0, 0.0], …, [1.0, f]] }`.
    #[serde(default, skip_serializing_if = "is_linear")]
    pub ramp: Ramp,
    /// Displacement: what moves ([`Bind`]).
    #[serde(default, skip_serializing_if = "is_nodes")]
    pub on: Bind,
    /// With `on = "points"`: the penalty factor β ([`crate::mpm::DEFAULT_POINT_PENALTY`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub penalty: Option<f64>,
}

/// What a displacement load moves: the grid `nodes` in its region (default), or the points
/// whose initial domain meets it, by a penalty ([`crate::discretise::point_penalty`]). FEM
/// nodes move with the material, so FEM prescribes its nodes either way.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Bind {
    #[default]
    Nodes,
    Points,
}

fn is_nodes(b: &Bind) -> bool {
    *b == Bind::Nodes
}

fn is_linear(r: &Ramp) -> bool {
    *r == Ramp::Linear
}

/// A face `x-`, `x+`, `y-`, … as (axis, +1 or −1).
pub fn face_of(key: &str, face: &str, dimension: usize) -> Result<(usize, f64), InputError> {
    let (axis, side) = face.split_at(face.len().min(1));
    let a = AXES[..dimension].iter().position(|x| *x == axis);
    match (a, side) {
        (Some(a), "-") => Ok((a, -1.0)),
        (Some(a), "+") => Ok((a, 1.0)),
        _ => Err(err(
            key,
            format!("{face:?}"),
            format!(
                "must be one of {}",
                AXES[..dimension]
                    .iter()
                    .flat_map(|x| [format!("{x}-"), format!("{x}+")])
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        )),
    }
}

/// The axis and magnitude of a scene's one gravity load when it has one box body and its
/// only gravity load lies along an axis (the column's setting).
pub fn column_axis(scene: &Scene) -> Option<(usize, f64)> {
    let [body] = &scene.bodies[..] else { return None };
    body.bounds.as_ref()?;
    let gravity: Vec<&Vec<f64>> = scene
        .loads
        .iter()
        .filter(|l| l.kind == LoadKind::Gravity)
        .filter_map(|l| l.vector.as_ref())
        .collect();
    let [g] = gravity[..] else { return None };
    let along: Vec<usize> = (0..g.len()).filter(|&a| g[a] != 0.0).collect();
    let [axis] = along[..] else { return None };
    (g[axis] < 0.0).then_some((axis, -g[axis]))
}

/// `[strength_reduction]`: the factor F by which the strength is divided, as a table of
/// [load fraction, F] rows (`ramp = { table = [[0.0, 1.0], [0.2, 1.0], [1.0, 2.0]] }`: the
/// full strength while gravity comes on over the first fifth, then F rising to 2).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StrengthReductionSection {
    pub ramp: Ramp,
}

/// A whole scene with its materials resolved.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Scene {
    pub dimension: usize,
    pub grid: GridSection,
    pub bodies: Vec<Body>,
    pub materials: BTreeMap<String, Material>,
    pub supports: Vec<Support>,
    pub loads: Vec<Load>,
    pub measures: Vec<Measure>,
    /// The strength divided by a rising factor ([`super::strength`]); none: the strength
    /// as given. Absent from the serialised scene when none, so that the cases of scenes
    /// without one keep their keys.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub strength_reduction: Option<StrengthReductionSection>,
}

pub(super) fn err(key: impl Into<String>, value: impl ToString, allowed: impl Into<String>) -> InputError {
    InputError::new(key, value, allowed)
}

/// The index of axis name `name` below `dimension`.
pub fn axis_index(key: &str, name: &str, dimension: usize) -> Result<usize, InputError> {
    AXES[..dimension].iter().position(|a| *a == name).ok_or_else(|| {
        err(
            key,
            format!("{name:?}"),
            format!("must be one of {}", AXES[..dimension].join(", ")),
        )
    })
}

/// A vector of `dimension` finite values.
pub(super) fn vector(key: &str, v: &[f64], dimension: usize) -> Result<(), InputError> {
    if v.len() != dimension {
        return Err(err(
            key,
            format!("{v:?}"),
            format!("must have {dimension} values (dimension = {dimension})"),
        ));
    }
    match v.iter().position(|x| !x.is_finite()) {
        Some(i) => Err(err(format!("{key}[{i}]"), v[i], "must be finite")),
        None => Ok(()),
    }
}

impl Bounds {
    /// `dimension` finite values each, max above min (`strict`, a body) or not below it (a
    /// region of nodes may be flat: a line or a plane of nodes).
    pub(super) fn check(&self, key: &str, dimension: usize, strict: bool) -> Result<(), InputError> {
        vector(&format!("{key}.min"), &self.min, dimension)?;
        vector(&format!("{key}.max"), &self.max, dimension)?;
        for a in 0..dimension {
            if self.max[a] < self.min[a] || strict && self.max[a] == self.min[a] {
                return Err(err(
                    format!("{key}.max[{a}]"),
                    shortest(self.max[a]),
                    format!(
                        "must be {} {key}.min[{a}] = {}",
                        if strict { "greater than" } else { "at least" },
                        shortest(self.min[a])
                    ),
                ));
            }
        }
        Ok(())
    }

    /// Does the box contain `x` (within `tol`)?
    pub fn contains(&self, x: &[f64], tol: f64) -> bool {
        x.iter()
            .enumerate()
            .all(|(a, &v)| v >= self.min[a] - tol && v <= self.max[a] + tol)
    }
}

/// A node region: a plane or a box, exactly one of them.
#[derive(Debug, Clone, Copy)]
pub enum Region<'a> {
    Plane(usize, f64),
    Box(&'a Bounds),
}

impl Region<'_> {
    /// Does the region hold the node at `x` (within `tol`)?
    pub fn holds(&self, x: &[f64], tol: f64) -> bool {
        match self {
            Region::Plane(a, at) => (x[*a] - at).abs() <= tol,
            Region::Box(b) => b.contains(x, tol),
        }
    }
}

/// The region of a support or load at `key` from its `plane` and `box` keys.
pub fn region<'a>(
    key: &str,
    plane: &Option<Plane>,
    bounds: &'a Option<Bounds>,
    dimension: usize,
) -> Result<Region<'a>, InputError> {
    match (plane, bounds) {
        (Some(p), None) => {
            let a = axis_index(&format!("{key}.plane.axis"), &p.axis, dimension)?;
            if !p.at.is_finite() {
                return Err(err(format!("{key}.plane.at"), p.at, "must be finite"));
            }
            Ok(Region::Plane(a, p.at))
        }
        (None, Some(b)) => {
            b.check(&format!("{key}.box"), dimension, false)?;
            Ok(Region::Box(b))
        }
        (Some(_), Some(_)) => Err(err(key, "plane and box", "must give a plane or a box, not both")),
        (None, None) => Err(err(
            key,
            "no region",
            "must give a plane = { axis, at } or a box = { min, max }",
        )),
    }
}

impl Scene {
    /// Check every value; an error names its key (`bodies[0].box.max[1]`), its value and the
    /// allowed range. What depends on the element size (a region on no node, a body off the
    /// point lattice) is checked when a case is built.
    pub fn validate(&self) -> Result<(), InputError> {
        let d = self.dimension;
        if !matches!(d, 2 | 3) {
            return Err(err("dimension", d, "must be 2 or 3"));
        }
        vector("grid.origin", &self.grid.origin, d)?;
        vector("grid.extent", &self.grid.extent, d)?;
        if let Some(a) = (0..d).find(|&a| self.grid.extent[a] <= 0.0) {
            return Err(err(
                format!("grid.extent[{a}]"),
                self.grid.extent[a],
                "must be > 0",
            ));
        }
        let grid = Bounds {
            min: self.grid.origin.clone(),
            max: (0..d)
                .map(|a| self.grid.origin[a] + self.grid.extent[a])
                .collect(),
        };
        if self.bodies.is_empty() {
            return Err(err("bodies", "[]", "must list at least one body ([[bodies]])"));
        }
        let mut names = std::collections::BTreeSet::new();
        for (i, b) in self.bodies.iter().enumerate() {
            let key = format!("bodies[{i}]");
            self.name(&format!("{key}.name"), &b.name, &mut names)?;
            match (&b.bounds, &b.polygon) {
                (Some(bx), None) => bx.check(&format!("{key}.box"), d, true)?,
                (None, Some(p)) => super::geometry::check_polygon(&format!("{key}.polygon"), p, d)?,
                _ => {
                    return Err(err(
                        key.clone(),
                        "box and polygon",
                        "must give a box or a polygon, exactly one",
                    ))
                }
            }
            let bb = b.bounding_box();
            if !(grid.contains(&bb.min, 1e-12) && grid.contains(&bb.max, 1e-12)) {
                return Err(err(
                    format!("{key}.{}", if b.polygon.is_some() { "polygon" } else { "box" }),
                    format!("{:?} .. {:?}", bb.min, bb.max),
                    format!("must lie inside the grid {:?} .. {:?}", grid.min, grid.max),
                ));
            }
            if !(b.density.is_finite() && b.density > 0.0) {
                return Err(err(format!("{key}.density"), b.density, "must be finite and > 0"));
            }
            if !self.materials.contains_key(&b.material) {
                let known: Vec<&str> = self.materials.keys().map(String::as_str).collect();
                return Err(err(
                    format!("{key}.material"),
                    format!("{:?}", b.material),
                    format!("must name a [materials.<name>] table: {}", known.join(", ")),
                ));
            }
            if b.material != self.bodies[0].material {
                return Err(err(
                    format!("{key}.material"),
                    format!("{:?}", b.material),
                    format!(
                        "must be bodies[0]'s {:?}: the solvers hold one constitutive model for all points",
                        self.bodies[0].material
                    ),
                ));
            }
            if let Some(t) = &b.initial_stress {
                t.check(&format!("{key}.initial_stress"), d)?;
            }
            if b.initial_stress != self.bodies[0].initial_stress {
                return Err(err(
                    format!("{key}.initial_stress"),
                    format!("{:?}", b.initial_stress),
                    format!(
                        "must be bodies[0]'s {:?}: the solvers start every point in one state",
                        self.bodies[0].initial_stress
                    ),
                ));
            }
            for (j, o) in self.bodies[..i].iter().enumerate() {
                let (a, c) = (b.bounding_box(), o.bounding_box());
                let boxes = (0..d).all(|x| a.min[x] < c.max[x] && c.min[x] < a.max[x]);
                let overlap = boxes && (d == 3 || super::geometry::overlap(&b.outline(), &o.outline()));
                if overlap {
                    return Err(err(
                        format!("{key}.{}", if b.polygon.is_some() { "polygon" } else { "box" }),
                        format!("{:?} .. {:?}", a.min, a.max),
                        format!("must not overlap bodies[{j}] ({:?})", o.name),
                    ));
                }
            }
        }
        for (i, s) in self.supports.iter().enumerate() {
            let key = format!("supports[{i}]");
            self.name(&format!("{key}.name"), &s.name, &mut names)?;
            region(&key, &s.plane, &s.bounds, d)?;
            self.components(&format!("{key}.fix"), &s.fix)?;
        }
        if self.loads.is_empty() {
            return Err(err("loads", "[]", "must list at least one load ([[loads]])"));
        }
        for (i, l) in self.loads.iter().enumerate() {
            self.check_load(i, l, &mut names)?;
        }
        let mut measures = std::collections::BTreeSet::new();
        for (i, m) in self.measures.iter().enumerate() {
            self.check_measure(i, m, &mut measures)?;
        }
        self.strength_reduction()?;
        Ok(())
    }

    /// A non-empty name not used before (bodies, supports and loads share one namespace).
    pub(super) fn name(
        &self,
        key: &str,
        name: &str,
        names: &mut std::collections::BTreeSet<String>,
    ) -> Result<(), InputError> {
        if name.trim().is_empty() || name.len() > 64 {
            return Err(err(
                key,
                format!("{name:?}"),
                "must be a name of 1 to 64 characters",
            ));
        }
        if !names.insert(name.to_string()) {
            return Err(err(
                key,
                format!("{name:?}"),
                "must differ from every other body's, support's and load's name",
            ));
        }
        Ok(())
    }

    /// At least one component name, each once.
    pub(super) fn components(&self, key: &str, names: &[String]) -> Result<Vec<usize>, InputError> {
        if names.is_empty() {
            return Err(err(key, "[]", "must list the fixed components, e.g. [\"x\"]"));
        }
        let mut axes = vec![];
        for (j, n) in names.iter().enumerate() {
            let a = axis_index(&format!("{key}[{j}]"), n, self.dimension)?;
            if axes.contains(&a) {
                return Err(err(
                    format!("{key}[{j}]"),
                    format!("{n:?}"),
                    "must not repeat a component",
                ));
            }
            axes.push(a);
        }
        Ok(axes)
    }
}

/// How one case solves a scene besides its method.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneSettings {
    /// Element size h: the grid's cells (cubes of h) and the FEM mesh's elements.
    pub element_size: f64,
    /// Material points per cell along each axis (material point methods).
    pub points_per_cell: usize,
    pub load_steps: usize,
    pub newton: NewtonSettings,
    pub ghost: GhostSettings,
    pub domain_update: DomainUpdate,
    pub linear_solver: LinearSolver,
    /// F-bar over each cell (material points) or element (FEM); reference/README.md item 69.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub f_bar: bool,
    /// With F-bar, every cell's or element's points carry its mean pressure (reference/README.md
    /// item 75).
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub pressure_projection: bool,
    /// Gauss points per axis of a FEM case (`None`: the element's default).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gauss_points: Option<usize>,
}
