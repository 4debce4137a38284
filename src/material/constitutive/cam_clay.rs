use super::registry::Parameter;
use super::{
    ConstitutiveModel, InternalVariable, InternalVariables, MaterialError, MaterialResponse, MaterialState,
    ModelEntry,
};
use crate::material::tensor::{deviator, identity_outer, identity_sym, outer, Tensor4};
use crate::solver::error::InputError;
use nalgebra::Matrix3;

/// `model = "modified-cam-clay"`: [`ModifiedCamClay`]. Its parameters are not (E, ν): the bulk
/// stiffness is pressure dependent, so the model is given by μ, κ̂, λ̂, M, p₀ and p_c0 (nothing
/// in the crate needs E and ν of a model but the Hencky closed forms, which refuse it).
pub static ENTRY: ModelEntry = ModelEntry {
    name: "modified-cam-clay",
    summary: "Modified Cam-Clay at finite strain (Borja & Tamagnini 1998): bulk stiffness p/κ̂, constant shear modulus, elliptic yield surface, associated flow, p_c hardening with the plastic volumetric log strain",
    parameters: &[
        Parameter {
            name: "shear_modulus",
            unit: "Pa",
            meaning: "constant shear modulus μ, > 0",
        },
        Parameter {
            name: "swelling_index",
            unit: "1",
            meaning: "κ̂, the slope of ln J against ln p on unloading (εᵥᵉ = −κ̂ ln(p/p₀)), > 0",
        },
        Parameter {
            name: "compression_index",
            unit: "1",
            meaning: "λ̂, the slope of ln J against ln p on the normal compression line, > κ̂",
        },
        Parameter {
            name: "critical_state_slope",
            unit: "1",
            meaning: "M, the critical state line q = M p, > 0",
        },
        Parameter {
            name: "reference_pressure",
            unit: "Pa",
            meaning: "p₀, the pressure at zero elastic strain (the initial stress τ = −p₀ 1), > 0",
        },
        Parameter {
            name: "preconsolidation_pressure",
            unit: "Pa",
            meaning: "initial preconsolidation pressure p_c0, ≥ p₀ (the initial state inside the ellipse)",
        },
    ],
    build: |m| {
        Ok(Box::new(ModifiedCamClay::try_new(
            m.value("shear_modulus"),
            m.value("swelling_index"),
            m.value("compression_index"),
            m.value("critical_state_slope"),
            m.value("reference_pressure"),
            m.value("preconsolidation_pressure"),
        )?))
    },
};

/// Modified Cam-Clay's internal variable: the plastic volumetric log strain εᵥᵖ (tension
/// positive), from which p_c = p_c0 exp(−εᵥᵖ / (λ̂ − κ̂)) follows (its initial value must be a
/// constant, p_c0 a parameter).
pub const PLASTIC_VOLUMETRIC_STRAIN: InternalVariable = InternalVariable {
    name: "plastic_volumetric_strain",
    initial: 0.0,
    meaning: "plastic volumetric log strain εᵥᵖ (tension positive; < 0 compacted, which raises p_c)",
};

/// Local Newton iterations of the return before it is refused.
const MAX_LOCAL_ITERATIONS: usize = 50;

/// Modified Cam-Clay at finite strain after Borja & Tamagnini (1998, CMAME 155, "Cam-Clay
/// plasticity Part III"), in the crate's log-strain / Kirchhoff framework: the return map acts
/// on the trial elastic log strain, the plastic flow integrated by the exponential map, as von
/// Mises and Drucker–Prager are (reference/README.md item 68).
///
/// Elasticity (hyperelastic, Borja–Tamagnini's α = 0, no pressure–shear coupling): with
/// εᵥᵉ = tr ε^e and e = dev ε^e, Ψ = κ̂ p₀ exp(−εᵥᵉ/κ̂) + μ |e|², so τ = ∂Ψ/∂ε^e = −p 1 + 2μ e
/// with the compression-positive Kirchhoff pressure p = −tr τ / 3 = p₀ exp(−εᵥᵉ/κ̂) and
/// q = √(3 J₂) = 3μ εₛᵉ. The tangent modulus is K = p/κ̂ (pressure dependent), 2μ constant.
/// At ε^e = 0 the stress is −p₀ 1: a boundary-value problem must start from that isotropic
/// stress (boundary tractions p₀ or confinement), not from zero.
///
/// Yield F = q²/M² + p (p − p_c), associated flow, p_c = p_c0 exp(−εᵥᵖ/(λ̂ − κ̂)). κ̂ and λ̂ are
/// slopes of ln J = tr(log strain) against ln p, so the normal compression line is exactly
/// tr ε = −λ̂ ln(p/p₀) from p_c0 = p₀.
///
/// Return map (backward Euler, radial in the deviatoric plane): unknowns εᵥᵉ and Δγ,
/// R₁ = εᵥᵉ − εᵥᵗ − Δγ (2p − p_c) = 0 (the plastic volumetric strain is −Δγ ∂F/∂p),
/// R₂ = q²/M² + p (p − p_c) = 0, with q = q_t / (1 + 6μΔγ/M²) and
/// p_c = p_c,n exp((εᵥᵉ − εᵥᵗ)/(λ̂ − κ̂)), solved by Newton to round-off.
///
/// Consistent tangent by the implicit function theorem on (R₁, R₂) at the solution: with
/// n = e_t/|e_t|, c = 1 + 6μΔγ/M², q_Δγ = ∂q/∂Δγ and (a_v, a_q, b_v, b_q) the sensitivities of
/// (εᵥᵉ, Δγ) to (εᵥᵗ, q_t), D = (p/κ̂) a_v 1⊗1 + √6 μ (p/κ̂) a_q 1⊗n + √(2/3) q_Δγ b_v n⊗1 +
/// 2μ q_Δγ b_q n⊗n + (2μ/c) I_dev. It is unsymmetric where p_c hardens (the hardening is not
/// associated, [`ConstitutiveModel::tangent_is_symmetric`]); checked against central
/// differences on every branch in the tests.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ModifiedCamClay {
    pub shear_modulus: f64,
    pub swelling_index: f64,
    pub compression_index: f64,
    pub critical_state_slope: f64,
    pub reference_pressure: f64,
    pub preconsolidation_pressure: f64,
}

/// The converged return: εᵥᵉ, Δγ, p, q, p_c, c = 1 + 6μΔγ/M².
#[derive(Debug, Clone, Copy)]
struct Return {
    ev: f64,
    dgamma: f64,
    p: f64,
    q: f64,
    pc: f64,
    c: f64,
}

/// Which branch a trial state takes.
enum Branch {
    Elastic,
    Plastic(Return),
}

fn positive(key: &str, value: f64) -> Result<(), InputError> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(InputError::new(
            format!("material.{key}"),
            value,
            "must be finite and > 0",
        ))
    }
}

impl ModifiedCamClay {
    /// μ > 0, κ̂ > 0, λ̂ > κ̂, M > 0, p₀ > 0, p_c0 ≥ p₀.
    pub fn try_new(
        shear_modulus: f64,
        swelling_index: f64,
        compression_index: f64,
        critical_state_slope: f64,
        reference_pressure: f64,
        preconsolidation_pressure: f64,
    ) -> Result<Self, InputError> {
        positive("shear_modulus", shear_modulus)?;
        positive("swelling_index", swelling_index)?;
        if !(compression_index.is_finite() && compression_index > swelling_index) {
            return Err(InputError::new(
                "material.compression_index",
                compression_index,
                format!("must be finite and > swelling_index = {swelling_index}"),
            ));
        }
        positive("critical_state_slope", critical_state_slope)?;
        positive("reference_pressure", reference_pressure)?;
        // The points start at ε^e = 0, p = p₀, q = 0: inside the ellipse only if p_c0 ≥ p₀.
        if !(preconsolidation_pressure.is_finite() && preconsolidation_pressure >= reference_pressure) {
            return Err(InputError::new(
                "material.preconsolidation_pressure",
                preconsolidation_pressure,
                format!("must be finite and ≥ reference_pressure = {reference_pressure}"),
            ));
        }
        Ok(Self {
            shear_modulus,
            swelling_index,
            compression_index,
            critical_state_slope,
            reference_pressure,
            preconsolidation_pressure,
        })
    }

    /// p = p₀ exp(−εᵥᵉ/κ̂), compression positive.
    pub fn pressure(&self, ev: f64) -> f64 {
        self.reference_pressure * (-ev / self.swelling_index).exp()
    }

    /// p_c = p_c0 exp(−εᵥᵖ/(λ̂ − κ̂)) at plastic volumetric strain `evp`.
    pub fn preconsolidation(&self, evp: f64) -> f64 {
        self.preconsolidation_pressure * (-evp / (self.compression_index - self.swelling_index)).exp()
    }

    /// F = q²/M² + p (p − p_c) of a Kirchhoff stress at plastic volumetric strain `evp`.
    pub fn yield_function(&self, tau: &Matrix3<f64>, evp: f64) -> f64 {
        let p = -tau.trace() / 3.0;
        let q2 = 1.5 * deviator(tau).norm_squared();
        let m2 = self.critical_state_slope * self.critical_state_slope;
        q2 / m2 + p * (p - self.preconsolidation(evp))
    }

    /// The branch of the trial strain from plastic volumetric strain `evp`: elastic where
    /// F(p_t, q_t) ≤ 0, else the converged return.
    fn branch(&self, eps_trial: &Matrix3<f64>, evp: f64) -> Result<Branch, MaterialError> {
        let ev_t = eps_trial.trace();
        let q_t = 6f64.sqrt() * self.shear_modulus * deviator(eps_trial).norm();
        let p_t = self.pressure(ev_t);
        let pc_n = self.preconsolidation(evp);
        let m2 = self.critical_state_slope * self.critical_state_slope;
        if !(p_t.is_finite() && pc_n.is_finite() && q_t.is_finite()) {
            return Err(MaterialError(format!(
                "modified Cam-Clay: trial pressure {p_t} or p_c {pc_n} is not finite (tr ε = {ev_t}, εᵥᵖ = {evp})"
            )));
        }
        if q_t * q_t / m2 + p_t * (p_t - pc_n) <= 0.0 {
            return Ok(Branch::Elastic);
        }
        self.local_newton(ev_t, q_t, pc_n).map(Branch::Plastic)
    }

    /// Newton on (R₁, R₂) from the trial state (εᵥᵉ = εᵥᵗ, Δγ = 0). Stops once both residuals
    /// are below 1e-13 of their scales (κ̂, p_c²) and takes one more step, so that the stress
    /// is converged to round-off (the tangent's central differences need it).
    fn local_newton(&self, ev_t: f64, q_t: f64, pc_n: f64) -> Result<Return, MaterialError> {
        let (kappa, theta, mu) = (
            self.swelling_index,
            self.compression_index - self.swelling_index,
            self.shear_modulus,
        );
        let m2 = self.critical_state_slope * self.critical_state_slope;
        let (mut ev, mut dgamma) = (ev_t, 0.0);
        let mut converged = false;
        for _ in 0..MAX_LOCAL_ITERATIONS {
            let p = self.pressure(ev);
            let pc = pc_n * ((ev - ev_t) / theta).exp();
            let c = 1.0 + 6.0 * mu * dgamma / m2;
            let q = q_t / c;
            let r1 = ev - ev_t - dgamma * (2.0 * p - pc);
            let r2 = q * q / m2 + p * (p - pc);
            if !(r1.is_finite() && r2.is_finite() && c > 0.0) || (converged && dgamma < 0.0) {
                return Err(MaterialError(format!(
                    "modified Cam-Clay: the return reached a non-physical iterate (εᵥᵉ = {ev}, Δγ = {dgamma}, p = {p}, p_c = {pc}) from εᵥᵗ = {ev_t}, q_t = {q_t}"
                )));
            }
            if converged {
                return Ok(Return {
                    ev,
                    dgamma,
                    p,
                    q,
                    pc,
                    c,
                });
            }
            let (j11, j12, j21, j22) = jacobian(p, q, pc, dgamma, c, kappa, theta, mu, m2, true);
            let det = j11 * j22 - j12 * j21;
            if det == 0.0 || !det.is_finite() {
                return Err(MaterialError(format!(
                    "modified Cam-Clay: the return's Jacobian is singular (εᵥᵉ = {ev}, Δγ = {dgamma})"
                )));
            }
            converged = r1.abs() <= 1e-13 * kappa && r2.abs() <= 1e-13 * pc * pc;
            ev -= (j22 * r1 - j12 * r2) / det;
            dgamma -= (j11 * r2 - j21 * r1) / det;
        }
        Err(MaterialError(format!(
            "modified Cam-Clay: the return did not converge in {MAX_LOCAL_ITERATIONS} iterations from εᵥᵗ = {ev_t}, q_t = {q_t}, p_c = {pc_n}"
        )))
    }
}

/// ∂(R₁, R₂)/∂(εᵥᵉ, Δγ) at (p, q, p_c, Δγ): with `hardening` false the p_c terms are left out
/// (the seeded bug's tangent).
#[allow(clippy::too_many_arguments)]
fn jacobian(
    p: f64,
    q: f64,
    pc: f64,
    dgamma: f64,
    c: f64,
    kappa: f64,
    theta: f64,
    mu: f64,
    m2: f64,
    hardening: bool,
) -> (f64, f64, f64, f64) {
    // ∂p/∂εᵥᵉ = −p/κ̂, ∂p_c/∂εᵥᵉ = p_c/(λ̂ − κ̂), ∂q/∂Δγ = −6μ q/(M² c).
    let dpc = if hardening { pc / theta } else { 0.0 };
    let dp = -p / kappa;
    let dq = -6.0 * mu * q / (m2 * c);
    (
        1.0 - dgamma * (2.0 * dp - dpc),
        -(2.0 * p - pc),
        (2.0 * p - pc) * dp - p * dpc,
        2.0 * q / m2 * dq,
    )
}

/// The seeded bug of this model: the consistent tangent without the hardening of p_c.
#[cfg(feature = "seeded-bugs")]
fn seeded_without_hardening() -> bool {
    crate::seeded::active(crate::seeded::Bug::CamClayTangentWithoutHardening)
}

#[cfg(not(feature = "seeded-bugs"))]
fn seeded_without_hardening() -> bool {
    false
}

impl ConstitutiveModel for ModifiedCamClay {
    fn update(
        &self,
        eps_trial: &Matrix3<f64>,
        committed: &MaterialState,
    ) -> Result<MaterialResponse, MaterialError> {
        let evp = committed.internal.get(0);
        let one = Matrix3::identity();
        let e_t = deviator(eps_trial);
        let ev_t = eps_trial.trace();
        let (tau, eps_e, evp_new) = match self.branch(eps_trial, evp)? {
            Branch::Elastic => (
                e_t * (2.0 * self.shear_modulus) - one * self.pressure(ev_t),
                *eps_trial,
                evp,
            ),
            // The deviator shrinks radially by 1/c; the volumetric plastic strain is what the
            // elastic one gave up.
            Branch::Plastic(r) => (
                e_t * (2.0 * self.shear_modulus / r.c) - one * r.p,
                e_t / r.c + one * (r.ev / 3.0),
                evp + (ev_t - r.ev),
            ),
        };
        if !(tau.iter().all(|v| v.is_finite()) && eps_e.iter().all(|v| v.is_finite())) {
            return Err(MaterialError(
                "modified Cam-Clay return map produced a non-finite stress".into(),
            ));
        }
        Ok(MaterialResponse {
            tau,
            eps_e,
            internal: InternalVariables::from_slice(&[evp_new]),
        })
    }

    fn tangent(&self, eps_trial: &Matrix3<f64>, committed: &MaterialState) -> Tensor4 {
        let (kappa, mu) = (self.swelling_index, self.shear_modulus);
        let theta = self.compression_index - self.swelling_index;
        let m2 = self.critical_state_slope * self.critical_state_slope;
        let i_dev = identity_sym() - identity_outer() * (1.0 / 3.0);
        let r = match self.branch(eps_trial, committed.internal.get(0)) {
            Ok(Branch::Plastic(r)) => r,
            // Elastic, or a state the update refuses (its error ends the iteration first):
            // K = p/κ̂ at the trial pressure, finite even there.
            _ => {
                let p = self.pressure(eps_trial.trace());
                let k = if p.is_finite() { p / kappa } else { 0.0 };
                return identity_outer() * k + i_dev * (2.0 * mu);
            }
        };
        let hardening = !(cfg!(feature = "seeded-bugs") && seeded_without_hardening());
        let Return {
            dgamma, p, q, pc, c, ..
        } = r;
        let (j11, j12, j21, j22) = jacobian(p, q, pc, dgamma, c, kappa, theta, mu, m2, hardening);
        let det = j11 * j22 - j12 * j21;
        // ∂R/∂εᵥᵗ (through p_c = p_c,n exp((εᵥᵉ − εᵥᵗ)/(λ̂ − κ̂)) and R₁'s −εᵥᵗ) and ∂R₂/∂q_t.
        let dpc = if hardening { pc / theta } else { 0.0 };
        let (r1_v, r2_v, r2_q) = (-1.0 - dgamma * dpc, p * dpc, 2.0 * q / (m2 * c));
        let a_v = -(j22 * r1_v - j12 * r2_v) / det;
        let b_v = -(j11 * r2_v - j21 * r1_v) / det;
        let a_q = j12 * r2_q / det;
        let b_q = -j11 * r2_q / det;
        let q_dg = -6.0 * mu * q / (m2 * c);
        let e_t = deviator(eps_trial);
        let norm = e_t.norm();
        let n = if norm > 0.0 { e_t / norm } else { Matrix3::zeros() };
        let one = Matrix3::identity();
        let k = p / kappa;
        identity_outer() * (k * a_v)
            + outer(&one, &n) * (6f64.sqrt() * mu * k * a_q)
            + outer(&n, &one) * ((2.0f64 / 3.0).sqrt() * q_dg * b_v)
            + outer(&n, &n) * (2.0 * mu * q_dg * b_q)
            + i_dev * (2.0 * mu / c)
    }

    /// Unsymmetric wherever p_c hardens: εᵥᵖ evolves with ∂F/∂p, not with ∂F/∂p_c, so the
    /// hardening is not associated even though the flow is (with p_c frozen the return is a
    /// closest-point projection in the complementary energy and the tangent symmetric).
    fn tangent_is_symmetric(&self) -> bool {
        false
    }

    fn young_modulus(&self) -> f64 {
        // The small-strain E at the reference state (K = p₀/κ̂, μ): a fixed stiffness scale
        // for stabilisation terms, not the model's stiffness at other pressures.
        let k = self.reference_pressure / self.swelling_index;
        9.0 * k * self.shear_modulus / (3.0 * k + self.shear_modulus)
    }

    fn internal_variables(&self) -> &'static [InternalVariable] {
        &[PLASTIC_VOLUMETRIC_STRAIN]
    }
}
