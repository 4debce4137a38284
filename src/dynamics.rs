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

use crate::error::{require_positive, InputError};
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
    #[serde(default)]
    pub mass: MassMatrix,
    #[serde(default)]
    pub load: LoadHistory,
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
        }
    }

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
        Ok(())
    }

    /// The coefficients of one step of length `dt`.
    pub fn step(&self, dt: f64) -> NewmarkStep {
        NewmarkStep {
            dt,
            beta: self.beta,
            gamma: self.gamma,
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
    pub newmark: NewmarkStep,
    pub end: f64,
    pub load_factor: f64,
}

/// (N1)–(N2) for one step of length `dt`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NewmarkStep {
    pub dt: f64,
    pub beta: f64,
    pub gamma: f64,
}

impl NewmarkStep {
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
    ) -> Result<(), crate::error::StepFailure> {
        for (q, ((x0, &v0), f)) in positions0.iter().zip(volumes0).zip(forces.iter_mut()).enumerate() {
            let b = self.at(x0, t);
            if b.iter().any(|v| !v.is_finite()) {
                return Err(crate::error::StepFailure::Kinematics {
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
    pub step: NewmarkStep,
    pub predictor: &'a [f64],
    /// The start-of-step acceleration a₀ per nodal dof (for the scale of the convergence
    /// test, [`crate::assembly::DynamicReference`]).
    pub acceleration: &'a [f64],
    pub mass: MassMatrix,
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

    #[test]
    fn bad_coefficients_name_their_key() {
        let mut n = Newmark::trapezoidal(1.0);
        n.beta = 0.6;
        assert!(n.validate().unwrap_err().to_string().contains("dynamics.beta"));
        n.beta = 0.25;
        n.gamma = 0.4;
        assert!(n.validate().unwrap_err().to_string().contains("dynamics.gamma"));
        n.gamma = 0.5;
        n.duration = 0.0;
        assert!(n
            .validate()
            .unwrap_err()
            .to_string()
            .contains("dynamics.duration"));
    }
}
