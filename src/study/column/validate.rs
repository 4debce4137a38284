//! Validation of a column study file: every error names the file, the key and its allowed
//! range ([`Checker`]).

use super::{ColumnStudy, FigureKind, Sweep};
use crate::basis::method::Method;
use crate::study::vocabulary::{max_points_per_axis, short, Checker, Header};
use crate::study::StudyError;
use std::collections::BTreeSet;

const MAX_ELEMENTS: i64 = 1_000_000;
/// Most material points of one case (elements × points per cell): ~0.6 GB of point state.
const MAX_POINTS_PER_CASE: i64 = 2_000_000;
/// Most cases of one sweep (methods × weights × points per cell × elements), checked before
/// the case list is built.
const MAX_CASES_PER_SWEEP: usize = 10_000;

impl ColumnStudy {
    /// Check every value; the error names the file, the key and its allowed range.
    pub(super) fn check(&self, file: &str) -> Result<(), StudyError> {
        let c = Checker { file };
        c.header(Header {
            schema: self.schema,
            problem: "column",
            expected_problem: "column",
            name: &self.name,
            summary: &self.summary,
            report_file: &self.report_file,
        })?;
        if let Some(g) = &self.ghost {
            g.one_point_per_cell
                .validate()
                .map_err(|e| c.err("ghost.one_point_per_cell", e.value.clone(), e.allowed.clone()))?;
        }
        if !matches!(self.dimension, 1 | 3) {
            return Err(c.err("dimension", self.dimension, "must be 1 or 3"));
        }
        let col = &self.column;
        c.positive("column.length", col.length)?;
        let material = c.material("material", &self.material)?;
        let what = "the column's closed form (eqs 42-45)";
        c.material_parameter("material", &material, "young_modulus", what)?;
        let nu = c.material_parameter("material", &material, "poisson_ratio", what)?;
        if !(0.0..0.5).contains(&nu) {
            return Err(c.err("material.poisson_ratio", nu, "must lie in [0, 0.5)"));
        }
        c.positive("column.density", col.density)?;
        c.count("load_steps", self.load_steps, 1, 10_000)?;
        c.newton("newton", &self.newton)?;
        c.non_empty("sweeps", &self.sweeps)?;

        let mut ids = BTreeSet::new();
        for (i, s) in self.sweeps.iter().enumerate() {
            let k = |f: &str| format!("sweeps[{i}].{f}");
            c.ident(&k("id"), &s.id)?;
            if !ids.insert(s.id.as_str()) {
                return Err(c.err(k("id"), format!("{:?}", s.id), "must be unique among sweeps"));
            }
            c.text(&k("title"), &s.title)?;
            self.check_lists(
                &c,
                &k(""),
                &s.methods,
                &s.weights,
                &s.elements,
                &s.points_per_cell,
            )?;
            let q = &s.quick;
            self.check_lists(
                &c,
                &k("quick."),
                q.methods.as_deref().unwrap_or(&s.methods),
                q.weights.as_deref().unwrap_or(&s.weights),
                q.elements.as_deref().unwrap_or(&s.elements),
                q.points_per_cell.as_deref().unwrap_or(&s.points_per_cell),
            )?;
            if let Some(n) = s.fit_points {
                c.count(&k("fit_points"), n, 2, 1000)?;
                // A fit over more element counts than a tier runs would silently use fewer.
                let quick = (!q.skip).then(|| q.elements.as_deref().unwrap_or(&s.elements));
                for (tier, list) in [("", Some(&s.elements[..])), (" (quick tier)", quick)] {
                    let distinct: BTreeSet<i64> = list.unwrap_or(&[]).iter().copied().collect();
                    if list.is_some() && n as usize > distinct.len() {
                        return Err(c.err(
                            k("fit_points"),
                            n,
                            format!(
                                "must be at most the {} element counts the sweep runs{tier}",
                                distinct.len()
                            ),
                        ));
                    }
                }
            }
            if let Some(n) = s.load_steps {
                c.count(&k("load_steps"), n, 1, 10_000)?;
            }
            if let Some(n) = &s.newton {
                c.newton(&k("newton"), n)?;
            }
        }

        // Every case is a valid column (its derived gravity and closed form included).
        for tier in [crate::study::Tier::Full, crate::study::Tier::Quick] {
            for (i, s) in self.sweeps.iter().enumerate() {
                let Some(plan) = self.plan(s, tier) else { continue };
                let scope = match tier {
                    crate::study::Tier::Full => format!("sweeps[{i}]"),
                    crate::study::Tier::Quick => format!("sweeps[{i}].quick"),
                };
                for case in self.sweep_cases(&plan) {
                    case.spec
                        .validate()
                        .map_err(|e| c.case_input(&scope, &case.id, e))?;
                }
            }
        }
        for (i, e) in self.expect.iter().enumerate() {
            let k = |f: &str| format!("expect[{i}].{f}");
            let sweep = self.sweep_ref(&c, &k("sweep"), &e.sweep)?;
            self.check_series_ref(&c, &k(""), sweep, e.method, e.weight, e.points_per_cell)?;
            if !e.rate.is_finite() {
                return Err(c.err(k("rate"), e.rate, "must be finite"));
            }
            c.positive(&k("tolerance"), e.tolerance)?;
            c.text(&k("source"), &e.source)?;
        }
        for (i, e) in self.compare.iter().enumerate() {
            let k = |f: &str| format!("compare[{i}].{f}");
            let sweep = self.sweep_ref(&c, &k("sweep"), &e.sweep)?;
            for (key, m) in [("lower", e.lower), ("higher", e.higher)] {
                if !sweep.methods.contains(&m) {
                    return Err(c.err(
                        k(key),
                        m.name(),
                        format!("must be a method of sweep `{}`", sweep.id),
                    ));
                }
            }
            if !sweep.weights.contains(&e.weight) {
                return Err(c.err(
                    k("weight"),
                    e.weight,
                    format!("must be a weight of sweep `{}`", sweep.id),
                ));
            }
            c.text(&k("source"), &e.source)?;
        }
        for (i, p) in self.paper.iter().enumerate() {
            let k = |f: &str| format!("paper[{i}].{f}");
            c.text(&k("table"), &p.table)?;
            let sweep = self.sweep_ref(&c, &k("sweep"), &p.sweep)?;
            self.check_series_ref(&c, &k(""), sweep, p.method, p.weight, p.points_per_cell)?;
            c.non_empty(&k("elements"), &p.elements)?;
            for (j, &n) in p.elements.iter().enumerate() {
                c.count(&k(&format!("elements[{j}]")), n, 1, MAX_ELEMENTS)?;
            }
            for (key, v) in [
                ("top_displacement", &p.top_displacement),
                ("base_f", &p.base_f),
                ("f_error", &p.f_error),
            ] {
                if v.len() != p.elements.len() {
                    return Err(c.err(
                        k(key),
                        format!("{} values", v.len()),
                        format!("must give one value per element count ({})", p.elements.len()),
                    ));
                }
            }
            c.positive(&k("analytical_base_f"), p.analytical_base_f)?;
        }
        let mut fig_ids = BTreeSet::new();
        for (i, f) in self.figures.iter().enumerate() {
            let k = |x: &str| format!("figures[{i}].{x}");
            c.ident(&k("id"), &f.id)?;
            if !fig_ids.insert(f.id.as_str()) {
                return Err(c.err(k("id"), format!("{:?}", f.id), "must be unique among figures"));
            }
            c.text(&k("title"), &f.title)?;
            let sweep = self.sweep_ref(&c, &k("sweep"), &f.sweep)?;
            if !sweep.weights.contains(&f.weight) {
                return Err(c.err(
                    k("weight"),
                    f.weight,
                    format!("must be a weight of sweep `{}`", sweep.id),
                ));
            }
            for (j, o) in f.overlay.iter().enumerate() {
                let key = k(&format!("overlay[{j}]"));
                let other = self.sweep_ref(&c, &key, o)?;
                if f.kind != FigureKind::Convergence || !other.weights.contains(&f.weight) || *o == f.sweep {
                    return Err(c.err(
                        key,
                        format!("{o:?}"),
                        format!(
                            "must be another sweep with weight {} on a convergence figure",
                            f.weight
                        ),
                    ));
                }
            }
            match (f.kind, f.measure) {
                (FigureKind::Convergence, None) => {
                    return Err(c.err(k("measure"), "(missing)", "convergence figures need a measure"))
                }
                (FigureKind::Profile, Some(m)) => {
                    return Err(c.err(k("measure"), m.name(), "profile figures take no measure"))
                }
                _ => {}
            }
        }
        Ok(())
    }

    fn check_lists(
        &self,
        c: &Checker,
        prefix: &str,
        methods: &[Method],
        weights: &[f64],
        elements: &[i64],
        ppc: &[i64],
    ) -> Result<(), StudyError> {
        let k = |f: &str| format!("{prefix}{f}");
        c.non_empty(&k("methods"), methods)?;
        for (j, m) in methods.iter().enumerate() {
            let allowed: &[Method] = if self.dimension == 3 {
                &crate::problems::column::METHODS_3D
            } else {
                &crate::problems::column::METHODS
            };
            m.expect_one_of(
                if self.dimension == 3 {
                    "3D column"
                } else {
                    "column"
                },
                allowed,
            )
            .map_err(|e| c.err(format!("{}[{j}]", k("methods")), m.name(), e.allowed))?;
            if methods[..j].contains(m) {
                return Err(c.err(
                    format!("{}[{j}]", k("methods")),
                    m.name(),
                    "must not repeat a method",
                ));
            }
        }
        c.non_empty(&k("weights"), weights)?;
        let limit = 1e3 * self.material.get("young_modulus").unwrap_or(f64::NAN);
        for (j, &w) in weights.iter().enumerate() {
            let key = format!("{}[{j}]", k("weights"));
            c.positive(&key, w)?;
            if w > limit {
                return Err(c.err(
                    key,
                    short(w),
                    format!("must be <= 1000 × material.young_modulus = {limit}"),
                ));
            }
        }
        c.non_empty(&k("elements"), elements)?;
        for (j, &n) in elements.iter().enumerate() {
            c.count(&format!("{}[{j}]", k("elements")), n, 1, MAX_ELEMENTS)?;
        }
        c.non_empty(&k("points_per_cell"), ppc)?;
        for (j, &n) in ppc.iter().enumerate() {
            c.count(
                &format!("{}[{j}]", k("points_per_cell")),
                n,
                1,
                max_points_per_axis(1),
            )?;
        }
        let max_ppc = ppc.iter().copied().max().unwrap_or(1);
        if methods.iter().any(|&m| m.uses_material_points()) {
            for (j, &n) in elements.iter().enumerate() {
                if n * max_ppc > MAX_POINTS_PER_CASE {
                    return Err(c.err(
                        format!("{}[{j}]", k("elements")),
                        n,
                        format!(
                            "elements × points_per_cell ({n} × {max_ppc}) must be <= {MAX_POINTS_PER_CASE}"
                        ),
                    ));
                }
            }
        }
        let cases = methods.len() * weights.len() * elements.len() * ppc.len();
        if cases > MAX_CASES_PER_SWEEP {
            return Err(c.err(
                prefix.trim_end_matches('.'),
                format!("{cases} cases"),
                format!("methods × weights × elements × points_per_cell must be <= {MAX_CASES_PER_SWEEP}"),
            ));
        }
        Ok(())
    }

    fn sweep_ref<'a>(&'a self, c: &Checker, key: &str, id: &str) -> Result<&'a Sweep, StudyError> {
        self.sweep(id).ok_or_else(|| {
            let known: Vec<&str> = self.sweeps.iter().map(|s| s.id.as_str()).collect();
            c.err(
                key,
                format!("{id:?}"),
                format!("must name a sweep: one of {known:?}"),
            )
        })
    }

    fn check_series_ref(
        &self,
        c: &Checker,
        prefix: &str,
        sweep: &Sweep,
        method: Method,
        weight: f64,
        ppc: Option<i64>,
    ) -> Result<(), StudyError> {
        let k = |f: &str| format!("{prefix}{f}");
        if !sweep.methods.contains(&method) {
            return Err(c.err(
                k("method"),
                method.name(),
                format!("must be a method of sweep `{}`", sweep.id),
            ));
        }
        if !sweep.weights.contains(&weight) {
            return Err(c.err(
                k("weight"),
                weight,
                format!("must be a weight of sweep `{}`", sweep.id),
            ));
        }
        match (method.uses_material_points(), ppc) {
            (true, None) => Err(c.err(
                k("points_per_cell"),
                "(missing)",
                format!("is required for {}", method.name()),
            )),
            (true, Some(n)) if !sweep.points_per_cell.contains(&n) => Err(c.err(
                k("points_per_cell"),
                n,
                format!(
                    "must be one of sweep `{}`'s points_per_cell {:?}",
                    sweep.id, sweep.points_per_cell
                ),
            )),
            (false, Some(n)) => Err(c.err(
                k("points_per_cell"),
                n,
                format!(
                    "must be absent for {} (FEM has no material points)",
                    method.name()
                ),
            )),
            _ => Ok(()),
        }
    }
}
