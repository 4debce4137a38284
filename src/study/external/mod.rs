//! Other codes beside igimp: the case protocol (`studies/PROTOCOL.md`). A study names an
//! external method `ext:<adapter>[@<method>]`; for each of its cases the harness writes
//! `case.json` (the scene at the case's resolution: the same grid, points, supports and
//! loads igimp solves), runs the adapter's command, reads `result.json` strictly and measures
//! the returned point fields with igimp's own measure code. Whatever goes wrong is that
//! case's recorded failure, never the study's.

pub mod adapter;
pub mod igimp_case;
mod method;
pub mod protocol;

pub use method::{ExternalMethod, StudyMethod};

use crate::problems::scene::{
    measures_of_fields, DiscreteScene, LoadKind, MeasureValue, Scene, SceneSettings,
};
use crate::study::results::{CaseStatus, FailureRecord, SolveRecord, StepRecord};
use adapter::Adapter;
use protocol::{CaseFile, NewtonCase, Outputs, ResultFile, RunStatus};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::Path;

/// What an external case records besides its solve: the code, its own timing and the
/// process's.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct ExternalRecord {
    /// The code's name and version, from its result (empty if it wrote none).
    pub code: String,
    /// The solve's wall seconds as the code measured them.
    pub seconds: Option<f64>,
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub phases: BTreeMap<String, f64>,
    /// The code's own residual norm, where it is not the case's.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub residual_norm: Option<String>,
    /// The adapter process's wall seconds (start-up and import included).
    pub process_seconds: Option<f64>,
    /// Where the case's files are, under the study's folder.
    pub files: String,
}

/// An external case's outcome.
#[derive(Debug, Clone)]
pub struct ExternalSolve {
    pub solve: SolveRecord,
    pub measures: Vec<MeasureValue>,
    /// Final positions of the points (converged steps only).
    pub positions: Vec<Vec<f64>>,
    pub record: ExternalRecord,
    pub points: usize,
}

/// The words of a residual norm, for codes that apply it themselves.
fn norm_definition(n: crate::solver::newton::ResidualNorm) -> &'static str {
    use crate::solver::newton::ResidualNorm::*;
    match n {
        External => "‖f_int − f_ext‖ / ‖f_ext‖ over the free dofs (f_ext: gravity and point loads at the step's load factor)",
        Total => "‖f_int − f_ext‖ over the free dofs / ‖f_ext + f_reaction‖ over all dofs",
        Linearised => "as `total`, with the reactions updated by their linearised increment (igimp reference/README.md item 18)",
    }
}

/// Why `adapter` cannot solve `scene`, if it cannot.
fn unsupported(adapter: &Adapter, scene: &Scene, discrete: &DiscreteScene, basis: &str) -> Option<String> {
    let s = &adapter.manifest.supports;
    let name = &adapter.manifest.name;
    if !s.dimensions.contains(&scene.dimension) {
        return Some(format!(
            "{name} supports dimensions {:?}, not {}",
            s.dimensions, scene.dimension
        ));
    }
    let model = discrete.material.model();
    if !s.models.iter().any(|m| m == model) {
        return Some(format!(
            "{name} supports the models {:?}, not {model:?}",
            s.models
        ));
    }
    for l in &scene.loads {
        let kind = match l.kind {
            LoadKind::Gravity => "gravity",
            LoadKind::Displacement => "displacement",
            LoadKind::Traction => "traction",
        };
        if !s.loads.iter().any(|k| k == kind) {
            return Some(format!("{name} supports the loads {:?}, not {kind}", s.loads));
        }
    }
    if !s.bases.iter().any(|b| b == basis) {
        return Some(format!("{name} supports the bases {:?}, not {basis}", s.bases));
    }
    None
}

/// A case that ended before any result: its record `solve`, nothing measured.
fn unsolved(solve: SolveRecord, record: ExternalRecord) -> ExternalSolve {
    ExternalSolve {
        solve,
        measures: vec![],
        positions: vec![],
        record,
        points: 0,
    }
}

/// A case that failed before any step (the adapter, its set-up or its files), with `reason`.
fn failed(reason: String, record: ExternalRecord) -> ExternalSolve {
    let mut solve = SolveRecord::rejected(reason);
    solve.status = CaseStatus::Failed;
    unsolved(solve, record)
}

/// Solve case `id` of `scene` by the external `method` with `settings`, its files in
/// `folder` (created).
pub fn solve(
    scene: &Scene,
    settings: &SceneSettings,
    method: &ExternalMethod,
    id: &str,
    folder: &Path,
    shown: &str,
) -> ExternalSolve {
    let mut record = ExternalRecord {
        files: shown.to_string(),
        ..Default::default()
    };
    let adapter = match Adapter::find(&method.adapter) {
        Ok(a) => a,
        Err(e) => return failed(e, record),
    };
    let discrete = match DiscreteScene::of(scene, settings) {
        Ok(d) => d,
        Err(e) => {
            return unsolved(SolveRecord::rejected(e), record);
        }
    };
    let basis = method
        .basis
        .map(|b| b.name().to_string())
        .or_else(|| adapter.manifest.supports.bases.first().cloned())
        .unwrap_or_default();
    if let Some(why) = unsupported(&adapter, scene, &discrete, &basis) {
        return unsolved(SolveRecord::rejected(format!("unsupported: {why}")), record);
    }
    let Some(basis_method) = crate::basis::method::Method::from_name(&basis) else {
        return failed(
            format!("the adapter's basis {basis:?} is not a method igimp names"),
            record,
        );
    };
    let case = CaseFile {
        protocol: protocol::CASE_PROTOCOL.into(),
        version: protocol::VERSION,
        id: id.to_string(),
        method: StudyMethod::External(method.clone()).name(),
        basis: basis_method,
        load_steps: settings.load_steps,
        newton: NewtonCase {
            tolerance: settings.newton.tolerance,
            max_iterations: settings.newton.max_iterations,
            norm: settings.newton.residual_norm,
            norm_definition: norm_definition(settings.newton.residual_norm).into(),
        },
        outputs: Outputs {
            every_step: scene.measures.iter().any(|m| m.history),
            reactions: discrete.regions.iter().map(|r| r.name.clone()).collect(),
        },
        igimp: *settings,
        scene: discrete,
    };
    let (case_path, result_path, log) = (
        folder.join("case.json"),
        folder.join("result.json"),
        folder.join("adapter.log"),
    );
    let written = std::fs::create_dir_all(folder)
        .and_then(|_| {
            let _ = std::fs::remove_file(&result_path);
            std::fs::write(&case_path, serde_json::to_vec(&case).unwrap_or_default())
        })
        .map_err(|e| format!("{}: {e}", case_path.display()));
    if let Err(e) = written {
        return failed(e, record);
    }
    if let Err(e) = adapter.set_up() {
        return failed(e, record);
    }
    match adapter.run_case(&case_path, &result_path, &log) {
        Ok(s) => record.process_seconds = Some(s),
        Err(e) => return failed(format!("adapter {}: {e}", adapter.manifest.name), record),
    }
    let text = match std::fs::read_to_string(&result_path) {
        Ok(t) => t,
        Err(e) => {
            return failed(
                format!(
                    "adapter {} wrote no result.json ({e}); its output ends:\n{}",
                    adapter.manifest.name,
                    adapter::tail(&log, 20)
                ),
                record,
            )
        }
    };
    let result = match ResultFile::parse(&text, &case) {
        Ok(r) => r,
        Err(e) => return failed(format!("adapter {}: {e}", adapter.manifest.name), record),
    };
    record.code = format!("{} {}", result.code.name, result.code.version);
    record.seconds = Some(result.timing.seconds);
    record.phases = result.timing.phases.clone();
    record.residual_norm = result.residual_norm.clone();
    measure(scene, &case, result, record)
}

/// The record of a valid `result` of `case`.
fn measure(scene: &Scene, case: &CaseFile, result: ResultFile, record: ExternalRecord) -> ExternalSolve {
    let steps: Vec<StepRecord> = result
        .steps
        .iter()
        .map(|s| StepRecord::residuals_only(s.step, s.load_factor, s.residuals.clone()))
        .collect();
    let status = match result.status {
        RunStatus::Converged => CaseStatus::Converged,
        RunStatus::Failed => CaseStatus::Failed,
        RunStatus::Unsupported => CaseStatus::Rejected,
    };
    let failure = result.failure.as_ref().map(|f| FailureRecord {
        step: f.step,
        reason: match result.status {
            RunStatus::Unsupported => format!("unsupported by {}: {}", result.code.name, f.reason),
            _ => f.reason.clone(),
        },
        residuals: f.residuals.clone(),
    });
    let solve = SolveRecord {
        status,
        failure,
        newton_iterations: result.steps.iter().map(|s| s.iterations).sum(),
        steps,
    };
    // The fields after each converged step with its reactions (only the last when the case
    // asked for no history).
    let mut per_step = vec![];
    let reactions = |k: usize| result.reactions.get(k).cloned().unwrap_or_default();
    if !result.step_fields.is_empty() {
        for (k, f) in result.step_fields.iter().enumerate() {
            per_step.push((f.clone(), reactions(k)));
        }
    } else if let Some(f) = &result.fields {
        per_step.push((f.clone(), reactions(result.steps.len().saturating_sub(1))));
    }
    let measures = if per_step.is_empty() {
        vec![]
    } else {
        measures_of_fields(scene, &case.scene, &per_step)
    };
    ExternalSolve {
        solve,
        measures,
        positions: result.fields.map(|f| f.position).unwrap_or_default(),
        record,
        points: case.scene.points.position.len(),
    }
}
