//! Large-deflection elastica of an end-loaded cantilever: the analytical reference of the
//! cantilever example (§5.3, Figure 21).
//!
//! An inextensible, shear-free Euler–Bernoulli rod of length L and bending stiffness EI is
//! clamped horizontally at s = 0 and carries a dead load P at s = L whose direction stays
//! vertical. The entry points are [`tip_elliptic`] (closed form in elliptic integrals, the
//! reference) and [`tip_shooting`] (RK4 shooting on the elastica ODE, the independent check),
//! both in terms of the load parameter α = PL²/EI, and [`Elastica`], which carries L and EI
//! and returns the tip response or the whole load path for given loads P. [`bending_stiffness`]
//! gives the EI that matches a plane-strain or plane-stress continuum beam.
//!
//! # Sign convention
//! `u_over_l` is the horizontal displacement of the tip over L: negative, towards the clamp.
//! `v_over_l` is the tip deflection over L measured *in the direction of the load*, so it is
//! positive; in a y-up frame with a downward load the tip displacement is (u, −v).
//! `end_rotation` is the tip slope θ(L) in radians, turning towards the load.
//!
//! # Plane strain and plane stress
//! A 2D continuum beam of depth h and unit width bends like a rod with
//! EI = E h³/12 in plane stress, and EI' = E/(1 − ν²) · h³/12 in plane strain (the
//! out-of-plane strain is suppressed, so the axial fibre stiffness is the plane-strain modulus
//! E/(1 − ν²)). For the paper's beam (E = 12 MPa, ν = 0.2, h = 1 m, L = 10 m, P = 100 kN)
//! this gives α = 10 in plane stress and α = 9.6 in plane strain.
//!
//! # References
//! - K. E. Bisshopp, D. C. Drucker (1945), Large deflection of cantilever beams,
//!   Quarterly of Applied Mathematics 3(3), 272–275.
//! - R. Frisch-Fay (1962), *Flexible Bars*, Butterworths, ch. 2.
//! - B. C. Carlson (1995), Numerical computation of real or complex elliptic integrals,
//!   Numerical Algorithms 10, 13–26; DLMF §19.25, §19.36.

use crate::solver::error::{require_positive, InputError};
use serde::{Deserialize, Serialize};
use std::f64::consts::{FRAC_PI_2, FRAC_PI_4, FRAC_PI_8};

/// Largest load parameter α = PL²/EI accepted. Beyond it the complementary modulus
/// k' ≈ 4 e^{−√α} of the elliptic solution comes close to underflow in R_F's arguments
/// (tan²β with β ≈ k'); the cantilever of Figure 21 has α ≈ 10.
pub const MAX_ALPHA: f64 = 1.0e4;

/// Largest α accepted by [`tip_shooting`]. The shooting problem is ill-conditioned at large
/// α: π/2 − θ_e and the tip curvature fall like e^{−√α}, and at α = 1000 RK4 shooting in
/// double precision misses the elliptic solution by 1e-4 in u/L (it agrees to 2e-10 at
/// α = 300 and 3e-13 at α = 100).
pub const SHOOTING_MAX_ALPHA: f64 = 300.0;

/// Default number of RK4 steps on s ∈ [0, 1] for [`tip_shooting`]; agreement with the elliptic
/// solution is better than 1e-10 for α ≤ 20 (tests/verification/elastica.rs).
pub const SHOOTING_STEPS: usize = 4000;

/// Tip response of the end-loaded elastica (see the module doc for signs).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct TipDisplacement {
    /// Load parameter α = PL²/EI.
    pub alpha: f64,
    /// Horizontal tip displacement over L (≤ 0, towards the clamp).
    pub u_over_l: f64,
    /// Tip deflection over L in the direction of the load (≥ 0).
    pub v_over_l: f64,
    /// Tip rotation θ(L) in radians (0 ≤ θ < π/2).
    pub end_rotation: f64,
}

impl TipDisplacement {
    fn unloaded() -> Self {
        Self {
            alpha: 0.0,
            u_over_l: 0.0,
            v_over_l: 0.0,
            end_rotation: 0.0,
        }
    }
}

/// Bending stiffness per unit width of a 2D continuum beam of depth h:
/// E h³/12 in plane stress, E/(1 − ν²) · h³/12 in plane strain.
pub fn bending_stiffness(
    young: f64,
    poisson: f64,
    depth: f64,
    plane_strain: bool,
) -> Result<f64, InputError> {
    require_positive("young", young)?;
    require_positive("depth", depth)?;
    if !(poisson.is_finite() && poisson > -1.0 && poisson < 0.5) {
        return Err(InputError::new("poisson", poisson, "must be in (-1, 0.5)"));
    }
    let modulus = if plane_strain {
        young / (1.0 - poisson * poisson)
    } else {
        young
    };
    Ok(modulus * depth.powi(3) / 12.0)
}

fn require_alpha(alpha: f64) -> Result<(), InputError> {
    if alpha.is_finite() && (0.0..=MAX_ALPHA).contains(&alpha) {
        Ok(())
    } else {
        Err(InputError::new(
            "alpha",
            alpha,
            format!("must be finite, >= 0 and <= {MAX_ALPHA:e}"),
        ))
    }
}

/// Tip response from the closed-form (elliptic-integral) elastica solution.
///
/// # Derivation
/// Let θ(s) be the tangent angle, turning towards the load, with s ∈ [0, 1] the arc length
/// over L, and (x, y) the position over L with y along the load. The load is dead (always
/// along y), so the bending moment at arc length S = sL is P (X(L) − X(S)) and the
/// Euler–Bernoulli law EI dθ/dS = P (X(L) − X(S)), in s and x = X/L, reads
///
///   θ' = α (x(1) − x(s)),   θ'' = −α cos θ,   θ(0) = 0,   θ'(1) = 0.          (1)
///
/// Multiplying by θ' and integrating from s to 1, with θ_e = θ(1):
///
///   θ'² = 2α (sin θ_e − sin θ).                                                (2)
///
/// θ grows monotonically from 0 to θ_e < π/2. Substitute 1 + sin θ = 2k² sin²φ with
/// k² = (1 + sin θ_e)/2, i.e. k = sin(π/4 + θ_e/2) (Bisshopp & Drucker; Frisch-Fay). Then
/// sin θ_e − sin θ = 2k² cos²φ, cos θ = 2k sin φ Δ(φ) with Δ(φ) = √(1 − k² sin²φ), and
/// dθ = 2k cos φ dφ / Δ, so by (2)
///
///   ds = dθ/θ' = dφ / (√α Δ(φ)),   φ from φ₀ (θ = 0, sin²φ₀ = 1/(2k²)) to π/2 (θ = θ_e).
///
/// *Length.* √α = K(k) − F(φ₀, k). The addition theorem F(φ) + F(ψ) = K when
/// tan φ tan ψ = 1/k' (k'² = 1 − k²), with tan φ₀ = 1/√(sin θ_e), rewrites this without
/// cancellation at small loads as
///
///   √α = F(ψ₀, k),   sin²ψ₀ = sin θ_e / k² = 2 sin θ_e / (1 + sin θ_e),   cos ψ₀ = k'/k.   (3)
///
/// *Horizontal.* From (1) at s = 0, x(1) = θ'(0)/α = √(2 sin θ_e / α), so
///
///   u/L = √(2 sin θ_e / α) − 1.                                                (4)
///
/// *Vertical.* y(1) = ∫ sin θ ds with sin θ = 2k² sin²φ − 1 = 1 − 2Δ², so
/// y(1) = [K − F(φ₀)]/√α − 2 [E(k) − E(φ₀, k)]/√α. The first term is 1 by (3); the companion
/// addition theorem E(φ) + E(ψ) = E(k) + k² sin φ sin ψ (same condition) gives
/// E(k) − E(φ₀) = E(ψ₀) − √(sin θ_e / 2), hence
///
///   v/L = 1 − (2/√α) [E(ψ₀, k) − √(sin θ_e / 2)].                              (5)
///
/// (3) is solved for θ_e by bisection to round-off. The unknown is γ = θ_e/2 when θ_e < π/4
/// and β = π/4 − θ_e/2 (so that k' = sin β, k = cos β) otherwise: each is the small quantity
/// in its regime, so sin θ_e = sin 2γ = cos 2β and k'² = sin²β are both computed to full
/// relative precision, which keeps (4) accurate at small α (u/L ≈ −α²/15) and (3) accurate
/// at large α (k' ≈ 4e^{−√α}). F and E come from Carlson's R_F and R_D ([`carlson_rf`],
/// [`carlson_rd`]).
///
/// Small-load limits (linear beam theory): θ_e = α/2, v/L = α/3, and the shortening from
/// ½∫ w'² ds with w = α(3s² − s³)/6 is u/L = −α²/15.
pub fn tip_elliptic(alpha: f64) -> Result<TipDisplacement, InputError> {
    require_alpha(alpha)?;
    if alpha == 0.0 {
        return Ok(TipDisplacement::unloaded());
    }
    let root_alpha = alpha.sqrt();
    // Residual of (3), increasing with θ_e; (γ, β) with γ + β = π/4.
    let residual = |gamma: f64, beta: f64| ElasticaShape::new(gamma, beta).length() - root_alpha;
    // θ_e = π/4 is the regime boundary: γ = β = π/8.
    let shape = if residual(FRAC_PI_8, FRAC_PI_8) >= 0.0 {
        // θ_e ≤ π/4: bisect on γ ∈ (0, π/8].
        let gamma = bisect(0.0, FRAC_PI_8, |g| residual(g, FRAC_PI_4 - g));
        ElasticaShape::new(gamma, FRAC_PI_4 - gamma)
    } else {
        // θ_e > π/4: bisect on β ∈ (0, π/8); the residual decreases with β.
        let beta = bisect(0.0, FRAC_PI_8, |b| -residual(FRAC_PI_4 - b, b));
        ElasticaShape::new(FRAC_PI_4 - beta, beta)
    };
    let sin_te = shape.sin_te;
    let u_over_l = (2.0 * sin_te / alpha).sqrt() - 1.0;
    let v_over_l = 1.0 - 2.0 / root_alpha * (shape.e_psi0() - (0.5 * sin_te).sqrt());
    Ok(TipDisplacement {
        alpha,
        u_over_l,
        v_over_l,
        end_rotation: 2.0 * shape.gamma,
    })
}

/// The elliptic-solution quantities for θ_e = 2γ = π/2 − 2β.
struct ElasticaShape {
    gamma: f64,
    sin_te: f64,
    /// k² = cos²β.
    k2: f64,
    /// sin ψ₀ and cos²ψ₀ = tan²β of (3).
    sin_psi0: f64,
    cos2_psi0: f64,
    /// Δ²(ψ₀) = 1 − k² sin²ψ₀ = 1 − sin θ_e = 2 sin²β.
    delta2_psi0: f64,
}

impl ElasticaShape {
    fn new(gamma: f64, beta: f64) -> Self {
        let sin_te = if gamma <= beta {
            (2.0 * gamma).sin()
        } else {
            (2.0 * beta).cos()
        };
        let (sb, cb) = beta.sin_cos();
        let k2 = cb * cb;
        let tb = sb / cb;
        Self {
            gamma,
            sin_te,
            k2,
            sin_psi0: sin_te.sqrt() / cb,
            cos2_psi0: tb * tb,
            delta2_psi0: 2.0 * sb * sb,
        }
    }

    /// F(ψ₀, k) = sin ψ₀ R_F(cos²ψ₀, Δ²(ψ₀), 1), which equals √α at the root of (3).
    fn length(&self) -> f64 {
        self.sin_psi0 * carlson_rf(self.cos2_psi0, self.delta2_psi0, 1.0)
    }

    /// E(ψ₀, k) = sin ψ₀ R_F − (k²/3) sin³ψ₀ R_D (DLMF 19.25.9).
    fn e_psi0(&self) -> f64 {
        let s = self.sin_psi0;
        s * carlson_rf(self.cos2_psi0, self.delta2_psi0, 1.0)
            - self.k2 / 3.0 * s * s * s * carlson_rd(self.cos2_psi0, self.delta2_psi0, 1.0)
    }
}

/// Root of an increasing function on [lo, hi] with f(lo) ≤ 0 ≤ f(hi), to round-off: bisect
/// until the midpoint coincides with an end of the bracket.
fn bisect(mut lo: f64, mut hi: f64, f: impl Fn(f64) -> f64) -> f64 {
    loop {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi {
            return mid;
        }
        // NaN (e.g. an R_F overflow at the open end lo = 0) counts as "below the root".
        if f(mid) > 0.0 {
            hi = mid;
        } else {
            lo = mid;
        }
    }
}

/// Tip response from a shooting solution of θ'' = −α cos θ, θ(0) = 0, θ'(1) = 0, with
/// x' = cos θ, y' = sin θ integrated alongside by classical RK4 with `steps` equal steps.
///
/// The unknown initial curvature q = θ'(0) lies in [0, √(2α)] (by (2) of [`tip_elliptic`],
/// q² = 2α sin θ_e); θ'(1) is negative at q = 0 and positive at q = √(2α) (the separatrix,
/// on which θ only approaches π/2). For large α, θ'(1) = 0 also has spurious roots on
/// trajectories that swing back (θ' < 0 inside (0, 1), higher buckled modes); such a
/// trajectory is counted as q too small, which makes the residual monotone in q and selects
/// the monotone solution θ' > 0 on [0, 1). The root is found by Newton with the sensitivity
/// (∂θ/∂q)'' = α sin θ ∂θ/∂q integrated alongside, safeguarded by bisection of the bracket.
/// This uses neither the first integral nor elliptic functions, so it is an independent check
/// of [`tip_elliptic`]; RK4's error falls as steps⁻⁴. α is limited to
/// [`SHOOTING_MAX_ALPHA`].
pub fn tip_shooting(alpha: f64, steps: usize) -> Result<TipDisplacement, InputError> {
    require_alpha(alpha)?;
    if alpha > SHOOTING_MAX_ALPHA {
        return Err(InputError::new(
            "alpha",
            alpha,
            format!("shooting needs alpha <= {SHOOTING_MAX_ALPHA} (use tip_elliptic)"),
        ));
    }
    if steps < 10 {
        return Err(InputError::new("steps", steps, "must be an integer >= 10"));
    }
    if alpha == 0.0 {
        return Ok(TipDisplacement::unloaded());
    }
    let (mut lo, mut hi) = (0.0, (2.0 * alpha).sqrt());
    let mut q = alpha.min(0.5 * hi); // linear theory: θ'(0) = α
    let mut end = integrate_elastica(alpha, q, steps);
    for _ in 0..200 {
        // A trajectory that turned back before s = 1 has S(q) < 1: q is too small.
        let r = end.map_or(-1.0, |z| z[1]);
        if r > 0.0 {
            hi = q;
        } else {
            lo = q;
        }
        let mut next = end.map_or(f64::NAN, |z| q - r / z[5]);
        if !(next > lo && next < hi && next.is_finite()) {
            next = 0.5 * (lo + hi);
        }
        let converged = (next - q).abs() <= 1e-15 * q || hi - lo <= 1e-15 * q;
        q = next;
        end = integrate_elastica(alpha, q, steps);
        if converged {
            break;
        }
    }
    // At very large α the root trajectory ends within round-off of θ' = 0 and may be flagged
    // as turning back; the upper end of the bracket then is the converged trajectory.
    let end = end
        .or_else(|| integrate_elastica(alpha, hi, steps))
        .expect("the upper end of the bracket never turns back");
    Ok(TipDisplacement {
        alpha,
        u_over_l: end[2] - 1.0,
        v_over_l: end[3],
        end_rotation: end[0],
    })
}

/// RK4 on z = (θ, θ', x, y, ∂θ/∂q, ∂θ'/∂q) from s = 0 to 1 with θ'(0) = q; `None` if θ'
/// becomes negative before the last step (the trajectory reached its maximum θ before s = 1).
fn integrate_elastica(alpha: f64, q: f64, steps: usize) -> Option<[f64; 6]> {
    let rhs = |z: &[f64; 6]| -> [f64; 6] {
        let (s, c) = z[0].sin_cos();
        [z[1], -alpha * c, c, s, z[5], alpha * s * z[4]]
    };
    let axpy = |z: &[f64; 6], h: f64, k: &[f64; 6]| -> [f64; 6] { std::array::from_fn(|i| z[i] + h * k[i]) };
    let h = 1.0 / steps as f64;
    let mut z = [0.0, q, 0.0, 0.0, 0.0, 1.0];
    for step in 0..steps {
        if step > 0 && z[1] < 0.0 {
            return None;
        }
        let k1 = rhs(&z);
        let k2 = rhs(&axpy(&z, 0.5 * h, &k1));
        let k3 = rhs(&axpy(&z, 0.5 * h, &k2));
        let k4 = rhs(&axpy(&z, h, &k3));
        z = std::array::from_fn(|i| z[i] + h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]));
    }
    Some(z)
}

/// An end-loaded cantilever elastica with dimensions: length L and bending stiffness EI.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Elastica {
    /// Length L.
    pub length: f64,
    /// Bending stiffness EI (per unit width for a 2D beam; see [`bending_stiffness`]).
    pub bending_stiffness: f64,
}

impl Elastica {
    /// Checks L > 0 and EI > 0 (finite).
    pub fn try_new(length: f64, bending_stiffness: f64) -> Result<Self, InputError> {
        require_positive("length", length)?;
        require_positive("bending_stiffness", bending_stiffness)?;
        Ok(Self {
            length,
            bending_stiffness,
        })
    }

    /// The paper's cantilever (§5.3): L = 10 m, depth 1 m, unit width, E = 12 MPa, ν = 0.2.
    pub fn paper_cantilever(plane_strain: bool) -> Self {
        let ei = bending_stiffness(12.0e6, 0.2, 1.0, plane_strain).expect("valid constants");
        Self::try_new(10.0, ei).expect("valid constants")
    }

    /// α = PL²/EI for an end load P ≥ 0.
    pub fn alpha(&self, load: f64) -> Result<f64, InputError> {
        if !(load.is_finite() && load >= 0.0) {
            return Err(InputError::new("load", load, "must be finite and >= 0"));
        }
        require_positive("length", self.length)?;
        require_positive("bending_stiffness", self.bending_stiffness)?;
        Ok(load * self.length * self.length / self.bending_stiffness)
    }

    /// Tip response under the end load P (elliptic solution).
    pub fn tip(&self, load: f64) -> Result<TipDisplacement, InputError> {
        tip_elliptic(self.alpha(load)?)
    }

    /// Tip response for each load of `loads` (any order), e.g. [`load_steps`].
    pub fn load_path(&self, loads: &[f64]) -> Result<Vec<TipDisplacement>, InputError> {
        loads.iter().map(|&p| self.tip(p)).collect()
    }
}

/// The loads P_i = i · total/steps, i = 1..=steps, of a linearly ramped load (Figure 21: 50
/// steps to 100 kN).
pub fn load_steps(total: f64, steps: usize) -> Vec<f64> {
    (1..=steps).map(|i| total * i as f64 / steps as f64).collect()
}

/// Carlson's symmetric integral R_F(x, y, z) = ½∫₀^∞ dt / √((t+x)(t+y)(t+z)), for x, y, z ≥ 0
/// with at most one zero, by duplication (Carlson 1995; DLMF 19.36.1); relative error ≲ 1e-16.
pub fn carlson_rf(x: f64, y: f64, z: f64) -> f64 {
    let (x0, y0) = (x, y);
    let (mut x, mut y, mut z) = (x, y, z);
    let a0 = (x + y + z) / 3.0;
    // Stop once 4^{-n} Q < |A_n|, Q = (3r)^{-1/6} max|A0 − ·| with r = 1e-16.
    let mut q = (3.0e-16f64).powf(-1.0 / 6.0) * (a0 - x).abs().max((a0 - y).abs()).max((a0 - z).abs());
    let mut a = a0;
    let mut scale = 1.0; // 4^{-n}
    while q >= a.abs() {
        let (sx, sy, sz) = (x.sqrt(), y.sqrt(), z.sqrt());
        let lambda = sx * sy + sx * sz + sy * sz;
        x = 0.25 * (x + lambda);
        y = 0.25 * (y + lambda);
        z = 0.25 * (z + lambda);
        a = 0.25 * (a + lambda);
        q *= 0.25;
        scale *= 0.25;
        if scale < 1e-300 {
            break;
        }
    }
    let xx = (a0 - x0) * scale / a;
    let yy = (a0 - y0) * scale / a;
    let zz = -(xx + yy);
    let e2 = xx * yy - zz * zz;
    let e3 = xx * yy * zz;
    (1.0 - e2 / 10.0 + e3 / 14.0 + e2 * e2 / 24.0 - 3.0 * e2 * e3 / 44.0) / a.sqrt()
}

/// Carlson's R_D(x, y, z) = (3/2)∫₀^∞ dt / ((t+z)√((t+x)(t+y)(t+z))), for x, y ≥ 0 (not both
/// zero) and z > 0, by duplication (Carlson 1995; DLMF 19.36.2); relative error ≲ 1e-16.
pub fn carlson_rd(x: f64, y: f64, z: f64) -> f64 {
    let (x0, y0) = (x, y);
    let (mut x, mut y, mut z) = (x, y, z);
    let a0 = (x + y + 3.0 * z) / 5.0;
    let mut q = (0.25e-16f64).powf(-1.0 / 6.0) * (a0 - x).abs().max((a0 - y).abs()).max((a0 - z).abs());
    let mut a = a0;
    let mut scale = 1.0; // 4^{-m}
    let mut sum = 0.0;
    while q >= a.abs() {
        let (sx, sy, sz) = (x.sqrt(), y.sqrt(), z.sqrt());
        let lambda = sx * sy + sx * sz + sy * sz;
        sum += scale / (sz * (z + lambda));
        x = 0.25 * (x + lambda);
        y = 0.25 * (y + lambda);
        z = 0.25 * (z + lambda);
        a = 0.25 * (a + lambda);
        q *= 0.25;
        scale *= 0.25;
        if scale < 1e-300 {
            break;
        }
    }
    let xx = (a0 - x0) * scale / a;
    let yy = (a0 - y0) * scale / a;
    let zz = -(xx + yy) / 3.0;
    let xy = xx * yy;
    let z2 = zz * zz;
    let e2 = xy - 6.0 * z2;
    let e3 = (3.0 * xy - 8.0 * z2) * zz;
    let e4 = 3.0 * (xy - z2) * z2;
    let e5 = xy * z2 * zz;
    let series =
        1.0 - 3.0 * e2 / 14.0 + e3 / 6.0 + 9.0 * e2 * e2 / 88.0 - 3.0 * e4 / 22.0 - 9.0 * e2 * e3 / 52.0
            + 3.0 * e5 / 26.0;
    scale * series / (a * a.sqrt()) + 3.0 * sum
}

/// Incomplete elliptic integral of the first kind F(φ, k) = ∫₀^φ dθ/√(1 − m sin²θ),
/// parameter m = k² ≤ 1, |φ| ≤ π/2 (DLMF 19.25.5).
pub fn elliptic_f(phi: f64, m: f64) -> f64 {
    let (s, c) = phi.sin_cos();
    s * carlson_rf(c * c, 1.0 - m * s * s, 1.0)
}

/// Incomplete elliptic integral of the second kind E(φ, k) = ∫₀^φ √(1 − m sin²θ) dθ,
/// parameter m = k² ≤ 1, |φ| ≤ π/2 (DLMF 19.25.9).
pub fn elliptic_e(phi: f64, m: f64) -> f64 {
    let (s, c) = phi.sin_cos();
    let (x, y) = (c * c, 1.0 - m * s * s);
    s * carlson_rf(x, y, 1.0) - m / 3.0 * s * s * s * carlson_rd(x, y, 1.0)
}

/// Complete elliptic integral of the first kind K(k) = F(π/2, k) = R_F(0, 1 − m, 1).
pub fn elliptic_k(m: f64) -> f64 {
    carlson_rf(0.0, 1.0 - m, 1.0)
}

/// Complete elliptic integral of the first kind by the arithmetic–geometric mean,
/// K = π / (2 AGM(1, √(1 − m))), for m < 1: an independent check of [`elliptic_k`].
pub fn elliptic_k_agm(m: f64) -> f64 {
    let (mut a, mut g) = (1.0, (1.0 - m).sqrt());
    // Quadratic convergence: a handful of steps; the cap guards a last-ulp oscillation.
    for _ in 0..64 {
        if (a - g).abs() <= 4.0 * f64::EPSILON * a {
            break;
        }
        (a, g) = (0.5 * (a + g), (a * g).sqrt());
    }
    FRAC_PI_2 / a
}
