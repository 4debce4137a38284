//! Time per Newton iteration of the small cases a sweep is made of: the plane-strain
//! compaction (§5.2, 40 load steps) at h = 1/4 and 1/8 with `mpm` and iGIMP, one thread,
//! by phase. `cargo bench --bench small_cases [-- N...]` (h = 1/N; default 4 and 8);
//! `BASIS=mpm|igimp` runs one method, `REPEATS` (default 3) runs each case that many times.
//! The Kratos side of the peer comparison is `benches/peers/kratos_compaction.sh`, which runs
//! this bench interleaved with Kratos.

use igimp::basis::Basis;
use igimp::problems::compaction::CompactionSpec;
use igimp::solver::load_stepping::LoadStepping;
use igimp::solver::profile::CasePool;

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
                println!(
                    "compaction,{},{h},{n},{its},{:.3},{:.2},{:.3},{:.3},{:.3},{:.3},{:.3},{:.3},{failure}",
                    basis.method_name(),
                    cost.seconds,
                    1e3 * cost.seconds / its as f64,
                    cost.weights,
                    cost.constitutive,
                    cost.assembly,
                    cost.setup,
                    cost.solve,
                    cost.other()
                );
            }
        }
    }
}
