//! Validation and planning of a cantilever study file: the `[[cases]]` and the depth study's
//! cases (P ∝ depth³, h ∝ depth) of a tier.

use super::{CantileverCase, CantileverFigureKind, CantileverStudy, CaseSection};
use crate::problems::cantilever::{methods, CantileverSpec};
use crate::study::vocabulary::{max_points_per_axis, Checker, Header};
use crate::study::{StudyError, Tier};
use std::collections::BTreeSet;

impl CantileverStudy {
    pub(super) fn check(&self, file: &str) -> Result<(), StudyError> {
        let chk = Checker { file };
        chk.header(Header {
            schema: self.schema,
            problem: &self.problem,
            expected_problem: "cantilever",
            name: &self.name,
            summary: &self.summary,
            report_file: &self.report_file,
        })?;
        let b = &self.beam;
        let material = chk.material("material", &self.material)?;
        let what = "the elastica (bending stiffness E d^3/12)";
        chk.material_parameter("material", &material, "young_modulus", what)?;
        chk.material_parameter("material", &material, "poisson_ratio", what)?;
        chk.count("beam.load_steps", b.load_steps, 1, 10_000)?;
        if !matches!(b.dimension, 2 | 3) {
            return Err(chk.err("beam.dimension", b.dimension, "must be 2 or 3"));
        }
        let dimension = b.dimension as usize;
        chk.count(
            "beam.points_per_cell",
            b.points_per_cell,
            1,
            max_points_per_axis(dimension as u32),
        )?;
        chk.newton("newton", &self.newton)?;
        chk.weak_node_tolerance("weak_nodes.tolerance", self.weak_nodes.tolerance)?;
        let mut ids = BTreeSet::new();
        for (i, c) in self.cases.iter().enumerate() {
            chk.unique_ident(&format!("cases[{i}].id"), &c.id, &mut ids)?;
            if let Some(h) = c.element_size {
                chk.positive(&format!("cases[{i}].element_size"), h)?;
            }
            if let Some(t) = c.weak_node_tolerance {
                chk.weak_node_tolerance(&format!("cases[{i}].weak_node_tolerance"), t)?;
            }
            c.method
                .expect_one_of(
                    if dimension == 3 {
                        "3D cantilever (beam.dimension = 3)"
                    } else {
                        "plane-strain cantilever (beam.dimension = 2)"
                    },
                    methods(dimension),
                )
                .map_err(|e| chk.err(format!("cases[{i}].method"), c.method.name(), e.allowed))?;
            chk.count(&format!("cases[{i}].snapshot_every"), c.snapshot_every, 0, 10_000)?;
            if let (Some(u), false) = (c.domain_update, c.method.uses_domain_update()) {
                return Err(chk.err(
                    format!("cases[{i}].domain_update"),
                    serde_json::to_string(&u).unwrap_or_default(),
                    format!(
                        "must be absent for {}: only the domain-averaged families (e.g. igimp) update point domains",
                        c.method.name()
                    ),
                ));
            }
        }
        if self.cases.is_empty() {
            return Err(chk.err("cases", "[]", "must list at least one case"));
        }
        self.ghost
            .validate()
            .map_err(|e| chk.err("ghost", e, "must be valid ghost settings"))?;
        for (i, c) in self.cases.iter().enumerate() {
            self.case_of(c)
                .spec
                .validate()
                .map_err(|e| chk.err(format!("cases[{i}]"), e, "must be a valid cantilever input"))?;
        }
        let known = |key: String, id: &str| -> Result<(), StudyError> {
            if self.cases.iter().any(|c| c.id == id) {
                Ok(())
            } else {
                Err(chk.err(key, id, "must name a case"))
            }
        };
        if let Some(d) = &self.depth_study {
            known("depth_study.case".into(), &d.case)?;
            if let Some(&x) = d.depths.iter().find(|&&x| !(x.is_finite() && x > 0.0)) {
                return Err(chk.err("depth_study.depths", x, "must be finite and > 0"));
            }
            if d.elements_through_depth.is_empty()
                || d.elements_through_depth
                    .iter()
                    .any(|&n| !(2..=64).contains(&n) || n % 2 != 0)
            {
                return Err(chk.err(
                    "depth_study.elements_through_depth",
                    format!("{:?}", d.elements_through_depth),
                    "must list even integers in 2..=64",
                ));
            }
        }
        let mut refinement_ids = BTreeSet::new();
        for (i, r) in self.refinement.iter().enumerate() {
            chk.unique_ident(&format!("refinement[{i}].id"), &r.id, &mut refinement_ids)?;
            if r.methods.is_empty() {
                return Err(chk.err(
                    format!("refinement[{i}].methods"),
                    "[]",
                    "must list at least one method",
                ));
            }
            for m in r.methods.iter().chain([&r.reference]) {
                m.expect_one_of("the cantilever", methods(dimension))
                    .map_err(|e| chk.err(format!("refinement[{i}].methods"), m.name(), e.allowed))?;
            }
            if !r.methods.contains(&r.reference) {
                return Err(chk.err(
                    format!("refinement[{i}].reference"),
                    r.reference.name(),
                    "must be one of the refinement's methods",
                ));
            }
            if r.element_sizes.is_empty() {
                return Err(chk.err(
                    format!("refinement[{i}].element_sizes"),
                    "[]",
                    "must list at least one size",
                ));
            }
            for &h in &r.element_sizes {
                chk.positive(&format!("refinement[{i}].element_sizes"), h)?;
            }
            for &h in r.quick_element_sizes.iter().flatten() {
                if !r.element_sizes.contains(&h) {
                    return Err(chk.err(
                        format!("refinement[{i}].quick_element_sizes"),
                        h,
                        "must be among the refinement's element_sizes",
                    ));
                }
            }
        }
        for (c, _) in self.refinement_cases() {
            if self.cases.iter().any(|x| x.id == c.id) {
                return Err(chk.err(
                    "refinement",
                    &c.id,
                    "a refinement's case id `{refinement}-{method}-h{h}` must not repeat a [[cases]] id",
                ));
            }
        }
        let refinement_known = |key: String, id: &str| -> Result<&super::RefinementSection, StudyError> {
            self.refinement
                .iter()
                .find(|r| r.id == id)
                .ok_or_else(|| chk.err(key, id, "must name a refinement"))
        };
        for (i, e) in self.expect_refined.iter().enumerate() {
            let r = refinement_known(format!("expect_refined[{i}].refinement"), &e.refinement)?;
            for m in &e.methods {
                if !r.methods.contains(m) || *m == r.reference {
                    return Err(chk.err(
                        format!("expect_refined[{i}].methods"),
                        m.name(),
                        format!(
                            "must name methods of refinement {:?} other than its reference",
                            r.id
                        ),
                    ));
                }
            }
            chk.positive(&format!("expect_refined[{i}].tolerance"), e.tolerance)?;
        }
        for (i, e) in self.expect_extrapolated.iter().enumerate() {
            let r = refinement_known(format!("expect_extrapolated[{i}].refinement"), &e.refinement)?;
            if !r.methods.contains(&e.method) || e.method == r.reference {
                return Err(chk.err(
                    format!("expect_extrapolated[{i}].method"),
                    e.method.name(),
                    format!(
                        "must name a method of refinement {:?} other than its reference",
                        r.id
                    ),
                ));
            }
            chk.positive(&format!("expect_extrapolated[{i}].tolerance"), e.tolerance)?;
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
            if e.reference == e.case {
                return Err(chk.err(
                    format!("expect_agreement[{i}].reference"),
                    format!("{:?}", e.reference),
                    "must name another case than `case` (a case always agrees with itself)",
                ));
            }
        }
        for (i, e) in self.expect_collapse.iter().enumerate() {
            known(format!("expect_collapse[{i}].case"), &e.case)?;
            if !(e.fraction > 0.0 && e.fraction < 1.0) || e.window < 2 {
                return Err(chk.err(
                    format!("expect_collapse[{i}]"),
                    &e.case,
                    "fraction must lie in (0, 1) and window be >= 2",
                ));
            }
        }
        let mut fig_ids = BTreeSet::new();
        for (i, f) in self.figures.iter().enumerate() {
            chk.unique_ident(&format!("figures[{i}].id"), &f.id, &mut fig_ids)?;
            for c in &f.cases {
                known(format!("figures[{i}].cases"), c)?;
            }
            match (&f.refinement, f.kind == CantileverFigureKind::Refinement) {
                (Some(r), true) => {
                    refinement_known(format!("figures[{i}].refinement"), r)?;
                }
                (None, true) => {
                    return Err(chk.err(
                        format!("figures[{i}].refinement"),
                        "absent",
                        "a refinement figure must name its refinement",
                    ))
                }
                (Some(r), false) => {
                    return Err(chk.err(
                        format!("figures[{i}].refinement"),
                        r,
                        "only a figure of kind \"refinement\" draws a refinement",
                    ))
                }
                (None, false) => {}
            }
            if f.kind == CantileverFigureKind::Domains && f.cases.len() != 1 {
                return Err(chk.err(
                    format!("figures[{i}].cases"),
                    f.cases.len(),
                    "domain figures draw exactly one case",
                ));
            }
            if f.kind == CantileverFigureKind::Domains {
                let takes = self
                    .cases
                    .iter()
                    .find(|c| c.id == f.cases[0])
                    .is_some_and(|c| c.snapshot_every > 0);
                if !takes {
                    return Err(chk.err(
                        format!("figures[{i}].cases"),
                        format!("{:?}", f.cases[0]),
                        "a domains figure must draw a case that takes domain snapshots (set its snapshot_every > 0)",
                    ));
                }
            }
        }
        for (c, _) in self.all_cases() {
            // A case of `[[cases]]` has its own overrides there; the others (refinements, the
            // depth study) take the beam's values.
            let scope = self
                .cases
                .iter()
                .position(|s| s.id == c.id)
                .map_or_else(String::new, |j| format!("cases[{j}]"));
            c.spec.validate().map_err(|e| chk.case_input(&scope, &c.id, e))?;
        }
        Ok(())
    }
}

impl CantileverStudy {
    pub(super) fn base_spec(&self) -> CantileverSpec {
        let b = &self.beam;
        CantileverSpec {
            length: b.length,
            depth: b.depth,
            material: self.material.material(),
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
            dimension: b.dimension as usize,
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
                    element_size: c.element_size.unwrap_or(base.element_size),
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
        let refined: Vec<(CantileverCase, bool)> = self.refinement_cases();
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
        out.extend(refined);
        out
    }

    /// The id of `method`'s case at element size `h` in refinement `id`.
    pub fn refinement_case_id(id: &str, method: crate::basis::method::Method, h: f64) -> String {
        format!("{id}-{}-h{h}", method.name())
    }

    /// The refinements' cases (with their full-only flags): every method at every size on the
    /// beam's base case (domain and volume update, ghost and weak-node defaults).
    fn refinement_cases(&self) -> Vec<(CantileverCase, bool)> {
        let base = self.base_spec();
        let mut out = vec![];
        for r in &self.refinement {
            for &m in &r.methods {
                for &h in &r.element_sizes {
                    let quick = r.quick_element_sizes.as_ref().is_none_or(|q| q.contains(&h));
                    out.push((
                        CantileverCase {
                            id: Self::refinement_case_id(&r.id, m, h),
                            method: m,
                            spec: CantileverSpec {
                                element_size: h,
                                ..base
                            },
                            snapshot_every: 0,
                        },
                        !quick,
                    ));
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
