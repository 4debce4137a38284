//! A dynamics study file's validation: every key in its range, named with its path.

use super::*;

impl DynamicStudy {
    pub(in crate::study) fn check(&self, file: &str) -> Result<(), StudyError> {
        let chk = Checker { file };
        chk.header(Header {
            schema: self.schema,
            problem: &self.problem,
            expected_problem: "dynamics",
            name: &self.name,
            summary: &self.summary,
            report_file: &self.report_file,
        })?;
        chk.newton("newton", &self.newton)?;
        if !self.newton.predictor.is_zero() {
            return Err(chk.err(
                "newton.predictor",
                self.newton.predictor.name(),
                "must be \"zero\" in a dynamics study: the Newmark predictor starts each time step",
            ));
        }
        let given: Vec<&str> = [
            ("bar", self.bar.is_some()),
            ("manufactured", self.manufactured.is_some()),
            ("cantilever", self.cantilever.is_some()),
        ]
        .iter()
        .filter(|g| g.1)
        .map(|g| g.0)
        .collect();
        if given.len() != 1 {
            return Err(chk.err(
                given.last().copied().unwrap_or("bar"),
                if given.is_empty() {
                    "(none given)".to_string()
                } else {
                    format!("({} given)", given.join(", "))
                },
                "exactly one of [bar], [manufactured] and [cantilever] must define the problem",
            ));
        }
        let material = chk.material("material", &self.material)?;
        let hencky = "the dynamic problems' closed forms and strain energy are Hencky elasticity's";
        material
            .require_model(&crate::material::constitutive::LINEAR_ELASTIC, hencky)
            .map_err(|e| chk.err(e.field, e.value, e.allowed))?;
        // A section's positive fields, and its duration: the period is measured between two
        // downward crossings (`of`), which 1.5 periods contain.
        let timed_section = |fields: &[(&str, f64)], periods: (&str, f64), of: &str| {
            for &(k, v) in fields.iter().chain([&periods]) {
                chk.positive(k, v)?;
            }
            if periods.1 < 1.5 {
                return Err(chk.err(
                    periods.0,
                    periods.1,
                    format!("must be >= 1.5 (two downward crossings of {of})"),
                ));
            }
            Ok(())
        };
        if let Some(c) = &self.cantilever {
            timed_section(
                &[
                    ("cantilever.length", c.length),
                    ("cantilever.depth", c.depth),
                    ("cantilever.load", c.load),
                    ("cantilever.density", c.density),
                    ("cantilever.grid_below", c.grid_below),
                    ("cantilever.grid_margin", c.grid_margin),
                ],
                ("cantilever.periods", c.periods),
                "half the peak deflection",
            )?;
        }
        match (&self.bar, &self.manufactured) {
            (None, None) => {}
            (Some(b), None) => timed_section(
                &[
                    ("bar.length", b.length),
                    ("bar.density", b.density),
                    ("bar.velocity", b.velocity),
                ],
                ("bar.periods", b.periods),
                "zero by the free end",
            )?,
            (None, Some(m)) => {
                if !matches!(m.dimension, 2 | 3) {
                    return Err(chk.err("manufactured.dimension", m.dimension, "must be 2 or 3"));
                }
                for (k, v) in [
                    ("manufactured.density", m.density),
                    ("manufactured.periods", m.periods),
                ] {
                    chk.positive(k, v)?;
                }
            }
            (Some(_), Some(_)) => unreachable!("one problem section, checked above"),
        }
        chk.non_empty("sweeps", &self.sweeps)?;
        let mut ids = BTreeSet::new();
        for (i, s) in self.sweeps.iter().enumerate() {
            chk.unique_ident(&format!("sweeps[{i}].id"), &s.id, &mut ids)?;
            chk.text(&format!("sweeps[{i}].title"), &s.title)?;
            match (self.manufactured.is_some(), s.field) {
                (true, None) => {
                    return Err(chk.err(
                        format!("sweeps[{i}].field"),
                        "(missing)",
                        "is required with [manufactured]: axis-aligned or vortex",
                    ))
                }
                (false, Some(f)) => {
                    return Err(chk.err(
                        format!("sweeps[{i}].field"),
                        f.name(),
                        "must be absent for the bar and the cantilever",
                    ))
                }
                _ => {}
            }
            for tier in [Tier::Full, Tier::Quick] {
                let Some(plan) = s.plan(tier) else { continue };
                let key = format!(
                    "sweeps[{i}].{}reference",
                    if tier == Tier::Quick { "quick." } else { "" }
                );
                match (self.manufactured.is_none(), &plan.reference) {
                    (true, None) if self.cantilever.is_some() => {
                        return Err(chk.err(
                            key,
                            "(missing)",
                            "is required with [cantilever]: { method, elements, steps_per_period }",
                        ))
                    }
                    (false, Some(_)) => {
                        return Err(chk.err(
                            key,
                            "(given)",
                            "is for the bar and the cantilever only (the manufactured fields have exact solutions)",
                        ))
                    }
                    (true, Some(r)) => {
                        if self.cantilever.is_some() {
                            chk.count(&format!("{key}.elements"), r.elements, 2, 64)?;
                        } else {
                            chk.count(&format!("{key}.elements"), r.elements, 1, MAX_ELEMENTS)?;
                        }
                        chk.count(&format!("{key}.steps_per_period"), r.steps_per_period, 1, MAX_STEPS_PER_PERIOD)?;
                        match (r.method, &self.bar) {
                            (Some(m), None) => m
                                .expect_one_of("dynamic cantilever", &CANTILEVER_METHODS)
                                .map_err(|e| chk.err(format!("{key}.method"), m.name(), e.allowed))?,
                            // The bar's field is measured at the points' X by the reference's
                            // shape functions: a line-element reference.
                            (Some(m), Some(_)) => m
                                .expect_one_of(
                                    "bar's reference (its field is read between the nodes)",
                                    &[Method::FEM_LINEAR, Method::FEM_QUADRATIC],
                                )
                                .map_err(|e| chk.err(format!("{key}.method"), m.name(), e.allowed))?,
                            (None, Some(_)) => {
                                return Err(chk.err(
                                    format!("{key}.method"),
                                    "(missing)",
                                    "is required for the bar: fem-linear or fem-quadratic",
                                ))
                            }
                            (None, None) => {}
                        }
                        // The history error samples the reference at the case's instants.
                        for &n in &plan.steps_per_period {
                            if n > 0 && r.steps_per_period % n != 0 {
                                return Err(chk.err(
                                    format!("{key}.steps_per_period"),
                                    r.steps_per_period,
                                    format!("must be a whole multiple of every case's steps_per_period ({n} is not a divisor)"),
                                ));
                            }
                        }
                    }
                    (_, None) => {}
                }
            }
            chk.non_empty(&format!("sweeps[{i}].mass"), &s.mass)?;
            chk.non_empty(&format!("sweeps[{i}].points_per_cell"), &s.points_per_cell)?;
            for (j, &p) in s.points_per_cell.iter().enumerate() {
                chk.count(&format!("sweeps[{i}].points_per_cell[{j}]"), p, 1, 64)?;
            }
            for tier in [Tier::Full, Tier::Quick] {
                let Some(plan) = s.plan(tier) else { continue };
                let k = |f: &str| {
                    format!(
                        "sweeps[{i}].{}{f}",
                        if tier == Tier::Quick { "quick." } else { "" }
                    )
                };
                chk.non_empty(&k("methods"), &plan.methods)?;
                chk.non_empty(&k("elements"), &plan.elements)?;
                chk.non_empty(&k("steps_per_period"), &plan.steps_per_period)?;
                for (j, m) in plan.methods.iter().enumerate() {
                    m.expect_one_of(
                        if self.bar.is_some() {
                            "bar"
                        } else if self.cantilever.is_some() {
                            "dynamic cantilever"
                        } else {
                            "dynamic manufactured"
                        },
                        self.methods(),
                    )
                    .map_err(|e| chk.err(k(&format!("methods[{j}]")), m.name(), e.allowed))?;
                }
                for (j, &n) in plan.elements.iter().enumerate() {
                    chk.count(&k(&format!("elements[{j}]")), n, 1, MAX_ELEMENTS)?;
                }
                for (j, &n) in plan.steps_per_period.iter().enumerate() {
                    chk.count(&k(&format!("steps_per_period[{j}]")), n, 1, MAX_STEPS_PER_PERIOD)?;
                }
                // One refinement per sweep, so that its rates have one meaning.
                if plan.elements.len() > 1 && plan.steps_per_period.len() > 1 {
                    return Err(chk.err(
                        k("steps_per_period"),
                        format!("{:?}", plan.steps_per_period),
                        format!("must be a single value when {} lists several", k("elements")),
                    ));
                }
                let varies_space = plan.elements.len() > 1;
                if plan.elements.len() + plan.steps_per_period.len() > 2
                    && varies_space != (s.refinement() == Refinement::Space)
                {
                    return Err(chk.err(
                        k("elements"),
                        format!("{:?}", plan.elements),
                        "must refine the same list (elements or steps_per_period) as the full tier",
                    ));
                }
            }
        }
        let sweep = |key: String, id: &str| -> Result<&DynamicSweep, StudyError> {
            self.sweep(id)
                .ok_or_else(|| chk.err(key, id, "must name a sweep"))
        };
        let method_and_mass = |k: &dyn Fn(&str) -> String, s: &DynamicSweep, m: Method, mass: MassMatrix| {
            if !s.methods.contains(&m) {
                return Err(chk.err(
                    k("method"),
                    m.name(),
                    format!("must be a method of sweep `{}`", s.id),
                ));
            }
            if !s.mass.contains(&mass) {
                return Err(chk.err(
                    k("mass"),
                    format!("{mass:?}"),
                    format!("must be a mass matrix of sweep `{}`", s.id),
                ));
            }
            Ok(())
        };
        for (i, e) in self.expect_rate.iter().enumerate() {
            let k = |f: &str| format!("expect_rate[{i}].{f}");
            let s = sweep(k("sweep"), &e.sweep)?;
            method_and_mass(&k, s, e.method, e.mass)?;
            chk.positive(&k("tolerance"), e.tolerance)?;
            chk.text(&k("source"), &e.source)?;
        }
        for (i, e) in self.expect_at_most.iter().enumerate() {
            let k = |f: &str| format!("expect_at_most[{i}].{f}");
            let s = sweep(k("sweep"), &e.sweep)?;
            method_and_mass(&k, s, e.method, e.mass)?;
            chk.positive(&k("limit"), e.limit)?;
            chk.text(&k("source"), &e.source)?;
        }
        let mut fig_ids = BTreeSet::new();
        for (i, f) in self.figures.iter().enumerate() {
            let k = |x: &str| format!("figures[{i}].{x}");
            chk.unique_ident(&k("id"), &f.id, &mut fig_ids)?;
            chk.text(&k("title"), &f.title)?;
            sweep(k("sweep"), &f.sweep)?;
            match (f.kind, f.measure) {
                (FigureKind::Convergence, None) => {
                    return Err(chk.err(k("measure"), "(missing)", "is required for convergence figures"))
                }
                (FigureKind::History, Some(m)) => {
                    return Err(chk.err(k("measure"), m.name(), "must be absent for history figures"))
                }
                (FigureKind::History, None) if self.manufactured.is_some() => {
                    return Err(chk.err(
                        k("kind"),
                        "history",
                        "is drawn for the bar and the cantilever only",
                    ))
                }
                _ => {}
            }
        }
        for tier in [Tier::Full, Tier::Quick] {
            for (i, s) in self.sweeps.iter().enumerate() {
                let Some(plan) = s.plan(tier) else { continue };
                let scope = match tier {
                    Tier::Full => format!("sweeps[{i}]"),
                    Tier::Quick => format!("sweeps[{i}].quick"),
                };
                for c in self.sweep_cases(s, &plan) {
                    c.spec.validate().map_err(|e| chk.case_input(&scope, &c.id, e))?;
                }
            }
        }
        Ok(())
    }
}
