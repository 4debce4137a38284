use igimp::method::Method;
use igimp::problems::manufactured::Field;
use igimp::problems::manufactured_dynamic::{solve_3d, DynamicManufacturedSpec};
fn main() {
    let args: Vec<String> = std::env::args().collect();
    let field = if args[1] == "vortex" {
        Field::Vortex
    } else {
        Field::AxisAligned
    };
    let method = Method::from_name(&args[2]).unwrap();
    let cells: Vec<usize> = args[3].split(',').map(|s| s.parse().unwrap()).collect();
    let spp: Vec<usize> = args[4].split(',').map(|s| s.parse().unwrap()).collect();
    for &c in &cells {
        for &n in &spp {
            let spec = DynamicManufacturedSpec {
                field,
                amplitude: if field == Field::Vortex { 0.6 } else { 0.05 },
                cells: c,
                steps_per_period: n,
                dimension: 3,
                ..Default::default()
            };
            let t0 = std::time::Instant::now();
            let s = solve_3d(&spec, method).unwrap();
            println!(
                "{} c{c} n{n}: {:?} fail {:?} steps {} {:.2}s",
                method.name(),
                s.errors,
                s.failure.as_ref().map(|f| f.to_string()),
                s.steps.len(),
                t0.elapsed().as_secs_f64()
            );
        }
    }
}
