//! The case protocol's two files (`studies/PROTOCOL.md`, schemas in `studies/protocol/`):
//! `case.json`, which the harness writes for a case an external code solves, and
//! `result.json`, which the code writes back and the harness reads strictly: a file that
//! breaks any rule is the case's failure, with the rule named.

use crate::basis::method::Method;
use crate::problems::scene::{DiscreteScene, PointFields, Reactions, SceneSettings};
use crate::solver::newton::ResidualNorm;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// `protocol` of a case file.
pub const CASE_PROTOCOL: &str = "igimp-case";
/// `protocol` of a result file.
pub const RESULT_PROTOCOL: &str = "igimp-result";
/// The protocol's version, in both files.
pub const VERSION: u32 = 1;

/// Newton's convergence test, for a code to apply as igimp does.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NewtonCase {
    pub tolerance: f64,
    pub max_iterations: usize,
    /// igimp's name of the norm (`external`, `total`, `linearised`).
    pub norm: ResidualNorm,
    /// The norm in words.
    pub norm_definition: String,
}

/// What the code is asked to return.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Outputs {
    /// The point fields after every converged step (`step_fields`), not only the last.
    pub every_step: bool,
    /// The regions whose reactions to return after every converged step.
    pub reactions: Vec<String>,
}

/// `case.json`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CaseFile {
    pub protocol: String,
    pub version: u32,
    /// The case's id in its study.
    pub id: String,
    /// The study's name of the method (`ext:<adapter>[@<method>]`).
    pub method: String,
    /// The basis asked of the code, as igimp names it (`mpm`: standard MPM).
    pub basis: Method,
    /// The problem at this case's resolution: grid, material, points, regions, loads.
    pub scene: DiscreteScene,
    /// Load steps of equal load factor increments 1/n (the load factor λ_k = k/n).
    pub load_steps: usize,
    pub newton: NewtonCase,
    pub outputs: Outputs,
    /// igimp's own settings of the case (what igimp's adapter solves with; other codes may
    /// ignore them).
    pub igimp: SceneSettings,
}

/// How a run ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum RunStatus {
    /// Every load step converged.
    Converged,
    /// A load step failed: `failure` says which and why.
    Failed,
    /// The code cannot solve this case as asked (a model, load or basis it lacks):
    /// `failure.reason` says what; nothing was approximated.
    Unsupported,
}

/// Why a run stopped.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RunFailure {
    /// The load step that failed, from 1 (0: before any).
    pub step: usize,
    pub reason: String,
    #[serde(default)]
    pub residuals: Vec<f64>,
}

/// One converged load step.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ResultStep {
    pub step: usize,
    pub load_factor: f64,
    /// Newton iterations (linear solves) of the step.
    pub iterations: usize,
    /// The normalised residual before the first Newton update and after each
    /// (`iterations` + 1 values), if the code can tell.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub residuals: Vec<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub seconds: Option<f64>,
}

/// The code that ran.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Code {
    pub name: String,
    pub version: String,
}

/// Wall time of the solve (import and set-up excluded where the code can tell), and its
/// phases if it can.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RunTiming {
    pub seconds: f64,
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub phases: BTreeMap<String, f64>,
}

/// `result.json`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ResultFile {
    pub protocol: String,
    pub version: u32,
    pub code: Code,
    pub status: RunStatus,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub failure: Option<RunFailure>,
    /// What the code's residuals are normalised by, where it is not the case's norm (a code
    /// that applies its own convergence test says which).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub residual_norm: Option<String>,
    /// Every converged step, in order.
    pub steps: Vec<ResultStep>,
    /// The points after the last converged step (absent if none converged).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fields: Option<PointFields>,
    /// The points after each converged step, when `outputs.every_step` asks.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub step_fields: Vec<PointFields>,
    /// The reactions of the asked regions after each converged step.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub reactions: Vec<Reactions>,
    pub timing: RunTiming,
}

/// Why a result file is refused: the rule it breaks, at its key path.
pub fn refuse(key: &str, why: impl std::fmt::Display) -> String {
    format!("result.json: `{key}`: {why}")
}

impl ResultFile {
    /// Parse `text` strictly against `case`: every rule of the protocol, or the first one
    /// broken, named by its key path.
    pub fn parse(text: &str, case: &CaseFile) -> Result<Self, String> {
        let r: ResultFile = serde_json::from_str(text).map_err(|e| {
            let hint = if ["NaN", "Infinity"].iter().any(|t| text.contains(t)) {
                " (NaN and Infinity are not JSON numbers: a code whose state is not finite reports status \"failed\")"
            } else {
                ""
            };
            format!("result.json is not a valid result file: {e}{hint}")
        })?;
        r.check(case)?;
        Ok(r)
    }

    fn check(&self, case: &CaseFile) -> Result<(), String> {
        if self.protocol != RESULT_PROTOCOL {
            return Err(refuse(
                "protocol",
                format!("{:?}, must be {RESULT_PROTOCOL:?}", self.protocol),
            ));
        }
        if self.version != VERSION {
            return Err(refuse("version", format!("{}, must be {VERSION}", self.version)));
        }
        if self.code.name.trim().is_empty() || self.code.version.trim().is_empty() {
            return Err(refuse("code", "must give the code's name and version"));
        }
        match (self.status, &self.failure) {
            (RunStatus::Converged, Some(_)) => {
                return Err(refuse("failure", "must be absent when status is \"converged\""))
            }
            (RunStatus::Failed | RunStatus::Unsupported, None) => {
                return Err(refuse(
                    "failure",
                    "must say the step and reason when the run did not converge",
                ))
            }
            (_, Some(f)) if f.reason.trim().is_empty() => {
                return Err(refuse("failure.reason", "must not be empty"))
            }
            _ => {}
        }
        let n = case.load_steps;
        if self.status == RunStatus::Converged && self.steps.len() != n {
            return Err(refuse(
                "steps",
                format!("{} steps, a converged run has {n}", self.steps.len()),
            ));
        }
        if self.steps.len() > n {
            return Err(refuse(
                "steps",
                format!("{} steps, the case has {n}", self.steps.len()),
            ));
        }
        for (k, s) in self.steps.iter().enumerate() {
            let key = format!("steps[{k}]");
            if s.step != k + 1 {
                return Err(refuse(
                    &format!("{key}.step"),
                    format!("{}, must be {}", s.step, k + 1),
                ));
            }
            if !(s.load_factor.is_finite() && s.load_factor > 0.0 && s.load_factor <= 1.0 + 1e-12) {
                return Err(refuse(
                    &format!("{key}.load_factor"),
                    format!("{}, must lie in (0, 1]", s.load_factor),
                ));
            }
            if !s.residuals.is_empty() && s.residuals.len() != s.iterations + 1 {
                return Err(refuse(
                    &format!("{key}.residuals"),
                    format!(
                        "{} values, must be iterations + 1 = {} (or none)",
                        s.residuals.len(),
                        s.iterations + 1
                    ),
                ));
            }
            if s.residuals.iter().any(|r| !(r.is_finite() && *r >= 0.0)) {
                return Err(refuse(&format!("{key}.residuals"), "must be finite and ≥ 0"));
            }
            if let Some(t) = s.seconds.filter(|t| !(t.is_finite() && *t >= 0.0)) {
                return Err(refuse(
                    &format!("{key}.seconds"),
                    format!("{t}, must be finite and ≥ 0"),
                ));
            }
        }
        let (count, d) = (case.scene.points.position.len(), case.scene.dimension);
        let converged = self.steps.len();
        match (&self.fields, converged) {
            (None, c) if c > 0 => {
                return Err(refuse(
                    "fields",
                    "must give the points after the last converged step",
                ))
            }
            (Some(f), _) => f
                .validate("fields", count, d)
                .map_err(|e| refuse(&e.field, format!("{}: {}", e.value, e.allowed)))?,
            _ => {}
        }
        if case.outputs.every_step && self.step_fields.len() != converged {
            return Err(refuse(
                "step_fields",
                format!(
                    "{} entries, must give one per converged step ({converged})",
                    self.step_fields.len()
                ),
            ));
        }
        for (k, f) in self.step_fields.iter().enumerate() {
            f.validate(&format!("step_fields[{k}]"), count, d)
                .map_err(|e| refuse(&e.field, format!("{}: {}", e.value, e.allowed)))?;
        }
        if !case.outputs.reactions.is_empty() && self.reactions.len() != converged {
            return Err(refuse(
                "reactions",
                format!(
                    "{} entries, must give one per converged step ({converged})",
                    self.reactions.len()
                ),
            ));
        }
        for (k, r) in self.reactions.iter().enumerate() {
            for name in &case.outputs.reactions {
                let Some(v) = r.get(name) else {
                    return Err(refuse(
                        &format!("reactions[{k}]"),
                        format!("must give region {name:?}"),
                    ));
                };
                if v.len() != d || v.iter().any(|x| !x.is_finite()) {
                    return Err(refuse(
                        &format!("reactions[{k}].{name}"),
                        format!("must give {d} finite values"),
                    ));
                }
            }
        }
        if !(self.timing.seconds.is_finite() && self.timing.seconds >= 0.0) {
            return Err(refuse(
                "timing.seconds",
                format!("{}, must be finite and ≥ 0", self.timing.seconds),
            ));
        }
        Ok(())
    }
}
