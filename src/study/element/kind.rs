//! The element study as a study kind: one case per test, solved by
//! [`crate::problems::element_test::run`] in microseconds to milliseconds; the kind adds each
//! closed form's value and the checks.

use super::{ClosedFormRecord, ElementMeasures, ElementRecord, ElementResults, ElementStudy, TestSection};
use crate::problems::element_test::closed_form::measures;
use crate::problems::element_test::{run, ElementState};
use crate::study::checks::{check_at_most, check_newton_quadratic, CheckRecord};
use crate::study::engine::{study_file_fields, CaseKey, Results, StudyKind, VtkTarget};
use crate::study::results::{CaseStatus, FailureRecord, SolveRecord, StepRecord, SweepIndex};
use crate::study::{StudyError, Tier};
use std::collections::BTreeMap;
use std::path::Path;

/// The one sweep of an element study: its tests in file order.
pub const SWEEP: &str = "tests";

fn solve_test(study: &ElementStudy, t: &TestSection) -> ElementRecord {
    let material = study.material(t);
    let mut rec = ElementRecord {
        id: t.id.clone(),
        model: material.model().to_string(),
        path: t.path,
        solve: SolveRecord::rejected(""),
        measures: BTreeMap::new(),
        histories: BTreeMap::new(),
        start: BTreeMap::new(),
    };
    let model = match material.build() {
        Ok(m) => m,
        Err(e) => {
            rec.solve = SolveRecord::rejected(e);
            return rec;
        }
    };
    let out = run(model.as_ref(), &t.test());
    let total = out.states.len() + usize::from(out.failure.is_some());
    let steps: Vec<StepRecord> = out
        .residuals
        .iter()
        .enumerate()
        .map(|(k, r)| StepRecord::residuals_only(k + 1, (k + 1) as f64 / total.max(1) as f64, r.clone()))
        .collect();
    rec.solve = SolveRecord {
        status: if out.failure.is_some() {
            CaseStatus::Failed
        } else {
            CaseStatus::Converged
        },
        failure: out.failure.as_ref().map(|f| FailureRecord {
            step: f.step,
            reason: f.reason.clone(),
            residuals: f.residuals.clone(),
        }),
        newton_iterations: out.residuals.iter().map(|r| r.len() - 1).sum(),
        steps,
    };
    rec.measures = measures(&out.states)
        .into_iter()
        .map(|(k, v)| (k.to_string(), v))
        .collect();
    let path: Vec<&ElementState> = out.states.iter().filter(|s| !s.confining).collect();
    let start = out
        .states
        .iter()
        .rev()
        .find(|s| s.confining)
        .copied()
        .unwrap_or_default();
    rec.start = [("p", start.p()), ("q", start.q())]
        .into_iter()
        .map(|(k, v)| (k.to_string(), v))
        .collect();
    // The figures' curves, after each step of the path.
    type Of = fn(&ElementState) -> f64;
    let series: [(&str, Of); 4] = [
        ("p", ElementState::p),
        ("q", ElementState::q),
        ("strain", |s| s.strain),
        ("volumetric_strain", ElementState::volumetric_strain),
    ];
    for (name, of) in series {
        rec.histories
            .insert(name.to_string(), path.iter().map(|s| of(s)).collect());
    }
    rec
}

impl StudyKind for ElementStudy {
    const PROBLEM: &'static str = "element";
    type Case = TestSection;
    type Output = ElementRecord;
    type Record = ElementRecord;
    type Measures = ElementMeasures;

    study_file_fields!();
    /// Every test in both tiers: a test takes at most milliseconds.
    fn cases(&self, _tier: Tier) -> (Vec<TestSection>, SweepIndex) {
        crate::study::engine::distinct_cases([(SWEEP.to_string(), self.tests.clone())], |t| &t.id)
    }
    fn key(&self, t: &TestSection) -> CaseKey {
        CaseKey {
            id: t.id.clone(),
            hash: crate::study::store::case_hash(&(&t.id, &self.materials[&t.material], &t.test())),
            has_vtk: false,
        }
    }
    fn cost(&self, t: &TestSection) -> f64 {
        (t.steps + t.confining_steps) as f64
    }
    fn solve(&self, t: &TestSection, _vtk: Option<&VtkTarget>) -> Result<ElementRecord, StudyError> {
        Ok(solve_test(self, t))
    }
    fn record(o: &ElementRecord) -> &ElementRecord {
        o
    }
    fn measure(results: &mut Results<Self>) {
        results.measures = closed_forms(results);
        results.checks = checks(results);
    }
    fn write_side_files(&self, _dir: &Path, _outputs: &[ElementRecord]) -> Result<(), StudyError> {
        Ok(())
    }
}

fn closed_forms(results: &ElementResults) -> ElementMeasures {
    let study = &results.study;
    let mut out = vec![];
    for e in &study.expect_closed_form {
        let t = study.tests.iter().find(|t| t.id == e.test);
        let case = results
            .case(&e.test)
            .filter(|c| c.solve.status == CaseStatus::Converged);
        let value = t.zip(case).and_then(|(t, c)| {
            let start = ElementState {
                tau: nalgebra::Matrix3::identity() * -c.start.get("p").copied().unwrap_or(0.0),
                ..Default::default()
            };
            e.closed_form.value(&study.material(t), &t.test(), &start).ok()
        });
        let measure = e.closed_form.measure();
        let measured = case.and_then(|c| c.measures.get(measure).copied());
        let error = value
            .zip(measured)
            .map(|(v, m)| (m - v).abs() / if v == 0.0 { 1.0 } else { v.abs() });
        out.push(ClosedFormRecord {
            test: e.test.clone(),
            closed_form: e.closed_form,
            measure: measure.to_string(),
            value,
            measured,
            error,
            source: e.source.clone(),
        });
    }
    ElementMeasures { closed_forms: out }
}

fn checks(results: &ElementResults) -> Vec<CheckRecord> {
    let study = &results.study;
    let mut out = vec![];
    for (e, r) in study
        .expect_closed_form
        .iter()
        .zip(&results.measures.closed_forms)
    {
        out.push(check_at_most(
            &format!("{}-{}", e.test, e.closed_form.name()),
            format!(
                "{} of test {} within {:e} of the closed form {} (measured: relative error)",
                r.measure,
                e.test,
                e.tolerance,
                e.closed_form.name()
            ),
            r.error,
            e.tolerance,
            &e.source,
        ));
    }
    if let Some(q) = &study.expect_quadratic {
        // Every step of every test, a failed test's last attempt included; not evaluated if
        // no step iterated twice.
        let steps = results.cases.iter().flat_map(|c| c.solve.newton_histories(&c.id));
        out.push(check_newton_quadratic(
            "newton-quadratic",
            "Newton on the stress-controlled components",
            "every test",
            steps,
            q,
        ));
    }
    out
}
