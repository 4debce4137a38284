//! The manufactured solutions as a study kind: one case is one field solved by one method on
//! one grid ([`crate::problems::manufactured::solve`]); its record carries the two error
//! measures, its material or Gauss points go to `points/<case>.csv`, and the domains of the
//! drawn cases, with their pointwise stress errors, to `domains.json`.

use super::records::{CasePoints, ManufacturedMeasures, ManufacturedRecord};
use super::{FigureKind, ManufacturedCase, ManufacturedStudy};
use crate::basis::method::Method;
use crate::mesh::grid::Grid;
use crate::problems::manufactured::{solve, stress_deviations, Errors, Exact, PointValue};
use crate::problems::manufactured3d::{solve_3d, stress_deviations_3d, Exact3, PointValue3};
use crate::study::engine::{study_file_fields, CaseKey, Results, StudyKind, VtkTarget};
use crate::study::results::{fresh_points_dir, write_case_data, CaseStatus, SolveRecord, SweepIndex};
use crate::study::store::{confined, write_file};
use crate::study::vtk_output::{grid_part, write_domain_frames, DomainBox, DomainFrame};
use crate::study::{StudyError, Tier};
use std::collections::BTreeSet;
use std::fmt::Write as _;
use std::path::Path;

fn solve_case(case: &ManufacturedCase) -> (ManufacturedRecord, CasePoints) {
    let (solved, errors, points) = if case.spec.dimension == 3 {
        solve_cube(case)
    } else {
        solve_square(case)
    };
    let mp = case.method.uses_material_points();
    let rec = ManufacturedRecord {
        id: case.id.clone(),
        field: case.spec.field,
        method: case.method,
        domain_update: case
            .method
            .uses_domain_update()
            .then_some(case.spec.domain_update),
        cells: case.spec.cells,
        points_per_cell: mp.then_some(case.spec.points_per_cell),
        solve: solved,
        displacement_error: errors.map(|e| e.displacement),
        stress_error: errors.map(|e| e.stress),
        points: points.points.len() + points.points_3d.len(),
    };
    (rec, points)
}

type Solved = (SolveRecord, Option<Errors>, CasePoints);

/// The plane case ([`solve`]).
fn solve_square(case: &ManufacturedCase) -> Solved {
    let (solved, o) = match solve(&case.spec, case.method) {
        Err(e) => (SolveRecord::rejected(e), None),
        Ok(o) => (SolveRecord::of(&o.steps, o.failure.as_ref()), Some(o)),
    };
    let errors = o.as_ref().and_then(|o| o.errors);
    let points = o.map_or(vec![], |o| o.points);
    let (deviation, smax) = stress_deviations(&Exact::of(&case.spec), &points);
    let stress_error = deviation.into_iter().map(|d| d / smax).collect();
    let points = CasePoints {
        points,
        stress_error,
        points_3d: vec![],
    };
    (solved, errors, points)
}

/// The cube case ([`solve_3d`]).
fn solve_cube(case: &ManufacturedCase) -> Solved {
    let (solved, o) = match solve_3d(&case.spec, case.method) {
        Err(e) => (SolveRecord::rejected(e), None),
        Ok(o) => (SolveRecord::of(&o.steps, o.failure.as_ref()), Some(o)),
    };
    let errors = o.as_ref().and_then(|o| o.errors);
    let points_3d = o.map_or(vec![], |o| o.points);
    let (deviation, smax) = stress_deviations_3d(&Exact3::of(&case.spec), &points_3d);
    let stress_error = deviation.into_iter().map(|d| d / smax).collect();
    let points = CasePoints {
        points: vec![],
        stress_error,
        points_3d,
    };
    (solved, errors, points)
}

/// Header of the point files: reference and current position, initial volume, Cauchy stress.
pub const POINTS_HEADER: &str = "X,Y,x,y,volume0,sigma_xx,sigma_yy,sigma_xy,sigma_zz";

/// Header of the 3D point files.
pub const POINTS_HEADER_3D: &str =
    "X,Y,Z,x,y,z,volume0,sigma_xx,sigma_yy,sigma_zz,sigma_xy,sigma_yz,sigma_xz";

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

/// The 3D point file: one row per point, shortest round-trip formatting.
pub fn points_csv_3d(points: &[PointValue3]) -> String {
    let mut s = String::with_capacity(200 * (points.len() + 1));
    s.push_str(POINTS_HEADER_3D);
    s.push('\n');
    for p in points {
        let (x0, x, t) = (p.x0, p.x, p.sigma);
        let _ = writeln!(
            s,
            "{},{},{},{},{},{},{},{},{},{},{},{},{}",
            x0[0],
            x0[1],
            x0[2],
            x[0],
            x[1],
            x[2],
            p.volume0,
            t[0][0],
            t[1][1],
            t[2][2],
            t[0][1],
            t[1][2],
            t[0][2]
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
        let d = c.spec.dimension as i32;
        let n = c.spec.cells as f64;
        let per_cell = match c.method {
            Method::MaterialPoint(_) => (c.spec.points_per_cell as f64).powi(d),
            // The scheduler's relative cost, used only to start the longest cases first
            // (results do not depend on it): 27 Gauss points per element, each coupling
            // 60 × 60 unknowns, about 6× the work per point of Hex8's 24 × 24 (6.25).
            Method::FEM_HEX20 => 27.0 * 6.0,
            _ => 3f64.powi(d),
        };
        n.powi(d) * per_cell
    }
    fn solve(&self, c: &ManufacturedCase, vtk: Option<&VtkTarget>) -> Result<Self::Output, StudyError> {
        let out = solve_case(c);
        if let Some(v) = vtk {
            write_case_vtk(&v.study_dir, c, &out)?;
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
        for (r, p) in outputs
            .iter()
            .filter(|(r, _)| r.solve.status == CaseStatus::Converged)
        {
            let path = confined(&pdir, &format!("{}.csv", r.id))?;
            let csv = if p.points_3d.is_empty() {
                points_csv(&p.points)
            } else {
                points_csv_3d(&p.points_3d)
            };
            write_file(&path, csv.as_bytes())?;
        }
        let drawn = self.drawn_cases();
        write_case_data(&dir.join("domains.json"), outputs, |r, _| drawn.contains(&r.id))
    }
}

/// ParaView files of a case: its final domains (quadrilaterals in 2D, hexahedra in 3D; Gauss
/// points have none) with each point's stress error, and the background grid.
fn write_case_vtk(
    dir: &Path,
    c: &ManufacturedCase,
    (rec, p): &(ManufacturedRecord, CasePoints),
) -> Result<(), StudyError> {
    let d = c.spec.dimension;
    let domains: Vec<DomainBox> = if d == 3 {
        p.points_3d.iter().map(|q| DomainBox::new(q.x, q.half)).collect()
    } else {
        p.points.iter().map(|q| DomainBox::new(q.x, q.half)).collect()
    };
    let frame = DomainFrame {
        time: 1.0,
        step: rec.solve.steps.len(),
        dimension: d,
        domains,
        scalars: vec![("stress_error".into(), p.stress_error.clone())],
    };
    let (h, n) = (c.spec.element_size(), c.spec.cells);
    let grid = grid_part(
        d,
        || Grid::try_new([0.0; 2], [h; 2], [n; 2]),
        || Grid::try_new([0.0; 3], [h; 3], [n; 3]),
    );
    write_domain_frames(dir, &c.id, &[frame], grid.as_ref()).map(|_| ())
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
                Some(Self::case_id(Method::IGIMP, &spec))
            })
            .collect()
    }
}
