//! Constitutive models in log-strain / Kirchhoff-stress space (eq 14), shared unchanged by
//! the material point solvers and the finite element comparators.
//!
//! The boundary sits where the paper puts it: a model receives the *trial* elastic
//! logarithmic strain (eq 19) and the committed state of the previous converged load step,
//! and returns the Kirchhoff stress, the updated elastic strain, its internal variables and the
//! algorithmic tangent `D^alg = ∂τ/∂ε^e_trial`. The finite-deformation wrapping (eqs 15–19, 25)
//! lives in [`crate::material::kinematics`], once for every model. Updates are pure functions:
//! committing happens in the solver after Newton converges.
//!
//! Models are chosen by name from the [`registry`]: a [`Material`] is a model's name and its
//! parameters (a study file's `[material]` table), [`Material::build`] makes the model. A new
//! model is one file (its [`ConstitutiveModel`] impl and its [`ModelEntry`]) and one row of
//! [`registry::BUILT_IN`], or, outside the crate, one [`registry::register`] call
//! (`examples/hardening_von_mises.rs`).

mod cam_clay;
mod drucker_prager;
mod friction;
mod linear_elastic;
mod mohr_coulomb;
mod neo_hookean;
pub mod registry;
mod von_mises;

pub use cam_clay::{ModifiedCamClay, ENTRY as MODIFIED_CAM_CLAY, PLASTIC_VOLUMETRIC_STRAIN};
pub use drucker_prager::{DruckerPrager, ENTRY as DRUCKER_PRAGER};
pub use friction::EQUIVALENT_PLASTIC_STRAIN;
pub use linear_elastic::{lame, LinearElastic, ENTRY as LINEAR_ELASTIC};
pub use mohr_coulomb::{MohrCoulomb, ReturnBranch, ENTRY as MOHR_COULOMB};
pub use neo_hookean::{NeoHookean, ENTRY as NEO_HOOKEAN};
pub use registry::{Material, ModelEntry, Parameter};
pub use von_mises::{VonMises, ENTRY as VON_MISES, PLASTIC_MULTIPLIER};

use crate::material::tensor::Tensor4;
use nalgebra::Matrix3;

/// Most internal variables a model may declare: a state holds them in a fixed array, so that
/// the point loops allocate nothing. Four covers scalar measures (a plastic multiplier, an
/// isotropic hardening variable, damage); a tensorial one (a back stress, six components)
/// needs a larger bound.
pub const MAX_INTERNAL: usize = 4;

/// An internal variable a model declares ([`ConstitutiveModel::internal_variables`]): its name
/// (the column of the point files and the array of the ParaView files), its value before
/// the first load step, and what it measures.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct InternalVariable {
    pub name: &'static str,
    pub initial: f64,
    pub meaning: &'static str,
}

/// The values of a model's internal variables at one point, in the order the model declares
/// them: at most [`MAX_INTERNAL`], stored inline.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct InternalVariables {
    values: [f64; MAX_INTERNAL],
    len: u8,
}

impl InternalVariables {
    /// The values `values`, in declaration order.
    ///
    /// # Panics
    /// With more than [`MAX_INTERNAL`] values (a model declaring more is refused by
    /// [`Material::build`] before a solver runs it).
    #[inline]
    pub fn from_slice(values: &[f64]) -> Self {
        assert!(
            values.len() <= MAX_INTERNAL,
            "{} internal variables, at most {MAX_INTERNAL}",
            values.len()
        );
        let mut out = Self {
            values: [0.0; MAX_INTERNAL],
            len: values.len() as u8,
        };
        out.values[..values.len()].copy_from_slice(values);
        out
    }

    /// The initial values of the variables `declared`.
    pub fn initial(declared: &[InternalVariable]) -> Self {
        let mut out = Self::from_slice(&[0.0; MAX_INTERNAL][..declared.len()]);
        for (v, d) in out.values.iter_mut().zip(declared) {
            *v = d.initial;
        }
        out
    }

    /// The `i`-th variable; 0 beyond the ones held (a state made by
    /// [`MaterialState::default`] holds none).
    #[inline]
    pub fn get(&self, i: usize) -> f64 {
        self.values[i]
    }

    /// The values held, in declaration order.
    pub fn as_slice(&self) -> &[f64] {
        &self.values[..self.len as usize]
    }

    pub fn len(&self) -> usize {
        self.len as usize
    }

    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// The value of the variable named `name` in `declared`, if declared.
    pub fn named(&self, declared: &[InternalVariable], name: &str) -> Option<f64> {
        declared.iter().position(|d| d.name == name).map(|i| self.get(i))
    }

    /// Whether a variable differs from its initial value in `declared` (a von Mises point
    /// that yielded).
    pub fn has_evolved(&self, declared: &[InternalVariable]) -> bool {
        declared.iter().enumerate().any(|(i, d)| self.get(i) != d.initial)
    }
}

/// As the list of the values held.
impl serde::Serialize for InternalVariables {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        self.as_slice().serialize(s)
    }
}

impl<'de> serde::Deserialize<'de> for InternalVariables {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let v = Vec::<f64>::deserialize(d)?;
        if v.len() > MAX_INTERNAL {
            return Err(serde::de::Error::custom(format!(
                "{} internal variables, at most {MAX_INTERNAL}",
                v.len()
            )));
        }
        Ok(Self::from_slice(&v))
    }
}

/// Committed constitutive state of one material or Gauss point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MaterialState {
    /// Elastic logarithmic strain ε^e of the last converged step.
    pub eps_e: Matrix3<f64>,
    /// Elastic left Cauchy–Green tensor b^e = exp(2 ε^e), eq (18), kept to avoid recomputing it.
    pub b_e: Matrix3<f64>,
    /// The model's internal variables ([`ConstitutiveModel::internal_variables`]), e.g. von
    /// Mises' accumulated plastic multiplier; none for an elastic model.
    pub internal: InternalVariables,
}

impl Default for MaterialState {
    /// Undeformed, holding no internal variables: a solver gives its points the model's
    /// initial ones ([`MaterialState::initialise`]).
    fn default() -> Self {
        Self {
            eps_e: Matrix3::zeros(),
            b_e: Matrix3::identity(),
            internal: InternalVariables::default(),
        }
    }
}

impl MaterialState {
    /// Give a state that holds no internal variables `model`'s initial ones (a state that
    /// holds some, e.g. restarted from a solved one, is left as it is).
    pub fn initialise(&mut self, model: &dyn ConstitutiveModel) {
        if self.internal.is_empty() {
            self.internal = InternalVariables::initial(model.internal_variables());
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
    /// Updated internal variables.
    pub internal: InternalVariables,
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
    /// trial states) do not carry it.
    fn tangent(&self, eps_trial: &Matrix3<f64>, committed: &MaterialState) -> Tensor4;

    /// Whether [`Self::tangent`] reads its trial strain. A model whose tangent is a constant
    /// (linear elasticity) says no, and the assembly skips the trial strain's spectral
    /// logarithm (three `ln` and a spectral product per point and tangent), passing zeros.
    fn tangent_reads_strain(&self) -> bool {
        true
    }

    /// Whether [`Self::tangent`] is symmetric in its pairs (D_ijkl = D_klij) at every state:
    /// a comparator's direct solver is then LDLᵀ, otherwise LU. Yes by default; a
    /// non-associated model says no.
    fn tangent_is_symmetric(&self) -> bool {
        true
    }

    /// The elastic Young's modulus E: the stiffness scale of stabilisation terms
    /// ([`crate::discretise::ghost`]), which must not depend on the state so that they stay quadratic.
    fn young_modulus(&self) -> f64;

    /// The internal variables the model carries in [`MaterialState::internal`], in the order
    /// [`Self::update`] writes them: their names are the columns of the point files and the
    /// arrays of the ParaView files. None by default (an elastic model).
    fn internal_variables(&self) -> &'static [InternalVariable] {
        &[]
    }
}
