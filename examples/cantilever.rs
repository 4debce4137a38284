//! Cantilever (§5.3): `cargo run --release --example cantilever -- [stretch|f-diagonal]`
use igimp::mpm::DomainUpdate;
use igimp::problems::cantilever::{solve_mpm, CantileverSpec};

fn main() {
    let update = match std::env::args().nth(1).as_deref() {
        Some("f-diagonal") => DomainUpdate::FDiagonal,
        _ => DomainUpdate::Stretch,
    };
    let volume_update = match std::env::args().nth(2).as_deref() {
        Some("domain") => igimp::mpm::VolumeUpdate::DomainProduct,
        _ => igimp::mpm::VolumeUpdate::Jacobian,
    };
    let spec = CantileverSpec {
        domain_update: update,
        volume_update,
        ..CantileverSpec::default()
    };
    let t = std::time::Instant::now();
    let o = solve_mpm(&spec, 10).unwrap();
    for e in o.end.iter().step_by(5) {
        println!(
            "step {:2}: P = {:8.0}, u/L = {:.5}, v/L = {:.5}, min half-length {:.4}",
            e.step,
            e.load,
            e.u_over_l,
            e.v_over_l,
            o.min_half_length[e.step - 1]
        );
    }
    if let Some(e) = o.end.last() {
        println!(
            "final step {}: u/L = {:.5}, v/L = {:.5}",
            e.step, e.u_over_l, e.v_over_l
        );
    }
    println!(
        "failure: {:?}; {:.2} s; iterations {:?}",
        o.failure
            .map(|f| f.to_string().chars().take(300).collect::<String>()),
        t.elapsed().as_secs_f64(),
        o.steps.iter().map(|s| s.newton.iterations()).collect::<Vec<_>>()
    );
}
