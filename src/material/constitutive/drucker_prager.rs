use super::friction::{self, EQUIVALENT_PLASTIC_STRAIN};
use super::linear_elastic::lame;
use super::{
    ConstitutiveModel, InternalVariable, InternalVariables, MaterialError, MaterialResponse, MaterialState,
    ModelEntry,
};
use crate::material::tensor::{deviator, identity_outer, identity_sym, outer, Tensor4};
use crate::solver::error::InputError;
use nalgebra::Matrix3;

/// `model = "drucker-prager"`: [`DruckerPrager`], its cone matched to Mohr–Coulomb in plane
/// strain.
pub static ENTRY: ModelEntry = ModelEntry {
    name: "drucker-prager",
    summary: "Drucker–Prager plasticity on the Kirchhoff stress, Hencky elasticity, plane-strain match to Mohr–Coulomb, apex return, linear cohesion hardening",
    parameters: &friction::PARAMETERS,
    build: |m| {
        let [e, nu, c, phi, psi, h] = friction::values(m);
        Ok(Box::new(DruckerPrager::try_new(e, nu, c, phi, psi, h)?))
    },
};

/// Drucker–Prager plasticity in Kirchhoff stress / logarithmic strain space (de Souza Neto,
/// Perić & Owen 2008, §8.3.4 and Box 8.9, applied to the trial log strain as von Mises is,
/// reference/README.md item 68): f = √J₂(s) + η p − ξ c(ε̄ᵖ), p = tr τ / 3 (tension positive),
/// flow potential √J₂ + η̄ p, cohesion c = c₀ + H ε̄ᵖ (ε̄ᵖ += ξ Δγ on the cone, (ξ/η̄) Δεᵥᵖ at the
/// apex). The cone is the plane-strain match to
/// Mohr–Coulomb: η = 3 tan φ / √(9 + 12 tan²φ), ξ = 3 / √(9 + 12 tan²φ), η̄ from ψ as η from
/// φ; it gives Mohr–Coulomb's collapse load in plane strain under associated flow.
///
/// Return map: with q_t = √J₂ of the trial deviator, the cone's Δγ = f_t / (G + K η η̄ + ξ² H),
/// q = q_t − G Δγ, p = p_t − K η̄ Δγ; where that leaves q < 0 the apex: s = 0,
/// Δεᵥᵖ = (p_t − β c_n) / (K + α β H), β = ξ/η, α = ξ/η̄.
///
/// Consistent tangent, cone (differentiating the return, N = s_t / |s_t|, A = 1 / (G + K η η̄ +
/// ξ² H)): D = 2G (1 − G Δγ / q_t) I_dev + 2G (G Δγ / q_t − G A) N⊗N − √2 G K A (η N⊗1 +
/// η̄ 1⊗N) + K (1 − K η η̄ A) 1⊗1, unsymmetric when η̄ ≠ η; apex: D = K (1 − K / (K + α β H))
/// 1⊗1. Checked against central differences on every branch in the tests.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DruckerPrager {
    pub young_modulus: f64,
    pub poisson_ratio: f64,
    pub cohesion: f64,
    /// φ and ψ in degrees.
    pub friction_angle: f64,
    pub dilatancy_angle: f64,
    pub hardening_modulus: f64,
    bulk: f64,
    shear: f64,
    /// η, ξ, η̄ of the plane-strain match.
    eta: f64,
    xi: f64,
    eta_bar: f64,
    d_elastic: Tensor4,
}

/// The plane-strain match's (η, ξ) of an angle in degrees.
fn plane_strain_match(degrees: f64) -> (f64, f64) {
    let t = degrees.to_radians().tan();
    let root = (9.0 + 12.0 * t * t).sqrt();
    (3.0 * t / root, 3.0 / root)
}

/// Which branch a trial state returns to, with its quantities.
enum Branch {
    Elastic,
    /// Δγ, q_t, N.
    Cone(f64, f64, Matrix3<f64>),
    /// Δεᵥᵖ.
    Apex(f64),
}

impl DruckerPrager {
    /// E > 0, −1 < ν < 0.5, c₀ ≥ 0, 0 ≤ ψ ≤ φ < 90°, H finite.
    pub fn try_new(
        young_modulus: f64,
        poisson_ratio: f64,
        cohesion: f64,
        friction_angle: f64,
        dilatancy_angle: f64,
        hardening_modulus: f64,
    ) -> Result<Self, InputError> {
        let elastic = super::LinearElastic::try_new(young_modulus, poisson_ratio)?;
        friction::check(cohesion, friction_angle, dilatancy_angle, hardening_modulus)?;
        let (lambda, mu) = lame(young_modulus, poisson_ratio);
        let (eta, xi) = plane_strain_match(friction_angle);
        let (eta_bar, _) = plane_strain_match(dilatancy_angle);
        Ok(Self {
            young_modulus,
            poisson_ratio,
            cohesion,
            friction_angle,
            dilatancy_angle,
            hardening_modulus,
            bulk: lambda + 2.0 * mu / 3.0,
            shear: mu,
            eta,
            xi,
            eta_bar,
            d_elastic: *elastic.stiffness(),
        })
    }

    /// (η, ξ, η̄) of the cone.
    pub fn cone(&self) -> (f64, f64, f64) {
        (self.eta, self.xi, self.eta_bar)
    }

    /// f = √J₂ + η p − ξ c of a Kirchhoff stress at plastic strain `ep`.
    pub fn yield_function(&self, tau: &Matrix3<f64>, ep: f64) -> f64 {
        let q = (0.5 * deviator(tau).norm_squared()).sqrt();
        q + self.eta * tau.trace() / 3.0 - self.xi * (self.cohesion + self.hardening_modulus * ep)
    }

    /// The branch of the trial strain from plastic strain `ep`.
    fn branch(&self, eps_trial: &Matrix3<f64>, ep: f64) -> Result<Branch, MaterialError> {
        let (k, g, h) = (self.bulk, self.shear, self.hardening_modulus);
        let s_t = deviator(eps_trial) * (2.0 * g);
        let norm = s_t.norm();
        let q_t = norm / std::f64::consts::SQRT_2;
        let p_t = k * eps_trial.trace();
        let c_n = self.cohesion + h * ep;
        let f_t = q_t + self.eta * p_t - self.xi * c_n;
        if f_t <= 0.0 {
            return Ok(Branch::Elastic);
        }
        let a = g + k * self.eta * self.eta_bar + self.xi * self.xi * h;
        if a <= 0.0 {
            return Err(MaterialError(format!(
                "Drucker–Prager: the softening modulus {h} makes the cone return unstable (G + K η η̄ + ξ² H = {a} ≤ 0)"
            )));
        }
        let dgamma = f_t / a;
        // The cone holds while its return keeps q ≥ 0 (a seeded bug keeps it always).
        let smooth_only = cfg!(feature = "seeded-bugs") && seeded_smooth_apex();
        if q_t - g * dgamma >= 0.0 || smooth_only {
            return Ok(Branch::Cone(
                dgamma,
                q_t,
                if norm > 0.0 { s_t / norm } else { Matrix3::zeros() },
            ));
        }
        if self.eta_bar == 0.0 || self.eta == 0.0 {
            return Err(MaterialError(
                "Drucker–Prager: a return to the apex needs friction and dilatancy angles > 0".into(),
            ));
        }
        let (alpha, beta) = (self.xi / self.eta_bar, self.xi / self.eta);
        let denominator = k + alpha * beta * h;
        if denominator <= 0.0 {
            return Err(MaterialError(format!(
                "Drucker–Prager: the softening modulus {h} makes the apex return unstable"
            )));
        }
        Ok(Branch::Apex((p_t - beta * c_n) / denominator))
    }
}

/// The seeded bug of this model: the apex treated as a smooth part of the cone.
#[cfg(feature = "seeded-bugs")]
fn seeded_smooth_apex() -> bool {
    crate::seeded::active(crate::seeded::Bug::DruckerPragerSmoothApex)
}

#[cfg(not(feature = "seeded-bugs"))]
fn seeded_smooth_apex() -> bool {
    false
}

impl ConstitutiveModel for DruckerPrager {
    fn update(
        &self,
        eps_trial: &Matrix3<f64>,
        committed: &MaterialState,
    ) -> Result<MaterialResponse, MaterialError> {
        let (k, g) = (self.bulk, self.shear);
        let ep = committed.internal.get(0);
        let p_t = k * eps_trial.trace();
        let s_t = deviator(eps_trial) * (2.0 * g);
        let (tau, eps_e, ep_new) = match self.branch(eps_trial, ep)? {
            Branch::Elastic => (s_t + Matrix3::identity() * p_t, *eps_trial, ep),
            Branch::Cone(dgamma, q_t, _) => {
                let s = s_t * (1.0 - g * dgamma / q_t);
                let p = p_t - k * self.eta_bar * dgamma;
                let tau = s + Matrix3::identity() * p;
                // Elastic strain from the stress: ε = dev τ / 2G + p / 3K 1.
                (
                    tau,
                    s / (2.0 * g) + Matrix3::identity() * (p / (3.0 * k)),
                    ep + self.xi * dgamma,
                )
            }
            Branch::Apex(dev) => {
                let p = p_t - k * dev;
                (
                    Matrix3::identity() * p,
                    Matrix3::identity() * (p / (3.0 * k)),
                    ep + self.xi / self.eta_bar * dev,
                )
            }
        };
        if !eps_e.iter().all(|v| v.is_finite()) {
            return Err(MaterialError(
                "Drucker–Prager return map produced a non-finite strain".into(),
            ));
        }
        Ok(MaterialResponse {
            tau,
            eps_e,
            internal: InternalVariables::from_slice(&[ep_new]),
        })
    }

    fn tangent(&self, eps_trial: &Matrix3<f64>, committed: &MaterialState) -> Tensor4 {
        let (k, g, h) = (self.bulk, self.shear, self.hardening_modulus);
        let (eta, xi, eta_bar) = (self.eta, self.xi, self.eta_bar);
        match self.branch(eps_trial, committed.internal.get(0)) {
            Ok(Branch::Cone(dgamma, q_t, n)) => {
                let a = 1.0 / (g + k * eta * eta_bar + xi * xi * h);
                let i_dev = identity_sym() - identity_outer() * (1.0 / 3.0);
                let one = Matrix3::identity();
                i_dev * (2.0 * g * (1.0 - g * dgamma / q_t))
                    + outer(&n, &n) * (2.0 * g * (g * dgamma / q_t - g * a))
                    - (outer(&n, &one) * eta + outer(&one, &n) * eta_bar)
                        * (std::f64::consts::SQRT_2 * g * k * a)
                    + identity_outer() * (k * (1.0 - k * eta * eta_bar * a))
            }
            Ok(Branch::Apex(_)) => {
                let (alpha, beta) = (xi / eta_bar, xi / eta);
                identity_outer() * (k * (1.0 - k / (k + alpha * beta * h)))
            }
            // Elastic, or a state the update refuses (its error ends the iteration first).
            _ => self.d_elastic,
        }
    }

    /// Unsymmetric on the cone under non-associated flow (η̄ ≠ η).
    fn tangent_is_symmetric(&self) -> bool {
        self.eta_bar == self.eta
    }

    fn young_modulus(&self) -> f64 {
        self.young_modulus
    }

    fn internal_variables(&self) -> &'static [InternalVariable] {
        &[EQUIVALENT_PLASTIC_STRAIN]
    }
}
