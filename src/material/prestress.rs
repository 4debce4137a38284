//! A point that starts stressed: the elastic state whose Kirchhoff stress is a given initial
//! stress (a surcharge's confinement, a geostatic start), with F = I. Every built-in model's
//! stress is a function of its elastic logarithmic strain ε^e and internal variables (eq 14),
//! so the state is ε^e with τ(ε^e) = τ₀, found by Newton on the model's own update and
//! tangent, and b^e = exp(2 ε^e) (eq 18). A stress the model would return from (outside its
//! elastic domain) is refused: it cannot be held elastically (reference/README.md item 77).

use crate::material::constitutive::{ConstitutiveModel, MaterialError, MaterialState};
use crate::material::kinematics::{left_cauchy_green_from_strain, PointState};
use crate::material::tensor::{flatten, identity_sym, unflatten, Tensor4};
use nalgebra::Matrix3;

/// Newton iterations allowed: Hencky's elasticity is linear in ε^e (one iteration); Cam-Clay's
/// pressure-dependent bulk modulus converges in a handful from ε^e = 0.
const MAX_ITERATIONS: usize = 50;

/// The state of volume `volume` at rest (F = I) whose Kirchhoff (= Cauchy) stress is `tau0`
/// under `model`, its internal variables the model's initial ones.
pub fn prestressed(
    model: &dyn ConstitutiveModel,
    tau0: &Matrix3<f64>,
    volume: f64,
) -> Result<PointState, MaterialError> {
    if !(tau0.iter().all(|v| v.is_finite()) && (tau0 - tau0.transpose()).norm() == 0.0) {
        return Err(MaterialError(format!(
            "the initial stress {:?} must be finite and symmetric",
            tau0.as_slice()
        )));
    }
    let mut committed = MaterialState::default();
    committed.initialise(model);
    // Converged at the stress's own precision, or at the round-off of a stress computed from
    // strains by a stiffness E (a neo-Hookean μ (exp(2ε) − 1) cancels to about E ε_mach).
    let tolerance = (1e-12 * tau0.norm()).max(64.0 * f64::EPSILON * model.young_modulus());
    let mut eps = Matrix3::zeros();
    let mut elastic_tangent: Option<Tensor4> = None;
    let mut elastic = true;
    for _ in 0..MAX_ITERATIONS {
        let response = model.update(&eps, &committed)?;
        elastic = response.internal == committed.internal
            && (response.eps_e - eps).norm() <= 1e-12 * eps.norm().max(f64::MIN_POSITIVE);
        let r = tau0 - response.tau;
        if elastic && r.norm() <= tolerance {
            return Ok(PointState {
                f: Matrix3::identity(),
                volume,
                tau: response.tau,
                material: MaterialState {
                    eps_e: eps,
                    b_e: left_cauchy_green_from_strain(&eps),
                    internal: committed.internal,
                },
            });
        }
        // Newton on the elastic law: an iterate the model returns from keeps the last elastic
        // tangent (a plastic one is singular on a perfectly plastic surface), and the stress
        // is refused if the iterates stay outside.
        if elastic {
            elastic_tangent = Some(model.tangent(&eps, &committed));
        }
        let Some(d) = elastic_tangent.as_ref() else {
            return Err(MaterialError(
                "the model returns from its unstrained state: no elastic state to start from".to_string(),
            ));
        };
        // D^alg acts on symmetric strains; the identity on the skew part makes it invertible
        // without changing the symmetric solution.
        let m: Tensor4 = d * identity_sym() + (Tensor4::identity() - identity_sym());
        let step = m.lu().solve(&flatten(&r)).ok_or_else(|| {
            MaterialError("the model's elastic tangent is singular at the initial stress".to_string())
        })?;
        let de = unflatten(&step);
        eps += (de + de.transpose()) * 0.5;
        if !eps.iter().all(|v| v.is_finite()) {
            break;
        }
    }
    if !elastic {
        return Err(MaterialError(format!(
            "the initial stress {:?} lies outside the model's elastic domain (the model returns from it)",
            tau0.as_slice()
        )));
    }
    Err(MaterialError(format!(
        "no elastic strain gives the initial stress {:?} (Newton on the model's update did not converge in {MAX_ITERATIONS} iterations)",
        tau0.as_slice()
    )))
}
