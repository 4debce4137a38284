//! Checks that prove they can fail: each key check runs on a deliberately wrong variant and
//! must catch it, while passing on the correct kernels. The wrong kernels exist only with the
//! `seeded-bugs` feature (`src/lib.rs (seeded)`): `cargo test --release --features seeded-bugs
//! --test seeded` (run by `.ci/run`). One test function, so the process-wide switch is never
//! shared between concurrent tests.
//!
//! | bug | check that must catch it |
//! |---|---|
//! | tangent without −σ_il δ_jk (eq 25) | Newton order on the vortex (check_quadratic, order ≥ 1.8) |
//! | eq 36 without ΔF⁻¹ | the manufactured study's rate bands |
//! | V_p without det ΔF (eq 28) | the manufactured study's rate bands |
//! | stress error at x_p instead of X_p | the iGIMP stress-rate band (1.64 ± 0.25) |
//! | GIMP weights without the per-element split (eqs 7–10) | weights against direct quadrature of ∫χ_p N_v, and the rate bands |
//! | multigrid prolongation with its two weights swapped | CG iterations per solve (≤ 20) and no fallback |
//! | B-splines without their boundary treatment | partition of unity within 1.5h of the grid's edge |
//! | CPDI corners moved against the grid | the column study's CPDI rate bands |
//! | TLMPM with ∇₀S as the start-of-step gradient (no Fₙ⁻ᵀ) | the column study's TLMPM rate bands |
//! | dynamic tangent without its mass term M/(βΔt²) | Newton order on the vibrating bar (check_quadratic, order ≥ 1.8) |
//! | Mohr–Coulomb's edge returned with one multiplier | \|f\| ≤ 1e-10 c₀ after returns from triaxial trial states |
//! | modified Cam-Clay's tangent without the hardening of p_c | central differences of the update (1e-6) on the wet side |
//! | strength reduction dividing c alone (tan φ kept) | the slope's Q8 factor of safety within its band of Bishop's 1.380 |
//! | point penalty without its tangent | central differences of the footing's residual (1e-6) |

/// The integration tests' shared checks (the finite-difference tangents), so that a seeded bug
/// meets the very check it is seeded against.
#[path = "verification/common.rs"]
mod common;
#[path = "verification/footing_scene.rs"]
mod footing_scene;
#[path = "verification/scene_text.rs"]
mod scene_text;

use igimp::basis::method::Method;
use igimp::problems::manufactured::{errors, solve, Exact, Field, ManufacturedSpec, PointValue};
use igimp::seeded::{set, Bug};
use igimp::solver::newton::check_quadratic;
use igimp::study::engine::{run_in_memory, StudyKind};
use igimp::study::manufactured::ManufacturedStudy;
use igimp::study::Tier;
use std::path::Path;

/// The manufactured study cut to what the iGIMP bugs can fail: its two fields' iGIMP sweeps
/// with the eq 39 domains (2×2 points), h = 1/4..1/32, and their rate bands. The other
/// methods, domain updates and point counts share these kernels; their bands only repeat
/// the verdict, and the wrong kernels make their Newton runs long (the whole quick tier took
/// 265 s for one bug).
fn study() -> ManufacturedStudy {
    use igimp::mpm::DomainUpdate;
    let mut s =
        ManufacturedStudy::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("studies/manufactured.toml"))
            .unwrap();
    let kept = |id: &str| id == "axis-aligned" || id == "vortex";
    s.sweeps.retain(|x| kept(&x.id));
    for x in &mut s.sweeps {
        x.methods = vec![Method::IGIMP];
        x.domain_updates = vec![DomainUpdate::Stretch];
    }
    s.expect_rate.retain(|x| {
        kept(&x.sweep)
            && x.method == Method::IGIMP
            && x.domain_update.unwrap_or(DomainUpdate::Stretch) == DomainUpdate::Stretch
    });
    s.figures.clear();
    s
}

/// (passed, failed, not evaluated) of the manufactured quick tier's rate checks, and the ids
/// of those that did not pass.
fn rate_checks() -> ((usize, usize, usize), Vec<String>) {
    let run = run_in_memory(&study(), "manufactured.toml", Tier::Quick).unwrap();
    let bad = run
        .results
        .checks
        .iter()
        .filter(|c| c.pass != Some(true))
        .map(|c| c.id.clone())
        .collect();
    (run.results.check_counts(), bad)
}

/// The lowest convergence order check_quadratic measures over the vortex's load steps (iGIMP,
/// h = 1/8, 2×2 points), or the error it reports.
fn newton_order() -> Result<f64, String> {
    let spec = ManufacturedSpec {
        field: Field::Vortex,
        amplitude: 0.6,
        cells: 8,
        ..ManufacturedSpec::default()
    };
    let o = solve(&spec, Method::IGIMP).map_err(|e| e.to_string())?;
    if let Some(f) = o.failure {
        return Err(f.to_string());
    }
    let mut worst = f64::INFINITY;
    for s in &o.steps {
        let q = check_quadratic(&s.newton.residuals, 1e-3, 1e-12, 1.0, 1.8)
            .map_err(|e| format!("step {}: {e}", s.step))?;
        worst = worst.min(q.min_order);
    }
    Ok(worst)
}

/// Fitted slope of the stress error over h = 1/8, 1/16, 1/32 (axis-aligned, iGIMP, 2×2
/// points), the error evaluated by `sigma_at` (X_p, or x_p for the seeded mistake).
fn stress_rate(at_current: bool) -> f64 {
    let mut h = vec![];
    let mut e = vec![];
    for n in [8, 16, 32] {
        let spec = ManufacturedSpec {
            cells: n,
            ..ManufacturedSpec::default()
        };
        let o = solve(&spec, Method::IGIMP).unwrap();
        let exact = Exact::of(&spec);
        let pts: Vec<PointValue> = o
            .points
            .iter()
            .map(|p| PointValue {
                x0: if at_current { p.x } else { p.x0 },
                ..*p
            })
            .collect();
        // `errors` evaluates σ(X) at x0; with at_current it sees σ(x_p). The displacement part
        // is not used.
        h.push(1.0 / n as f64);
        e.push(errors(&exact, &pts).stress);
    }
    igimp::problems::norms::fitted_rate(&h, &e).unwrap()
}

/// Largest difference between the GIMP weights of domains straddling an element edge and
/// (1/2r) ∫ N_v over the domain by direct quadrature of the true hat functions (20,000
/// midpoints): the per-element split is what makes them agree.
fn gimp_weight_error() -> f64 {
    use igimp::basis::{AxisWeights, Basis, GridAxis};
    let axis = GridAxis {
        axis: 0,
        origin: 0.0,
        spacing: 1.0,
        cells: 8,
    };
    let hat = |v: usize, y: f64| (1.0 - (y - v as f64).abs()).max(0.0);
    let mut worst: f64 = 0.0;
    for (x, r) in [(3.9, 0.25), (4.1, 0.3), (2.95, 0.45), (5.5, 0.5), (3.7, 0.6)] {
        let mut w = AxisWeights::default();
        Basis::Gimp.axis_weights(axis, x, r, &mut w).unwrap();
        for v in 0..=8usize {
            let n = 20_000;
            let q: f64 = (0..n)
                .map(|i| hat(v, x - r + 2.0 * r * (i as f64 + 0.5) / n as f64))
                .sum::<f64>()
                / n as f64;
            let got = if (w.first..w.first + w.len).contains(&v) {
                w.w[v - w.first]
            } else {
                0.0
            };
            worst = worst.max((got - q).abs());
        }
    }
    worst
}

/// CG iterations per solve and fallbacks of the elastic Q4 compaction at h = 1/16, one
/// load step (the check of tests/verification/multigrid.rs: at most 20 per solve, none).
fn multigrid_iterations() -> (f64, usize) {
    use igimp::fem::QuadElement;
    use igimp::problems::compaction::{fem_solver, CompactionSpec};
    use igimp::solver::linear::LinearSolver;
    use igimp::solver::load_stepping::LoadStepping;
    let spec = CompactionSpec {
        element_size: 1.0 / 16.0,
        load_steps: 1,
        linear_solver: LinearSolver::Iterative,
        ..CompactionSpec::default()
    };
    let (mut fem, _) = fem_solver(&spec, QuadElement::Q4).unwrap();
    let _ = fem.run();
    let s = fem.linear_stats();
    (
        s.iterations as f64 / s.solves.max(1) as f64,
        fem.linear_solver_fallbacks(),
    )
}

/// Worst |Σ S − 1| of the quadratic and cubic B-splines over points within 1.5h of the
/// grid's lower edge (2D, unit cells).
fn spline_unity_defect() -> f64 {
    use igimp::basis::{Basis, PointSupport, PointView};
    use igimp::mesh::grid::Grid;
    use nalgebra::{Matrix3, SVector};
    let grid = Grid::<2>::try_new([0.0; 2], [1.0; 2], [6; 2]).unwrap();
    let mut sup = PointSupport::<2>::default();
    let mut worst: f64 = 0.0;
    for basis in [Basis::Bspline2, Basis::Bspline3] {
        for i in 0..=30 {
            let x = SVector::<f64, 2>::new(0.05 * i as f64, 3.3);
            let r = SVector::<f64, 2>::repeat(0.25);
            let f = Matrix3::identity();
            let view = PointView {
                position: &x,
                half_length: &r,
                position0: &x,
                half_length0: &r,
                f: &f,
                corners: &[],
            };
            basis.family::<2>().evaluate(&grid, &view, &mut sup).unwrap();
            worst = worst.max((sup.weights().iter().sum::<f64>() - 1.0).abs());
        }
    }
    worst
}

/// The ids of the failing checks of the column quick tier's `families` sweep cut to one
/// family and its bands (the other sweeps run no family).
fn column_bad_checks(family: Method) -> Vec<String> {
    use igimp::study::column::ColumnStudy;
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("studies/column.toml");
    let text = std::fs::read_to_string(&path).unwrap();
    let mut study = ColumnStudy::parse(&text, "column.toml").unwrap();
    study.sweeps.retain(|x| x.id == "families");
    study.sweeps[0].methods = vec![family];
    study
        .expect
        .retain(|x| x.sweep == "families" && x.method == family);
    assert!(
        !study.expect.is_empty(),
        "no band of {family:?} in the column study"
    );
    study.compare.clear();
    study.paper.clear();
    study.figures.clear();
    failing_checks(
        &run_in_memory(&study, "column.toml", Tier::Quick)
            .unwrap()
            .results
            .checks,
    )
}

/// The ids of the checks that did not pass (failed or not evaluated).
fn failing_checks(checks: &[igimp::study::checks::CheckRecord]) -> Vec<String> {
    checks
        .iter()
        .filter(|c| c.pass != Some(true))
        .map(|c| c.id.clone())
        .collect()
}

/// The failing checks of the slope study's quick tier cut to its coarse Q8 sweep and the
/// checks on that sweep (Q8's factor of safety against Bishop's 1.380).
fn slope_bad_checks() -> Vec<String> {
    use igimp::study::scene::SceneStudy;
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("studies/slope-strength-reduction.toml");
    let mut study = SceneStudy::load(&path).unwrap();
    study.sweeps.retain(|x| x.id == "q8-coarse");
    study.expect_reference.retain(|e| e.sweep == "q8-coarse");
    study.expect_rate.retain(|e| e.sweep == "q8-coarse");
    study.expect_quadratic.retain(|e| e.sweep == "q8-coarse");
    assert!(
        !study.expect_reference.is_empty(),
        "no Q8 check in the slope study"
    );
    let run = run_in_memory(&study, "slope-strength-reduction.toml", Tier::Quick).unwrap();
    failing_checks(&run.results.checks)
}

/// Newton's order on a large-amplitude vibrating bar (v₀/c = 0.05, iGIMP, consistent mass):
/// every step's history must pass check_quadratic (once r ≤ 0.1, r_{k+1} ≤ 10 r_k², order ≥
/// 1.8), as in tests/verification/dynamics.rs; Err names the first step that does not (or the
/// failure of the run).
fn bar_newton_order() -> Result<usize, String> {
    use igimp::problems::bar::{solve, BarSpec};
    let spec = BarSpec {
        velocity: 0.5,
        elements: 16,
        steps_per_period: 32,
        periods: 0.5,
        newton: igimp::solver::newton::NewtonSettings {
            tolerance: 1e-11,
            max_iterations: 30,
            max_cutbacks: 0,
            ..Default::default()
        },
        ..BarSpec::default()
    };
    let o = solve(&spec, Method::IGIMP).map_err(|e| e.to_string())?;
    if let Some(f) = o.failure {
        return Err(f.to_string());
    }
    let mut checks = 0;
    for s in &o.steps {
        checks += check_quadratic(&s.newton.residuals, 0.1, 1e-11, 10.0, 1.8)
            .map_err(|e| format!("step {}: {e}", s.step))?
            .ratio_checks;
    }
    Ok(checks)
}

/// The largest |f| / c₀ after Drucker–Prager's return from trial states past its apex
/// (isotropic tension): 0 to round-off when the apex is returned to.
fn drucker_prager_apex_error() -> f64 {
    use igimp::material::constitutive::{ConstitutiveModel, DruckerPrager, MaterialState};
    let m = DruckerPrager::try_new(1e5, 0.3, 50.0, 30.0, 30.0, 0.0).unwrap();
    let mut worst: f64 = 0.0;
    for k in 1..=10 {
        let mut eps = nalgebra::Matrix3::identity() * (1e-3 * k as f64);
        eps[(0, 1)] = 1e-5;
        eps[(1, 0)] = 1e-5;
        let r = m.update(&eps, &MaterialState::default()).unwrap();
        worst = worst.max(m.yield_function(&r.tau, r.internal.get(0)).abs() / 50.0);
    }
    worst
}

/// The largest |D_fd − D| / |D| of modified Cam-Clay's tangent (central differences, h = 1e-8,
/// as tests/verification/cam_clay.rs checks it) at plastic states on the wet side from a
/// hardened state, where p_c hardens.
fn cam_clay_tangent_error() -> f64 {
    use igimp::material::constitutive::{
        ConstitutiveModel, InternalVariables, MaterialState, ModifiedCamClay,
    };
    use nalgebra::Matrix3;
    let m = ModifiedCamClay::try_new(3000.0, 0.02, 0.1, 1.2, 100.0, 100.0).unwrap();
    let s = MaterialState {
        internal: InternalVariables::from_slice(&[-0.02]),
        ..Default::default()
    };
    let mut worst: f64 = 0.0;
    for k in 1..=5 {
        let mut eps = Matrix3::identity() * (-0.02 * k as f64);
        eps[(0, 0)] -= 0.01;
        eps[(0, 1)] = 0.004;
        eps[(1, 0)] = 0.004;
        assert!(
            m.update(&eps, &s).unwrap().internal.get(0) < -0.02,
            "elastic state {k}"
        );
        worst = worst.max(common::material_tangent_error(&m, &eps, &s, 0.0));
    }
    worst
}

/// The largest |f| / c₀ after Mohr–Coulomb's return from triaxial trial states (two equal
/// principal strains: axial compression returns to the left edge τ₁ = τ₂, axial extension to
/// the right edge τ₂ = τ₃), f on the ordered principal stresses: 0 to round-off when the edge
/// is returned to with its two multipliers.
fn mohr_coulomb_edge_error() -> f64 {
    use igimp::material::constitutive::{ConstitutiveModel, MaterialState, MohrCoulomb};
    use nalgebra::{Matrix3, Vector3};
    let m = MohrCoulomb::try_new(1e5, 0.3, 50.0, 30.0, 30.0, 0.0).unwrap();
    let mut worst: f64 = 0.0;
    for k in 1..=10 {
        let a = 2e-3 * k as f64;
        for d in [
            Vector3::new(-a, 0.5 * a, 0.5 * a),
            Vector3::new(a, -0.5 * a, -0.5 * a),
        ] {
            let r = m
                .update(&Matrix3::from_diagonal(&d), &MaterialState::default())
                .unwrap();
            assert!(r.internal.get(0) > 0.0, "the triaxial state {d} stayed elastic");
            worst = worst.max(m.yield_function(&r.tau, r.internal.get(0)).abs() / 50.0);
        }
    }
    worst
}

/// max |K − K_fd| / max |K| of iGIMP with F-bar on the yielding compaction block (von Mises,
/// σ_y = 2.5e4, h = 1, at its last step), by `tests/verification/fbar.rs`'s check and increment, with
/// `bug` switched on for the check only (the steps before it are solved correctly).
fn fbar_tangent_error(bug: Bug) -> f64 {
    fbar_tangent_error_with(bug, false)
}

/// F-bar's FD tangent error on the compaction block with `bug`, the pressure projection on
/// or off (tests/verification/fbar.rs).
fn fbar_tangent_error_with(bug: Bug, project_pressure: bool) -> f64 {
    use igimp::material::constitutive::Material;
    use igimp::problems::compaction::CompactionSpec;
    use igimp::solver::load_stepping::LoadStepping;
    let spec = CompactionSpec {
        material: Material::von_mises(1e5, 0.3, 2.5e4),
        load_steps: 10,
        f_bar: true,
        ..Default::default()
    };
    let mut solver = spec.mpm_solver().unwrap();
    solver.set_pressure_projection(project_pressure);
    for _ in 0..9 {
        solver.step().unwrap();
    }
    set(bug);
    let err = solver
        .with_step_system(1.0, |sys| common::fd_tangent_errors(sys, 2e-3, 5).0)
        .unwrap();
    set(Bug::None);
    err
}

#[test]
fn every_seeded_bug_is_caught() {
    // The correct kernels pass everything the variants must fail.
    set(Bug::None);
    let ((pass, fail, none), bad) = rate_checks();
    assert_eq!((fail, none), (0, 0), "correct kernels: {bad:?}");
    let bands = study()
        .expect_rate
        .iter()
        .filter(|x| x.tier != Some(Tier::Full))
        .count();
    assert!(bands >= 4, "the cut study keeps {bands} iGIMP bands");
    assert_eq!(pass, bands);
    let order = newton_order().expect("correct kernels converge quadratically");
    assert!(order >= 1.8, "correct kernels: order {order}");
    let rate = stress_rate(false);
    assert!((rate - 1.64).abs() <= 0.25, "correct stress rate {rate}");
    let w = gimp_weight_error();
    assert!(w < 1e-8, "correct GIMP weights off the quadrature by {w:e}");
    let (its, fallbacks) = multigrid_iterations();
    assert!(
        its <= 20.0 && fallbacks == 0,
        "correct multigrid: {its} iterations per solve, {fallbacks} fallbacks"
    );
    let d = spline_unity_defect();
    assert!(d < 1e-12, "correct B-splines: |ΣS − 1| = {d:e}");
    let bar = bar_newton_order().expect("correct dynamic tangent converges quadratically");
    assert!(bar >= 5, "only {bar} quadratic ratio checks on the bar");
    for family in [Method::CPDI, Method::TLMPM] {
        let bad = column_bad_checks(family);
        assert!(bad.is_empty(), "correct kernels: column checks {bad:?}");
    }
    eprintln!("control: {pass}/{bands} iGIMP rate checks pass, Newton quadratic, stress rate {rate:.2}, GIMP weights within {w:.1e} of the quadrature");

    // 1. No geometric term: the solution is unchanged, so the rate bands cannot see it, but
    //    Newton is no longer quadratic.
    set(Bug::NoGeometricTerm);
    let caught = newton_order();
    eprintln!("no geometric term: Newton order check -> {caught:?}");
    assert!(
        caught.is_err(),
        "a tangent without its geometric term passed the Newton-order check"
    );

    // 2, 3, 5. Wrong kinematics or weights: the manufactured solution's rate bands fail.
    set(Bug::NoElementSplit);
    let w = gimp_weight_error();
    eprintln!("no element split: GIMP weights off the quadrature by {w:.3e}");
    assert!(
        w > 1e-3,
        "GIMP weights without the per-element split passed: {w:e}"
    );
    for bug in [Bug::NoDeltaFInverse, Bug::NoVolumeChange, Bug::NoElementSplit] {
        set(bug);
        let ((pass, fail, none), bad) = rate_checks();
        eprintln!("{bug:?}: rate checks {pass} passed, {fail} failed, {none} not evaluated: {bad:?}");
        assert!(
            bad.iter().any(|id| id.contains("igimp")),
            "{bug:?} passed every iGIMP rate band"
        );
    }
    set(Bug::None);

    // 6. A wrong multigrid prolongation: CG needs far more iterations or falls back.
    set(Bug::SwappedProlongation);
    let (its, fallbacks) = multigrid_iterations();
    eprintln!("swapped prolongation: {its:.1} CG iterations per solve, {fallbacks} fallbacks");
    assert!(
        its > 20.0 || fallbacks > 0,
        "a swapped prolongation passed the multigrid iteration bound"
    );
    set(Bug::None);

    // 7. B-splines without their boundary treatment: Σ S = 1 fails near the edge.
    set(Bug::SplineWithoutBoundary);
    let d = spline_unity_defect();
    eprintln!("splines without boundary treatment: |ΣS − 1| up to {d:.3e}");
    assert!(d > 1e-2, "splines without boundary treatment passed: {d:e}");

    // 8, 9. CPDI corners against the grid, TLMPM without Fₙ⁻ᵀ: the column's family bands.
    for (bug, family) in [
        (Bug::CornersAgainstGrid, Method::CPDI),
        (Bug::ReferenceGradients, Method::TLMPM),
    ] {
        set(bug);
        let bad = column_bad_checks(family);
        eprintln!("{bug:?}: column checks failing: {bad:?}");
        assert!(
            !bad.is_empty(),
            "{bug:?} passed every {family:?} band of the column"
        );
    }
    set(Bug::None);

    // 10. The dynamic tangent without its mass term: Newton on the bar is no longer quadratic.
    set(Bug::NoMassInTangent);
    let caught = bar_newton_order();
    eprintln!("no mass in the dynamic tangent: bar Newton order check -> {caught:?}");
    assert!(
        caught.is_err(),
        "a dynamic tangent without its mass term passed the Newton-order check"
    );
    set(Bug::None);

    // 11. Drucker–Prager's apex treated as smooth: the return past the apex leaves the cone
    //     (tests/verification/drucker_prager.rs checks |f| ≤ 1e-10 c₀ after every return).
    let right = drucker_prager_apex_error();
    set(Bug::DruckerPragerSmoothApex);
    let wrong = drucker_prager_apex_error();
    set(Bug::None);
    eprintln!("Drucker–Prager apex as smooth: |f|/c₀ {wrong:.2e} (correct {right:.1e})");
    assert!(
        right <= 1e-10,
        "the correct apex return leaves |f|/c₀ = {right:e}"
    );
    assert!(
        wrong > 1e-3,
        "a smooth apex passed the yield-surface check: {wrong:e}"
    );

    // 12. F-bar's tangent without its F-bar terms: the finite-difference check of
    //     tests/verification/fbar.rs (1e-6) fails.
    let right = fbar_tangent_error(Bug::None);
    let wrong = fbar_tangent_error(Bug::FBarWithoutItsTangent);
    eprintln!("F-bar tangent without its terms: FD error {wrong:.2e} (correct {right:.1e})");
    assert!(right < 1e-6, "the correct F-bar tangent is off by {right:e}");
    assert!(
        wrong > 1e-6,
        "F-bar's tangent without its terms passed: {wrong:e}"
    );

    // 13. Mohr–Coulomb's edges returned with one multiplier (the main plane's return kept
    //     where it breaks the ordering): the returned stress leaves the yield surface
    //     (tests/verification/mohr_coulomb.rs checks |f| ≤ 1e-10 c₀ and the ordering).
    let right = mohr_coulomb_edge_error();
    set(Bug::MohrCoulombEdgeOneMultiplier);
    let wrong = mohr_coulomb_edge_error();
    set(Bug::None);
    eprintln!("Mohr–Coulomb edge with one multiplier: |f|/c₀ {wrong:.2e} (correct {right:.1e})");
    assert!(
        right <= 1e-10,
        "the correct edge return leaves |f|/c₀ = {right:e}"
    );
    assert!(
        wrong > 1e-3,
        "an edge returned with one multiplier passed the yield-surface check: {wrong:e}"
    );

    // 14. Modified Cam-Clay's tangent without the hardening of p_c: the finite-difference check
    //     of tests/verification/cam_clay.rs (1e-6) fails on the wet side.
    let right = cam_clay_tangent_error();
    set(Bug::CamClayTangentWithoutHardening);
    let wrong = cam_clay_tangent_error();
    set(Bug::None);
    eprintln!("Cam-Clay tangent without hardening: FD error {wrong:.2e} (correct {right:.1e})");
    assert!(right < 1e-6, "the correct Cam-Clay tangent is off by {right:e}");
    assert!(
        wrong > 1e-6,
        "Cam-Clay's tangent without hardening passed: {wrong:e}"
    );

    // 15. The pressure projection's tangent without its patch block: the finite-difference
    //     check of tests/verification/fbar.rs (1e-6) fails.
    let right = fbar_tangent_error_with(Bug::None, true);
    let wrong = fbar_tangent_error_with(Bug::PressureProjectionWithoutItsBlock, true);
    eprintln!("pressure projection without its block: FD error {wrong:.2e} (correct {right:.1e})");
    assert!(right < 1e-6, "the correct projected tangent is off by {right:e}");
    assert!(
        wrong > 1e-6,
        "the projected tangent without its block passed: {wrong:e}"
    );

    // 16. The strength reduction dividing the cohesion alone: the slope's Q8 factor of
    //     safety leaves its band around Bishop's 1.380 (studies/slope-strength-reduction.toml).
    let right = slope_bad_checks();
    set(Bug::StrengthReductionCohesionOnly);
    let wrong = slope_bad_checks();
    set(Bug::None);
    eprintln!("strength reduction of c alone: failing checks {wrong:?} (correct {right:?})");
    assert!(right.is_empty(), "the correct strength reduction fails {right:?}");
    assert!(
        !wrong.is_empty(),
        "a strength reduction of c alone passed the slope's checks"
    );

    // 17. The point penalty without its tangent: the finite-difference check of
    //     tests/verification/point_penalty.rs (1e-6) fails.
    let right = footing_scene::penalty_tangent_error(igimp::basis::Basis::Gimp);
    set(Bug::PointPenaltyWithoutItsTangent);
    let wrong = footing_scene::penalty_tangent_error(igimp::basis::Basis::Gimp);
    set(Bug::None);
    eprintln!("point penalty without its tangent: FD error {wrong:.2e} (correct {right:.1e})");
    assert!(right < 1e-6, "the correct penalty tangent is off by {right:e}");
    assert!(wrong > 1e-6, "the penalty tangent left out passed: {wrong:e}");

    // 18. The extrapolated start repeating the last increment unscaled: the start's residual
    //     on the quadrupling footing (tests/verification/predictor.rs, below 1e-2 of the zero
    //     start's) is not reduced.
    let method = igimp::basis::method::Method::MaterialPoint(igimp::basis::Basis::Gimp);
    let right = footing_scene::extrapolated_start_ratio(method);
    set(Bug::ExtrapolatedStartUnscaled);
    let wrong = footing_scene::extrapolated_start_ratio(method);
    set(Bug::None);
    eprintln!("extrapolated start unscaled: start residual ratio {wrong:.2e} (correct {right:.1e})");
    assert!(right < 1e-2, "the correct extrapolated start leaves {right:e}");
    assert!(wrong > 1e-2, "the unscaled extrapolated start passed: {wrong:e}");

    // 4. The stress error at the current position: the band of the iGIMP stress rate fails.
    let wrong = stress_rate(true);
    eprintln!("stress error at x_p: fitted rate {wrong:.2} against the band 1.64 ± 0.25");
    assert!(
        (wrong - 1.64).abs() > 0.25,
        "the stress error at x_p passed the band: {wrong}"
    );
}
