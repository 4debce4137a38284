//! Validation and planning of a compaction study file: the cases of a tier (methods ×
//! element sizes × points per cell × weak-node tolerances × ghost γ per sweep), their inputs
//! and ids.

use super::{CompactionCase, CompactionFigureKind, CompactionStudy, CompactionSweep};
use crate::basis::method::Method;
use crate::material::constitutive::Material;
use crate::problems::compaction::{methods, CompactionSpec};
use crate::study::engine::distinct_cases;
use crate::study::results::SweepIndex;
use crate::study::vocabulary::{max_points_per_axis, number, Checker, Header, MAX_POINTS_PER_CELL};
use crate::study::{StudyError, Tier};
use std::collections::BTreeSet;

/// A material's part of a case id: `elastic` (Hencky), `vm<yield stress>` (von Mises), else
/// the model's name.
fn material_tag(material: &Material) -> String {
    match (material.model(), material.get("yield_stress")) {
        ("linear-elastic", _) => "elastic".to_string(),
        ("von-mises", Some(y)) => format!("vm{}", number(y)),
        (model, _) => model.to_string(),
    }
}

impl CompactionStudy {
    /// The material sweep `s` solves: the `[materials.<name>]` it names, else `[material]`
    /// (checked when the study was read: [`Self::check_materials`]).
    pub(super) fn sweep_material(&self, s: &CompactionSweep) -> Material {
        match s.material.as_ref().and_then(|name| self.materials.get(name)) {
            Some(table) => table.material(),
            None => self.material.material(),
        }
    }

    /// `[material]` and every `[materials.<name>]` resolve, each sweep's `material` names one,
    /// and two different materials do not share a case-id tag ([`material_tag`]).
    fn check_materials(&self, chk: &Checker<'_>) -> Result<(), StudyError> {
        let mut tags = vec![(
            material_tag(&chk.material("material", &self.material)?),
            "material".to_string(),
        )];
        for (name, table) in &self.materials {
            let path = format!("materials.{name}");
            chk.ident(&path, name)?;
            let m = chk.material(&path, table)?;
            let tag = material_tag(&m);
            if let Some((_, other)) = tags.iter().find(|(t, _)| *t == tag) {
                return Err(chk.err(
                    path,
                    format!("{tag:?}"),
                    format!("must differ from `{other}`: both name their cases {tag:?}"),
                ));
            }
            tags.push((tag, format!("materials.{name}")));
        }
        for (i, s) in self.sweeps.iter().enumerate() {
            if let Some(name) = &s.material {
                if !self.materials.contains_key(name) {
                    let known: Vec<&str> = self.materials.keys().map(String::as_str).collect();
                    return Err(chk.err(
                        format!("sweeps[{i}].material"),
                        format!("{name:?}"),
                        format!(
                            "must name a [materials.<name>] table of the study (it has: {})",
                            if known.is_empty() {
                                "none".to_string()
                            } else {
                                known.join(", ")
                            }
                        ),
                    ));
                }
            }
        }
        Ok(())
    }

    /// Checks the header, that every sweep's cases are valid problem inputs (the solver's own
    /// validation names the field), and that references name existing sweeps and cases.
    pub(super) fn check(&self, file: &str) -> Result<(), StudyError> {
        let chk = Checker { file };
        chk.header(Header {
            schema: self.schema,
            problem: &self.problem,
            expected_problem: "compaction",
            name: &self.name,
            summary: &self.summary,
            report_file: &self.report_file,
        })?;
        chk.count("block.load_steps", self.block.load_steps, 1, 10_000)?;
        self.check_materials(&chk)?;
        if !matches!(self.block.dimension, 2 | 3) {
            return Err(chk.err("block.dimension", self.block.dimension, "must be 2 or 3"));
        }
        let dimension = self.block.dimension as usize;
        chk.newton("newton", &self.newton)?;
        chk.weak_node_tolerance("weak_nodes.tolerance", self.weak_nodes.tolerance)?;
        self.ghost
            .validate()
            .map_err(|e| chk.err("ghost", e, "must be valid ghost settings"))?;
        if self.sweeps.is_empty() {
            return Err(chk.err("sweeps", "[]", "must list at least one sweep"));
        }
        let mut ids = BTreeSet::new();
        for (i, s) in self.sweeps.iter().enumerate() {
            chk.unique_ident(&format!("sweeps[{i}].id"), &s.id, &mut ids)?;
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
                        return Err(chk.err(k(key), "[]", "must list at least one value"));
                    }
                }
                let max = max_points_per_axis(dimension as u32);
                if let Some(&p) = plan.points_per_cell.iter().find(|&&p| !(1..=max).contains(&p)) {
                    return Err(chk.err(
                        k("points_per_cell"),
                        p,
                        format!(
                            "must be integers in 1..={max} (per axis: at most {} points per cell)",
                            MAX_POINTS_PER_CELL
                        ),
                    ));
                }
                for (j, m) in plan.methods.iter().enumerate() {
                    m.expect_one_of(
                        if dimension == 3 {
                            "3D compaction (block.dimension = 3)"
                        } else {
                            "plane-strain compaction (block.dimension = 2)"
                        },
                        methods(dimension),
                    )
                    .map_err(|e| chk.err(k(&format!("methods[{j}]")), m.name(), e.allowed))?;
                }
                let scope = k("");
                for c in self.sweep_cases(s, &plan) {
                    c.spec
                        .validate()
                        .map_err(|e| chk.case_input(scope.trim_end_matches('.'), &c.id, e))?;
                }
            }
        }
        let sweep_known = |key: String, id: &str| -> Result<&CompactionSweep, StudyError> {
            self.sweeps
                .iter()
                .find(|s| s.id == id)
                .ok_or_else(|| chk.err(key, id, "must name a sweep"))
        };
        sweep_known("reference.fem_sweep".into(), &self.reference.fem_sweep)?;
        sweep_known("reference.igimp_sweep".into(), &self.reference.igimp_sweep)?;
        for (i, e) in self.expect_deviation.iter().enumerate() {
            let sweep = sweep_known(format!("expect_deviation[{i}].sweep"), &e.sweep)?;
            for m in &e.methods {
                if m.is_fem() || !sweep.methods.contains(m) {
                    return Err(chk.err(
                        format!("expect_deviation[{i}].methods"),
                        m.name(),
                        format!("must name material point methods of sweep {:?}", e.sweep),
                    ));
                }
            }
        }
        for (i, e) in self.expect_extrapolation.iter().enumerate() {
            let sweep = sweep_known(format!("expect_extrapolation[{i}].sweep"), &e.sweep)?;
            if !sweep.methods.contains(&e.method) {
                return Err(chk.err(
                    format!("expect_extrapolation[{i}].method"),
                    e.method.name(),
                    format!("must be a method of sweep {:?}", e.sweep),
                ));
            }
            if !(e.tolerance > 0.0 && e.tolerance < 1.0) {
                return Err(chk.err(
                    format!("expect_extrapolation[{i}].tolerance"),
                    e.tolerance,
                    "must lie in (0, 1) (relative)",
                ));
            }
        }
        for (i, e) in self.expect_ghost_spread.iter().enumerate() {
            sweep_known(format!("expect_ghost_spread[{i}].sweep"), &e.sweep)?;
        }
        for (i, e) in self.expect_linear_iterations.iter().enumerate() {
            sweep_known(format!("expect_linear_iterations[{i}].sweep"), &e.sweep)?;
            if !(e.max_per_solve >= 1.0 && e.max_per_solve.is_finite()) {
                return Err(chk.err(
                    format!("expect_linear_iterations[{i}].max_per_solve"),
                    e.max_per_solve,
                    "must be a finite number >= 1",
                ));
            }
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
                return Err(chk.err(
                    format!("paper_residuals[{i}].residuals"),
                    p.residuals.len(),
                    "must give one list per step",
                ));
            }
            chk.markdown_file(&format!("paper_residuals[{i}].file"), &p.file)?;
        }
        let mut fig_ids = BTreeSet::new();
        for (i, f) in self.figures.iter().enumerate() {
            chk.unique_ident(&format!("figures[{i}].id"), &f.id, &mut fig_ids)?;
            sweep_known(format!("figures[{i}].sweep"), &f.sweep)?;
            let needs_case = f.kind != CompactionFigureKind::DisplacementConvergence;
            if needs_case && (f.element_size.is_none() || f.points_per_cell.is_none()) {
                return Err(chk.err(
                    format!("figures[{i}]"),
                    &f.id,
                    "domain and residual figures need element_size and points_per_cell",
                ));
            }
            if f.kind == CompactionFigureKind::Residuals && f.step.is_none() {
                return Err(chk.err(
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
    pub(super) fn plan(&self, s: &CompactionSweep, tier: Tier) -> Option<SweepPlan> {
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

    pub(super) fn case_spec(
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
            material: self.sweep_material(s),
            weight: b.weight,
            load_steps: b.load_steps.max(1) as usize,
            newton: self.newton.settings(),
            weak_node_tolerance: tolerance,
            weak_node_treatment: self.weak_nodes.treatment,
            ghost: self
                .ghost
                .settings(ppc, self.sweep_material(s).get("yield_stress").is_some(), gamma),
            dimension: self.block.dimension as usize,
            linear_solver: s.linear_solver.unwrap_or_default(),
            ..CompactionSpec::default()
        }
    }

    pub(super) fn case_id(&self, method: Method, spec: &CompactionSpec) -> String {
        let material = material_tag(&spec.material);
        let mut id = format!("{}-{material}-h{}", method.name(), number(spec.element_size));
        // A solver other than the default names itself in the id, so that a sweep by LU
        // beside the same cases by default is two sets of cases, not one.
        use crate::solver::linear::LinearSolver;
        match spec.linear_solver {
            LinearSolver::Auto => {}
            LinearSolver::Iterative => id.push_str("-cg"),
            LinearSolver::Lu => id.push_str("-lu"),
            LinearSolver::Ldlt => id.push_str("-ldlt"),
            LinearSolver::Llt => id.push_str("-llt"),
        }
        if !method.is_fem() {
            id.push_str(&format!("-p{}", spec.points_per_cell));
            if spec.weak_node_tolerance != self.weak_nodes.tolerance {
                id.push_str(&format!("-wn{}", number(spec.weak_node_tolerance)));
            }
            if spec.ghost
                != self
                    .ghost
                    .settings(spec.points_per_cell, spec.yield_stress().is_some(), None)
            {
                id.push_str(&format!("-g{}", number(spec.ghost.gamma)));
            }
        }
        id
    }

    pub(super) fn sweep_cases(&self, s: &CompactionSweep, plan: &SweepPlan) -> Vec<CompactionCase> {
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
    pub fn cases(&self, tier: Tier) -> (Vec<CompactionCase>, SweepIndex) {
        let sweeps = self
            .sweeps
            .iter()
            .filter_map(|s| Some((s.id.clone(), self.sweep_cases(s, &self.plan(s, tier)?))));
        distinct_cases(sweeps, |c| &c.id)
    }
}

#[derive(Debug, Clone, PartialEq)]
pub(super) struct SweepPlan {
    methods: Vec<Method>,
    element_sizes: Vec<f64>,
    points_per_cell: Vec<i64>,
    tolerances: Vec<f64>,
    gammas: Vec<Option<f64>>,
}
