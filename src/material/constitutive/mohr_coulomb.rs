use super::friction::{self, EQUIVALENT_PLASTIC_STRAIN};
use super::linear_elastic::lame;
use super::{
    ConstitutiveModel, InternalVariable, InternalVariables, MaterialError, MaterialResponse, MaterialState,
    ModelEntry,
};
use crate::material::kinematics::sym_eigen;
use crate::material::tensor::{ij, Tensor4};
use crate::solver::error::InputError;
use nalgebra::{Matrix2, Matrix3, Vector2, Vector3};

/// `model = "mohr-coulomb"`: [`MohrCoulomb`], the multi-surface return on the principal
/// Kirchhoff stresses.
pub static ENTRY: ModelEntry = ModelEntry {
    name: "mohr-coulomb",
    summary: "Mohr–Coulomb plasticity on the principal Kirchhoff stresses, Hencky elasticity, main-plane, edge and apex returns, linear cohesion hardening",
    parameters: &friction::PARAMETERS,
    build: |m| {
        let [e, nu, c, phi, psi, h] = friction::values(m);
        Ok(Box::new(MohrCoulomb::try_new(e, nu, c, phi, psi, h)?))
    },
};

/// Mohr–Coulomb plasticity in Kirchhoff stress / logarithmic strain space (de Souza Neto,
/// Perić & Owen 2008, §8.2, Boxes 8.4–8.5, applied to the trial log strain as von Mises and
/// Drucker–Prager are): on the principal stresses τ₁ ≥ τ₂ ≥ τ₃ (tension positive),
/// f = (τ₁ − τ₃) + (τ₁ + τ₃) sin φ − 2 c cos φ, flow potential with ψ in place of φ,
/// c = c₀ + H ε̄ᵖ, ε̄ᵖ growing at de Souza Neto's rates (§8.2.2): 2 cos φ Δγ on the main plane,
/// 2 cos φ (Δγ_a + Δγ_b) on an edge, (cos φ / sin ψ) Δεᵥᵖ at the apex. Hencky elasticity is isotropic, so the return acts on the principal values
/// of the trial strain and the stress keeps the trial eigenvectors.
///
/// Return: the one-vector return to the main plane; where it breaks the ordering, the
/// two-vector return to the edge the trial state faces (right, τ₂ = τ₃, when
/// (1 − sin ψ) τ₁ − 2 τ₂ + (1 + sin ψ) τ₃ > 0, else left, τ₁ = τ₂); where that breaks the
/// ordering or needs a negative multiplier, the apex p = c cot φ. The hardening is linear, so
/// each return's residual is linear in its multipliers and Newton's first iterate is exact:
/// the multipliers are solved in closed form, hardening or not.
///
/// Consistent tangent: D^p = D^e − Σ (D^e n_i) (A⁻¹)_ij (D^e a_j)ᵀ on the active planes
/// (a_j their normals, n_i their flow vectors, A_ij = a_i · D^e n_j + 4 H cos²φ), the apex's
/// K (1 − K / (K + α H cot φ)) in every entry, assembled with the trial eigenvectors by the
/// isotropic-function formula (de Souza Neto Appendix A). Checked against central
/// differences on every branch in the tests.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MohrCoulomb {
    pub young_modulus: f64,
    pub poisson_ratio: f64,
    pub cohesion: f64,
    /// φ and ψ in degrees.
    pub friction_angle: f64,
    pub dilatancy_angle: f64,
    pub hardening_modulus: f64,
    bulk: f64,
    shear: f64,
    sin_phi: f64,
    cos_phi: f64,
    sin_psi: f64,
}

/// Which surface a trial state returns to; public so that tests can count the branches.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ReturnBranch {
    Elastic,
    MainPlane,
    /// τ₁ = τ₂ ≥ τ₃ (triaxial compression in soil mechanics' terms).
    LeftEdge,
    /// τ₁ ≥ τ₂ = τ₃ (triaxial extension).
    RightEdge,
    Apex,
}

/// A return with the quantities its tangent needs.
enum Branch {
    Elastic,
    Plane,
    /// The second plane's index in [`planes`] (1 right, 2 left) and A⁻¹ of the two planes.
    Edge(usize, Matrix2<f64>),
    Apex,
}

/// The result of the return in principal space.
struct Return {
    /// Trial principal strains, in the order of decreasing stress.
    eps: Vector3<f64>,
    /// Their eigenvectors, as columns in the same order.
    q: Matrix3<f64>,
    /// The returned principal stresses.
    tau: Vector3<f64>,
    branch: Branch,
    /// The updated ε̄ᵖ.
    ep: f64,
}

/// The normals of the main plane (τ₁, τ₃), the right plane (τ₁, τ₂) and the left plane (τ₂,
/// τ₃) for an angle's sine: the yield normals with sin φ, the flow vectors with sin ψ.
fn planes(s: f64) -> [Vector3<f64>; 3] {
    [
        Vector3::new(1.0 + s, 0.0, -(1.0 - s)),
        Vector3::new(1.0 + s, -(1.0 - s), 0.0),
        Vector3::new(0.0, 1.0 + s, -(1.0 - s)),
    ]
}

/// The eigenvalues of a symmetric matrix in decreasing order and their eigenvectors.
fn sorted_eigen(m: &Matrix3<f64>) -> (Vector3<f64>, Matrix3<f64>) {
    let (e, q) = sym_eigen(m);
    let mut order = [0usize, 1, 2];
    order.sort_by(|&a, &b| e[b].total_cmp(&e[a]));
    (
        Vector3::from_fn(|a, _| e[order[a]]),
        Matrix3::from_fn(|i, a| q[(i, order[a])]),
    )
}

impl MohrCoulomb {
    /// E > 0, −1 < ν < 0.5, c₀ ≥ 0, 0 ≤ ψ ≤ φ < 90°, H finite.
    pub fn try_new(
        young_modulus: f64,
        poisson_ratio: f64,
        cohesion: f64,
        friction_angle: f64,
        dilatancy_angle: f64,
        hardening_modulus: f64,
    ) -> Result<Self, InputError> {
        super::LinearElastic::try_new(young_modulus, poisson_ratio)?;
        friction::check(cohesion, friction_angle, dilatancy_angle, hardening_modulus)?;
        let (lambda, mu) = lame(young_modulus, poisson_ratio);
        let (sin_phi, cos_phi) = friction_angle.to_radians().sin_cos();
        Ok(Self {
            young_modulus,
            poisson_ratio,
            cohesion,
            friction_angle,
            dilatancy_angle,
            hardening_modulus,
            bulk: lambda + 2.0 * mu / 3.0,
            shear: mu,
            sin_phi,
            cos_phi,
            sin_psi: dilatancy_angle.to_radians().sin(),
        })
    }

    /// The elastic law on principal values: λ 1 1ᵀ + 2G I.
    fn principal_elastic(&self) -> Matrix3<f64> {
        let lambda = self.bulk - 2.0 * self.shear / 3.0;
        Matrix3::repeat(lambda) + Matrix3::identity() * (2.0 * self.shear)
    }

    /// f = (τ₁ − τ₃) + (τ₁ + τ₃) sin φ − 2 c cos φ of a Kirchhoff stress at plastic strain
    /// `ep`, on its ordered principal values (the largest of the six planes' values).
    pub fn yield_function(&self, tau: &Matrix3<f64>, ep: f64) -> f64 {
        let (t, _) = sorted_eigen(tau);
        let c = self.cohesion + self.hardening_modulus * ep;
        planes(self.sin_phi)[0].dot(&t) - 2.0 * c * self.cos_phi
    }

    /// The branch the trial strain returns to from the committed state.
    pub fn branch(
        &self,
        eps_trial: &Matrix3<f64>,
        committed: &MaterialState,
    ) -> Result<ReturnBranch, MaterialError> {
        Ok(
            match self
                .principal_return(eps_trial, committed.internal.get(0))?
                .branch
            {
                Branch::Elastic => ReturnBranch::Elastic,
                Branch::Plane => ReturnBranch::MainPlane,
                Branch::Edge(1, _) => ReturnBranch::RightEdge,
                Branch::Edge(..) => ReturnBranch::LeftEdge,
                Branch::Apex => ReturnBranch::Apex,
            },
        )
    }

    /// The return map in principal space from plastic strain `ep`.
    fn principal_return(&self, eps_trial: &Matrix3<f64>, ep: f64) -> Result<Return, MaterialError> {
        let (k, h) = (self.bulk, self.hardening_modulus);
        let (eps, q) = sorted_eigen(eps_trial);
        let de = self.principal_elastic();
        let tau_t = de * eps;
        let c_n = self.cohesion + h * ep;
        let two_c_cos = 2.0 * c_n * self.cos_phi;
        let (a, n) = (planes(self.sin_phi), planes(self.sin_psi));
        let done = |tau, branch, ep| {
            Ok(Return {
                eps,
                q,
                tau,
                branch,
                ep,
            })
        };
        let f_t = a[0].dot(&tau_t) - two_c_cos;
        if f_t <= 0.0 {
            return done(tau_t, Branch::Elastic, ep);
        }
        // Every plane's residual has the same hardening term: c grows by 2 H cos φ per Δγ.
        let hk = 4.0 * h * self.cos_phi * self.cos_phi;
        let den = a[0].dot(&(de * n[0])) + hk;
        if den <= 0.0 {
            return Err(MaterialError(format!(
                "Mohr–Coulomb: the softening modulus {h} makes the main-plane return unstable (a · Dᵉ n + 4 H cos²φ = {den} ≤ 0)"
            )));
        }
        let dgamma = f_t / den;
        let tau = tau_t - de * n[0] * dgamma;
        // The main plane holds while its return keeps the ordering (a seeded bug keeps it
        // always, returning edge states with one multiplier).
        let one_multiplier = cfg!(feature = "seeded-bugs") && seeded_one_multiplier();
        if (tau[0] >= tau[1] && tau[1] >= tau[2]) || one_multiplier {
            return done(tau, Branch::Plane, ep + 2.0 * self.cos_phi * dgamma);
        }
        // The main plane's return path lies in a plane through the hydrostatic axis; the
        // trial state's side of it says which ordering the return breaks (Box 8.5).
        let right = (1.0 - self.sin_psi) * tau_t[0] - 2.0 * tau_t[1] + (1.0 + self.sin_psi) * tau_t[2] > 0.0;
        let b = if right { 1 } else { 2 };
        let m = Matrix2::new(
            a[0].dot(&(de * n[0])) + hk,
            a[0].dot(&(de * n[b])) + hk,
            a[b].dot(&(de * n[0])) + hk,
            a[b].dot(&(de * n[b])) + hk,
        );
        let det = m.determinant();
        if det <= 0.0 {
            return Err(MaterialError(format!(
                "Mohr–Coulomb: the softening modulus {h} makes the edge return unstable (det A = {det} ≤ 0)"
            )));
        }
        let inv = Matrix2::new(m[(1, 1)], -m[(0, 1)], -m[(1, 0)], m[(0, 0)]) / det;
        let g = inv * Vector2::new(f_t, a[b].dot(&tau_t) - two_c_cos);
        let tau = tau_t - de * (n[0] * g[0] + n[b] * g[1]);
        // On the edge the two planes' equality makes the edge pair equal; the third value
        // must stay on its side of them.
        let ordered = if right { tau[0] >= tau[1] } else { tau[1] >= tau[2] };
        if ordered && g[0] >= 0.0 && g[1] >= 0.0 {
            return done(tau, Branch::Edge(b, inv), ep + 2.0 * self.cos_phi * (g[0] + g[1]));
        }
        if self.sin_phi == 0.0 || self.sin_psi == 0.0 {
            return Err(MaterialError(
                "Mohr–Coulomb: a return to the apex needs friction and dilatancy angles > 0".into(),
            ));
        }
        // Apex: p = c cot φ with c hardened by α Δεᵥᵖ, α = cos φ / sin ψ (Box 8.5).
        let cot = self.cos_phi / self.sin_phi;
        let alpha = self.cos_phi / self.sin_psi;
        let den = k + alpha * h * cot;
        if den <= 0.0 {
            return Err(MaterialError(format!(
                "Mohr–Coulomb: the softening modulus {h} makes the apex return unstable (K + α H cot φ = {den} ≤ 0)"
            )));
        }
        let p_t = tau_t.sum() / 3.0;
        let dv = (p_t - c_n * cot) / den;
        done(Vector3::repeat(p_t - k * dv), Branch::Apex, ep + alpha * dv)
    }

    /// D^p_ab = ∂τ_a/∂ε_b of a return, in its order of principal values.
    fn principal_tangent(&self, r: &Return) -> Matrix3<f64> {
        let de = self.principal_elastic();
        let (a, n) = (planes(self.sin_phi), planes(self.sin_psi));
        let hk = 4.0 * self.hardening_modulus * self.cos_phi * self.cos_phi;
        match r.branch {
            Branch::Elastic => de,
            Branch::Plane => {
                let den = a[0].dot(&(de * n[0])) + hk;
                de - (de * n[0]) * (de * a[0]).transpose() / den
            }
            Branch::Edge(b, inv) => {
                let (ia, ib) = ([0, b], [0, b]);
                let mut d = de;
                for (i, &pi) in ia.iter().enumerate() {
                    for (j, &pj) in ib.iter().enumerate() {
                        d -= (de * n[pi]) * (de * a[pj]).transpose() * inv[(i, j)];
                    }
                }
                d
            }
            Branch::Apex => {
                let (k, h) = (self.bulk, self.hardening_modulus);
                let cot = self.cos_phi / self.sin_phi;
                let alpha = self.cos_phi / self.sin_psi;
                Matrix3::repeat(k * (1.0 - k / (k + alpha * h * cot)))
            }
        }
    }
}

/// The seeded bug of this model: an edge state returned to the main plane with its one
/// multiplier.
#[cfg(feature = "seeded-bugs")]
fn seeded_one_multiplier() -> bool {
    crate::seeded::active(crate::seeded::Bug::MohrCoulombEdgeOneMultiplier)
}

#[cfg(not(feature = "seeded-bugs"))]
fn seeded_one_multiplier() -> bool {
    false
}

impl ConstitutiveModel for MohrCoulomb {
    fn update(
        &self,
        eps_trial: &Matrix3<f64>,
        committed: &MaterialState,
    ) -> Result<MaterialResponse, MaterialError> {
        let r = self.principal_return(eps_trial, committed.internal.get(0))?;
        let tau = r.q * Matrix3::from_diagonal(&r.tau) * r.q.transpose();
        // Elastic strain from the stress: ε = dev τ / 2G + tr τ / 9K 1.
        let tr = tau.trace();
        let eps_e = (tau - Matrix3::identity() * (tr / 3.0)) / (2.0 * self.shear)
            + Matrix3::identity() * (tr / (9.0 * self.bulk));
        if !(eps_e.iter().all(|v| v.is_finite()) && r.ep.is_finite()) {
            return Err(MaterialError(
                "Mohr–Coulomb return map produced a non-finite strain".into(),
            ));
        }
        Ok(MaterialResponse {
            tau,
            eps_e,
            internal: InternalVariables::from_slice(&[r.ep]),
        })
    }

    /// D_ijkl = Σ_ab D^p_ab e_a,i e_a,j e_b,k e_b,l + Σ_{a≠b} θ_ab e_a,i e_b,j ½(e_a,k e_b,l +
    /// e_b,k e_a,l), θ_ab = (τ_a − τ_b)/(ε_a − ε_b), → D^p_aa − D^p_ab as ε_b → ε_a (de Souza
    /// Neto Appendix A). On an edge (its pair) and at the apex (every pair) τ_a = τ_b on the
    /// whole branch, so θ_ab = 0 there exactly rather than a quotient of round-off.
    fn tangent(&self, eps_trial: &Matrix3<f64>, committed: &MaterialState) -> Tensor4 {
        let r = match self.principal_return(eps_trial, committed.internal.get(0)) {
            Ok(r) => r,
            // A state the update refuses: its error ends the iteration first.
            Err(_) => {
                let (eps, q) = sorted_eigen(eps_trial);
                let de = self.principal_elastic();
                Return {
                    eps,
                    q,
                    tau: de * eps,
                    branch: Branch::Elastic,
                    ep: 0.0,
                }
            }
        };
        let dp = self.principal_tangent(&r);
        let scale = r.eps.amax();
        let theta = Matrix3::from_fn(|a, b| {
            let equal_on_branch = match r.branch {
                Branch::Apex => true,
                Branch::Edge(1, _) => a.min(b) == 1 && a.max(b) == 2,
                Branch::Edge(..) => a.min(b) == 0 && a.max(b) == 1,
                _ => false,
            };
            let gap = r.eps[a] - r.eps[b];
            if a == b || equal_on_branch {
                0.0
            } else if gap.abs() <= 1e-12 * scale {
                dp[(a, a)] - dp[(a, b)]
            } else {
                (r.tau[a] - r.tau[b]) / gap
            }
        });
        let q = &r.q;
        let mut d = Tensor4::zeros();
        for i in 0..3 {
            for j in 0..3 {
                for k in 0..3 {
                    for l in 0..3 {
                        let mut s = 0.0;
                        for a in 0..3 {
                            let qa = q[(i, a)] * q[(j, a)];
                            for b in 0..3 {
                                s += dp[(a, b)] * qa * q[(k, b)] * q[(l, b)]
                                    + theta[(a, b)]
                                        * q[(i, a)]
                                        * q[(j, b)]
                                        * 0.5
                                        * (q[(k, a)] * q[(l, b)] + q[(k, b)] * q[(l, a)]);
                            }
                        }
                        d[(ij(i, j), ij(k, l))] = s;
                    }
                }
            }
        }
        d
    }

    /// Unsymmetric on the plastic branches under non-associated flow (ψ ≠ φ).
    fn tangent_is_symmetric(&self) -> bool {
        self.dilatancy_angle == self.friction_angle
    }

    fn young_modulus(&self) -> f64 {
        self.young_modulus
    }

    fn internal_variables(&self) -> &'static [InternalVariable] {
        &[EQUIVALENT_PLASTIC_STRAIN]
    }
}
