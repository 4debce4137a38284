//! The vibrating bar as a study kind: one case is one bar solved by one method with one mass
//! matrix, grid and time step ([`crate::problems::bar::solve`]); its record carries the
//! displacement error, the period and the energy drift, and the free end's displacement
//! history of the cases a history figure draws goes to `histories.json`.

use super::records::{BarMeasures, BarRecord, BarResults, ExpectedBand, RateRecord, Series};
use super::{BarCase, BarMeasure, BarStudy, FigureKind, Refinement};
use crate::problems::bar;
use crate::study::checks::{check_at_most, check_rate, CheckRecord};
use crate::study::engine::{study_file_fields, CaseKey, Results, StudyKind, VtkTarget};
use crate::study::results::{write_case_data, SolveRecord, SweepIndex};
use crate::study::{StudyError, Tier};
use std::collections::BTreeSet;
use std::path::Path;

/// (t, u of the free end) after every step.
pub type History = Vec<[f64; 2]>;

fn solve_case(case: &BarCase) -> (BarRecord, History) {
    let (mut solved, o) = match bar::solve(&case.spec, case.method) {
        Err(e) => (SolveRecord::rejected(e), None),
        Ok(o) => (SolveRecord::of(&o.steps, o.failure.as_ref()), Some(o)),
    };
    let time_steps = solved.steps.len();
    let max_newton_iterations = o
        .as_ref()
        .and_then(|o| o.steps.iter().map(|s| s.newton.iterations()).max())
        .unwrap_or(0);
    let steps_at_floor = solved
        .steps
        .iter()
        .filter(|s| s.accepted_at_floor.is_some())
        .count();
    let steps_cut_back = o
        .as_ref()
        .map_or(0, |o| o.steps.iter().filter(|s| s.cutbacks() > 0).count());
    solved.steps.drain(..time_steps.saturating_sub(1));
    let conv = o.as_ref().filter(|o| o.failure.is_none());
    let (exact, end) = (case.spec.period(), case.spec.duration());
    let finite = |x: f64| x.is_finite().then_some(x);
    let rec = BarRecord {
        id: case.id.clone(),
        method: case.method,
        mass: case.spec.mass,
        elements: case.spec.elements,
        points_per_cell: case.spec.points_per_cell,
        steps_per_period: case.spec.steps_per_period,
        solve: solved,
        time_steps,
        max_newton_iterations,
        steps_at_floor,
        steps_cut_back,
        displacement_error: conv.and_then(|o| finite(o.displacement_error(&case.spec, end))),
        measured_period: conv.and_then(|o| o.measured_period),
        period_error: conv
            .and_then(|o| o.measured_period)
            .map(|t| (t - exact).abs() / exact),
        energy_drift: conv.and_then(|o| finite(o.energy_drift())),
        points: o.as_ref().map_or(0, |o| o.points.len()),
    };
    let history = o.map_or(vec![], |o| o.top_history.iter().map(|&(t, u)| [t, u]).collect());
    (rec, history)
}

impl StudyKind for BarStudy {
    const PROBLEM: &'static str = "bar";
    type Case = BarCase;
    type Output = (BarRecord, History);
    type Record = BarRecord;
    type Measures = BarMeasures;

    study_file_fields!();
    fn cases(&self, tier: Tier) -> (Vec<BarCase>, SweepIndex) {
        self.cases(tier)
    }
    fn key(&self, c: &BarCase) -> CaseKey {
        CaseKey {
            has_vtk: false,
            ..CaseKey::of_spec(&c.id, c.method, &c.spec, 0)
        }
    }
    fn cost(&self, c: &BarCase) -> f64 {
        (c.spec.elements * c.spec.points_per_cell * c.spec.time_steps()) as f64
    }
    fn solve(&self, c: &BarCase, _vtk: Option<&VtkTarget>) -> Result<Self::Output, StudyError> {
        Ok(solve_case(c))
    }
    fn record(o: &Self::Output) -> &BarRecord {
        &o.0
    }
    fn measure(results: &mut Results<Self>) {
        results.measures.exact_period = results.study.case_spec(Default::default(), 1, 1, 1).period();
        results.measures.rates = rates(results);
        results.checks = checks(results);
    }
    /// `histories.json`: the free end's history of the cases a history figure draws.
    fn write_side_files(&self, dir: &Path, outputs: &[Self::Output]) -> Result<(), StudyError> {
        let drawn = self.drawn_cases(outputs.iter().map(|o| &o.0));
        write_case_data(&dir.join("histories.json"), outputs, |r, _| drawn.contains(&r.id))
    }
}

impl BarStudy {
    /// The finest case of every series of each sweep a history figure draws.
    fn drawn_cases<'a>(&self, records: impl Iterator<Item = &'a BarRecord> + Clone) -> BTreeSet<String> {
        let mut out = BTreeSet::new();
        for f in self.figures.iter().filter(|f| f.kind == FigureKind::History) {
            let Some(sw) = self.sweep(&f.sweep) else { continue };
            let in_sweep = |r: &&BarRecord| {
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
fn finest<'a>(cases: impl Iterator<Item = &'a BarRecord>) -> Option<&'a BarRecord> {
    cases.max_by_key(|c| (c.elements, c.steps_per_period))
}

/// The refined variable's step of a case: h = L / elements or Δt = T / steps per period (in
/// units of L and T: only ratios enter a slope).
fn level_size(r: &BarRecord, refinement: Refinement) -> (usize, f64) {
    let n = match refinement {
        Refinement::Space => r.elements,
        Refinement::Time => r.steps_per_period,
    };
    (n, 1.0 / n as f64)
}

fn rates(results: &BarResults) -> Vec<RateRecord> {
    let study = &results.study;
    let mut out = vec![];
    for sw in &study.sweeps {
        let refinement = sw.refinement();
        for s in results.sweep_series(&sw.id) {
            for measure in [BarMeasure::Displacement, BarMeasure::Period] {
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
                let slope = crate::norms::fitted_rate(&h, &e);
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

fn checks(results: &BarResults) -> Vec<CheckRecord> {
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
