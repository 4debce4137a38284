//! The one results envelope every study kind writes as `results.json`: provenance, the study
//! as parsed, the sweep index, the case records, the kind's measures (flattened), the checks
//! and the timing, plus the records every kind shares (status, steps, failures). The engine
//! fills it, each kind's measures extend it, the renderers read it only.
//!
//! `results.json` holds no wall-clock data except its `timing` block, so two runs compare
//! equal after [`Envelope::without_timing`].

use super::checks::{check_counts, CheckRecord};
use super::{StudyError, Tier};
use crate::solver::error::SolveError;
use crate::solver::load_stepping::StepReport;
use crate::solver::profile::CaseCost;
use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum CaseStatus {
    /// Every load step converged.
    Converged,
    /// A load step failed (see `failure`); errors are not reported.
    Failed,
    /// The solver refused the input (see `failure.reason`); nothing was solved.
    Rejected,
    /// A strength reduction drove the body to collapse: the step where it collapsed is in
    /// `failure`, and the measures (the factor of safety among them) are those of the last
    /// converged state.
    Collapsed,
}

impl CaseStatus {
    pub fn word(self) -> &'static str {
        match self {
            CaseStatus::Converged => "converged",
            CaseStatus::Failed => "failed",
            CaseStatus::Rejected => "rejected",
            CaseStatus::Collapsed => "collapsed",
        }
    }

    /// Did the case give its measures: did it converge, or end in the collapse it was
    /// driven to?
    pub fn solved(self) -> bool {
        matches!(self, CaseStatus::Converged | CaseStatus::Collapsed)
    }
}

/// Newton residual history of one converged load step.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct StepRecord {
    pub step: usize,
    pub load_factor: f64,
    /// Normalised out-of-balance force before the first and after each Newton update.
    pub residuals: Vec<f64>,
    /// Unknowns and non-zeros of the step's tangent (0 in results written before they were
    /// recorded).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub unknowns: usize,
    #[serde(default, skip_serializing_if = "is_zero")]
    pub nonzeros: usize,
    /// Non-zeros of the step's last LDLᵀ/LLᵀ factor (0: none, or not recorded).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub factor_nonzeros: usize,
    /// Krylov iterations of the step's solves: CG's, plus GMRES's where CG gave up (0 for
    /// direct solves).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub linear_iterations: usize,
    /// Accepted stalled at this estimated round-off floor, above the tolerance but within
    /// [`crate::solver::newton::FLOOR_ACCEPT_FACTOR`] of it (absent: the tolerance was met).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub accepted_at_floor: Option<f64>,
    /// Increments of the step that failed and were halved (0: none, or not recorded).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub cutbacks: usize,
    /// Newton iterations of the step's increments before the one whose residuals are
    /// recorded, failed and converged alike: the work `residuals` does not show (0 when the
    /// nominal increment converged at once, or not recorded).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub earlier_iterations: usize,
}

impl StepRecord {
    /// A step of which only its residuals are known (an element test's, another code's):
    /// the solver's counts are zero, "not recorded".
    pub fn residuals_only(step: usize, load_factor: f64, residuals: Vec<f64>) -> Self {
        Self {
            step,
            load_factor,
            residuals,
            ..Default::default()
        }
    }
}

fn is_zero(n: &usize) -> bool {
    *n == 0
}

/// Why a case did not converge.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FailureRecord {
    /// Load step that failed (from 1); 0 when the input was rejected.
    pub step: usize,
    pub reason: String,
    /// Residual history of the failing step.
    pub residuals: Vec<f64>,
}

impl SolveRecord {
    /// Every step's residual history as (case, step, residuals), a failed case's last
    /// attempt included: a tangent off its derivative often makes Newton so slow that the
    /// case fails, and its residuals are then the evidence (the Newton-order checks).
    pub fn newton_histories<'a>(
        &'a self,
        case: &'a str,
    ) -> impl Iterator<Item = (&'a str, usize, &'a [f64])> {
        let failed = self
            .failure
            .iter()
            .map(move |f| (case, f.step, f.residuals.as_slice()));
        self.steps
            .iter()
            .map(move |s| (case, s.step, s.residuals.as_slice()))
            .chain(failed)
    }
}

/// Residual histories of converged load steps.
pub fn step_records(steps: &[StepReport]) -> Vec<StepRecord> {
    steps
        .iter()
        .map(|s| StepRecord {
            step: s.step,
            load_factor: s.load_factor,
            residuals: s.newton.residuals.clone(),
            unknowns: s.linear.unknowns,
            nonzeros: s.linear.nonzeros,
            factor_nonzeros: s.linear.factor_nonzeros,
            linear_iterations: s.linear.iterations,
            accepted_at_floor: s.newton.accepted_floor,
            cutbacks: s.cutbacks(),
            earlier_iterations: s.earlier_iterations(),
        })
        .collect()
}

pub fn failure_record(e: &SolveError) -> FailureRecord {
    FailureRecord {
        step: e.step,
        reason: e.failure.to_string(),
        residuals: e.residuals.clone(),
    }
}

/// A case that was not solved (step 0, no residuals).
pub fn rejection(reason: impl Into<String>) -> FailureRecord {
    FailureRecord {
        step: 0,
        reason: reason.into(),
        residuals: vec![],
    }
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Software {
    pub name: String,
    pub version: String,
    /// The git commit the binary was built from ("unknown" outside a checkout); absent in
    /// results written before it was recorded.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub commit: Option<String>,
    /// Whether the sources the binary was built from (src/, Cargo.toml, Cargo.lock, build.rs)
    /// differed from `commit`; absent where unknown.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub dirty: Option<bool>,
}

impl Software {
    /// This build: name, version, commit and dirty flag (build.rs).
    pub fn this_build() -> Self {
        Software {
            name: env!("CARGO_PKG_NAME").to_string(),
            version: env!("CARGO_PKG_VERSION").to_string(),
            commit: Some(env!("IGIMP_GIT_COMMIT").to_string()),
            dirty: env!("IGIMP_GIT_DIRTY").parse().ok(),
        }
    }

    /// `igimp 0.1.0, commit 507f631` (`, with uncommitted changes` when dirty).
    pub fn label(&self) -> String {
        let mut s = format!("{} {}", self.name, self.version);
        if let Some(c) = &self.commit {
            s.push_str(&format!(", commit {}", &c[..c.len().min(12)]));
            if self.dirty == Some(true) {
                s.push_str(" with uncommitted changes");
            }
        }
        s
    }
}

/// Header fields every `results.json` starts with.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Provenance {
    pub software: Software,
    /// File name of the study file the inputs came from.
    pub study_file: String,
    pub tier: Tier,
}

impl Provenance {
    pub fn new(study_file: &str, tier: Tier) -> Self {
        Provenance {
            software: Software::this_build(),
            study_file: study_file.to_string(),
            tier,
        }
    }

    /// One line for the top of a report.
    pub fn line(&self) -> String {
        format!(
            "Rendered from `results.json` by `study` ({}, {} tier, study file `{}`); regenerate, do not edit.",
            self.software.label(),
            self.tier.name(),
            self.study_file
        )
    }
}

/// Wall-clock data: the only part of `results.json` that changes from run to run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Timing {
    pub wall_seconds: f64,
    pub threads: usize,
    /// Wall seconds of each case, by case id (a resumed case keeps its original time).
    pub cases: BTreeMap<String, f64>,
    /// Each case's seconds by phase and its heap peak, by case id (absent in results written
    /// before they were accounted; a case resumed from such a store has its seconds only).
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub costs: BTreeMap<String, CaseCost>,
    /// Peak resident memory of the process during the study's run (Linux `VmHWM`, reset at
    /// its start to the resident size then, which includes what the allocator kept from
    /// studies run before in the same process); absent where the peak cannot be reset or
    /// cases were resumed.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub peak_resident_bytes: Option<u64>,
}

impl Timing {
    /// The same block with every time zeroed (case ids kept), for comparing two runs.
    pub fn zeroed(&self) -> Self {
        Timing {
            wall_seconds: 0.0,
            threads: 0,
            cases: self.cases.keys().map(|k| (k.clone(), 0.0)).collect(),
            costs: self
                .costs
                .keys()
                .map(|k| (k.clone(), CaseCost::default()))
                .collect(),
            peak_resident_bytes: None,
        }
    }
}

/// Case ids of each sweep of the tier (a case may belong to several sweeps).
pub type SweepIndex = BTreeMap<String, Vec<String>>;

/// `results.json` of any study kind: `S` the study file, `C` a case record, `M` the kind's
/// measures (flattened into the top level).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Envelope<S, C, M> {
    #[serde(flatten)]
    pub provenance: Provenance,
    /// The study inputs as parsed.
    pub study: S,
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub sweep_cases: SweepIndex,
    pub cases: Vec<C>,
    #[serde(flatten)]
    pub measures: M,
    /// Every claim of the paper or the study file checked against the results.
    pub checks: Vec<CheckRecord>,
    pub timing: Timing,
}

/// What an envelope's case records say of themselves.
pub trait CaseRecordOf {
    fn id(&self) -> &str;
    fn status(&self) -> CaseStatus;
    /// The converged load steps.
    fn steps(&self) -> &[StepRecord];
}

/// [`CaseRecordOf`] for a record with `id: String` and `solve: SolveRecord` fields.
macro_rules! case_record {
    ($record:ty) => {
        impl $crate::study::results::CaseRecordOf for $record {
            fn id(&self) -> &str {
                &self.id
            }
            fn status(&self) -> $crate::study::results::CaseStatus {
                self.solve.status
            }
            fn steps(&self) -> &[$crate::study::results::StepRecord] {
                &self.solve.steps
            }
        }
    };
}
pub(crate) use case_record;

/// What every kind records of one solve: status, failure, Newton iterations and the
/// residual histories of the converged steps; each kind's record flattens it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SolveRecord {
    pub status: CaseStatus,
    pub failure: Option<FailureRecord>,
    /// Newton iterations summed over the converged steps.
    pub newton_iterations: usize,
    pub steps: Vec<StepRecord>,
}

impl SolveRecord {
    /// The record of a solve that ran `steps` and stopped at `failure` (if any).
    pub fn of(steps: &[StepReport], failure: Option<&SolveError>) -> Self {
        SolveRecord {
            status: if failure.is_some() {
                CaseStatus::Failed
            } else {
                CaseStatus::Converged
            },
            failure: failure.map(failure_record),
            newton_iterations: steps.iter().map(|s| s.newton.iterations()).sum(),
            steps: step_records(steps),
        }
    }

    /// A case whose input the solver refused (nothing solved).
    pub fn rejected(reason: impl std::fmt::Display) -> Self {
        SolveRecord {
            status: CaseStatus::Rejected,
            failure: Some(rejection(reason.to_string())),
            newton_iterations: 0,
            steps: vec![],
        }
    }
}

impl<S: Clone, C: Clone + CaseRecordOf, M: Clone> Envelope<S, C, M> {
    pub fn case(&self, id: &str) -> Option<&C> {
        self.cases.iter().find(|c| c.id() == id)
    }

    /// The cases of a sweep, in plan order.
    pub fn sweep(&self, id: &str) -> Vec<&C> {
        self.sweep_cases
            .get(id)
            .map_or(vec![], |ids| ids.iter().filter_map(|i| self.case(i)).collect())
    }

    /// Copy with the wall-clock times zeroed.
    pub fn without_timing(&self) -> Self {
        let mut r = self.clone();
        r.timing = r.timing.zeroed();
        r
    }

    /// (passed, failed, not evaluated) checks.
    pub fn check_counts(&self) -> (usize, usize, usize) {
        check_counts(&self.checks)
    }

    pub fn summary(&self, resumed: usize) -> RunSummary {
        RunSummary::new(self.cases.iter().map(|c| c.status()), &self.checks).with_resumed(resumed)
    }
}

/// Outcome of running one study file (for the binary's summary line).
#[derive(Debug, Clone, PartialEq)]
pub struct RunSummary {
    pub cases: usize,
    pub failed: usize,
    pub rejected: usize,
    pub checks: (usize, usize, usize),
    /// Cases read back from the case store (`--resume`).
    pub resumed: usize,
}

impl RunSummary {
    pub fn new(statuses: impl Iterator<Item = CaseStatus>, checks: &[CheckRecord]) -> Self {
        let mut r = RunSummary {
            cases: 0,
            failed: 0,
            rejected: 0,
            checks: check_counts(checks),
            resumed: 0,
        };
        for s in statuses {
            r.cases += 1;
            r.failed += usize::from(s == CaseStatus::Failed);
            r.rejected += usize::from(s == CaseStatus::Rejected);
        }
        r
    }

    pub fn with_resumed(mut self, resumed: usize) -> Self {
        self.resumed = resumed;
        self
    }
}

/// The failed and rejected cases of a `results.json` of any kind: those its study declares
/// expected (`[[expected_failures]]`), with the reason, and the others.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Failures {
    pub expected: Vec<(String, String)>,
    pub unexpected: Vec<(String, CaseStatus)>,
    /// Declared patterns that match no case of the run (stale, or of sweeps not run).
    pub unmatched: Vec<String>,
}

impl Failures {
    /// Read from a `results.json` parsed as JSON (a case's status is its `status` or its
    /// `solve.status`).
    pub fn of(results: &serde_json::Value) -> Self {
        let declared: Vec<super::vocabulary::ExpectedFailure> = results
            .pointer("/study/expected_failures")
            .and_then(|v| serde_json::from_value(v.clone()).ok())
            .unwrap_or_default();
        let mut out = Failures::default();
        let cases = results.get("cases").and_then(|c| c.as_array());
        let ids: Vec<&str> = cases
            .into_iter()
            .flatten()
            .filter_map(|c| c.get("id")?.as_str())
            .collect();
        for p in declared.iter().flat_map(|e| &e.cases) {
            if !ids.iter().any(|id| super::vocabulary::glob_match(p, id)) {
                out.unmatched.push(p.clone());
            }
        }
        for c in cases.into_iter().flatten() {
            let id = c.get("id").and_then(|v| v.as_str()).unwrap_or("?").to_string();
            let status = c
                .get("status")
                .or_else(|| c.pointer("/solve/status"))
                .and_then(|v| serde_json::from_value::<CaseStatus>(v.clone()).ok());
            match status {
                Some(CaseStatus::Converged | CaseStatus::Collapsed) => {}
                Some(s) => match super::vocabulary::expected_reason(&declared, &id) {
                    Some(reason) => out.expected.push((id, reason.to_string())),
                    None => out.unexpected.push((id, s)),
                },
                None => out.unexpected.push((id, CaseStatus::Rejected)),
            }
        }
        out
    }

    /// One line for the terminal: which failures were expected and why (the reasons, each
    /// once), and which were not.
    pub fn line(&self) -> Option<String> {
        let mut reasons: Vec<&str> = vec![];
        for (_, r) in &self.expected {
            if !reasons.contains(&r.as_str()) {
                reasons.push(r);
            }
        }
        let mut parts = vec![];
        if !self.expected.is_empty() {
            parts.push(format!(
                "{} expected to fail ({})",
                self.expected.len(),
                reasons.join("; ")
            ));
        }
        if !self.unexpected.is_empty() {
            let ids: Vec<String> = self
                .unexpected
                .iter()
                .map(|(id, s)| format!("{id} {}", s.word()))
                .collect();
            parts.push(format!(
                "{} NOT expected: {}",
                self.unexpected.len(),
                ids.join(", ")
            ));
        }
        if !self.unmatched.is_empty() {
            parts.push(format!(
                "expected failures that match no case of this run: {}",
                self.unmatched.join(", ")
            ));
        }
        (!parts.is_empty()).then(|| parts.join("; "))
    }
}

/// Write `value` as JSON (pretty or compact), atomically.
pub fn write_json<T: Serialize>(path: &Path, value: &T, pretty: bool) -> Result<(), StudyError> {
    let text = if pretty {
        serde_json::to_string_pretty(value)
    } else {
        serde_json::to_string(value)
    }
    .map_err(|e| StudyError::io(path, e))?;
    super::store::write_file(path, (text + "\n").as_bytes())
}

/// Write `path` (compact JSON): the side data `D` of the cases whose (record, data) `keep`
/// accepts, by case id.
pub fn write_case_data<R: CaseRecordOf, D: Serialize>(
    path: &Path,
    outputs: &[(R, D)],
    keep: impl Fn(&R, &D) -> bool,
) -> Result<(), StudyError> {
    let kept: BTreeMap<&str, &D> = outputs
        .iter()
        .filter(|(r, d)| keep(r, d))
        .map(|(r, d)| (r.id(), d))
        .collect();
    write_json(path, &kept, false)
}

pub fn read_json<T: DeserializeOwned>(path: &Path) -> Result<T, StudyError> {
    let text = std::fs::read_to_string(path).map_err(|e| StudyError::io(path, e))?;
    serde_json::from_str(&text).map_err(|e| StudyError::Parse {
        file: path.display().to_string(),
        message: e.to_string(),
    })
}

/// Read `<dir>/results.json`.
pub fn read_results<T: DeserializeOwned>(dir: &Path) -> Result<T, StudyError> {
    read_json(&dir.join("results.json"))
}

/// `<dir>/points/`, created, without the point files (`*.csv`) of an earlier run.
pub fn fresh_points_dir(dir: &Path) -> Result<PathBuf, StudyError> {
    let pdir = dir.join("points");
    std::fs::create_dir_all(&pdir).map_err(|e| StudyError::io(&pdir, e))?;
    for entry in std::fs::read_dir(&pdir).map_err(|e| StudyError::io(&pdir, e))? {
        let p = entry.map_err(|e| StudyError::io(&pdir, e))?.path();
        if p.extension().is_some_and(|x| x == "csv") {
            std::fs::remove_file(&p).map_err(|e| StudyError::io(&p, e))?;
        }
    }
    Ok(pdir)
}

/// Write `text` to `path` atomically and note it in `written`.
pub fn write_text(path: &Path, text: &str, written: &mut Vec<PathBuf>) -> Result<(), StudyError> {
    super::store::write_file(path, text.as_bytes())?;
    written.push(path.to_path_buf());
    Ok(())
}

/// The `problem` key of a study file, if it has one.
pub fn problem_of_study(text: &str) -> Option<String> {
    let v: toml::Value = toml::from_str(text).ok()?;
    v.get("problem")?.as_str().map(str::to_string)
}

/// The `study.problem` recorded in `<dir>/results.json`; an error that says whether the file
/// is missing, is not valid JSON (the parser's message, with line and column: e.g. a file
/// truncated by a full disk) or lacks the key.
pub fn problem_of_results(dir: &Path) -> Result<String, StudyError> {
    let path = dir.join("results.json");
    let text = std::fs::read_to_string(&path).map_err(|e| {
        if e.kind() == std::io::ErrorKind::NotFound {
            StudyError::NoResults {
                study: dir
                    .file_name()
                    .map_or_else(|| dir.display().to_string(), |n| n.to_string_lossy().into_owned()),
                path: path.display().to_string(),
            }
        } else {
            StudyError::io(&path, e)
        }
    })?;
    let v: serde_json::Value = serde_json::from_str(&text).map_err(|e| StudyError::Parse {
        file: path.display().to_string(),
        message: format!("not valid JSON ({e}); solve the study again to rewrite it"),
    })?;
    v.get("study")
        .and_then(|s| s.get("problem"))
        .and_then(|p| p.as_str())
        .map(str::to_string)
        .ok_or_else(|| StudyError::Parse {
            file: path.display().to_string(),
            message: "no `study.problem`: not the results.json of a study".into(),
        })
}
