//! The manufactured solutions' ingredients: F in closed form against automatic
//! differentiation of the motion, the Hencky stress against the library's own model, the body
//! force b₀ = −Div P against central differences of P, det F = 1 for the vortex, and b₀ = 0
//! where the vortex does not move.

use igimp::material::constitutive::{ConstitutiveModel, LinearElastic, MaterialState};
use igimp::material::kinematics::log_strain;
use igimp::problems::manufactured::{deformation_gradient, motion, Exact, Field, ManufacturedSpec};
use nalgebra::Matrix3;
use num_dual::Dual64;

/// Points inside the square, off any symmetry line, inside and outside the vortex core.
const POINTS: [[f64; 2]; 6] = [
    [0.13, 0.27],
    [0.41, 0.66],
    [0.5, 0.31],
    [0.77, 0.58],
    [0.92, 0.08],
    [0.3, 0.9],
];

fn exact(field: Field) -> Exact {
    Exact::of(&ManufacturedSpec {
        field,
        amplitude: if field == Field::Vortex { 0.6 } else { 0.1 },
        ..ManufacturedSpec::default()
    })
}

/// F_iJ = ∂x_i/∂X_J by dual numbers equals the closed form to round-off (1e-13).
#[test]
#[allow(clippy::needless_range_loop)] // index notation F_iJ
fn deformation_gradient_is_the_derivative_of_the_motion() {
    for field in [Field::AxisAligned, Field::Vortex] {
        let e = exact(field);
        for x in POINTS {
            let f = deformation_gradient(field, e.amplitude, x);
            for jj in 0..2 {
                let xd = [
                    Dual64::new(x[0], (jj == 0) as u8 as f64),
                    Dual64::new(x[1], (jj == 1) as u8 as f64),
                ];
                let m = motion(field, e.amplitude, xd);
                for i in 0..2 {
                    assert!((m[i].eps - f[i][jj]).abs() < 1e-13, "{field:?} {x:?} F{i}{jj}");
                }
            }
            if field == Field::Vortex {
                let det = f[0][0] * f[1][1] - f[0][1] * f[1][0];
                assert!((det - 1.0).abs() < 1e-13, "det F = {det}");
            }
        }
    }
}

/// The closed-form Hencky stress (smooth ln b) equals the library's LinearElastic update on
/// ε = ½ ln(F Fᵀ) from its own spectral log (plane strain), to 1e-13 relative.
#[test]
fn hencky_stress_matches_the_library_model() {
    let model = LinearElastic::try_new(1.0, 0.3).unwrap();
    for field in [Field::AxisAligned, Field::Vortex] {
        let e = exact(field);
        for x in POINTS {
            let f = deformation_gradient(field, e.amplitude, x);
            let f3 = Matrix3::new(f[0][0], f[0][1], 0.0, f[1][0], f[1][1], 0.0, 0.0, 0.0, 1.0);
            // `log_strain` is ε = ½ ln b.
            let eps = log_strain(&(f3 * f3.transpose())).unwrap();
            let tau = model.update(&eps, &MaterialState::default()).unwrap().tau;
            let sigma = e.cauchy(x);
            let lib = tau / f3.determinant();
            assert!(
                (sigma - lib).norm() <= 1e-13 * lib.norm().max(1e-3),
                "{field:?} {x:?}: {sigma} vs {lib}"
            );
        }
    }
}

/// Div P by automatic differentiation against fourth-order central differences of P
/// (step 1e-3: truncation ~1e-12, round-off ~1e-13), relative 1e-9 of |Div P|.
#[test]
fn body_force_matches_central_differences_of_p() {
    for field in [Field::AxisAligned, Field::Vortex] {
        let e = exact(field);
        // Vortex: the points inside its core (outside, b₀ = 0: the test below).
        let inside = |x: &[f64; 2]| field == Field::AxisAligned || (x[0] - 0.5).hypot(x[1] - 0.5) < 0.45;
        for x in POINTS.into_iter().filter(inside) {
            let ad = e.div_first_piola(x);
            let h = 1e-3;
            let mut fd = [0.0; 2];
            for jj in 0..2 {
                let at = |s: f64| {
                    let mut y = x;
                    y[jj] += s * h;
                    e.first_piola(y)
                };
                let (p2, p1, m1, m2) = (at(2.0), at(1.0), at(-1.0), at(-2.0));
                for (i, d) in fd.iter_mut().enumerate() {
                    *d += (-p2[i][jj] + 8.0 * p1[i][jj] - 8.0 * m1[i][jj] + m2[i][jj]) / (12.0 * h);
                }
            }
            let scale = ad[0].hypot(ad[1]).max(1e-12);
            for i in 0..2 {
                assert!(
                    (ad[i] - fd[i]).abs() <= 1e-8 * scale,
                    "{field:?} {x:?}: {ad:?} vs {fd:?}"
                );
            }
            assert!(
                scale > 1e-3,
                "{field:?} {x:?}: a body force this small tests nothing"
            );
        }
    }
}

/// Outside the vortex core (r > ½) nothing moves: F = I, P = 0, b₀ = 0.
#[test]
fn vortex_is_still_outside_its_core() {
    let e = exact(Field::Vortex);
    for x in [[0.02, 0.03], [0.97, 0.96], [0.05, 0.95]] {
        let p = e.position(x);
        assert!(
            (p[0] - x[0]).abs() < 1e-15 && (p[1] - x[1]).abs() < 1e-15,
            "{p:?}"
        );
        assert_eq!(e.body_force(x), [0.0, 0.0]);
    }
}

/// The exact field's own residual: the manufactured displacement interpolated at the FEM
/// nodes (iGIMP, MPM: the grid nodes), fed to the internal force at the full load from the
/// undeformed state, leaves ‖f_int − f_ext‖ / ‖f_ext‖ that
/// converges with h at a fitted order (h = 1/8, 1/16, 1/32), which checks b₀ and its
/// quadrature together (a wrong b₀ would leave an O(1) residual). Measured 2026-12-01, at
/// h = 1/8, 1/16, 1/32: axis-aligned Q4 6.65e-3, 1.76e-3, 4.45e-4 (slope 1.95), Q8 3.56e-3,
/// 9.22e-4, 2.33e-4 (1.97); vortex Q4 1.08e-1, 3.64e-2, 1.20e-2 (1.58), Q8 1.03e-1, 3.39e-2,
/// 1.08e-2 (1.63, pre-asymptotic like its displacement); iGIMP and MPM (2×2 points) 9.77e-3,
/// 2.52e-3, 6.34e-4 (1.97) and 1.17e-1, 3.68e-2, 1.23e-2 (1.63), the same for both because the
/// undeformed domains lie inside their cells, where GIMP weights equal MPM's. Bands: the
/// measured slopes ± 0.3.
#[test]
fn exact_field_residual_converges() {
    use igimp::basis::method::Method;
    use igimp::problems::manufactured::{fem_solver, mpm_solver};
    use igimp::solver::newton::{NonlinearSystem, ResidualNorm};
    let residual = |field: Field, method: Method, n: usize| -> f64 {
        let spec = ManufacturedSpec {
            field,
            amplitude: if field == Field::Vortex { 0.6 } else { 0.1 },
            cells: n,
            ..ManufacturedSpec::default()
        };
        let e = Exact::of(&spec);
        let at = |x: [f64; 2]| {
            let y = e.position(x);
            [y[0] - x[0], y[1] - x[1]]
        };
        let norm = |sys: &mut igimp::discretise::assembly::LoadStepSystem<'_, 2>, nodal: &[f64]| {
            let mut u = vec![0.0; sys.num_unknowns()];
            sys.dofs.gather(nodal, &mut u);
            let mut r = vec![0.0; u.len()];
            sys.evaluate(&u, &mut r).unwrap();
            r.iter().map(|x| x * x).sum::<f64>().sqrt() / sys.reference_norm(ResidualNorm::External)
        };
        if method.uses_material_points() {
            let mut s = mpm_solver(&spec, method).unwrap();
            let nodal: Vec<f64> = (0..s.grid.num_nodes())
                .flat_map(|k| {
                    let x = s.grid.node_position(k);
                    at([x[0], x[1]])
                })
                .collect();
            s.with_step_system(1.0, |sys| norm(sys, &nodal)).unwrap()
        } else {
            let mut fem = fem_solver(&spec, method).unwrap();
            let nodal: Vec<f64> = fem.mesh0.nodes.iter().flat_map(|x| at([x[0], x[1]])).collect();
            fem.with_step_system(1.0, |sys| norm(sys, &nodal)).unwrap()
        }
    };
    let mut report = vec![];
    for (field, method, expected) in [
        (Field::AxisAligned, Method::FEM_Q4, 1.95),
        (Field::AxisAligned, Method::FEM_Q8, 1.97),
        (Field::Vortex, Method::FEM_Q4, 1.58),
        (Field::Vortex, Method::FEM_Q8, 1.63),
        (Field::AxisAligned, Method::IGIMP, 1.97),
        (Field::Vortex, Method::IGIMP, 1.63),
        (Field::AxisAligned, Method::MPM, 1.97),
        (Field::Vortex, Method::MPM, 1.63),
    ] {
        let r: Vec<f64> = [8, 16, 32].iter().map(|&n| residual(field, method, n)).collect();
        let h = [1.0 / 8.0, 1.0 / 16.0, 1.0 / 32.0];
        let slope = igimp::problems::norms::fitted_rate(&h, &r).unwrap();
        report.push(format!(
            "{field:?} {method:?}: {:.3e} {:.3e} {:.3e} slope {slope:.2}",
            r[0], r[1], r[2]
        ));
        assert!(r[2] < 0.02, "{report:?}");
        assert!((slope - expected).abs() <= 0.3, "{report:?}");
    }
}

// ---------------------------------------------------------------------------------------------
// 3D (reference/README.md item 31)

/// The 3D fields: F against automatic differentiation of the motion, σ against the library's
/// stress update at that F, and b₀ against 4th-order central differences of P, at random
/// points of the unit cube.
#[test]
fn manufactured_3d_exact_solution_is_consistent() {
    use igimp::problems::manufactured3d::Exact3;
    let mut rng = crate::common::Rng::new(31);
    for (field, a) in [(Field::AxisAligned, 0.1), (Field::Vortex, 0.6)] {
        let spec = ManufacturedSpec {
            field,
            amplitude: a,
            ..ManufacturedSpec::default()
        };
        let exact = Exact3::of(&spec);
        let model = spec.model().unwrap();
        for _ in 0..10 {
            let x: [f64; 3] = std::array::from_fn(|_| rng.uniform(0.05, 0.95));
            let f = exact.deformation_gradient(x);
            let h = 1e-6;
            for j in 0..3 {
                let mut xp = x;
                let mut xm = x;
                xp[j] += h;
                xm[j] -= h;
                let (pp, pm) = (exact.position(xp), exact.position(xm));
                for i in 0..3 {
                    let fd = (pp[i] - pm[i]) / (2.0 * h);
                    assert!((fd - f[(i, j)]).abs() < 1e-8, "{field:?} F[{i}{j}]");
                }
            }
            // `log_strain` is ε = ½ ln b.
            let eps = log_strain(&(f * f.transpose())).unwrap();
            let tau = model.update(&eps, &MaterialState::default()).unwrap().tau;
            let sigma = exact.cauchy(x);
            assert!(
                (tau / f.determinant() - sigma).amax() < 1e-12 * sigma.amax().max(1.0),
                "{field:?} σ"
            );
            let b = exact.body_force(x);
            let h = 1e-3;
            for (i, &bi) in b.iter().enumerate() {
                let mut div = 0.0;
                for j in 0..3 {
                    let at = |d: f64| {
                        let mut y = x;
                        y[j] += d;
                        exact.first_piola(y)[(i, j)]
                    };
                    div += (-at(2.0 * h) + 8.0 * at(h) - 8.0 * at(-h) + at(-2.0 * h)) / (12.0 * h);
                }
                assert!((bi + div).abs() < 1e-8, "{field:?} b0[{i}] = {bi} vs {}", -div);
            }
        }
    }
}

/// The vortex about z is plane strain: the 3D iGIMP run on the unit cube (8³ cells, 2×2×2
/// points) gives the 2D run's errors to round-off (measured 2026-12-01: 3e-16 and 5e-15
/// relative).
#[test]
fn manufactured_3d_vortex_equals_the_plane_strain_run() {
    use igimp::basis::method::Method;
    use igimp::problems::manufactured::solve;
    use igimp::problems::manufactured3d::solve_3d;
    let spec = ManufacturedSpec {
        field: Field::Vortex,
        amplitude: 0.6,
        cells: 8,
        ..ManufacturedSpec::default()
    };
    let cube = ManufacturedSpec { dimension: 3, ..spec };
    let (e3, e2) = (
        solve_3d(&cube, Method::IGIMP).unwrap().errors.unwrap(),
        solve(&spec, Method::IGIMP).unwrap().errors.unwrap(),
    );
    for (a, b) in [(e3.displacement, e2.displacement), (e3.stress, e2.stress)] {
        assert!((a / b - 1.0).abs() < 1e-12, "3D {a:e} against 2D {b:e}");
    }
}

/// The same for every material point family (CPDI2, both B-splines, TLMPM, MPM) on 4³ cells:
/// the 3D vortex is the plane-strain one, so each family's 3D weights, gradients, corner or
/// reference update and tangent reduce to its 2D ones (measured 2026-12-03 with the study
/// runs at 4³ and 8³: at most 3e-15 relative).
#[test]
fn every_family_3d_vortex_equals_the_plane_strain_run() {
    use igimp::basis::method::Method;
    use igimp::problems::manufactured::solve;
    use igimp::problems::manufactured3d::solve_3d;
    let spec = ManufacturedSpec {
        field: Field::Vortex,
        amplitude: 0.6,
        cells: 4,
        ..ManufacturedSpec::default()
    };
    let cube = ManufacturedSpec { dimension: 3, ..spec };
    for m in Method::MATERIAL_POINT {
        if m == Method::IGIMP {
            continue; // the test above, on 8³ cells
        }
        let (e3, e2) = (
            solve_3d(&cube, m).unwrap().errors.unwrap(),
            solve(&spec, m).unwrap().errors.unwrap(),
        );
        for (a, b) in [(e3.displacement, e2.displacement), (e3.stress, e2.stress)] {
            assert!(
                (a / b - 1.0).abs() < 1e-12,
                "{}: 3D {a:e} against 2D {b:e}",
                m.name()
            );
        }
    }
}

// The 3D rates (Hex8, Hex20 at their textbook orders, iGIMP's measured slopes) are the
// checks of studies/manufactured-3d.toml, asserted by tests/studies/manufactured3d_study.rs.
