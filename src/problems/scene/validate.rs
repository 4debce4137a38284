//! The checks of a scene's loads and measures (the rest of [`Scene::validate`]).

use super::spec::{
    axis_index, err, region, vector, ClosedForm, Load, LoadKind, Measure, MeasureKind, Reference, Scene, AXES,
};
use crate::solver::error::InputError;
use std::collections::BTreeSet;

impl Scene {
    pub(super) fn check_load(
        &self,
        i: usize,
        l: &Load,
        names: &mut BTreeSet<String>,
    ) -> Result<(), InputError> {
        let key = format!("loads[{i}]");
        let d = self.dimension;
        l.ramp.validate(&format!("{key}.ramp"))?;
        let refuse = |field: &str, given: bool| -> Result<(), InputError> {
            if given {
                return Err(err(
                    format!("{key}.{field}"),
                    "given",
                    format!("is not a key of a {:?} load", l.kind),
                ));
            }
            Ok(())
        };
        if l.kind != LoadKind::Traction {
            refuse("body", l.body.is_some())?;
            refuse("face", l.face.is_some())?;
        }
        if l.kind != LoadKind::Displacement {
            refuse("on", l.on != super::spec::Bind::Nodes)?;
        }
        if let Some(b) = l.penalty {
            if l.on != super::spec::Bind::Points || !(b.is_finite() && b > 0.0) {
                return Err(err(
                    format!("{key}.penalty"),
                    b,
                    "must be finite and > 0, on a displacement load with on = \"points\"",
                ));
            }
        }
        match l.kind {
            LoadKind::Traction => {
                refuse("name", l.name.is_some())?;
                refuse("plane", l.plane.is_some())?;
                refuse("displacement", l.displacement.is_some())?;
                if let Some(b) = &l.bounds {
                    b.check(&format!("{key}.box"), d, false)?;
                }
                // The solvers take one ramp for all point (nodal) loads.
                let first = self.loads.iter().position(|o| o.kind == LoadKind::Traction);
                if let Some(f) = first.filter(|&f| self.loads[f].ramp != l.ramp) {
                    return Err(err(
                        format!("{key}.ramp"),
                        format!("{:?}", l.ramp),
                        format!(
                            "must be loads[{f}]'s {:?}: every traction follows one ramp",
                            self.loads[f].ramp
                        ),
                    ));
                }
                let v = l.vector.as_ref().ok_or_else(|| {
                    err(
                        format!("{key}.vector"),
                        "missing",
                        "a traction needs its vector (force per unit area)",
                    )
                })?;
                vector(&format!("{key}.vector"), v, d)?;
                let name = l.body.as_ref().ok_or_else(|| {
                    err(
                        format!("{key}.body"),
                        "missing",
                        "a traction needs the body it loads",
                    )
                })?;
                let body = self
                    .bodies
                    .iter()
                    .find(|b| &b.name == name)
                    .ok_or_else(|| err(format!("{key}.body"), format!("{name:?}"), "must name a body"))?;
                if body.bounds.is_none() {
                    return Err(err(
                        format!("{key}.body"),
                        format!("{name:?}"),
                        "must be a box body (a traction loads one of its faces)",
                    ));
                }
                let face = l.face.as_ref().ok_or_else(|| {
                    err(
                        format!("{key}.face"),
                        "missing",
                        "a traction needs a face, e.g. \"y+\"",
                    )
                })?;
                let (axis, side) = super::spec::face_of(&format!("{key}.face"), face, d)?;
                if let Some(b) = &l.bounds {
                    // The box picks part of the face: it must reach the face's plane and
                    // overlap the face along every other axis.
                    let (bx, at) = (body.bounding_box(), body.face_at(axis, side));
                    let meets = (0..d).all(|a| {
                        if a == axis {
                            b.min[a] <= at && at <= b.max[a]
                        } else {
                            b.min[a] < bx.max[a] && bx.min[a] < b.max[a]
                        }
                    });
                    if !meets {
                        return Err(err(
                            format!("{key}.box"),
                            format!("{:?} .. {:?}", b.min, b.max),
                            format!(
                                "must meet the face {face} of body {name:?} ({:?} .. {:?}) over a part of positive area",
                                bx.min, bx.max
                            ),
                        ));
                    }
                }
                Ok(())
            }
            LoadKind::Gravity => {
                refuse("name", l.name.is_some())?;
                refuse("plane", l.plane.is_some())?;
                refuse("box", l.bounds.is_some())?;
                refuse("displacement", l.displacement.is_some())?;
                let v = l.vector.as_ref().ok_or_else(|| {
                    err(
                        format!("{key}.vector"),
                        "missing",
                        "a gravity load needs its vector",
                    )
                })?;
                vector(&format!("{key}.vector"), v, d)
            }
            LoadKind::Displacement => {
                refuse("vector", l.vector.is_some())?;
                let name = l.name.as_ref().ok_or_else(|| {
                    err(
                        format!("{key}.name"),
                        "missing",
                        "a displacement load needs a name",
                    )
                })?;
                self.name(&format!("{key}.name"), name, names)?;
                region(&key, &l.plane, &l.bounds, d)?;
                let c = l.displacement.as_ref().ok_or_else(|| {
                    err(
                        format!("{key}.displacement"),
                        "missing",
                        "must give the moved components, e.g. { y = -0.1 }",
                    )
                })?;
                let given = c.given();
                if given.is_empty() {
                    return Err(err(
                        format!("{key}.displacement"),
                        "{}",
                        "must give at least one component",
                    ));
                }
                for (a, v) in given {
                    let k = format!("{key}.displacement.{}", AXES[a]);
                    if a >= d {
                        return Err(err(k, v, format!("is not a component in dimension {d}")));
                    }
                    if !v.is_finite() {
                        return Err(err(k, v, "must be finite"));
                    }
                }
                Ok(())
            }
        }
    }

    pub(super) fn check_measure(
        &self,
        i: usize,
        m: &Measure,
        names: &mut BTreeSet<String>,
    ) -> Result<(), InputError> {
        let key = format!("measures[{i}]");
        let d = self.dimension;
        if m.name.trim().is_empty() || m.name.len() > 64 || !names.insert(m.name.clone()) {
            return Err(err(
                format!("{key}.name"),
                format!("{:?}", m.name),
                "must be a name of 1 to 64 characters, each measure's its own",
            ));
        }
        let refuse = |field: &str, given: bool| -> Result<(), InputError> {
            if given {
                return Err(err(
                    format!("{key}.{field}"),
                    "given",
                    format!("is not a key of a {:?} measure", m.kind),
                ));
            }
            Ok(())
        };
        if m.kind != MeasureKind::StressLine {
            refuse("to", m.to.is_some())?;
            refuse("samples", m.samples.is_some())?;
        }
        if m.kind != MeasureKind::FactorOfSafety {
            refuse("limit", m.limit.is_some())?;
        }
        match m.kind {
            MeasureKind::Displacement => {
                refuse("region", m.region.is_some())?;
                let at = m.at.as_ref().ok_or_else(|| {
                    err(
                        format!("{key}.at"),
                        "missing",
                        "a displacement measure needs its point",
                    )
                })?;
                vector(&format!("{key}.at"), at, d)?;
                self.component(&key, m)?;
            }
            MeasureKind::Reaction => {
                refuse("at", m.at.is_some())?;
                refuse("domain_edge", m.domain_edge)?;
                let r = m.region.as_ref().ok_or_else(|| {
                    err(
                        format!("{key}.region"),
                        "missing",
                        "a reaction needs the name of a support or displacement load",
                    )
                })?;
                let known = self.supports.iter().any(|s| &s.name == r)
                    || self
                        .loads
                        .iter()
                        .any(|l| l.kind == LoadKind::Displacement && l.name.as_ref() == Some(r));
                if !known {
                    return Err(err(
                        format!("{key}.region"),
                        format!("{r:?}"),
                        "must name a support or a displacement load",
                    ));
                }
                self.component(&key, m)?;
            }
            MeasureKind::StressLine => {
                for (f, g) in [
                    ("region", m.region.is_some()),
                    ("domain_edge", m.domain_edge),
                    ("history", m.history),
                ] {
                    refuse(f, g)?;
                }
                let at = m.at.as_ref().ok_or_else(|| {
                    err(
                        format!("{key}.at"),
                        "missing",
                        "a stress line needs its start `at`",
                    )
                })?;
                vector(&format!("{key}.at"), at, d)?;
                let to = m
                    .to
                    .as_ref()
                    .ok_or_else(|| err(format!("{key}.to"), "missing", "a stress line needs its end `to`"))?;
                vector(&format!("{key}.to"), to, d)?;
                let n = m.samples.ok_or_else(|| {
                    err(
                        format!("{key}.samples"),
                        "missing",
                        "a stress line needs its number of samples",
                    )
                })?;
                if !(2..=1000).contains(&n) {
                    return Err(err(format!("{key}.samples"), n, "must be an integer in 2..=1000"));
                }
                let c = m.component.as_ref().ok_or_else(|| {
                    err(
                        format!("{key}.component"),
                        "missing",
                        "a stress line needs a component, e.g. \"yy\"",
                    )
                })?;
                if super::measures::stress_component(c, d).is_none() {
                    return Err(err(
                        format!("{key}.component"),
                        format!("{c:?}"),
                        "must be a stress component: two of x, y, z (in 2D also zz), e.g. \"yy\", \"xy\"",
                    ));
                }
            }
            MeasureKind::ColumnStressError => {
                for (f, g) in [
                    ("at", m.at.is_some()),
                    ("region", m.region.is_some()),
                    ("component", m.component.is_some()),
                    ("domain_edge", m.domain_edge),
                ] {
                    refuse(f, g)?;
                }
                if super::spec::column_axis(self).is_none() {
                    return Err(err(
                        format!("{key}.kind"),
                        "column-stress-error",
                        "needs one box body and one gravity load along an axis, pointing to its negative side",
                    ));
                }
            }
            MeasureKind::FactorOfSafety => {
                for (f, g) in [
                    ("region", m.region.is_some()),
                    ("domain_edge", m.domain_edge),
                    ("history", m.history),
                    // The limit is a displacement and the value a factor: neither is scaled.
                    ("scale", m.scale.is_some()),
                ] {
                    refuse(f, g)?;
                }
                if let Some(limit) = m.limit {
                    if !(limit.is_finite() && limit > 0.0) {
                        return Err(err(format!("{key}.limit"), limit, "must be a displacement > 0"));
                    }
                    let at = m.at.as_ref().ok_or_else(|| {
                        err(
                            format!("{key}.at"),
                            "missing",
                            "a displacement limit needs the point it is read at",
                        )
                    })?;
                    vector(&format!("{key}.at"), at, d)?;
                    self.component(&key, m)?;
                } else {
                    refuse("at", m.at.is_some())?;
                    refuse("component", m.component.is_some())?;
                }
                if self.strength_reduction.is_none() {
                    return Err(err(
                        format!("{key}.kind"),
                        "factor-of-safety",
                        "needs a [strength_reduction] section: the factor of safety is the factor at which the body collapses",
                    ));
                }
            }
            MeasureKind::StrainEnergy => {
                for (f, g) in [
                    ("at", m.at.is_some()),
                    ("region", m.region.is_some()),
                    ("component", m.component.is_some()),
                    ("domain_edge", m.domain_edge),
                ] {
                    refuse(f, g)?;
                }
                self.hencky_parameters(&format!("{key}.kind"))?;
            }
        }
        if let Some(r) = &m.reference {
            self.check_reference(&format!("{key}.reference"), m, r)?;
        }
        Ok(())
    }

    fn component(&self, key: &str, m: &Measure) -> Result<usize, InputError> {
        let c = m
            .component
            .as_ref()
            .ok_or_else(|| err(format!("{key}.component"), "missing", "must be x, y or z"))?;
        axis_index(&format!("{key}.component"), c, self.dimension)
    }

    /// (E, ν) of the bodies' material, which a Hencky energy or closed form needs.
    pub fn hencky_parameters(&self, key: &str) -> Result<(f64, f64), InputError> {
        let m = &self.materials[&self.bodies[0].material];
        match (m.get("young_modulus"), m.get("poisson_ratio")) {
            (Some(e), Some(nu)) => Ok((e, nu)),
            _ => Err(err(
                key,
                m.model(),
                "needs a material with young_modulus and poisson_ratio",
            )),
        }
    }

    fn check_reference(&self, key: &str, m: &Measure, r: &Reference) -> Result<(), InputError> {
        if r.source.trim().is_empty() {
            return Err(err(
                format!("{key}.source"),
                "\"\"",
                "must say where the reference comes from",
            ));
        }
        if r.fem_sweep.is_some() {
            // The study checks that it names a sweep of one FEM method.
            if r.value.is_some() || r.closed_form.is_some() || r.body.is_some() || r.load.is_some() {
                return Err(err(
                    key,
                    "fem_sweep with value, closed_form, body or load",
                    "must give exactly one of value, closed_form or fem_sweep",
                ));
            }
            return Ok(());
        }
        match (r.value, r.closed_form) {
            (Some(v), None) => {
                if !v.is_finite() {
                    return Err(err(format!("{key}.value"), v, "must be finite"));
                }
                if r.body.is_some() || r.load.is_some() {
                    return Err(err(key, "body/load", "a value needs no body or load"));
                }
                Ok(())
            }
            (None, Some(form)) => {
                let wanted = match form {
                    ClosedForm::PlatenForce => MeasureKind::Reaction,
                    ClosedForm::PlatenDisplacement | ClosedForm::ColumnDisplacement => {
                        MeasureKind::Displacement
                    }
                };
                if m.kind != wanted {
                    return Err(err(
                        format!("{key}.closed_form"),
                        format!("{form:?}"),
                        format!("is a closed form of a {wanted:?} measure"),
                    ));
                }
                if form != ClosedForm::ColumnDisplacement {
                    return self.platen(key, r).map(|_| ());
                }
                let c = self.column(key)?;
                if m.component
                    .as_deref()
                    .map(|n| super::spec::axis_index("", n, self.dimension))
                    != Some(Ok(c.axis))
                {
                    return Err(err(
                        format!("{key}.closed_form"),
                        "column-displacement",
                        format!("is the displacement along the gravity's axis: the measure's component must be {:?}", super::spec::AXES[c.axis]),
                    ));
                }
                if r.body.is_some() || r.load.is_some() {
                    return Err(err(
                        key,
                        "body/load",
                        "the column's closed form needs no body or load (its one body and gravity)",
                    ));
                }
                if !c.displacement(m.at.as_deref().unwrap_or(&[]), 1.0).is_finite() {
                    return Err(err(
                        format!("{key}.closed_form"),
                        "column-displacement",
                        "has no solution: the column's weight exceeds the law's largest compressive stress",
                    ));
                }
                Ok(())
            }
            _ => Err(err(
                key,
                "value and closed_form",
                "must give exactly one of value, closed_form or fem_sweep",
            )),
        }
    }
}
