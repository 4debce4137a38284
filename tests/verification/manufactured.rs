//! The manufactured solutions' ingredients: F in closed form against automatic
//! differentiation of the motion, the Hencky stress against the library's own model, the body
//! force b₀ = −Div P against central differences of P, det F = 1 for the vortex, and b₀ = 0
//! where the vortex does not move.

use igimp::constitutive::{ConstitutiveModel, LinearElastic, MaterialState};
use igimp::kinematics::log_strain;
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
