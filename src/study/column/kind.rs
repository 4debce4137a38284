//! The column as a study kind: one case is one column solved by one method
//! ([`crate::problems::column::solve_column_observed`]); its record carries the errors of
//! eqs (46)–(47) and the final point values go to `points/<case>.csv`. The measures are the
//! fitted rates, the `[[compare]]` checks and the analytical column.
//!
//! A Newton failure or a point leaving the grid is recorded in the case (`status = "failed"`,
//! with the failing step and its residual history) and the sweep goes on; a case the solver
//! rejects as input is `"rejected"`.

use super::rates::{compute_comparisons, compute_rates};
use super::records::{AnalyticalRecord, ColumnRecord, POINTS_HEADER, POINTS_HEADER_PLASTIC, PROFILE_SAMPLES};
use super::{ColumnCase, ColumnStudy};
use crate::material::constitutive::InternalVariable;
use crate::problems::column::{solve_column_observed, ColumnObserver, ColumnSpec, PointRecord};
use crate::study::checks::{check_rate, CheckRecord};
use crate::study::engine::{study_file_fields, CaseKey, Results, StudyKind, VtkTarget};
use crate::study::results::{fresh_points_dir, CaseStatus, SolveRecord, SweepIndex};
use crate::study::store::{confined, write_file};
use crate::study::vtk_output::ColumnVtkWriter;
use crate::study::{StudyError, Tier};
use std::path::Path;

fn finite(x: f64) -> Option<f64> {
    x.is_finite().then_some(x)
}

/// Solve one case.
pub fn run_case(case: &ColumnCase) -> (ColumnRecord, Vec<PointRecord>) {
    run_case_observed(case, &mut |_, _| {})
}

/// [`run_case`], showing the solver to `observer` before the first and after every converged
/// load step.
pub fn run_case_observed(
    case: &ColumnCase,
    observer: &mut ColumnObserver<'_>,
) -> (ColumnRecord, Vec<PointRecord>) {
    let (solved, out) = match solve_column_observed(&case.spec, case.method, observer) {
        Err(e) => (SolveRecord::rejected(e), None),
        Ok(o) => (SolveRecord::of(&o.steps, o.failure.as_ref()), Some(o)),
    };
    // Errors are measured on converged cases only.
    let conv = out.as_ref().filter(|_| solved.status == CaseStatus::Converged);
    let plastic = conv.filter(|_| case.spec.yield_stress().is_some());
    let yield_height = plastic.and_then(|o| o.yield_height);
    let exact_yield = case.spec.analytical().yield_height();
    let rec = ColumnRecord {
        id: case.id.clone(),
        method: case.method,
        load: case.spec.weight,
        elements: case.spec.elements,
        points_per_cell: case.points_per_cell,
        load_steps: case.spec.load_steps,
        newton: case.spec.newton,
        solve: solved,
        stress_error: conv.and_then(|o| finite(o.stress_error)),
        f_error: conv.and_then(|o| finite(o.f_error)),
        sigma_xx_error: plastic.and_then(|o| finite(o.sigma_xx_error)),
        yield_height,
        yield_height_error: match (yield_height, exact_yield) {
            (Some(h), Some(e)) => finite((h - e).abs() / case.spec.length),
            _ => None,
        },
        top_displacement: conv.and_then(|o| finite(o.top_displacement)),
        base_f: conv.and_then(|o| finite(o.base_f)),
        points: out.as_ref().map_or(0, |o| o.points.len()),
    };
    (rec, out.map_or(vec![], |o| o.points))
}

impl StudyKind for ColumnStudy {
    const PROBLEM: &'static str = "column";
    type Case = ColumnCase;
    type Output = (ColumnRecord, Vec<PointRecord>);
    type Record = ColumnRecord;
    type Measures = super::records::ColumnMeasures;

    study_file_fields!();
    fn cases(&self, tier: Tier) -> (Vec<ColumnCase>, SweepIndex) {
        (self.cases(tier), self.case_index(tier))
    }
    fn key(&self, case: &ColumnCase) -> CaseKey {
        // FEM columns write ParaView files too (their Gauss points, ColumnVtkWriter).
        CaseKey {
            has_vtk: true,
            ..CaseKey::of_spec(&case.id, case.method, &case.spec, 0)
        }
    }
    fn cost(&self, c: &ColumnCase) -> f64 {
        (c.spec.elements * c.points_per_cell.unwrap_or(3) * c.spec.load_steps) as f64
    }
    fn solve(&self, case: &ColumnCase, vtk: Option<&VtkTarget>) -> Result<Self::Output, StudyError> {
        Ok(match vtk {
            None => run_case(case),
            Some(v) => {
                let mut w = ColumnVtkWriter::new(&v.study_dir, &case.id, case.spec.load_steps, v.options)?;
                let out = run_case_observed(case, &mut |step, state| w.observe(step, state));
                w.finish()?;
                out
            }
        })
    }
    fn record(o: &Self::Output) -> &ColumnRecord {
        &o.0
    }
    fn measure(results: &mut Results<Self>) {
        let (spec, tier) = (&results.study, results.provenance.tier);
        let m = &mut results.measures;
        m.rates = compute_rates(spec, tier, &results.cases, &results.sweep_cases);
        m.comparisons = compute_comparisons(spec, tier, &results.cases, &results.sweep_cases);
        m.analytical = analytical_records(spec, &results.cases);
        results.checks = column_checks(m);
    }
    /// `points/<case>.csv` of every case that was solved (stale point files removed).
    fn write_side_files(&self, dir: &Path, outputs: &[Self::Output]) -> Result<(), StudyError> {
        let pdir = fresh_points_dir(dir)?;
        let plastic = self.plastic();
        // The model's internal variables are columns of their own (none for an elastic one).
        let model = self.material.material().build();
        let internal = model.as_ref().map_or(&[][..], |m| m.internal_variables());
        for (record, points) in outputs
            .iter()
            .filter(|o| o.0.solve.status != CaseStatus::Rejected)
        {
            let p = confined(&pdir, &format!("{}.csv", record.id))?;
            write_file(&p, points_csv(points, plastic, internal).as_bytes())?;
        }
        Ok(())
    }
}

/// The expected rates and the comparisons as checks (one per `[[expect]]` and `[[compare]]`).
fn column_checks(m: &super::records::ColumnMeasures) -> Vec<CheckRecord> {
    let rates = m.rates.iter().filter_map(|r| {
        let e = r.expected.as_ref()?;
        let ppc = r.points_per_cell.map_or(String::new(), |p| format!("-p{p}"));
        let id = format!(
            "{}-{}-w{}{ppc}-{}-rate",
            r.sweep,
            r.method.name(),
            super::weight_label(r.load),
            r.measure.name()
        );
        let what = format!(
            "{} of {} (W = {}{}) in sweep `{}`, fitted over elements {:?}",
            r.measure.label(),
            r.method.label(),
            super::weight_label(r.load),
            r.points_per_cell
                .map_or(String::new(), |p| format!(", {p} points per cell")),
            r.sweep,
            r.elements_used
        );
        let mut c = check_rate(&id, &what, r.slope, e.rate, e.tolerance, &e.source);
        // A series the tier did not run leaves the check not evaluated, as the rate record says.
        c.pass = r.pass;
        Some(c)
    });
    let comparisons = m.comparisons.iter().map(|c| CheckRecord {
        id: format!(
            "{}-w{}-{}-{}-below-{}",
            c.sweep,
            super::weight_label(c.load),
            c.measure.name(),
            c.lower.name(),
            c.higher.name()
        ),
        description: format!(
            "{} of {} below that of {} at every element count both ran ({:?}); measured: the largest ratio",
            c.measure.label(),
            c.lower.label(),
            c.higher.label(),
            c.elements_checked
        ),
        measured: c.ratios.iter().copied().reduce(f64::max),
        limit: 1.0,
        pass: c.pass,
        source: c.source.clone(),
    });
    rates.chain(comparisons).collect()
}

/// The analytical column at every load of the cases, paper tables and figures.
fn analytical_records(spec: &ColumnStudy, cases: &[ColumnRecord]) -> Vec<AnalyticalRecord> {
    let mut loads: Vec<f64> = cases
        .iter()
        .map(|c| c.load)
        .chain(spec.paper.iter().map(|p| p.weight))
        .chain(spec.figures.iter().map(|f| f.weight))
        .collect();
    loads.sort_by(f64::total_cmp);
    loads.dedup();
    let c = &spec.column;
    let material = spec.material.material();
    loads
        .into_iter()
        .map(|load| {
            let column = ColumnSpec {
                length: c.length,
                material,
                density: c.density,
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
                paper_yield_height: column
                    .yield_stress()
                    .map(|ry| column.length - ry / (column.density * column.gravity())),
                profile,
            }
        })
        .collect()
}

/// Points file of a case, relative to the study folder.
pub fn points_file(case_id: &str) -> String {
    format!("points/{case_id}.csv")
}

/// One row per point, shortest round-trip formatting (so the file re-reads exactly): the
/// columns of [`POINTS_HEADER`], sigma_xx in plastic studies, then the material's internal
/// variables `internal` by name (e.g. von Mises' `plastic_multiplier`).
pub fn points_csv(points: &[PointRecord], plastic: bool, internal: &[InternalVariable]) -> String {
    let mut s = String::with_capacity(80 * (points.len() + 1));
    s.push_str(if plastic {
        POINTS_HEADER_PLASTIC
    } else {
        POINTS_HEADER
    });
    for v in internal {
        s.push(',');
        s.push_str(v.name);
    }
    s.push('\n');
    for p in points {
        s.push_str(&format!(
            "{},{},{},{},{}",
            p.z0, p.z, p.volume0, p.sigma_zz, p.f_zz
        ));
        if plastic {
            s.push_str(&format!(",{}", p.sigma_xx));
        }
        for i in 0..internal.len() {
            s.push_str(&format!(",{}", p.internal.get(i)));
        }
        s.push('\n');
    }
    s
}

/// Parse a points file written by [`points_csv`]: rows of (z0, z, volume0, sigma_zz, f_zz),
/// in plastic studies sigma_xx, then any internal variables.
pub fn read_points_csv(path: &Path) -> Result<Vec<Vec<f64>>, StudyError> {
    let text = std::fs::read_to_string(path).map_err(|e| StudyError::io(path, e))?;
    let mut lines = text.lines();
    let width = match lines.next() {
        Some(h) if h == POINTS_HEADER || h.starts_with(&format!("{POINTS_HEADER},")) => h.split(',').count(),
        _ => {
            return Err(StudyError::io(
                path,
                format!("header must start with `{POINTS_HEADER}`"),
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
