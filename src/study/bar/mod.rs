//! The vibrating-bar study kind (implicit dynamics): `studies/vibrating-bar.toml` →
//! `results.json` → `report.md` and its figures. A sweep is methods × mass matrices ×
//! elements × points per cell × time steps per period, with either the elements (space
//! convergence at a small Δt) or the time steps (time convergence on a fine grid) varied; each
//! series gets a rate fitted against h or Δt, and `[[expect_rate]]` / `[[expect_at_most]]` turn
//! rates, period errors and energy drifts into checks.

pub mod kind;
pub mod records;

use super::vocabulary::{Checker, Header, NewtonSection};
use super::{StudyError, Tier};
use crate::dynamics::MassMatrix;
use crate::method::Method;
use crate::problems::bar::BarSpec;
use crate::study::engine::distinct_cases;
use crate::study::results::SweepIndex;
use serde::{Deserialize, Serialize};
use std::collections::BTreeSet;

/// The bar of every case.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BarSection {
    pub length: f64,
    pub young_modulus: f64,
    pub density: f64,
    /// Peak initial velocity v₀ of the first mode.
    pub velocity: f64,
    /// Simulated time in periods T = 4L/c.
    pub periods: f64,
    /// Newmark β, γ (default 1/4, 1/2: the trapezoidal rule).
    #[serde(default = "quarter")]
    pub beta: f64,
    #[serde(default = "half")]
    pub gamma: f64,
}

fn quarter() -> f64 {
    0.25
}

fn half() -> f64 {
    0.5
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
    pub elements: Option<Vec<i64>>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub steps_per_period: Option<Vec<i64>>,
}

/// One sweep: the lists' product, one of `elements` and `steps_per_period` varied.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BarSweep {
    pub id: String,
    pub title: String,
    pub methods: Vec<Method>,
    #[serde(default = "consistent")]
    pub mass: Vec<MassMatrix>,
    pub elements: Vec<i64>,
    pub points_per_cell: Vec<i64>,
    pub steps_per_period: Vec<i64>,
    #[serde(default)]
    pub quick: SweepQuick,
}

fn consistent() -> Vec<MassMatrix> {
    vec![MassMatrix::Consistent]
}

impl super::vocabulary::TieredSweep for BarSweep {
    fn id(&self) -> &str {
        &self.id
    }
    fn runs_in(&self, tier: Tier) -> bool {
        tier == Tier::Full || !self.quick.skip
    }
}

/// What a sweep varies, and so what its rates are fitted against.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Refinement {
    /// Elements: rates against h.
    Space,
    /// Time steps: rates against Δt.
    Time,
}

/// A measure of a case.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum BarMeasure {
    /// ‖u_h − u‖ / ‖u‖ over the points at the end.
    Displacement,
    /// |T_h − T| / T, T_h from the free end's zero crossings.
    Period,
    /// max_t |E(t) − E(0)| / E(0).
    Energy,
}

impl BarMeasure {
    pub const ALL: [BarMeasure; 3] = [BarMeasure::Displacement, BarMeasure::Period, BarMeasure::Energy];
    pub fn name(self) -> &'static str {
        match self {
            BarMeasure::Displacement => "displacement",
            BarMeasure::Period => "period",
            BarMeasure::Energy => "energy",
        }
    }
    pub fn label(self) -> &'static str {
        match self {
            BarMeasure::Displacement => "relative L2 displacement error at the end",
            BarMeasure::Period => "relative period error",
            BarMeasure::Energy => "largest relative energy change",
        }
    }
}

/// The fitted rate of one series must lie in `rate ± tolerance`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RateExpectation {
    pub sweep: String,
    pub method: Method,
    #[serde(default)]
    pub mass: MassMatrix,
    pub measure: BarMeasure,
    pub rate: f64,
    pub tolerance: f64,
    /// Only in this tier; absent: both.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tier: Option<Tier>,
    pub source: String,
}

/// The measure of a series' finest case (most elements, then most steps) must not exceed
/// `limit`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BoundExpectation {
    pub sweep: String,
    pub method: Method,
    #[serde(default)]
    pub mass: MassMatrix,
    pub measure: BarMeasure,
    pub limit: f64,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tier: Option<Tier>,
    pub source: String,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FigureKind {
    /// A measure against h or Δt, log-log, every series of the sweep.
    Convergence,
    /// The free end's displacement against time, every method of the sweep at its finest
    /// level, with the analytical one.
    History,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FigureSpec {
    pub id: String,
    pub title: String,
    pub kind: FigureKind,
    pub sweep: String,
    /// Convergence figures.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub measure: Option<BarMeasure>,
}

impl super::vocabulary::SweepFigure for FigureSpec {
    fn sweep(&self) -> &str {
        &self.sweep
    }
}

/// `studies/vibrating-bar.toml`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BarStudy {
    pub schema: i64,
    pub name: String,
    pub summary: String,
    /// Always "bar".
    pub problem: String,
    pub report_file: String,
    pub bar: BarSection,
    pub newton: NewtonSection,
    pub sweeps: Vec<BarSweep>,
    #[serde(default)]
    pub expect_rate: Vec<RateExpectation>,
    #[serde(default)]
    pub expect_at_most: Vec<BoundExpectation>,
    #[serde(default)]
    pub figures: Vec<FigureSpec>,
}

/// One case to solve.
#[derive(Debug, Clone, PartialEq)]
pub struct BarCase {
    pub id: String,
    pub method: Method,
    pub spec: BarSpec,
}

/// The sweep's lists after the tier's overrides.
struct SweepPlan {
    methods: Vec<Method>,
    elements: Vec<i64>,
    steps_per_period: Vec<i64>,
}

/// The methods a bar case can use: every material point family and the line elements.
pub const BAR_METHODS: [Method; 8] = [
    Method::MPM,
    Method::IGIMP,
    Method::CPDI,
    Method::BSPLINE2,
    Method::BSPLINE3,
    Method::TLMPM,
    Method::FEM_LINEAR,
    Method::FEM_QUADRATIC,
];

/// Most elements of one case (1D: cheap; a bound against typos).
const MAX_ELEMENTS: i64 = 65_536;
/// Most time steps per period.
const MAX_STEPS_PER_PERIOD: i64 = 65_536;

impl BarSweep {
    fn plan(&self, tier: Tier) -> Option<SweepPlan> {
        if !super::vocabulary::TieredSweep::runs_in(self, tier) {
            return None;
        }
        let q = (tier == Tier::Quick).then_some(&self.quick);
        Some(SweepPlan {
            methods: q
                .and_then(|q| q.methods.clone())
                .unwrap_or_else(|| self.methods.clone()),
            elements: q
                .and_then(|q| q.elements.clone())
                .unwrap_or_else(|| self.elements.clone()),
            steps_per_period: q
                .and_then(|q| q.steps_per_period.clone())
                .unwrap_or_else(|| self.steps_per_period.clone()),
        })
    }

    /// What the sweep varies (the full tier's lists decide; validation keeps the quick
    /// tier's the same).
    pub fn refinement(&self) -> Refinement {
        if self.elements.len() > 1 {
            Refinement::Space
        } else {
            Refinement::Time
        }
    }
}

impl BarStudy {
    pub fn sweep(&self, id: &str) -> Option<&BarSweep> {
        self.sweeps.iter().find(|s| s.id == id)
    }

    /// The spec of one case.
    pub fn case_spec(&self, mass: MassMatrix, elements: i64, ppc: i64, steps: i64) -> BarSpec {
        let b = &self.bar;
        BarSpec {
            length: b.length,
            young_modulus: b.young_modulus,
            density: b.density,
            velocity: b.velocity,
            elements: elements as usize,
            points_per_cell: ppc as usize,
            steps_per_period: steps as usize,
            periods: b.periods,
            beta: b.beta,
            gamma: b.gamma,
            mass,
            newton: self.newton.settings(),
        }
    }

    /// `<method>-<mass>-e<elements>-p<ppc>-n<steps per period>`.
    pub fn case_id(method: Method, spec: &BarSpec) -> String {
        let mass = match spec.mass {
            MassMatrix::Consistent => "cm",
            MassMatrix::Lumped => "lm",
        };
        format!(
            "{}-{mass}-e{}-p{}-n{}",
            method.name(),
            spec.elements,
            spec.points_per_cell,
            spec.steps_per_period
        )
    }

    fn sweep_cases(&self, s: &BarSweep, plan: &SweepPlan) -> Vec<BarCase> {
        let mut out = vec![];
        for &method in &plan.methods {
            for &mass in &s.mass {
                for &ppc in &s.points_per_cell {
                    for &e in &plan.elements {
                        for &n in &plan.steps_per_period {
                            let spec = self.case_spec(mass, e, ppc, n);
                            out.push(BarCase {
                                id: Self::case_id(method, &spec),
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

    pub fn cases(&self, tier: Tier) -> (Vec<BarCase>, SweepIndex) {
        distinct_cases(
            self.sweeps
                .iter()
                .filter_map(|s| Some((s.id.clone(), self.sweep_cases(s, &s.plan(tier)?)))),
            |c| c.id.as_str(),
        )
    }

    pub(super) fn check(&self, file: &str) -> Result<(), StudyError> {
        let chk = Checker { file };
        chk.header(Header {
            schema: self.schema,
            problem: &self.problem,
            expected_problem: "bar",
            name: &self.name,
            summary: &self.summary,
            report_file: &self.report_file,
        })?;
        chk.newton("newton", &self.newton)?;
        let b = &self.bar;
        for (k, v) in [
            ("bar.length", b.length),
            ("bar.young_modulus", b.young_modulus),
            ("bar.density", b.density),
            ("bar.velocity", b.velocity),
            ("bar.periods", b.periods),
        ] {
            chk.positive(k, v)?;
        }
        // The period is measured from zero crossings: at least two need 1.5 periods.
        if b.periods < 1.5 {
            return Err(chk.err(
                "bar.periods",
                b.periods,
                "must be >= 1.5 (two zero crossings of the free end)",
            ));
        }
        chk.non_empty("sweeps", &self.sweeps)?;
        let mut ids = BTreeSet::new();
        for (i, s) in self.sweeps.iter().enumerate() {
            chk.unique_ident(&format!("sweeps[{i}].id"), &s.id, &mut ids)?;
            chk.text(&format!("sweeps[{i}].title"), &s.title)?;
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
                    m.expect_one_of("bar", &BAR_METHODS)
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
        let sweep = |key: String, id: &str| -> Result<&BarSweep, StudyError> {
            self.sweep(id)
                .ok_or_else(|| chk.err(key, id, "must name a sweep"))
        };
        let method_and_mass = |k: &dyn Fn(&str) -> String, s: &BarSweep, m: Method, mass: MassMatrix| {
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
                _ => {}
            }
        }
        for tier in [Tier::Full, Tier::Quick] {
            for c in self.cases(tier).0 {
                c.spec
                    .validate()
                    .map_err(|e| chk.err(format!("case {}", c.id), e, "must be a valid bar input"))?;
            }
        }
        Ok(())
    }
}
