//! Constitutive models in log-strain / Kirchhoff-stress space (eq 14), shared unchanged by
//! the material point solvers and the finite element comparators.
//!
//! The boundary sits where the paper puts it: a model receives the *trial* elastic
//! logarithmic strain (eq 19) and the committed state of the previous converged load step,
//! and returns the Kirchhoff stress, the updated elastic strain and the algorithmic tangent
//! `D^alg = ∂τ/∂ε^e_trial`. The finite-deformation wrapping (eqs 15–19, 25) lives in
//! [`crate::material::kinematics`], once for every model. Updates are pure functions: committing
//! happens in the solver after Newton converges.

mod linear_elastic;
mod von_mises;

pub use linear_elastic::{lame, LinearElastic};
pub use von_mises::VonMises;

use crate::material::tensor::Tensor4;
use crate::solver::error::InputError;
use nalgebra::Matrix3;
use serde::{Deserialize, Serialize};

/// Committed constitutive state of one material or Gauss point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MaterialState {
    /// Elastic logarithmic strain ε^e of the last converged step.
    pub eps_e: Matrix3<f64>,
    /// Elastic left Cauchy–Green tensor b^e = exp(2 ε^e), eq (18), kept to avoid recomputing it.
    pub b_e: Matrix3<f64>,
    /// Accumulated plastic multiplier (equivalent plastic strain measure), 0 for elastic models.
    pub plastic_multiplier: f64,
}

impl Default for MaterialState {
    fn default() -> Self {
        Self {
            eps_e: Matrix3::zeros(),
            b_e: Matrix3::identity(),
            plastic_multiplier: 0.0,
        }
    }
}

/// What a stress update returns.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MaterialResponse {
    /// Kirchhoff stress τ.
    pub tau: Matrix3<f64>,
    /// Updated elastic logarithmic strain.
    pub eps_e: Matrix3<f64>,
    /// Updated accumulated plastic multiplier.
    pub plastic_multiplier: f64,
}

/// A stress update failed (e.g. the return map did not converge).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{0}")]
pub struct MaterialError(pub String);

/// A constitutive model in log-strain / Kirchhoff space.
pub trait ConstitutiveModel: Send + Sync {
    /// Stress update from the trial elastic log strain and the committed state. Pure.
    fn update(
        &self,
        eps_trial: &Matrix3<f64>,
        committed: &MaterialState,
    ) -> Result<MaterialResponse, MaterialError>;

    /// Algorithmic tangent D^alg = ∂τ/∂ε^e_trial consistent with [`Self::update`] at the same
    /// arguments. Separate from the update so that residual-only evaluations (and the stored
    /// trial states, 648 bytes less per point) do not carry it.
    fn tangent(&self, eps_trial: &Matrix3<f64>, committed: &MaterialState) -> Tensor4;

    /// Whether [`Self::tangent`] reads its trial strain. A model whose tangent is a constant
    /// (linear elasticity) says no, and the assembly skips the trial strain's spectral
    /// logarithm (three `ln` and a spectral product per point and tangent), passing zeros.
    fn tangent_reads_strain(&self) -> bool {
        true
    }

    /// The elastic Young's modulus E: the stiffness scale of stabilisation terms
    /// ([`crate::discretise::ghost`]), which must not depend on the state so that they stay quadratic.
    fn young_modulus(&self) -> f64;
}

/// The models igimp ships, selectable from study files.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "model", rename_all = "kebab-case", deny_unknown_fields)]
pub enum Material {
    /// Linear elasticity in principal logarithmic strain (Hencky), eq (14).
    LinearElastic { young_modulus: f64, poisson_ratio: f64 },
    /// Von Mises perfect plasticity on the Kirchhoff stress, eqs (48)–(49).
    VonMises {
        young_modulus: f64,
        poisson_ratio: f64,
        yield_stress: f64,
    },
}

/// Linear elasticity, or von Mises plasticity when a yield stress is given: the material of
/// every example in the paper.
pub fn elastic_or_von_mises(
    young_modulus: f64,
    poisson_ratio: f64,
    yield_stress: Option<f64>,
) -> Result<Box<dyn ConstitutiveModel>, InputError> {
    match yield_stress {
        None => Ok(Box::new(LinearElastic::try_new(young_modulus, poisson_ratio)?)),
        Some(ry) => Ok(Box::new(VonMises::try_new(young_modulus, poisson_ratio, ry)?)),
    }
}

impl Material {
    /// Validate the parameters and build the model.
    pub fn build(&self) -> Result<Box<dyn ConstitutiveModel>, InputError> {
        match *self {
            Material::LinearElastic {
                young_modulus,
                poisson_ratio,
            } => Ok(Box::new(LinearElastic::try_new(young_modulus, poisson_ratio)?)),
            Material::VonMises {
                young_modulus,
                poisson_ratio,
                yield_stress,
            } => Ok(Box::new(VonMises::try_new(
                young_modulus,
                poisson_ratio,
                yield_stress,
            )?)),
        }
    }
}
