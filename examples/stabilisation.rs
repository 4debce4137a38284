//! Stabilisation probe: `cargo run --release --example stabilisation -- <compaction|cantilever> [args]`.
//! Prints the measure of each problem for one treatment per line, for quick sensitivity runs
//! outside the studies (which record the same sweeps in results.json).
//!
//! compaction: h ppc treatment [yield]   (treatment: none | tie | ghost:<gamma>[:all])
//! cantilever: treatment [update]        (update: stretch | f-diagonal)
use igimp::discretise::ghost::{GhostFaces, GhostSettings};
use igimp::material::constitutive::Material;
use igimp::mpm::{DomainUpdate, WeakNodeTreatment};
use igimp::problems::{cantilever, compaction};

fn treatment(s: &str) -> (f64, WeakNodeTreatment, GhostSettings) {
    let mut g = GhostSettings::default();
    match s {
        "none" => (0.0, WeakNodeTreatment::Tie, g),
        "tie" => (2e-2, WeakNodeTreatment::Tie, g),
        "fix" => (2e-2, WeakNodeTreatment::Fix, g),
        _ => {
            let parts: Vec<&str> = s.split(':').collect();
            assert_eq!(
                parts[0], "ghost",
                "treatment: none | tie | fix | ghost:<gamma>[:all]"
            );
            g.gamma = parts[1].parse().expect("gamma");
            if parts.get(2) == Some(&"all") {
                g.faces = GhostFaces::All;
            }
            (0.0, WeakNodeTreatment::Tie, g)
        }
    }
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let t = std::time::Instant::now();
    match args.first().map(String::as_str) {
        Some("compaction") => {
            let (tol, tr, ghost) = treatment(&args[3]);
            let spec = compaction::CompactionSpec {
                element_size: args[1].parse().unwrap(),
                points_per_cell: args[2].parse().unwrap(),
                material: match args.get(4).and_then(|s| s.parse().ok()) {
                    Some(yield_stress) => Material::von_mises(1e5, 0.3, yield_stress),
                    None => Material::linear_elastic(1e5, 0.3),
                },
                weak_node_tolerance: tol,
                weak_node_treatment: tr,
                ghost,
                linear_solver: igimp::solver::linear::LinearSolver::Ldlt,
                ..Default::default()
            };
            let o = compaction::solve_mpm(&spec).unwrap();
            if std::env::var("DUMP").is_ok() {
                for (p, r) in o.points.iter().enumerate() {
                    println!(
                        "{p} x0 {:?} x {:.4?} half {:.4?} syy {:.1} pm {:.4}",
                        r.x0, r.x, r.half, r.sigma_yy, r.plastic_multiplier
                    );
                }
            }
            let cuts: usize = o.steps.iter().map(|s| s.cutbacks()).sum();
            let its: usize = o.steps.iter().map(|s| s.newton.iterations()).sum();
            println!(
                "compaction h={} ppc={} {}: umax {:.6} steps {} cutbacks {cuts} its {its} fail {:?} {:.1}s",
                args[1],
                args[2],
                args[3],
                o.max_horizontal_displacement,
                o.steps.len(),
                o.failure
                    .map(|f| f.to_string().chars().take(160).collect::<String>()),
                t.elapsed().as_secs_f64()
            );
        }
        Some("cantilever") => {
            let (tol, tr, ghost) = treatment(&args[1]);
            let spec = cantilever::CantileverSpec {
                weak_node_tolerance: tol,
                weak_node_treatment: tr,
                ghost,
                domain_update: if args.get(2).map(String::as_str) == Some("f-diagonal") {
                    DomainUpdate::FDiagonal
                } else {
                    DomainUpdate::Stretch
                },
                element_size: args.get(3).and_then(|s| s.parse().ok()).unwrap_or(0.5),
                ..Default::default()
            };
            let o = cantilever::solve_mpm(&spec, 1000).unwrap();
            let e = o.end.last().unwrap();
            // Points one cell back from the loaded end (not loaded): the displacement of the
            // beam away from the concentrated load.
            let (s0, s1) = (&o.snapshots[0].domains, &o.snapshots.last().unwrap().domains);
            let back: Vec<usize> = (0..s0.len())
                .filter(|&p| (s0[p][0] - (spec.length - 0.5 - s0[p][2])).abs() < 1e-9)
                .collect();
            let (mut bu, mut bv) = (0.0, 0.0);
            for &p in &back {
                bu += (s1[p][0] - s0[p][0]) / spec.length / back.len() as f64;
                bv += (s1[p][1] - s0[p][1]) / spec.length / back.len() as f64;
            }
            println!(
                "  section at L - h: u/L {bu:.5} v/L {bv:.5} ({} points)",
                back.len()
            );
            // Length of the beam axis: the polyline through the mean final position of each
            // column of points (same x0), against its initial length.
            let mut cols: std::collections::BTreeMap<i64, (f64, f64, f64, usize)> = Default::default();
            for p in 0..s0.len() {
                let key = (s0[p][0] * 1e6).round() as i64;
                let e = cols.entry(key).or_insert((s0[p][0], 0.0, 0.0, 0));
                e.1 += s1[p][0];
                e.2 += s1[p][1];
                e.3 += 1;
            }
            let pts: Vec<(f64, f64, f64)> = cols
                .values()
                .map(|&(x0, sx, sy, n)| (x0, sx / n as f64, sy / n as f64))
                .collect();
            let len: f64 = pts
                .windows(2)
                .map(|w| ((w[1].1 - w[0].1).powi(2) + (w[1].2 - w[0].2).powi(2)).sqrt())
                .sum();
            let len0 = pts.last().unwrap().0 - pts[0].0;
            println!(
                "  axis length {len:.5} of {len0:.5} (strain {:.4} %)",
                100.0 * (len / len0 - 1.0)
            );
            if std::env::var("AXIS").is_ok() {
                for w in pts.windows(2).step_by(3) {
                    let ang = (w[1].2 - w[0].2).atan2(w[1].1 - w[0].1);
                    println!(
                        "    x0 {:.3}: x {:.4} y {:.4} angle {:.4}",
                        w[0].0, w[0].1, w[0].2, ang
                    );
                }
            }
            let cuts: usize = o.steps.iter().map(|s| s.cutbacks()).sum();
            println!(
                "cantilever h={} {} {:?}: u/L {:.5} v/L {:.5} steps {} cutbacks {cuts} fail {:?} {:.1}s",
                spec.element_size,
                args[1],
                spec.domain_update,
                e.u_over_l,
                e.v_over_l,
                o.steps.len(),
                o.failure
                    .map(|f| f.to_string().chars().take(160).collect::<String>()),
                t.elapsed().as_secs_f64()
            );
        }
        _ => {
            eprintln!(
                "usage: stabilisation compaction h ppc treatment [yield] | cantilever treatment [update]"
            );
            std::process::exit(2);
        }
    }
}
