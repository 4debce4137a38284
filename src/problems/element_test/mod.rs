//! Element tests: one material point under a prescribed strain or mixed strain–stress path,
//! with no grid, the way a laboratory tests a soil sample and a constitutive model is verified
//! before any boundary-value problem (issue 51). The point's deformation is homogeneous, so the
//! test measures the model and its finite-strain wrapping alone.
//!
//! Axes: y (index 1) is the axial direction; x and z are lateral (z is the out-of-plane axis
//! of the plane-strain path). Stresses are reported compression positive, as soil mechanics
//! writes them; the model sees the code's tension-positive Kirchhoff stress.
//!
//! Every step multiplies the deformation gradient by an increment ΔF and updates the point as
//! the solvers do (eqs 17–19): b^e_trial = ΔF b^e_n ΔFᵀ, ε_trial = ½ ln b^e_trial. On the
//! coaxial paths ΔF = diag(exp Δε), so ε_trial = ε^e_n + Δε and the model's D^alg is the exact
//! Jacobian of the stress-controlled components; Newton on those components is then quadratic
//! (asserted by the element study).

pub mod closed_form;

use crate::material::constitutive::{ConstitutiveModel, MaterialState};
use crate::material::kinematics::{left_cauchy_green_from_strain, log_strain};
use crate::material::tensor::ij;
use crate::solver::error::InputError;
use nalgebra::Matrix3;
use serde::{Deserialize, Serialize};

pub use closed_form::ClosedForm;

/// The loading path of an element test.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ElementPath {
    /// Isotropic compression: equal compressive log strains on the three axes; the driven
    /// strain is the volumetric one.
    Isotropic,
    /// Oedometric (confined) compression: axial strain driven, no lateral strain.
    Oedometer,
    /// Drained triaxial compression: axial strain driven, both lateral stresses held at the
    /// confining pressure.
    TriaxialDrained,
    /// Undrained triaxial compression: axial strain driven at constant volume (each lateral
    /// log strain is minus half the axial one, so det F = 1 exactly).
    TriaxialUndrained,
    /// Plane-strain biaxial compression: axial strain driven, the x stress held at the
    /// confining pressure, no strain along z.
    PlaneStrainBiaxial,
    /// Simple shear: F = I + γ e_x ⊗ e_y, every component prescribed; the driven strain is γ.
    SimpleShear,
}

impl ElementPath {
    pub const ALL: [ElementPath; 6] = [
        ElementPath::Isotropic,
        ElementPath::Oedometer,
        ElementPath::TriaxialDrained,
        ElementPath::TriaxialUndrained,
        ElementPath::PlaneStrainBiaxial,
        ElementPath::SimpleShear,
    ];

    /// The name a study file writes.
    pub fn name(self) -> &'static str {
        match self {
            ElementPath::Isotropic => "isotropic",
            ElementPath::Oedometer => "oedometer",
            ElementPath::TriaxialDrained => "triaxial-drained",
            ElementPath::TriaxialUndrained => "triaxial-undrained",
            ElementPath::PlaneStrainBiaxial => "plane-strain-biaxial",
            ElementPath::SimpleShear => "simple-shear",
        }
    }

    /// The diagonal components held at the confining stress during the path (none: every
    /// component is prescribed).
    fn stress_controlled(self) -> &'static [usize] {
        match self {
            ElementPath::TriaxialDrained => &[0, 2],
            ElementPath::PlaneStrainBiaxial => &[0],
            _ => &[],
        }
    }

    /// The prescribed log-strain increment of the diagonal for a driven increment `d`
    /// (compression positive), before the stress-controlled components are solved for.
    fn driven(self, d: f64) -> [f64; 3] {
        match self {
            ElementPath::Isotropic => [-d / 3.0; 3],
            ElementPath::TriaxialUndrained => [0.5 * d, -d, 0.5 * d],
            ElementPath::SimpleShear => [0.0; 3],
            _ => [0.0, -d, 0.0],
        }
    }
}

/// One element test: a path, the isotropic confinement reached first, and the driven strain.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ElementTest {
    pub path: ElementPath,
    /// Isotropic Kirchhoff pressure (compression positive) applied first by stress control in
    /// `confining_steps` steps, and held on the lateral axes of the drained and biaxial paths.
    pub confining: f64,
    pub confining_steps: usize,
    /// The driven strain at the end of the path (compression positive): axial log strain,
    /// volumetric log strain (isotropic) or the shear γ (simple shear).
    pub strain: f64,
    pub steps: usize,
    /// Newton on the stress-controlled components stops at |Δτ| ≤ tolerance × the stress scale.
    pub tolerance: f64,
    pub max_iterations: usize,
}

impl ElementTest {
    /// Every value in its range; an error names `<scope>.<key>`.
    pub fn validate(&self, scope: &str) -> Result<(), InputError> {
        let key = |k: &str| format!("{scope}.{k}");
        if !(self.confining.is_finite() && self.confining >= 0.0) {
            return Err(InputError::new(
                key("confining"),
                self.confining,
                "must be finite and ≥ 0 (compression positive)",
            ));
        }
        if !(self.strain.is_finite() && self.strain > 0.0 && self.strain <= 5.0) {
            return Err(InputError::new(
                key("strain"),
                self.strain,
                "must lie in (0, 5] (compression positive; a log strain, or γ for simple shear)",
            ));
        }
        if !(1..=1_000_000).contains(&self.steps) {
            return Err(InputError::new(
                key("steps"),
                self.steps as f64,
                "must be an integer in 1..=1000000",
            ));
        }
        if self.confining > 0.0 && !(1..=100_000).contains(&self.confining_steps) {
            return Err(InputError::new(
                key("confining_steps"),
                self.confining_steps as f64,
                "must be an integer in 1..=100000 when confining > 0",
            ));
        }
        if !(self.tolerance.is_finite() && (1e-15..1e-2).contains(&self.tolerance)) {
            return Err(InputError::new(
                key("tolerance"),
                self.tolerance,
                "must lie in [1e-15, 1e-2)",
            ));
        }
        if !(1..=100).contains(&self.max_iterations) {
            return Err(InputError::new(
                key("max_iterations"),
                self.max_iterations as f64,
                "must be an integer in 1..=100",
            ));
        }
        Ok(())
    }
}

/// The point after one converged step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ElementState {
    /// The driven strain reached (0 during the confinement).
    pub strain: f64,
    /// Total logarithmic strain of the diagonal (tension positive; the coaxial paths).
    pub log_strain: [f64; 3],
    /// Kirchhoff stress (tension positive).
    pub tau: Matrix3<f64>,
    /// Whether the step belongs to the confinement.
    pub confining: bool,
}

impl ElementState {
    /// Mean pressure p = −tr τ / 3 (compression positive).
    pub fn p(&self) -> f64 {
        -self.tau.trace() / 3.0
    }
    /// Deviatoric stress q = √(3 J₂).
    pub fn q(&self) -> f64 {
        let s = crate::material::tensor::deviator(&self.tau);
        (1.5 * s.norm_squared()).sqrt()
    }
    /// Volumetric log strain, compression positive (coaxial paths; 0 in simple shear).
    pub fn volumetric_strain(&self) -> f64 {
        -self.log_strain.iter().sum::<f64>()
    }
}

/// The undeformed, unstressed state.
impl Default for ElementState {
    fn default() -> Self {
        Self {
            strain: 0.0,
            log_strain: [0.0; 3],
            tau: Matrix3::zeros(),
            confining: false,
        }
    }
}

/// Why a test stopped.
#[derive(Debug, Clone, PartialEq)]
pub struct ElementFailure {
    /// The step that failed, from 1 (confinement steps first).
    pub step: usize,
    pub reason: String,
    pub residuals: Vec<f64>,
}

/// What a test produced: the state after every converged step (confinement first), the
/// normalised Newton residuals of each (one entry, 0, where no component is stress-controlled),
/// and the failure that stopped it, if any.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ElementOutcome {
    pub states: Vec<ElementState>,
    pub residuals: Vec<Vec<f64>>,
    pub failure: Option<ElementFailure>,
}

/// The trial state of a step: the committed point deformed by ΔF.
fn trial(committed: &MaterialState, delta_f: &Matrix3<f64>) -> Option<Matrix3<f64>> {
    let b = delta_f * left_cauchy_green_from_strain(&committed.eps_e) * delta_f.transpose();
    log_strain(&(0.5 * (b + b.transpose())))
}

/// Run `test` on `model` from its undeformed state (a model with a reference pressure, e.g.
/// Cam-Clay's, starts from that stress).
pub fn run(model: &dyn ConstitutiveModel, test: &ElementTest) -> ElementOutcome {
    let mut committed = MaterialState::default();
    committed.initialise(model);
    let mut out = ElementOutcome::default();
    let mut log_total = [0.0; 3];
    let confinement = if test.confining > 0.0 {
        test.confining_steps
    } else {
        0
    };
    let total = confinement + test.steps;
    let mut step_of_path = 0usize;
    for step in 1..=total {
        let confining = step <= confinement;
        // Confinement: the three diagonal stresses ramp to −confining, nothing driven.
        let (controlled, target, prescribed): (&[usize], f64, [f64; 3]) = if confining {
            (
                &[0, 1, 2],
                -test.confining * step as f64 / confinement as f64,
                [0.0; 3],
            )
        } else {
            step_of_path += 1;
            let d = test.strain / test.steps as f64;
            (
                test.path.stress_controlled(),
                -test.confining,
                test.path.driven(d),
            )
        };
        let shear = if !confining && test.path == ElementPath::SimpleShear {
            test.strain / test.steps as f64
        } else {
            0.0
        };
        match solve_step(model, &committed, test, controlled, target, prescribed, shear) {
            Ok((response, increments, residuals)) => {
                for a in 0..3 {
                    log_total[a] += increments[a];
                }
                committed.eps_e = response.eps_e;
                committed.b_e = left_cauchy_green_from_strain(&response.eps_e);
                committed.internal = response.internal;
                out.states.push(ElementState {
                    strain: if confining {
                        0.0
                    } else {
                        test.strain * step_of_path as f64 / test.steps as f64
                    },
                    log_strain: log_total,
                    tau: response.tau,
                    confining,
                });
                out.residuals.push(residuals);
            }
            Err((reason, residuals)) => {
                out.failure = Some(ElementFailure {
                    step,
                    reason,
                    residuals,
                });
                break;
            }
        }
    }
    out
}

type StepResult = Result<
    (
        crate::material::constitutive::MaterialResponse,
        [f64; 3],
        Vec<f64>,
    ),
    (String, Vec<f64>),
>;

/// One step: Newton on the log-strain increments of the `controlled` diagonal components until
/// their stresses equal `target`, the others prescribed.
fn solve_step(
    model: &dyn ConstitutiveModel,
    committed: &MaterialState,
    test: &ElementTest,
    controlled: &[usize],
    target: f64,
    prescribed: [f64; 3],
    shear: f64,
) -> StepResult {
    let mut d = prescribed;
    let scale = test.confining.max(model.young_modulus() * 1e-6);
    let mut residuals = vec![];
    for iteration in 0..=test.max_iterations {
        let mut delta_f = Matrix3::from_diagonal(&nalgebra::Vector3::from(d.map(f64::exp)));
        delta_f[(0, 1)] = shear;
        let eps = trial(committed, &delta_f).ok_or_else(|| {
            (
                "the trial left Cauchy–Green tensor is not positive definite".to_string(),
                residuals.clone(),
            )
        })?;
        let response = model
            .update(&eps, committed)
            .map_err(|e| (format!("the stress update failed: {}", e.0), residuals.clone()))?;
        if !response.tau.iter().all(|v| v.is_finite()) {
            return Err(("the stress update returned a non-finite stress".into(), residuals));
        }
        // The residual and Jacobian of the controlled components, padded to 3×3 with identity
        // rows for the prescribed ones (fixed size: nothing allocated per iteration).
        let mut r = nalgebra::Vector3::zeros();
        for &a in controlled {
            r[a] = response.tau[(a, a)] - target;
        }
        let norm = r.norm() / scale;
        residuals.push(norm);
        if norm <= test.tolerance {
            return Ok((response, d, residuals));
        }
        if iteration == test.max_iterations {
            break;
        }
        // J_ab = ∂τ_aa/∂Δε_bb = D^alg_aabb: exact on the coaxial paths (ε_trial = ε^e_n + Δε).
        let tangent = model.tangent(&eps, committed);
        let mut j = Matrix3::identity();
        for &a in controlled {
            for &b in controlled {
                j[(a, b)] = tangent[(ij(a, a), ij(b, b))];
            }
        }
        let step = j
            .lu()
            .solve(&r)
            .filter(|s| s.iter().all(|v| v.is_finite()))
            .ok_or_else(|| {
                (
                    "the stress-controlled block of the tangent is singular (the point cannot carry the held stress)".to_string(),
                    residuals.clone(),
                )
            })?;
        for &a in controlled {
            d[a] -= step[a];
        }
    }
    Err((
        format!(
            "Newton on the stress-controlled components did not reach {:e} in {} iterations",
            test.tolerance, test.max_iterations
        ),
        residuals,
    ))
}
