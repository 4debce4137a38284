//! F-bar's cost per Newton iteration against the plain method's (issue 50: at most 1.5×):
//! the residual (with its patch averages) and the tangent (with its patch blocks) of
//! - `footing_2d`: the strip footing of `studies/footing.toml` at h = B/32 (61,440 points),
//!   MPM and iGIMP, at a settlement increment of the first step;
//! - `compaction_3d`: the 3D quarter block at h = 0.2 (128,000 points), iGIMP, elastic, at a
//!   tenth of its load.
//!
//! `cargo bench --bench fbar` (reference/README.md item 69 has the figures).

use criterion::{criterion_group, criterion_main, Criterion};
use igimp::basis::Basis;
use igimp::material::constitutive::Material;
use igimp::problems::compaction::CompactionSpec;
use igimp::problems::scene::{self, DiscreteScene, SceneSettings};
use igimp::solver::newton::NonlinearSystem;
use std::hint::black_box;

#[path = "../tests/verification/scene_text.rs"]
mod scene_text;

fn footing() -> scene::Scene {
    scene_text::scene(
        2,
        r#"
grid = { origin = [0.0, 0.0], extent = [5.0, 4.0] }
bodies = [{ name = "soil", box = { min = [0.0, 0.0], max = [5.0, 3.0] }, material = "m" }]
supports = [
  { name = "symmetry", plane = { axis = "x", at = 0.0 }, fix = ["x"] },
  { name = "far", plane = { axis = "x", at = 5.0 }, fix = ["x"] },
  { name = "base", plane = { axis = "y", at = 0.0 }, fix = ["x", "y"] },
]
loads = [{ kind = "displacement", name = "footing", box = { min = [0.0, 3.0], max = [0.5, 3.0] }, displacement = { y = -0.02 } }]
"#,
        Material::von_mises(1e4, 0.49, 3f64.sqrt()),
    )
}

/// Residual and tangent of `sys` at the increment `u`, each as one benchmark.
fn bench_system<const D: usize>(
    c: &mut Criterion,
    label: &str,
    sys: &mut igimp::discretise::assembly::LoadStepSystem<'_, D>,
) {
    let n = sys.num_unknowns();
    let u: Vec<f64> = (0..n).map(|i| 1e-5 * (i as f64 * 0.7).sin()).collect();
    let mut r = vec![0.0; n];
    c.bench_function(&format!("{label}/residual"), |b| {
        b.iter(|| sys.evaluate(black_box(&u), &mut r).unwrap())
    });
    sys.evaluate(&u, &mut r).unwrap();
    c.bench_function(&format!("{label}/tangent"), |b| b.iter(|| sys.assemble_tangent()));
}

fn footing_2d(c: &mut Criterion) {
    let scene = footing();
    for basis in [Basis::Mpm, Basis::Gimp] {
        for f_bar in [false, true] {
            let settings = SceneSettings {
                element_size: 1.0 / 32.0,
                points_per_cell: 2,
                load_steps: 20,
                newton: Default::default(),
                ghost: Default::default(),
                domain_update: Default::default(),
                linear_solver: Default::default(),
                f_bar,
                pressure_projection: false,
                gauss_points: None,
            };
            let discrete = DiscreteScene::of(&scene, &settings).unwrap();
            let mut solver = discrete.solver::<2>(basis, &settings).unwrap();
            let label = format!("footing_2d/{basis:?}/{}", if f_bar { "f-bar" } else { "plain" });
            solver
                .with_step_system(0.05, |sys| bench_system(c, &label, sys))
                .unwrap();
        }
    }
}

fn compaction_3d(c: &mut Criterion) {
    for f_bar in [false, true] {
        let spec = CompactionSpec {
            element_size: 0.2,
            dimension: 3,
            f_bar,
            ..Default::default()
        };
        let mut solver = spec.mpm_solver_3d().unwrap();
        let label = format!("compaction_3d/{}", if f_bar { "f-bar" } else { "plain" });
        solver
            .with_step_system(0.1, |sys| bench_system(c, &label, sys))
            .unwrap();
    }
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(10);
    targets = footing_2d, compaction_3d
}
criterion_main!(benches);
