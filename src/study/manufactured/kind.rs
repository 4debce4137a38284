//! The manufactured solutions as a study kind: one case is one field solved by one method on
//! one grid ([`crate::problems::manufactured::solve`]); its record carries the two error
//! measures, its material or Gauss points go to `points/<case>.csv`, and the domains of the
//! drawn cases, with their pointwise stress errors, to `domains.json`.

use super::records::{CasePoints, ManufacturedMeasures, ManufacturedRecord};
use super::{FigureKind, ManufacturedCase, ManufacturedStudy};
use crate::method::Method;
use crate::problems::manufactured::{solve, stress_deviations, Exact, PointValue};
use crate::study::engine::{study_file_fields, CaseKey, Results, StudyKind, VtkTarget};
use crate::study::results::{fresh_points_dir, write_case_data, CaseStatus, SolveRecord, SweepIndex};
use crate::study::store::{confined, write_file};
use crate::study::vtk_output::{write_domain_frames, DomainFrame};
use crate::study::{StudyError, Tier};
use std::collections::BTreeSet;
use std::fmt::Write as _;
use std::path::Path;

fn solve_case(case: &ManufacturedCase) -> (ManufacturedRecord, CasePoints) {
    let (solved, o) = match solve(&case.spec, case.method) {
        Err(e) => (SolveRecord::rejected(e), None),
        Ok(o) => (SolveRecord::of(&o.steps, o.failure.as_ref()), Some(o)),
    };
    let errors = o.as_ref().and_then(|o| o.errors);
    let mp = case.method.uses_material_points();
    let rec = ManufacturedRecord {
        id: case.id.clone(),
        field: case.spec.field,
        method: case.method,
        domain_update: (case.method == Method::Igimp).then_some(case.spec.domain_update),
        cells: case.spec.cells,
        points_per_cell: mp.then_some(case.spec.points_per_cell),
        status: solved.status,
        failure: solved.failure,
        displacement_error: errors.map(|e| e.displacement),
        stress_error: errors.map(|e| e.stress),
        points: o.as_ref().map_or(0, |o| o.points.len()),
        newton_iterations: solved.newton_iterations,
        steps: solved.steps,
    };
    let points = o.map_or(vec![], |o| o.points);
    let (deviation, smax) = stress_deviations(&Exact::of(&case.spec), &points);
    let stress_error = deviation.into_iter().map(|d| d / smax).collect();
    (rec, CasePoints { points, stress_error })
}

/// Header of the point files: reference and current position, initial volume, Cauchy stress.
pub const POINTS_HEADER: &str = "X,Y,x,y,volume0,sigma_xx,sigma_yy,sigma_xy,sigma_zz";

/// One row per point, shortest round-trip formatting (the file re-reads exactly).
pub fn points_csv(points: &[PointValue]) -> String {
    let mut s = String::with_capacity(120 * (points.len() + 1));
    s.push_str(POINTS_HEADER);
    s.push('\n');
    for p in points {
        let _ = writeln!(
            s,
            "{},{},{},{},{},{},{},{},{}",
            p.x0[0], p.x0[1], p.x[0], p.x[1], p.volume0, p.sigma[0], p.sigma[1], p.sigma[2], p.sigma[3]
        );
    }
    s
}

impl StudyKind for ManufacturedStudy {
    const PROBLEM: &'static str = "manufactured";
    type Case = ManufacturedCase;
    type Output = (ManufacturedRecord, CasePoints);
    type Record = ManufacturedRecord;
    type Measures = ManufacturedMeasures;

    study_file_fields!();
    fn cases(&self, tier: Tier) -> (Vec<ManufacturedCase>, SweepIndex) {
        self.cases(tier)
    }
    fn key(&self, c: &ManufacturedCase) -> CaseKey {
        CaseKey::of_spec(&c.id, c.method, &c.spec, 0)
    }
    fn cost(&self, c: &ManufacturedCase) -> f64 {
        let n = c.spec.cells as f64;
        let per_cell = if c.method.uses_material_points() {
            (c.spec.points_per_cell * c.spec.points_per_cell) as f64
        } else {
            9.0
        };
        n * n * per_cell
    }
    fn solve(&self, c: &ManufacturedCase, vtk: Option<&VtkTarget>) -> Result<Self::Output, StudyError> {
        let out = solve_case(c);
        if let Some(v) = vtk {
            let p = &out.1;
            let frame = DomainFrame {
                time: 1.0,
                step: out.0.steps.len(),
                dimension: 2,
                domains: p
                    .points
                    .iter()
                    .map(|q| [q.x[0], q.x[1], q.half[0], q.half[1]].into())
                    .collect(),
                scalars: vec![("stress_error".into(), p.stress_error.clone())],
            };
            write_domain_frames(&v.study_dir, &c.id, &[frame])?;
        }
        Ok(out)
    }
    fn record(o: &Self::Output) -> &ManufacturedRecord {
        &o.0
    }
    fn measure(results: &mut Results<Self>) {
        results.measures.rates = super::checks::rates(results);
        results.checks = super::checks::checks(results);
    }
    /// `points/<case>.csv` of every converged case (stale point files removed) and
    /// `domains.json`, the points of the cases a domain figure draws.
    fn write_side_files(&self, dir: &Path, outputs: &[Self::Output]) -> Result<(), StudyError> {
        let pdir = fresh_points_dir(dir)?;
        for (r, p) in outputs.iter().filter(|(r, _)| r.status == CaseStatus::Converged) {
            let path = confined(&pdir, &format!("{}.csv", r.id))?;
            write_file(&path, points_csv(&p.points).as_bytes())?;
        }
        let drawn = self.drawn_cases();
        write_case_data(&dir.join("domains.json"), outputs, |r, _| drawn.contains(&r.id))
    }
}

impl ManufacturedStudy {
    /// Ids of the iGIMP cases a domain figure draws.
    pub fn drawn_cases(&self) -> BTreeSet<String> {
        self.figures
            .iter()
            .filter(|f| f.kind == FigureKind::Domains)
            .filter_map(|f| {
                let s = self.sweeps.iter().find(|s| s.id == f.sweep)?;
                let spec = self.case_spec(
                    s.field,
                    f.cells?,
                    f.points_per_cell?,
                    f.domain_update.unwrap_or_default(),
                );
                Some(Self::case_id(Method::Igimp, &spec))
            })
            .collect()
    }
}
