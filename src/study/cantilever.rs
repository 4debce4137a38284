//! The cantilever study (§5.3): `studies/cantilever.toml` → `results.json` → `report.md` and
//! Figures 19–21.
//!
//! Each `[[cases]]` entry is one analysis of the beam (iGIMP with a domain and volume update
//! rule, or a FEM comparator). The elastica (plane strain, optionally plane stress too) gives
//! the analytical end displacement at every load step. The depth study repeats a case at
//! smaller depths with the load scaled by depth³ (so PL²/EI, hence the elastica, is unchanged)
//! and the element size scaled with the depth (two elements through it): the continuum beam's
//! shear and axial flexibility, which the elastica ignores, shrink with the depth, and so
//! should its difference from the elastica.
//!
//! Signs: u/L and v/L are the displacements along +x and +y over L. The load acts along −y,
//! so the elastica's deflection (positive in the load direction) is stored as −v/L.

use super::plane::{
    self, check_at_most, failure_record, invalid, rejection, step_records, CheckRecord, GhostSection,
    PlaneStudy, Provenance, RunSummary, Timing, WeakNodeSection,
};
use super::runner::{CaseStatus, FailureRecord, StepRecord};
use super::vtk_output::{write_domain_frames, DomainFrame};
use super::{NewtonSection, StudyError, Tier};
use crate::method::Method;
use crate::mpm::{DomainUpdate, VolumeUpdate};
use crate::problems::cantilever::{solve, CantileverSpec, DomainSnapshot, EndDisplacement, METHODS};
use crate::problems::elastica::{bending_stiffness, Elastica};
use serde::{Deserialize, Serialize};
use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// The beam, material, load and discretisation (the paper's §5.3 values in the study file).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BeamSection {
    pub length: f64,
    pub depth: f64,
    pub young_modulus: f64,
    pub poisson_ratio: f64,
    /// End load P (N per unit width), downwards, ramped over `load_steps`.
    pub load: f64,
    pub load_steps: i64,
    pub element_size: f64,
    /// Material points per element along each axis.
    pub points_per_cell: i64,
    /// Background grid below the beam and beyond its end/top (room for the deflection).
    pub grid_below: f64,
    pub grid_margin: f64,
}

/// One analysis of the beam.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CaseSection {
    pub id: String,
    pub title: String,
    pub method: Method,
    /// iGIMP domain update: `stretch` (eq 39, the default) or `f-diagonal` (eq 37).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub domain_update: Option<DomainUpdate>,
    /// iGIMP volume rule: `domain-product` (the paper's, the default) or `jacobian`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub volume_update: Option<VolumeUpdate>,
    /// Ghost penalty factor γ of this case (0 = off); default: the `[ghost]` section's.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ghost_gamma: Option<f64>,
    /// Weak-node tolerance of this case (the tie/fix alternative); default: `[weak_nodes]`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub weak_node_tolerance: Option<f64>,
    /// Keep the domains every this many steps (and the last) for the figures; 0: none.
    #[serde(default)]
    pub snapshot_every: i64,
    /// Leave the case out of the quick tier.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub full_only: bool,
}

/// The depth study: `case` repeated at each depth with P ∝ depth³ and h ∝ depth.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DepthStudy {
    pub case: String,
    /// Depths other than the beam's own (which is the case itself).
    pub depths: Vec<f64>,
    /// Elements through the depth, one series each (h = depth / n); the beam's own n is the
    /// case itself at its depth.
    pub elements_through_depth: Vec<i64>,
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub full_only: bool,
    pub source: String,
}

/// Final u/L and v/L of `case` within `tolerance` (relative) of the elastica.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ElasticaExpectation {
    pub case: String,
    pub tolerance: f64,
    pub source: String,
}

/// Final u/L and v/L of `case` within `tolerance` (relative) of `reference`'s.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AgreementExpectation {
    pub case: String,
    pub reference: String,
    pub tolerance: f64,
    pub source: String,
}

/// `case` completes every load step.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CompletionExpectation {
    pub case: String,
    pub source: String,
}

/// `case` fails part-way (recorded with step, reason and residuals) after its smallest domain
/// half-length fell below `fraction` of its initial value, without growing over the last
/// `window` converged steps.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CollapseExpectation {
    pub case: String,
    pub fraction: f64,
    pub window: i64,
    pub source: String,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum CantileverFigureKind {
    /// Domains of one case at several load steps (Figures 19, 20).
    Domains,
    /// u/L and v/L against load for several cases and the elastica (Figure 21).
    EndDisplacement,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CantileverFigure {
    pub id: String,
    pub title: String,
    pub kind: CantileverFigureKind,
    pub cases: Vec<String>,
    /// Domain figures: the load steps to draw (0 = initial); absent: every stored snapshot.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub steps: Option<Vec<i64>>,
    /// Domain figures: mark the loaded points.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub mark_loads: bool,
}

/// `studies/cantilever.toml`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CantileverStudy {
    pub schema: i64,
    pub name: String,
    pub summary: String,
    /// Always "cantilever".
    pub problem: String,
    pub report_file: String,
    /// Also draw and tabulate the plane-stress elastica (the solver is plane strain).
    #[serde(default)]
    pub plane_stress_elastica: bool,
    pub beam: BeamSection,
    pub newton: NewtonSection,
    pub weak_nodes: WeakNodeSection,
    pub ghost: GhostSection,
    pub cases: Vec<CaseSection>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub depth_study: Option<DepthStudy>,
    #[serde(default)]
    pub expect_completes: Vec<CompletionExpectation>,
    #[serde(default)]
    pub expect_elastica: Vec<ElasticaExpectation>,
    #[serde(default)]
    pub expect_agreement: Vec<AgreementExpectation>,
    #[serde(default)]
    pub expect_collapse: Vec<CollapseExpectation>,
    #[serde(default)]
    pub figures: Vec<CantileverFigure>,
}

/// One analysis to run.
#[derive(Debug, Clone, PartialEq)]
pub struct CantileverCase {
    pub id: String,
    pub method: Method,
    pub spec: CantileverSpec,
    pub snapshot_every: usize,
}

impl PlaneStudy for CantileverStudy {
    fn validate(&self, file: &str) -> Result<(), StudyError> {
        plane::check_header(
            file,
            self.schema,
            &self.problem,
            "cantilever",
            &self.name,
            &self.report_file,
        )?;
        let b = &self.beam;
        for (key, v, lo, hi) in [
            ("beam.load_steps", b.load_steps, 1, 10_000),
            (
                "beam.points_per_cell",
                b.points_per_cell,
                1,
                super::max_points_per_axis(2),
            ),
            ("newton.max_iterations", self.newton.max_iterations, 1, 1000),
        ] {
            if !(lo..=hi).contains(&v) {
                return Err(invalid(
                    file,
                    key,
                    v,
                    format!("must be an integer in {lo}..={hi}"),
                ));
            }
        }
        let mut ids = BTreeSet::new();
        for (i, c) in self.cases.iter().enumerate() {
            if !plane::ident_ok(&c.id) || !ids.insert(c.id.as_str()) {
                return Err(invalid(
                    file,
                    format!("cases[{i}].id"),
                    &c.id,
                    format!("must be a unique identifier ({})", super::IDENT_RULE),
                ));
            }
            c.method
                .expect_one_of("cantilever", &METHODS)
                .map_err(|e| invalid(file, format!("cases[{i}].method"), c.method.name(), e.allowed))?;
            if !(0..=10_000).contains(&c.snapshot_every) {
                return Err(invalid(
                    file,
                    format!("cases[{i}].snapshot_every"),
                    c.snapshot_every,
                    "must be in 0..=10000",
                ));
            }
        }
        if self.cases.is_empty() {
            return Err(invalid(file, "cases", "[]", "must list at least one case"));
        }
        self.ghost
            .validate()
            .map_err(|e| invalid(file, "ghost", e, "must be valid ghost settings"))?;
        for (i, c) in self.cases.iter().enumerate() {
            self.case_of(c)
                .spec
                .validate()
                .map_err(|e| invalid(file, format!("cases[{i}]"), e, "must be a valid cantilever input"))?;
        }
        let known = |key: String, id: &str| -> Result<(), StudyError> {
            if self.cases.iter().any(|c| c.id == id) {
                Ok(())
            } else {
                Err(invalid(file, key, id, "must name a case"))
            }
        };
        if let Some(d) = &self.depth_study {
            known("depth_study.case".into(), &d.case)?;
            if let Some(&x) = d.depths.iter().find(|&&x| !(x.is_finite() && x > 0.0)) {
                return Err(invalid(file, "depth_study.depths", x, "must be finite and > 0"));
            }
            if d.elements_through_depth.is_empty()
                || d.elements_through_depth
                    .iter()
                    .any(|&n| !(2..=64).contains(&n) || n % 2 != 0)
            {
                return Err(invalid(
                    file,
                    "depth_study.elements_through_depth",
                    format!("{:?}", d.elements_through_depth),
                    "must list even integers in 2..=64",
                ));
            }
        }
        for (i, e) in self.expect_completes.iter().enumerate() {
            known(format!("expect_completes[{i}].case"), &e.case)?;
        }
        for (i, e) in self.expect_elastica.iter().enumerate() {
            known(format!("expect_elastica[{i}].case"), &e.case)?;
        }
        for (i, e) in self.expect_agreement.iter().enumerate() {
            known(format!("expect_agreement[{i}].case"), &e.case)?;
            known(format!("expect_agreement[{i}].reference"), &e.reference)?;
        }
        for (i, e) in self.expect_collapse.iter().enumerate() {
            known(format!("expect_collapse[{i}].case"), &e.case)?;
            if !(e.fraction > 0.0 && e.fraction < 1.0) || e.window < 2 {
                return Err(invalid(
                    file,
                    format!("expect_collapse[{i}]"),
                    &e.case,
                    "fraction must lie in (0, 1) and window be >= 2",
                ));
            }
        }
        let mut fig_ids = BTreeSet::new();
        for (i, f) in self.figures.iter().enumerate() {
            if !plane::ident_ok(&f.id) || !fig_ids.insert(f.id.as_str()) {
                return Err(invalid(
                    file,
                    format!("figures[{i}].id"),
                    &f.id,
                    "must be a unique name",
                ));
            }
            for c in &f.cases {
                known(format!("figures[{i}].cases"), c)?;
            }
            if f.kind == CantileverFigureKind::Domains && f.cases.len() != 1 {
                return Err(invalid(
                    file,
                    format!("figures[{i}].cases"),
                    f.cases.len(),
                    "domain figures draw exactly one case",
                ));
            }
        }
        for (c, _) in self.all_cases() {
            c.spec.validate().map_err(|e| {
                invalid(
                    file,
                    format!("case {}", c.id),
                    e,
                    "must be a valid cantilever input",
                )
            })?;
        }
        Ok(())
    }
}

impl CantileverStudy {
    fn base_spec(&self) -> CantileverSpec {
        let b = &self.beam;
        CantileverSpec {
            length: b.length,
            depth: b.depth,
            young_modulus: b.young_modulus,
            poisson_ratio: b.poisson_ratio,
            load: b.load,
            load_steps: b.load_steps.max(1) as usize,
            element_size: b.element_size,
            points_per_cell: b.points_per_cell.max(1) as usize,
            grid_below: b.grid_below,
            grid_margin: b.grid_margin,
            newton: self.newton.settings(),
            weak_node_tolerance: self.weak_nodes.tolerance,
            weak_node_treatment: self.weak_nodes.treatment,
            ghost: self
                .ghost
                .settings(b.points_per_cell.max(1) as usize, false, None),
            ..CantileverSpec::default()
        }
    }

    fn case_of(&self, c: &CaseSection) -> CantileverCase {
        CantileverCase {
            id: c.id.clone(),
            method: c.method,
            spec: {
                let base = self.base_spec();
                CantileverSpec {
                    domain_update: c.domain_update.unwrap_or(base.domain_update),
                    volume_update: c.volume_update.unwrap_or(base.volume_update),
                    ghost: self.ghost.settings(base.points_per_cell, false, c.ghost_gamma),
                    weak_node_tolerance: c.weak_node_tolerance.unwrap_or(base.weak_node_tolerance),
                    ..base
                }
            },
            snapshot_every: c.snapshot_every.max(0) as usize,
        }
    }

    /// Elements through the beam's own depth.
    fn base_elements_through_depth(&self) -> i64 {
        (self.beam.depth / self.beam.element_size).round() as i64
    }

    /// The depth-study case at `depth` with `n` elements through it: P scaled by (depth/d0)³,
    /// h = depth / n.
    fn depth_case(&self, base: &CantileverCase, depth: f64, n: i64) -> CantileverCase {
        let ratio = depth / self.beam.depth;
        CantileverCase {
            id: format!("{}-depth{depth}-n{n}", base.id),
            method: base.method,
            spec: CantileverSpec {
                depth,
                load: base.spec.load * ratio.powi(3),
                element_size: depth / n.max(1) as f64,
                ..base.spec
            },
            snapshot_every: 0,
        }
    }

    /// Every case (with its full-only flag) in file order, depth-study cases last.
    fn all_cases(&self) -> Vec<(CantileverCase, bool)> {
        let mut out: Vec<(CantileverCase, bool)> = self
            .cases
            .iter()
            .map(|c| (self.case_of(c), c.full_only))
            .collect();
        if let Some(d) = &self.depth_study {
            if let Some((base, full_only)) = out.iter().find(|(c, _)| c.id == d.case).cloned() {
                for &n in &d.elements_through_depth {
                    let own = (n != self.base_elements_through_depth()).then_some(self.beam.depth);
                    for &depth in own.iter().chain(&d.depths) {
                        out.push((self.depth_case(&base, depth, n), full_only || d.full_only));
                    }
                }
            }
        }
        out
    }

    /// The cases of a tier.
    pub fn cases(&self, tier: Tier) -> Vec<CantileverCase> {
        self.all_cases()
            .into_iter()
            .filter(|(_, full_only)| tier == Tier::Full || !full_only)
            .map(|(c, _)| c)
            .collect()
    }
}

/// The elastica at one load: the end displacement in the model's axes.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ElasticaPoint {
    pub load: f64,
    /// α = PL²/EI.
    pub alpha: f64,
    pub u_over_l: f64,
    /// −(deflection in the load direction)/L.
    pub v_over_l: f64,
}

/// The elastica load path of one beam.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ElasticaPath {
    pub plane_strain: bool,
    pub bending_stiffness: f64,
    pub points: Vec<ElasticaPoint>,
}

fn elastica_path(spec: &CantileverSpec, plane_strain: bool) -> Option<ElasticaPath> {
    let ei = bending_stiffness(spec.young_modulus, spec.poisson_ratio, spec.depth, plane_strain).ok()?;
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

/// Result of one case.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CantileverRecord {
    pub id: String,
    pub method: Method,
    pub domain_update: Option<DomainUpdate>,
    pub volume_update: Option<VolumeUpdate>,
    pub depth: f64,
    pub load: f64,
    pub element_size: f64,
    pub load_steps: usize,
    pub status: CaseStatus,
    pub failure: Option<FailureRecord>,
    /// End displacement (mean of the two loaded points) after each converged step.
    pub end: Vec<EndDisplacement>,
    /// Final u/L and v/L (converged cases only).
    pub u_over_l: Option<f64>,
    pub v_over_l: Option<f64>,
    /// Plane-strain elastica of this beam at the full load, and the relative differences
    /// (continuum − elastica)/|elastica|.
    pub elastica: Option<ElasticaPoint>,
    pub difference_u: Option<f64>,
    pub difference_v: Option<f64>,
    /// Initial domain half-length and the smallest half-length after each converged step.
    pub initial_half_length: f64,
    pub min_half_length: Vec<f64>,
    /// Indices of the two loaded points in the domain snapshots.
    pub loaded_points: Option<[usize; 2]>,
    pub newton_iterations: usize,
    pub steps: Vec<StepRecord>,
}

/// One row of the depth study.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DepthRow {
    pub case: String,
    pub elements_through_depth: i64,
    pub depth: f64,
    pub load: f64,
    pub element_size: f64,
    pub u_over_l: Option<f64>,
    pub v_over_l: Option<f64>,
    pub difference_u: Option<f64>,
    pub difference_v: Option<f64>,
}

/// `results.json` of the cantilever study.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CantileverResults {
    #[serde(flatten)]
    pub provenance: Provenance,
    pub study: CantileverStudy,
    pub cases: Vec<CantileverRecord>,
    /// Plane strain first, then plane stress when asked for.
    pub elastica: Vec<ElasticaPath>,
    pub depth_study: Vec<DepthRow>,
    pub checks: Vec<CheckRecord>,
    pub timing: Timing,
}

impl CantileverResults {
    pub fn case(&self, id: &str) -> Option<&CantileverRecord> {
        self.cases.iter().find(|c| c.id == id)
    }
    pub fn without_timing(&self) -> Self {
        let mut r = self.clone();
        r.timing = r.timing.zeroed();
        r
    }
}

/// A solved study: results and the domain snapshots per case.
#[derive(Debug, Clone)]
pub struct CantileverRun {
    pub results: CantileverResults,
    pub snapshots: BTreeMap<String, Vec<DomainSnapshot>>,
    /// Cases read back from the case store (`--resume`).
    pub resumed: usize,
}

impl CantileverRun {
    pub fn summary(&self) -> RunSummary {
        RunSummary::new(self.results.cases.iter().map(|c| c.status), &self.results.checks)
    }
}

/// Solve one case, taking domain snapshots every `snapshot_every` steps (0: none).
fn solve_case_snapshots(
    case: &CantileverCase,
    snapshot_every: usize,
) -> (CantileverRecord, Vec<DomainSnapshot>) {
    let s = &case.spec;
    let igimp = case.method == Method::Igimp;
    let mut rec = CantileverRecord {
        id: case.id.clone(),
        method: case.method,
        domain_update: igimp.then_some(s.domain_update),
        volume_update: igimp.then_some(s.volume_update),
        depth: s.depth,
        load: s.load,
        element_size: s.element_size,
        load_steps: s.load_steps,
        status: CaseStatus::Rejected,
        failure: None,
        end: vec![],
        u_over_l: None,
        v_over_l: None,
        elastica: elastica_path(s, true).and_then(|p| p.points.last().copied()),
        difference_u: None,
        difference_v: None,
        initial_half_length: 0.5 * s.element_size / s.points_per_cell as f64,
        min_half_length: vec![],
        loaded_points: None,
        newton_iterations: 0,
        steps: vec![],
    };
    let outcome = solve(s, case.method, snapshot_every);
    let o = match outcome {
        Err(e) => {
            rec.failure = Some(rejection(e.to_string()));
            return (rec, vec![]);
        }
        Ok(o) => o,
    };
    rec.steps = step_records(&o.steps);
    rec.newton_iterations = o.steps.iter().map(|s| s.newton.iterations()).sum();
    rec.end = o.end;
    rec.min_half_length = o.min_half_length;
    rec.loaded_points = o.loaded_points;
    match &o.failure {
        Some(e) => {
            rec.status = CaseStatus::Failed;
            rec.failure = Some(failure_record(e));
        }
        None => {
            rec.status = CaseStatus::Converged;
            if let Some(last) = rec.end.last() {
                rec.u_over_l = Some(last.u_over_l);
                rec.v_over_l = Some(last.v_over_l);
            }
            if let (Some(e), Some(u), Some(v)) = (rec.elastica, rec.u_over_l, rec.v_over_l) {
                rec.difference_u = Some((u - e.u_over_l) / e.u_over_l.abs());
                rec.difference_v = Some((v - e.v_over_l) / e.v_over_l.abs());
            }
        }
    }
    // Keep one snapshot per step (a failing step repeats the last converged state).
    let mut snaps = o.snapshots;
    snaps.dedup_by_key(|s| s.step);
    (rec, snaps)
}

fn largest_difference(du: Option<f64>, dv: Option<f64>) -> Option<f64> {
    Some(du?.abs().max(dv?.abs()))
}

fn compute_checks(results: &CantileverResults) -> Vec<CheckRecord> {
    let study = &results.study;
    let mut out = vec![];
    for e in &study.expect_completes {
        let c = results.case(&e.case);
        out.push(check_at_most(
            &format!("{}-completes", e.case),
            format!(
                "load steps not completed by `{}` (status {})",
                e.case,
                c.map_or("not run", |c| plane::status_word(c.status))
            ),
            c.map(|c| (c.load_steps - c.end.len()) as f64),
            0.0,
            &e.source,
        ));
    }
    for e in &study.expect_elastica {
        let c = results.case(&e.case);
        out.push(check_at_most(
            &format!("{}-vs-elastica", e.case),
            format!("largest abs(Δ)/abs(elastica) of the final u/L, v/L of `{}` against the plane-strain elastica", e.case),
            c.and_then(|c| largest_difference(c.difference_u, c.difference_v)),
            e.tolerance,
            &e.source,
        ));
    }
    for e in &study.expect_agreement {
        let diff = (|| {
            let (a, b) = (results.case(&e.case)?, results.case(&e.reference)?);
            let du = (a.u_over_l? - b.u_over_l?) / b.u_over_l?.abs();
            let dv = (a.v_over_l? - b.v_over_l?) / b.v_over_l?.abs();
            Some(du.abs().max(dv.abs()))
        })();
        let rstatus = results.case(&e.reference).map_or("not run".to_string(), |c| {
            format!(
                "{}{}",
                plane::status_word(c.status),
                c.failure
                    .as_ref()
                    .map_or(String::new(), |f| format!(": {}", f.reason))
            )
        });
        out.push(check_at_most(
            &format!("{}-vs-{}", e.case, e.reference),
            format!(
                "largest abs(Δ)/abs(reference) of the final u/L, v/L of `{}` against `{}` ({rstatus})",
                e.case, e.reference
            ),
            diff,
            e.tolerance,
            &e.source,
        ));
    }
    for e in &study.expect_collapse {
        let c = results.case(&e.case);
        let (measured, pass, what) = match c {
            None => (None, None, "not run".to_string()),
            Some(c) => {
                // The failing step's residuals are empty when the failure comes before its
                // first Newton solve (a collapsed domain cannot be evaluated); the converged
                // steps' histories are in `steps`.
                let failed_part_way = c.status == CaseStatus::Failed
                    && c.failure
                        .as_ref()
                        .is_some_and(|f| f.step > 1 && f.step <= c.load_steps && !f.reason.is_empty());
                let m = &c.min_half_length;
                let w = (e.window as usize).min(m.len());
                let shrinking = w >= 2 && m[m.len() - w..].windows(2).all(|p| p[1] <= p[0]);
                let ratio = m.last().map(|&x| x / c.initial_half_length);
                (
                    ratio,
                    ratio.map(|r| failed_part_way && shrinking && r < e.fraction),
                    format!(
                        "failed part-way with step and reason recorded: {failed_part_way} (step {}, {} residuals of the failing step); smallest half-length non-increasing over the last {w} converged steps: {shrinking}",
                        c.failure.as_ref().map_or(0, |f| f.step),
                        c.failure.as_ref().map_or(0, |f| f.residuals.len())
                    ),
                )
            }
        };
        out.push(CheckRecord {
            id: format!("{}-collapses", e.case),
            description: format!(
                "`{}`: smallest domain half-length at the last converged step over its initial value; {what}",
                e.case
            ),
            measured,
            limit: e.fraction,
            pass,
            source: e.source.clone(),
        });
    }
    if let Some(d) = &study.depth_study {
        let mut growth: Option<f64> = None;
        let mut series = 0;
        for &n in &d.elements_through_depth {
            let diffs: Vec<f64> = results
                .depth_study
                .iter()
                .filter(|r| r.elements_through_depth == n)
                .filter_map(|r| largest_difference(r.difference_u, r.difference_v))
                .collect();
            if diffs.len() >= 2 {
                series += 1;
                for w in diffs.windows(2) {
                    growth = Some(growth.map_or(w[1] - w[0], |g: f64| g.max(w[1] - w[0])));
                }
            }
        }
        out.push(check_at_most(
            "depth-study-shrinks",
            format!(
                "largest growth of the continuum − elastica difference (largest of abs(Δu), abs(Δv)) from one depth to the next smaller at fixed PL²/EI, over {series} series of fixed elements through the depth"
            ),
            growth,
            0.0,
            &d.source,
        ));
    }
    out
}

fn depth_rows(study: &CantileverStudy, records: &[CantileverRecord]) -> Vec<DepthRow> {
    let Some(d) = &study.depth_study else {
        return vec![];
    };
    let mut rows: Vec<DepthRow> = records
        .iter()
        .filter(|r| r.id == d.case || r.id.starts_with(&format!("{}-depth", d.case)))
        .map(|r| DepthRow {
            case: r.id.clone(),
            elements_through_depth: (r.depth / r.element_size).round() as i64,
            depth: r.depth,
            load: r.load,
            element_size: r.element_size,
            u_over_l: r.u_over_l,
            v_over_l: r.v_over_l,
            difference_u: r.difference_u,
            difference_v: r.difference_v,
        })
        .collect();
    rows.sort_by(|a, b| {
        a.elements_through_depth
            .cmp(&b.elements_through_depth)
            .then(b.depth.total_cmp(&a.depth))
    });
    rows
}

/// Solve every case of the tier.
pub fn run_study(study: &CantileverStudy, study_file: &str, tier: Tier) -> CantileverRun {
    run_study_with(study, study_file, tier, &plane::PlaneRunOptions::default())
        .expect("no case store, nothing to fail")
}

/// ParaView files of an iGIMP case: its domain snapshots (the initial state, every
/// `--vtk-every` steps or the figure's interval, and the last converged step).
fn write_case_vtk(
    dir: &Path,
    case: &CantileverCase,
    out: &(CantileverRecord, Vec<DomainSnapshot>),
) -> Result<(), StudyError> {
    let frames: Vec<DomainFrame> = out
        .1
        .iter()
        .map(|s| DomainFrame {
            time: s.step as f64 / case.spec.load_steps.max(1) as f64,
            step: s.step,
            domains: s.domains.clone(),
            scalars: vec![],
        })
        .collect();
    write_domain_frames(dir, &case.id, &frames).map(|_| ())
}

/// [`run_study`] with the case store, `--resume`, `--vtk` and progress of `options`.
pub fn run_study_with(
    study: &CantileverStudy,
    study_file: &str,
    tier: Tier,
    options: &plane::PlaneRunOptions<'_>,
) -> Result<CantileverRun, StudyError> {
    let start = std::time::Instant::now();
    let cases = study.cases(tier);
    let cost =
        |c: &CantileverCase| (c.spec.length / c.spec.element_size) * (c.spec.points_per_cell as f64).powi(2);
    let key = |c: &CantileverCase| plane::case_key(&c.id, c.method, &c.spec, c.snapshot_every);
    // With --vtk every iGIMP case takes snapshots: its figure's interval, else --vtk-every,
    // else only the initial and final states.
    let solve = |c: &CantileverCase| {
        let every = match options.vtk {
            Some(v) if c.snapshot_every == 0 => {
                if v.every > 0 {
                    v.every
                } else {
                    c.spec.load_steps
                }
            }
            _ => c.snapshot_every,
        };
        solve_case_snapshots(c, every)
    };
    let (solved, resumed) = plane::run_cases_stored(
        &cases,
        key,
        cost,
        solve,
        |(r, _): &(CantileverRecord, Vec<DomainSnapshot>)| r.status,
        write_case_vtk,
        options,
    )?;
    let mut records = vec![];
    let mut snapshots = BTreeMap::new();
    let mut times = BTreeMap::new();
    for ((rec, snaps), secs) in solved {
        times.insert(rec.id.clone(), secs);
        if !snaps.is_empty() && cases.iter().any(|c| c.id == rec.id && c.snapshot_every > 0) {
            snapshots.insert(rec.id.clone(), snaps);
        }
        records.push(rec);
    }
    let base = study.base_spec();
    let mut elastica: Vec<ElasticaPath> = elastica_path(&base, true).into_iter().collect();
    if study.plane_stress_elastica {
        elastica.extend(elastica_path(&base, false));
    }
    let mut results = CantileverResults {
        provenance: Provenance::new(study_file, tier),
        study: study.clone(),
        depth_study: depth_rows(study, &records),
        cases: records,
        elastica,
        checks: vec![],
        timing: Timing {
            wall_seconds: 0.0,
            threads: rayon::current_num_threads(),
            cases: times,
        },
    };
    results.checks = compute_checks(&results);
    results.timing.wall_seconds = start.elapsed().as_secs_f64();
    Ok(CantileverRun {
        results,
        snapshots,
        resumed,
    })
}

/// Write `<out>/<name>/results.json` and `domains.json`; returns the folder.
pub fn write_outputs(out: &Path, run: &CantileverRun) -> Result<PathBuf, StudyError> {
    plane::write_outputs(out, &run.results.study.name, &run.results, &run.snapshots)
}

pub fn read_results(dir: &Path) -> Result<CantileverResults, StudyError> {
    plane::read_json(&dir.join("results.json"))
}
