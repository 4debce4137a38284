//! Error types: bad input names the field and its allowed range; solver failures carry the
//! load step and the Newton residual history so that a failed case in a sweep can be reported.

use thiserror::Error;

/// Invalid user input: names the field, the offending value and what is allowed.
#[derive(Debug, Clone, PartialEq, Error)]
#[error("invalid `{field}` = {value}: {allowed}")]
pub struct InputError {
    /// Dotted path of the offending field, e.g. `material.young_modulus`.
    pub field: String,
    /// The value as given (formatted).
    pub value: String,
    /// The allowed range, in words.
    pub allowed: String,
}

impl InputError {
    /// The error of `field` = `value`, with what is `allowed`; long numbers are shortened
    /// ([`tidy_numbers`]).
    pub fn new(field: impl Into<String>, value: impl ToString, allowed: impl Into<String>) -> Self {
        Self {
            field: field.into(),
            value: tidy_numbers(&value.to_string()),
            allowed: tidy_numbers(&allowed.into()),
        }
    }
}

/// The shortest text that reads back to the same float, without a trailing `.0` (`40000`,
/// `0.25`, `1e300`, `1e-300`): Rust's `Display` writes every digit of 1e300.
pub fn shortest(x: f64) -> String {
    let s = format!("{x:?}");
    match s.strip_suffix(".0") {
        Some(t) => t.to_string(),
        None => s,
    }
}

/// Longest number written out in full in a message: longer ones (`Display` of 1e300 has 301
/// digits) are rewritten in their shortest round-trip form (`1e300`, `1e-300`).
const LONGEST_PLAIN_NUMBER: usize = 24;

/// `text` with every number longer than `LONGEST_PLAIN_NUMBER` characters in shortest
/// round-trip form, so that an extreme input gives a readable message.
pub fn tidy_numbers(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let mut run = String::new();
    let flush = |run: &mut String, out: &mut String| {
        match run.parse::<f64>() {
            Ok(v) if run.len() > LONGEST_PLAIN_NUMBER => out.push_str(&shortest(v)),
            _ => out.push_str(run),
        }
        run.clear();
    };
    for c in text.chars() {
        if c.is_ascii_digit() || (c == '.' && !run.is_empty()) || (c == '-' && run.is_empty()) {
            run.push(c);
        } else {
            flush(&mut run, &mut out);
            out.push(c);
        }
    }
    flush(&mut run, &mut out);
    out
}

/// Check that `value` is finite and strictly positive.
pub fn require_positive(field: &str, value: f64) -> Result<(), InputError> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(InputError::new(field, value, "must be finite and > 0"))
    }
}

/// A quantity derived from the inputs (gravity from W, ρ₀ and L; a period from L, E and ρ)
/// must be finite, positive and normal: an overflow or underflow there turns the closed forms
/// built on it into NaN or zero, silently, after every case has been solved. The error names
/// the input `field` (with its `value`) that the quantity is derived from.
pub fn require_derived(field: &str, value: f64, derived: &str, d: f64) -> Result<(), InputError> {
    if d.is_finite() && d >= f64::MIN_POSITIVE {
        Ok(())
    } else {
        Err(InputError::new(
            field,
            value,
            format!("gives {derived} = {d:e}, which must be finite, positive and normal (>= 2.2e-308)"),
        ))
    }
}

/// Check that `value` is finite.
pub fn require_finite(field: &str, value: f64) -> Result<(), InputError> {
    if value.is_finite() {
        Ok(())
    } else {
        Err(InputError::new(field, value, "must be finite"))
    }
}

/// Check that a count is at least `min`.
pub fn require_count(field: &str, value: usize, min: usize) -> Result<(), InputError> {
    if value >= min {
        Ok(())
    } else {
        Err(InputError::new(
            field,
            value,
            format!("must be an integer >= {min}"),
        ))
    }
}

/// Why a load step failed.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum StepFailure {
    /// Newton used its iterations without meeting the tolerance, and did not stall.
    #[error("Newton did not converge in {iterations} iterations (last normalised residual {last:.3e})")]
    NotConverged {
        /// Newton iterations done ([`crate::solver::newton::NewtonSettings::max_iterations`]).
        iterations: usize,
        /// The normalised residual after the last iteration.
        last: f64,
    },
    /// Newton used its iterations stuck at a round-off floor too far above the tolerance to
    /// accept ([`crate::solver::newton::FLOOR_ACCEPT_FACTOR`]).
    #[error("Newton stalled at its round-off floor after {iterations} iterations: the residual stays near {floor:.1e} (best {best:.1e}), above the tolerance {tolerance:.1e}; the tangent is too ill-conditioned for this tolerance (e.g. near-incompressible material): raise newton.tolerance above the floor or change the discretisation")]
    Stalled {
        /// Newton iterations done.
        iterations: usize,
        /// The floor estimate: the median normalised residual of the stalled iterations.
        floor: f64,
        /// The smallest normalised residual reached.
        best: f64,
        /// The Newton tolerance the floor stays above.
        tolerance: f64,
    },
    /// The residual or the update turned NaN or infinite.
    #[error("non-finite residual or update at Newton iteration {iteration}")]
    NonFinite {
        /// The Newton iteration (0: the residual at the starting point).
        iteration: usize,
    },
    /// Newton failed from its extrapolated start
    /// ([`crate::solver::newton::Predictor::Extrapolated`]); the load stepping tries the same
    /// increment from zero before it cuts it.
    #[error("from the extrapolated start: {0}")]
    Extrapolated(Box<StepFailure>),
    /// The linear solve of a Newton iteration failed.
    #[error("the linear solve failed: {0}")]
    LinearSolve(SolverError),
    /// A material point's weights could not be formed: it or its domain left the grid (or the
    /// domain grew too long).
    #[error("material point {point} left the background grid (position {position})")]
    LeftGrid {
        /// Index of the material point.
        point: usize,
        /// Its position and the basis's reason, formatted.
        position: String,
    },
    /// An integration point's kinematics failed (e.g. det ΔF ≤ 0, an inverted element, a
    /// collapsed or inverted domain, a non-finite body force).
    #[error("material point {point}: {reason}")]
    Kinematics {
        /// Index of the integration point (material point or Gauss point).
        point: usize,
        /// What failed, in words.
        reason: String,
    },
}

/// One attempt at a load step that failed: why, and the normalised residuals of its Newton
/// iterations (empty when it failed before the first).
#[derive(Debug, Clone, PartialEq, Error)]
#[error("{failure}")]
pub struct FailedAttempt {
    /// Why the attempt failed.
    pub failure: StepFailure,
    /// Normalised out-of-balance force per Newton iteration before the failure.
    pub residuals: Vec<f64>,
}

impl From<StepFailure> for FailedAttempt {
    /// A failure before any Newton iteration.
    fn from(failure: StepFailure) -> Self {
        FailedAttempt {
            failure,
            residuals: vec![],
        }
    }
}

/// A load step that failed, with the Newton residual history of its last attempt.
#[derive(Debug, Clone, PartialEq, Error)]
#[error("load step {step}{}: {failure}; residual history {residuals:?}", cut_note(*.attempts, *.load_factor))]
pub struct SolveError {
    /// Load step number, counted from 1.
    pub step: usize,
    /// Why the last attempt failed.
    pub failure: StepFailure,
    /// Normalised out-of-balance force per Newton iteration of the failing attempt.
    pub residuals: Vec<f64>,
    /// Attempts made at this load step (1 without adaptive cutbacks).
    pub attempts: usize,
    /// Load factor the failing attempt aimed at.
    pub load_factor: f64,
    /// Load factor of the last committed state, which the solver holds after the failure
    /// (a converged sub-step of the failing step counts).
    pub reached: f64,
}

fn cut_note(attempts: usize, load_factor: f64) -> String {
    if attempts > 1 {
        format!(
            " (after {attempts} attempts, the last at load factor {load_factor:.6}, at the cutback floor)"
        )
    } else {
        String::new()
    }
}

#[cfg(test)]
mod tidy_tests {
    use super::tidy_numbers;

    #[test]
    fn long_numbers_are_shortened_and_short_ones_kept() {
        let big = format!("{}", 1e300);
        assert_eq!(tidy_numbers(&format!("must be <= {big}")), "must be <= 1e300");
        let tiny = format!("{}", 1e-300);
        assert_eq!(tidy_numbers(&format!("{tiny}, x")), "1e-300, x");
        for kept in [
            "elements[3] = 1.5",
            "1-64 characters",
            "h = 0.005649717514124294",
            "a-b",
        ] {
            assert_eq!(tidy_numbers(kept), kept);
        }
    }
}

/// Why a linear solve failed: the error of the solver floors ([`crate::solver::direct`],
/// [`crate::solver::krylov`], [`crate::solver::multigrid`], [`crate::solver::linear`]), with its real cause.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum SolverError {
    /// faer rejected the factorisation (a structurally or numerically singular matrix, or a
    /// workspace it could not allocate); faer's own account.
    #[error("the factorisation failed: {0}")]
    Factorisation(String),
    /// The solve finished with a non-finite entry.
    #[error("the solution of the linear system is not finite (singular tangent)")]
    NotFinite,
    /// A Krylov method broke down, diverged or ran out of iterations (its own account, with
    /// the iteration and residual).
    #[error("{0}")]
    Krylov(String),
    /// The multigrid could not be built or applied.
    #[error("{0}")]
    Multigrid(String),
    /// The solver was used out of order (no factorisation, no geometry for CG, a
    /// factorisation asked of the iterative strategy): a bug of the caller.
    #[error("{0}")]
    Usage(&'static str),
}
