//! The checks of a scene study file: the header, the materials, the scene itself (every key
//! named, [`crate::problems::scene::Scene::validate`]), the sweeps, each case's resolution
//! (a region on no node, a body off the point lattice) and the expectations.

use super::SceneStudy;
use crate::basis::method::Method;
use crate::problems::scene::{check_resolution, methods, LoadKind};
use crate::solver::newton::ResidualNorm;
use crate::study::external::StudyMethod;
use crate::study::vocabulary::{Checker, Header};
use crate::study::{StudyError, Tier};
use std::collections::BTreeSet;

impl SceneStudy {
    pub(super) fn check(&self, file: &str) -> Result<(), StudyError> {
        let chk = Checker { file };
        chk.header(Header {
            schema: self.schema,
            problem: &self.problem,
            expected_problem: "scene",
            name: &self.name,
            summary: &self.summary,
            report_file: &self.report_file,
        })?;
        if !matches!(self.dimension, 2 | 3) {
            return Err(chk.err("dimension", self.dimension, "must be 2 or 3"));
        }
        if self.materials.is_empty() {
            return Err(chk.err(
                "materials",
                "{}",
                "must define at least one [materials.<name>] table",
            ));
        }
        for (name, table) in &self.materials {
            chk.material(&format!("materials.{name}"), table)?;
        }
        let scene = self.scene();
        let input = |e: crate::solver::error::InputError| chk.err(e.field, e.value, e.allowed);
        scene.validate().map_err(input)?;
        chk.count("load_steps", self.load_steps, 1, 100_000)?;
        chk.newton("newton", &self.newton)?;
        self.ghost
            .validate()
            .map_err(|e| chk.err(format!("ghost.{}", e.field), e.value, e.allowed))?;
        let gravity = self.loads.iter().any(|l| l.kind != LoadKind::Displacement);
        if !gravity && self.newton.residual_norm == ResidualNorm::External {
            return Err(chk.err(
                "newton.residual_norm",
                "\"external\"",
                "must be \"total\" when no load is a force (only prescribed displacements): the external force is zero, so ‖f_ext‖ cannot scale the residual",
            ));
        }
        chk.non_empty("sweeps", &self.sweeps)?;
        let mut ids = BTreeSet::new();
        let allowed = methods(scene.dimension);
        for (i, s) in self.sweeps.iter().enumerate() {
            chk.unique_ident(&format!("sweeps[{i}].id"), &s.id, &mut ids)?;
            chk.text(&format!("sweeps[{i}].title"), &s.title)?;
            if s.pressure_projection && !s.f_bar {
                return Err(chk.err(
                    format!("sweeps[{i}].pressure_projection"),
                    "true",
                    "needs f_bar = true in the same sweep",
                ));
            }
            if let Some(n) = s.gauss_points {
                chk.count(&format!("sweeps[{i}].gauss_points"), n, 1, 5)?;
            }
            if let Some(n) = s.load_steps {
                chk.count(&format!("sweeps[{i}].load_steps"), n, 1, 100_000)?;
            }
            for tier in [Tier::Full, Tier::Quick] {
                let Some((ms, sizes, ppcs)) = self.plan(s, tier) else {
                    continue;
                };
                let k = |f: &str| {
                    format!(
                        "sweeps[{i}].{}{f}",
                        if tier == Tier::Quick { "quick." } else { "" }
                    )
                };
                chk.non_empty(&k("methods"), &ms)?;
                chk.non_empty(&k("element_sizes"), &sizes)?;
                chk.non_empty(&k("points_per_cell"), &ppcs)?;
                for (j, m) in ms.iter().enumerate() {
                    // An external code solves igimp's material points: its basis (if named)
                    // must be a material point one. Whether its adapter exists and supports
                    // the scene is the case's to find out (a recorded failure, not an
                    // invalid study).
                    let own = match m {
                        StudyMethod::Own(m) => *m,
                        StudyMethod::External(e) => match e.basis {
                            Some(b) if !b.uses_material_points() => {
                                return Err(chk.err(
                                    format!("{}[{j}]", k("methods")),
                                    m,
                                    "an external code solves the case's material points: its basis after @ must be a material point method",
                                ))
                            }
                            b => b.unwrap_or(Method::MPM),
                        },
                    };
                    if !allowed.contains(&own) {
                        let e =
                            own.unsupported(&format!("a scene in dimension {}", scene.dimension), allowed);
                        return Err(chk.err(format!("{}[{j}]", k("methods")), e.value, e.allowed));
                    }
                }
                for (j, &p) in ppcs.iter().enumerate() {
                    chk.count(&format!("{}[{j}]", k("points_per_cell")), p, 1, 16)?;
                }
                for (j, &h) in sizes.iter().enumerate() {
                    chk.positive(&format!("{}[{j}]", k("element_sizes")), h)?;
                    for m in &ms {
                        let own = m.own().unwrap_or(Method::MPM);
                        for &p in &ppcs {
                            let settings = self.settings(s, h, p as usize);
                            check_resolution(&scene, &settings, own).map_err(|e| {
                                chk.err(
                                    e.field.clone(),
                                    e.value.clone(),
                                    format!(
                                        "{} (sweep {:?}, {m} at h = {h}, {p} points per cell)",
                                        e.allowed, s.id
                                    ),
                                )
                            })?;
                        }
                    }
                }
            }
        }
        self.check_expectations(&chk)
    }

    fn check_expectations(&self, chk: &Checker<'_>) -> Result<(), StudyError> {
        for (i, m) in self.measures.iter().enumerate() {
            let Some(sweep) = m.reference.as_ref().and_then(|r| r.fem_sweep.as_ref()) else {
                continue;
            };
            let key = format!("measures[{i}].reference.fem_sweep");
            let s = self
                .sweeps
                .iter()
                .find(|s| &s.id == sweep)
                .ok_or_else(|| chk.err(&key, format!("{sweep:?}"), "must name a sweep"))?;
            for tier in [Tier::Full, Tier::Quick] {
                let Some((ms, sizes, _)) = self.plan(s, tier) else {
                    return Err(chk.err(
                        &key,
                        format!("{sweep:?}"),
                        "must name a sweep that every tier runs (not quick.skip)",
                    ));
                };
                let distinct: BTreeSet<u64> = sizes.iter().map(|h| h.to_bits()).collect();
                if ms.len() != 1 || !ms[0].own().is_some_and(|m| m.is_fem()) || distinct.len() < 3 {
                    return Err(chk.err(
                        &key,
                        format!("{sweep:?}"),
                        format!("must name a sweep of one FEM method with three or more element sizes in the {} tier", tier.name()),
                    ));
                }
            }
        }
        let measure = |key: &str, name: &str| -> Result<(), StudyError> {
            match self.measures.iter().find(|m| m.name == name) {
                None => Err(chk.err(key, format!("{name:?}"), "must name a measure")),
                Some(m) if m.reference.is_none() => {
                    Err(chk.err(key, format!("{name:?}"), "must name a measure with a reference"))
                }
                Some(_) => Ok(()),
            }
        };
        let sweep = |key: &str, id: &str| -> Result<&super::SceneSweep, StudyError> {
            self.sweeps
                .iter()
                .find(|s| s.id == id)
                .ok_or_else(|| chk.err(key, format!("{id:?}"), "must name a sweep"))
        };
        // What a rate and an extrapolation name: a measure with a reference, a sweep and one
        // of its methods.
        let series =
            |key: &str, m: &str, id: &str, method: &StudyMethod| -> Result<&super::SceneSweep, StudyError> {
                measure(&format!("{key}.measure"), m)?;
                let s = sweep(&format!("{key}.sweep"), id)?;
                if !s.methods.contains(method) {
                    return Err(chk.err(
                        format!("{key}.method"),
                        method,
                        format!("must be a method of sweep {:?}", s.id),
                    ));
                }
                Ok(s)
            };
        for (i, e) in self.expect_reference.iter().enumerate() {
            let key = format!("expect_reference[{i}]");
            measure(&format!("{key}.measure"), &e.measure)?;
            let s = sweep(&format!("{key}.sweep"), &e.sweep)?;
            for (j, m) in e.methods.iter().enumerate() {
                if !s.methods.contains(m) {
                    return Err(chk.err(
                        format!("{key}.methods[{j}]"),
                        m,
                        format!("must be a method of sweep {:?}", s.id),
                    ));
                }
            }
            chk.positive(&format!("{key}.tolerance"), e.tolerance)?;
            chk.text(&format!("{key}.source"), &e.source)?;
        }
        for (i, e) in self.expect_rate.iter().enumerate() {
            let key = format!("expect_rate[{i}]");
            series(&key, &e.measure, &e.sweep, &e.method)?;
            if !(e.rate.is_finite() && e.rate > 0.0) {
                return Err(chk.err(format!("{key}.rate"), e.rate, "must be finite and > 0"));
            }
            chk.positive(&format!("{key}.tolerance"), e.tolerance)?;
            chk.text(&format!("{key}.source"), &e.source)?;
        }
        for (i, e) in self.expect_extrapolation.iter().enumerate() {
            let key = format!("expect_extrapolation[{i}]");
            let sizes = series(&key, &e.measure, &e.sweep, &e.method)?.element_sizes.len();
            if !(e.tolerance > 0.0 && e.tolerance < 1.0) {
                return Err(chk.err(format!("{key}.tolerance"), e.tolerance, "must lie in (0, 1)"));
            }
            chk.text(&format!("{key}.source"), &e.source)?;
            if sizes < 3 {
                return Err(chk.err(
                    format!("{key}.sweep"),
                    format!("{:?}", e.sweep),
                    format!("has {sizes} element size(s); an extrapolation needs three"),
                ));
            }
        }
        for (i, e) in self.expect_agreement.iter().enumerate() {
            let key = format!("expect_agreement[{i}]");
            let s = sweep(&format!("{key}.sweep"), &e.sweep)?;
            for (j, m) in e.methods.iter().enumerate() {
                if !s.methods.contains(m) || !m.uses_material_points() {
                    return Err(chk.err(
                        format!("{key}.methods[{j}]"),
                        m,
                        format!("must be a material point method of sweep {:?}", s.id),
                    ));
                }
            }
            if e.methods[0] == e.methods[1] {
                return Err(chk.err(
                    format!("{key}.methods"),
                    &e.methods[1],
                    "must name two different methods",
                ));
            }
            chk.positive(&format!("{key}.tolerance"), e.tolerance)?;
            chk.text(&format!("{key}.source"), &e.source)?;
        }
        for (i, e) in self.expect_quadratic.iter().enumerate() {
            let key = format!("expect_quadratic[{i}]");
            sweep(&format!("{key}.sweep"), &e.sweep)?;
            chk.quadratic(&key, &e.terms())?;
        }
        Ok(())
    }
}
