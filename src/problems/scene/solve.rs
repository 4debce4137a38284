//! A scene solved by one method: the grid and points (or the mesh) built from its bodies, the
//! supports and displacement loads turned into node dofs, gravity and the ramps applied, the
//! load steps run, and the measures read after every step.

use super::build::{body_mesh, fixed_dofs, prescribed, region_dofs, traction_nodal_forces, NamedDofs};
use super::discrete::{gravity_loads, gravity_split};
use super::spec::{axis_index, MeasureKind, Scene, SceneSettings};
use crate::basis::method::Method;
use crate::basis::Basis;
use crate::fem::{ContinuumFem, ElementFamily, FemLoads, HexElement, PlaneFemSettings, QuadElement};
use crate::material::kinematics::PointState;
use crate::mpm::MpmSolver;
use crate::solver::error::{InputError, SolveError};
use crate::solver::load_stepping::{steps_and_failure, LoadStepping, StepReport};
use nalgebra::SVector;
use serde::{Deserialize, Serialize};

/// One measure of a solved case: its final value and, if asked, its value after every step.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MeasureValue {
    pub name: String,
    pub value: f64,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub history: Vec<f64>,
    /// A stress line's samples at the end (its `value` is their mean).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub profile: Vec<f64>,
}

/// Final state of one material point or Gauss point (ParaView).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PointRecord {
    pub x0: [f64; 3],
    pub x: [f64; 3],
    pub half0: [f64; 3],
    pub half: [f64; 3],
    /// Cauchy stress σ along the last axis.
    pub sigma: f64,
}

/// What a scene case gives.
#[derive(Debug, Clone, PartialEq)]
pub struct SceneOutcome {
    pub steps: Vec<StepReport>,
    pub failure: Option<SolveError>,
    /// Did the run end in the collapse its strength reduction drove it to
    /// ([`Scene::collapsed`])? Then `failure` is where it collapsed.
    pub collapsed: bool,
    /// The measures at the last converged step (in the scene's order), and their histories.
    pub measures: Vec<MeasureValue>,
    /// Material points or elements.
    pub size: usize,
    /// Material points' final domains (none for FEM).
    pub points: Vec<PointRecord>,
}

/// The methods of a scene in `dimension`.
pub fn methods(dimension: usize) -> &'static [Method] {
    // Every family, and the plane (solid) elements: the compaction's set.
    crate::problems::compaction::methods(dimension)
}

/// Solve `scene` by `method` with `settings`. Errors are the case's input errors (a region
/// on no node at this h, a body off the point lattice, a method the scene cannot use).
pub fn solve(scene: &Scene, settings: &SceneSettings, method: Method) -> Result<SceneOutcome, InputError> {
    scene.validate()?;
    match (scene.dimension, method) {
        (2, Method::MaterialPoint(b)) => solve_mpm::<2>(scene, settings, b),
        (3, Method::MaterialPoint(b)) => solve_mpm::<3>(scene, settings, b),
        (2, Method::FEM_Q4) => solve_fem::<2, _>(scene, settings, QuadElement::Q4),
        (2, Method::FEM_Q8) => solve_fem::<2, _>(scene, settings, QuadElement::Q8),
        (3, Method::FEM_HEX8) => solve_fem::<3, _>(scene, settings, HexElement::Hex8),
        (3, Method::FEM_HEX20) => solve_fem::<3, _>(scene, settings, HexElement::Hex20),
        (d, m) => Err(m.unsupported(&format!("a scene in dimension {d}"), methods(d))),
    }
}

/// Stored energy V₀ W of one point: Hencky's in εᵉ (the linear-elastic model and von Mises'
/// elastic part), or the neo-Hookean one in b = exp 2εᵉ and ln J = tr εᵉ.
fn energy(state: &PointState, volume0: f64, young: f64, poisson: f64, neo_hookean: bool) -> f64 {
    let (lambda, mu) = crate::material::constitutive::lame(young, poisson);
    let e = &state.material.eps_e;
    let w = if neo_hookean {
        let (l, _) = crate::material::kinematics::sym_eigen(e);
        let tr_b: f64 = l.iter().map(|x| (2.0 * x).exp()).sum();
        let ln_j = e.trace();
        0.5 * mu * (tr_b - 3.0) - mu * ln_j + 0.5 * lambda * ln_j * ln_j
    } else {
        mu * e.component_mul(e).sum() + 0.5 * lambda * e.trace().powi(2)
    };
    volume0 * w
}

/// What the measures read from a solver.
/// A region's reaction along an axis, by the region's name.
pub(super) type RegionReaction<'a> = &'a dyn Fn(&str, usize) -> Option<f64>;

pub(super) struct Probe<'a> {
    pub displacement: &'a dyn Fn(&[f64], usize, bool) -> f64,
    /// The reaction at (node, axis).
    pub reaction: &'a dyn Fn(usize, usize) -> f64,
    /// A region's reaction along an axis, where only the regions' sums are known (a case
    /// solved by another code); `None`: summed from `reaction`.
    pub region_reaction: Option<RegionReaction<'a>>,
    /// Calls its argument with every integration point's initial position, initial volume
    /// and committed state.
    pub points: PointVisitor<'a>,
}

/// Calls its argument with each integration point's X₀, current x, V₀ and state.
pub(super) type PointVisitor<'a> = &'a dyn Fn(PointSink<'_>);

/// What a [`PointVisitor`] calls with X₀, x, V₀ and the state of each point.
pub(super) type PointSink<'a> = &'a mut dyn FnMut(&[f64], &[f64], f64, &PointState);

/// The Cauchy stress component `m.component` (`xx`, `yy`, `xy`, …) along the segment from
/// `m.at` to `m.to` in the current configuration, at `m.samples` equally spaced points: at
/// each, the stress of the integration point whose current position is nearest.
pub(super) fn stress_line(scene: &Scene, m: &super::spec::Measure, points: PointVisitor<'_>) -> Vec<f64> {
    let (Some(a), Some(b), Some(c)) = (m.at.as_ref(), m.to.as_ref(), m.component.as_ref()) else {
        return vec![];
    };
    let Some((i, j)) = super::measures::stress_component(c, scene.dimension) else {
        return vec![];
    };
    let n = m.samples.unwrap_or(2).max(2);
    let targets: Vec<Vec<f64>> = (0..n)
        .map(|k| {
            let t = k as f64 / (n - 1) as f64;
            a.iter().zip(b).map(|(p, q)| p + t * (q - p)).collect()
        })
        .collect();
    let mut best = vec![(f64::INFINITY, f64::NAN); n];
    points(&mut |_, x, _, state| {
        for (k, y) in targets.iter().enumerate() {
            let d: f64 = x.iter().zip(y).map(|(u, v)| (u - v) * (u - v)).sum();
            if d < best[k].0 {
                best[k] = (d, state.cauchy()[(i, j)]);
            }
        }
    });
    best.into_iter().map(|b| b.1).collect()
}

/// Every material point's X₀, x, V₀ and state, to `f`.
fn visit_points<const D: usize>(pts: &crate::mpm::particles::MaterialPoints<D>, f: PointSink<'_>) {
    for p in 0..pts.len() {
        f(
            pts.position0[p].as_slice(),
            pts.position[p].as_slice(),
            pts.volume0[p],
            &pts.state[p],
        );
    }
}

/// Every Gauss point's X₀, x, V₀ and state, to `f`.
fn visit_gauss<const D: usize, E: ElementFamily<D>>(fem: &ContinuumFem<D, E>, f: PointSink<'_>) {
    let g = &fem.gauss;
    for q in 0..g.len() {
        let x = fem.gauss_point_position(q);
        f(g.position0[q].as_slice(), x.as_slice(), g.volume0[q], &g.state[q]);
    }
}

/// Eq (46) of the column, for a body under one gravity load along an axis: Σ_p |σ_aa,p −
/// σ(Z_p)| V₀_p / (ρ g V L) with σ(Z) = −ρ g (L − Z) (eq 42, equilibrium alone), Z the height
/// above the body's base along the gravity's axis a, L the body's height and V its volume;
/// in one dimension V = L and this is the column kind's measure.
fn column_stress_error(scene: &Scene, points: PointVisitor<'_>) -> f64 {
    let Some((axis, g)) = super::spec::column_axis(scene) else {
        return f64::NAN;
    };
    let body = &scene.bodies[0];
    let bb = body.bounding_box();
    let (base, length) = (bb.min[axis], bb.max[axis] - bb.min[axis]);
    let unit_weight = body.density * g;
    let (mut sum, mut volume) = (0.0, 0.0);
    points(&mut |x0, _, v0, state| {
        let exact = -unit_weight * (length - (x0[axis] - base));
        sum += (state.cauchy()[(axis, axis)] - exact).abs() * v0;
        volume += v0;
    });
    sum / (unit_weight * volume * length)
}

/// One measure read after a step: its value and, for a stress line, its samples (the value
/// is their mean).
#[derive(Debug, Clone)]
pub(super) struct Reading {
    value: f64,
    profile: Vec<f64>,
}

/// Every measure of `scene` from `probe`, with the region dofs `named`.
pub(super) fn read_measures(scene: &Scene, named: &NamedDofs, probe: &Probe<'_>) -> Vec<Reading> {
    let value = |value: f64| Reading {
        value,
        profile: vec![],
    };
    scene
        .measures
        .iter()
        .map(|m| {
            let axis = m
                .component
                .as_ref()
                .and_then(|c| axis_index("", c, scene.dimension).ok())
                .unwrap_or(0);
            let reading =
                match m.kind {
                    MeasureKind::Displacement | MeasureKind::FactorOfSafety if m.at.is_some() => value(
                        (probe.displacement)(m.at.as_deref().unwrap_or(&[]), axis, m.domain_edge),
                    ),
                    MeasureKind::Reaction if probe.region_reaction.is_some() => {
                        let region = m.region.as_deref().unwrap_or("");
                        value(
                            probe
                                .region_reaction
                                .and_then(|r| r(region, axis))
                                .unwrap_or(f64::NAN),
                        )
                    }
                    MeasureKind::Reaction => {
                        let dofs = named
                            .iter()
                            .find(|n| Some(&n.0) == m.region.as_ref())
                            .map_or(&[][..], |n| &n.1[..]);
                        value(
                            dofs.iter()
                                .filter(|d| d.1 == axis)
                                .map(|&(n, a)| (probe.reaction)(n, a))
                                .sum(),
                        )
                    }
                    MeasureKind::StrainEnergy => {
                        let (e, nu) = scene.hencky_parameters("").unwrap_or((f64::NAN, f64::NAN));
                        let neo = scene.materials[&scene.bodies[0].material].model() == "neo-hookean";
                        let mut sum = 0.0;
                        (probe.points)(&mut |_, _, v0, state| sum += energy(state, v0, e, nu, neo));
                        value(sum)
                    }
                    MeasureKind::ColumnStressError => value(column_stress_error(scene, probe.points)),
                    // Known only when the run ends ([`with_factor_of_safety`]); read meanwhile:
                    // the displacement its limit watches, if it has one.
                    MeasureKind::Displacement | MeasureKind::FactorOfSafety => value(f64::NAN),
                    MeasureKind::StressLine => {
                        let profile = stress_line(scene, m, probe.points);
                        Reading {
                            value: profile.iter().sum::<f64>() / profile.len().max(1) as f64,
                            profile,
                        }
                    }
                };
            scaled(m.scale, reading)
        })
        .collect()
}

/// `measures` with their factors of safety ([`Scene::factor_of_safety`]) from the run's
/// `failure` and each one's readings after every step (`history`, of `load_steps` steps).
fn with_factor_of_safety(
    scene: &Scene,
    mut measures: Vec<MeasureValue>,
    history: &[Vec<Reading>],
    load_steps: usize,
    failure: Option<&SolveError>,
) -> Vec<MeasureValue> {
    for (k, (m, v)) in scene.measures.iter().zip(&mut measures).enumerate() {
        if m.kind == MeasureKind::FactorOfSafety {
            let moved: Vec<f64> = history.iter().map(|h| h[k].value).collect();
            let limit = m.limit.map(|l| (l, &moved[..]));
            v.value = scene.factor_of_safety(failure, limit, load_steps);
        }
    }
    measures
}

/// `reading` multiplied by `scale` (none: 1, the reading itself).
fn scaled(scale: Option<f64>, mut reading: Reading) -> Reading {
    if let Some(s) = scale {
        reading.value *= s;
        reading.profile.iter_mut().for_each(|v| *v *= s);
    }
    reading
}

/// The measures after the run, from the readings after each converged step: the final
/// values (and stress-line samples) are the last step's, or `unloaded`'s when no step
/// converged, never those of a failed attempt (its reactions would be the failed iterate's).
pub(super) fn gather(
    scene: &Scene,
    history: &[Vec<Reading>],
    unloaded: impl FnOnce() -> Vec<Reading>,
) -> Vec<MeasureValue> {
    let last = history.last().cloned().unwrap_or_else(unloaded);
    scene
        .measures
        .iter()
        .zip(last)
        .enumerate()
        .map(|(k, (m, last))| MeasureValue {
            name: m.name.clone(),
            value: last.value,
            history: if m.history {
                history.iter().map(|h| h[k].value).collect()
            } else {
                vec![]
            },
            profile: last.profile,
        })
        .collect()
}

fn pad<const D: usize>(v: &SVector<f64, D>) -> [f64; 3] {
    std::array::from_fn(|a| if a < D { v[a] } else { 0.0 })
}

fn solve_mpm<const D: usize>(
    scene: &Scene,
    s: &SceneSettings,
    basis: Basis,
) -> Result<SceneOutcome, InputError> {
    let discrete = super::discrete::DiscreteScene::of(scene, s)?;
    let named = discrete.named_dofs();
    let mut solver = discrete.solver::<D>(basis, s)?;
    solver.set_pressure_projection(s.f_bar && s.pressure_projection);
    let measure = |solver: &MpmSolver<D>| {
        let pts = &solver.points;
        let displacement = |at: &[f64], axis: usize, edge: bool| {
            let at = SVector::<f64, D>::from_iterator(at.iter().copied());
            let p = (0..pts.len())
                .min_by(|&a, &b| {
                    (pts.position0[a] - at)
                        .norm_squared()
                        .total_cmp(&(pts.position0[b] - at).norm_squared())
                })
                .expect("points");
            let grow = if edge {
                (pts.half_length[p][axis] - pts.half_length0[p][axis])
                    * (at[axis] - pts.position0[p][axis]).signum()
            } else {
                0.0
            };
            pts.displacement(p)[axis] + grow
        };
        let reaction = |n: usize, a: usize| solver.reaction(n, a);
        let sums = super::discrete::region_reactions(&discrete, solver);
        let region_reaction = |name: &str, a: usize| sums.get(name).and_then(|r| r.get(a).copied());
        let points = |f: PointSink<'_>| visit_points(pts, f);
        read_measures(
            scene,
            &named,
            &Probe {
                displacement: &displacement,
                reaction: &reaction,
                region_reaction: Some(&region_reaction),
                points: &points,
            },
        )
    };
    let mut history = vec![];
    let run = solver.run_observed(&mut |solver, _| history.push(measure(solver)));
    let (steps, failure) = steps_and_failure(run);
    let measures = with_factor_of_safety(
        scene,
        gather(scene, &history, || measure(&solver)),
        &history,
        s.load_steps,
        failure.as_ref(),
    );
    let pts = &solver.points;
    let points = (0..pts.len())
        .map(|p| PointRecord {
            x0: pad(&pts.position0[p]),
            x: pad(&pts.position[p]),
            half0: pad(&pts.half_length0[p]),
            half: pad(&pts.half_length[p]),
            sigma: pts.state[p].cauchy()[(D - 1, D - 1)],
        })
        .collect();
    Ok(SceneOutcome {
        collapsed: scene.collapsed(failure.as_ref()),
        steps,
        failure,
        measures,
        size: pts.len(),
        points,
    })
}

fn solve_fem<const D: usize, E: ElementFamily<D>>(
    scene: &Scene,
    s: &SceneSettings,
    element: E,
) -> Result<SceneOutcome, InputError> {
    let h = s.element_size;
    let mesh = body_mesh::<D, E>(scene, h, element)?;
    let body = &scene.bodies[0];
    let named = region_dofs(scene, h, &|f| {
        for (k, x) in mesh.nodes.iter().enumerate() {
            f(k, x.as_slice())
        }
    })?;
    // One body (the mesh's): its density is every Gauss point's.
    let (g, tabled) = gravity_split::<D>(&gravity_loads(scene), body.density);
    let fixed = fixed_dofs(&named);
    let model = scene.materials[&body.material].build()?;
    let settings = PlaneFemSettings {
        gauss_points: s.gauss_points,
        newton: s.newton,
        load_steps: s.load_steps,
        // F-bar's tangent is unsymmetric whatever the model (item 69).
        linear_solver: crate::fem::comparator_solver(
            s.linear_solver,
            model.tangent_is_symmetric() && !s.f_bar,
        ),
        f_bar: s.f_bar,
    };
    let loads = FemLoads {
        gravity: g,
        nodal_forces: traction_nodal_forces(scene, &mesh, h)?,
    };
    let mut fem = ContinuumFem::try_new(mesh, body.density, model, fixed, loads, settings)?;
    if let Some(t) = &body.initial_stress {
        let last: Vec<f64> = fem.gauss.position0.iter().map(|x| x[D - 1]).collect();
        let mut states = fem.gauss.state.clone();
        super::initial_stress::start_in("bodies[0].initial_stress", t, fem.model(), &mut states, &last)?;
        fem.gauss.state = states;
    }
    fem.set_pressure_projection(s.f_bar && s.pressure_projection);
    fem.set_nodal_force_ramp(super::build::traction_ramp(scene));
    fem.set_strength_reduction(scene.strength_reduction()?);
    if let Some(b) = tabled {
        fem.set_body_force(b);
    }
    for (values, ramp) in prescribed(&named) {
        fem.prescribe(values, ramp.clone())?;
    }
    let measure = |fem: &ContinuumFem<D, E>| {
        let displacement = |at: &[f64], axis: usize, _edge: bool| {
            let node = fem
                .mesh0
                .nearest_node(SVector::<f64, D>::from_iterator(at.iter().copied()));
            fem.displacement(node)[axis]
        };
        let reaction = |n: usize, a: usize| fem.reaction(n, a);
        let points = |f: PointSink<'_>| visit_gauss(fem, f);
        read_measures(
            scene,
            &named,
            &Probe {
                displacement: &displacement,
                reaction: &reaction,
                region_reaction: None,
                points: &points,
            },
        )
    };
    let mut history = vec![];
    let run = fem.run_observed(&mut |fem, _| history.push(measure(fem)));
    let (steps, failure) = steps_and_failure(run);
    Ok(SceneOutcome {
        collapsed: scene.collapsed(failure.as_ref()),
        measures: with_factor_of_safety(
            scene,
            gather(scene, &history, || measure(&fem)),
            &history,
            s.load_steps,
            failure.as_ref(),
        ),
        steps,
        failure,
        size: fem.mesh.num_elements(),
        points: vec![],
    })
}
