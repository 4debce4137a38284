//! Von Mises perfect plasticity (eqs 48–49): return map, consistent tangent, objectivity,
//! the elasto-plastic column against the analytical solution derived in
//! `problems::column::AnalyticalColumn`, and Newton's convergence on it.

use crate::common;

use common::Rng;
use igimp::basis::Basis;
use igimp::material::constitutive::{ConstitutiveModel, Material, MaterialState, VonMises};
use igimp::material::kinematics::{evaluate_point, left_cauchy_green_from_strain, PointState};
use igimp::material::tensor::contract;
use igimp::problems::column::{solve_column, yield_height_estimate, ColumnSpec, Method};
use igimp::solver::load_stepping::LoadStepping;
use igimp::solver::newton::{check_quadratic, NewtonSettings};
use nalgebra::{Matrix2, Matrix3, SMatrix};

const RHO_Y: f64 = 3e4;

fn model() -> VonMises {
    VonMises::try_new(1e6, 0.3, RHO_Y).unwrap()
}

fn random_strain(rng: &mut Rng, size: f64) -> Matrix3<f64> {
    let a = Matrix3::from_fn(|_, _| rng.uniform(-size, size));
    0.5 * (a + a.transpose())
}

/// Plastic trial states return onto the yield surface (|f| ≤ 1e-10 ρ_y); elastic trial states
/// come back unchanged with the elastic stiffness.
#[test]
fn von_mises_return_map_lands_on_yield_surface_and_elastic_states_pass() {
    let m = model();
    let mut rng = Rng::new(51);
    let (mut plastic, mut elastic) = (0, 0);
    for _ in 0..500 {
        let size = rng.uniform(0.002, 0.06);
        let eps = random_strain(&mut rng, size);
        let r = m.update(&eps, &MaterialState::default()).unwrap();
        let f = m.yield_function(&r.tau);
        if r.internal.get(0) > 0.0 {
            plastic += 1;
            assert!(f.abs() <= 1e-10 * RHO_Y, "f = {f}");
            // Plastic flow is deviatoric: the volumetric strain is untouched.
            assert!((r.eps_e.trace() - eps.trace()).abs() < 1e-15);
        } else {
            elastic += 1;
            assert!(f <= 0.0);
            assert_eq!(r.eps_e, eps);
            let lin = igimp::material::constitutive::LinearElastic::try_new(1e6, 0.3).unwrap();
            assert_eq!(m.tangent(&eps, &MaterialState::default()), *lin.stiffness());
        }
    }
    assert!(
        plastic > 50 && elastic > 50,
        "plastic {plastic}, elastic {elastic}"
    );
}

/// D^alg matches central differences of the return map for elastic and plastic states
/// (≤ 1e-6 relative).
#[test]
fn von_mises_algorithmic_tangent_matches_central_differences() {
    let m = model();
    let mut rng = Rng::new(52);
    let state = MaterialState::default();
    let mut checked_plastic = 0;
    for _ in 0..100 {
        let eps = random_strain(&mut rng, 0.05);
        let r = m.update(&eps, &state).unwrap();
        let d_alg = m.tangent(&eps, &state);
        let elastic = igimp::material::constitutive::LinearElastic::try_new(1e6, 0.3).unwrap();
        let trial_margin = m.yield_function(&contract(elastic.stiffness(), &eps));
        if trial_margin.abs() < 1e-3 * RHO_Y {
            continue; // too close to the elastic/plastic kink for differences
        }
        if r.internal.get(0) > 0.0 {
            checked_plastic += 1;
        }
        let h = 1e-8;
        for k in 0..3 {
            for l in 0..3 {
                let mut d = Matrix3::zeros();
                d[(k, l)] += 0.5;
                d[(l, k)] += 0.5;
                let fd = (m.update(&(eps + d * h), &state).unwrap().tau
                    - m.update(&(eps - d * h), &state).unwrap().tau)
                    / (2.0 * h);
                let an = contract(&d_alg, &d);
                assert!(
                    (fd - an).amax() <= 1e-6 * d_alg.amax(),
                    "tangent mismatch: {fd} vs {an}"
                );
            }
        }
    }
    assert!(checked_plastic > 20);
}

/// Superposing a rigid rotation on the increment of a plastically deformed point rotates τ
/// and leaves the plastic multiplier unchanged.
#[test]
fn von_mises_update_is_objective_under_superposed_rotation() {
    let m = model();
    let mut rng = Rng::new(53);
    for _ in 0..20 {
        let mut state = PointState::undeformed(1.0);
        // A committed plastic state from a first increment.
        let g0 = SMatrix::<f64, 2, 2>::from_fn(|_, _| rng.uniform(-0.08, 0.08));
        let t0 = evaluate_point::<2>(&m, &state, &g0).unwrap();
        state = t0.committed(&state);
        assert_eq!(
            state.material.b_e,
            left_cauchy_green_from_strain(&state.material.eps_e)
        );
        let g = SMatrix::<f64, 2, 2>::from_fn(|_, _| rng.uniform(-0.08, 0.08));
        let t1 = evaluate_point::<2>(&m, &state, &g).unwrap();
        let th = rng.uniform(-3.0, 3.0);
        let q = Matrix2::new(th.cos(), -th.sin(), th.sin(), th.cos());
        let g2 = q * (Matrix2::identity() + g) - Matrix2::identity();
        let t2 = evaluate_point::<2>(&m, &state, &g2).unwrap();
        let mut q3 = Matrix3::identity();
        q3.fixed_view_mut::<2, 2>(0, 0).copy_from(&q);
        let rotated = q3 * t1.response.tau * q3.transpose();
        assert!((rotated - t2.response.tau).amax() < 1e-8 * RHO_Y);
        assert!((t1.response.internal.get(0) - t2.response.internal.get(0)).abs() < 1e-12);
    }
}

/// ρ_y ≤ 0 or NaN is an input error naming `material.yield_stress`.
#[test]
fn bad_yield_stress_is_an_error() {
    for ry in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        let e = VonMises::try_new(1e6, 0.0, ry).unwrap_err();
        assert!(e.field.contains("yield_stress"), "{e}");
        let spec = ColumnSpec {
            material: Material::von_mises(1e6, 0.0, ry),
            ..ColumnSpec::default()
        };
        assert!(solve_column(&spec, Method::IGIMP)
            .unwrap_err()
            .field
            .contains("yield_stress"));
    }
}

fn plastic_spec(weight: f64, elements: usize) -> ColumnSpec {
    ColumnSpec {
        weight,
        elements,
        material: Material::von_mises(1e6, 0.0, RHO_Y),
        ..ColumnSpec::default()
    }
}

/// The analytical elasto-plastic column agrees with the paper's eqs (51)–(54) for ν = 0 and
/// corrects its yield height: yield starts where the Kirchhoff τ_zz = −ρ_y, i.e. at
/// Z_y = L0 − ρ_y e^{ρ_y/E}/(ρ0 g) (11.358 for W = 40,000, 46.136 for W = 400,000), not the
/// paper's L0 − ρ_y/(ρ0 g) (12.5, 46.25).
#[test]
fn analytical_plastic_column_matches_eqs_51_to_54_with_corrected_yield_height() {
    for (w, zy) in [(40_000.0, 11.357955), (400_000.0, 46.135795)] {
        let a = plastic_spec(w, 10).analytical();
        let g = w / (80.0 * 50.0);
        let expected = 50.0 - RHO_Y * (RHO_Y / 1e6f64).exp() / (80.0 * g);
        assert!((a.yield_height().unwrap() - expected).abs() < 1e-9);
        assert!((expected - zy).abs() < 1e-6);
        for z in [0.0, 0.3 * zy, 0.9 * zy] {
            let f = a.deformation_gradient(z);
            // Eq (52)-(53): F = (F^e_zz)^3 e^{2ρ_y/E}, σ_zz = E ln F^e_zz / F.
            let fe_zz = (f / (2.0 * RHO_Y / 1e6f64).exp()).cbrt();
            assert!((1e6 * fe_zz.ln() / f - a.stress(z)).abs() < 1e-6 * a.stress(0.0).abs());
            // Eq (51), (54): F^e_xx = F^e_zz e^{ρ_y/E}, σ_xx = E ln F^e_xx / F_zz.
            let fe_xx = fe_zz * (RHO_Y / 1e6f64).exp();
            assert!((1e6 * fe_xx.ln() / f - a.lateral_stress(z)).abs() < 1e-6 * a.stress(0.0).abs());
        }
        // Above the yield height the column is elastic: no lateral stress for ν = 0.
        assert!(a.lateral_stress(0.5 * (zy + 50.0)).abs() < 1e-9);
    }
}

/// Newton reaches quadratic convergence on the plastic column (same criterion as the elastic
/// column: r_{k+1} ≤ 1.0·r_k² once r_k ≤ 1e-3, above the round-off floor). The floor is
/// 1e-10 here: at W = 40,000 the residual, normalised by a ten times smaller external force,
/// stagnates at ≈ 1e-11 (measured by iterating past convergence).
#[test]
fn newton_converges_quadratically_on_the_plastic_column() {
    let mut checks = 0;
    for w in [40_000.0, 400_000.0] {
        let spec = ColumnSpec {
            newton: NewtonSettings {
                tolerance: 1e-10,
                max_iterations: 30,
                line_search: false,
                ..Default::default()
            },
            ..plastic_spec(w, 256)
        };
        let mut solver = spec.mpm_solver(Basis::Gimp).unwrap();
        for s in solver.run().unwrap() {
            let c = check_quadratic(&s.newton.residuals, 1e-3, 1e-10, 1.0, 1.8)
                .unwrap_or_else(|e| panic!("W = {w}, step {}: {e}", s.step));
            checks += c.ratio_checks;
            assert!(
                s.newton.iterations() <= 8,
                "step {}: {:?}",
                s.step,
                s.newton.residuals
            );
        }
    }
    // Guards against a vacuous pass (measured: 17 checks).
    assert!(checks >= 10, "only {checks} checks");
}

/// Refinement, W = 400,000, iGIMP, 2 points per element, 64–2048 elements: the σ_zz and σ_xx
/// errors (eq 46 applied to each) decrease at every level, and the computed yield height
/// (`yield_height_estimate`) converges to the corrected analytical 46.1358 — away from the
/// paper's 46.25. Measured errors: 2.1e-2, 3.2e-2, 1.2e-2, 1.6e-2, 4.2e-3, 1.5e-3 (fitted
/// rate 0.88; largest error 0.16 h at 512 elements); asserted: every error ≤ 0.25 h and a fitted
/// rate ≥ 0.7.
#[test]
fn gimp_plastic_column_converges_to_analytical_solution() {
    let levels = [64usize, 128, 256, 512, 1024, 2048];
    let (mut hs, mut zy_errs) = (vec![], vec![]);
    let mut prev: Option<(f64, f64)> = None;
    let mut last_zy = 0.0;
    for n in levels {
        let spec = plastic_spec(400_000.0, n);
        let o = solve_column(&spec, Method::IGIMP).unwrap();
        assert!(o.failure.is_none());
        let a = spec.analytical();
        let sxx_err: f64 = o
            .points
            .iter()
            .map(|p| (a.lateral_stress(p.z0) - p.sigma_xx).abs() * p.volume0)
            .sum::<f64>()
            / (spec.weight * spec.length);
        let zy_h = yield_height_estimate(&o.points, RHO_Y).unwrap();
        let zy_err = (zy_h - a.yield_height().unwrap()).abs();
        let h = spec.length / n as f64;
        eprintln!("n={n}: sigma_zz error {:.3e}, sigma_xx error {sxx_err:.3e}, yield height {zy_h:.5} (error {zy_err:.2e})", o.stress_error);
        assert!(zy_err <= 0.25 * h, "n={n}: yield height error {zy_err} > 0.25 h");
        if let Some((se, xe)) = prev {
            assert!(o.stress_error < 0.75 * se, "sigma_zz error not decreasing");
            assert!(sxx_err < 0.75 * xe, "sigma_xx error not decreasing");
        }
        prev = Some((o.stress_error, sxx_err));
        hs.push(h);
        zy_errs.push(zy_err);
        last_zy = zy_h;
    }
    let rate = igimp::problems::norms::fitted_rate(&hs, &zy_errs).unwrap();
    assert!(rate >= 0.7, "yield height convergence rate {rate}");
    assert!(
        (last_zy - 46.25).abs() > 50.0 * zy_errs[zy_errs.len() - 1],
        "converges to the paper's yield height?"
    );
}
