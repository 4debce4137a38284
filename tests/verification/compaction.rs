//! Plane-strain compaction under self weight (§5.2): Newton's convergence pattern against
//! Tables 2 and 3, the weak-node treatment's insensitivity to its tolerance, and failures
//! recorded rather than panicking.

use igimp::discretise::ghost::{GhostFaces, GhostSettings};
use igimp::material::constitutive::Material;
use igimp::problems::compaction::{solve_mpm, CompactionSpec};
use igimp::solver::newton::{check_quadratic, ResidualNorm};

/// Paper Table 2 (elastic, h = 1, 2×2 points, steps 16–20): the normalised out-of-balance
/// force after Newton iterations 1, 2, 3, with the paper's normalisation (`linearised`:
/// reactions updated by their linearised increment, AMPLE's scheme; reference/README.md item
/// 18). Reference: the paper's printed values. Tolerances: iteration 1 within 5 % (the issue's
/// band; measured 2026-12-01: at most 1.9 %); iteration 2 within 7 % at steps 16, 17, 18, 20
/// (measured at most 6.6 %, step 20) and 15 % at step 19 (measured 12.9 %: the paper's step 19
/// is off its own trend, its iteration 3 printed as 1.839e-12 against 3–7e-14 at the
/// neighbouring steps); iteration 3 at round-off (< 1e-12); the quadratic criterion of the
/// column tests. With `external` iteration 1 is 17 % above the paper's (1.590e-3 at step 16).
#[test]
fn paper_table2_elastic_newton_pattern() {
    let paper = [
        [1.357e-3, 4.805e-7],
        [1.246e-3, 4.202e-7],
        [1.147e-3, 3.658e-7],
        [1.094e-3, 3.478e-7],
        [9.897e-4, 2.872e-7],
    ];
    let mut spec = CompactionSpec::default();
    spec.newton.residual_norm = ResidualNorm::Linearised;
    let o = solve_mpm(&spec).unwrap();
    assert!(o.failure.is_none(), "{:?}", o.failure);
    for s in &o.steps {
        check_quadratic(&s.newton.residuals, 1e-3, 1e-11, 1.0, 1.8)
            .unwrap_or_else(|e| panic!("step {}: {e}", s.step));
        assert!(
            s.newton.iterations() <= 4,
            "step {}: {:?}",
            s.step,
            s.newton.residuals
        );
    }
    for (k, row) in paper.iter().enumerate() {
        let step = 16 + k;
        let r = &o.steps[step - 1].newton.residuals;
        assert_eq!(r.len(), 4, "step {step}: {r:?}");
        let bands = [0.05, if step == 19 { 0.15 } else { 0.07 }];
        for it in 0..2 {
            let dev = (r[it + 1] / row[it] - 1.0).abs();
            assert!(
                dev <= bands[it],
                "step {step} iteration {}: {:.3e} vs paper {:.3e} ({:.1} %)",
                it + 1,
                r[it + 1],
                row[it],
                100.0 * dev
            );
        }
        assert!(r[3] < 1e-12);
    }
}

/// The `external` normalisation (‖f_ext‖ over the free dofs) does not reproduce Table 2: the
/// same run is 17 % above the paper at iteration 1 of step 16 (a check that the agreement
/// above comes from the normalisation, not from the run).
#[test]
fn table2_with_external_norm_is_off_the_paper() {
    let o = solve_mpm(&CompactionSpec::default()).unwrap();
    let r1 = o.steps[15].newton.residuals[1];
    assert!(r1 / 1.357e-3 - 1.0 > 0.1, "{r1:e}");
}

/// Paper Table 3 (von Mises, ρ_y = 1.2×10⁴, h = 1, the study's plastic treatment): more
/// iterations while the plastic zone settles, then asymptotic quadratic convergence:
/// r_{k+1} ≤ C r_k² once r_k ≤ 1e-4, with C = 20, round-off floor 1e-10, observed order ≥ 1.8
/// where three residuals qualify. Above 1e-4 the active plastic set may still change, as in
/// the paper's iterations 1-4 (its step 16 has 8.852e-6 / (2.379e-4)² = 156); below 1e-4 every
/// pair of the paper's Table 3 satisfies C = 20 (largest 2.6). Measured 2026-12-01: largest
/// ratio 2.7 (step 16), 5 qualifying pairs (most steps jump from above 1e-4 to the floor).
#[test]
fn paper_table3_plastic_newton_reaches_quadratic_convergence() {
    // The compaction study's plastic treatment: the ghost penalty on every face, γ = 0.1
    // (studies/compaction.toml, [ghost] plastic).
    let spec = CompactionSpec {
        material: Material::von_mises(1e5, 0.3, 1.2e4),
        ghost: GhostSettings {
            gamma: 0.1,
            faces: GhostFaces::All,
            ..Default::default()
        },
        ..CompactionSpec::default()
    };
    let o = solve_mpm(&spec).unwrap();
    assert!(o.failure.is_none(), "{:?}", o.failure);
    let mut checks = 0;
    for s in &o.steps {
        let c = check_quadratic(&s.newton.residuals, 1e-4, 1e-10, 20.0, 1.8)
            .unwrap_or_else(|e| panic!("step {}: {e}", s.step));
        checks += c.ratio_checks;
        assert!(s.newton.iterations() <= 10);
    }
    assert!(checks >= 3, "{checks} ratio checks");
    // Plastic flow spreads the block far more than the elastic case (Figure 18).
    let elastic = solve_mpm(&CompactionSpec::default()).unwrap();
    assert!(o.max_horizontal_displacement > 5.0 * elastic.max_horizontal_displacement);
}

/// Weak nodes, without the ghost penalty (the default treatment, off here): without treatment
/// (and with fixed load steps) the h = 1 elastic case diverges;
/// with nodes tied to their
/// strongest neighbour the maximum horizontal displacement changes by less than 0.1 % over
/// tolerances 1e-2 … 3e-2 at h = 1 and h = 1/2 (measured spread 0.06 % and 0.03 %), and
/// treated nodes are counted.
#[test]
fn weak_node_treatment_is_needed_and_insensitive_to_its_tolerance() {
    let mut fixed_steps = CompactionSpec::default().newton;
    fixed_steps.max_cutbacks = 0;
    let no_ghost = GhostSettings::default();
    let untreated = solve_mpm(&CompactionSpec {
        weak_node_tolerance: 0.0,
        newton: fixed_steps,
        ghost: no_ghost,
        ..CompactionSpec::default()
    })
    .unwrap();
    let failure = untreated
        .failure
        .expect("untreated weak nodes should stop Newton");
    assert!(failure.step > 1 && !failure.residuals.is_empty());
    for h in [1.0, 0.5] {
        let u: Vec<f64> = [1e-2, 2e-2, 3e-2]
            .iter()
            .map(|&tol| {
                let o = solve_mpm(&CompactionSpec {
                    element_size: h,
                    weak_node_tolerance: tol,
                    ghost: no_ghost,
                    ..CompactionSpec::default()
                })
                .unwrap();
                assert!(o.failure.is_none() && o.weak_nodes_treated > 0);
                o.max_horizontal_displacement
            })
            .collect();
        let (lo, hi) = u
            .iter()
            .fold((f64::MAX, f64::MIN), |(a, b), &x| (a.min(x), b.max(x)));
        assert!((hi - lo) / lo < 1e-3, "h = {h}: {u:?}");
    }
}

/// One point per cell in 2D integrates each element at one point (hourglass modes): without
/// the ghost penalty Newton fails, and the failure is a recorded case with its step and
/// residuals, not a panic (with it, see tests/verification/robustness.rs and the compaction study).
#[test]
fn one_point_per_cell_failure_is_recorded() {
    let o = solve_mpm(&CompactionSpec {
        points_per_cell: 1,
        ghost: GhostSettings::default(),
        ..CompactionSpec::default()
    })
    .unwrap();
    let f = o.failure.expect("1 point per cell fails");
    assert!(f.step >= 1 && !f.residuals.is_empty(), "{f}");
    assert!(o.max_horizontal_displacement.is_finite());
}

/// Bad input names the field.
#[test]
fn bad_compaction_input_names_the_field() {
    let cases = [
        (
            CompactionSpec {
                element_size: 0.3,
                ..Default::default()
            },
            "grid_extent",
        ),
        (
            CompactionSpec {
                element_size: -1.0,
                ..Default::default()
            },
            "element_size",
        ),
        (
            CompactionSpec {
                half_width: 20.0,
                ..Default::default()
            },
            "grid_extent",
        ),
        (
            CompactionSpec {
                points_per_cell: 0,
                ..Default::default()
            },
            "points_per_cell",
        ),
        (
            CompactionSpec {
                material: Material::linear_elastic(1e5, 0.7),
                ..Default::default()
            },
            "poisson_ratio",
        ),
        (
            CompactionSpec {
                weight: f64::NAN,
                ..Default::default()
            },
            "weight",
        ),
        (
            CompactionSpec {
                weak_node_tolerance: 1.5,
                ..Default::default()
            },
            "weak_node_tolerance",
        ),
        (
            CompactionSpec {
                material: Material::von_mises(1e5, 0.3, 0.0),
                ..Default::default()
            },
            "yield_stress",
        ),
    ];
    for (spec, field) in cases {
        let e = solve_mpm(&spec)
            .err()
            .unwrap_or_else(|| panic!("{field} accepted"));
        assert!(e.field.contains(field), "expected {field}: {e}");
    }
}

/// Plain MPM weights on the same points (Method::MPM; the problem sets the basis) converge
/// and agree with iGIMP: at h = 1, 2×2 points, max horizontal u 0.586795 against 0.592824
/// (1.0 %, measured 2026-12-01; 0.86 % at h = 0.5). Band 2 %: the two weightings differ by
/// the GIMP smoothing only, which is O(h) here. A method the problem has no solution for is
/// an input error naming `method` and the methods it has.
#[test]
fn mpm_weights_solve_the_compaction_and_other_methods_are_named_errors() {
    use igimp::basis::method::Method;
    use igimp::problems::compaction::solve;
    let spec = CompactionSpec::default();
    let mpm = solve(&spec, Method::MPM).unwrap();
    let gimp = solve(&spec, Method::IGIMP).unwrap();
    assert!(mpm.failure.is_none() && gimp.failure.is_none());
    let dev = (mpm.max_horizontal_displacement / gimp.max_horizontal_displacement - 1.0).abs();
    assert!(dev < 0.02, "MPM vs iGIMP: {dev:.4}");
    assert!(dev > 1e-4, "MPM must not be the iGIMP run: {dev:.2e}");
    let e = solve(&spec, Method::FEM_LINEAR).unwrap_err();
    assert_eq!(e.field, "method");
    // Every family (derived, so that a new one needs no edit here), then the elements.
    let expected: Vec<&str> = Method::MATERIAL_POINT
        .iter()
        .map(|m| m.name())
        .chain(["fem-q4", "fem-q8"])
        .collect();
    assert!(e.allowed.contains(&expected.join(", ")), "{e}");
}

/// The 3D quarter block (reference/README.md item 26; symmetry planes x = 0, y = 0, base on rollers, h = 1,
/// 2×2×2 points per cell, 1,024 points): every load step converges quadratically (3 Newton
/// iterations, e.g. 5.6e-2, 1.2e-3, 4.3e-7, 6.0e-14 at step 20), and the corner displacement
/// 0.452943 is within 0.05 % of the h = 1/2 run (8,192 points: 0.452841, measured 2026-12-01;
/// not re-run here, it takes 36 s). It is below the plane-strain block's 0.5928, as the 3D
/// block is free to expand along y.
#[test]
fn compaction_3d_quarter_block_converges_quadratically() {
    use igimp::problems::compaction::solve_mpm_3d;
    let o = solve_mpm_3d(&CompactionSpec::default()).unwrap();
    assert!(o.failure.is_none(), "{:?}", o.failure);
    assert_eq!(o.num_points, 1024);
    assert_eq!(o.points.len(), 8 * 16, "the slice next to y = 0: 8 x 16 points");
    for s in &o.steps {
        check_quadratic(&s.newton.residuals, 1e-3, 1e-11, 1.0, 1.8)
            .unwrap_or_else(|e| panic!("step {}: {e}", s.step));
    }
    let u = o.max_horizontal_displacement;
    assert!((u / 0.452841 - 1.0).abs() < 5e-4, "u = {u}");
    assert!(u < 0.5928, "u = {u}");
}

/// The 3D quarter block with Hex8 (2×2×2 Gauss points) and Hex20 (3×3×3) FEM, h = 1: every
/// load step converges quadratically, and the corner displacement sits beside iGIMP's: Hex20
/// 0.452273 is 0.12 % from iGIMP at h = 1/2 (0.452841, the test above; band 0.5 %), Hex8
/// 0.441320 is 2.5 % below it, stiffer on 4 × 4 × 8 elements (band: below Hex20, within 4 %);
/// measured 2026-12-01.
#[test]
fn compaction_3d_fem_converges_quadratically() {
    use igimp::basis::method::Method;
    use igimp::problems::compaction::solve;
    let spec = CompactionSpec {
        dimension: 3,
        ..CompactionSpec::default()
    };
    let mut us = vec![];
    for method in [Method::FEM_HEX8, Method::FEM_HEX20] {
        let o = solve(&spec, method).unwrap();
        assert!(o.failure.is_none(), "{method:?}: {:?}", o.failure);
        assert_eq!(o.size, 4 * 4 * 8);
        for s in &o.steps {
            check_quadratic(&s.newton.residuals, 1e-3, 1e-11, 1.0, 1.8)
                .unwrap_or_else(|e| panic!("{method:?} step {}: {e}", s.step));
        }
        us.push(o.max_horizontal_displacement);
    }
    let (hex8, hex20) = (us[0] / 0.452841 - 1.0, us[1] / 0.452841 - 1.0);
    println!(
        "Hex8 {:.6} ({hex8:+.2e}), Hex20 {:.6} ({hex20:+.2e})",
        us[0], us[1]
    );
    assert!(hex20.abs() < 5e-3, "Hex20 {hex20:e} from iGIMP");
    assert!(hex8 < hex20 && hex8.abs() < 4e-2, "Hex8 {hex8:e} from iGIMP");
    let e = solve(&spec, Method::FEM_Q4).unwrap_err();
    assert_eq!(e.field, "method");
    // Every family (derived, so that a new one needs no edit here), then the elements.
    let expected: Vec<&str> = Method::MATERIAL_POINT
        .iter()
        .map(|m| m.name())
        .chain(["fem-hex8", "fem-hex20"])
        .collect();
    assert!(e.allowed.contains(&expected.join(", ")), "{e}");
}

/// Points renumbered cell by cell (`MpmSolver::sort_points_by_cell`, the large runs' opt-in)
/// give the row-by-row numbering's solution to round-off: the 3D compaction at h = 1 (1024
/// points, elastic, 20 steps) with a point load on one point, so that a load left on its old
/// index would move another point. Every point's final position agrees to 1e-12 of the
/// largest displacement (sums over points differ only in their order) and every step takes
/// the same Newton iterations; each cell's points are consecutive after the sort.
#[test]
fn points_sorted_by_cell_give_the_same_solution() {
    use igimp::solver::load_stepping::LoadStepping;
    use nalgebra::Vector3;
    let spec = CompactionSpec {
        dimension: 3,
        ..CompactionSpec::default()
    };
    let build = || {
        let mut s = spec.mpm_solver_3d().unwrap();
        s.loads.point_loads.push((5, Vector3::new(2.0e3, -1.0e3, 0.5e3)));
        s
    };
    let mut rows = build();
    let mut cells = build();
    let order = cells.sort_points_by_cell();
    assert_ne!(
        order,
        (0..order.len()).collect::<Vec<_>>(),
        "already cell-ordered"
    );
    let cell_of = |x: &Vector3<f64>| [x[0].floor(), x[1].floor(), x[2].floor()];
    let mut seen = std::collections::HashSet::new();
    let mut last = None;
    for x in &cells.points.position {
        let c = cell_of(x).map(|v| v as i64);
        if last != Some(c) {
            assert!(seen.insert(c), "cell {c:?} visited twice");
            last = Some(c);
        }
    }
    let r_rows = rows.run().unwrap();
    let r_cells = cells.run().unwrap();
    for (a, b) in r_rows.iter().zip(&r_cells) {
        assert_eq!(a.newton.iterations(), b.newton.iterations(), "step {}", a.step);
    }
    let scale = (0..rows.points.len())
        .map(|p| rows.points.displacement(p).amax())
        .fold(0.0, f64::max);
    assert!(scale > 0.0);
    for (k, &p) in order.iter().enumerate() {
        let d = (cells.points.position[k] - rows.points.position[p]).amax();
        assert!(d <= 1e-12 * scale, "point {p}: {d:e} of {scale:e}");
    }
}
