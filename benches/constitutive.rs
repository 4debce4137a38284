//! The constitutive pass of each built-in plasticity model against von Mises' (issue 51: Mohr–
//! Coulomb and Cam-Clay at most 2× von Mises per pass at 1e6 points in 2D):
//! - `residual_2d/<model>`: one residual of a 5 × 3 plane-strain block at h = 1/128 with 2 × 2
//!   points per cell (983,040 points, MPM), at a displacement increment whose strains
//!   (about 1e-3) put every point of the friction and von Mises models past yield (their
//!   strengths are 1e-6 of E) and the compressed half of the Cam-Clay points on its ellipse;
//!   the residual is the kinematics, the stress update and the internal force of every point;
//! - `update_2d/<model>`: the stress update alone over 1e6 such plane-strain trial strains.
//!
//! `cargo bench --bench constitutive` (reference/README.md item 74 has the figures).

use criterion::{criterion_group, criterion_main, Criterion};
use igimp::basis::Basis;
use igimp::material::constitutive::{ConstitutiveModel, Material, MaterialState};
use igimp::problems::scene::{self, DiscreteScene, SceneSettings};
use igimp::solver::newton::NonlinearSystem;
use nalgebra::Matrix3;
use rayon::prelude::*;
use std::hint::black_box;

#[path = "../tests/verification/scene_text.rs"]
mod scene_text;

fn materials() -> Vec<(&'static str, Material)> {
    let friction = |model: &str| {
        Material::new(
            model,
            &[
                ("young_modulus", 1e4),
                ("poisson_ratio", 0.3),
                ("cohesion", 1e-2),
                ("friction_angle", 30.0),
                ("dilatancy_angle", 30.0),
                ("hardening_modulus", 0.0),
            ],
        )
        .unwrap()
    };
    vec![
        ("linear-elastic", Material::linear_elastic(1e4, 0.3)),
        ("von-mises", Material::von_mises(1e4, 0.3, 1e-2)),
        ("drucker-prager", friction("drucker-prager")),
        ("mohr-coulomb", friction("mohr-coulomb")),
        (
            "modified-cam-clay",
            Material::new(
                "modified-cam-clay",
                &[
                    ("shear_modulus", 3000.0),
                    ("swelling_index", 0.02),
                    ("compression_index", 0.1),
                    ("critical_state_slope", 1.2),
                    ("reference_pressure", 100.0),
                    ("preconsolidation_pressure", 100.0),
                ],
            )
            .unwrap(),
        ),
    ]
}

fn block(material: Material) -> scene::Scene {
    scene_text::scene(
        2,
        r#"
grid = { origin = [0.0, 0.0], extent = [5.0, 4.0] }
bodies = [{ name = "soil", box = { min = [0.0, 0.0], max = [5.0, 3.0] }, material = "m" }]
supports = [{ name = "base", plane = { axis = "y", at = 0.0 }, fix = ["x", "y"] }]
loads = [{ kind = "gravity", vector = [0.0, -1.0] }]
"#,
        material,
    )
}

fn residual_2d(c: &mut Criterion) {
    let settings = SceneSettings {
        element_size: 1.0 / 128.0,
        points_per_cell: 2,
        load_steps: 1,
        newton: Default::default(),
        ghost: Default::default(),
        domain_update: Default::default(),
        linear_solver: Default::default(),
        f_bar: false,
        pressure_projection: false,
        gauss_points: None,
    };
    for (name, material) in materials() {
        let discrete = DiscreteScene::of(&block(material), &settings).unwrap();
        let mut solver = discrete.solver::<2>(Basis::Mpm, &settings).unwrap();
        solver
            .with_step_system(1.0, |sys| {
                let n = sys.num_unknowns();
                let u: Vec<f64> = (0..n).map(|i| 1e-5 * (i as f64 * 0.7).sin()).collect();
                let mut r = vec![0.0; n];
                c.bench_function(&format!("residual_2d/{name}"), |b| {
                    b.iter(|| sys.evaluate(black_box(&u), &mut r).unwrap())
                });
            })
            .unwrap();
    }
}

fn update_2d(c: &mut Criterion) {
    // Plane-strain trial strains around a compression of 1e-3, deviatoric parts up to 2e-3.
    let strains: Vec<Matrix3<f64>> = (0..1_000_000)
        .map(|i| {
            let t = i as f64;
            let (a, b, s) = ((t * 0.37).sin(), (t * 0.71).cos(), (t * 0.13).sin());
            Matrix3::new(
                -1e-3 + 2e-3 * a,
                1e-3 * s,
                0.0,
                1e-3 * s,
                -1e-3 + 2e-3 * b,
                0.0,
                0.0,
                0.0,
                0.0,
            )
        })
        .collect();
    for (name, material) in materials() {
        let model: Box<dyn ConstitutiveModel> = material.build().unwrap();
        let mut committed = MaterialState::default();
        committed.initialise(model.as_ref());
        c.bench_function(&format!("update_2d/{name}"), |b| {
            b.iter(|| {
                strains
                    .par_iter()
                    .map(|e| {
                        model
                            .update(black_box(e), &committed)
                            .map_or(0.0, |r| r.tau[(0, 0)])
                    })
                    .sum::<f64>()
            })
        });
    }
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(10);
    targets = residual_2d, update_2d
}
criterion_main!(benches);
