//! Plane-strain compaction (§5.2): `cargo run --release --example compaction -- [h] [ppc] [yield]`
use igimp::material::constitutive::Material;
use igimp::problems::compaction::{solve_mpm, CompactionSpec};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let h = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(1.0);
    let ppc = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(2);
    let (e, nu) = (1e5, 0.3);
    let material = match args.get(3).and_then(|s| s.parse().ok()) {
        Some(yield_stress) => Material::von_mises(e, nu, yield_stress),
        None => Material::linear_elastic(e, nu),
    };
    let line_search = args.get(4).is_some_and(|s| s == "ls");
    let mut spec = CompactionSpec {
        element_size: h,
        points_per_cell: ppc,
        material,
        ..CompactionSpec::default()
    };
    spec.newton.line_search = line_search;
    let t = std::time::Instant::now();
    let o = solve_mpm(&spec).expect("valid input");
    println!(
        "h={h} ppc={ppc}: max horizontal displacement {:.6}, weak nodes {}, failure {:?}, {:.3} s",
        o.max_horizontal_displacement,
        o.weak_nodes_treated,
        o.failure.as_ref().map(|f| f.to_string()),
        t.elapsed().as_secs_f64()
    );
    for s in o.steps.iter().skip(15) {
        let r: Vec<String> = s.newton.residuals.iter().map(|r| format!("{r:.3e}")).collect();
        println!("  step {}: {}", s.step, r.join(" "));
    }
}
