//! Full Newton–Raphson on the out-of-balance force of one load step (eqs 21–23).

use crate::error::{require_count, require_positive, InputError, SolveError, StepFailure};
use serde::{Deserialize, Serialize};

/// Upper bound of [`NewtonSettings::max_iterations`]: far beyond any useful Newton run, and
/// small enough that the residual history can be allocated up front.
pub const MAX_NEWTON_ITERATIONS: usize = 100_000;

/// Newton settings.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NewtonSettings {
    /// Converged when ‖f_int − f_ext‖ / ‖f_ext‖ falls below this.
    pub tolerance: f64,
    /// Most Newton iterations (linear solves) per load step.
    pub max_iterations: usize,
    /// Backtrack (halve the update, up to 10 times) while the normalised residual does not
    /// decrease or the trial state is inadmissible (e.g. det ΔF ≤ 0). Off by default: plain
    /// Newton as in the paper. Full steps are taken near the solution either way, so the
    /// asymptotic quadratic rate is unaffected.
    #[serde(default)]
    pub line_search: bool,
}

impl Default for NewtonSettings {
    fn default() -> Self {
        Self {
            tolerance: 1e-9,
            max_iterations: 30,
            line_search: false,
        }
    }
}

impl NewtonSettings {
    pub fn validate(&self) -> Result<(), InputError> {
        require_positive("newton.tolerance", self.tolerance)?;
        if self.tolerance >= 1.0 {
            return Err(InputError::new(
                "newton.tolerance",
                self.tolerance,
                "must lie in (0, 1)",
            ));
        }
        require_count("newton.max_iterations", self.max_iterations, 1)?;
        if self.max_iterations > MAX_NEWTON_ITERATIONS {
            return Err(InputError::new(
                "newton.max_iterations",
                self.max_iterations,
                format!("must be <= {MAX_NEWTON_ITERATIONS}"),
            ));
        }
        Ok(())
    }
}

/// A discrete nonlinear system `r(u) = f_int(u) − f_ext = 0` with its tangent.
///
/// Evaluation order: [`NonlinearSystem::solve_tangent`] is called only after
/// [`NonlinearSystem::evaluate`] at the same `u`, so the tangent may be formed there.
pub trait NonlinearSystem {
    /// Number of unknowns.
    fn num_unknowns(&self) -> usize;
    /// Residual at `u` (and the tangent for the next solve).
    fn evaluate(&mut self, u: &[f64], residual: &mut [f64]) -> Result<(), StepFailure>;
    /// Solve `K x = rhs` in place with the tangent formed at the last `evaluate`.
    fn solve_tangent(&mut self, rhs: &mut [f64]) -> Result<(), StepFailure>;
    /// Norm used to normalise the residual (‖f_ext‖).
    fn reference_norm(&self) -> f64;
}

/// The residual history of a converged solve.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct NewtonReport {
    /// Normalised out-of-balance force: entry 0 before the first solve, entry k after the
    /// k-th Newton update.
    pub residuals: Vec<f64>,
}

impl NewtonReport {
    /// Number of linear solves performed.
    pub fn iterations(&self) -> usize {
        self.residuals.len() - 1
    }
}

fn norm(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

/// Solve `r(u) = 0` starting from `u`. On failure returns the reason and the residual history.
pub fn solve(
    system: &mut dyn NonlinearSystem,
    u: &mut [f64],
    settings: &NewtonSettings,
) -> Result<NewtonReport, (StepFailure, Vec<f64>)> {
    let n = system.num_unknowns();
    let mut r = vec![0.0; n];
    let mut history = Vec::with_capacity(settings.max_iterations.min(64) + 1);
    let scale = system.reference_norm();
    let scale = if scale > 0.0 && scale.is_finite() {
        scale
    } else {
        1.0
    };
    if let Err(f) = system.evaluate(u, &mut r) {
        return Err((f, history));
    }
    let mut res = norm(&r) / scale;
    if !res.is_finite() {
        return Err((StepFailure::NonFinite { iteration: 0 }, history));
    }
    history.push(res);
    let mut delta = vec![0.0; n];
    let mut trial = vec![0.0; n];
    for it in 1..=settings.max_iterations {
        if res <= settings.tolerance {
            return Ok(NewtonReport { residuals: history });
        }
        // K δ = −r, eq (22), with the tangent of the last evaluated (accepted) state.
        for (d, ri) in delta.iter_mut().zip(&r) {
            *d = -ri;
        }
        if let Err(f) = system.solve_tangent(&mut delta) {
            return Err((f, history));
        }
        // Δd += α δ, eq (23); α = 1 unless the line search backtracks.
        let mut alpha = 1.0;
        let mut halvings = 0;
        loop {
            for ((t, ui), di) in trial.iter_mut().zip(u.iter()).zip(&delta) {
                *t = ui + alpha * di;
            }
            let last_try = !settings.line_search || halvings == MAX_HALVINGS;
            match system.evaluate(&trial, &mut r) {
                Ok(()) => {
                    let res_t = norm(&r) / scale;
                    if res_t.is_finite() && (last_try || res_t < (1.0 - 1e-4 * alpha) * res) {
                        u.copy_from_slice(&trial);
                        res = res_t;
                        break;
                    }
                    if last_try {
                        return Err((StepFailure::NonFinite { iteration: it }, history));
                    }
                }
                Err(f) => {
                    if last_try {
                        return Err((f, history));
                    }
                }
            }
            alpha *= 0.5;
            halvings += 1;
        }
        history.push(res);
    }
    if res <= settings.tolerance {
        return Ok(NewtonReport { residuals: history });
    }
    Err((
        StepFailure::NotConverged {
            iterations: settings.max_iterations,
            last: res,
        },
        history,
    ))
}

/// Most step halvings of the backtracking line search.
const MAX_HALVINGS: usize = 10;

/// Observed convergence order from three successive residuals, ln(r3/r2)/ln(r2/r1).
pub fn observed_order(r1: f64, r2: f64, r3: f64) -> f64 {
    (r3 / r2).ln() / (r2 / r1).ln()
}

/// What [`check_quadratic`] verified.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct QuadraticCheck {
    /// Number of pairs (r_k, r_{k+1}) tested against r_{k+1} ≤ C r_k².
    pub ratio_checks: usize,
    /// Number of triples whose observed order was tested.
    pub order_checks: usize,
    /// Largest r_{k+1} / r_k² seen.
    pub max_ratio: f64,
    /// Smallest observed order seen (∞ if none).
    pub min_order: f64,
}

/// Assert asymptotic quadratic convergence from a residual history (entry 0, before the first
/// solve, is excluded). Once `r_k ≤ small`, each next residual above `floor` (round-off) must
/// satisfy `r_{k+1} ≤ c r_k²`; where three successive residuals qualify, the observed order
/// `ln(r3/r2)/ln(r2/r1)` must be at least `min_order`. Returns what was checked, or a message
/// naming the first violation.
pub fn check_quadratic(
    residuals: &[f64],
    small: f64,
    floor: f64,
    c: f64,
    min_order: f64,
) -> Result<QuadraticCheck, String> {
    let r = if residuals.len() > 1 {
        &residuals[1..]
    } else {
        &[][..]
    };
    let mut out = QuadraticCheck {
        ratio_checks: 0,
        order_checks: 0,
        max_ratio: 0.0,
        min_order: f64::INFINITY,
    };
    for k in 0..r.len().saturating_sub(1) {
        if r[k] <= small && r[k + 1] > floor {
            let ratio = r[k + 1] / (r[k] * r[k]);
            out.ratio_checks += 1;
            out.max_ratio = out.max_ratio.max(ratio);
            if ratio > c {
                return Err(format!(
                    "r_{} = {:.3e} > {c} * r_{}^2 = {:.3e} (history {residuals:?})",
                    k + 2,
                    r[k + 1],
                    k + 1,
                    c * r[k] * r[k]
                ));
            }
            if k + 2 < r.len() && r[k + 2] > floor {
                let order = observed_order(r[k], r[k + 1], r[k + 2]);
                out.order_checks += 1;
                out.min_order = out.min_order.min(order);
                if order < min_order {
                    return Err(format!(
                        "observed order {order:.3} < {min_order} from residuals {:.3e}, {:.3e}, {:.3e}",
                        r[k],
                        r[k + 1],
                        r[k + 2]
                    ));
                }
            }
        }
    }
    Ok(out)
}

/// What one converged load step did.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StepReport {
    /// Load step number, from 1.
    pub step: usize,
    pub load_factor: f64,
    pub newton: NewtonReport,
    /// Grid nodes constrained by the weak-node treatment in this step (0 for FEM).
    #[serde(default)]
    pub weak_nodes: usize,
}

/// A solver that advances through a fixed number of proportional load steps.
pub trait LoadStepping {
    /// Solve and commit the next load step.
    fn step(&mut self) -> Result<StepReport, SolveError>;
    /// Load steps completed so far.
    fn steps_done(&self) -> usize;
    /// Total number of load steps.
    fn load_steps(&self) -> usize;

    /// Run all remaining load steps. On failure returns the reports of the converged steps
    /// and the error; the solver then holds the last converged state.
    fn run(&mut self) -> Result<Vec<StepReport>, (Vec<StepReport>, SolveError)> {
        self.run_observed(&mut |_, _| {})
    }

    /// [`Self::run`], calling `after_step` with the solver and the report after each
    /// converged step (e.g. to write the state for ParaView).
    fn run_observed(
        &mut self,
        after_step: &mut dyn FnMut(&Self, &StepReport),
    ) -> Result<Vec<StepReport>, (Vec<StepReport>, SolveError)> {
        let mut reports = Vec::with_capacity(self.load_steps().min(1024));
        while self.steps_done() < self.load_steps() {
            match self.step() {
                Ok(r) => {
                    after_step(self, &r);
                    reports.push(r)
                }
                Err(e) => return Err((reports, e)),
            }
        }
        Ok(reports)
    }
}
