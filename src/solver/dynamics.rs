//! Implicit dynamics: Newmark time integration of M a + f_int(u) = f_ext, shared by the material
//! point solvers and the finite element comparators.
//!
//! Newmark (1959) relates the end-of-step acceleration and velocity of every nodal dof to the
//! displacement increment Δu of the step:
//!
//! ```text
//! a₁ = (Δu − Δt v₀ − Δt² (½ − β) a₀) / (β Δt²)          (N1)
//! v₁ = v₀ + Δt ((1 − γ) a₀ + γ a₁)                       (N2)
//! ```
//!
//! so that each step is the nonlinear system r(Δu) = f_int(Δu) + M a₁(Δu) − f_ext(t₁) = 0 with
//! the effective tangent K + M / (β Δt²), solved by the same Newton loop as a quasi-static load
//! step. β = 1/4, γ = 1/2 (the trapezoidal rule: second order, unconditionally stable, no
//! numerical damping) is the default; γ > 1/2 damps, and second order needs γ = 1/2 (Hughes,
//! *The Finite Element Method* (1987), §9.1).
//!
//! The material point methods reset the grid every step, so the nodal v₀, a₀ are projected from
//! the points, mass-weighted (v_a = Σ_p S_ap m_p v_p / Σ_p S_ap m_p), and the points take the
//! grid's change FLIP-fashion: v_p += Δt Σ_a S_ap ((1 − γ) a₀ + γ a₁)_a, a_p = Σ_a S_ap a₁_a,
//! x_p += Σ_a S_ap Δu_a (the nodal-Newmark update of Guilkey & Weiss, *Int. J. Numer. Meth.
//! Engng* 57 (2003) 1323, eqs 14–19, and Sulsky & Kaul's implicit MPM (2004)). The finite
//! element comparators keep v, a on their nodes and apply (N1)–(N2) there.

use crate::solver::error::{require_positive, InputError};
use nalgebra::SVector;
use serde::{Deserialize, Serialize};
use std::sync::Arc;

/// Which mass matrix the inertia term uses.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum MassMatrix {
    /// M_ab = Σ_p m_p S_ap S_bp δ_ij: same pattern as the stiffness, the variationally
    /// consistent choice (no loss of order from lumping).
    #[default]
    Consistent,
    /// Row sums m_a = Σ_p m_p S_ap on the diagonal.
    Lumped,
}

impl MassMatrix {
    /// The name in study files and reports.
    pub fn name(self) -> &'static str {
        match self {
            MassMatrix::Consistent => "consistent",
            MassMatrix::Lumped => "lumped",
        }
    }
}

/// How the external load varies in time t ∈ [0, duration].
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case", tag = "kind", deny_unknown_fields)]
pub enum LoadHistory {
    /// Full load from t = 0⁺ (suddenly applied).
    #[default]
    Sudden,
    /// No external load: free vibration from the initial velocities.
    None,
}

impl LoadHistory {
    /// The load factor at time `t`.
    pub fn factor(self, _t: f64) -> f64 {
        match self {
            LoadHistory::Sudden => 1.0,
            LoadHistory::None => 0.0,
        }
    }
}

/// Newmark settings of a dynamic analysis; the analysis runs `steps` equal steps over
/// `duration` (the load stepping's "load factor" is then t / duration).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Newmark {
    /// Total simulated time (> 0).
    pub duration: f64,
    /// Newmark β ∈ (0, 1/2]; 1/4 by default (trapezoidal rule).
    #[serde(default = "quarter")]
    pub beta: f64,
    /// Newmark γ ∈ [1/2, 1]; 1/2 by default (no numerical damping).
    #[serde(default = "half")]
    pub gamma: f64,
    /// The mass matrix of the inertia term.
    #[serde(default)]
    pub mass: MassMatrix,
    /// How the external load varies in time.
    #[serde(default)]
    pub load: LoadHistory,
    /// Generalised-α (Chung & Hulbert 1993) instead of plain Newmark: the spectral radius ρ∞ ∈
    /// [0, 1] of the scheme at ωΔt → ∞, from which α_m, α_f, β and γ follow ([`GeneralizedAlpha`]);
    /// `beta` and `gamma` must then be left at their defaults. `None`: Newmark with `beta`,
    /// `gamma`. Not serialised when absent, so that Newmark analyses keep their keys.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rho_infinity: Option<f64>,
}

/// The generalised-α method of Chung & Hulbert (*J. Appl. Mech.* 60 (1993) 371), eqs 2–3
/// and 25: the equation of motion is balanced at the weighted instants
///
/// ```text
/// M a_{n+1−α_m} + f_int(u_{n+1−α_f}) = f_ext(t_{n+1−α_f}),   x_{n+1−α} = (1 − α) x_{n+1} + α x_n,
/// α_m = (2ρ∞ − 1)/(ρ∞ + 1),  α_f = ρ∞/(ρ∞ + 1),  γ = ½ − α_m + α_f,  β = ¼ (1 − α_m + α_f)²,
/// ```
///
/// with the Newmark relations (N1)–(N2) for u, v, a: second order, unconditionally stable,
/// and the high-frequency modes damped to the spectral radius ρ∞ (ρ∞ = 1 has no dissipation).
/// The internal force at the weighted instant is taken as the weighted force,
/// f_int(u_{n+1−α_f}) ≈ (1 − α_f) f_int(u_{n+1}) + α_f f_int(u_n) (the form of Kuhl & Crisfield,
/// *Int. J. Numer. Meth. Engng* 45 (1999) 569, which keeps the updated-Lagrangian
/// configuration of each step; the two agree for a linear f_int). Divided by 1 − α_f, a step
/// solves
///
/// ```text
/// f_int(u₁) + c_m M a₁ + c_a M a₀ + c_f (f_int(u₀) − f_ext(t₀)) = f_ext(t₁),
/// c_m = (1 − α_m)/(1 − α_f),  c_a = α_m/(1 − α_f),  c_f = α_f/(1 − α_f),
/// ```
///
/// with f_int(u₀) the committed stresses' force on the step's own grid or mesh, and the
/// effective tangent K + c_m M/(βΔt²).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GeneralizedAlpha {
    /// α_m = (2ρ∞ − 1)/(ρ∞ + 1): the weight of the start-of-step acceleration.
    pub alpha_m: f64,
    /// α_f = ρ∞/(ρ∞ + 1): the weight of the start-of-step forces.
    pub alpha_f: f64,
    /// Newmark β = ¼ (1 − α_m + α_f)².
    pub beta: f64,
    /// Newmark γ = ½ − α_m + α_f.
    pub gamma: f64,
}

impl GeneralizedAlpha {
    /// The parameters of spectral radius ρ∞ (Chung & Hulbert 1993, eq 25).
    pub fn of_spectral_radius(rho: f64) -> Self {
        let alpha_m = (2.0 * rho - 1.0) / (rho + 1.0);
        let alpha_f = rho / (rho + 1.0);
        GeneralizedAlpha {
            alpha_m,
            alpha_f,
            beta: 0.25 * (1.0 - alpha_m + alpha_f).powi(2),
            gamma: 0.5 - alpha_m + alpha_f,
        }
    }
}

fn quarter() -> f64 {
    0.25
}

fn half() -> f64 {
    0.5
}

impl Newmark {
    /// The trapezoidal rule (β = 1/4, γ = 1/2), consistent mass, sudden load, over `duration`.
    pub fn trapezoidal(duration: f64) -> Self {
        Newmark {
            duration,
            beta: quarter(),
            gamma: half(),
            mass: MassMatrix::Consistent,
            load: LoadHistory::Sudden,
            rho_infinity: None,
        }
    }

    /// Generalised-α of spectral radius `rho` ([`GeneralizedAlpha`]), consistent mass, sudden
    /// load, over `duration`.
    pub fn generalized_alpha(duration: f64, rho: f64) -> Self {
        Newmark {
            rho_infinity: Some(rho),
            ..Self::trapezoidal(duration)
        }
    }

    /// β, γ, α_m, α_f of the scheme: Newmark's with α_m = α_f = 0, or generalised-α's.
    pub fn parameters(&self) -> GeneralizedAlpha {
        match self.rho_infinity {
            Some(rho) => GeneralizedAlpha::of_spectral_radius(rho),
            None => GeneralizedAlpha {
                alpha_m: 0.0,
                alpha_f: 0.0,
                beta: self.beta,
                gamma: self.gamma,
            },
        }
    }

    /// Check the duration, β, γ and ρ∞ against their ranges (β and γ left at their defaults
    /// when ρ∞ is given).
    pub fn validate(&self) -> Result<(), InputError> {
        require_positive("dynamics.duration", self.duration)?;
        if !(self.beta > 0.0 && self.beta <= 0.5) {
            return Err(InputError::new(
                "dynamics.beta",
                self.beta,
                "must lie in (0, 0.5]",
            ));
        }
        if !(self.gamma >= 0.5 && self.gamma <= 1.0) {
            return Err(InputError::new(
                "dynamics.gamma",
                self.gamma,
                "must lie in [0.5, 1]",
            ));
        }
        if let Some(rho) = self.rho_infinity {
            if !(0.0..=1.0).contains(&rho) {
                return Err(InputError::new(
                    "dynamics.rho_infinity",
                    rho,
                    "must lie in [0, 1] (the spectral radius of generalised-α at high frequency)",
                ));
            }
            if self.beta != quarter() || self.gamma != half() {
                return Err(InputError::new(
                    "dynamics.beta",
                    format!("beta = {}, gamma = {}", self.beta, self.gamma),
                    "must be left at 0.25, 0.5 with rho_infinity: generalised-α derives both from it",
                ));
            }
        }
        Ok(())
    }

    /// The coefficients of one step of length `dt`.
    pub fn step(&self, dt: f64) -> NewmarkStep {
        let p = self.parameters();
        NewmarkStep {
            dt,
            beta: p.beta,
            gamma: p.gamma,
            alpha_m: p.alpha_m,
            alpha_f: p.alpha_f,
        }
    }

    /// The step from the committed time `time` to t₁ = `load_factor` × duration (the load
    /// stepping's factor is t / duration, and it only advances, so t₁ > `time`; a step of
    /// zero length would make every residual non-finite, which Newton reports).
    pub fn step_to(&self, time: f64, load_factor: f64) -> TimeStep {
        let end = load_factor * self.duration;
        debug_assert!(end > time, "a time step must advance: {time} -> {end}");
        TimeStep {
            newmark: self.step(end - time),
            end,
            load_factor: self.load.factor(end),
        }
    }
}

/// One time step of a dynamic analysis: its Newmark coefficients, its end time and the factor
/// the external loads take there.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TimeStep {
    /// The step's coefficients, Δt = t₁ − the committed time.
    pub newmark: NewmarkStep,
    /// End time t₁ of the step.
    pub end: f64,
    /// The factor the external loads take at t₁ ([`LoadHistory::factor`]).
    pub load_factor: f64,
}

/// (N1)–(N2) for one step of length `dt`, and the weights α_m, α_f of generalised-α (zero for
/// Newmark).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NewmarkStep {
    /// Step length Δt.
    pub dt: f64,
    /// Newmark β.
    pub beta: f64,
    /// Newmark γ.
    pub gamma: f64,
    /// Generalised-α's α_m (0 for Newmark).
    pub alpha_m: f64,
    /// Generalised-α's α_f (0 for Newmark).
    pub alpha_f: f64,
}

impl NewmarkStep {
    /// Plain Newmark: the step balances the equation of motion at its end.
    pub fn is_newmark(&self) -> bool {
        self.alpha_m == 0.0 && self.alpha_f == 0.0
    }

    /// c_f = α_f / (1 − α_f): the weight of f_int(u₀) − f_ext(t₀) in a step ([`GeneralizedAlpha`]).
    pub fn start_force_weight(&self) -> f64 {
        self.alpha_f / (1.0 - self.alpha_f)
    }

    /// The acceleration the inertia force of a step is M times: a₁ (N1) for Newmark, c_m a₁ +
    /// c_a a₀ for generalised-α ([`GeneralizedAlpha`]), a₁ = Δu/(βΔt²) − ã.
    pub fn inertia_acceleration(&self, du: f64, predictor: f64, a0: f64) -> f64 {
        if self.is_newmark() {
            return self.acceleration_after(du, predictor);
        }
        let den = 1.0 - self.alpha_f;
        (1.0 - self.alpha_m) / den * self.acceleration_after(du, predictor) + self.alpha_m / den * a0
    }

    /// The part of [`Self::inertia_acceleration`] that does not depend on Δu, negated: ã for
    /// Newmark, c_m ã − c_a a₀ for generalised-α.
    pub fn inertia_predictor(&self, predictor: f64, a0: f64) -> f64 {
        if self.is_newmark() {
            return predictor;
        }
        let den = 1.0 - self.alpha_f;
        (1.0 - self.alpha_m) / den * predictor - self.alpha_m / den * a0
    }

    /// ∂(inertia acceleration)/∂Δu, the factor of M in the effective tangent: 1/(βΔt²) for
    /// Newmark, c_m/(βΔt²) for generalised-α.
    pub fn tangent_mass_factor(&self) -> f64 {
        if self.is_newmark() {
            return self.mass_factor();
        }
        (1.0 - self.alpha_m) / (1.0 - self.alpha_f) * self.mass_factor()
    }

    /// 1 / (β Δt²): ∂a₁/∂Δu, the factor of M in the effective tangent.
    pub fn mass_factor(&self) -> f64 {
        1.0 / (self.beta * self.dt * self.dt)
    }

    /// The part of a₁ that does not depend on Δu, negated: a₁ = Δu / (β Δt²) − ã with
    /// ã = (Δt v₀ + Δt² (½ − β) a₀) / (β Δt²) (N1).
    pub fn predictor(&self, v0: f64, a0: f64) -> f64 {
        (self.dt * v0 + self.dt * self.dt * (0.5 - self.beta) * a0) * self.mass_factor()
    }

    /// a₁ from the increment (N1).
    pub fn acceleration(&self, du: f64, v0: f64, a0: f64) -> f64 {
        self.acceleration_after(du, self.predictor(v0, a0))
    }

    /// a₁ = Δu/(βΔt²) − ã from the increment and the step's [`Self::predictor`] ã.
    pub fn acceleration_after(&self, du: f64, predictor: f64) -> f64 {
        du * self.mass_factor() - predictor
    }

    /// The velocity change v₁ − v₀ over the step (N2).
    pub fn velocity_change(&self, a0: f64, a1: f64) -> f64 {
        self.dt * ((1.0 - self.gamma) * a0 + self.gamma * a1)
    }
}

/// A body force per unit reference volume b₀(X, t), given as a function of the reference
/// position X and the time t: the load of a manufactured solution whose force does not
/// factor into a fixed pattern times a load factor (b₀ = ρ₀ ẍ − Div P varies in shape with t).
/// A solver applies it at each integration point q as b₀(X_q, t) V_q0 at the end time of each
/// step (Newmark's trapezoidal rule balances the step's end), or, in a quasi-static analysis,
/// with t the load factor of the step.
#[derive(Clone)]
pub struct BodyForce<const D: usize>(Arc<BodyForceFn<D>>);

/// b₀(X, t) per unit reference volume.
type BodyForceFn<const D: usize> = dyn Fn(&SVector<f64, D>, f64) -> SVector<f64, D> + Send + Sync;

impl<const D: usize> BodyForce<D> {
    /// The body force b₀ = `f`(X, t).
    pub fn new(f: impl Fn(&SVector<f64, D>, f64) -> SVector<f64, D> + Send + Sync + 'static) -> Self {
        BodyForce(Arc::new(f))
    }

    /// b₀(X, t).
    pub fn at(&self, x0: &SVector<f64, D>, t: f64) -> SVector<f64, D> {
        (self.0)(x0, t)
    }

    /// Add b₀(X_q, t) V_q0 to each integration point's force; fails with the first point whose
    /// force is not finite (a body force evaluated outside its domain of definition).
    pub fn add_to(
        &self,
        positions0: &[SVector<f64, D>],
        volumes0: &[f64],
        t: f64,
        forces: &mut [SVector<f64, D>],
    ) -> Result<(), crate::solver::error::StepFailure> {
        for (q, ((x0, &v0), f)) in positions0.iter().zip(volumes0).zip(forces.iter_mut()).enumerate() {
            let b = self.at(x0, t);
            if b.iter().any(|v| !v.is_finite()) {
                return Err(crate::solver::error::StepFailure::Kinematics {
                    point: q,
                    reason: format!(
                        "body force not finite at X = {:?}, t = {t:e}: {:?}",
                        x0.as_slice(),
                        b.as_slice()
                    ),
                });
            }
            *f += b * v0;
        }
        Ok(())
    }
}

impl<const D: usize> std::fmt::Debug for BodyForce<D> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("BodyForce(b0(X, t))")
    }
}

/// The inertia term of one step in nodal-dof order (dof = node·D + axis): the step's
/// coefficients, the negated predictor ã (a₁ = Δu/(βΔt²) − ã), the mass matrix kind and the
/// mass of each integration point (m_p; for the finite elements ρ₀ w det J₀ of each Gauss point).
#[derive(Debug, Clone, Copy)]
pub struct Inertia<'a> {
    /// The step's Newmark (or generalised-α) coefficients.
    pub step: NewmarkStep,
    /// The negated predictor ã per nodal dof (a₁ = Δu/(βΔt²) − ã).
    pub predictor: &'a [f64],
    /// The start-of-step acceleration a₀ per nodal dof (for the scale of the convergence
    /// test, [`crate::discretise::assembly::DynamicReference`]).
    pub acceleration: &'a [f64],
    /// Consistent or lumped mass.
    pub mass: MassMatrix,
    /// Mass of each integration point: m_p, or ρ₀ w_q det J₀ for a Gauss point.
    pub point_masses: &'a [f64],
}

#[cfg(test)]
mod tests {
    use super::*;

    /// (N1)–(N2) integrate ü = −ω² u: the trapezoidal rule's period error is (ωΔt)²/12 to
    /// leading order (Hughes 1987, §9.3), so halving Δt quarters the phase error.
    #[test]
    fn trapezoidal_rule_is_second_order_on_the_oscillator() {
        let omega = 2.0 * std::f64::consts::PI;
        let error = |steps: usize| {
            let n = Newmark::trapezoidal(1.0).step(1.0 / steps as f64);
            let (mut u, mut v, mut a) = (0.0, omega, 0.0);
            for _ in 0..steps {
                // Linear: (1/(βΔt²) + ω²) Δu = ã − ω² u.
                let du = (n.predictor(v, a) - omega * omega * u) / (n.mass_factor() + omega * omega);
                let a1 = n.acceleration(du, v, a);
                v += n.velocity_change(a, a1);
                a = a1;
                u += du;
            }
            u.abs() // exact: sin(2π) = 0
        };
        let (e1, e2) = (error(64), error(128));
        let rate = (e1 / e2).log2();
        assert!((rate - 2.0).abs() < 0.05, "rate {rate} ({e1:e}, {e2:e})");
    }

    /// One generalised-α step of m ü + k u = f as the solvers take it (the residual of
    /// [`GeneralizedAlpha`] with [`NewmarkStep::inertia_acceleration`]), linear so solved at
    /// once, with the weight `c_f` of the start-force term given (the scheme's
    /// [`NewmarkStep::start_force_weight`]; 0: a wrong variant); returns the new (u, v, a).
    fn alpha_step(
        n: &NewmarkStep,
        c_f: f64,
        (k, m): (f64, f64),
        (u, v, a): (f64, f64, f64),
        (f0, f1): (f64, f64),
    ) -> (f64, f64, f64) {
        let pred = n.predictor(v, a);
        // k (u + Δu) + m (c_m/(βΔt²) Δu − inertia predictor) + c_f (k u − f₀) = f₁.
        let rhs = f1 - k * u - c_f * (k * u - f0) + m * n.inertia_predictor(pred, a);
        let du = rhs / (k + m * n.tangent_mass_factor());
        let a1 = n.acceleration(du, v, a);
        (u + du, v + n.velocity_change(a, a1), a1)
    }

    /// Generalised-α through the solvers' coefficients: at ωΔt = 10⁴ the state decays per step
    /// by the spectral radius ρ∞ (Chung & Hulbert 1993, eq 25's design), and at small ωΔt the
    /// scheme is second order; ρ∞ = 1 has no dissipation.
    #[test]
    fn generalized_alpha_damps_by_its_spectral_radius_and_is_second_order() {
        let k = 1e8; // ωΔt = 10⁴
                     // The amplification matrix of (u, v, a), column by column, and its spectral radius (a
                     // double root −ρ∞ at infinity, so the decay of a run converges slowly to it).
        let radius_of = |n: &NewmarkStep, c_f: f64| {
            let columns = [(1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0)]
                .map(|s| alpha_step(n, c_f, (k, 1.0), s, (0.0, 0.0)));
            let amp = nalgebra::Matrix3::from_fn(|i, j| {
                let c = columns[j];
                [c.0, c.1, c.2][i]
            });
            amp.complex_eigenvalues()
                .iter()
                .map(|l| l.norm())
                .fold(0.0, f64::max)
        };
        for rho in [0.0, 0.5, 0.8, 1.0] {
            let n = Newmark::generalized_alpha(1.0, rho).step(1.0);
            let radius = radius_of(&n, n.start_force_weight());
            // Measured offsets 1.7e-3 (ρ∞ = 0.5, 0.8) and 2.2e-3 (ρ∞ = 0): a finite ωΔt and
            // the double root, whose eigenvalues are sensitive to round-off.
            assert!(
                (radius - rho).abs() < 5e-3,
                "ρ∞ = {rho}: spectral radius {radius}"
            );
        }
        let omega = 2.0 * std::f64::consts::PI;
        // `with_start`: the term c_f (f_int(u₀) − f_ext(t₀)) kept, or dropped (a wrong variant).
        let error = |steps: usize, with_start: bool| {
            let n = Newmark::generalized_alpha(1.0, 0.8).step(1.0 / steps as f64);
            let c_f = if with_start { n.start_force_weight() } else { 0.0 };
            let mut s = (0.0, omega, 0.0);
            for _ in 0..steps {
                s = alpha_step(&n, c_f, (omega * omega, 1.0), s, (0.0, 0.0));
            }
            s.0.abs()
        };
        let rate = (error(64, true) / error(128, true)).log2();
        assert!((rate - 2.0).abs() < 0.05, "rate {rate}");
        let wrong = (error(64, false) / error(128, false)).log2();
        println!("rate {rate}, without the start force {wrong}");
        assert!((wrong - 2.0).abs() > 0.5, "the wrong variant's rate {wrong}");
    }

    #[test]
    fn bad_coefficients_name_their_key() {
        let mut n = Newmark::trapezoidal(1.0);
        n.beta = 0.6;
        assert!(n.validate().unwrap_err().to_string().contains("dynamics.beta"));
        n.beta = 0.25;
        n.gamma = 0.4;
        assert!(n.validate().unwrap_err().to_string().contains("dynamics.gamma"));
        n.gamma = 0.5;
        n.rho_infinity = Some(1.5);
        assert!(n
            .validate()
            .unwrap_err()
            .to_string()
            .contains("dynamics.rho_infinity"));
        n.rho_infinity = Some(0.8);
        n.beta = 0.3;
        assert!(n.validate().unwrap_err().to_string().contains("dynamics.beta"));
        n.beta = 0.25;
        n.validate().unwrap();
        n.rho_infinity = None;
        n.duration = 0.0;
        assert!(n
            .validate()
            .unwrap_err()
            .to_string()
            .contains("dynamics.duration"));
    }
}
