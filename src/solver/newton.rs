//! Full Newton–Raphson on the out-of-balance force of one load step (eqs 21–23).

use crate::solver::error::{require_count, FailedAttempt, InputError, StepFailure};
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
    /// What the out-of-balance force is normalised by.
    #[serde(default)]
    pub residual_norm: ResidualNorm,
    /// Adaptive load stepping: a load step that fails is retried from the last committed
    /// state with half the increment, at most this many times in a row, so the smallest
    /// increment is 2^-max_cutbacks of the nominal one (default 6: 1/64). 0 = fixed steps.
    #[serde(default = "default_cutbacks")]
    pub max_cutbacks: u32,
    /// Where Newton starts an increment: from a zero increment of the free dofs (the paper's
    /// choice, the default) or from the last converged increment scaled to this one's load
    /// ([`Predictor::Extrapolated`]; static analyses only).
    #[serde(default, skip_serializing_if = "Predictor::is_zero")]
    pub predictor: Predictor,
}

/// Newton's starting point in a load increment (reference/README.md item 82).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Predictor {
    /// A zero increment of the free dofs; the prescribed dofs take their whole increment at
    /// once (the paper's Newton, whose residual tables start there).
    #[default]
    Zero,
    /// The last converged increment (nodal, on the same grid or mesh) times the ratio of this
    /// increment's load to that one's: under steady plastic flow the start is then close to
    /// the solution, where a zero start puts the whole displacement jump on the loaded nodes'
    /// first row of cells. A start that cannot be evaluated falls back to zero. Ignored in
    /// dynamics, whose Newmark predictor starts each step.
    Extrapolated,
}

impl Predictor {
    pub fn is_zero(&self) -> bool {
        *self == Predictor::Zero
    }
    /// Its name in a study file.
    pub fn name(&self) -> &'static str {
        match self {
            Predictor::Zero => "zero",
            Predictor::Extrapolated => "extrapolated",
        }
    }
}

fn default_cutbacks() -> u32 {
    DEFAULT_CUTBACKS
}

/// Default of [`NewtonSettings::max_cutbacks`]: the floor 1/64 of the nominal increment.
pub const DEFAULT_CUTBACKS: u32 = 6;

/// Most halvings of a load increment ([`NewtonSettings::max_cutbacks`]): 2^-20 of a step.
pub const MAX_CUTBACKS: u32 = 20;

/// How the out-of-balance force is normalised in the convergence test.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ResidualNorm {
    /// ‖f_int − f_ext‖ / ‖f_ext‖ over the free dofs.
    #[default]
    External,
    /// ‖f_int − f_ext‖ over the free dofs / ‖f_ext + f_reaction‖ over all dofs, with the exact
    /// reactions (f_int at the fixed dofs).
    Total,
    /// As the paper's group's code (AMPLE) computes it: the reactions are updated by their
    /// linearised increment K_f δu, and the out-of-balance this leaves at the fixed dofs (the
    /// Taylor remainder of f_int there) joins the numerator: ‖f^ob‖ / ‖f_ext + f_rct‖ over
    /// all dofs (reference/README.md, item 18).
    Linearised,
}

impl Default for NewtonSettings {
    fn default() -> Self {
        Self {
            tolerance: 1e-9,
            max_iterations: 30,
            line_search: false,
            residual_norm: ResidualNorm::External,
            max_cutbacks: DEFAULT_CUTBACKS,
            predictor: Predictor::Zero,
        }
    }
}

impl NewtonSettings {
    /// Check the tolerance, the iteration limit and the cutback limit against their ranges.
    pub fn validate(&self) -> Result<(), InputError> {
        if !(self.tolerance.is_finite() && (MIN_TOLERANCE..1.0).contains(&self.tolerance)) {
            return Err(InputError::new(
                "newton.tolerance",
                self.tolerance,
                format!("must lie in [{MIN_TOLERANCE:e}, 1) (below it the force balance is under round-off)"),
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
        if self.max_cutbacks > MAX_CUTBACKS {
            return Err(InputError::new(
                "newton.max_cutbacks",
                self.max_cutbacks,
                format!("must be <= {MAX_CUTBACKS}"),
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
    /// The relative residual an iterative linear solve must reach next ([`linear_tolerance`]);
    /// direct solvers ignore it.
    fn set_linear_tolerance(&mut self, _relative: f64) {}
    /// Norm that normalises the residual, from the last `evaluate` (for
    /// [`ResidualNorm::Total`] the reactions change with the iterate).
    fn reference_norm(&self, norm: ResidualNorm) -> f64;
    /// Squared out-of-balance at the fixed dofs from the last `evaluate`, added to the
    /// numerator under [`ResidualNorm::Linearised`] (0 for systems without reactions).
    fn fixed_out_of_balance_sq(&self) -> f64 {
        0.0
    }
}

/// The residual history of a converged solve.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct NewtonReport {
    /// Normalised out-of-balance force: entry 0 before the first solve, entry k after the
    /// k-th Newton update.
    pub residuals: Vec<f64>,
    /// Set when the step was accepted stalled at its estimated round-off floor (this value),
    /// above the tolerance but within [`FLOOR_ACCEPT_FACTOR`] of it; `None` for a step that
    /// met the tolerance.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub accepted_floor: Option<f64>,
}

impl NewtonReport {
    /// Number of linear solves performed.
    pub fn iterations(&self) -> usize {
        self.residuals.len() - 1
    }
}

/// Solve `r(u) = 0` starting from `u`. On failure returns the reason and the residual history.
pub fn solve(
    system: &mut dyn NonlinearSystem,
    u: &mut [f64],
    settings: &NewtonSettings,
) -> Result<NewtonReport, FailedAttempt> {
    let n = system.num_unknowns();
    let mut r = vec![0.0; n];
    let mut history = Vec::with_capacity(settings.max_iterations.min(64) + 1);
    let scale = |system: &dyn NonlinearSystem| {
        let s = system.reference_norm(settings.residual_norm);
        if s > 0.0 && s.is_finite() {
            s
        } else {
            1.0
        }
    };
    let measure = |system: &dyn NonlinearSystem, r: &[f64]| {
        let extra = match settings.residual_norm {
            ResidualNorm::Linearised => system.fixed_out_of_balance_sq(),
            _ => 0.0,
        };
        let nr = crate::solver::norms::l2(r);
        let sq = nr.powi(2) + extra;
        // The textbook formula in range (results unchanged); without underflow outside it.
        let numerator = if sq.is_normal() {
            sq.sqrt()
        } else if extra == 0.0 {
            nr
        } else {
            nr.hypot(extra.sqrt())
        };
        numerator / scale(system)
    };
    if let Err(f) = system.evaluate(u, &mut r) {
        return Err(FailedAttempt {
            failure: f,
            residuals: history,
        });
    }
    let mut res = measure(system, &r);
    if !res.is_finite() {
        return Err(FailedAttempt {
            failure: StepFailure::NonFinite { iteration: 0 },
            residuals: history,
        });
    }
    history.push(res);
    let mut delta = vec![0.0; n];
    let mut trial = vec![0.0; n];
    for it in 1..=settings.max_iterations {
        if res <= settings.tolerance {
            return Ok(NewtonReport {
                residuals: history,
                accepted_floor: None,
            });
        }
        // K δ = −r, eq (22), with the tangent of the last evaluated (accepted) state.
        for (d, ri) in delta.iter_mut().zip(&r) {
            *d = -ri;
        }
        system.set_linear_tolerance(linear_tolerance(res));
        if let Err(f) = system.solve_tangent(&mut delta) {
            return Err(FailedAttempt {
                failure: f,
                residuals: history,
            });
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
                    let res_t = measure(system, &r);
                    if res_t.is_finite() && (last_try || res_t < (1.0 - 1e-4 * alpha) * res) {
                        u.copy_from_slice(&trial);
                        res = res_t;
                        break;
                    }
                    if last_try {
                        return Err(FailedAttempt {
                            failure: StepFailure::NonFinite { iteration: it },
                            residuals: history,
                        });
                    }
                }
                Err(f) => {
                    if last_try {
                        return Err(FailedAttempt {
                            failure: f,
                            residuals: history,
                        });
                    }
                }
            }
            alpha *= 0.5;
            halvings += 1;
        }
        history.push(res);
    }
    if res <= settings.tolerance {
        return Ok(NewtonReport {
            residuals: history,
            accepted_floor: None,
        });
    }
    if let Some(stall) = detect_stall(&history, settings.tolerance) {
        if let StepFailure::Stalled { floor, .. } = stall {
            if floor <= FLOOR_ACCEPT_FACTOR * settings.tolerance
                && res <= FLOOR_ACCEPT_FACTOR * settings.tolerance
            {
                return Ok(NewtonReport {
                    residuals: history,
                    accepted_floor: Some(floor),
                });
            }
        }
        return Err(FailedAttempt {
            failure: stall,
            residuals: history,
        });
    }
    Err(FailedAttempt {
        failure: StepFailure::NotConverged {
            iterations: settings.max_iterations,
            last: res,
        },
        residuals: history,
    })
}

/// A step whose Newton iterations are used up, stalled (`detect_stall`) at a floor within
/// this factor of the tolerance — and whose last residual is too — is accepted and recorded
/// as such ([`NewtonReport::accepted_floor`]); a floor further above is a failure. The floor
/// is round-off in `f_int − f_ext` and grows like the tangent's condition number
/// (reference/README.md item 5: 2e-13 at 50 elements, 2.5e-10 at 2048 on the W = 400,000
/// column). Measured: quadratic FEM at 2048 elements stalls at 1.3e-9 against the tolerance
/// 1e-9 (accepted); ν = 0.49999999 at 3.4e-5 (a failure, 3.4e4 times the tolerance). One
/// decade keeps the accepted answer within one decade of the requested force balance.
pub const FLOOR_ACCEPT_FACTOR: f64 = 10.0;

/// Smallest Newton tolerance accepted: the lowest round-off floor measured, the 50-element
/// column's 2e-13 (reference/README.md item 5), rounded down a factor 2. A tolerance below it
/// cannot be met by any case: every step would end stalled and every case fail.
pub const MIN_TOLERANCE: f64 = 1e-13;

/// Iterations in a row without halving the best residual that make a stall.
pub const STALL_WINDOW: usize = 3;

/// Residuals (normalised) below which a stall is read as the round-off floor: Newton has
/// already converged quadratically this far and the next decade is lost to cancellation in
/// `f_int − f_ext` (the floor grows like the condition number of the tangent).
pub const ROUND_OFF_REGION: f64 = 1e-3;

/// A stall, diagnosed once Newton has used its iterations (a round-off floor can still dip
/// below the tolerance by chance, so it never cuts a solve short): the best residual reached
/// is below [`ROUND_OFF_REGION`] and above `tolerance`, and the last [`STALL_WINDOW`]
/// iterations have not halved it. The floor estimate is the
/// median of the stalled residuals (the level round-off keeps returning to).
fn detect_stall(history: &[f64], tolerance: f64) -> Option<StepFailure> {
    if history.len() < STALL_WINDOW + 2 {
        return None;
    }
    let (head, window) = history.split_at(history.len() - STALL_WINDOW);
    let best_before = head.iter().copied().fold(f64::INFINITY, f64::min);
    if best_before.is_nan()
        || best_before > ROUND_OFF_REGION
        || window.iter().any(|&r| r <= 0.5 * best_before)
    {
        return None;
    }
    let mut w: Vec<f64> = window.to_vec();
    w.sort_by(f64::total_cmp);
    Some(StepFailure::Stalled {
        iterations: history.len() - 1,
        floor: w[w.len() / 2],
        best: best_before.min(w[0]),
        tolerance,
    })
}

/// Most step halvings of the backtracking line search.
const MAX_HALVINGS: usize = 10;

/// The forcing term of an inexact Newton step at normalised residual `res`: the linear solve
/// must reduce its residual by η = 10⁻² · res (at most 10⁻², at least 10⁻¹¹). The error it
/// leaves adds η ‖r‖ ∝ ‖r‖² to the next residual, so the quadratic rate survives (Eisenstat
/// & Walker 1996, choice with η_k ∝ ‖r_k‖); the floor keeps CG above round-off.
pub fn linear_tolerance(res: f64) -> f64 {
    (1e-2 * res).clamp(1e-11, 1e-2)
}

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
