use super::registry::{POISSON_RATIO, YOUNG_MODULUS};
use super::{ConstitutiveModel, MaterialError, MaterialResponse, MaterialState, ModelEntry};
use crate::material::kinematics::{spectral_map, sym_eigen};
use crate::material::tensor::{identity_outer, ij, Tensor4};
use crate::solver::error::InputError;
use nalgebra::{Matrix3, Vector3};

/// `model = "neo-hookean"`: [`NeoHookean`] with `young_modulus` and `poisson_ratio`.
pub static ENTRY: ModelEntry = ModelEntry {
    name: "neo-hookean",
    summary: "compressible neo-Hookean: W = μ/2 (tr C − 3) − μ ln J + λ/2 (ln J)², Kratos MPM's law",
    parameters: &[YOUNG_MODULUS, POISSON_RATIO],
    build: |m| {
        Ok(Box::new(NeoHookean::try_new(
            m.value("young_modulus"),
            m.value("poisson_ratio"),
        )?))
    },
};

/// Compressible neo-Hookean elasticity, `W = μ/2 (tr C − 3) − μ ln J + λ/2 (ln J)²`, so
/// `τ = λ ln J I + μ (b − I)`: the law Kratos' MPM application registers as
/// `HyperElasticNeoHookeanPlaneStrain2DLaw` / `…3DLaw` (its `HyperElastic3DLaw`, the 3D Lamé
/// constants in plane strain too; reference/README.md item 67), so that igimp's FEM on a
/// scene is a reference for Kratos' runs. In the log-strain form of the solvers, b = exp(2ε)
/// and ln J = tr ε.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NeoHookean {
    pub young_modulus: f64,
    pub poisson_ratio: f64,
}

impl NeoHookean {
    /// E > 0 and −1 < ν < 0.5, both finite.
    pub fn try_new(young_modulus: f64, poisson_ratio: f64) -> Result<Self, InputError> {
        // The same ranges as Hencky's: one check.
        super::LinearElastic::try_new(young_modulus, poisson_ratio)?;
        Ok(Self {
            young_modulus,
            poisson_ratio,
        })
    }
}

/// (e^{2a} − e^{2b}) / (a − b), stable as a → b (limit 2 e^{2a}).
#[inline]
fn exp2_divided_difference(a: f64, b: f64) -> f64 {
    let d = a - b;
    if d == 0.0 {
        2.0 * (2.0 * b).exp()
    } else {
        (2.0 * b).exp() * (2.0 * d).exp_m1() / d
    }
}

impl ConstitutiveModel for NeoHookean {
    fn update(
        &self,
        eps_trial: &Matrix3<f64>,
        committed: &MaterialState,
    ) -> Result<MaterialResponse, MaterialError> {
        let (lambda, mu) = super::lame(self.young_modulus, self.poisson_ratio);
        let (e, q) = sym_eigen(eps_trial);
        let b = spectral_map(&e, &q, |x| (2.0 * x).exp());
        let tau = Matrix3::identity() * (lambda * eps_trial.trace()) + (b - Matrix3::identity()) * mu;
        Ok(MaterialResponse {
            tau,
            eps_e: *eps_trial,
            internal: committed.internal,
        })
    }

    /// λ I ⊗ I + μ ∂exp(2ε)/∂ε, the second by the Daleckii–Krein formula (as
    /// [`crate::material::kinematics::dlog`]), symmetrised in its last pair.
    fn tangent(&self, eps_trial: &Matrix3<f64>, _committed: &MaterialState) -> Tensor4 {
        let (lambda, mu) = super::lame(self.young_modulus, self.poisson_ratio);
        let (e, q): (Vector3<f64>, Matrix3<f64>) = sym_eigen(eps_trial);
        let theta = Matrix3::from_fn(|a, b| exp2_divided_difference(e[a], e[b]));
        let mut d = identity_outer() * lambda;
        for m in 0..3 {
            for n in 0..3 {
                for p in 0..3 {
                    for r in 0..3 {
                        let mut s = 0.0;
                        for a in 0..3 {
                            for b in 0..3 {
                                s += 0.5
                                    * theta[(a, b)]
                                    * q[(m, a)]
                                    * q[(n, b)]
                                    * (q[(p, a)] * q[(r, b)] + q[(r, a)] * q[(p, b)]);
                            }
                        }
                        d[(ij(m, n), ij(p, r))] += mu * s;
                    }
                }
            }
        }
        d
    }

    fn young_modulus(&self) -> f64 {
        self.young_modulus
    }
}
