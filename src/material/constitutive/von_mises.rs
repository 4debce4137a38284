use super::linear_elastic::lame;
use super::registry::{Parameter, POISSON_RATIO, YOUNG_MODULUS};
use super::{
    ConstitutiveModel, InternalVariable, InternalVariables, MaterialError, MaterialResponse, MaterialState,
    ModelEntry,
};
use crate::material::tensor::{deviator, identity_outer, identity_sym, outer, Tensor4};
use crate::solver::error::InputError;
use nalgebra::Matrix3;

/// `model = "von-mises"`: [`VonMises`] with `young_modulus`, `poisson_ratio` and
/// `yield_stress`.
pub static ENTRY: ModelEntry = ModelEntry {
    name: "von-mises",
    summary: "von Mises perfect plasticity on the Kirchhoff stress, Hencky elasticity, eqs (48)-(49)",
    parameters: &[
        YOUNG_MODULUS,
        POISSON_RATIO,
        Parameter {
            name: "yield_stress",
            unit: "Pa",
            meaning: "yield stress ρ_y on ρ = √(3 J2) of the Kirchhoff stress, > 0",
        },
    ],
    build: |m| {
        Ok(Box::new(VonMises::try_new(
            m.value("young_modulus"),
            m.value("poisson_ratio"),
            m.value("yield_stress"),
        )?))
    },
};

/// Von Mises' internal variable: the accumulated plastic multiplier Σ Δγ, which with this
/// return map's normalisation equals the equivalent plastic strain √(2/3) Σ |Δε^p|.
pub const PLASTIC_MULTIPLIER: InternalVariable = InternalVariable {
    name: "plastic_multiplier",
    initial: 0.0,
    meaning: "accumulated plastic multiplier (equivalent plastic strain), 0 where the point never yielded",
};

/// Von Mises perfect plasticity in Kirchhoff stress / logarithmic strain space, eqs (48)–(49):
/// f = ρ − ρ_y with ρ = √(3 J2) of the Kirchhoff stress, linear elasticity (eq 14) and
/// associated flow integrated by backward Euler. With the exponential map of the plastic flow
/// the return map is the small-strain radial return applied to the trial log strain
/// (paper §3; de Souza Neto et al. 2008, §14.4).
///
/// Return map: with s_t = dev τ_t and ρ_t = √(3/2)|s_t| > ρ_y, the plastic multiplier is
/// Δγ = (ρ_t − ρ_y)/(3G), s = (ρ_y/ρ_t) s_t and ε^e = ε_t − Δγ (3/2) s_t/ρ_t.
///
/// Consistent tangent (perfect plasticity), derived by differentiating the return map:
/// D^alg = K 1⊗1 + 2G (ρ_y/ρ_t) (I_dev − n⊗n), n = s_t/|s_t|; checked against central
/// differences in the tests.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VonMises {
    pub young_modulus: f64,
    pub poisson_ratio: f64,
    /// Yield stress ρ_y on the measure ρ = √(3 J2).
    pub yield_stress: f64,
    bulk: f64,
    shear: f64,
    d_elastic: Tensor4,
    /// K 1 ⊗ 1 and I_dev, the plastic tangent's constant parts, formed once.
    bulk_outer: Tensor4,
    i_dev: Tensor4,
}

impl VonMises {
    /// E > 0, −1 < ν < 0.5 and ρ_y > 0, all finite.
    pub fn try_new(young_modulus: f64, poisson_ratio: f64, yield_stress: f64) -> Result<Self, InputError> {
        let elastic = super::LinearElastic::try_new(young_modulus, poisson_ratio)?;
        if !(yield_stress.is_finite() && yield_stress > 0.0) {
            return Err(InputError::new(
                "material.yield_stress",
                yield_stress,
                "must be finite and > 0",
            ));
        }
        let (lambda, mu) = lame(young_modulus, poisson_ratio);
        Ok(Self {
            young_modulus,
            poisson_ratio,
            yield_stress,
            bulk: lambda + 2.0 * mu / 3.0,
            shear: mu,
            d_elastic: *elastic.stiffness(),
            bulk_outer: identity_outer() * (lambda + 2.0 * mu / 3.0),
            i_dev: identity_sym() - identity_outer() * (1.0 / 3.0),
        })
    }

    /// Yield function f = ρ − ρ_y, eq (48), of a Kirchhoff stress.
    pub fn yield_function(&self, tau: &Matrix3<f64>) -> f64 {
        let s = deviator(tau);
        (1.5 * s.norm_squared()).sqrt() - self.yield_stress
    }
}

impl ConstitutiveModel for VonMises {
    fn update(
        &self,
        eps_trial: &Matrix3<f64>,
        committed: &MaterialState,
    ) -> Result<MaterialResponse, MaterialError> {
        let (k, g) = (self.bulk, self.shear);
        let vol = eps_trial.trace();
        let s_trial = deviator(eps_trial) * (2.0 * g);
        let norm_s = s_trial.norm();
        let rho_trial = (1.5f64).sqrt() * norm_s;
        let p = k * vol;
        if rho_trial <= self.yield_stress {
            return Ok(MaterialResponse {
                tau: s_trial + Matrix3::identity() * p,
                eps_e: *eps_trial,
                internal: InternalVariables::from_slice(&[committed.internal.get(0)]),
            });
        }
        let dgamma = (rho_trial - self.yield_stress) / (3.0 * g);
        let ratio = self.yield_stress / rho_trial;
        let s = s_trial * ratio;
        let eps_e = eps_trial - s_trial * (1.5 * dgamma / rho_trial);
        if !eps_e.iter().all(|v| v.is_finite()) {
            return Err(MaterialError(
                "von Mises return map produced a non-finite strain".into(),
            ));
        }
        Ok(MaterialResponse {
            tau: s + Matrix3::identity() * p,
            eps_e,
            internal: InternalVariables::from_slice(&[committed.internal.get(0) + dgamma]),
        })
    }

    fn tangent(&self, eps_trial: &Matrix3<f64>, _committed: &MaterialState) -> Tensor4 {
        let g = self.shear;
        let s_trial = deviator(eps_trial) * (2.0 * g);
        let norm_s = s_trial.norm();
        let rho_trial = (1.5f64).sqrt() * norm_s;
        if rho_trial <= self.yield_stress {
            return self.d_elastic;
        }
        let ratio = self.yield_stress / rho_trial;
        let n = s_trial / norm_s;
        self.bulk_outer + (self.i_dev - outer(&n, &n)) * (2.0 * g * ratio)
    }

    fn young_modulus(&self) -> f64 {
        self.young_modulus
    }

    fn internal_variables(&self) -> &'static [InternalVariable] {
        &[PLASTIC_MULTIPLIER]
    }
}
