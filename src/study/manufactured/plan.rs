//! Validation and planning of a manufactured-solution study file: the cases of a tier and
//! their ids.

use super::{FigureKind, ManufacturedCase, ManufacturedStudy, ManufacturedSweep};
use crate::basis::method::Method;
use crate::material::constitutive::LINEAR_ELASTIC;
use crate::mpm::DomainUpdate;
use crate::problems::manufactured::{Field, ManufacturedSpec, METHODS};
use crate::problems::manufactured3d::METHODS_3D;
use crate::study::engine::distinct_cases;
use crate::study::results::SweepIndex;
use crate::study::vocabulary::{max_points_per_axis, Checker, Header};
use crate::study::{StudyError, Tier};
use std::collections::BTreeSet;

/// Most cells per side of one case: h = 1/512 in 2D (262,144 cells), 1/64 in 3D (262,144
/// cells, ~2e6 points at 2×2×2: the direct solver's limit, README "Measured").
const fn max_cells(dimension: i64) -> i64 {
    if dimension == 3 {
        64
    } else {
        512
    }
}

/// The short name of a domain update in case ids.
pub fn update_tag(u: DomainUpdate) -> &'static str {
    match u {
        DomainUpdate::Stretch => "stretch",
        DomainUpdate::FDiagonal => "fdiag",
        DomainUpdate::Fixed => "fixed",
    }
}

/// The sweep's lists after the tier's overrides.
pub(super) struct SweepPlan {
    pub methods: Vec<Method>,
    pub cells: Vec<i64>,
    pub points_per_cell: Vec<i64>,
}

impl ManufacturedStudy {
    pub(super) fn check(&self, file: &str) -> Result<(), StudyError> {
        let chk = Checker { file };
        chk.header(Header {
            schema: self.schema,
            problem: &self.problem,
            expected_problem: "manufactured",
            name: &self.name,
            summary: &self.summary,
            report_file: &self.report_file,
        })?;
        if !matches!(self.dimension, 2 | 3) {
            return Err(chk.err("dimension", self.dimension, "must be 2 or 3"));
        }
        let (dimension, methods) = (self.dimension, self.methods());
        let material = chk.material("material", &self.material)?;
        material
            .require_model(&LINEAR_ELASTIC, crate::problems::manufactured::HENCKY_ONLY)
            .map_err(|e| chk.err(e.field, e.value, e.allowed))?;
        chk.count("load_steps", self.load_steps, 1, 10_000)?;
        chk.newton("newton", &self.newton)?;
        chk.non_empty("sweeps", &self.sweeps)?;
        let mut ids = BTreeSet::new();
        for (i, s) in self.sweeps.iter().enumerate() {
            chk.unique_ident(&format!("sweeps[{i}].id"), &s.id, &mut ids)?;
            chk.text(&format!("sweeps[{i}].title"), &s.title)?;
            chk.non_empty(&format!("sweeps[{i}].domain_updates"), &s.domain_updates)?;
            if !s.methods.iter().any(|m| m.uses_domain_update())
                && s.domain_updates != [DomainUpdate::Stretch]
            {
                return Err(chk.err(
                    format!("sweeps[{i}].domain_updates"),
                    serde_json::to_string(&s.domain_updates).unwrap_or_default(),
                    "must be left out (its default is [\"stretch\"]): none of the sweep's methods updates point domains (only the domain-averaged families, e.g. igimp, do)",
                ));
            }
            if let Some(n) = s.fit_points {
                chk.count(&format!("sweeps[{i}].fit_points"), n, 2, 100)?;
            }
            for tier in [Tier::Full, Tier::Quick] {
                let Some(plan) = self.plan(s, tier) else { continue };
                let k = |f: &str| {
                    format!(
                        "sweeps[{i}].{}{f}",
                        if tier == Tier::Quick { "quick." } else { "" }
                    )
                };
                chk.non_empty(&k("methods"), &plan.methods)?;
                chk.non_empty(&k("cells"), &plan.cells)?;
                let levels: BTreeSet<i64> = plan.cells.iter().copied().collect();
                if let Some(n) = s.fit_points.filter(|&n| n as usize > levels.len()) {
                    // A fit over more levels than the tier runs would silently use fewer.
                    return Err(chk.err(
                        format!("sweeps[{i}].fit_points"),
                        n,
                        format!(
                            "must be at most the {} cell counts {} runs",
                            levels.len(),
                            k("cells")
                        ),
                    ));
                }
                chk.non_empty(&k("points_per_cell"), &plan.points_per_cell)?;
                for (j, m) in plan.methods.iter().enumerate() {
                    m.expect_one_of(self.problem_name(), methods)
                        .map_err(|e| chk.err(k(&format!("methods[{j}]")), m.name(), e.allowed))?;
                }
                for (j, &n) in plan.cells.iter().enumerate() {
                    chk.count(&k(&format!("cells[{j}]")), n, 1, max_cells(dimension))?;
                }
                for (j, &p) in plan.points_per_cell.iter().enumerate() {
                    chk.count(
                        &k(&format!("points_per_cell[{j}]")),
                        p,
                        1,
                        max_points_per_axis(dimension as u32),
                    )?;
                }
                let scope = k("");
                for c in self.sweep_cases(s, &plan) {
                    c.spec
                        .validate()
                        .map_err(|e| chk.case_input(scope.trim_end_matches('.'), &c.id, e))?;
                }
            }
        }
        let sweep = |key: String, id: &str| -> Result<&ManufacturedSweep, StudyError> {
            self.sweeps
                .iter()
                .find(|s| s.id == id)
                .ok_or_else(|| chk.err(key, id, "must name a sweep"))
        };
        for (i, e) in self.expect_rate.iter().enumerate() {
            let k = |f: &str| format!("expect_rate[{i}].{f}");
            let s = sweep(k("sweep"), &e.sweep)?;
            if !s.methods.contains(&e.method) {
                return Err(chk.err(
                    k("method"),
                    e.method.name(),
                    format!("must be a method of sweep `{}`", s.id),
                ));
            }
            match (e.method.uses_material_points(), e.points_per_cell) {
                (true, None) => {
                    return Err(chk.err(k("points_per_cell"), "(missing)", "is required for mpm and igimp"))
                }
                (true, Some(p)) if !s.points_per_cell.contains(&p) => {
                    return Err(chk.err(
                        k("points_per_cell"),
                        p,
                        format!("must be one of sweep `{}`'s", s.id),
                    ))
                }
                (false, Some(p)) => return Err(chk.err(k("points_per_cell"), p, "must be absent for FEM")),
                _ => {}
            }
            if let Some(u) = e.domain_update {
                if !e.method.uses_domain_update() || !s.domain_updates.contains(&u) {
                    return Err(chk.err(
                        k("domain_update"),
                        update_tag(u),
                        "must be a domain update of the sweep, on a method that has domain updates (igimp)",
                    ));
                }
            }
            chk.positive(&k("tolerance"), e.tolerance)?;
            chk.text(&k("source"), &e.source)?;
        }
        let mut fig_ids = BTreeSet::new();
        for (i, f) in self.figures.iter().enumerate() {
            chk.unique_ident(&format!("figures[{i}].id"), &f.id, &mut fig_ids)?;
            sweep(format!("figures[{i}].sweep"), &f.sweep)?;
            match f.kind {
                FigureKind::Convergence if f.measure.is_none() => {
                    return Err(chk.err(
                        format!("figures[{i}].measure"),
                        "(missing)",
                        "convergence figures need a measure",
                    ))
                }
                FigureKind::Domains if dimension == 3 => {
                    return Err(chk.err(
                        format!("figures[{i}].kind"),
                        "domains",
                        "is a plane (dimension = 2) figure; `study --vtk` writes the 3D domains",
                    ))
                }
                FigureKind::Domains if f.cells.is_none() || f.points_per_cell.is_none() => {
                    return Err(chk.err(
                        format!("figures[{i}]"),
                        &f.id,
                        "domain figures need cells and points_per_cell",
                    ))
                }
                _ => {}
            }
        }
        Ok(())
    }

    /// The methods of the study's dimension.
    pub fn methods(&self) -> &'static [Method] {
        if self.dimension == 3 {
            &METHODS_3D
        } else {
            &METHODS
        }
    }

    fn problem_name(&self) -> &'static str {
        if self.dimension == 3 {
            "3D manufactured problem (dimension = 3)"
        } else {
            "manufactured problem (dimension = 2)"
        }
    }

    pub(super) fn plan(&self, s: &ManufacturedSweep, tier: Tier) -> Option<SweepPlan> {
        let q = &s.quick;
        let quick = tier == Tier::Quick;
        if quick && q.skip {
            return None;
        }
        let pick = |full: &Vec<i64>, over: &Option<Vec<i64>>| {
            if quick { over.clone() } else { None }.unwrap_or_else(|| full.clone())
        };
        Some(SweepPlan {
            methods: if quick { q.methods.clone() } else { None }.unwrap_or_else(|| s.methods.clone()),
            cells: pick(&s.cells, &q.cells),
            points_per_cell: pick(&s.points_per_cell, &q.points_per_cell),
        })
    }

    pub(super) fn case_spec(
        &self,
        field: Field,
        cells: i64,
        ppc: i64,
        update: DomainUpdate,
    ) -> ManufacturedSpec {
        ManufacturedSpec {
            field,
            amplitude: match field {
                Field::AxisAligned => self.amplitude.axis_aligned,
                Field::Vortex => self.amplitude.vortex,
            },
            material: self.material.material(),
            cells: cells.max(1) as usize,
            points_per_cell: ppc.max(1) as usize,
            load_steps: self.load_steps.max(1) as usize,
            newton: self.newton.settings(),
            domain_update: update,
            dimension: self.dimension.clamp(2, 3) as usize,
        }
    }

    /// `<field>-<method>[-<update>]-n<cells>[-p<ppc>]`.
    pub fn case_id(method: Method, spec: &ManufacturedSpec) -> String {
        let mut id = format!("{}-{}", spec.field.name(), method.name());
        if method.uses_domain_update() {
            id.push_str(&format!("-{}", update_tag(spec.domain_update)));
        }
        id.push_str(&format!("-n{}", spec.cells));
        if method.uses_material_points() {
            id.push_str(&format!("-p{}", spec.points_per_cell));
        }
        id
    }

    pub(super) fn sweep_cases(&self, s: &ManufacturedSweep, plan: &SweepPlan) -> Vec<ManufacturedCase> {
        let mut out = vec![];
        for &method in &plan.methods {
            let updates = if method.uses_domain_update() {
                s.domain_updates.clone()
            } else {
                vec![DomainUpdate::Stretch]
            };
            let ppcs = if method.uses_material_points() {
                plan.points_per_cell.clone()
            } else {
                vec![1]
            };
            for &update in &updates {
                for &ppc in &ppcs {
                    for &n in &plan.cells {
                        let spec = self.case_spec(s.field, n, ppc, update);
                        out.push(ManufacturedCase {
                            id: Self::case_id(method, &spec),
                            method,
                            spec,
                        });
                    }
                }
            }
        }
        out
    }

    /// Every distinct case of the tier in file order, and the case ids of each sweep.
    pub fn cases(&self, tier: Tier) -> (Vec<ManufacturedCase>, SweepIndex) {
        let sweeps = self
            .sweeps
            .iter()
            .filter_map(|s| Some((s.id.clone(), self.sweep_cases(s, &self.plan(s, tier)?))));
        distinct_cases(sweeps, |c| &c.id)
    }
}
