//! F-bar's cost per Newton iteration against the plain method's (issue 50: at most 1.5×),
//! measured in pairs: the plain and the F-bar system of the same step are evaluated one
//! after the other, residual and tangent, 40 times (8 in 3D), and the medians and quartiles
//! of the pairs' ratios are printed. On a shared machine two benchmarks run minutes apart
//! differ by up to 40 % (reference/README.md item 78), a pair run back to back by little.
//! - `footing_2d`: the strip footing of `studies/footing.toml` at h = B/32 (61,440 points),
//!   MPM and iGIMP, at a settlement increment of the first step;
//! - `compaction_3d`: the 3D quarter block at h = 0.2 (128,000 points), iGIMP, elastic, at a
//!   tenth of its load.
//!
//! `cargo bench --bench fbar` (reference/README.md items 69 and 78 have the figures).

use igimp::basis::Basis;
use igimp::discretise::assembly::LoadStepSystem;
use igimp::material::constitutive::Material;
use igimp::problems::compaction::CompactionSpec;
use igimp::problems::scene::{self, DiscreteScene, SceneSettings};
use igimp::solver::newton::NonlinearSystem;
use std::time::Instant;

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

/// The median and quartiles of `v`.
fn quartiles(mut v: Vec<f64>) -> [f64; 3] {
    v.sort_by(f64::total_cmp);
    let at = |f: f64| v[((v.len() - 1) as f64 * f).round() as usize];
    [at(0.25), at(0.5), at(0.75)]
}

/// Seconds of one residual and one tangent of `sys` at `u`.
fn timed<const D: usize>(sys: &mut LoadStepSystem<'_, D>, u: &[f64], r: &mut [f64]) -> (f64, f64) {
    let clock = Instant::now();
    sys.evaluate(u, r).unwrap();
    let residual = clock.elapsed().as_secs_f64();
    let clock = Instant::now();
    sys.assemble_tangent();
    (residual, clock.elapsed().as_secs_f64())
}

/// `pairs` rounds of the plain system `a` and the F-bar system `b` at the same increment,
/// each round residual then tangent of `a`, then of `b`; prints the ratios.
fn pairs<const D: usize>(
    label: &str,
    a: &mut LoadStepSystem<'_, D>,
    b: &mut LoadStepSystem<'_, D>,
    rounds: usize,
) {
    let n = a.num_unknowns();
    let u: Vec<f64> = (0..n).map(|i| 1e-5 * (i as f64 * 0.7).sin()).collect();
    let mut r = vec![0.0; n];
    let (mut whole, mut tangent) = (vec![], vec![]);
    let mut best = [f64::INFINITY; 4];
    for _ in 0..rounds {
        let (r0, t0) = timed(a, &u, &mut r);
        let (r1, t1) = timed(b, &u, &mut r);
        let t = [r0, t0, r1, t1];
        whole.push((t[2] + t[3]) / (t[0] + t[1]));
        tangent.push(t[3] / t[1]);
        for (b, t) in best.iter_mut().zip(t) {
            *b = b.min(t);
        }
    }
    let (w, g) = (quartiles(whole), quartiles(tangent));
    println!(
        "{label}: F-bar / plain per iteration {:.3} (quartiles {:.3}–{:.3}), tangent {:.3} ({:.3}–{:.3}); \
         fastest plain {:.1} + {:.1} ms, F-bar {:.1} + {:.1} ms",
        w[1],
        w[0],
        w[2],
        g[1],
        g[0],
        g[2],
        best[0] * 1e3,
        best[1] * 1e3,
        best[2] * 1e3,
        best[3] * 1e3
    );
}

fn footing_2d() {
    let scene = footing();
    let settings = |f_bar| SceneSettings {
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
    for basis in [Basis::Mpm, Basis::Gimp] {
        let (sp, sf) = (settings(false), settings(true));
        let mut plain = DiscreteScene::of(&scene, &sp)
            .unwrap()
            .solver::<2>(basis, &sp)
            .unwrap();
        let mut f_bar = DiscreteScene::of(&scene, &sf)
            .unwrap()
            .solver::<2>(basis, &sf)
            .unwrap();
        plain
            .with_step_system(0.05, |a| {
                f_bar
                    .with_step_system(0.05, |b| pairs(&format!("footing_2d/{basis:?}"), a, b, 40))
                    .unwrap()
            })
            .unwrap();
    }
}

fn compaction_3d() {
    let solver = |f_bar| {
        CompactionSpec {
            element_size: 0.2,
            dimension: 3,
            f_bar,
            ..Default::default()
        }
        .mpm_solver_3d()
        .unwrap()
    };
    let (mut plain, mut f_bar) = (solver(false), solver(true));
    plain
        .with_step_system(0.1, |a| {
            f_bar
                .with_step_system(0.1, |b| pairs("compaction_3d/Gimp", a, b, 8))
                .unwrap()
        })
        .unwrap();
}

fn main() {
    // `cargo bench` passes `--bench`; any other argument filters by label start.
    let filter: Vec<String> = std::env::args()
        .skip(1)
        .filter(|a| !a.starts_with("--"))
        .collect();
    let wanted = |label: &str| filter.is_empty() || filter.iter().any(|f| label.starts_with(f.as_str()));
    if wanted("footing_2d") {
        footing_2d();
    }
    if wanted("compaction_3d") {
        compaction_3d();
    }
}
