//! The elastic column of §5.1: Newton's quadratic convergence, the iGIMP rows of Table 1,
//! the MPM-vs-GIMP stress error of Figure 8, and input validation.

use igimp::basis::Basis;
use igimp::material::constitutive::Material;
use igimp::problems::column::{f_from_cauchy_stress, solve_column, ColumnSpec, Method};
use igimp::solver::load_stepping::LoadStepping;
use igimp::solver::newton::{check_quadratic, NewtonSettings};

fn table1_spec(elements: usize) -> ColumnSpec {
    ColumnSpec {
        elements,
        weight: 400_000.0,
        ..ColumnSpec::default()
    }
}

/// The analytical column (eqs 42–45) reproduces the paper's printed base F 0.74292 and top
/// displacement −7.3347 (§5.1, text above Table 1).
#[test]
fn analytical_column_matches_paper_values() {
    let exact = table1_spec(256).analytical();
    let f0 = exact.deformation_gradient(0.0);
    assert!((f0 - 0.74292).abs() < 0.5e-5, "base F {f0}");
    assert!((exact.displacement(50.0) + 7.3347).abs() < 0.5e-4);
    // Residual of eq (45) at the computed root.
    assert!((1e6 * f0.ln() / f0 + 400_000.0).abs() < 1e-8);
    assert!((f_from_cauchy_stress(0.0) - 1.0).abs() < 1e-15);
    assert!((f_from_cauchy_stress(0.2) - 1.0).abs() > 0.1);
}

/// Newton converges quadratically on the W = 400,000 column (20 steps and, to see longer
/// histories, one step), for GIMP and MPM. Criterion: once r_k ≤ 1e-3, r_{k+1} ≤ 1.0·r_k²
/// for r_{k+1} above the round-off floor, and an observed order ≥ 1.8 where three such
/// residuals exist. The floor 1e-11 is measured: residuals stagnate at 2e-13 (50 elements)
/// to 5e-12 (256 elements) when iterated past convergence.
#[test]
fn newton_converges_quadratically_on_the_column() {
    let mut ratio_checks = 0;
    let mut order_checks = 0;
    for basis in [Basis::Gimp, Basis::Mpm] {
        for load_steps in [20, 1] {
            let spec = ColumnSpec {
                load_steps,
                newton: NewtonSettings {
                    tolerance: 1e-11,
                    max_iterations: 30,
                    line_search: false,
                    ..Default::default()
                },
                ..table1_spec(256)
            };
            let mut solver = spec.mpm_solver(basis).unwrap();
            let steps = solver.run().unwrap();
            for s in &steps {
                let c = check_quadratic(&s.newton.residuals, 1e-3, 1e-11, 1.0, 1.8)
                    .unwrap_or_else(|e| panic!("{basis:?}, step {}: {e}", s.step));
                ratio_checks += c.ratio_checks;
                order_checks += c.order_checks;
                // A wider window for the order test: from r ≤ 0.1 on, three residuals usually exist.
                let c = check_quadratic(&s.newton.residuals, 0.1, 1e-11, 10.0, 1.8)
                    .unwrap_or_else(|e| panic!("{basis:?}, step {}: {e}", s.step));
                order_checks += c.order_checks;
                assert!(
                    s.newton.iterations() <= 6,
                    "{basis:?} step {}: {:?}",
                    s.step,
                    s.newton.residuals
                );
            }
        }
    }
    // Most pairs straddle the window (r1 ≈ 1.1e-3 > 1e-3) or end below the floor, so the
    // count is small; it only guards against a vacuous pass.
    assert!(
        ratio_checks >= 5,
        "only {ratio_checks} quadratic ratio checks ran"
    );
    assert!(order_checks >= 2, "only {order_checks} observed-order checks ran");
}

/// Table 1, iGIMP rows (W = 400,000, 2 points per element, 20 load steps). Reference: the
/// paper's Table 1. Displacement and base F must match the printed digits to 1 in the last
/// digit. The paper's F errors (4.091e-4, ...) are reproduced when eq (47) uses the printed,
/// rounded base value 0.74292 rather than the exact 0.7429194: against the exact value our
/// errors are 4.099e-4, 2.050e-4, 1.025e-4, 5.12e-5 (see reference/README.md). We assert the
/// paper's numbers in the form that reproduces them, to 1 in the last printed digit.
#[test]
fn paper_table1_igimp_rows() {
    let printed_f = [0.74322, 0.74307, 0.74300, 0.74296];
    let printed_err = [4.091e-4, 2.041e-4, 1.017e-4, 5.040e-5];
    for (k, &n) in [256usize, 512, 1024, 2048].iter().enumerate() {
        let o = solve_column(&table1_spec(n), Method::IGIMP).unwrap();
        assert!(o.failure.is_none(), "{n}: {:?}", o.failure);
        assert!(
            (o.top_displacement + 7.3347).abs() <= 1.5e-4,
            "{n}: top u {}",
            o.top_displacement
        );
        assert!(
            (o.base_f - printed_f[k]).abs() <= 1.5e-5,
            "{n}: base F {} vs {}",
            o.base_f,
            printed_f[k]
        );
        let err_rounded = (o.base_f - 0.74292).abs() / 0.74292;
        let unit = if printed_err[k] < 1e-4 { 1e-8 } else { 1e-7 };
        assert!(
            (err_rounded - printed_err[k]).abs() <= 1.5 * unit,
            "{n}: F error vs 0.74292 = {err_rounded:.4e}, paper {:.4e}",
            printed_err[k]
        );
        eprintln!(
            "{n}: top u {:.6}, base F {:.7}, F error vs exact {:.4e}, vs 0.74292 {err_rounded:.4e}",
            o.top_displacement, o.base_f, o.f_error
        );
    }
}

/// Figure 8 (50 elements, 2 points per element, W = 40,000): MPM's cell-crossing error makes
/// its stress error (eq 46) many times GIMP's. Measured: MPM 3.51e-2, GIMP 1.19e-3 (ratio
/// 29.6); asserted ratio ≥ 10.
#[test]
fn paper_figure8_mpm_stress_error_is_many_times_gimp() {
    let spec = ColumnSpec::default();
    assert_eq!((spec.elements, spec.weight), (50, 40_000.0));
    let gimp = solve_column(&spec, Method::IGIMP).unwrap();
    let mpm = solve_column(&spec, Method::MPM).unwrap();
    assert!(gimp.failure.is_none() && mpm.failure.is_none());
    let ratio = mpm.stress_error / gimp.stress_error;
    assert!(
        ratio >= 10.0,
        "MPM {:.3e} / GIMP {:.3e} = {ratio:.1}",
        mpm.stress_error,
        gimp.stress_error
    );
    assert!(
        gimp.stress_error < 2e-3,
        "GIMP stress error {:.3e}",
        gimp.stress_error
    );
}

/// Bad input is an error naming the field and its allowed range, never a panic or NaN.
#[test]
fn bad_column_input_names_the_field() {
    let cases: Vec<(ColumnSpec, &str)> = vec![
        (
            ColumnSpec {
                material: Material::linear_elastic(0.0, 0.0),
                ..Default::default()
            },
            "young_modulus",
        ),
        (
            ColumnSpec {
                material: Material::linear_elastic(-1.0, 0.0),
                ..Default::default()
            },
            "young_modulus",
        ),
        (
            ColumnSpec {
                material: Material::linear_elastic(f64::NAN, 0.0),
                ..Default::default()
            },
            "young_modulus",
        ),
        (
            ColumnSpec {
                material: Material::linear_elastic(1e6, 0.5),
                ..Default::default()
            },
            "poisson_ratio",
        ),
        (
            ColumnSpec {
                material: Material::linear_elastic(1e6, -1.0),
                ..Default::default()
            },
            "poisson_ratio",
        ),
        (
            ColumnSpec {
                material: Material::linear_elastic(1e6, f64::INFINITY),
                ..Default::default()
            },
            "poisson_ratio",
        ),
        (
            ColumnSpec {
                elements: 0,
                ..Default::default()
            },
            "elements",
        ),
        (
            ColumnSpec {
                points_per_cell: 0,
                ..Default::default()
            },
            "points_per_cell",
        ),
        (
            ColumnSpec {
                load_steps: 0,
                ..Default::default()
            },
            "load_steps",
        ),
        (
            ColumnSpec {
                density: f64::NAN,
                ..Default::default()
            },
            "density",
        ),
        (
            ColumnSpec {
                weight: -5.0,
                ..Default::default()
            },
            "weight",
        ),
        (
            ColumnSpec {
                length: 0.0,
                ..Default::default()
            },
            "length",
        ),
        (
            ColumnSpec {
                newton: NewtonSettings {
                    tolerance: f64::NAN,
                    max_iterations: 5,
                    line_search: false,
                    ..Default::default()
                },
                ..Default::default()
            },
            "newton.tolerance",
        ),
        (
            ColumnSpec {
                newton: NewtonSettings {
                    tolerance: 1e-9,
                    max_iterations: 0,
                    line_search: false,
                    ..Default::default()
                },
                ..Default::default()
            },
            "newton.max_iterations",
        ),
    ];
    for (spec, field) in cases {
        for method in [Method::IGIMP, Method::MPM] {
            let err = solve_column(&spec, method).expect_err(field);
            assert!(err.field.contains(field), "expected field {field}, got {err}");
            assert!(!err.allowed.is_empty());
        }
    }
}

/// Points outside the grid are rejected at set-up; a divergent case is a recorded failure
/// carrying its step and residual history, not a panic.
#[test]
fn points_outside_grid_rejected_and_divergence_recorded() {
    use igimp::mesh::grid::Grid;
    use igimp::mpm::particles::MaterialPoints;
    let grid = Grid::try_new([0.0], [1.0], [4]).unwrap();
    let err = MaterialPoints::fill_box(&grid, [0.0], [5.0], [2], 1.0).unwrap_err();
    assert!(err.field.contains("material box"), "{err}");

    let spec = ColumnSpec {
        load_steps: 1,
        newton: NewtonSettings {
            tolerance: 1e-12,
            max_iterations: 1,
            line_search: false,
            ..Default::default()
        },
        ..table1_spec(16)
    };
    let o = solve_column(&spec, Method::IGIMP).unwrap();
    let f = o.failure.expect("must fail");
    assert_eq!(f.step, 1);
    assert_eq!(f.residuals.len(), 2);
    assert!(f.to_string().contains("load step 1"));
    assert!(o.points.iter().all(|p| p.sigma_zz.is_finite()));
}
