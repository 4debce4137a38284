//! The compaction as a study kind: one case is the block solved by one method
//! ([`crate::problems::compaction::solve`]); its record carries Figure 17's measure and the
//! Newton histories, and the domains of the drawn cases go to `domains.json`.

use super::records::{CompactionMeasures, CompactionRecord};
use super::{CompactionCase, CompactionFigureKind, CompactionStudy};
use crate::basis::method::Method;
use crate::material::constitutive::InternalVariables;
use crate::problems::compaction::{solve, Domain3dRecord, DomainRecord};
use crate::study::engine::{study_file_fields, CaseKey, Results, StudyKind, VtkTarget};
use crate::study::results::{write_case_data, CaseStatus, SolveRecord, SweepIndex};
use crate::study::vtk_output::{grid_part, write_domain_frames, DomainBox, DomainFrame};
use crate::study::{StudyError, Tier};
use std::collections::BTreeSet;
use std::path::Path;

/// One case: its record, the domains the figures draw, and (3D) every point's domain for
/// ParaView, which the kind does not keep.
fn solve_case(case: &CompactionCase) -> (CompactionRecord, Vec<DomainRecord>, Vec<Domain3dRecord>) {
    let s = &case.spec;
    let (solved, o) = match solve(s, case.method) {
        Err(e) => (SolveRecord::rejected(e), None),
        Ok(o) => (SolveRecord::of(&o.steps, o.failure.as_ref()), Some(o)),
    };
    let u = o.as_ref().and_then(|o| {
        let u = o.max_horizontal_displacement;
        u.is_finite().then_some(u)
    });
    let converged = solved.status == CaseStatus::Converged;
    let failed = solved.status == CaseStatus::Failed;
    let steps = o.as_ref().map_or(&[][..], |o| &o.steps[..]);
    let rec = CompactionRecord {
        id: case.id.clone(),
        method: case.method,
        h: s.element_size,
        points_per_cell: (!case.method.is_fem()).then_some(s.points_per_cell),
        yield_stress: s.yield_stress(),
        weak_node_tolerance: s.weak_node_tolerance,
        ghost_gamma: if case.method.is_fem() { 0.0 } else { s.ghost.gamma },
        ghost_faces: s.ghost.faces,
        steps_cut: steps.iter().filter(|s| s.cutbacks() > 0).count(),
        cutbacks: steps.iter().map(|s| s.cutbacks()).sum(),
        solve: solved,
        max_horizontal_displacement: u.filter(|_| converged),
        last_converged_displacement: u.filter(|_| failed),
        weak_nodes_treated: o.as_ref().map_or(0, |o| o.weak_nodes_treated),
        points: o.as_ref().map_or(0, |o| o.size),
    };
    let (domains, domains_3d) = o.map_or((vec![], vec![]), |o| (o.domains, o.domains_3d));
    (rec, domains, domains_3d)
}

impl StudyKind for CompactionStudy {
    const PROBLEM: &'static str = "compaction";
    type Case = CompactionCase;
    type Output = (CompactionRecord, Vec<DomainRecord>);
    type Record = CompactionRecord;
    type Measures = CompactionMeasures;

    study_file_fields!();
    fn cases(&self, tier: Tier) -> (Vec<CompactionCase>, SweepIndex) {
        self.cases(tier)
    }
    fn key(&self, c: &CompactionCase) -> CaseKey {
        CaseKey::of_spec(&c.id, c.method, &c.spec, 0)
    }
    fn cost(&self, c: &CompactionCase) -> f64 {
        let s = &c.spec;
        let d = s.dimension as i32;
        (s.points_per_cell as f64 / s.element_size).powi(d)
    }
    fn solve(&self, c: &CompactionCase, vtk: Option<&VtkTarget>) -> Result<Self::Output, StudyError> {
        let (rec, domains, domains_3d) = solve_case(c);
        if let Some(v) = vtk {
            write_case_vtk(&v.study_dir, c, &rec, &domains, &domains_3d)?;
        }
        Ok((rec, domains))
    }
    fn record(o: &Self::Output) -> &CompactionRecord {
        &o.0
    }
    fn measure(results: &mut Results<Self>) {
        results.measures.reference = super::checks::figure17_reference(results);
        results.measures.gci = super::checks::gci_records(results);
        results.checks = super::checks::compute_checks(results);
    }
    /// `domains.json`: the final domains of the cases the domain figures draw.
    fn write_side_files(&self, dir: &Path, outputs: &[Self::Output]) -> Result<(), StudyError> {
        let drawn = self.drawn_cases();
        write_case_data(&dir.join("domains.json"), outputs, |r, _| drawn.contains(&r.id))
    }
}

impl CompactionStudy {
    /// Ids of the iGIMP cases a domain figure draws.
    fn drawn_cases(&self) -> BTreeSet<String> {
        self.figures
            .iter()
            .filter(|f| f.kind == CompactionFigureKind::Domains)
            .filter_map(|f| {
                let s = self.sweeps.iter().find(|s| s.id == f.sweep)?;
                let spec = self.case_spec(
                    s,
                    f.element_size?,
                    f.points_per_cell? as usize,
                    self.weak_nodes.tolerance,
                    None,
                );
                Some(self.case_id(Method::IGIMP, &spec))
            })
            .collect()
    }
}

/// ParaView files of an iGIMP or MPM case: the initial domains and those of the last
/// converged step (the vertical stress and the material's internal variables, by name, as
/// cell data):
/// quadrilaterals in 2D, every point's hexahedron in 3D (`domains_3d`), with the background
/// grid.
fn write_case_vtk(
    dir: &Path,
    case: &CompactionCase,
    rec: &CompactionRecord,
    doms: &[DomainRecord],
    doms_3d: &[Domain3dRecord],
) -> Result<(), StudyError> {
    let steps = rec.solve.steps.len();
    let frame = |step: usize, domains: Vec<DomainBox>, scalars| DomainFrame {
        time: step as f64 / case.spec.load_steps.max(1) as f64,
        step,
        dimension: case.spec.dimension,
        domains,
        scalars,
    };
    type Columns = (Vec<DomainBox>, Vec<DomainBox>, Vec<f64>, Vec<InternalVariables>);
    let (initial, last, stress, internal): Columns = if case.spec.dimension == 3 {
        (
            doms_3d.iter().map(|d| DomainBox::new(d.x0, d.half0)).collect(),
            doms_3d.iter().map(|d| DomainBox::new(d.x, d.half)).collect(),
            doms_3d.iter().map(|d| d.sigma_zz).collect(),
            doms_3d.iter().map(|d| d.internal).collect(),
        )
    } else {
        (
            doms.iter().map(|d| DomainBox::new(d.x0, d.half0)).collect(),
            doms.iter().map(|d| DomainBox::new(d.x, d.half)).collect(),
            doms.iter().map(|d| d.sigma_yy).collect(),
            doms.iter().map(|d| d.internal).collect(),
        )
    };
    let vertical = if case.spec.dimension == 3 {
        "sigma_zz"
    } else {
        "sigma_yy"
    };
    let model = case.spec.model().map_err(|e| StudyError::io(dir, e))?;
    let mut scalars = vec![(vertical.to_string(), stress)];
    for (i, v) in model.internal_variables().iter().enumerate() {
        scalars.push((v.name.to_string(), internal.iter().map(|x| x.get(i)).collect()));
    }
    let frames = [frame(0, initial, vec![]), frame(steps, last, scalars)];
    let s = &case.spec;
    let grid = grid_part(s.dimension, || s.grid_2d(), || s.grid_3d());
    write_domain_frames(dir, &case.id, &frames, grid.as_ref()).map(|_| ())
}
