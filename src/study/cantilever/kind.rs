//! The cantilever as a study kind: one case is the beam solved by one method
//! ([`crate::problems::cantilever::solve`]); its record carries the end displacement after
//! every step against the elastica, and the domain snapshots of the figures' cases go to
//! `domains.json`.

use super::records::{CantileverMeasures, CantileverRecord, ElasticaPath, ElasticaPoint};
use super::{CantileverCase, CantileverStudy};
use crate::problems::cantilever::{solve, CantileverSpec, DomainSnapshot, SolidSnapshot};
use crate::problems::elastica::{bending_stiffness, Elastica};
use crate::study::engine::{study_file_fields, CaseKey, Results, StudyKind, VtkTarget};
use crate::study::results::{write_case_data, CaseStatus, SolveRecord, SweepIndex};
use crate::study::vtk_output::{grid_part, write_domain_frames, DomainBox, DomainFrame};
use crate::study::{StudyError, Tier};
use std::path::Path;

/// The elastica of the beam: plane strain (EI = E/(1 − ν²) d³/12 per unit width) or plane
/// stress (E d³/12 per unit width), which for the 3D beam's square section, times the width
/// d, is its EI = E d⁴/12 under a load P that is the total.
pub(super) fn elastica_path(spec: &CantileverSpec, plane_strain: bool) -> Option<ElasticaPath> {
    let width = if spec.dimension == 3 { spec.depth } else { 1.0 };
    let (e, nu) = spec.elastic_constants().ok()?;
    let ei = width * bending_stiffness(e, nu, spec.depth, plane_strain).ok()?;
    let beam = Elastica::try_new(spec.length, ei).ok()?;
    let loads = crate::problems::elastica::load_steps(spec.load, spec.load_steps);
    let tips = beam.load_path(&loads).ok()?;
    Some(ElasticaPath {
        plane_strain,
        bending_stiffness: ei,
        points: loads
            .iter()
            .zip(tips)
            .map(|(&load, t)| ElasticaPoint {
                load,
                alpha: t.alpha,
                u_over_l: t.u_over_l,
                v_over_l: -t.v_over_l,
            })
            .collect(),
    })
}

/// Solve one case, taking domain snapshots every `snapshot_every` steps (0: none).
fn solve_case_snapshots(
    case: &CantileverCase,
    snapshot_every: usize,
) -> (CantileverRecord, Vec<DomainSnapshot>, Vec<SolidSnapshot>) {
    let s = &case.spec;
    let method = case.method;
    let (solved, o) = match solve(s, case.method, snapshot_every) {
        Err(e) => (SolveRecord::rejected(e), None),
        Ok(o) => (SolveRecord::of(&o.steps, o.failure.as_ref()), Some(o)),
    };
    let elastica = elastica_path(s, s.dimension == 2).and_then(|p| p.points.last().copied());
    let (end, min_half_length, loaded_points, mut snaps, mut solid) = match o {
        Some(o) => (
            o.end,
            o.min_half_length,
            o.loaded_points,
            o.snapshots,
            o.solid_snapshots,
        ),
        None => (vec![], vec![], None, vec![], vec![]),
    };
    let last = end.last().filter(|_| solved.status == CaseStatus::Converged);
    let (u, v) = (last.map(|e| e.u_over_l), last.map(|e| e.v_over_l));
    let relative = |x: Option<f64>, e: Option<f64>| Some((x? - e?) / e?.abs());
    let rec = CantileverRecord {
        id: case.id.clone(),
        method: case.method,
        domain_update: method.uses_domain_update().then_some(s.domain_update),
        volume_update: method.uses_material_points().then_some(s.volume_update),
        depth: s.depth,
        load: s.load,
        element_size: s.element_size,
        load_steps: s.load_steps,
        solve: solved,
        end,
        u_over_l: u,
        v_over_l: v,
        elastica,
        difference_u: relative(u, elastica.map(|e| e.u_over_l)),
        difference_v: relative(v, elastica.map(|e| e.v_over_l)),
        initial_half_length: 0.5 * s.element_size / s.points_per_cell as f64,
        min_half_length,
        loaded_points,
    };
    // Keep one snapshot per step (a failing step repeats the last converged state).
    snaps.dedup_by_key(|s| s.step);
    solid.dedup_by_key(|s| s.step);
    (rec, snaps, solid)
}

impl StudyKind for CantileverStudy {
    const PROBLEM: &'static str = "cantilever";
    type Case = CantileverCase;
    type Output = (CantileverRecord, Vec<DomainSnapshot>);
    type Record = CantileverRecord;
    type Measures = CantileverMeasures;

    study_file_fields!();
    fn cases(&self, tier: Tier) -> (Vec<CantileverCase>, SweepIndex) {
        (self.cases(tier), SweepIndex::new())
    }
    fn key(&self, c: &CantileverCase) -> CaseKey {
        CaseKey::of_spec(&c.id, c.method, &c.spec, c.snapshot_every)
    }
    fn cost(&self, c: &CantileverCase) -> f64 {
        let d = c.spec.dimension as i32;
        (c.spec.length / c.spec.element_size) * (c.spec.points_per_cell as f64).powi(d)
    }
    /// With `--vtk` every iGIMP case takes snapshots: its figure's interval, else
    /// `--vtk-every`, else only the initial and final states.
    fn solve(&self, c: &CantileverCase, vtk: Option<&VtkTarget>) -> Result<Self::Output, StudyError> {
        let every = match vtk {
            Some(v) if c.snapshot_every == 0 => {
                if v.options.every > 0 {
                    v.options.every
                } else {
                    c.spec.load_steps
                }
            }
            _ => c.snapshot_every,
        };
        let (rec, snaps, solid) = solve_case_snapshots(c, every);
        if let Some(v) = vtk {
            write_case_vtk(&v.study_dir, c, &snaps, &solid)?;
        }
        Ok((rec, snaps))
    }
    fn record(o: &Self::Output) -> &CantileverRecord {
        &o.0
    }
    fn measure(results: &mut Results<Self>) {
        let study = &results.study;
        let base = study.base_spec();
        let mut elastica: Vec<ElasticaPath> = elastica_path(&base, base.dimension == 2).into_iter().collect();
        if study.plane_stress_elastica && base.dimension == 2 {
            elastica.extend(elastica_path(&base, false));
        }
        let depth_study = super::checks::depth_rows(study, &results.cases);
        let refinement = super::checks::refinement_rows(study, &results.cases);
        let mut gci = super::checks::gci_records(study, &depth_study);
        gci.extend(super::checks::refinement_gci(study, &refinement));
        results.measures = CantileverMeasures {
            elastica,
            gci,
            depth_study,
            refinement,
        };
        results.checks = super::checks::compute_checks(results);
    }
    /// `domains.json`: the snapshots of the cases a figure draws (`snapshot_every` > 0).
    fn write_side_files(&self, dir: &Path, outputs: &[Self::Output]) -> Result<(), StudyError> {
        write_case_data(&dir.join("domains.json"), outputs, |r, s| {
            !s.is_empty() && self.cases.iter().any(|c| c.id == r.id && c.snapshot_every > 0)
        })
    }
}

/// ParaView files of an iGIMP case: its domain snapshots (the initial state, every
/// `--vtk-every` steps or the figure's interval, and the last converged step);
/// quadrilaterals in 2D, every point's hexahedron in 3D, with the background grid.
fn write_case_vtk(
    dir: &Path,
    case: &CantileverCase,
    snaps: &[DomainSnapshot],
    solid: &[SolidSnapshot],
) -> Result<(), StudyError> {
    let time = |step: usize| step as f64 / case.spec.load_steps.max(1) as f64;
    let frames: Vec<DomainFrame> = if case.spec.dimension == 3 {
        solid
            .iter()
            .map(|s| DomainFrame {
                time: time(s.step),
                step: s.step,
                dimension: 3,
                domains: s
                    .domains
                    .iter()
                    .map(|d| DomainBox::new([d[0], d[1], d[2]], [d[3], d[4], d[5]]))
                    .collect(),
                scalars: vec![],
            })
            .collect()
    } else {
        snaps
            .iter()
            .map(|s| DomainFrame {
                time: time(s.step),
                step: s.step,
                dimension: 2,
                domains: s.domains.iter().map(|&d| d.into()).collect(),
                scalars: vec![],
            })
            .collect()
    };
    let s = &case.spec;
    let grid = grid_part(s.dimension, || s.grid_2d(), || s.grid_3d());
    write_domain_frames(dir, &case.id, &frames, grid.as_ref()).map(|_| ())
}
