//! igimp's own adapter (`examples/adapters/igimp/`, `study --solve-case`): a case file
//! solved from its data alone (the grid, points, regions and loads it carries, through
//! [`crate::problems::scene::DiscreteScene::solver`]) and the result file written. Its results equal the in-process
//! run's, which shows that the protocol carries everything a solve needs.

use super::protocol::{CaseFile, Code, ResultFile, ResultStep, RunFailure, RunStatus, RunTiming};
use crate::mpm::MpmSolver;
use crate::problems::scene::{region_reactions, PointFields};
use crate::solver::load_stepping::{steps_and_failure, LoadStepping};
use std::path::Path;
use std::time::Instant;

/// Read `case`, solve it and write `result`. An error is a file that cannot be read or
/// written; a case that cannot be solved is a result with its status.
pub fn solve_case_file(case: &Path, result: &Path) -> Result<(), String> {
    let text = std::fs::read_to_string(case).map_err(|e| format!("{}: {e}", case.display()))?;
    let case: CaseFile = serde_json::from_str(&text).map_err(|e| format!("{}: {e}", case.display()))?;
    let out = solve(&case);
    let bytes = serde_json::to_vec(&out).map_err(|e| e.to_string())?;
    std::fs::write(result, bytes).map_err(|e| format!("{}: {e}", result.display()))
}

fn code() -> Code {
    Code {
        name: "igimp".into(),
        version: format!(
            "{} ({})",
            env!("CARGO_PKG_VERSION"),
            crate::study::results::Software::this_build().label()
        ),
    }
}

/// The result of `case`.
pub fn solve(case: &CaseFile) -> ResultFile {
    let t = Instant::now();
    let stopped = |status: RunStatus, reason: String| ResultFile {
        protocol: super::protocol::RESULT_PROTOCOL.into(),
        version: super::protocol::VERSION,
        code: code(),
        status,
        failure: Some(RunFailure {
            step: 0,
            reason,
            residuals: vec![],
        }),
        residual_norm: None,
        steps: vec![],
        fields: None,
        step_fields: vec![],
        reactions: vec![],
        timing: RunTiming::default(),
    };
    let Some(basis) = case.basis.basis() else {
        return stopped(
            RunStatus::Unsupported,
            format!(
                "igimp's adapter solves material point bases, not {}",
                case.basis.name()
            ),
        );
    };
    let mut settings = case.igimp;
    settings.load_steps = case.load_steps;
    let run = match case.scene.dimension {
        2 => case.scene.solver::<2>(basis, &settings).map(|s| run(s, case)),
        3 => case.scene.solver::<3>(basis, &settings).map(|s| run(s, case)),
        d => return stopped(RunStatus::Unsupported, format!("dimension {d}")),
    };
    match run {
        Err(e) => stopped(RunStatus::Failed, format!("the case was refused: {e}")),
        Ok(mut r) => {
            r.timing.seconds = t.elapsed().as_secs_f64();
            r
        }
    }
}

fn run<const D: usize>(mut solver: MpmSolver<D>, case: &CaseFile) -> ResultFile {
    let mut step_fields = vec![];
    let mut step_reactions = vec![];
    let every = case.outputs.every_step;
    let outcome = solver.run_observed(&mut |s, _| {
        if every {
            step_fields.push(PointFields::of_points(&s.points));
        }
        step_reactions.push(region_reactions(&case.scene, s));
    });
    let (steps, failure) = steps_and_failure(outcome);
    let fields = (!steps.is_empty()).then(|| PointFields::of_points(&solver.points));
    ResultFile {
        protocol: super::protocol::RESULT_PROTOCOL.into(),
        version: super::protocol::VERSION,
        code: code(),
        status: if failure.is_some() {
            RunStatus::Failed
        } else {
            RunStatus::Converged
        },
        failure: failure.map(|e| RunFailure {
            step: e.step,
            reason: e.failure.to_string(),
            residuals: e.residuals,
        }),
        residual_norm: None,
        steps: steps
            .iter()
            .map(|s| ResultStep {
                step: s.step,
                load_factor: s.load_factor,
                iterations: s.newton.iterations(),
                residuals: s.newton.residuals.clone(),
                seconds: None,
            })
            .collect(),
        fields,
        step_fields,
        reactions: step_reactions,
        timing: RunTiming::default(),
    }
}
