//! Runs the cases of a study in parallel and writes `results.json` and the point CSVs.
//!
//! Cases are independent, so rayon runs them across threads (largest first, to balance the
//! load) and the records are put back in the study's case order: the output does not depend
//! on the thread count. A Newton failure or a point leaving the grid is recorded in the case
//! (`status = "failed"`, with the failing step and its residual history) and the sweep goes
//! on; a case the solver rejects as input (e.g. a method not built yet) is `"rejected"`.
//!
//! Wall-clock times are the only fields that differ between two runs (`wall_seconds` of each
//! case and the `timing` block).

use super::rates::{compute_comparisons, compute_rates};
use super::results::{AnalyticalRecord, PROFILE_SAMPLES};
pub use super::results::{
    CaseRecord, CaseStatus, FailureRecord, Software, StepRecord, StudyResults, Timing, POINTS_HEADER,
    POINTS_HEADER_PLASTIC,
};
use super::store::{case_hash, write_file, CaseStore};
use super::vtk_output::{pvd_path, ColumnVtkWriter, VtkOptions};
use super::{Case, StudyError, StudySpec, Tier};
use crate::problems::column::{solve_column_observed, ColumnObserver, ColumnSpec, Method, PointRecord};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;
use std::time::Instant;

/// A solved study: the results and the final point values of each case (same order).
#[derive(Debug, Clone)]
pub struct StudyRun {
    pub results: StudyResults,
    pub points: Vec<Vec<PointRecord>>,
    /// Cases taken from the case store instead of being solved (`--resume`).
    pub resumed: usize,
}

fn finite(x: f64) -> Option<f64> {
    x.is_finite().then_some(x)
}

/// Solve one case.
pub fn run_case(case: &Case) -> (CaseRecord, Vec<PointRecord>) {
    run_case_observed(case, &mut |_, _| {})
}

/// [`run_case`], showing the solver to `observer` before the first and after every converged
/// load step.
pub fn run_case_observed(case: &Case, observer: &mut ColumnObserver<'_>) -> (CaseRecord, Vec<PointRecord>) {
    let start = Instant::now();
    let mut rec = CaseRecord {
        id: case.id.clone(),
        method: case.method,
        load: case.spec.weight,
        elements: case.spec.elements,
        points_per_cell: case.points_per_cell,
        load_steps: case.spec.load_steps,
        newton: case.spec.newton,
        status: CaseStatus::Rejected,
        failure: None,
        stress_error: None,
        f_error: None,
        sigma_xx_error: None,
        yield_height: None,
        yield_height_error: None,
        top_displacement: None,
        base_f: None,
        points: 0,
        newton_iterations: 0,
        steps: vec![],
        wall_seconds: 0.0,
    };
    let points = match solve_column_observed(&case.spec, case.method, observer) {
        Err(e) => {
            rec.failure = Some(FailureRecord {
                step: 0,
                reason: e.to_string(),
                residuals: vec![],
            });
            vec![]
        }
        Ok(out) => {
            rec.steps = out
                .steps
                .iter()
                .map(|s| StepRecord {
                    step: s.step,
                    load_factor: s.load_factor,
                    residuals: s.newton.residuals.clone(),
                })
                .collect();
            rec.newton_iterations = out.steps.iter().map(|s| s.newton.iterations()).sum();
            rec.points = out.points.len();
            match &out.failure {
                Some(f) => {
                    rec.status = CaseStatus::Failed;
                    rec.failure = Some(FailureRecord {
                        step: f.step,
                        reason: f.failure.to_string(),
                        residuals: f.residuals.clone(),
                    });
                }
                None => {
                    rec.status = CaseStatus::Converged;
                    rec.stress_error = finite(out.stress_error);
                    rec.f_error = finite(out.f_error);
                    if let Some(ry) = case.spec.yield_stress {
                        let _ = ry;
                        rec.sigma_xx_error = finite(out.sigma_xx_error);
                        rec.yield_height = out.yield_height;
                        let exact = case.spec.analytical().yield_height();
                        rec.yield_height_error = match (out.yield_height, exact) {
                            (Some(h), Some(e)) => finite((h - e).abs() / case.spec.length),
                            _ => None,
                        };
                    }
                    rec.top_displacement = finite(out.top_displacement);
                    rec.base_f = finite(out.base_f);
                }
            }
            out.points
        }
    };
    rec.wall_seconds = start.elapsed().as_secs_f64();
    (rec, points)
}

/// Solve every case of the tier. `on_case_done` is called (from worker threads) after each
/// case, e.g. to advance a progress bar. Nothing is written; see [`run_study_in`].
pub fn run_study(
    spec: &StudySpec,
    study_file: &str,
    tier: Tier,
    on_case_done: &(dyn Fn(&CaseRecord) + Sync),
) -> StudyRun {
    run_cases(
        spec,
        study_file,
        tier,
        &|c: &Case| Ok((run_case(c), false)),
        on_case_done,
    )
    .unwrap_or_else(|e: StudyError| unreachable!("in-memory run failed: {e}"))
}

/// Options of [`run_study_in`].
#[derive(Debug, Clone, PartialEq)]
pub struct RunOptions {
    /// Output folder; the study writes into `<out>/<name>/`.
    pub out: PathBuf,
    /// Reuse the stored record of a case whose inputs hash equally (see [`case_definition_hash`]).
    pub resume: bool,
    /// Write ParaView files of every case.
    pub vtk: Option<VtkOptions>,
    /// `--shard K/N` or `--merge`.
    pub distribution: super::Distribution,
}

/// What the case store keeps of a finished column case.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StoredCase {
    pub record: CaseRecord,
    pub points: Vec<PointRecord>,
}

/// The inputs that determine a case's results.
#[derive(Serialize)]
struct CaseDefinition<'a> {
    id: &'a str,
    method: Method,
    points_per_cell: Option<usize>,
    spec: &'a ColumnSpec,
}

/// Stable hash of a case's inputs (id, method, points per cell and the full [`ColumnSpec`]),
/// [`case_hash`] of their canonical JSON.
pub fn case_definition_hash(case: &Case) -> String {
    case_hash(&CaseDefinition {
        id: &case.id,
        method: case.method,
        points_per_cell: case.points_per_cell,
        spec: &case.spec,
    })
}

/// Solve every case of the tier, storing each finished case atomically in
/// `<out>/<name>/cases/` as soon as it is done; with `resume`, cases stored earlier with the
/// same input hash (and, with VTK output, whose `.pvd` exists) are read back instead of
/// solved. `write_outputs` then writes `results.json` and the point files.
pub fn run_study_in(
    spec: &StudySpec,
    study_file: &str,
    tier: Tier,
    options: &RunOptions,
    on_case_done: &(dyn Fn(&CaseRecord) + Sync),
) -> Result<StudyRun, StudyError> {
    use super::Distribution;
    let dir = study_dir(&options.out, &spec.name);
    let store = CaseStore::open(&dir.join("cases"))?;
    let resume = options.resume || options.distribution == Distribution::Merge;
    if options.distribution == Distribution::Merge {
        let missing: Vec<String> = spec
            .cases(tier)
            .iter()
            .filter(|c| {
                store
                    .load::<StoredCase>(&c.id, &case_definition_hash(c))
                    .is_none()
            })
            .map(|c| c.id.clone())
            .collect();
        if !missing.is_empty() {
            return Err(StudyError::MissingCases {
                dir: dir.join("cases").display().to_string(),
                total: spec.cases(tier).len(),
                missing,
            });
        }
    }
    let solve = |case: &Case| -> Result<((CaseRecord, Vec<PointRecord>), bool), StudyError> {
        let hash = case_definition_hash(case);
        let vtk_done = match options.vtk {
            Some(_) => pvd_path(&dir, &case.id)?.exists(),
            None => true,
        };
        if resume && vtk_done {
            if let Some(s) = store.load::<StoredCase>(&case.id, &hash) {
                return Ok(((s.record, s.points), true));
            }
        }
        let (record, points) = match options.vtk {
            None => run_case(case),
            Some(v) => {
                let mut w = ColumnVtkWriter::new(&dir, &case.id, case.spec.load_steps, v)?;
                let out = run_case_observed(case, &mut |step, state| w.observe(step, state));
                w.finish()?;
                out
            }
        };
        let stored = StoredCase { record, points };
        store.save(&case.id, &hash, &stored)?;
        Ok(((stored.record, stored.points), false))
    };
    if let Distribution::Shard { k, n } = options.distribution {
        let cases = spec.cases(tier);
        let own: Vec<&Case> = cases
            .iter()
            .enumerate()
            .filter(|(i, _)| options.distribution.owns(*i))
            .map(|(_, c)| c)
            .collect();
        own.par_iter()
            .try_for_each(|c| solve(c).map(|((rec, _), _)| on_case_done(&rec)))?;
        return Err(StudyError::ShardDone {
            k,
            n,
            solved: own.len(),
            total: cases.len(),
            dir: dir.join("cases").display().to_string(),
        });
    }
    run_cases(spec, study_file, tier, &solve, on_case_done)
}

type CaseOutput = ((CaseRecord, Vec<PointRecord>), bool);

/// Run `solve` over the cases in parallel (largest first) and put the records back in case
/// order; the first error (in case order) is returned.
fn run_cases(
    spec: &StudySpec,
    study_file: &str,
    tier: Tier,
    solve: &(dyn Fn(&Case) -> Result<CaseOutput, StudyError> + Sync),
    on_case_done: &(dyn Fn(&CaseRecord) + Sync),
) -> Result<StudyRun, StudyError> {
    let start = Instant::now();
    let cases = spec.cases(tier);
    // Largest cases first so that the last one to start is short.
    let mut order: Vec<usize> = (0..cases.len()).collect();
    let cost = |c: &Case| c.spec.elements * c.points_per_cell.unwrap_or(3) * c.spec.load_steps;
    order.sort_by_key(|&i| std::cmp::Reverse(cost(&cases[i])));
    let resumed = AtomicUsize::new(0);
    let first_error: Mutex<Option<(usize, StudyError)>> = Mutex::new(None);
    let mut solved: Vec<(usize, CaseRecord, Vec<PointRecord>)> = order
        .par_iter()
        .filter_map(|&i| match solve(&cases[i]) {
            Ok(((rec, pts), reused)) => {
                if reused {
                    resumed.fetch_add(1, Ordering::Relaxed);
                }
                on_case_done(&rec);
                Some((i, rec, pts))
            }
            Err(e) => {
                let mut slot = first_error.lock().unwrap_or_else(|p| p.into_inner());
                if slot.as_ref().is_none_or(|(j, _)| i < *j) {
                    *slot = Some((i, e));
                }
                None
            }
        })
        .collect();
    if let Some((_, e)) = first_error.into_inner().unwrap_or_else(|p| p.into_inner()) {
        return Err(e);
    }
    solved.sort_by_key(|s| s.0);
    let (records, points): (Vec<CaseRecord>, Vec<Vec<PointRecord>>) =
        solved.into_iter().map(|(_, r, p)| (r, p)).unzip();
    let index = spec.case_index(tier);
    let rates = compute_rates(spec, tier, &records, &index);
    let comparisons = compute_comparisons(spec, tier, &records, &index);
    let analytical = analytical_records(spec, &records);
    Ok(StudyRun {
        results: StudyResults {
            software: Software {
                name: env!("CARGO_PKG_NAME").to_string(),
                version: env!("CARGO_PKG_VERSION").to_string(),
            },
            study_file: study_file.to_string(),
            tier,
            study: spec.clone(),
            sweep_cases: index,
            cases: records,
            rates,
            comparisons,
            analytical,
            timing: Timing {
                wall_seconds: start.elapsed().as_secs_f64(),
                threads: rayon::current_num_threads(),
            },
        },
        points,
        resumed: resumed.into_inner(),
    })
}

/// The analytical column at every load of the cases, paper tables and figures.
fn analytical_records(spec: &StudySpec, cases: &[CaseRecord]) -> Vec<AnalyticalRecord> {
    let mut loads: Vec<f64> = cases
        .iter()
        .map(|c| c.load)
        .chain(spec.paper.iter().map(|p| p.weight))
        .chain(spec.figures.iter().map(|f| f.weight))
        .collect();
    loads.sort_by(f64::total_cmp);
    loads.dedup();
    let c = &spec.column;
    loads
        .into_iter()
        .map(|load| {
            let column = ColumnSpec {
                length: c.length,
                young_modulus: c.young_modulus,
                poisson_ratio: c.poisson_ratio,
                density: c.density,
                yield_stress: c.yield_stress,
                weight: load,
                ..ColumnSpec::default()
            };
            let exact = column.analytical();
            let profile = (0..=PROFILE_SAMPLES)
                .map(|i| {
                    let z0 = c.length * i as f64 / PROFILE_SAMPLES as f64;
                    [
                        z0,
                        z0 + exact.displacement(z0),
                        exact.stress(z0),
                        exact.lateral_stress(z0),
                    ]
                })
                .collect();
            AnalyticalRecord {
                load,
                top_displacement: exact.displacement(c.length),
                base_f: exact.deformation_gradient(0.0),
                yield_height: exact.yield_height(),
                paper_yield_height: c
                    .yield_stress
                    .map(|ry| column.length - ry / (column.density * column.gravity())),
                profile,
            }
        })
        .collect()
}

/// Folder of a study's outputs: `<out>/<name>`.
pub fn study_dir(out: &Path, name: &str) -> PathBuf {
    out.join(name)
}

/// Points file of a case, relative to the study folder.
pub fn points_file(case_id: &str) -> String {
    format!("points/{case_id}.csv")
}

/// One row per point, shortest round-trip formatting (so the file re-reads exactly).
pub fn points_csv(points: &[PointRecord], plastic: bool) -> String {
    let mut s = String::with_capacity(80 * (points.len() + 1));
    s.push_str(if plastic {
        POINTS_HEADER_PLASTIC
    } else {
        POINTS_HEADER
    });
    s.push('\n');
    for p in points {
        s.push_str(&format!(
            "{},{},{},{},{}",
            p.z0, p.z, p.volume0, p.sigma_zz, p.f_zz
        ));
        if plastic {
            s.push_str(&format!(",{}", p.sigma_xx));
        }
        s.push('\n');
    }
    s
}

/// Parse a points file written by [`points_csv`]: rows of (z0, z, volume0, sigma_zz, f_zz)
/// and, in plastic studies, sigma_xx.
pub fn read_points_csv(path: &Path) -> Result<Vec<Vec<f64>>, StudyError> {
    let text = std::fs::read_to_string(path).map_err(|e| StudyError::io(path, e))?;
    let mut lines = text.lines();
    let width = match lines.next() {
        Some(POINTS_HEADER) => 5,
        Some(POINTS_HEADER_PLASTIC) => 6,
        _ => {
            return Err(StudyError::io(
                path,
                format!("header must be `{POINTS_HEADER}` or `{POINTS_HEADER_PLASTIC}`"),
            ))
        }
    };
    lines
        .enumerate()
        .map(|(i, l)| {
            let v: Vec<f64> = l.split(',').filter_map(|x| x.parse().ok()).collect();
            if v.len() == width {
                Ok(v)
            } else {
                Err(StudyError::io(
                    path,
                    format!("line {}: expected {width} numbers", i + 2),
                ))
            }
        })
        .collect()
}

/// Write `results.json` and `points/*.csv` atomically (stale point files of earlier runs are
/// removed).
pub fn write_outputs(out: &Path, run: &StudyRun) -> Result<PathBuf, StudyError> {
    let dir = study_dir(out, &run.results.study.name);
    let pdir = dir.join("points");
    std::fs::create_dir_all(&pdir).map_err(|e| StudyError::io(&pdir, e))?;
    for entry in std::fs::read_dir(&pdir).map_err(|e| StudyError::io(&pdir, e))? {
        let p = entry.map_err(|e| StudyError::io(&pdir, e))?.path();
        if p.extension().is_some_and(|x| x == "csv") {
            std::fs::remove_file(&p).map_err(|e| StudyError::io(&p, e))?;
        }
    }
    for (case, pts) in run.results.cases.iter().zip(&run.points) {
        if case.status == CaseStatus::Rejected {
            continue;
        }
        let p = super::store::confined(&pdir, &format!("{}.csv", case.id))?;
        let plastic = run.results.study.column.yield_stress.is_some();
        write_file(&p, points_csv(pts, plastic).as_bytes())?;
    }
    let json = serde_json::to_string_pretty(&run.results).map_err(|e| StudyError::io(&dir, e))?;
    write_file(&dir.join("results.json"), (json + "\n").as_bytes())?;
    Ok(dir)
}

/// Read a study's `results.json`.
pub fn read_results(study_dir: &Path) -> Result<StudyResults, StudyError> {
    let p = study_dir.join("results.json");
    let text = std::fs::read_to_string(&p).map_err(|e| StudyError::io(&p, e))?;
    serde_json::from_str(&text).map_err(|e| StudyError::Parse {
        file: p.display().to_string(),
        message: e.to_string(),
    })
}
