//! The dynamics study kind's solving and measuring: one case is one dynamic problem (the
//! vibrating bar, [`crate::problems::bar::solve`], or a dynamic manufactured field,
//! [`crate::problems::manufactured_dynamic::solve`]) solved by one method with one mass
//! matrix, grid and time step; its record carries the errors at the end (and the bar's period
//! and energy drift), and the bar's free-end displacement history of the cases a history
//! figure draws goes to `histories.json`.

use super::records::{DynamicMeasures, DynamicRecord, DynamicResults, ExpectedBand, RateRecord, Series};
use super::{BarCase, BarReferenceRun, CantileverCase, CaseSpec, ReferenceRun};
use super::{DynamicCase, DynamicMeasure, DynamicStudy, FigureKind, Refinement};
use crate::problems::bar::{self, BarSpec};
use crate::problems::cantilever_dynamic::{self, DynamicCantileverOutcome};
use crate::problems::manufactured_dynamic::{self, DynamicManufacturedSpec};
use crate::solver::load_stepping::StepReport;
use crate::study::checks::{check_at_most, check_rate, CheckRecord};
use crate::study::engine::{study_file_fields, CaseKey, Results, StudyKind, VtkTarget};
use crate::study::results::{write_case_data, SolveRecord, SweepIndex};
use crate::study::{StudyError, Tier};
use std::any::Any;
use std::collections::BTreeSet;
use std::collections::HashMap;
use std::path::Path;
use std::sync::{Arc, Mutex, OnceLock};

/// (t, u of the free end) after every step.
pub type History = Vec<[f64; 2]>;

fn solve_case(case: &DynamicCase) -> (DynamicRecord, History) {
    match &case.spec {
        CaseSpec::Bar(spec) => solve_bar(case, spec),
        CaseSpec::Manufactured(spec) => (solve_manufactured(case, spec), vec![]),
        CaseSpec::Cantilever(c) => solve_cantilever(case, c),
        CaseSpec::BarAgainst(c) => solve_bar_against(case, c),
    }
}

/// The value of `key`, computed once per process by the first caller (the others, on any
/// thread, wait for it): each reference analysis is solved once however many cases ask.
fn cached<T: Send + Sync + 'static>(key: String, solve: impl FnOnce() -> T) -> Arc<T> {
    type Slot = Arc<dyn Any + Send + Sync>;
    static CACHE: OnceLock<Mutex<HashMap<String, Slot>>> = OnceLock::new();
    let slot = CACHE
        .get_or_init(Default::default)
        .lock()
        .expect("reference cache")
        .entry(key)
        .or_insert_with(|| Arc::new(OnceLock::<Arc<T>>::new()))
        .clone();
    let cell = slot
        .downcast_ref::<OnceLock<Arc<T>>>()
        .expect("one value type per key (keys name their problem)");
    cell.get_or_init(|| Arc::new(solve())).clone()
}

/// A reference analysis' outcome, or why it has none (rejected, or failed at a step).
fn reference_result<O>(
    method: crate::basis::method::Method,
    solved: Result<O, crate::solver::error::InputError>,
    failure: impl Fn(&O) -> Option<(usize, String)>,
) -> Result<O, String> {
    let o = solved.map_err(|e| format!("reference {} rejected: {e}", method.name()))?;
    match failure(&o) {
        Some((step, why)) => Err(format!(
            "reference {} failed at step {step}: {why}",
            method.name()
        )),
        None => Ok(o),
    }
}

/// The cantilever reference of `run` (solved once per process).
fn cantilever_reference(run: &ReferenceRun) -> Arc<Result<DynamicCantileverOutcome, String>> {
    let key = format!(
        "cantilever:{}",
        serde_json::to_string(run).expect("a reference run serialises")
    );
    cached(key, || {
        reference_result(
            run.method,
            cantilever_dynamic::solve(&run.spec, run.method),
            |o| o.failure.as_ref().map(|f| (o.steps.len() + 1, f.to_string())),
        )
    })
}

/// The bar reference of `run` (solved once per process).
fn bar_reference(run: &BarReferenceRun) -> Arc<Result<bar::BarOutcome, String>> {
    let key = format!(
        "bar:{}",
        serde_json::to_string(run).expect("a reference run serialises")
    );
    cached(key, || {
        reference_result(run.method, bar::solve(&run.spec, run.method), |o| {
            o.failure.as_ref().map(|f| (o.steps.len() + 1, f.to_string()))
        })
    })
}

/// A bar measured against its reference: the end field and the period of the reference
/// instead of the closed form's; the energy is the case's own.
fn solve_bar_against(case: &DynamicCase, c: &BarCase) -> (DynamicRecord, History) {
    let o = match bar::solve(&c.spec, case.method) {
        Err(e) => return (base_record(case, SolveRecord::rejected(e), None, 0), vec![]),
        Ok(o) => o,
    };
    let (mut rec, history) = bar_record(case, &c.spec, &o);
    let reference = bar_reference(&c.reference);
    let against = Some(&o)
        .filter(|o| o.failure.is_none())
        .zip(reference.as_ref().as_ref().ok());
    rec.displacement_error = against
        .and_then(|(o, r)| o.displacement_error_against(&c.spec, r))
        .and_then(finite);
    rec.period_error = against
        .and_then(|(o, r)| o.measured_period.zip(r.measured_period))
        .map(|(t, tr)| (t - tr).abs() / tr);
    rec.reference_failure = reference.as_ref().as_ref().err().cloned();
    (rec, history)
}

fn solve_cantilever(case: &DynamicCase, c: &CantileverCase) -> (DynamicRecord, History) {
    let o = match cantilever_dynamic::solve(&c.spec, case.method) {
        Err(e) => return (base_record(case, SolveRecord::rejected(e), None, 0), vec![]),
        Ok(o) => o,
    };
    let solve = SolveRecord::of(&o.steps, o.failure.as_ref());
    let reference = cantilever_reference(&c.reference);
    let converged = Some(&o).filter(|o| o.failure.is_none());
    let against = converged.zip(reference.as_ref().as_ref().ok());
    let period = converged.and_then(|o| o.period());
    let rec = DynamicRecord {
        tip_error: against.and_then(|(o, r)| o.tip_error(r)).and_then(finite),
        peak_deflection: converged.map(|o| o.peak()),
        measured_period: period,
        period_error: against
            .and_then(|(_, r)| r.period())
            .zip(period)
            .map(|(tr, t)| (t - tr).abs() / tr),
        energy_drift: converged.and_then(|o| finite(o.energy_drift())),
        // A converged case that cannot be measured says why beside its status.
        reference_failure: reference.as_ref().as_ref().err().cloned(),
        ..base_record(case, solve, Some(&o.steps), o.points)
    };
    (rec, o.tip.iter().map(|&(t, v)| [t, v]).collect())
}

/// The record of a case from its solve (status, failure, the last step's history) and the
/// steps behind it, with what every problem records: the case's discretisation, the step
/// counts (time steps, most Newton iterations of a step, steps accepted at their floor, steps
/// cut back) and the point count; the problem fills in its measures.
fn base_record(
    case: &DynamicCase,
    mut solve: SolveRecord,
    steps: Option<&[StepReport]>,
    points: usize,
) -> DynamicRecord {
    let time_steps = solve.steps.len();
    let max_newton_iterations = steps
        .and_then(|s| s.iter().map(|s| s.newton.iterations()).max())
        .unwrap_or(0);
    let steps_at_floor = solve
        .steps
        .iter()
        .filter(|s| s.accepted_at_floor.is_some())
        .count();
    let steps_cut_back = steps.map_or(0, |s| s.iter().filter(|s| s.cutbacks() > 0).count());
    solve.steps.drain(..time_steps.saturating_sub(1));
    let l = case.spec.levels();
    DynamicRecord {
        id: case.id.clone(),
        method: case.method,
        field: l.field,
        mass: l.mass,
        elements: l.elements,
        points_per_cell: l.points_per_cell,
        steps_per_period: l.steps_per_period,
        solve,
        time_steps,
        max_newton_iterations,
        steps_at_floor,
        steps_cut_back,
        displacement_error: None,
        stress_error: None,
        measured_period: None,
        period_error: None,
        energy_drift: None,
        tip_error: None,
        peak_deflection: None,
        reference_failure: None,
        points,
    }
}

fn finite(x: f64) -> Option<f64> {
    x.is_finite().then_some(x)
}

fn solve_bar(case: &DynamicCase, spec: &BarSpec) -> (DynamicRecord, History) {
    match bar::solve(spec, case.method) {
        Err(e) => (base_record(case, SolveRecord::rejected(e), None, 0), vec![]),
        Ok(o) => bar_record(case, spec, &o),
    }
}

/// The record of a bar analysis against the closed form, and its free-end history.
fn bar_record(case: &DynamicCase, spec: &BarSpec, o: &bar::BarOutcome) -> (DynamicRecord, History) {
    let base = base_record(
        case,
        SolveRecord::of(&o.steps, o.failure.as_ref()),
        Some(&o.steps),
        o.points.len(),
    );
    let conv = Some(o).filter(|o| o.failure.is_none());
    let (exact, end) = (spec.period(), spec.duration());
    let rec = DynamicRecord {
        displacement_error: conv.and_then(|o| finite(o.displacement_error(spec, end))),
        measured_period: conv.and_then(|o| o.measured_period),
        period_error: conv
            .and_then(|o| o.measured_period)
            .map(|t| (t - exact).abs() / exact),
        energy_drift: conv.and_then(|o| finite(o.energy_drift())),
        ..base
    };
    (rec, o.top_history.iter().map(|&(t, u)| [t, u]).collect())
}

fn solve_manufactured(case: &DynamicCase, spec: &DynamicManufacturedSpec) -> DynamicRecord {
    // (steps, failure, errors, points) of the plane or the 3D solve.
    let solved = if spec.dimension == 3 {
        manufactured_dynamic::solve_3d(spec, case.method)
            .map(|o| (o.steps, o.failure, o.errors, o.points.len()))
    } else {
        manufactured_dynamic::solve(spec, case.method).map(|o| (o.steps, o.failure, o.errors, o.points.len()))
    };
    let (steps, failure, errors, points) = match solved {
        Err(e) => return base_record(case, SolveRecord::rejected(e), None, 0),
        Ok(o) => o,
    };
    DynamicRecord {
        displacement_error: errors.and_then(|e| finite(e.displacement)),
        stress_error: errors.and_then(|e| finite(e.stress)),
        ..base_record(
            case,
            SolveRecord::of(&steps, failure.as_ref()),
            Some(&steps),
            points,
        )
    }
}

impl StudyKind for DynamicStudy {
    const PROBLEM: &'static str = "dynamics";
    type Case = DynamicCase;
    type Output = (DynamicRecord, History);
    type Record = DynamicRecord;
    type Measures = DynamicMeasures;

    study_file_fields!();
    fn cases(&self, tier: Tier) -> (Vec<DynamicCase>, SweepIndex) {
        self.cases(tier)
    }
    fn key(&self, c: &DynamicCase) -> CaseKey {
        CaseKey {
            has_vtk: false,
            ..CaseKey::of_spec(&c.id, c.method, &c.spec, 0)
        }
    }
    fn cost(&self, c: &DynamicCase) -> f64 {
        c.spec.cost()
    }
    fn solve(&self, c: &DynamicCase, _vtk: Option<&VtkTarget>) -> Result<Self::Output, StudyError> {
        Ok(solve_case(c))
    }
    fn record(o: &Self::Output) -> &DynamicRecord {
        &o.0
    }
    fn measure(results: &mut Results<Self>) {
        let study = &results.study;
        results.measures.exact_period = match &study.cantilever {
            Some(c) => DynamicStudy::cantilever_spec(
                c,
                study.material.material(),
                &study.newton,
                Default::default(),
                2,
                1,
                1,
            )
            .period(),
            None => study
                .sweeps
                .iter()
                .find_map(|s| study.case_spec(s, Default::default(), 1, 1, 1))
                .map_or(f64::NAN, |c| c.period()),
        };
        results.measures.rates = rates(results);
        results.checks = checks(results);
    }
    /// `histories.json`: the free end's history of the cases a history figure draws.
    fn write_side_files(&self, dir: &Path, outputs: &[Self::Output]) -> Result<(), StudyError> {
        let drawn = self.drawn_cases(outputs.iter().map(|o| &o.0));
        write_case_data(&dir.join("histories.json"), outputs, |r, _| drawn.contains(&r.id))
    }
}

impl DynamicStudy {
    /// The finest case of every series of each sweep a history figure draws.
    fn drawn_cases<'a>(&self, records: impl Iterator<Item = &'a DynamicRecord> + Clone) -> BTreeSet<String> {
        let mut out = BTreeSet::new();
        for f in self.figures.iter().filter(|f| f.kind == FigureKind::History) {
            let Some(sw) = self.sweep(&f.sweep) else { continue };
            let in_sweep = |r: &&DynamicRecord| {
                sw.methods.contains(&r.method)
                    && sw.mass.contains(&r.mass)
                    && sw.points_per_cell.contains(&(r.points_per_cell as i64))
                    && sw.elements.contains(&(r.elements as i64))
            };
            let series: BTreeSet<Series> = records.clone().filter(in_sweep).map(|r| r.series()).collect();
            out.extend(
                series
                    .iter()
                    .filter_map(|s| finest(records.clone().filter(in_sweep).filter(|r| r.series() == *s)))
                    .map(|r| r.id.clone()),
            );
        }
        out
    }
}

/// The finest of `cases`: most elements, then most time steps.
fn finest<'a>(cases: impl Iterator<Item = &'a DynamicRecord>) -> Option<&'a DynamicRecord> {
    cases.max_by_key(|c| (c.elements, c.steps_per_period))
}

/// The refined variable's step of a case: h = L / elements or Δt = T / steps per period (in
/// units of L and T: only ratios enter a slope).
fn level_size(r: &DynamicRecord, refinement: Refinement) -> (usize, f64) {
    let n = match refinement {
        Refinement::Space => r.elements,
        Refinement::Time => r.steps_per_period,
    };
    (n, 1.0 / n as f64)
}

fn rates(results: &DynamicResults) -> Vec<RateRecord> {
    let study = &results.study;
    let mut out = vec![];
    for sw in &study.sweeps {
        let refinement = sw.refinement();
        for s in results.sweep_series(&sw.id) {
            let measures = if study.bar.is_some() {
                [DynamicMeasure::Displacement, DynamicMeasure::Period]
            } else if study.cantilever.is_some() {
                [DynamicMeasure::Tip, DynamicMeasure::Period]
            } else {
                [DynamicMeasure::Displacement, DynamicMeasure::Stress]
            };
            for measure in measures {
                let pts: Vec<(usize, f64, f64)> = results
                    .series_cases(&sw.id, &s)
                    .into_iter()
                    .filter_map(|c| {
                        let (n, h) = level_size(c, refinement);
                        Some((n, h, c.measure(measure)?))
                    })
                    .collect();
                let h: Vec<f64> = pts.iter().map(|p| p.1).collect();
                let e: Vec<f64> = pts.iter().map(|p| p.2).collect();
                let slope = crate::problems::norms::fitted_rate(&h, &e);
                let expected = study
                    .expect_rate
                    .iter()
                    .find(|x| {
                        x.tier.is_none_or(|t| t == results.provenance.tier)
                            && x.sweep == sw.id
                            && x.method == s.method
                            && x.mass == s.mass
                            && x.measure == measure
                    })
                    .map(|x| ExpectedBand {
                        rate: x.rate,
                        tolerance: x.tolerance,
                        source: x.source.clone(),
                    });
                out.push(RateRecord {
                    sweep: sw.id.clone(),
                    series: s,
                    measure,
                    refinement,
                    slope,
                    levels_used: pts.iter().map(|p| p.0).collect(),
                    expected,
                });
            }
        }
    }
    out
}

fn checks(results: &DynamicResults) -> Vec<CheckRecord> {
    let tier = results.provenance.tier;
    let in_tier =
        |t: Option<Tier>, sweep: &str| t.is_none_or(|t| t == tier) && results.sweep_cases.contains_key(sweep);
    let mut out: Vec<CheckRecord> = results
        .study
        .expect_rate
        .iter()
        .filter(|x| in_tier(x.tier, &x.sweep))
        .map(|x| {
            let r = results.measures.rates.iter().find(|r| {
                r.sweep == x.sweep
                    && r.series.method == x.method
                    && r.series.mass == x.mass
                    && r.measure == x.measure
            });
            let id = format!(
                "{}-{}-{}-{}-rate",
                x.sweep,
                x.method.name(),
                x.mass.name(),
                x.measure.name()
            );
            let what = format!(
                "{} of {} ({} mass) in sweep `{}`, fitted against {} over levels {:?}",
                x.measure.label(),
                x.method.label(),
                x.mass.name(),
                x.sweep,
                r.map_or("h", |r| if r.refinement == Refinement::Time {
                    "Δt"
                } else {
                    "h"
                }),
                r.map_or(vec![], |r| r.levels_used.clone())
            );
            check_rate(
                &id,
                &what,
                r.and_then(|r| r.slope),
                x.rate,
                x.tolerance,
                &x.source,
            )
        })
        .collect();
    out.extend(
        results
            .study
            .expect_at_most
            .iter()
            .filter(|x| in_tier(x.tier, &x.sweep))
            .map(|x| {
                let c = finest(
                    results
                        .sweep(&x.sweep)
                        .into_iter()
                        .filter(|c| c.method == x.method && c.mass == x.mass),
                );
                let id = format!(
                    "{}-{}-{}-{}-bound",
                    x.sweep,
                    x.method.name(),
                    x.mass.name(),
                    x.measure.name()
                );
                let what = format!(
                    "{} of {} ({} mass) at the finest case of sweep `{}` ({})",
                    x.measure.label(),
                    x.method.label(),
                    x.mass.name(),
                    x.sweep,
                    c.map_or("none converged".to_string(), |c| c.id.clone())
                );
                check_at_most(
                    &id,
                    what,
                    c.and_then(|c| c.measure(x.measure)),
                    x.limit,
                    &x.source,
                )
            }),
    );
    out
}
