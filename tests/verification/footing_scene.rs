//! The small strip footing bound to its points, shared by the point-penalty checks
//! (`point_penalty.rs`) and the seeded-bug test (`tests/seeded.rs`), so that a seeded bug
//! meets the very check it is seeded against.
#![allow(dead_code)]

use igimp::basis::Basis;
use igimp::discretise::ghost::GhostSettings;
use igimp::material::constitutive::Material;
use igimp::problems::scene::{DiscreteScene, Scene, SceneSettings};
use igimp::solver::newton::{NewtonSettings, ResidualNorm};

use crate::common;
use crate::scene_text::scene;

/// A 3 × 2 block on a fixed base between two rollers, the left third of its top pressed down
/// by `delta` through the points under it (a strip footing's half model), with `extra` keys on
/// the load.
pub fn footing(material: Material, delta: f64, extra: &str) -> Scene {
    let text = format!(
        r#"
grid = {{ origin = [0.0, 0.0], extent = [3.0, 3.0] }}
bodies = [{{ name = "soil", box = {{ min = [0.0, 0.0], max = [3.0, 2.0] }}, material = "m" }}]
supports = [
  {{ name = "symmetry", plane = {{ axis = "x", at = 0.0 }}, fix = ["x"] }},
  {{ name = "far", plane = {{ axis = "x", at = 3.0 }}, fix = ["x"] }},
  {{ name = "base", plane = {{ axis = "y", at = 0.0 }}, fix = ["x", "y"] }},
]
loads = [{{ kind = "displacement", name = "footing", box = {{ min = [0.0, 2.0], max = [1.0, 2.0] }}, displacement = {{ y = {delta:?} }}, on = "points"{extra} }}]
measures = [
  {{ name = "footing", kind = "reaction", region = "footing", component = "y" }},
  {{ name = "base", kind = "reaction", region = "base", component = "y" }},
]
"#
    );
    scene(2, &text, material)
}

/// h = 1/2, 2 points per cell, `load_steps` steps, F-bar if `f_bar`, a tight Newton.
pub fn settings(load_steps: usize, f_bar: bool) -> SceneSettings {
    SceneSettings {
        element_size: 0.5,
        points_per_cell: 2,
        load_steps,
        newton: NewtonSettings {
            residual_norm: ResidualNorm::Total,
            tolerance: 1e-11,
            max_iterations: 30,
            ..Default::default()
        },
        // GIMP-type domains heave into the empty row above the block (item 69).
        ghost: GhostSettings {
            gamma: 1e-4,
            ..Default::default()
        },
        domain_update: Default::default(),
        linear_solver: Default::default(),
        f_bar,
        pressure_projection: false,
        gauss_points: None,
    }
}

/// The finite-difference error of the tangent of a footing's first step, from its scene.
pub fn penalty_tangent_error(basis: Basis) -> f64 {
    let s = footing(Material::von_mises(1e4, 0.49, 3f64.sqrt()), -0.02, "");
    let d = DiscreteScene::of(&s, &settings(1, false)).unwrap();
    let mut solver = d.solver::<2>(basis, &settings(1, false)).unwrap();
    solver
        .with_step_system(1.0, |sys| common::fd_tangent_errors(sys, 2e-3, 11).0)
        .unwrap()
}

/// The footing pressed down along a ramp whose increments quadruple after the second step
/// (0.1, 0.1, 0.4, 0.4 of the settlement): an extrapolated start must scale the last increment
/// by the ratio of the loads, not repeat it.
pub fn quadrupling_footing(material: Material, delta: f64) -> Scene {
    footing(
        material,
        delta,
        r#", ramp = { table = [[0.0, 0.0], [0.5, 0.2], [1.0, 1.0]] }"#,
    )
}

/// The elastic quadrupling footing (δ = 0.5 % of the block) in 4 steps from a zero and from an
/// extrapolated start (reference/README.md item 82): each run's first residual per step and
/// Newton iterations, and its footing force.
pub fn zero_and_extrapolated(method: igimp::basis::method::Method) -> [(Vec<f64>, usize, f64); 2] {
    use igimp::solver::newton::Predictor;
    let s = quadrupling_footing(Material::linear_elastic(1e4, 0.3), -0.01);
    [Predictor::Zero, Predictor::Extrapolated].map(|p| {
        let mut set = settings(4, false);
        set.newton.predictor = p;
        let o = igimp::problems::scene::solve(&s, &set, method).unwrap();
        assert!(o.failure.is_none(), "{method:?} {p:?}: {:?}", o.failure);
        let first = o.steps.iter().map(|s| s.newton.residuals[0]).collect();
        let iterations = o.steps.iter().map(|s| s.newton.residuals.len() - 1).sum();
        (first, iterations, o.measures[0].value)
    })
}

/// The largest ratio, over the steps after the first, of the extrapolated start's residual to
/// the zero start's on the elastic quadrupling footing.
pub fn extrapolated_start_ratio(method: igimp::basis::method::Method) -> f64 {
    let [(z, _, _), (e, _, _)] = zero_and_extrapolated(method);
    (1..z.len()).map(|k| e[k] / z[k]).fold(0.0, f64::max)
}
