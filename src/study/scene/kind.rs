//! The scene as a study kind: one case is the scene solved by one method at one resolution
//! ([`crate::problems::scene::solve`]); its record carries every measure (and the histories
//! asked for); the kind adds each measure's reference, the fitted rates of the errors and the
//! checks.

use super::checks::series_name;
use super::{RateRecord, ReferenceValue, SceneCase, SceneMeasures, SceneRecord, SceneResults, SceneStudy};
use crate::problems::scene::{solve, ClosedForm, Scene};
use crate::study::checks::GciRecord;
use crate::study::engine::{study_file_fields, CaseKey, Results, StudyKind, VtkTarget};
use crate::study::external::{self, StudyMethod};
use crate::study::results::{CaseStatus, SolveRecord, SweepIndex};
use crate::study::vtk_output::{write_domain_frames, DomainBox, DomainFrame};
use crate::study::{StudyError, Tier};
use std::collections::BTreeMap;
use std::path::Path;

fn solve_case(
    scene: &Scene,
    case: &SceneCase,
    study_dir: Option<&Path>,
) -> (SceneRecord, Vec<crate::problems::scene::PointRecord>) {
    let mut rec = SceneRecord {
        id: case.id.clone(),
        method: case.method.clone(),
        h: case.settings.element_size,
        points_per_cell: case
            .method
            .uses_material_points()
            .then_some(case.settings.points_per_cell),
        solve: SolveRecord::rejected(""),
        measures: BTreeMap::new(),
        histories: BTreeMap::new(),
        profiles: BTreeMap::new(),
        points: 0,
        positions: vec![],
        external: None,
    };
    let (measures, points) = match &case.method {
        StudyMethod::External(e) => {
            // The case's files stay under the study's folder; an in-memory run's in a
            // temporary folder, removed after.
            let (folder, shown, temporary) = match study_dir {
                Some(d) => (
                    d.join("external").join(&case.id),
                    format!("external/{}", case.id),
                    false,
                ),
                None => (
                    std::env::temp_dir().join(format!("igimp-ext-{}-{}", std::process::id(), case.id)),
                    String::new(),
                    true,
                ),
            };
            let o = external::solve(scene, &case.settings, e, &case.id, &folder, &shown);
            if temporary {
                let _ = std::fs::remove_dir_all(&folder);
            }
            rec.solve = o.solve;
            rec.points = o.points;
            rec.external = Some(o.record);
            if case.positions && !rec.solve.steps.is_empty() {
                rec.positions = o.positions;
            }
            (o.measures, vec![])
        }
        StudyMethod::Own(m) => match solve(scene, &case.settings, *m) {
            Err(e) => {
                rec.solve = SolveRecord::rejected(e);
                (vec![], vec![])
            }
            Ok(o) => {
                rec.solve = SolveRecord::of(&o.steps, o.failure.as_ref());
                if o.collapsed {
                    rec.solve.status = CaseStatus::Collapsed;
                }
                rec.points = o.size;
                if o.steps.is_empty() {
                    (vec![], o.points)
                } else {
                    if case.positions {
                        let d = scene.dimension;
                        rec.positions = o.points.iter().map(|p| p.x[..d].to_vec()).collect();
                    }
                    (o.measures, o.points)
                }
            }
        },
    };
    for m in &measures {
        if m.value.is_finite() && !rec.solve.steps.is_empty() {
            rec.measures.insert(m.name.clone(), m.value);
        }
        // A measure a case cannot give (an external code's domain edge) is absent, never NaN.
        if !m.history.is_empty() && m.history.iter().all(|v| v.is_finite()) {
            rec.histories.insert(m.name.clone(), m.history.clone());
        }
        if !m.profile.is_empty() && !rec.solve.steps.is_empty() {
            rec.profiles.insert(m.name.clone(), m.profile.clone());
        }
    }
    (rec, points)
}

impl StudyKind for SceneStudy {
    const PROBLEM: &'static str = "scene";
    type Case = SceneCase;
    type Output = SceneRecord;
    type Record = SceneRecord;
    type Measures = SceneMeasures;

    study_file_fields!();
    fn cases(&self, tier: Tier) -> (Vec<SceneCase>, SweepIndex) {
        self.cases(tier)
    }
    fn key(&self, c: &SceneCase) -> CaseKey {
        // The scene is part of every case's definition: editing it re-solves the cases; an
        // external case's, its adapter's manifest too.
        match &c.method {
            // A case that keeps no positions hashes as it did before positions could be
            // kept, so its stored records still resume.
            StudyMethod::Own(m) if !c.positions => {
                CaseKey::of_spec(&c.id, *m, &(&self.scene(), &c.settings), 0)
            }
            StudyMethod::Own(m) => CaseKey::of_spec(&c.id, *m, &(&self.scene(), &c.settings, true), 0),
            StudyMethod::External(e) => CaseKey {
                id: c.id.clone(),
                hash: crate::study::store::case_hash(&(
                    &c.id,
                    c.method.name(),
                    &self.scene(),
                    &c.settings,
                    c.positions,
                    crate::study::external::adapter::Adapter::find(&e.adapter)
                        .map(|a| a.text)
                        .unwrap_or_default(),
                )),
                has_vtk: false,
            },
        }
    }
    fn cost(&self, c: &SceneCase) -> f64 {
        let s = &c.settings;
        (s.points_per_cell as f64 / s.element_size).powi(self.dimension as i32) * s.load_steps as f64
    }
    fn solve(&self, c: &SceneCase, vtk: Option<&VtkTarget>) -> Result<SceneRecord, StudyError> {
        self.solve_in(c, vtk, None)
    }
    fn solve_in(
        &self,
        c: &SceneCase,
        vtk: Option<&VtkTarget>,
        study_dir: Option<&Path>,
    ) -> Result<SceneRecord, StudyError> {
        let (rec, points) = solve_case(&self.scene(), c, study_dir);
        if let (Some(v), false) = (vtk, points.is_empty()) {
            let d = self.dimension as usize;
            let boxes = |initial: bool| -> Vec<DomainBox> {
                points
                    .iter()
                    .map(|p| {
                        let (x, h) = if initial { (p.x0, p.half0) } else { (p.x, p.half) };
                        if d == 3 {
                            DomainBox::new(x, h)
                        } else {
                            DomainBox::new([x[0], x[1]], [h[0], h[1]])
                        }
                    })
                    .collect()
            };
            let stress = if d == 3 { "sigma_zz" } else { "sigma_yy" };
            let frames = [
                DomainFrame {
                    time: 0.0,
                    step: 0,
                    dimension: d,
                    domains: boxes(true),
                    scalars: vec![],
                },
                DomainFrame {
                    time: 1.0,
                    step: rec.solve.steps.len(),
                    dimension: d,
                    domains: boxes(false),
                    scalars: vec![(stress.to_string(), points.iter().map(|p| p.sigma).collect())],
                },
            ];
            write_domain_frames(&v.study_dir, &c.id, &frames, None)?;
        }
        Ok(rec)
    }
    fn record(o: &SceneRecord) -> &SceneRecord {
        o
    }
    fn measure(results: &mut Results<Self>) {
        results.measures = measures(results);
        results.checks = super::checks::checks(results);
    }
    fn write_side_files(&self, _dir: &Path, _outputs: &[SceneRecord]) -> Result<(), StudyError> {
        Ok(())
    }
}

/// Below this relative error a measure is exact to round-off and no rate is fitted: the
/// patch tests' errors are at most 1.4e-14 and an equilibrium's 3e-14 (reference/README.md
/// item 66), while Q8's error against the confined column's closed form is 2.2e-12 at 64
/// elements and still a discretisation error (rate 4.0, item 67).
const ROUND_OFF: f64 = 1e-13;

/// A series of a sweep: the method's name and the points per cell.
type Series = (String, Option<usize>);

/// The (h, value) of measure `name` in each series of `cases`, converged cases only.
fn converged_series(cases: &[&SceneRecord], name: &str) -> BTreeMap<Series, Vec<(f64, f64)>> {
    let mut series: BTreeMap<Series, Vec<(f64, f64)>> = BTreeMap::new();
    for c in cases.iter().filter(|c| c.solve.status.solved()) {
        if let Some(v) = c.measures.get(name) {
            series
                .entry((c.method.name().to_string(), c.points_per_cell))
                .or_default()
                .push((c.h, *v));
        }
    }
    series
}

/// Each measure's reference, and the fitted rates of the errors.
fn measures(results: &SceneResults) -> SceneMeasures {
    let study = &results.study;
    let scene = study.scene();
    let steps = study.load_steps.max(1) as usize;
    let mut references = BTreeMap::new();
    let mut gci = vec![];
    for m in &scene.measures {
        let Some(r) = &m.reference else { continue };
        if let Some(sweep) = &r.fem_sweep {
            let levels: Vec<(f64, f64)> = results
                .sweep(sweep)
                .into_iter()
                .filter(|c| c.solve.status.solved())
                .filter_map(|c| Some((c.h, *c.measures.get(&m.name)?)))
                .collect();
            let method = results
                .sweep(sweep)
                .first()
                .map_or("FEM".to_string(), |c| c.method.name().to_string());
            let record = GciRecord::of(sweep, method.clone(), &m.name, levels);
            if let Some(g) = &record.gci {
                references.insert(
                    m.name.clone(),
                    ReferenceValue {
                        value: g.extrapolated,
                        history: vec![],
                        source: format!(
                            "{} ({method} of sweep {sweep} at h = {}, {}, {} extrapolated, observed order {:.2}, GCI_fine {:.2e}; {})",
                            r.source, g.h[0], g.h[1], g.h[2], g.order, g.gci_fine, record.note
                        ),
                    },
                );
            }
            gci.push(record);
            continue;
        }
        let at = |t: f64| -> Option<f64> {
            match r.closed_form {
                None => r.value,
                Some(ClosedForm::ColumnDisplacement) => {
                    let c = scene.column("").ok()?;
                    Some(c.displacement(m.at.as_deref()?, t)).filter(|v| v.is_finite())
                }
                Some(form) => {
                    let p = scene.platen("", r).ok()?;
                    let axis = m
                        .component
                        .as_ref()
                        .and_then(|c| crate::problems::scene::axis_index("", c, scene.dimension).ok())?;
                    Some(match form {
                        ClosedForm::PlatenForce => p.force(t),
                        _ => p.displacement(m.at.as_deref()?, axis, t),
                    })
                }
            }
        };
        let Some(value) = at(1.0) else { continue };
        let history = if m.history && r.closed_form.is_some() {
            (1..=steps).filter_map(|k| at(k as f64 / steps as f64)).collect()
        } else {
            vec![]
        };
        references.insert(
            m.name.clone(),
            ReferenceValue {
                value,
                history,
                source: r.source.clone(),
            },
        );
    }
    let mut rates = vec![];
    for s in &study.sweeps {
        let cases = results.sweep(&s.id);
        for (name, r) in &references {
            for ((method, ppc), levels) in converged_series(&cases, name) {
                let mut errors: Vec<(f64, f64)> = levels.into_iter().map(|(h, v)| (h, r.error(v))).collect();
                errors.sort_by(|a, b| b.0.total_cmp(&a.0));
                let (h, e): (Vec<f64>, Vec<f64>) = errors.iter().copied().unzip();
                // Errors at round-off (a patch test, an equilibrium) have no rate.
                let slope = (errors.len() >= 2 && e.iter().all(|&x| x > ROUND_OFF))
                    .then(|| crate::problems::norms::fitted_rate(&h, &e))
                    .flatten();
                let method = cases
                    .iter()
                    .find(|c| c.method.name() == method)
                    .map(|c| c.method.clone())
                    .expect("a case of the series");
                rates.push(RateRecord {
                    sweep: s.id.clone(),
                    measure: name.clone(),
                    method,
                    points_per_cell: ppc,
                    errors,
                    slope,
                });
            }
        }
    }
    for e in &study.expect_extrapolation {
        if gci.iter().any(|g| g.sweep == e.sweep && g.measure == e.measure) {
            continue; // another expectation on this sweep and measure made them
        }
        for ((method, ppc), levels) in converged_series(&results.sweep(&e.sweep), &e.measure) {
            gci.push(GciRecord::of(
                &e.sweep,
                series_name(&method, ppc),
                &e.measure,
                levels,
            ));
        }
    }
    SceneMeasures {
        references,
        gci,
        rates,
    }
}
