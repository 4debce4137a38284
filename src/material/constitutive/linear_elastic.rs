use super::registry::{POISSON_RATIO, YOUNG_MODULUS};
use super::{ConstitutiveModel, MaterialError, MaterialResponse, MaterialState, ModelEntry};
use crate::material::tensor::{identity_outer, identity_sym, Tensor4};
use crate::solver::error::InputError;
use nalgebra::Matrix3;

/// `model = "linear-elastic"`: [`LinearElastic`] with `young_modulus` and `poisson_ratio`.
pub static ENTRY: ModelEntry = ModelEntry {
    name: "linear-elastic",
    summary: "Hencky elasticity: Kirchhoff stress linear in the elastic logarithmic strain, eq (14)",
    parameters: &[YOUNG_MODULUS, POISSON_RATIO],
    build: |m| {
        Ok(Box::new(LinearElastic::try_new(
            m.value("young_modulus"),
            m.value("poisson_ratio"),
        )?))
    },
};

/// Isotropic linear elasticity between Kirchhoff stress and elastic log strain, eq (14):
/// `τ = λ tr(ε) I + 2μ ε` (Hencky). Works in 3D even for 1D and plane-strain problems, so
/// out-of-plane stresses follow from ν.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LinearElastic {
    /// Young's modulus E.
    pub young_modulus: f64,
    /// Poisson's ratio ν.
    pub poisson_ratio: f64,
    d: Tensor4,
}

impl LinearElastic {
    /// E > 0 and −1 < ν < 0.5, both finite.
    pub fn try_new(young_modulus: f64, poisson_ratio: f64) -> Result<Self, InputError> {
        if !(young_modulus.is_finite() && young_modulus > 0.0) {
            return Err(InputError::new(
                "material.young_modulus",
                young_modulus,
                "must be finite and > 0",
            ));
        }
        if !(poisson_ratio.is_finite() && poisson_ratio > -1.0 && poisson_ratio < 0.5) {
            return Err(InputError::new(
                "material.poisson_ratio",
                poisson_ratio,
                "must lie in the open interval (-1, 0.5)",
            ));
        }
        let (lambda, mu) = lame(young_modulus, poisson_ratio);
        let d = identity_outer() * lambda + identity_sym() * (2.0 * mu);
        Ok(Self {
            young_modulus,
            poisson_ratio,
            d,
        })
    }

    /// Elastic stiffness D^e_ijkl.
    pub fn stiffness(&self) -> &Tensor4 {
        &self.d
    }

    /// Lamé parameters (λ, μ).
    pub fn lame(&self) -> (f64, f64) {
        lame(self.young_modulus, self.poisson_ratio)
    }
}

/// Lamé parameters from Young's modulus and Poisson's ratio.
pub fn lame(e: f64, nu: f64) -> (f64, f64) {
    (e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu)), e / (2.0 * (1.0 + nu)))
}

impl ConstitutiveModel for LinearElastic {
    fn update(
        &self,
        eps_trial: &Matrix3<f64>,
        committed: &MaterialState,
    ) -> Result<MaterialResponse, MaterialError> {
        let (lambda, mu) = self.lame();
        let tau = Matrix3::identity() * (lambda * eps_trial.trace()) + eps_trial * (2.0 * mu);
        Ok(MaterialResponse {
            tau,
            eps_e: *eps_trial,
            internal: committed.internal,
        })
    }

    fn tangent(&self, _eps_trial: &Matrix3<f64>, _committed: &MaterialState) -> Tensor4 {
        self.d
    }

    fn tangent_reads_strain(&self) -> bool {
        false
    }

    fn young_modulus(&self) -> f64 {
        self.young_modulus
    }
}
