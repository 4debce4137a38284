//! A scene resolved at one element size for the material point methods, as plain data: the
//! grid, every point's initial position, volume and domain, the node dofs of each support and
//! displacement load, the gravity loads and the tractions as point loads. It is what a case of
//! the case protocol carries (`studies/PROTOCOL.md`), so that another code solves exactly the
//! points igimp solves, and what igimp builds its own solver from, in process or through its
//! adapter: one path, so that the two agree.

use super::build::{cells, fill_points, region_dofs, traction_point_loads, NamedDofs};
use super::initial_stress::StressComponents;
use super::spec::{LoadKind, Scene, SceneSettings};
use crate::basis::Basis;
use crate::material::constitutive::Material;
use crate::mesh::grid::Grid;
use crate::mpm::particles::MaterialPoints;
use crate::mpm::{Loads, MpmSettings, MpmSolver};
use crate::solver::dynamics::BodyForce;
use crate::solver::error::InputError;
use crate::solver::ramp::Ramp;
use nalgebra::SVector;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// The background grid: `cells[a]` cubes of side `cell_size` from `origin` along axis `a`.
/// Node `(i, j, k)` is number `i + (n₀ + 1) (j + (n₁ + 1) k)`: axis 0 fastest, from 0.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DiscreteGrid {
    pub origin: Vec<f64>,
    pub cell_size: f64,
    pub cells: Vec<usize>,
}

/// Every material point's initial state.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DiscretePoints {
    pub position: Vec<Vec<f64>>,
    /// Initial volume (the part of its lattice cell inside the body).
    pub volume: Vec<f64>,
    /// Half the side of the point's initial box domain along each axis.
    pub half_length: Vec<Vec<f64>>,
}

/// A support or a displacement load: grid nodes whose `components` are fixed, to zero or to
/// `displacement[c]` (one value per component) times the ramp's factor.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DiscreteRegion {
    pub name: String,
    pub nodes: Vec<usize>,
    /// Axes (0 = x).
    pub components: Vec<usize>,
    /// Displacement at full load per component; absent for a support (zero).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub displacement: Option<Vec<f64>>,
    #[serde(default)]
    pub ramp: Ramp,
    /// A displacement load on material points (`on = "points"`): the points whose initial
    /// domain meets its region, bound by a penalty ([`crate::discretise::point_penalty`]);
    /// `nodes` is then empty.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub points: Vec<usize>,
    /// The bound points' penalty factor β (absent: [`crate::mpm::DEFAULT_POINT_PENALTY`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub penalty: Option<f64>,
}

/// Reactions summed over each region's fixed dofs: region name → one value per axis.
pub type Reactions = BTreeMap<String, Vec<f64>>;

/// Gravity g (acceleration) times the ramp's factor.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GravityLoad {
    pub vector: Vec<f64>,
    #[serde(default)]
    pub ramp: Ramp,
}

/// A dead force on a material point (a traction's share), following the scene's
/// `point_load_ramp`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PointLoad {
    pub point: usize,
    pub force: Vec<f64>,
}

/// A scene resolved at one element size (see the module's doc).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DiscreteScene {
    /// 2 (plane strain) or 3.
    pub dimension: usize,
    pub grid: DiscreteGrid,
    pub material: Material,
    /// Initial density ρ₀ of every point.
    pub density: f64,
    pub points: DiscretePoints,
    pub regions: Vec<DiscreteRegion>,
    pub gravity: Vec<GravityLoad>,
    #[serde(default)]
    pub point_loads: Vec<PointLoad>,
    /// The ramp every point load follows (default linear).
    #[serde(default, skip_serializing_if = "is_linear")]
    pub point_load_ramp: Ramp,
    /// The Cauchy stress every point starts in (absent: unstressed), held elastically.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub initial_stress: Option<StressComponents>,
    /// The factor the material's strength is divided by, over the load steps (absent: none;
    /// [`crate::material::strength_reduction`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub strength_reduction: Option<Ramp>,
}

fn is_linear(r: &Ramp) -> bool {
    *r == Ramp::Linear
}

fn err(key: impl Into<String>, value: impl ToString, allowed: impl Into<String>) -> InputError {
    InputError::new(key, value, allowed)
}

impl DiscreteScene {
    /// `scene` at `settings`' element size and points per cell (one material and density:
    /// the solvers take one constitutive model).
    pub fn of(scene: &Scene, settings: &SceneSettings) -> Result<Self, InputError> {
        scene.validate()?;
        match scene.dimension {
            2 => Self::build::<2>(scene, settings),
            3 => Self::build::<3>(scene, settings),
            d => Err(err("dimension", d, "must be 2 or 3")),
        }
    }

    fn build<const D: usize>(scene: &Scene, s: &SceneSettings) -> Result<Self, InputError> {
        let h = s.element_size;
        let mut n = [0; D];
        for a in 0..D {
            n[a] = cells(&format!("grid.extent[{a}]"), scene.grid.extent[a], h)?;
        }
        let origin: [f64; D] = std::array::from_fn(|a| scene.grid.origin[a]);
        let grid = Grid::try_new(origin, [h; D], n)?;
        let points = fill_points(scene, &grid, s.points_per_cell)?;
        let named = region_dofs(scene, h, &|f| {
            for k in 0..grid.num_nodes() {
                f(k, grid.node_position(k).as_slice())
            }
        })?;
        let body = &scene.bodies[0];
        let v = |x: &SVector<f64, D>| x.iter().copied().collect::<Vec<f64>>();
        Ok(DiscreteScene {
            dimension: D,
            grid: DiscreteGrid {
                origin: origin.to_vec(),
                cell_size: h,
                cells: n.to_vec(),
            },
            material: scene.materials[&body.material],
            density: body.density,
            points: DiscretePoints {
                position: points.position0.iter().map(v).collect(),
                volume: points.volume0.clone(),
                half_length: points.half_length0.iter().map(v).collect(),
            },
            regions: bind_points(scene, &points, regions_of(&named), h)?,
            gravity: gravity_loads(scene),
            point_loads: traction_point_loads(scene, &points, h)
                .into_iter()
                .map(|(p, f)| PointLoad {
                    point: p,
                    force: v(&f),
                })
                .collect(),
            point_load_ramp: super::build::traction_ramp(scene),
            initial_stress: body.initial_stress,
            strength_reduction: scene.strength_reduction.as_ref().map(|r| r.ramp.clone()),
        })
    }

    /// Every value checked: sizes that agree, finite numbers, nodes on the grid, points
    /// inside it. An error names the key path under `case`.
    pub fn validate(&self) -> Result<(), InputError> {
        let d = self.dimension;
        if d != 2 && d != 3 {
            return Err(err("dimension", d, "must be 2 or 3"));
        }
        let vector = |key: String, x: &[f64]| -> Result<(), InputError> {
            if x.len() != d {
                return Err(err(key, format!("{x:?}"), format!("must have {d} entries")));
            }
            if let Some(i) = x.iter().position(|v| !v.is_finite()) {
                return Err(err(format!("{key}[{i}]"), x[i], "must be finite"));
            }
            Ok(())
        };
        vector("grid.origin".into(), &self.grid.origin)?;
        if self.grid.cells.len() != d {
            return Err(err(
                "grid.cells",
                format!("{:?}", self.grid.cells),
                format!("must have {d} entries"),
            ));
        }
        if !(self.grid.cell_size.is_finite() && self.grid.cell_size > 0.0) {
            return Err(err(
                "grid.cell_size",
                self.grid.cell_size,
                "must be finite and > 0",
            ));
        }
        let nodes: usize = self.grid.cells.iter().map(|c| c + 1).product();
        if !(self.density.is_finite() && self.density > 0.0) {
            return Err(err("density", self.density, "must be finite and > 0"));
        }
        self.material.build()?;
        let p = &self.points;
        let count = p.position.len();
        if count == 0 {
            return Err(err("points.position", "[]", "must list at least one point"));
        }
        for (key, len) in [
            ("points.volume", p.volume.len()),
            ("points.half_length", p.half_length.len()),
        ] {
            if len != count {
                return Err(err(
                    key,
                    format!("{len} entries"),
                    format!("must have one per point ({count})"),
                ));
            }
        }
        for k in 0..count {
            vector(format!("points.position[{k}]"), &p.position[k])?;
            vector(format!("points.half_length[{k}]"), &p.half_length[k])?;
            for a in 0..d {
                let (lo, hi) = (
                    self.grid.origin[a],
                    self.grid.origin[a] + self.grid.cells[a] as f64 * self.grid.cell_size,
                );
                if !(lo..=hi).contains(&p.position[k][a]) {
                    return Err(err(
                        format!("points.position[{k}][{a}]"),
                        p.position[k][a],
                        format!("must lie on the grid, in [{lo}, {hi}]"),
                    ));
                }
                if p.half_length[k][a] <= 0.0 {
                    return Err(err(
                        format!("points.half_length[{k}][{a}]"),
                        p.half_length[k][a],
                        "must be > 0",
                    ));
                }
            }
            if !(p.volume[k].is_finite() && p.volume[k] > 0.0) {
                return Err(err(
                    format!("points.volume[{k}]"),
                    p.volume[k],
                    "must be finite and > 0",
                ));
            }
        }
        for (i, r) in self.regions.iter().enumerate() {
            let key = format!("regions[{i}]");
            if let Some(j) = r.nodes.iter().position(|&n| n >= nodes) {
                return Err(err(
                    format!("{key}.nodes[{j}]"),
                    r.nodes[j],
                    format!("must be a node of the grid, < {nodes}"),
                ));
            }
            if let Some(j) = r.components.iter().position(|&c| c >= d) {
                return Err(err(
                    format!("{key}.components[{j}]"),
                    r.components[j],
                    format!("must be an axis, < {d}"),
                ));
            }
            if let Some(u) = &r.displacement {
                if u.len() != r.components.len() || u.iter().any(|v| !v.is_finite()) {
                    return Err(err(
                        format!("{key}.displacement"),
                        format!("{u:?}"),
                        "must give one finite value per component",
                    ));
                }
            }
            r.ramp.validate(&format!("{key}.ramp"))?;
            if let Some(j) = r.points.iter().position(|&p| p >= count) {
                return Err(err(
                    format!("{key}.points[{j}]"),
                    r.points[j],
                    format!("must be a point, < {count}"),
                ));
            }
            if !r.points.is_empty() && r.displacement.is_none() {
                return Err(err(
                    format!("{key}.displacement"),
                    "missing",
                    "bound points need the displacement they follow",
                ));
            }
        }
        for (i, g) in self.gravity.iter().enumerate() {
            vector(format!("gravity[{i}].vector"), &g.vector)?;
            g.ramp.validate(&format!("gravity[{i}].ramp"))?;
        }
        for (i, l) in self.point_loads.iter().enumerate() {
            if l.point >= count {
                return Err(err(
                    format!("point_loads[{i}].point"),
                    l.point,
                    format!("must be a point, < {count}"),
                ));
            }
            vector(format!("point_loads[{i}].force"), &l.force)?;
        }
        self.point_load_ramp.validate("point_load_ramp")?;
        if let Some(t) = &self.initial_stress {
            t.check("initial_stress", d)?;
        }
        Ok(())
    }

    /// The regions as (name, fixed dofs, prescribed values and ramp), in the order the solver
    /// takes them.
    pub(super) fn named_dofs(&self) -> NamedDofs {
        self.regions
            .iter()
            .map(|r| {
                let dofs = r
                    .components
                    .iter()
                    .flat_map(|&a| r.nodes.iter().map(move |&n| (n, a)))
                    .collect();
                let values = r.displacement.as_ref().map(|u| {
                    let v = r
                        .components
                        .iter()
                        .zip(u)
                        .flat_map(|(&a, &v)| r.nodes.iter().map(move |&n| (n, a, v)))
                        .collect();
                    (v, r.ramp.clone())
                });
                (r.name.clone(), dofs, values)
            })
            .collect()
    }

    /// The material point solver of this scene by `basis` with `s`'s Newton, load steps and
    /// linear solver; the displacement loads prescribed.
    pub fn solver<const D: usize>(
        &self,
        basis: Basis,
        s: &SceneSettings,
    ) -> Result<MpmSolver<D>, InputError> {
        self.validate()?;
        if self.dimension != D {
            return Err(err(
                "dimension",
                self.dimension,
                format!("must be {D} for this solver"),
            ));
        }
        let at = |x: &[f64]| SVector::<f64, D>::from_iterator(x.iter().copied());
        let g = &self.grid;
        let grid = Grid::try_new(
            std::array::from_fn(|a| g.origin[a]),
            [g.cell_size; D],
            std::array::from_fn(|a| g.cells[a]),
        )?;
        let mut points = MaterialPoints::<D>::default();
        let p = &self.points;
        for k in 0..p.position.len() {
            points.push_with_volume(
                at(&p.position[k]),
                at(&p.half_length[k]),
                p.volume[k],
                self.density,
            );
        }
        let named = self.named_dofs();
        let (linear, tabled) = gravity_split::<D>(&self.gravity, self.density);
        let settings = MpmSettings {
            basis,
            domain_update: s.domain_update,
            newton: s.newton,
            load_steps: s.load_steps,
            weak_node_tolerance: 0.0,
            weak_node_treatment: Default::default(),
            volume_update: Default::default(),
            linear_solver: s.linear_solver,
            ghost: s.ghost,
            dynamics: None,
            f_bar: s.f_bar,
        };
        let loads = Loads {
            gravity: linear,
            point_loads: self.point_loads.iter().map(|l| (l.point, at(&l.force))).collect(),
        };
        let fixed = super::build::fixed_dofs(&named);
        let model = self.material.build()?;
        if let Some(t) = &self.initial_stress {
            let last: Vec<f64> = points.position0.iter().map(|x| x[D - 1]).collect();
            super::initial_stress::start_in("initial_stress", t, model.as_ref(), &mut points.state, &last)?;
        }
        let mut solver = MpmSolver::try_new(grid, points, model, fixed, loads, settings)?;
        solver.set_point_load_ramp(self.point_load_ramp.clone());
        if let Some(r) = &self.strength_reduction {
            solver.set_strength_reduction(Some(crate::material::strength_reduction::StrengthReduction::new(
                "strength_reduction",
                self.material,
                r.clone(),
            )?));
        }
        if let Some(b) = tabled {
            solver.set_body_force(b);
        }
        for (values, ramp) in super::build::prescribed(&named) {
            solver.prescribe(values, ramp.clone())?;
        }
        for (i, r) in self
            .regions
            .iter()
            .enumerate()
            .filter(|(_, r)| !r.points.is_empty())
        {
            let u = r.displacement.as_deref().unwrap_or_default();
            let values: Vec<(usize, f64)> = r.components.iter().copied().zip(u.iter().copied()).collect();
            let beta = r.penalty.unwrap_or(crate::mpm::DEFAULT_POINT_PENALTY);
            solver
                .bind_points(&r.points, &values, r.ramp.clone(), beta)
                .map_err(|e| err(format!("regions[{i}].{}", e.field), e.value, e.allowed))?;
        }
        Ok(solver)
    }

    /// The index of region `name`'s bound points in [`Self::solver`]'s solver, if it binds any.
    pub fn bound_group(&self, name: &str) -> Option<usize> {
        self.regions
            .iter()
            .filter(|r| !r.points.is_empty())
            .position(|r| r.name == name)
    }
}

/// The gravity loads of `scene`, in its order.
pub(super) fn gravity_loads(scene: &Scene) -> Vec<GravityLoad> {
    scene
        .loads
        .iter()
        .filter(|l| l.kind == LoadKind::Gravity)
        .map(|l| GravityLoad {
            vector: l.vector.clone().unwrap_or_default(),
            ramp: l.ramp.clone(),
        })
        .collect()
}

/// `gravity` as the solvers take it: the sum of the linearly ramped loads (the solvers ramp a
/// gravity themselves), and the tabled ones as a body force ρ₀ g f(λ) of one density.
pub(super) fn gravity_split<const D: usize>(
    gravity: &[GravityLoad],
    density: f64,
) -> (SVector<f64, D>, Option<BodyForce<D>>) {
    let at = |x: &[f64]| SVector::<f64, D>::from_iterator(x.iter().copied());
    let mut linear = SVector::<f64, D>::zeros();
    let mut tabled = vec![];
    for l in gravity {
        match l.ramp {
            Ramp::Linear => linear += at(&l.vector),
            _ => tabled.push((at(&l.vector), l.ramp.clone())),
        }
    }
    let force = (!tabled.is_empty()).then(|| {
        BodyForce::new(move |_: &SVector<f64, D>, t: f64| {
            tabled.iter().map(|(g, r)| g * (density * r.factor(t))).sum()
        })
    });
    (linear, force)
}

/// The regions of `named`, each with its nodes once and its components in order.
fn regions_of(named: &NamedDofs) -> Vec<DiscreteRegion> {
    named
        .iter()
        .map(|(name, dofs, values)| {
            let mut components: Vec<usize> = vec![];
            for &(_, a) in dofs {
                if !components.contains(&a) {
                    components.push(a);
                }
            }
            let first = components.first().copied();
            let nodes = dofs.iter().filter(|d| Some(d.1) == first).map(|d| d.0).collect();
            let displacement = values.as_ref().map(|(v, _)| {
                components
                    .iter()
                    .map(|&a| v.iter().find(|x| x.1 == a).map_or(0.0, |x| x.2))
                    .collect()
            });
            DiscreteRegion {
                name: name.clone(),
                nodes,
                components,
                displacement,
                ramp: values.as_ref().map_or(Ramp::Linear, |v| v.1.clone()),
                points: vec![],
                penalty: None,
            }
        })
        .collect()
}

/// `regions` (supports, then displacement loads, in the scene's order) with every
/// displacement load `on = "points"` moved from its nodes to the points whose initial domain
/// meets its region (within 1e-9 h; along an axis where the region is flat, the domain must
/// reach it, elsewhere overlap it over a positive length).
fn bind_points<const D: usize>(
    scene: &Scene,
    points: &MaterialPoints<D>,
    mut regions: Vec<DiscreteRegion>,
    h: f64,
) -> Result<Vec<DiscreteRegion>, InputError> {
    let tol = 1e-9 * h;
    let loads = scene
        .loads
        .iter()
        .enumerate()
        .filter(|(_, l)| l.kind == LoadKind::Displacement);
    for ((i, l), r) in loads.zip(regions.iter_mut().skip(scene.supports.len())) {
        if l.on != super::spec::Bind::Points {
            continue;
        }
        let key = format!("loads[{i}]");
        let region = super::spec::region(&key, &l.plane, &l.bounds, D)?;
        let overlaps = |lo: f64, hi: f64, min: f64, max: f64| {
            if max - min <= tol {
                lo <= max + tol && hi >= min - tol
            } else {
                lo < max - tol && hi > min + tol
            }
        };
        r.points = (0..points.len())
            .filter(|&p| {
                let (x, l) = (&points.position0[p], &points.half_length0[p]);
                (0..D).all(|a| {
                    let (lo, hi) = (x[a] - l[a], x[a] + l[a]);
                    match region {
                        super::spec::Region::Plane(b, at) => b != a || overlaps(lo, hi, at, at),
                        super::spec::Region::Box(bx) => overlaps(lo, hi, bx.min[a], bx.max[a]),
                    }
                })
            })
            .collect();
        if r.points.is_empty() {
            return Err(err(
                key,
                "no material point",
                format!("on = \"points\" must meet the domain of at least one point at h = {h}"),
            ));
        }
        r.nodes.clear();
        r.penalty = l.penalty;
    }
    Ok(regions)
}

/// The reaction of every region of `discrete` after `solver`'s last step, per axis: summed
/// over its nodes, or the force of its bound points ([`MpmSolver::bound_reaction`]).
pub fn region_reactions<const D: usize>(discrete: &DiscreteScene, solver: &MpmSolver<D>) -> Reactions {
    let mut all = reactions(solver, &discrete.named_dofs());
    for (name, r) in all.iter_mut() {
        if let Some(g) = discrete.bound_group(name) {
            *r = solver.bound_reaction(g).iter().copied().collect();
        }
    }
    all
}

/// The reaction of every region of `named`: the solver's reactions summed over its fixed
/// dofs, per axis, in the order the measures sum them.
fn reactions<const D: usize>(solver: &MpmSolver<D>, named: &NamedDofs) -> Reactions {
    named
        .iter()
        .map(|(name, dofs, _)| {
            let r = (0..D)
                .map(|a| {
                    dofs.iter()
                        .filter(|d| d.1 == a)
                        .map(|&(n, a)| solver.reaction(n, a))
                        .sum()
                })
                .collect();
            (name.clone(), r)
        })
        .collect()
}
