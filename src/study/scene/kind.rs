//! The scene as a study kind: one case is the scene solved by one method at one resolution
//! ([`crate::problems::scene::solve`]); its record carries every measure (and the histories
//! asked for); the kind adds each measure's reference, the fitted rates of the errors and the
//! checks.

use super::{RateRecord, ReferenceValue, SceneCase, SceneMeasures, SceneRecord, SceneResults, SceneStudy};
use crate::problems::scene::{solve, ClosedForm, Scene};
use crate::study::checks::{check_at_most, check_newton_quadratic, check_rate, CheckRecord, GciRecord};
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
        results.checks = checks(results);
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
            let mut series: BTreeMap<Series, Vec<(f64, f64)>> = BTreeMap::new();
            for c in cases.iter().filter(|c| c.solve.status.solved()) {
                if let Some(v) = c.measures.get(name) {
                    let e = r.error(*v);
                    series
                        .entry((c.method.name().to_string(), c.points_per_cell))
                        .or_default()
                        .push((c.h, e));
                }
            }
            for ((method, ppc), mut errors) in series {
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
    SceneMeasures {
        references,
        gci,
        rates,
    }
}

/// The largest relative error of `case`'s measure `name` against `r`, at the end and after
/// every step of a history (whose steps are the study's load steps).
fn largest_error(case: &SceneRecord, name: &str, r: &ReferenceValue) -> Option<f64> {
    let scale = if r.value == 0.0 { 1.0 } else { r.value.abs() };
    let mut worst = r.error(*case.measures.get(name)?);
    if let Some(h) = case.histories.get(name) {
        if h.len() == r.history.len() {
            for (v, e) in h.iter().zip(&r.history) {
                worst = worst.max((v - e).abs() / scale);
            }
        }
    }
    Some(worst)
}

fn checks(results: &SceneResults) -> Vec<CheckRecord> {
    let study = &results.study;
    let mut out = vec![];
    for e in &study.expect_reference {
        let r = results.measures.references.get(&e.measure);
        let mut cases: Vec<&SceneRecord> = results
            .sweep(&e.sweep)
            .into_iter()
            .filter(|c| e.methods.is_empty() || e.methods.contains(&c.method))
            .collect();
        if e.finest {
            let finest = |m: &StudyMethod| {
                cases
                    .iter()
                    .filter(|c| &c.method == m)
                    .map(|c| c.h)
                    .fold(f64::INFINITY, f64::min)
            };
            cases = cases
                .iter()
                .copied()
                .filter(|c| c.h == finest(&c.method))
                .collect();
        }
        if cases.is_empty() {
            // The tier does not run the sweep (a full-tier sweep in the quick tier).
            continue;
        }
        let failed = cases.iter().any(|c| !c.solve.status.solved());
        let worst = r.and_then(|r| {
            let errors: Option<Vec<f64>> = cases.iter().map(|c| largest_error(c, &e.measure, r)).collect();
            errors
                .filter(|v| !v.is_empty() && !failed)
                .map(|v| v.into_iter().fold(0.0, f64::max))
        });
        let who = if e.methods.is_empty() {
            "every method".to_string()
        } else {
            e.methods.iter().map(|m| m.name()).collect::<Vec<_>>().join(", ")
        };
        out.push(check_at_most(
            &format!("{}-{}-reference", e.sweep, e.measure),
            format!(
                "{} of {who} in sweep {}{} within {:e} of its reference (measured: the largest relative error over {} cases{})",
                e.measure,
                e.sweep,
                if e.finest { " at its finest h" } else { "" },
                e.tolerance,
                cases.len(),
                if failed { "; a case did not converge" } else { "" }
            ),
            worst,
            e.tolerance,
            &e.source,
        ));
    }
    for e in &study.expect_quadratic {
        let cases = results.sweep(&e.sweep);
        if cases.is_empty() {
            continue; // not run in this tier
        }
        let steps = cases.into_iter().flat_map(|c| c.solve.newton_histories(&c.id));
        out.push(check_newton_quadratic(
            &format!("{}-newton-quadratic", e.sweep),
            &format!("Newton in sweep {}", e.sweep),
            "every case (a failed case's last attempt included)",
            steps,
            &e.terms(),
        ));
    }
    let extent = scene_extent(study);
    for e in &study.expect_agreement {
        let cases = results.sweep(&e.sweep);
        let of = |m: &StudyMethod| -> Vec<&SceneRecord> {
            cases.iter().copied().filter(|c| &c.method == m).collect()
        };
        let (a, b) = (of(&e.methods[0]), of(&e.methods[1]));
        if a.is_empty() && b.is_empty() {
            continue;
        }
        // Every pair at one h and points per cell whose cases both converged (a failed case
        // is listed among the failures, and --check refuses it unless the study expects it);
        // a converged pair without positions leaves the check not evaluated.
        let mut worst: Option<f64> = Some(0.0);
        let (mut pairs, mut skipped) = (0, 0);
        for x in &a {
            let Some(y) = b
                .iter()
                .find(|y| y.h == x.h && y.points_per_cell == x.points_per_cell)
            else {
                continue;
            };
            if !x.solve.status.solved() || !y.solve.status.solved() {
                skipped += 1;
                continue;
            }
            pairs += 1;
            let ok = x.positions.len() == y.positions.len() && !x.positions.is_empty();
            worst = worst.filter(|_| ok).map(|w| {
                x.positions
                    .iter()
                    .zip(&y.positions)
                    .flat_map(|(p, q)| p.iter().zip(q).map(|(u, v)| (u - v).abs()))
                    .fold(w, f64::max)
            });
        }
        if pairs == 0 {
            worst = None;
        }
        out.push(check_at_most(
            &format!("{}-{}-{}-agreement", e.sweep, e.methods[0].slug(), e.methods[1].slug()),
            format!(
                "final point positions of {} and {} in sweep {} agree to {:e} of the scene's largest body extent {extent} (measured: the largest difference over {pairs} pairs of converged cases, over {extent}{})",
                e.methods[0],
                e.methods[1],
                e.sweep,
                e.tolerance,
                if skipped > 0 {
                    format!("; {skipped} pair(s) with a failed case left out")
                } else {
                    String::new()
                }
            ),
            worst.map(|w| w / extent),
            e.tolerance,
            &e.source,
        ));
    }
    for e in &study.expect_rate {
        for r in results
            .measures
            .rates
            .iter()
            .filter(|r| r.sweep == e.sweep && r.measure == e.measure && r.method == e.method)
        {
            let ppc = r
                .points_per_cell
                .map_or(String::new(), |p| format!(", {p} points per cell"));
            out.push(check_rate(
                &format!(
                    "{}-{}-{}-rate{}",
                    e.sweep,
                    e.measure,
                    e.method.name(),
                    r.points_per_cell.map_or(String::new(), |p| format!("-ppc{p}"))
                ),
                &format!(
                    "error of {} by {}{ppc} in sweep {}",
                    e.measure,
                    e.method.name(),
                    e.sweep
                ),
                r.slope,
                e.rate,
                e.tolerance,
                &e.source,
            ));
        }
    }
    out
}

/// The largest side of the bodies' bounding boxes.
fn scene_extent(study: &SceneStudy) -> f64 {
    study
        .bodies
        .iter()
        .flat_map(|b| {
            let bx = b.bounding_box();
            (0..bx.min.len())
                .map(move |a| bx.max[a] - bx.min[a])
                .collect::<Vec<f64>>()
        })
        .fold(0.0, f64::max)
}
