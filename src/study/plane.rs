//! Machinery shared by the plane-strain studies: compaction (§5.2) and the cantilever (§5.3);
//! which study a file or results folder holds is [`super::registry`]'s business, so this module
//! imports neither.
//!
//! Their study files carry `problem = "compaction"` / `"cantilever"`; the `study` binary and
//! [`crate::render::column::render_index`] dispatch on that key ([`problem_of_study`],
//! [`problem_of_results`]) and otherwise use the column study's conventions: compute →
//! `results.json` → render, rayon across cases with the records in study order, failed cases
//! recorded with their step, reason and residuals, `--quick`, `--render-only`, `--check`, the
//! case store with `--resume`, `--vtk` and the progress bar ([`run_cases_stored`]).
//!
//! `results.json` holds no wall-clock data except its `timing` block, so two runs compare
//! equal after [`Timing::zeroed`]. The material point domains drawn in the figures are kept
//! in a compact `domains.json` beside it.

use super::runner::{CaseStatus, FailureRecord, Software, StepRecord};
use super::{StudyError, Tier};
use crate::error::SolveError;
use crate::load_stepping::StepReport;
use crate::method::Method;
use crate::mpm::WeakNodeTreatment;
use rayon::prelude::*;
use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Weak-node treatment as written in a study file (see [`crate::mpm::MpmSettings`]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WeakNodeSection {
    /// Nodes whose material volume share is below this fraction of an element are treated;
    /// in [0, 1), 0 disables the treatment.
    pub tolerance: f64,
    pub treatment: WeakNodeTreatment,
}

/// Ghost stabilisation as written in a study file ([`crate::ghost`]): γ and the faces for
/// two or more points per cell, the settings for one point per cell (every face), and those
/// of plastic cases.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GhostSection {
    /// Penalty factor γ for two or more points per cell (0 = off); in [0, 1000].
    pub gamma: f64,
    #[serde(default)]
    pub faces: crate::ghost::GhostFaces,
    /// Fill fraction below which a cell is cut, in (0, 1]; default
    /// [`crate::ghost::DEFAULT_CUT_FILL`].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cut_fill: Option<f64>,
    /// Settings for one point per cell; default: the ones above.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub one_point_per_cell: Option<crate::ghost::GhostSettings>,
    /// Settings for plastic (von Mises) cases with two or more points per cell; default: the
    /// ones above.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub plastic: Option<crate::ghost::GhostSettings>,
    /// Where the defaults come from (the measurement that chose them).
    pub source: String,
}

impl GhostSection {
    /// The settings of a case with `ppc` points per cell, plastic or not; `gamma` (a sweep's
    /// value) replaces the default γ.
    pub fn settings(&self, ppc: usize, plastic: bool, gamma: Option<f64>) -> crate::ghost::GhostSettings {
        let mut g = match (ppc, self.one_point_per_cell, plastic, self.plastic) {
            (1, Some(one), _, _) => one,
            (_, _, true, Some(p)) => p,
            _ => crate::ghost::GhostSettings {
                gamma: self.gamma,
                faces: self.faces,
                cut_fill: self.cut_fill.unwrap_or(crate::ghost::DEFAULT_CUT_FILL),
            },
        };
        if let Some(gamma) = gamma {
            g.gamma = gamma;
        }
        g
    }

    pub fn validate(&self) -> Result<(), crate::error::InputError> {
        self.settings(2, false, None).validate()?;
        self.settings(2, true, None).validate()?;
        self.settings(1, false, None).validate()
    }
}

/// A claim of the paper or the issue, checked against the results.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CheckRecord {
    /// Short identifier, e.g. `fig17-within-1pc`.
    pub id: String,
    /// What is checked, in one sentence.
    pub description: String,
    /// The measured quantity compared with `limit` (e.g. a largest relative difference).
    pub measured: Option<f64>,
    pub limit: f64,
    /// `None`: could not be evaluated (e.g. the cases it needs were rejected or not run).
    pub pass: Option<bool>,
    pub source: String,
}

/// Wall-clock data: the only part of `results.json` that changes from run to run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Timing {
    pub wall_seconds: f64,
    pub threads: usize,
    /// Wall seconds of each case, by case id.
    pub cases: BTreeMap<String, f64>,
}

impl Timing {
    /// The same block with every time zeroed (case ids kept), for comparing two runs.
    pub fn zeroed(&self) -> Self {
        Timing {
            wall_seconds: 0.0,
            threads: 0,
            cases: self.cases.keys().map(|k| (k.clone(), 0.0)).collect(),
        }
    }
}

/// Header fields every plane-strain `results.json` starts with.
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
            software: Software {
                name: env!("CARGO_PKG_NAME").to_string(),
                version: env!("CARGO_PKG_VERSION").to_string(),
            },
            study_file: study_file.to_string(),
            tier,
        }
    }

    /// One line for the top of a report.
    pub fn line(&self) -> String {
        format!(
            "Rendered from `results.json` by `study` ({} {}, {} tier, study file `{}`); regenerate, do not edit.",
            self.software.name,
            self.software.version,
            tier_name(self.tier),
            self.study_file
        )
    }
}

pub fn tier_name(t: Tier) -> &'static str {
    match t {
        Tier::Full => "full",
        Tier::Quick => "quick",
    }
}

/// Solve `cases` on the rayon pool, most expensive first (by `cost`), and return the results
/// in the order of `cases` with each one's wall seconds: the output does not depend on the
/// thread count.
pub fn run_cases<C: Sync, R: Send>(
    cases: &[C],
    cost: impl Fn(&C) -> f64 + Sync,
    solve: impl Fn(&C) -> R + Sync,
) -> Vec<(R, f64)> {
    let mut order: Vec<usize> = (0..cases.len()).collect();
    order.sort_by(|&a, &b| cost(&cases[b]).total_cmp(&cost(&cases[a])).then(a.cmp(&b)));
    let mut solved: Vec<(usize, R, f64)> = order
        .par_iter()
        .map(|&i| {
            let t = Instant::now();
            let r = solve(&cases[i]);
            (i, r, t.elapsed().as_secs_f64())
        })
        .collect();
    solved.sort_by_key(|s| s.0);
    solved.into_iter().map(|(_, r, t)| (r, t)).collect()
}

/// What the `study` binary asks of a plane-strain run besides the tier: the case store
/// (`<out>/<name>/cases/`, every finished case written atomically as soon as it is done),
/// `--resume`, `--vtk` and the progress bar.
pub struct PlaneRunOptions<'a> {
    /// The study's output folder; `None`: no case store and no VTK (the library's
    /// `run_study`).
    pub study_dir: Option<PathBuf>,
    /// Reuse the stored record of a case whose inputs hash equally.
    pub resume: bool,
    /// Write ParaView files of the material point domains of each iGIMP case.
    pub vtk: Option<super::vtk_output::VtkOptions>,
    /// `--shard K/N` or `--merge` (needs `study_dir`).
    pub distribution: super::Distribution,
    /// Called once with the number of cases, then with each case's id and status when done.
    pub on_start: &'a (dyn Fn(usize) + Sync),
    pub on_done: &'a (dyn Fn(&str, CaseStatus) + Sync),
}

impl Default for PlaneRunOptions<'_> {
    fn default() -> Self {
        Self {
            study_dir: None,
            resume: false,
            vtk: None,
            distribution: super::Distribution::Whole,
            on_start: &|_| {},
            on_done: &|_, _| {},
        }
    }
}

/// The inputs that define a plane-strain case's result, hashed for `--resume`.
#[derive(Serialize)]
struct CaseDefinition<'a, S> {
    id: &'a str,
    method: Method,
    spec: &'a S,
    /// Domain snapshots taken for the figures (0: none).
    snapshot_every: usize,
}

/// The store key of a case for [`run_cases_stored`]: its id, the hash of its definition, and
/// whether it has VTK output (iGIMP cases).
pub fn case_key<S: Serialize>(
    id: &str,
    method: Method,
    spec: &S,
    snapshot_every: usize,
) -> (String, String, bool) {
    let def = CaseDefinition {
        id,
        method,
        spec,
        snapshot_every,
    };
    (
        id.to_string(),
        super::store::case_hash(&def),
        method.uses_material_points(),
    )
}

/// A finished case as the store keeps it: its output and the seconds it took (so that a
/// resumed run reports the original timing).
#[derive(Serialize, Deserialize)]
struct StoredCase<R> {
    output: R,
    seconds: f64,
}

/// [`run_cases`] with the case store (`--merge`: every case must be read from it, the ids of
/// those that are not are returned in one error): with `resume`, a case stored earlier under the same id
/// and input hash (`key` gives both, and whether the case has VTK output; with `--vtk`, its
/// `.pvd` must exist too) is read back
/// instead of solved; every solved case is stored as soon as it is done, and `vtk` (if on)
/// writes its ParaView files. Returns the outputs in case order with their seconds, and how
/// many were resumed; the first store error (in case order) fails the run.
#[allow(clippy::too_many_arguments)]
pub fn run_cases_stored<C: Sync, R: Send + Serialize + DeserializeOwned>(
    cases: &[C],
    key: impl Fn(&C) -> (String, String, bool) + Sync,
    cost: impl Fn(&C) -> f64 + Sync,
    solve: impl Fn(&C) -> R + Sync,
    status: impl Fn(&R) -> CaseStatus + Sync,
    vtk: impl Fn(&Path, &C, &R) -> Result<(), StudyError> + Sync,
    options: &PlaneRunOptions<'_>,
) -> Result<(Vec<(R, f64)>, usize), StudyError> {
    use super::Distribution;
    let store = match &options.study_dir {
        Some(dir) => Some(super::store::CaseStore::open(&dir.join("cases"))?),
        None => None,
    };
    let distribution = options.distribution;
    let merge = distribution == Distribution::Merge;
    let resume = options.resume || merge;
    let own: Vec<&C> = cases
        .iter()
        .enumerate()
        .filter(|(i, _)| distribution.owns(*i))
        .map(|(_, c)| c)
        .collect();
    (options.on_start)(own.len());
    let resumed = std::sync::atomic::AtomicUsize::new(0);
    let outputs = run_cases(
        &own,
        |c| cost(c),
        |c| {
            let (id, hash, has_vtk) = key(c);
            let (Some(store), Some(dir)) = (&store, &options.study_dir) else {
                let r = solve(c);
                (options.on_done)(&id, status(&r));
                return Ok(Some((r, None)));
            };
            // --merge solves nothing, so it does not ask for the VTK files either.
            let vtk_done = match options.vtk {
                Some(_) if has_vtk && !merge => super::vtk_output::pvd_path(dir, &id)?.exists(),
                _ => true,
            };
            if resume && vtk_done {
                if let Some(s) = store.load::<StoredCase<R>>(&id, &hash) {
                    resumed.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                    (options.on_done)(&id, status(&s.output));
                    return Ok(Some((s.output, Some(s.seconds))));
                }
            }
            if merge {
                return Ok(None);
            }
            let t = Instant::now();
            let r = solve(c);
            let seconds = t.elapsed().as_secs_f64();
            if options.vtk.is_some() && has_vtk {
                vtk(dir, c, &r)?;
            }
            let stored = StoredCase { output: r, seconds };
            store.save(&id, &hash, &stored)?;
            (options.on_done)(&id, status(&stored.output));
            Ok(Some((stored.output, Some(seconds))))
        },
    );
    let mut out = Vec::with_capacity(outputs.len());
    let mut missing = vec![];
    for (c, (r, secs)) in own.iter().zip(outputs) {
        match r? {
            Some((r, stored_secs)) => out.push((r, stored_secs.unwrap_or(secs))),
            None => missing.push(key(c).0),
        }
    }
    if let (false, Some(dir)) = (missing.is_empty(), &options.study_dir) {
        return Err(StudyError::MissingCases {
            dir: dir.join("cases").display().to_string(),
            total: cases.len(),
            missing,
        });
    }
    if let (Distribution::Shard { k, n }, Some(dir)) = (distribution, &options.study_dir) {
        return Err(StudyError::ShardDone {
            k,
            n,
            solved: out.len(),
            total: cases.len(),
            dir: dir.join("cases").display().to_string(),
        });
    }
    Ok((out, resumed.into_inner()))
}

/// Residual histories of converged load steps.
pub fn step_records(steps: &[StepReport]) -> Vec<StepRecord> {
    steps
        .iter()
        .map(|s| StepRecord {
            step: s.step,
            load_factor: s.load_factor,
            residuals: s.newton.residuals.clone(),
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

pub fn status_word(s: CaseStatus) -> &'static str {
    match s {
        CaseStatus::Converged => "converged",
        CaseStatus::Failed => "failed",
        CaseStatus::Rejected => "rejected",
    }
}

/// The identifier rule of every study file ([`super::ident_ok`]).
pub use super::ident_ok;

/// Checks the keys every plane-strain study file starts with.
pub fn check_header(
    file: &str,
    schema: i64,
    problem: &str,
    expected_problem: &str,
    name: &str,
    report_file: &str,
) -> Result<(), StudyError> {
    if schema != super::SCHEMA_VERSION {
        return Err(invalid(
            file,
            "schema",
            schema,
            format!("must be {}", super::SCHEMA_VERSION),
        ));
    }
    if problem != expected_problem {
        return Err(invalid(
            file,
            "problem",
            problem,
            format!("must be {expected_problem:?}"),
        ));
    }
    if !ident_ok(name) {
        return Err(invalid(
            file,
            "name",
            name,
            format!("must be {}", super::IDENT_RULE),
        ));
    }
    if !(report_file.ends_with(".md") && ident_ok(report_file.trim_end_matches(".md"))) {
        return Err(invalid(
            file,
            "report_file",
            report_file,
            format!("must be a file name <identifier>.md ({})", super::IDENT_RULE),
        ));
    }
    Ok(())
}

/// A plane-strain study file: parsed strictly, then validated.
pub trait PlaneStudy: DeserializeOwned {
    /// Check every value; errors name the file, the key and its allowed range.
    fn validate(&self, file: &str) -> Result<(), StudyError>;

    /// Parse and validate a study file's text; `file` names it in errors.
    fn parse(text: &str, file: &str) -> Result<Self, StudyError> {
        let spec: Self = parse_toml(text, file)?;
        spec.validate(file)?;
        Ok(spec)
    }

    /// Read, parse and validate a study file.
    fn load(path: &Path) -> Result<Self, StudyError> {
        let text = std::fs::read_to_string(path).map_err(|e| StudyError::io(path, e))?;
        Self::parse(&text, &path.display().to_string())
    }
}

/// Write `<out>/<name>/results.json` (pretty) and `domains.json` (compact); returns the folder.
pub fn write_outputs<R: Serialize, D: Serialize>(
    out: &Path,
    name: &str,
    results: &R,
    domains: &D,
) -> Result<PathBuf, StudyError> {
    let dir = out.join(name);
    std::fs::create_dir_all(&dir).map_err(|e| StudyError::io(&dir, e))?;
    write_json(&dir.join("domains.json"), domains, false)?;
    write_json(&dir.join("results.json"), results, true)?;
    Ok(dir)
}

/// A value outside its allowed range in a study file.
pub fn invalid(
    file: &str,
    key: impl Into<String>,
    value: impl ToString,
    allowed: impl Into<String>,
) -> StudyError {
    StudyError::Invalid {
        file: file.to_string(),
        key: key.into(),
        value: value.to_string(),
        allowed: allowed.into(),
    }
}

/// Parse a study file's TOML into `T` (unknown keys are errors through `deny_unknown_fields`).
pub fn parse_toml<T: DeserializeOwned>(text: &str, file: &str) -> Result<T, StudyError> {
    toml::from_str(text).map_err(|e| StudyError::Parse {
        file: file.to_string(),
        message: e.to_string().trim_end().to_string(),
    })
}

/// The `problem` key of a study file, if it has one.
pub fn problem_of_study(text: &str) -> Option<String> {
    let v: toml::Value = toml::from_str(text).ok()?;
    v.get("problem")?.as_str().map(str::to_string)
}

/// The `study.problem` recorded in `<dir>/results.json`, if readable.
pub fn problem_of_results(dir: &Path) -> Option<String> {
    let text = std::fs::read_to_string(dir.join("results.json")).ok()?;
    let v: serde_json::Value = serde_json::from_str(&text).ok()?;
    v.get("study")?.get("problem")?.as_str().map(str::to_string)
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

pub fn read_json<T: DeserializeOwned>(path: &Path) -> Result<T, StudyError> {
    let text = std::fs::read_to_string(path).map_err(|e| StudyError::io(path, e))?;
    serde_json::from_str(&text).map_err(|e| StudyError::Parse {
        file: path.display().to_string(),
        message: e.to_string(),
    })
}

pub fn write_text(path: &Path, text: &str, written: &mut Vec<PathBuf>) -> Result<(), StudyError> {
    super::store::write_file(path, text.as_bytes())?;
    written.push(path.to_path_buf());
    Ok(())
}

/// (passed, failed, not evaluated).
pub fn check_counts(checks: &[CheckRecord]) -> (usize, usize, usize) {
    let mut n = (0, 0, 0);
    for c in checks {
        match c.pass {
            Some(true) => n.0 += 1,
            Some(false) => n.1 += 1,
            None => n.2 += 1,
        }
    }
    n
}

/// A check whose measured value must not exceed `limit`; not evaluated without a value.
pub fn check_at_most(
    id: &str,
    description: String,
    measured: Option<f64>,
    limit: f64,
    source: &str,
) -> CheckRecord {
    CheckRecord {
        id: id.to_string(),
        description,
        measured,
        limit,
        pass: measured.map(|m| m <= limit),
        source: source.to_string(),
    }
}

pub fn checks_markdown(checks: &[CheckRecord]) -> String {
    let mut s = String::from(
        "## Checks\n\n| check | what | measured | limit | result | source |\n|---|---|---:|---:|---|---|\n",
    );
    for c in checks {
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} | {} | {} |",
            c.id,
            c.description.replace('|', "\\|"),
            c.measured.map_or("—".into(), |v| format!("{v:.4e}")),
            c.limit,
            match c.pass {
                Some(true) => "pass",
                Some(false) => "FAIL",
                None => "not evaluated",
            },
            c.source.replace('|', "\\|")
        );
    }
    s.push('\n');
    s
}

/// Table of the cases that did not converge: id, status, step, reason and the last residuals.
pub fn failures_markdown<'a>(
    cases: impl Iterator<Item = (&'a str, CaseStatus, Option<&'a FailureRecord>)>,
) -> String {
    let mut rows = String::new();
    for (id, status, f) in cases.filter(|c| c.1 != CaseStatus::Converged) {
        let tail: Vec<String> = f
            .map(|f| {
                f.residuals
                    .iter()
                    .rev()
                    .take(3)
                    .rev()
                    .map(|r| format!("{r:.2e}"))
                    .collect()
            })
            .unwrap_or_default();
        let _ = writeln!(
            rows,
            "| {id} | {} | {} | {} | {} |",
            status_word(status),
            f.map_or(0, |f| f.step),
            f.map_or(String::new(), |f| f.reason.replace('|', "/")),
            if tail.is_empty() {
                "—".to_string()
            } else {
                tail.join(", ")
            }
        );
    }
    if rows.is_empty() {
        return String::new();
    }
    format!(
        "## Cases that did not converge\n\n| case | status | step | reason | last residuals |\n|---|---|---:|---|---|\n{rows}\n"
    )
}

/// What a plane-strain study contributes to `reports/index.md`.
pub struct IndexEntry {
    pub name: String,
    pub summary: String,
    pub tier: Tier,
    pub checks: Vec<CheckRecord>,
    /// (link text, file name) of the tables and figures.
    pub files: Vec<(String, String)>,
}

impl IndexEntry {
    pub fn markdown(&self) -> String {
        let (pass, fail, none) = check_counts(&self.checks);
        let mut s = format!(
            "## {}\n\n{}\n\nTier: {}; checks: {pass} passed, {fail} failed, {none} not evaluated.\n\n",
            self.name,
            self.summary,
            tier_name(self.tier)
        );
        for (text, file) in &self.files {
            let _ = writeln!(s, "- [{text}]({}/{file})", self.name);
        }
        let _ = writeln!(
            s,
            "- [results.json]({0}/results.json) and the drawn domains in `{0}/domains.json`\n",
            self.name
        );
        s
    }
}

/// Outcome of running one plane-strain study file (for the binary's summary line).
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
