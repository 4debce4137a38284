//! Elastic column of §5.1 with iGIMP and MPM: prints top displacement, base F and errors.
//! `cargo run --release --example column -- [elements] [weight] [yield stress]`
use igimp::material::constitutive::Material;
use igimp::problems::column::{solve_column, ColumnSpec, Method};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let elements = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(256);
    let weight = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(400_000.0);
    let (e, nu) = (1e6, 0.0);
    let material = match args.get(3).and_then(|s| s.parse().ok()) {
        Some(yield_stress) => Material::von_mises(e, nu, yield_stress),
        None => Material::linear_elastic(e, nu),
    };
    let spec = ColumnSpec {
        elements,
        weight,
        material,
        ..ColumnSpec::default()
    };
    let exact = spec.analytical();
    println!(
        "analytical: top displacement {:.6}, base F {:.8}",
        exact.displacement(spec.length),
        exact.deformation_gradient(0.0)
    );
    if let Some(z) = exact.yield_height() {
        println!(
            "analytical yield height {z:.6}, base lateral stress {:.3}",
            exact.lateral_stress(0.0)
        );
    }
    for method in [Method::IGIMP, Method::MPM] {
        let t = std::time::Instant::now();
        match solve_column(&spec, method) {
            Ok(o) => {
                let its: Vec<usize> = o.steps.iter().map(|s| s.newton.iterations()).collect();
                println!(
                    "{:6} elements {elements}: top u {:.6}, base F {:.6}, stress error {:.4e}, F error {:.4e}, failure {:?}, {:.3} s, iterations {:?}",
                    method.name(),
                    o.top_displacement,
                    o.base_f,
                    o.stress_error,
                    o.f_error,
                    o.failure.as_ref().map(|f| f.to_string()),
                    t.elapsed().as_secs_f64(),
                    its
                );
                if let Some(s) = o.steps.last() {
                    println!("  last step residuals {:?}", s.newton.residuals);
                }
            }
            Err(e) => println!("{}: input error {e}", method.name()),
        }
    }
}
