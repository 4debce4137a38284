//! The compaction study (§5.2): `studies/compaction.toml` → `results.json` → `report.md`,
//! `table2.md`, `table3.md` and Figures 15–18.
//!
//! A sweep is methods × element sizes × points per cell × weak-node tolerances for one
//! material (elastic, or von Mises when `yield_stress` is set). Figure 17 normalises the
//! maximum horizontal displacement by a reference: the converged Q4 FEM value of the
//! `reference.fem_sweep` (Richardson-extrapolated over its finest three meshes when they allow
//! it, else its finest mesh), or, when no FEM case converged, the finest iGIMP case of the
//! Figure 17 sweep (smallest element size, most points per cell), which the report and
//! captions then state.

use super::plane::{
    self, check_at_most, failure_record, invalid, rejection, step_records, CheckRecord, GhostSection,
    PlaneStudy, Provenance, RunSummary, Timing, WeakNodeSection,
};
use super::runner::{CaseStatus, FailureRecord, StepRecord};
use super::vtk_output::{write_domain_frames, DomainFrame};
use super::{NewtonSection, StudyError, Tier};
use crate::method::Method;
use crate::problems::compaction::{solve, CompactionSpec, DomainRecord, METHODS};
use serde::{Deserialize, Serialize};
use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// Geometry, material and loading of the block (the paper's §5.2 values in the study file).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BlockSection {
    /// Half width of the block, the modelled half (the full block is twice as wide).
    pub half_width: f64,
    pub height: f64,
    /// Background grid extent along x and y from the symmetry line / base.
    pub grid_extent: [f64; 2],
    pub young_modulus: f64,
    pub poisson_ratio: f64,
    /// Weight w of the full block at the end of loading.
    pub weight: f64,
    /// Gravity is ramped linearly over this many load steps.
    pub load_steps: i64,
}

/// Quick-tier overrides of a sweep.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SweepQuick {
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub skip: bool,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub methods: Option<Vec<Method>>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub element_sizes: Option<Vec<f64>>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub points_per_cell: Option<Vec<i64>>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub weak_node_tolerances: Option<Vec<f64>>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ghost_gammas: Option<Vec<f64>>,
}

/// Methods × element sizes × points per cell × weak-node tolerances, one material.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CompactionSweep {
    pub id: String,
    pub title: String,
    pub methods: Vec<Method>,
    /// Von Mises yield stress ρ_y; absent: linear elastic.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub yield_stress: Option<f64>,
    pub element_sizes: Vec<f64>,
    /// Material points per element along each axis (iGIMP only).
    pub points_per_cell: Vec<i64>,
    /// Defaults to `[weak_nodes.tolerance]`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub weak_node_tolerances: Option<Vec<f64>>,
    /// Ghost penalty factors γ (0 = off); defaults to the `[ghost]` section's.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ghost_gammas: Option<Vec<f64>>,
    #[serde(default)]
    pub quick: SweepQuick,
}

/// The result does not depend on γ beyond `tolerance` (relative spread) for h ≤
/// `max_element_size`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GhostSpreadExpectation {
    pub sweep: String,
    pub max_element_size: f64,
    pub tolerance: f64,
    pub source: String,
}

/// The Figure 17 normalisation.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ReferenceSection {
    /// Sweep whose FEM cases give the reference: Richardson-extrapolated over its three
    /// finest meshes when they refine by a constant ratio and converge monotonically, else
    /// its finest mesh.
    pub fem_sweep: String,
    /// The Figure 17 sweep; its finest iGIMP case is the fallback reference when no FEM case
    /// converged.
    pub igimp_sweep: String,
    pub source: String,
}

/// Every converged iGIMP case of `sweep` with h ≤ `max_element_size` lies within `tolerance`
/// (relative) of the reference.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DeviationExpectation {
    pub sweep: String,
    pub max_element_size: f64,
    pub tolerance: f64,
    pub source: String,
}

/// For each points-per-cell series of `sweep`, the distance to the reference does not grow
/// by more than `slack` (relative) from one element size to the next smaller one.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ConvergenceExpectation {
    pub sweep: String,
    pub slack: f64,
    pub source: String,
}

/// At each element size of `sweep`, the spread (max − min) / min of the displacement over
/// the non-zero weak-node tolerances is at most `tolerance`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SpreadExpectation {
    pub sweep: String,
    pub tolerance: f64,
    pub source: String,
}

/// Newton residuals printed in the paper (Tables 2 and 3), shown beside this code's.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PaperResiduals {
    /// e.g. "Table 2".
    pub table: String,
    /// Output file, e.g. `table2.md`.
    pub file: String,
    pub title: String,
    /// The iGIMP case: sweep, element size and points per cell.
    pub sweep: String,
    pub element_size: f64,
    pub points_per_cell: i64,
    pub steps: Vec<i64>,
    /// Per step, the normalised out-of-balance force after Newton iterations 1, 2, ….
    pub residuals: Vec<Vec<f64>>,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum CompactionFigureKind {
    /// Initial (grey) and final domains coloured by σ_yy (Figures 15, 18).
    Domains,
    /// Residual against Newton iteration of one load step, log scale (Figure 16).
    Residuals,
    /// Normalised maximum horizontal displacement against element size (Figure 17).
    DisplacementConvergence,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CompactionFigure {
    pub id: String,
    pub title: String,
    pub kind: CompactionFigureKind,
    pub sweep: String,
    /// The case of domain and residual figures.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub element_size: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub points_per_cell: Option<i64>,
    /// Load step of residual figures.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub step: Option<i64>,
}

/// `studies/compaction.toml`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CompactionStudy {
    pub schema: i64,
    pub name: String,
    pub summary: String,
    /// Always "compaction".
    pub problem: String,
    /// Main report file name in the output folder.
    pub report_file: String,
    pub block: BlockSection,
    pub newton: NewtonSection,
    pub weak_nodes: WeakNodeSection,
    pub ghost: GhostSection,
    pub sweeps: Vec<CompactionSweep>,
    pub reference: ReferenceSection,
    #[serde(default)]
    pub expect_deviation: Vec<DeviationExpectation>,
    #[serde(default)]
    pub expect_convergence: Vec<ConvergenceExpectation>,
    #[serde(default)]
    pub expect_weak_node_spread: Vec<SpreadExpectation>,
    /// Spread of the result over the ghost penalty factors of a sweep, per element size
    /// (and points per cell), for h ≤ `max_element_size`.
    #[serde(default)]
    pub expect_ghost_spread: Vec<GhostSpreadExpectation>,
    #[serde(default)]
    pub paper_residuals: Vec<PaperResiduals>,
    #[serde(default)]
    pub figures: Vec<CompactionFigure>,
}

/// One case to solve.
#[derive(Debug, Clone, PartialEq)]
pub struct CompactionCase {
    pub id: String,
    pub method: Method,
    pub spec: CompactionSpec,
}

fn number(x: f64) -> String {
    format!("{x}")
}

impl PlaneStudy for CompactionStudy {
    /// Checks the header, that every sweep's cases are valid problem inputs (the solver's own
    /// validation names the field), and that references name existing sweeps and cases.
    fn validate(&self, file: &str) -> Result<(), StudyError> {
        plane::check_header(
            file,
            self.schema,
            &self.problem,
            "compaction",
            &self.name,
            &self.report_file,
        )?;
        if !(1..=10_000).contains(&self.block.load_steps) {
            return Err(invalid(
                file,
                "block.load_steps",
                self.block.load_steps,
                "must be an integer in 1..=10000",
            ));
        }
        if !(1..=1000).contains(&self.newton.max_iterations) {
            return Err(invalid(
                file,
                "newton.max_iterations",
                self.newton.max_iterations,
                "must be in 1..=1000",
            ));
        }
        self.ghost
            .validate()
            .map_err(|e| invalid(file, "ghost", e, "must be valid ghost settings"))?;
        if self.sweeps.is_empty() {
            return Err(invalid(file, "sweeps", "[]", "must list at least one sweep"));
        }
        let mut ids = BTreeSet::new();
        for (i, s) in self.sweeps.iter().enumerate() {
            if !plane::ident_ok(&s.id) || !ids.insert(s.id.as_str()) {
                return Err(invalid(
                    file,
                    format!("sweeps[{i}].id"),
                    &s.id,
                    format!("must be a unique identifier ({})", super::IDENT_RULE),
                ));
            }
            for tier in [Tier::Full, Tier::Quick] {
                let Some(plan) = self.plan(s, tier) else { continue };
                let k = |f: &str| {
                    format!(
                        "sweeps[{i}].{}{f}",
                        if tier == Tier::Quick { "quick." } else { "" }
                    )
                };
                for (key, empty) in [
                    ("methods", plan.methods.is_empty()),
                    ("element_sizes", plan.element_sizes.is_empty()),
                    ("points_per_cell", plan.points_per_cell.is_empty()),
                    ("weak_node_tolerances", plan.tolerances.is_empty()),
                ] {
                    if empty {
                        return Err(invalid(file, k(key), "[]", "must list at least one value"));
                    }
                }
                let max = super::max_points_per_axis(2);
                if let Some(&p) = plan.points_per_cell.iter().find(|&&p| !(1..=max).contains(&p)) {
                    return Err(invalid(
                        file,
                        k("points_per_cell"),
                        p,
                        format!(
                            "must be integers in 1..={max} (per axis: at most {} points per cell)",
                            super::MAX_POINTS_PER_CELL
                        ),
                    ));
                }
                for (j, m) in plan.methods.iter().enumerate() {
                    m.expect_one_of("compaction", &METHODS)
                        .map_err(|e| invalid(file, k(&format!("methods[{j}]")), m.name(), e.allowed))?;
                }
                for c in self.sweep_cases(s, &plan) {
                    c.spec.validate().map_err(|e| {
                        invalid(
                            file,
                            format!("sweeps[{i}] case {}", c.id),
                            e,
                            "must be a valid compaction input",
                        )
                    })?;
                }
            }
        }
        let sweep_known = |key: String, id: &str| -> Result<&CompactionSweep, StudyError> {
            self.sweeps
                .iter()
                .find(|s| s.id == id)
                .ok_or_else(|| invalid(file, key, id, "must name a sweep"))
        };
        sweep_known("reference.fem_sweep".into(), &self.reference.fem_sweep)?;
        sweep_known("reference.igimp_sweep".into(), &self.reference.igimp_sweep)?;
        for (i, e) in self.expect_deviation.iter().enumerate() {
            sweep_known(format!("expect_deviation[{i}].sweep"), &e.sweep)?;
        }
        for (i, e) in self.expect_ghost_spread.iter().enumerate() {
            sweep_known(format!("expect_ghost_spread[{i}].sweep"), &e.sweep)?;
        }
        for (i, e) in self.expect_convergence.iter().enumerate() {
            sweep_known(format!("expect_convergence[{i}].sweep"), &e.sweep)?;
        }
        for (i, e) in self.expect_weak_node_spread.iter().enumerate() {
            sweep_known(format!("expect_weak_node_spread[{i}].sweep"), &e.sweep)?;
        }
        for (i, p) in self.paper_residuals.iter().enumerate() {
            sweep_known(format!("paper_residuals[{i}].sweep"), &p.sweep)?;
            if p.steps.len() != p.residuals.len() {
                return Err(invalid(
                    file,
                    format!("paper_residuals[{i}].residuals"),
                    p.residuals.len(),
                    "must give one list per step",
                ));
            }
            if !(p.file.ends_with(".md") && plane::ident_ok(p.file.trim_end_matches(".md"))) {
                return Err(invalid(
                    file,
                    format!("paper_residuals[{i}].file"),
                    &p.file,
                    format!("must be a file name <identifier>.md ({})", super::IDENT_RULE),
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
                    format!("must be a unique identifier ({})", super::IDENT_RULE),
                ));
            }
            sweep_known(format!("figures[{i}].sweep"), &f.sweep)?;
            let needs_case = f.kind != CompactionFigureKind::DisplacementConvergence;
            if needs_case && (f.element_size.is_none() || f.points_per_cell.is_none()) {
                return Err(invalid(
                    file,
                    format!("figures[{i}]"),
                    &f.id,
                    "domain and residual figures need element_size and points_per_cell",
                ));
            }
            if f.kind == CompactionFigureKind::Residuals && f.step.is_none() {
                return Err(invalid(
                    file,
                    format!("figures[{i}].step"),
                    "(missing)",
                    "residual figures need a load step",
                ));
            }
        }
        Ok(())
    }
}

impl CompactionStudy {
    fn plan(&self, s: &CompactionSweep, tier: Tier) -> Option<SweepPlan> {
        let q = &s.quick;
        let quick = tier == Tier::Quick;
        if quick && q.skip {
            return None;
        }
        let pick = |full: &Vec<f64>, over: &Option<Vec<f64>>| {
            if quick { over.clone() } else { None }.unwrap_or_else(|| full.clone())
        };
        let default_tol = vec![self.weak_nodes.tolerance];
        Some(SweepPlan {
            methods: if quick { q.methods.clone() } else { None }.unwrap_or_else(|| s.methods.clone()),
            element_sizes: pick(&s.element_sizes, &q.element_sizes),
            points_per_cell: if quick { q.points_per_cell.clone() } else { None }
                .unwrap_or_else(|| s.points_per_cell.clone()),
            tolerances: pick(
                s.weak_node_tolerances.as_ref().unwrap_or(&default_tol),
                &q.weak_node_tolerances,
            ),
            gammas: if quick { q.ghost_gammas.clone() } else { None }
                .or_else(|| s.ghost_gammas.clone())
                .map_or(vec![None], |g| g.into_iter().map(Some).collect()),
        })
    }

    fn case_spec(
        &self,
        s: &CompactionSweep,
        h: f64,
        ppc: usize,
        tolerance: f64,
        gamma: Option<f64>,
    ) -> CompactionSpec {
        let b = &self.block;
        CompactionSpec {
            half_width: b.half_width,
            height: b.height,
            grid_extent: b.grid_extent,
            element_size: h,
            points_per_cell: ppc,
            young_modulus: b.young_modulus,
            poisson_ratio: b.poisson_ratio,
            weight: b.weight,
            yield_stress: s.yield_stress,
            load_steps: b.load_steps.max(1) as usize,
            newton: self.newton.settings(),
            weak_node_tolerance: tolerance,
            weak_node_treatment: self.weak_nodes.treatment,
            ghost: self.ghost.settings(ppc, s.yield_stress.is_some(), gamma),
            ..CompactionSpec::default()
        }
    }

    fn case_id(&self, method: Method, spec: &CompactionSpec) -> String {
        let material = match spec.yield_stress {
            None => "elastic".to_string(),
            Some(y) => format!("vm{}", number(y)),
        };
        let mut id = format!("{}-{material}-h{}", method.name(), number(spec.element_size));
        if !method.is_fem() {
            id.push_str(&format!("-p{}", spec.points_per_cell));
            if spec.weak_node_tolerance != self.weak_nodes.tolerance {
                id.push_str(&format!("-wn{}", number(spec.weak_node_tolerance)));
            }
            if spec.ghost
                != self
                    .ghost
                    .settings(spec.points_per_cell, spec.yield_stress.is_some(), None)
            {
                id.push_str(&format!("-g{}", number(spec.ghost.gamma)));
            }
        }
        id
    }

    fn sweep_cases(&self, s: &CompactionSweep, plan: &SweepPlan) -> Vec<CompactionCase> {
        let mut out = vec![];
        for &method in &plan.methods {
            let (ppcs, tols, gammas) = if method.is_fem() {
                (vec![2], vec![self.weak_nodes.tolerance], vec![None])
            } else {
                (
                    plan.points_per_cell.clone(),
                    plan.tolerances.clone(),
                    plan.gammas.clone(),
                )
            };
            for &ppc in &ppcs {
                for &h in &plan.element_sizes {
                    for &tol in &tols {
                        for &gamma in &gammas {
                            let spec = self.case_spec(s, h, ppc.max(1) as usize, tol, gamma);
                            out.push(CompactionCase {
                                id: self.case_id(method, &spec),
                                method,
                                spec,
                            });
                        }
                    }
                }
            }
        }
        out
    }

    /// Every distinct case of the tier in file order, and the case ids of each sweep.
    pub fn cases(&self, tier: Tier) -> (Vec<CompactionCase>, BTreeMap<String, Vec<String>>) {
        let mut seen = BTreeSet::new();
        let mut all = vec![];
        let mut index = BTreeMap::new();
        for s in &self.sweeps {
            let Some(plan) = self.plan(s, tier) else { continue };
            let cases = self.sweep_cases(s, &plan);
            index.insert(s.id.clone(), cases.iter().map(|c| c.id.clone()).collect());
            all.extend(cases.into_iter().filter(|c| seen.insert(c.id.clone())));
        }
        (all, index)
    }
}

#[derive(Debug, Clone, PartialEq)]
struct SweepPlan {
    methods: Vec<Method>,
    element_sizes: Vec<f64>,
    points_per_cell: Vec<i64>,
    tolerances: Vec<f64>,
    gammas: Vec<Option<f64>>,
}

/// Result of one case.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CompactionRecord {
    pub id: String,
    pub method: Method,
    /// Element size h.
    pub h: f64,
    /// Points per element along each axis; `None` (null) for FEM.
    pub points_per_cell: Option<usize>,
    pub yield_stress: Option<f64>,
    pub weak_node_tolerance: f64,
    /// Ghost penalty factor γ of the case (0: off; FEM: 0).
    pub ghost_gamma: f64,
    /// Faces carrying the ghost penalty (`cut` or `all`).
    pub ghost_faces: crate::ghost::GhostFaces,
    /// Load steps that needed cutbacks, and the failed attempts in all.
    pub steps_cut: usize,
    pub cutbacks: usize,
    pub status: CaseStatus,
    pub failure: Option<FailureRecord>,
    /// Bottom-right point's horizontal displacement plus half its domain's growth (Figure 17);
    /// converged cases only.
    pub max_horizontal_displacement: Option<f64>,
    /// The same measure at the last converged step of a failed case.
    pub last_converged_displacement: Option<f64>,
    /// Weak-node constraints applied, summed over the load steps.
    pub weak_nodes_treated: usize,
    /// Material points (iGIMP) or elements (FEM).
    pub points: usize,
    pub newton_iterations: usize,
    pub steps: Vec<StepRecord>,
}

/// The value Figure 17 is normalised by.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ReferenceRecord {
    pub value: f64,
    pub method: Method,
    /// The case(s) it comes from.
    pub cases: Vec<String>,
    /// Observed convergence order when Richardson-extrapolated.
    pub observed_order: Option<f64>,
    /// One sentence for captions and the report.
    pub description: String,
}

/// `results.json` of the compaction study.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CompactionResults {
    #[serde(flatten)]
    pub provenance: Provenance,
    pub study: CompactionStudy,
    pub sweep_cases: BTreeMap<String, Vec<String>>,
    pub cases: Vec<CompactionRecord>,
    pub reference: Option<ReferenceRecord>,
    pub checks: Vec<CheckRecord>,
    pub timing: Timing,
}

impl CompactionResults {
    pub fn case(&self, id: &str) -> Option<&CompactionRecord> {
        self.cases.iter().find(|c| c.id == id)
    }

    /// Copy with the wall-clock times zeroed.
    pub fn without_timing(&self) -> Self {
        let mut r = self.clone();
        r.timing = r.timing.zeroed();
        r
    }

    /// The cases of a sweep, in plan order.
    pub fn sweep(&self, id: &str) -> Vec<&CompactionRecord> {
        self.sweep_cases
            .get(id)
            .map_or(vec![], |ids| ids.iter().filter_map(|i| self.case(i)).collect())
    }

    /// The iGIMP case of a sweep at (h, points per cell) with the study's weak-node tolerance.
    pub fn igimp_case(&self, sweep: &str, h: f64, ppc: usize) -> Option<&CompactionRecord> {
        self.sweep(sweep).into_iter().find(|c| {
            c.method == Method::Igimp && c.h == h && c.points_per_cell == Some(ppc) && self.is_default(c)
        })
    }

    /// Does the case use the study's default treatment of nearly empty cells (weak-node
    /// tolerance and ghost γ)? FEM cases always do.
    pub fn is_default(&self, c: &CompactionRecord) -> bool {
        match c.points_per_cell {
            None => true,
            Some(p) => {
                c.weak_node_tolerance == self.study.weak_nodes.tolerance
                    && c.ghost_gamma == self.study.ghost.settings(p, c.yield_stress.is_some(), None).gamma
            }
        }
    }
}

/// A solved study: the results and the final domains of the cases the figures draw.
#[derive(Debug, Clone)]
pub struct CompactionRun {
    pub results: CompactionResults,
    pub domains: BTreeMap<String, Vec<DomainRecord>>,
    /// Cases read back from the case store (`--resume`).
    pub resumed: usize,
}

impl CompactionRun {
    pub fn summary(&self) -> RunSummary {
        RunSummary::new(self.results.cases.iter().map(|c| c.status), &self.results.checks)
    }
}

fn solve_case(case: &CompactionCase) -> (CompactionRecord, Vec<DomainRecord>) {
    let s = &case.spec;
    let mut rec = CompactionRecord {
        id: case.id.clone(),
        method: case.method,
        h: s.element_size,
        points_per_cell: (!case.method.is_fem()).then_some(s.points_per_cell),
        yield_stress: s.yield_stress,
        weak_node_tolerance: s.weak_node_tolerance,
        ghost_gamma: if case.method.is_fem() { 0.0 } else { s.ghost.gamma },
        ghost_faces: s.ghost.faces,
        steps_cut: 0,
        cutbacks: 0,
        status: CaseStatus::Rejected,
        failure: None,
        max_horizontal_displacement: None,
        last_converged_displacement: None,
        weak_nodes_treated: 0,
        points: 0,
        newton_iterations: 0,
        steps: vec![],
    };
    let outcome = solve(s, case.method);
    match outcome {
        Err(e) => {
            rec.failure = Some(rejection(e.to_string()));
            (rec, vec![])
        }
        Ok(o) => {
            rec.steps = step_records(&o.steps);
            rec.newton_iterations = o.steps.iter().map(|s| s.newton.iterations()).sum();
            rec.weak_nodes_treated = o.weak_nodes_treated;
            rec.steps_cut = o.steps.iter().filter(|s| s.cutbacks() > 0).count();
            rec.cutbacks = o.steps.iter().map(|s| s.cutbacks()).sum();
            rec.points = o.size;
            let u = o
                .max_horizontal_displacement
                .is_finite()
                .then_some(o.max_horizontal_displacement);
            match &o.failure {
                Some(e) => {
                    rec.status = CaseStatus::Failed;
                    rec.failure = Some(failure_record(e));
                    rec.last_converged_displacement = u;
                }
                None => {
                    rec.status = CaseStatus::Converged;
                    rec.max_horizontal_displacement = u;
                }
            }
            (rec, o.domains)
        }
    }
}

/// Richardson extrapolation of three values on meshes refined by a constant ratio r
/// (coarse to fine): (limit, observed order). `None` if the differences do not shrink.
pub fn richardson(values: [f64; 3], ratio: f64) -> Option<(f64, f64)> {
    let (d1, d2) = (values[1] - values[0], values[2] - values[1]);
    if d1 == 0.0 || d2 == 0.0 || d1.signum() != d2.signum() || d2.abs() >= d1.abs() {
        return None;
    }
    let p = (d1 / d2).ln() / ratio.ln();
    Some((values[2] + d2 / (ratio.powf(p) - 1.0), p))
}

fn figure17_reference(results: &CompactionResults) -> Option<ReferenceRecord> {
    let mut fem: Vec<&CompactionRecord> = results
        .sweep(&results.study.reference.fem_sweep)
        .into_iter()
        .filter(|c| c.method.is_fem() && c.max_horizontal_displacement.is_some())
        .collect();
    fem.sort_by(|a, b| b.h.total_cmp(&a.h));
    if let Some(finest) = fem.last() {
        let n = fem.len();
        let u = |c: &CompactionRecord| c.max_horizontal_displacement.unwrap_or(f64::NAN);
        if n >= 3 {
            let (a, b, c) = (fem[n - 3], fem[n - 2], fem[n - 1]);
            let r = a.h / b.h;
            if ((b.h / c.h) - r).abs() < 1e-9 * r {
                if let Some((limit, p)) = richardson([u(a), u(b), u(c)], r) {
                    return Some(ReferenceRecord {
                        value: limit,
                        method: finest.method,
                        cases: vec![a.id.clone(), b.id.clone(), c.id.clone()],
                        observed_order: Some(p),
                        description: format!(
                            "{} extrapolated from h = {}, {}, {} (observed order {p:.2})",
                            finest.method.label(),
                            a.h,
                            b.h,
                            c.h
                        ),
                    });
                }
            }
        }
        return Some(ReferenceRecord {
            value: u(finest),
            method: finest.method,
            cases: vec![finest.id.clone()],
            observed_order: None,
            description: format!("finest {} mesh, h = {}", finest.method.label(), finest.h),
        });
    }
    let finest = results
        .sweep(&results.study.reference.igimp_sweep)
        .into_iter()
        .filter(|c| c.method == Method::Igimp && c.max_horizontal_displacement.is_some())
        .min_by(|a, b| {
            a.h.total_cmp(&b.h)
                .then(b.points_per_cell.cmp(&a.points_per_cell))
        })?;
    Some(ReferenceRecord {
        value: finest.max_horizontal_displacement?,
        method: Method::Igimp,
        cases: vec![finest.id.clone()],
        observed_order: None,
        description: format!(
            "finest iGIMP case (h = {}, {}×{} points per cell): the study has no converged FEM reference sweep",
            finest.h,
            finest.points_per_cell.unwrap_or(0),
            finest.points_per_cell.unwrap_or(0)
        ),
    })
}

fn compute_checks(results: &CompactionResults) -> Vec<CheckRecord> {
    let mut out = vec![];
    let reference = results.reference.as_ref().map(|r| r.value);
    let igimp = |sweep: &str| -> Vec<&CompactionRecord> {
        results
            .sweep(sweep)
            .into_iter()
            .filter(|c| c.method == Method::Igimp && c.max_horizontal_displacement.is_some())
            .collect()
    };
    let deviation = |c: &CompactionRecord| -> Option<f64> {
        Some((c.max_horizontal_displacement? / reference? - 1.0).abs())
    };
    let against = results
        .reference
        .as_ref()
        .map_or("no reference".into(), |r| r.description.clone());
    for e in &results.study.expect_deviation {
        let devs: Vec<f64> = igimp(&e.sweep)
            .into_iter()
            .filter(|c| c.h <= e.max_element_size)
            .filter_map(deviation)
            .collect();
        let measured = (!devs.is_empty()).then(|| devs.iter().copied().fold(0.0, f64::max));
        out.push(check_at_most(
            &format!(
                "{}-within-{}pc-h{}",
                e.sweep,
                100.0 * e.tolerance,
                e.max_element_size
            ),
            format!(
                "largest abs(u/u_ref − 1) over the {} completed iGIMP cases with h ≤ {} (u_ref: {against})",
                devs.len(),
                e.max_element_size
            ),
            measured,
            e.tolerance,
            &e.source,
        ));
    }
    for e in &results.study.expect_convergence {
        let cases = igimp(&e.sweep);
        let ppcs: BTreeSet<usize> = cases.iter().filter_map(|c| c.points_per_cell).collect();
        let mut worst: Option<f64> = None;
        let mut series = 0;
        for p in ppcs {
            let mut s: Vec<&CompactionRecord> = cases
                .iter()
                .copied()
                .filter(|c| c.points_per_cell == Some(p) && results.is_default(c))
                .collect();
            s.sort_by(|a, b| b.h.total_cmp(&a.h));
            let d: Vec<f64> = s.iter().filter_map(|c| deviation(c)).collect();
            if d.len() >= 2 {
                series += 1;
                for w in d.windows(2) {
                    let growth = w[1] - w[0];
                    worst = Some(worst.map_or(growth, |x: f64| x.max(growth)));
                }
            }
        }
        out.push(check_at_most(
            &format!("{}-converges", e.sweep),
            format!(
                "largest growth of abs(u/u_ref − 1) from one element size to the next smaller, over {series} points-per-cell series (u_ref: {against})"
            ),
            worst,
            e.slack,
            &e.source,
        ));
    }
    for e in &results.study.expect_weak_node_spread {
        let cases: Vec<&CompactionRecord> = igimp(&e.sweep)
            .into_iter()
            .filter(|c| c.weak_node_tolerance > 0.0)
            .collect();
        let hs: BTreeSet<u64> = cases.iter().map(|c| c.h.to_bits()).collect();
        let mut worst: Option<f64> = None;
        for h in hs {
            let u: Vec<f64> = cases
                .iter()
                .filter(|c| c.h.to_bits() == h)
                .filter_map(|c| c.max_horizontal_displacement)
                .collect();
            if let Some(spread) = relative_spread(&u) {
                worst = Some(worst.map_or(spread, |w: f64| w.max(spread)));
            }
        }
        out.push(check_at_most(
            &format!("{}-weak-node-spread", e.sweep),
            "largest (max − min)/min of the displacement over the non-zero weak-node tolerances at one element size".into(),
            worst,
            e.tolerance,
            &e.source,
        ));
    }
    for e in &results.study.expect_ghost_spread {
        let cases: Vec<&CompactionRecord> = igimp(&e.sweep)
            .into_iter()
            .filter(|c| c.ghost_gamma > 0.0 && c.h <= e.max_element_size)
            .collect();
        let keys: BTreeSet<(u64, Option<usize>)> =
            cases.iter().map(|c| (c.h.to_bits(), c.points_per_cell)).collect();
        let mut worst: Option<f64> = None;
        let mut gammas: BTreeSet<u64> = BTreeSet::new();
        let mut incomplete = 0;
        for k in keys {
            let group: Vec<&&CompactionRecord> = cases
                .iter()
                .filter(|c| (c.h.to_bits(), c.points_per_cell) == k)
                .collect();
            gammas.extend(group.iter().map(|c| c.ghost_gamma.to_bits()));
            let u: Vec<f64> = group
                .iter()
                .filter_map(|c| c.max_horizontal_displacement)
                .collect();
            incomplete += group.len() - u.len();
            if let Some(spread) = relative_spread(&u) {
                worst = Some(worst.map_or(spread, |w: f64| w.max(spread)));
            }
        }
        let (g_lo, g_hi) = gammas
            .iter()
            .map(|&b| f64::from_bits(b))
            .fold((f64::MAX, f64::MIN), |(a, b), x| (a.min(x), b.max(x)));
        out.push(check_at_most(
            &format!("{}-ghost-spread", e.sweep),
            format!(
                "largest (max − min)/min of the displacement over ghost γ in [{}, {}] at one element size ≤ {} ({incomplete} case(s) not completed count as a failure)",
                number(g_lo),
                number(g_hi),
                e.max_element_size
            ),
            if incomplete > 0 { Some(f64::INFINITY) } else { worst },
            e.tolerance,
            &e.source,
        ));
    }
    out
}

/// (max − min)/|min| of at least two values, the spread of a sensitivity check.
fn relative_spread(u: &[f64]) -> Option<f64> {
    if u.len() < 2 {
        return None;
    }
    let (lo, hi) = u
        .iter()
        .fold((f64::MAX, f64::MIN), |(a, b), &x| (a.min(x), b.max(x)));
    Some((hi - lo) / lo.abs())
}

/// Solve every case of the tier.
pub fn run_study(study: &CompactionStudy, study_file: &str, tier: Tier) -> CompactionRun {
    run_study_with(study, study_file, tier, &plane::PlaneRunOptions::default())
        .expect("no case store, nothing to fail")
}

/// ParaView files of an iGIMP case: the initial domains and those of the last converged step
/// (σyy and the plastic multiplier as cell data).
fn write_case_vtk(
    dir: &Path,
    case: &CompactionCase,
    out: &(CompactionRecord, Vec<DomainRecord>),
) -> Result<(), StudyError> {
    let (rec, doms) = out;
    let initial = DomainFrame {
        time: 0.0,
        step: 0,
        domains: doms
            .iter()
            .map(|d| [d.x0[0], d.x0[1], d.half0[0], d.half0[1]])
            .collect(),
        scalars: vec![],
    };
    let steps = rec.steps.len();
    let last = DomainFrame {
        time: steps as f64 / case.spec.load_steps.max(1) as f64,
        step: steps,
        domains: doms
            .iter()
            .map(|d| [d.x[0], d.x[1], d.half[0], d.half[1]])
            .collect(),
        scalars: vec![
            ("sigma_yy".into(), doms.iter().map(|d| d.sigma_yy).collect()),
            (
                "plastic_multiplier".into(),
                doms.iter().map(|d| d.plastic_multiplier).collect(),
            ),
        ],
    };
    write_domain_frames(dir, &case.id, &[initial, last]).map(|_| ())
}

/// [`run_study`] with the case store, `--resume`, `--vtk` and progress of `options`.
pub fn run_study_with(
    study: &CompactionStudy,
    study_file: &str,
    tier: Tier,
    options: &plane::PlaneRunOptions<'_>,
) -> Result<CompactionRun, StudyError> {
    let start = std::time::Instant::now();
    let (cases, sweep_cases) = study.cases(tier);
    let cost = |c: &CompactionCase| {
        let s = &c.spec;
        (s.points_per_cell * s.points_per_cell) as f64 / (s.element_size * s.element_size)
    };
    let key = |c: &CompactionCase| plane::case_key(&c.id, c.method, &c.spec, 0);
    let (solved, resumed) = plane::run_cases_stored(
        &cases,
        key,
        cost,
        solve_case,
        |(r, _): &(CompactionRecord, Vec<DomainRecord>)| r.status,
        write_case_vtk,
        options,
    )?;
    let drawn: BTreeSet<String> = study
        .figures
        .iter()
        .filter(|f| f.kind == CompactionFigureKind::Domains)
        .filter_map(|f| {
            let s = study.sweeps.iter().find(|s| s.id == f.sweep)?;
            let spec = study.case_spec(
                s,
                f.element_size?,
                f.points_per_cell? as usize,
                study.weak_nodes.tolerance,
                None,
            );
            Some(study.case_id(Method::Igimp, &spec))
        })
        .collect();
    let mut records = vec![];
    let mut domains = BTreeMap::new();
    let mut times = BTreeMap::new();
    for ((rec, doms), secs) in solved {
        times.insert(rec.id.clone(), secs);
        if drawn.contains(&rec.id) {
            domains.insert(rec.id.clone(), doms);
        }
        records.push(rec);
    }
    let mut results = CompactionResults {
        provenance: Provenance::new(study_file, tier),
        study: study.clone(),
        sweep_cases,
        cases: records,
        reference: None,
        checks: vec![],
        timing: Timing {
            wall_seconds: 0.0,
            threads: rayon::current_num_threads(),
            cases: times,
        },
    };
    results.reference = figure17_reference(&results);
    results.checks = compute_checks(&results);
    results.timing.wall_seconds = start.elapsed().as_secs_f64();
    Ok(CompactionRun {
        results,
        domains,
        resumed,
    })
}

/// Write `<out>/<name>/results.json` and `domains.json`; returns the folder.
pub fn write_outputs(out: &Path, run: &CompactionRun) -> Result<PathBuf, StudyError> {
    plane::write_outputs(out, &run.results.study.name, &run.results, &run.domains)
}

pub fn read_results(dir: &Path) -> Result<CompactionResults, StudyError> {
    plane::read_json(&dir.join("results.json"))
}
