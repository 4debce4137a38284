//! Updated-Lagrangian finite-deformation kinematics shared by every discretisation:
//! the deformation-gradient increment on the start-of-step configuration (eq 31), the trial
//! elastic left Cauchy–Green tensor and log strain (eqs 15–19), Cauchy stress (eq 16), the
//! spatial consistent tangent (eq 25), the spatial derivative mapping (eqs 35–36) and the
//! stretch tensor used to update domains (eq 38).
//!
//! All per-point tensors are 3×3 even in 1D and 2D: a `D`-dimensional problem deforms the
//! leading `D×D` block of F and keeps the out-of-plane stretches at one (uniaxial strain in
//! 1D, plane strain in 2D), so one constitutive code serves all dimensions.

use crate::material::constitutive::{ConstitutiveModel, MaterialResponse, MaterialState};
use crate::material::tensor::{ij, Tensor4};
use nalgebra::{Matrix3, SMatrix, SymmetricEigen, Vector3};

/// Eigen-decomposition of a symmetric 3×3 matrix: eigenvalues and eigenvectors (columns).
///
/// 1D and plane-strain problems keep the out-of-plane axes principal, so the matrices met in
/// practice are diagonal or have a single 2×2 block; those are decomposed in closed form
/// (exactly, with no iteration), anything else by nalgebra's symmetric QR algorithm.
#[inline]
pub fn sym_eigen(m: &Matrix3<f64>) -> (Vector3<f64>, Matrix3<f64>) {
    if m[(0, 2)] == 0.0 && m[(1, 2)] == 0.0 && m[(2, 0)] == 0.0 && m[(2, 1)] == 0.0 {
        let (a, b, c) = (m[(0, 0)], 0.5 * (m[(0, 1)] + m[(1, 0)]), m[(1, 1)]);
        if b == 0.0 {
            return (Vector3::new(a, c, m[(2, 2)]), Matrix3::identity());
        }
        // Rotation by θ with tan 2θ = 2b / (a − c) diagonalises the block.
        let theta = 0.5 * (2.0 * b).atan2(a - c);
        let (sn, cs) = theta.sin_cos();
        let l1 = a * cs * cs + 2.0 * b * sn * cs + c * sn * sn;
        let l2 = a * sn * sn - 2.0 * b * sn * cs + c * cs * cs;
        let q = Matrix3::new(cs, -sn, 0.0, sn, cs, 0.0, 0.0, 0.0, 1.0);
        return (Vector3::new(l1, l2, m[(2, 2)]), q);
    }
    let e = SymmetricEigen::new(*m);
    (e.eigenvalues, e.eigenvectors)
}

/// Isotropic function of a symmetric matrix from its spectral decomposition.
#[inline]
pub fn spectral_map(lam: &Vector3<f64>, q: &Matrix3<f64>, f: impl Fn(f64) -> f64) -> Matrix3<f64> {
    let d = Matrix3::from_diagonal(&lam.map(f));
    q * d * q.transpose()
}

/// Logarithmic strain ε = ½ ln b, eqs (15) and (19). Requires b symmetric positive definite.
pub fn log_strain(b: &Matrix3<f64>) -> Option<Matrix3<f64>> {
    let (lam, q) = sym_eigen(b);
    if lam.iter().any(|&l| !(l > 0.0 && l.is_finite())) {
        return None;
    }
    Some(spectral_map(&lam, &q, |l| 0.5 * l.ln()))
}

/// b = exp(2ε), eq (18).
pub fn left_cauchy_green_from_strain(eps: &Matrix3<f64>) -> Matrix3<f64> {
    let (lam, q) = sym_eigen(eps);
    spectral_map(&lam, &q, |l| (2.0 * l).exp())
}

/// Right stretch tensor U = √(FᵀF), eq (38).
pub fn stretch_tensor(f: &Matrix3<f64>) -> Matrix3<f64> {
    let (lam, q) = sym_eigen(&(f.transpose() * f));
    spectral_map(&lam, &q, |l| l.max(0.0).sqrt())
}

/// First divided difference of ln at (a, b), stable as a → b (limit 1/a).
#[inline]
fn ln_divided_difference(a: f64, b: f64) -> f64 {
    let d = a - b;
    if d == 0.0 {
        1.0 / b
    } else {
        (d / b).ln_1p() / d
    }
}

/// Divided differences Θ_ab of ln at the eigenvalues (Θ_aa = 1/λ_a).
#[inline]
fn log_divided_differences(lam: &Vector3<f64>) -> Matrix3<f64> {
    Matrix3::from_fn(|a, b| ln_divided_difference(lam[a], lam[b]))
}

/// L_mnpq = ∂ ln(b)_mn / ∂ b_pq (eq 26) by the Daleckii–Krein formula for the derivative of a
/// symmetric matrix function: `dln(b)[H] = Q (Θ ∘ QᵀHQ) Qᵀ` with `Θ_aa = 1/λ_a` and
/// `Θ_ab = (ln λ_a − ln λ_b)/(λ_a − λ_b)` (the closed form of Miehe's algorithm, paper ref. 102).
pub fn dlog(lam: &Vector3<f64>, q: &Matrix3<f64>) -> Tensor4 {
    let theta = log_divided_differences(lam);
    let mut l = Tensor4::zeros();
    for m in 0..3 {
        for n in 0..3 {
            for p in 0..3 {
                for qq in 0..3 {
                    let mut s = 0.0;
                    for a in 0..3 {
                        let ma = q[(m, a)] * q[(p, a)];
                        for b in 0..3 {
                            s += ma * q[(n, b)] * q[(qq, b)] * theta[(a, b)];
                        }
                    }
                    l[(ij(m, n), ij(p, qq))] = s;
                }
            }
        }
    }
    l
}

/// Whether the tangent carries its geometric term (always, unless a seeded bug removes it).
#[inline(always)]
fn geometric_term() -> bool {
    #[cfg(feature = "seeded-bugs")]
    if crate::seeded::active(crate::seeded::Bug::NoGeometricTerm) {
        return false;
    }
    true
}

/// Spatial consistent tangent a_ijkl = (1/2J) D^alg_ijmn L_mnpq B_pqkl − σ_il δ_jk, eqs (25)–(26),
/// with B_pqkl = δ_pk b_ql + δ_qk b_pl evaluated at the trial b^e.
///
/// Only entries with all of i, j, k, l < `D` are computed (the rest stay zero): a `D`-dimensional
/// discretisation never contracts the others.
pub fn spatial_tangent<const D: usize>(
    d_alg: &Tensor4,
    l: &Tensor4,
    b: &Matrix3<f64>,
    sigma: &Matrix3<f64>,
    j: f64,
) -> Tensor4 {
    // (L B)_{mn,kl} = L_{mn,kq} b_ql + L_{mn,pk} b_pl, only for active k, l.
    let mut lb = Tensor4::zeros();
    for r in 0..9 {
        for k in 0..D {
            for ll in 0..D {
                let mut s = 0.0;
                for q in 0..3 {
                    s += l[(r, ij(k, q))] * b[(q, ll)] + l[(r, ij(q, k))] * b[(q, ll)];
                }
                lb[(r, ij(k, ll))] = s;
            }
        }
    }
    let mut a = Tensor4::zeros();
    let scale = 0.5 / j;
    for i in 0..D {
        for jj in 0..D {
            let row = ij(i, jj);
            for k in 0..D {
                for ll in 0..D {
                    let col = ij(k, ll);
                    let mut s = 0.0;
                    for r in 0..9 {
                        s += d_alg[(row, r)] * lb[(r, col)];
                    }
                    a[(row, col)] = scale * s
                        - if jj == k && geometric_term() {
                            sigma[(i, ll)]
                        } else {
                            0.0
                        };
                }
            }
        }
    }
    a
}

/// The strain rate ½ L : B : (e_k ⊗ e_l) from the eigenbasis `q` of the trial b^e, its
/// eigenvalues `lam` and Θ = `theta`, their divided differences of ln:
/// (Qᵀ ½L:B_kl Q)_ab = ½ Θ_ab (Q_ka Q_lb λ_b + Q_la Q_kb λ_a).
#[inline(always)]
fn log_strain_rate(
    theta: &Matrix3<f64>,
    lam: &Vector3<f64>,
    q: &Matrix3<f64>,
    k: usize,
    l: usize,
) -> Matrix3<f64> {
    let hat = Matrix3::from_fn(|x, y| {
        0.5 * theta[(x, y)] * (q[(k, x)] * q[(l, y)] * lam[y] + q[(l, x)] * q[(k, y)] * lam[x])
    });
    q * hat * q.transpose()
}

/// Spatial tangent of eq (25) without forming L: for each active (k, l), the strain rate
/// ½ L : B : (e_k ⊗ e_l) is evaluated in the eigenbasis of the trial b^e, where with
/// b = Q Λ Qᵀ and Θ the divided differences of ln,
/// (Qᵀ ½L:B_kl Q)_ab = ½ Θ_ab (Q_ka Q_lb λ_b + Q_la Q_kb λ_a).
/// Equal to [`spatial_tangent`] (checked in the tests) at a fraction of the cost.
pub fn spatial_tangent_eigen<const D: usize>(
    d_alg: &Tensor4,
    lam: &Vector3<f64>,
    q: &Matrix3<f64>,
    sigma: &Matrix3<f64>,
    j: f64,
) -> Tensor4 {
    let theta = log_divided_differences(lam);
    let mut a = Tensor4::zeros();
    // In 1D and 2D the eigenvectors of b keep the out-of-plane axes apart (`sym_eigen`'s
    // exact block), so de vanishes outside its leading D × D block for in-plane k, l and the
    // contraction with D^alg skips those zero terms (the same sums, but for signed zeros).
    let block = (0..3).all(|r| (0..3).all(|c| (r < D) == (c < D) || q[(r, c)] == 0.0));
    let dm = if block { D } else { 3 };
    for k in 0..D {
        for l in 0..D {
            let de = log_strain_rate(&theta, lam, q, k, l);
            let col = ij(k, l);
            // D^alg : de for all nine rows at once, column by column of D^alg (contiguous)
            // in the order r = ij(m, n) ascending: each row's sum takes its products in the
            // order the row-by-row loop did, so the values are the same to the bit, and the
            // nine rows vectorise.
            let mut s = [0.0; 9];
            for m in 0..dm {
                for n in 0..dm {
                    let e = de[(m, n)];
                    let column = d_alg.fixed_view::<9, 1>(0, ij(m, n));
                    for (acc, d) in s.iter_mut().zip(column.iter()) {
                        *acc += d * e;
                    }
                }
            }
            for i in 0..D {
                for jj in 0..D {
                    let row = ij(i, jj);
                    a[(row, col)] = s[row] / j
                        - if jj == k && geometric_term() {
                            sigma[(i, l)]
                        } else {
                            0.0
                        };
                }
            }
        }
    }
    a
}

/// The trace over all three axes of [`spatial_tangent_eigen`]'s material part: T_kl =
/// Σ_m (D^alg : ½L:B_kl)_mm / J for in-plane k, l, the rate of tr τ / J per ∂Δu_k/∂x_l. The
/// spatial tangent keeps only in-plane rows; the pressure projection needs the out-of-plane
/// one too (reference/README.md item 75).
pub fn spatial_trace_tangent<const D: usize>(
    d_alg: &Tensor4,
    lam: &Vector3<f64>,
    q: &Matrix3<f64>,
    j: f64,
) -> Matrix3<f64> {
    let theta = log_divided_differences(lam);
    let mut t = Matrix3::zeros();
    for k in 0..D {
        for l in 0..D {
            let de = log_strain_rate(&theta, lam, q, k, l);
            let mut s = 0.0;
            for a in 0..3 {
                for m in 0..3 {
                    for n in 0..3 {
                        s += d_alg[(ij(a, a), ij(m, n))] * de[(m, n)];
                    }
                }
            }
            t[(k, l)] = s / j;
        }
    }
    t
}

/// Embed a `D×D` displacement-gradient block into the 3×3 deformation-gradient increment
/// ΔF = I + ∂Δu/∂X̃, eq (31).
#[inline]
pub fn delta_f_from_gradient<const D: usize>(grad_du: &SMatrix<f64, D, D>) -> Matrix3<f64> {
    let mut df = Matrix3::identity();
    for i in 0..D {
        for j in 0..D {
            df[(i, j)] += grad_du[(i, j)];
        }
    }
    df
}

/// The state of one integration point (material point or Gauss point) at the last
/// converged load step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PointState {
    /// Deformation gradient F_n.
    pub f: Matrix3<f64>,
    /// Volume V_p^n in the last converged configuration.
    pub volume: f64,
    /// Kirchhoff stress τ of the last converged step (σ = τ / det F).
    pub tau: Matrix3<f64>,
    /// Committed constitutive state.
    pub material: MaterialState,
}

impl PointState {
    /// Cauchy stress σ = τ / det F, eq (16).
    pub fn cauchy(&self) -> Matrix3<f64> {
        self.tau / self.f.determinant()
    }

    /// Undeformed state with volume `volume`.
    pub fn undeformed(volume: f64) -> Self {
        Self {
            f: Matrix3::identity(),
            volume,
            tau: Matrix3::zeros(),
            material: MaterialState::default(),
        }
    }
}

/// Result of evaluating one integration point at a trial displacement increment.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PointTrial<const D: usize> {
    /// ΔF, eq (31). F = ΔF F_n (eq 30) and σ = τ/J (eq 16) are not stored but formed when
    /// asked ([`Self::f`], [`Self::sigma`]), by the same operations as at the evaluation: 144
    /// bytes less per point (0.58 GB of the 1,002,528-element Q4 reference's 4e6 Gauss points).
    pub delta_f: Matrix3<f64>,
    /// Current volume V_p = det(ΔF) V_p^n, eq (28).
    pub volume: f64,
    /// Inverse of the in-plane block of ΔF, mapping ∂/∂X̃ to ∂/∂x (eqs 35–36).
    pub delta_f_inv: SMatrix<f64, D, D>,
    /// Constitutive response (τ, ε^e, internal variables).
    pub response: MaterialResponse,
    /// Eigenvalues of the trial b^e.
    pub b_trial_eigenvalues: Vector3<f64>,
    /// Eigenvectors (columns) of the trial b^e.
    pub b_trial_eigenvectors: Matrix3<f64>,
    /// J = det F.
    pub j: f64,
}

/// Why a point could not be evaluated.
#[derive(Debug, Clone, PartialEq)]
pub enum PointError {
    /// det ΔF ≤ 0 or non-finite: the trial increment inverts the material.
    Inverted(f64),
    /// The trial b^e is not positive definite or not finite.
    BadStrain,
    /// The constitutive update failed.
    Material(String),
}

impl std::fmt::Display for PointError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            PointError::Inverted(j) => write!(f, "det(dF) = {j:e} <= 0: the increment inverts the material"),
            PointError::BadStrain => write!(f, "trial elastic b is not symmetric positive definite"),
            PointError::Material(m) => write!(f, "constitutive update failed: {m}"),
        }
    }
}

/// Evaluate one integration point: trial kinematics (eqs 17, 19, 30, 31), the stress update,
/// Cauchy stress (eq 16) and current volume (eq 28). The spatial tangent (eq 25) follows from
/// the result on demand ([`PointTrial::spatial_tangent`]), so residual-only evaluations do not
/// pay for it.
///
/// `grad_du` is ∂Δu/∂X̃ on the start-of-step configuration (eq 32).
///
/// Inlined into its callers so that the trial is built where they store it, not copied
/// there (about 400 bytes a point; reference/README.md item 64).
#[inline(always)]
pub fn evaluate_point<const D: usize>(
    model: &dyn ConstitutiveModel,
    state: &PointState,
    grad_du: &SMatrix<f64, D, D>,
) -> Result<PointTrial<D>, PointError> {
    let delta_f = delta_f_from_gradient(grad_du);
    let det_df = delta_f.determinant();
    if !(det_df > 0.0 && det_df.is_finite()) {
        return Err(PointError::Inverted(det_df));
    }
    let j = det_df * state.f.determinant();
    let b_trial = delta_f * state.material.b_e * delta_f.transpose(); // eq (17)
    let b_trial = 0.5 * (b_trial + b_trial.transpose());
    let (lam, q) = sym_eigen(&b_trial);
    if lam.iter().any(|&l| !(l > 0.0 && l.is_finite())) {
        return Err(PointError::BadStrain);
    }
    let eps_trial = spectral_map(&lam, &q, |l| 0.5 * l.ln()); // eq (19)
    let response = model
        .update(&eps_trial, &state.material)
        .map_err(|e| PointError::Material(e.0))?;
    let block = SMatrix::<f64, D, D>::from_fn(|r, c| delta_f[(r, c)]);
    #[allow(unused_mut)]
    let mut delta_f_inv = block.try_inverse().ok_or(PointError::Inverted(det_df))?;
    #[allow(unused_mut)]
    let mut volume = det_df * state.volume; // eq (28)
    #[cfg(feature = "seeded-bugs")]
    {
        use crate::seeded::{active, Bug};
        if active(Bug::NoDeltaFInverse) {
            delta_f_inv = SMatrix::identity();
        }
        if active(Bug::NoVolumeChange) {
            volume = state.volume;
        }
    }
    Ok(PointTrial {
        delta_f,
        volume,
        delta_f_inv,
        response,
        b_trial_eigenvalues: lam,
        b_trial_eigenvectors: q,
        j,
    })
}

impl<const D: usize> PointTrial<D> {
    /// Trial elastic log strain ε^e_t = ½ ln b^e_t, eq (19).
    pub fn eps_trial(&self) -> Matrix3<f64> {
        spectral_map(&self.b_trial_eigenvalues, &self.b_trial_eigenvectors, |l| {
            0.5 * l.ln()
        })
    }

    /// Spatial tangent a_ijkl, eq (25), at this trial state (active components only);
    /// `committed` is the state the trial was evaluated from.
    pub fn spatial_tangent(&self, model: &dyn ConstitutiveModel, committed: &PointState) -> Tensor4 {
        let eps = if model.tangent_reads_strain() {
            self.eps_trial()
        } else {
            Matrix3::zeros()
        };
        let d_alg = model.tangent(&eps, &committed.material);
        spatial_tangent_eigen::<D>(
            &d_alg,
            &self.b_trial_eigenvalues,
            &self.b_trial_eigenvectors,
            &self.sigma(),
            self.j,
        )
    }

    /// The trial elastic left Cauchy–Green tensor b^e_t, eq (17).
    pub fn b_trial(&self) -> Matrix3<f64> {
        spectral_map(&self.b_trial_eigenvalues, &self.b_trial_eigenvectors, |l| l)
    }

    /// Cauchy stress σ = τ/J, eq (16).
    #[inline]
    pub fn sigma(&self) -> Matrix3<f64> {
        self.response.tau / self.j
    }

    /// F = ΔF F_n, eq (30), from the state `start` the trial was evaluated from.
    #[inline]
    pub fn f(&self, start: &PointState) -> Matrix3<f64> {
        self.delta_f * start.f
    }

    /// The state to commit once the load step has converged; `start` is the state the trial
    /// was evaluated from.
    pub fn committed(&self, start: &PointState) -> PointState {
        PointState {
            f: self.f(start),
            volume: self.volume,
            tau: self.response.tau,
            material: MaterialState {
                eps_e: self.response.eps_e,
                b_e: left_cauchy_green_from_strain(&self.response.eps_e),
                internal: self.response.internal,
            },
        }
    }
}
