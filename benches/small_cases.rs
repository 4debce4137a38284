//! Time per Newton iteration of the small cases a sweep is made of: the plane-strain
//! compaction (§5.2, 40 load steps) at h = 1/4 and 1/8 with `mpm` and iGIMP, one thread,
//! by phase. `cargo bench --bench small_cases [-- N...]` (h = 1/N; default 4 and 8);
//! `BASIS=mpm|igimp` runs one method, `REPEATS` (default 3) runs each case that many times.
//! The Kratos side of the peer comparison is `benches/peers/kratos_compaction.sh`, which runs
//! this bench interleaved with Kratos. Each compaction run is followed by the same case
//! through the scene path (`studies/scene-compaction.toml` with the same 40 steps and Newton
//! settings, rows `scene-compaction`): its cost against the built-in problem's (issue 48 asks
//! for 5 %), and its answer, which must be equal.

use igimp::basis::method::Method;
use igimp::basis::Basis;
use igimp::problems::compaction::CompactionSpec;
use igimp::problems::scene::{self, SceneSettings};
use igimp::solver::load_stepping::LoadStepping;
use igimp::solver::profile::CasePool;
use igimp::study::engine::StudyKind;
use igimp::study::scene::SceneStudy;

fn main() {
    let sizes: Vec<f64> = std::env::args()
        .skip(1)
        .filter_map(|a| a.parse::<f64>().ok())
        .map(|d| if d > 1.0 { 1.0 / d } else { d })
        .collect();
    let sizes = if sizes.is_empty() {
        vec![0.25, 0.125]
    } else {
        sizes
    };
    let repeats = std::env::var("REPEATS")
        .ok()
        .and_then(|r| r.parse().ok())
        .unwrap_or(3usize);
    let pool = CasePool::new(1);
    let study = SceneStudy::load(std::path::Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/studies/scene-compaction.toml"
    )))
    .expect("the scene-compaction study");
    let scene = study.scene();
    println!("case,basis,h,unknowns_last,newton_iterations,seconds,ms_per_iteration,weights,constitutive,assembly,setup,solve,other,failure");
    for &h in &sizes {
        let bases: Vec<Basis> = match std::env::var("BASIS").as_deref() {
            Ok("mpm") => vec![Basis::Mpm],
            Ok("igimp") => vec![Basis::Gimp],
            _ => vec![Basis::Mpm, Basis::Gimp],
        };
        for &basis in &bases {
            for _ in 0..repeats {
                let spec = CompactionSpec {
                    element_size: h,
                    load_steps: 40,
                    basis,
                    ..CompactionSpec::default()
                };
                let (out, cost) = pool.run(|| {
                    let mut solver = spec.mpm_solver().expect("valid compaction");
                    let (reports, failure) = match solver.run() {
                        Ok(r) => (r, String::new()),
                        Err(f) => (
                            f.steps.clone(),
                            format!("step {}: {}", f.steps.len() + 1, f.error),
                        ),
                    };
                    let its: usize = reports.iter().map(|s| s.newton.iterations()).sum();
                    (its, solver.system_size().0, failure)
                });
                let (its, n, failure) = out;
                let line = |case: &str,
                            its: usize,
                            n: usize,
                            cost: &igimp::solver::profile::CaseCost,
                            failure: &str| {
                    println!(
                        "{case},{},{h},{n},{its},{:.3},{:.2},{:.3},{:.3},{:.3},{:.3},{:.3},{:.3},{failure}",
                        basis.method_name(),
                        cost.seconds,
                        1e3 * cost.seconds / its as f64,
                        cost.weights,
                        cost.constitutive,
                        cost.assembly,
                        cost.setup,
                        cost.solve,
                        cost.other()
                    )
                };
                line("compaction", its, n, &cost, &failure);
                let settings = SceneSettings {
                    element_size: h,
                    points_per_cell: spec.points_per_cell,
                    load_steps: spec.load_steps,
                    newton: spec.newton,
                    ghost: spec.ghost,
                    domain_update: spec.domain_update,
                    linear_solver: spec.linear_solver,
                    f_bar: false,
                    pressure_projection: false,
                    gauss_points: None,
                };
                let (o, cost) = pool.run(|| {
                    scene::solve(&scene, &settings, Method::MaterialPoint(basis)).expect("valid scene")
                });
                let its: usize = o.steps.iter().map(|s| s.newton.iterations()).sum();
                let failure = o.failure.as_ref().map_or(String::new(), |f| f.to_string());
                let n = o.steps.last().map_or(0, |s| s.linear.unknowns);
                line("scene-compaction", its, n, &cost, &failure);
            }
        }
    }
}
