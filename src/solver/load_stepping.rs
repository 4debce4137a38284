//! Adaptive load stepping: the loop over the proportional load steps that every method (MPM,
//! iGIMP, the FEM comparators) runs, with halving cutbacks of a failing increment and the
//! record of every attempt. Newton on one increment is [`crate::solver::newton`]'s.

use crate::solver::error::{FailedAttempt, SolveError, StepFailure};
use crate::solver::newton::{NewtonReport, NewtonSettings};
use serde::{Deserialize, Serialize};

/// Most load or time steps of one analysis, material point or finite element. A sanity
/// bound, not a tuned limit: every study uses at most a few thousand steps (cut-backs
/// included), and a count beyond it is a typo that would run for days.
pub const MAX_LOAD_STEPS: usize = 1_000_000;

/// `periods × steps_per_period` time steps, at most [`MAX_LOAD_STEPS`]: checked in floating
/// point before the count is rounded to an integer; the error names the periods' `field`.
pub fn require_time_steps(
    field: &str,
    periods: f64,
    steps_per_period: usize,
) -> Result<(), crate::solver::error::InputError> {
    let steps = periods * steps_per_period as f64;
    if steps <= MAX_LOAD_STEPS as f64 {
        return Ok(());
    }
    Err(crate::solver::error::InputError::new(
        field,
        periods,
        format!(
            "periods × steps_per_period = {} time steps must be <= {MAX_LOAD_STEPS}",
            crate::solver::error::shortest(steps.round())
        ),
    ))
}

/// The time scales of a dynamic analysis of `periods` periods of `period` at
/// `steps_per_period`: at most [`MAX_LOAD_STEPS`] steps ([`require_time_steps`]), and the
/// period, the duration and the time step finite, positive and normal
/// ([`crate::solver::error::require_derived`]). `periods` is the periods' key and value; `from` the
/// input the period derives from (its key and value) and how, for the message.
pub fn require_time_scales(
    periods: (&str, f64),
    steps_per_period: usize,
    period: f64,
    from: (&str, f64, &str),
) -> Result<(), crate::solver::error::InputError> {
    require_time_steps(periods.0, periods.1, steps_per_period)?;
    let duration = periods.1 * period;
    let steps = (periods.1 * steps_per_period as f64).round().max(1.0);
    for (what, v) in [
        ("period", period),
        ("duration", duration),
        ("time step", duration / steps),
    ] {
        crate::solver::error::require_derived(from.0, from.1, &format!("the {what} {}", from.2), v)?;
    }
    Ok(())
}

/// The steps of a run and its failure, if any: the form the problems record a run in,
/// whether it converged or stopped at a failing step.
pub fn steps_and_failure(
    result: Result<Vec<StepReport>, RunFailure>,
) -> (Vec<StepReport>, Option<SolveError>) {
    match result {
        Ok(s) => (s, None),
        Err(RunFailure { steps, error }) => (steps, Some(error)),
    }
}

/// A run that stopped at a failing load step: the reports of the steps that converged before
/// it (the solver holds their state) and the failure.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{error} (after {} converged load steps)", steps.len())]
pub struct RunFailure {
    /// Reports of the load steps that converged before the failure.
    pub steps: Vec<StepReport>,
    /// The failure of the load step that stopped the run.
    #[source]
    pub error: SolveError,
}

/// One attempt at an increment inside a load step that needed cutbacks.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SubStep {
    /// Load factor the attempt aimed at.
    pub load_factor: f64,
    /// Did it converge (and so commit)?
    pub converged: bool,
    /// Why it failed (and the increment was cut), if it did.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub failure: Option<String>,
    /// Its normalised residual history.
    pub residuals: Vec<f64>,
}

/// What one converged load step did.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StepReport {
    /// Load step number, from 1.
    pub step: usize,
    /// Total load factor reached (the step's nominal level `step / load_steps`).
    pub load_factor: f64,
    /// The Newton solve that reached `load_factor` (the last sub-step).
    pub newton: NewtonReport,
    /// Grid nodes constrained by the weak-node treatment in this step (0 for FEM).
    #[serde(default)]
    pub weak_nodes: usize,
    /// The size of the step's linear systems and the iterations of its iterative solves.
    #[serde(default)]
    pub linear: LinearRecord,
    /// Every attempt of a step that needed cutbacks, in order (empty when the nominal
    /// increment converged at once).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub substeps: Vec<SubStep>,
}

impl StepReport {
    /// Failed attempts (increments cut) in this step.
    pub fn cutbacks(&self) -> usize {
        self.substeps.iter().filter(|s| !s.converged).count()
    }

    /// Newton iterations of the increments before the one `newton` records, failed and
    /// converged alike (the last sub-step is that increment itself).
    pub fn earlier_iterations(&self) -> usize {
        let earlier = self.substeps.len().saturating_sub(1);
        self.substeps[..earlier]
            .iter()
            .map(|s| s.residuals.len().saturating_sub(1))
            .sum()
    }
}

/// The linear systems of one converged increment: unknowns and non-zeros of its tangent, the
/// non-zeros of its last LDLᵀ/LLᵀ factor (0 if none) and the Krylov iterations of its solves
/// (CG's plus GMRES's where CG gave up; 0 for direct solves).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct LinearRecord {
    /// Number of equations of the tangent.
    pub unknowns: usize,
    /// Stored entries of the tangent's sparsity pattern.
    pub nonzeros: usize,
    /// Non-zeros of the last LDLᵀ/LLᵀ factor (0 if none; always 0 under the iterative strategy).
    #[serde(default)]
    pub factor_nonzeros: usize,
    /// Krylov iterations of the increment's solves (0 for direct solves).
    pub iterations: usize,
}

/// One converged increment, as a solver reports it to the load stepping.
#[derive(Debug, Clone, PartialEq)]
pub struct Increment {
    /// The Newton solve of the increment.
    pub newton: NewtonReport,
    /// Grid nodes constrained by the weak-node treatment (0 for FEM).
    pub weak_nodes: usize,
    /// The size of the increment's linear systems and their Krylov iterations.
    pub linear: LinearRecord,
}

/// A solver that advances through proportional load steps, cutting a failing increment
/// (adaptive load stepping, [`NewtonSettings::max_cutbacks`]).
///
/// The nominal load levels `k / load_steps` are always hit exactly: a step that fails is
/// rolled back to the last committed state and retried with half the increment, down to
/// 2^-max_cutbacks of the nominal one; after a converged sub-step the increment doubles
/// again (never beyond the nominal one, never past the step's level). A step still failing
/// at the floor is the analysis' failure.
pub trait LoadStepping {
    /// Solve one increment from the committed state to the total load factor `load_factor`
    /// and commit it on success. On failure nothing is committed: the solver is as before.
    fn advance(&mut self, load_factor: f64) -> Result<Increment, FailedAttempt>;
    /// Load steps completed so far.
    fn steps_done(&self) -> usize;
    /// Record that nominal step `n` is complete.
    fn set_steps_done(&mut self, n: usize);
    /// Total number of load steps.
    fn load_steps(&self) -> usize;
    /// The Newton settings (for the cutback limit).
    fn newton_settings(&self) -> &NewtonSettings;

    /// Solve and commit the next nominal load step, with cutbacks where needed.
    fn step(&mut self) -> Result<StepReport, SolveError> {
        let n = self.steps_done();
        let total = self.load_steps();
        let step = n + 1;
        let target = step as f64 / total as f64;
        let nominal = 1.0 / total as f64;
        let max_cuts = self.newton_settings().max_cutbacks;
        let floor = nominal / f64::powi(2.0, max_cuts as i32);
        let mut current = n as f64 / total as f64;
        let mut increment = nominal;
        let mut substeps: Vec<SubStep> = Vec::new();
        loop {
            // Snap onto the step's level when within round-off of it.
            let to = if current + increment >= target - 1e-9 * nominal {
                target
            } else {
                current + increment
            };
            match self.advance(to) {
                Ok(inc) => {
                    let done = to == target;
                    // A step reached in one increment records no sub-steps.
                    if !(done && substeps.is_empty()) {
                        substeps.push(SubStep {
                            load_factor: to,
                            converged: true,
                            failure: None,
                            residuals: inc.newton.residuals.clone(),
                        });
                    }
                    if done {
                        self.set_steps_done(step);
                        return Ok(StepReport {
                            step,
                            load_factor: target,
                            newton: inc.newton,
                            weak_nodes: inc.weak_nodes,
                            linear: inc.linear,
                            substeps,
                        });
                    }
                    current = to;
                    increment = (2.0 * increment).min(nominal);
                }
                Err(FailedAttempt { failure, residuals }) => {
                    // From the extrapolated start: the same increment again, from zero.
                    let next = if matches!(failure, StepFailure::Extrapolated(_)) {
                        to - current
                    } else {
                        0.5 * (to - current)
                    };
                    if next < floor * (1.0 - 1e-9) {
                        return Err(SolveError {
                            step,
                            failure,
                            residuals,
                            attempts: substeps.len() + 1,
                            load_factor: to,
                            reached: current,
                        });
                    }
                    substeps.push(SubStep {
                        load_factor: to,
                        converged: false,
                        failure: Some(failure.to_string()),
                        residuals,
                    });
                    increment = next;
                }
            }
        }
    }

    /// Run all remaining load steps. On failure returns the reports of the converged steps
    /// and the error ([`RunFailure`]); the solver then holds the last converged state.
    fn run(&mut self) -> Result<Vec<StepReport>, RunFailure> {
        self.run_observed(&mut |_, _| {})
    }

    /// [`Self::run`], calling `after_step` with the solver and the report after each
    /// converged step (e.g. to write the state for ParaView).
    fn run_observed(
        &mut self,
        after_step: &mut dyn FnMut(&Self, &StepReport),
    ) -> Result<Vec<StepReport>, RunFailure> {
        let mut reports = Vec::with_capacity(self.load_steps().min(1024));
        while self.steps_done() < self.load_steps() {
            match self.step() {
                Ok(r) => {
                    after_step(self, &r);
                    reports.push(r)
                }
                Err(error) => {
                    return Err(RunFailure {
                        steps: reports,
                        error,
                    })
                }
            }
        }
        Ok(reports)
    }
}
