//! The dynamics study kind (implicit dynamics, `problem = "dynamics"`): a study file of one
//! dynamic problem, the vibrating bar (`[bar]`, `studies/vibrating-bar.toml`) or the dynamic
//! manufactured fields (`[manufactured]`, `studies/manufactured-dynamic.toml`) → `results.json`
//! → `report.md` and its figures. A sweep is methods × mass matrices × elements (cells) ×
//! points per cell × time steps per period, with either the elements (space convergence at a
//! small Δt) or the time steps (time convergence on a fine grid) varied; each series gets a
//! rate fitted against h or Δt, and `[[expect_rate]]` / `[[expect_at_most]]` turn rates, errors,
//! periods and energy drifts into checks.

pub mod kind;
pub mod records;

use super::vocabulary::{Checker, Header, NewtonSection};
use super::{StudyError, Tier};
use crate::basis::method::Method;
use crate::material::constitutive::Material;
use crate::problems::bar::BarSpec;
use crate::problems::cantilever::CantileverSpec;
use crate::problems::cantilever_dynamic::DynamicCantileverSpec;
use crate::problems::manufactured::Field;
use crate::problems::manufactured_dynamic::{self, DynamicManufacturedSpec};
use crate::solver::dynamics::MassMatrix;
use crate::study::engine::distinct_cases;
use crate::study::results::SweepIndex;
use serde::{Deserialize, Serialize};
use std::collections::BTreeSet;

/// The bar of every case.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BarSection {
    pub length: f64,
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
    /// Generalised-α's ρ∞ instead of Newmark's β, γ.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rho_infinity: Option<f64>,
}

/// The dynamic manufactured fields of every case
/// ([`crate::problems::manufactured_dynamic`]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ManufacturedSection {
    /// ρ₀.
    pub density: f64,
    /// Peak amplitude of each field (A of the axis-aligned field, θ₀ of the vortex).
    pub amplitude: crate::study::manufactured::AmplitudeSection,
    /// Simulated time in periods T = 2/c of the forcing.
    pub periods: f64,
    #[serde(default = "quarter")]
    pub beta: f64,
    #[serde(default = "half")]
    pub gamma: f64,
    /// Generalised-α's ρ∞ instead of Newmark's β, γ.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rho_infinity: Option<f64>,
    /// 2 (the unit square, plane strain) or 3 (the unit cube).
    #[serde(default = "plane", skip_serializing_if = "is_plane")]
    pub dimension: usize,
}

/// The dynamic cantilever of every case ([`crate::problems::cantilever_dynamic`]): the paper's
/// beam, its end load applied suddenly and held.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CantileverSection {
    pub length: f64,
    pub depth: f64,
    /// P (N), downwards.
    pub load: f64,
    pub density: f64,
    /// Grid room below the beam and beyond its end and top (material point methods).
    pub grid_below: f64,
    pub grid_margin: f64,
    /// Simulated time in units of the Euler–Bernoulli first-mode period T₁.
    pub periods: f64,
    #[serde(default = "quarter")]
    pub beta: f64,
    #[serde(default = "half")]
    pub gamma: f64,
    /// Generalised-α's ρ∞ instead of Newmark's β, γ.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rho_infinity: Option<f64>,
}

/// The analysis a sweep's cases are measured against (the dynamic cantilever, which has no
/// closed form): `method` (absent: each case's own, a temporal or spatial self-convergence) on
/// `elements` with `steps_per_period`, otherwise as the case.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SweepReference {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub method: Option<Method>,
    pub elements: i64,
    pub steps_per_period: i64,
}

fn plane() -> usize {
    2
}

fn is_plane(d: &usize) -> bool {
    *d == 2
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
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub reference: Option<SweepReference>,
}

/// One sweep: the lists' product, one of `elements` and `steps_per_period` varied.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DynamicSweep {
    pub id: String,
    pub title: String,
    /// The manufactured field (manufactured studies only).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub field: Option<Field>,
    pub methods: Vec<Method>,
    #[serde(default = "consistent")]
    pub mass: Vec<MassMatrix>,
    pub elements: Vec<i64>,
    pub points_per_cell: Vec<i64>,
    pub steps_per_period: Vec<i64>,
    /// What the cases are measured against (the cantilever; required there, absent elsewhere).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub reference: Option<SweepReference>,
    #[serde(default)]
    pub quick: SweepQuick,
}

fn consistent() -> Vec<MassMatrix> {
    vec![MassMatrix::Consistent]
}

impl super::vocabulary::TieredSweep for DynamicSweep {
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
pub enum DynamicMeasure {
    /// ‖u_h − u‖ / ‖u‖ over the points at the end.
    Displacement,
    /// The stress error of the form of eq (46) at the end (manufactured fields).
    Stress,
    /// |T_h − T| / T, T_h from the free end's zero crossings.
    Period,
    /// max_t |E(t) − E(0)| / E(0) (the cantilever: max_t |K + U − W| / max_t W).
    Energy,
    /// max_n |v(t_n) − v_ref(t_n)| / max_t |v_ref|: the tip deflection history against the
    /// sweep's reference (the cantilever).
    Tip,
}

impl DynamicMeasure {
    pub const ALL: [DynamicMeasure; 5] = [
        DynamicMeasure::Displacement,
        DynamicMeasure::Stress,
        DynamicMeasure::Period,
        DynamicMeasure::Energy,
        DynamicMeasure::Tip,
    ];
    pub fn name(self) -> &'static str {
        match self {
            DynamicMeasure::Displacement => "displacement",
            DynamicMeasure::Stress => "stress",
            DynamicMeasure::Period => "period",
            DynamicMeasure::Energy => "energy",
            DynamicMeasure::Tip => "tip",
        }
    }
    pub fn label(self) -> &'static str {
        match self {
            DynamicMeasure::Displacement => "relative L2 displacement error at the end",
            DynamicMeasure::Stress => "stress error at the end, form of eq (46)",
            DynamicMeasure::Period => "relative period error",
            DynamicMeasure::Energy => "largest relative energy change",
            DynamicMeasure::Tip => "tip deflection history error against the reference",
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
    pub measure: DynamicMeasure,
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
    pub measure: DynamicMeasure,
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
    pub measure: Option<DynamicMeasure>,
}

impl super::vocabulary::SweepFigure for FigureSpec {
    fn sweep(&self) -> &str {
        &self.sweep
    }
}

/// A dynamics study file (`studies/vibrating-bar.toml`, `studies/manufactured-dynamic.toml`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DynamicStudy {
    pub schema: i64,
    pub name: String,
    pub summary: String,
    /// Always "dynamics" ("bar" in files written before the kind had a second problem).
    pub problem: String,
    pub report_file: String,
    /// Cases expected to fail, and why; `study --check` fails on any other failed case.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub expected_failures: Vec<crate::study::vocabulary::ExpectedFailure>,
    /// The vibrating bar; exactly one of `bar` and `manufactured` is given.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bar: Option<BarSection>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub manufactured: Option<ManufacturedSection>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cantilever: Option<CantileverSection>,
    /// The material of every case (`[material]`): Hencky elasticity (`linear-elastic`), whose
    /// closed forms and strain energy the measures take.
    pub material: crate::study::material::MaterialTable,
    pub newton: NewtonSection,
    pub sweeps: Vec<DynamicSweep>,
    #[serde(default)]
    pub expect_rate: Vec<RateExpectation>,
    #[serde(default)]
    pub expect_at_most: Vec<BoundExpectation>,
    #[serde(default)]
    pub figures: Vec<FigureSpec>,
}

/// One case to solve.
#[derive(Debug, Clone, PartialEq)]
pub struct DynamicCase {
    pub id: String,
    pub method: Method,
    pub spec: CaseSpec,
}

/// The problem input of one case. Serialised untagged, so that a bar case's key (a hash of
/// its spec) is what it was before the kind had a second problem.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(untagged)]
// A study holds tens of cases: the cantilever's size (its spec and its reference's) costs
// nothing, and boxing it would lose Copy.
#[allow(clippy::large_enum_variant)]
pub enum CaseSpec {
    Bar(BarSpec),
    Manufactured(DynamicManufacturedSpec),
    Cantilever(CantileverCase),
    /// A bar measured against a reference analysis instead of the small-amplitude closed form.
    BarAgainst(BarCase),
}

/// A vibrating bar case and the analysis it is measured against.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct BarCase {
    pub spec: BarSpec,
    pub reference: BarReferenceRun,
}

/// The reference analysis of a bar case.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct BarReferenceRun {
    pub method: Method,
    pub spec: BarSpec,
}

/// A dynamic cantilever case and the analysis it is measured against.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct CantileverCase {
    pub spec: DynamicCantileverSpec,
    pub reference: ReferenceRun,
}

/// The reference analysis of a cantilever case.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ReferenceRun {
    pub method: Method,
    pub spec: DynamicCantileverSpec,
}

/// Elements through the depth of a cantilever spec (h = depth / elements).
fn through_depth(s: &DynamicCantileverSpec) -> usize {
    (s.beam.depth / s.beam.element_size).round() as usize
}

impl CaseSpec {
    pub fn validate(&self) -> Result<(), crate::solver::error::InputError> {
        match self {
            CaseSpec::Bar(b) => b.validate(),
            CaseSpec::Manufactured(m) => m.validate(),
            CaseSpec::Cantilever(c) => c.spec.validate().and_then(|_| c.reference.spec.validate()),
            CaseSpec::BarAgainst(c) => c.spec.validate().and_then(|_| c.reference.spec.validate()),
        }
    }

    /// Points (or Gauss points) × time steps: the planner's cost.
    pub fn cost(&self) -> f64 {
        match self {
            CaseSpec::Bar(b) | CaseSpec::BarAgainst(BarCase { spec: b, .. }) => {
                (b.elements * b.points_per_cell * b.time_steps()) as f64
            }
            CaseSpec::Manufactured(m) => {
                ((m.cells * m.points_per_cell).pow(m.dimension as u32) * m.time_steps()) as f64
            }
            CaseSpec::Cantilever(c) => {
                let b = &c.spec.beam;
                let cells = (b.length / b.element_size) * (b.depth / b.element_size);
                cells * (b.points_per_cell * b.points_per_cell * c.spec.time_steps()) as f64
            }
        }
    }

    /// What names the case in its sweep: its field (manufactured), mass matrix, elements
    /// (cells per side), points per cell and time steps per period.
    pub fn levels(&self) -> CaseLevels {
        match self {
            CaseSpec::Bar(b) | CaseSpec::BarAgainst(BarCase { spec: b, .. }) => CaseLevels {
                field: None,
                mass: b.mass,
                elements: b.elements,
                points_per_cell: b.points_per_cell,
                steps_per_period: b.steps_per_period,
            },
            CaseSpec::Manufactured(m) => CaseLevels {
                field: Some(m.field),
                mass: m.mass,
                elements: m.cells,
                points_per_cell: m.points_per_cell,
                steps_per_period: m.steps_per_period,
            },
            CaseSpec::Cantilever(c) => CaseLevels {
                field: None,
                mass: c.spec.mass,
                elements: through_depth(&c.spec),
                points_per_cell: c.spec.beam.points_per_cell,
                steps_per_period: c.spec.steps_per_period,
            },
        }
    }

    /// The period of the motion: the bar's 4L/c, the manufactured forcing's 2/c, the
    /// cantilever's time unit T₁ (the Euler–Bernoulli first mode).
    pub fn period(&self) -> f64 {
        match self {
            CaseSpec::Bar(b) | CaseSpec::BarAgainst(BarCase { spec: b, .. }) => b.period(),
            CaseSpec::Manufactured(m) => m.period(),
            CaseSpec::Cantilever(c) => c.spec.period(),
        }
    }
}

/// The sweep's lists after the tier's overrides.
struct SweepPlan {
    methods: Vec<Method>,
    elements: Vec<i64>,
    steps_per_period: Vec<i64>,
    reference: Option<SweepReference>,
}

/// The discretisation of one case ([`CaseSpec::levels`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CaseLevels {
    pub field: Option<Field>,
    pub mass: MassMatrix,
    pub elements: usize,
    pub points_per_cell: usize,
    pub steps_per_period: usize,
}

/// The methods a bar case can use: every material point family and the line elements.
pub const BAR_METHODS: [Method; Method::FAMILIES + 2] = Method::listed(Some(1), &[]);

/// The methods of a plane manufactured case: every material point family, Q4 and Q8.
pub const MANUFACTURED_METHODS: [Method; Method::FAMILIES + 2] = manufactured_dynamic::METHODS;
/// The methods of a 3D manufactured case: every material point family, Hex8 and Hex20.
pub const MANUFACTURED_METHODS_3D: [Method; Method::FAMILIES + 2] =
    crate::problems::manufactured3d::METHODS_3D;
/// The methods of a dynamic cantilever case: every material point family and Q8.
pub const CANTILEVER_METHODS: [Method; Method::FAMILIES + 1] = crate::problems::cantilever_dynamic::METHODS;

/// Most elements of one case (1D: cheap; a bound against typos).
const MAX_ELEMENTS: i64 = 65_536;
/// Most time steps per period.
const MAX_STEPS_PER_PERIOD: i64 = 65_536;

impl DynamicSweep {
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
            reference: q.and_then(|q| q.reference).or(self.reference),
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

impl DynamicStudy {
    pub fn sweep(&self, id: &str) -> Option<&DynamicSweep> {
        self.sweeps.iter().find(|s| s.id == id)
    }

    /// The bar's spec of one case.
    pub fn bar_spec(
        b: &BarSection,
        material: Material,
        newton: &NewtonSection,
        mass: MassMatrix,
        elements: i64,
        ppc: i64,
        steps: i64,
    ) -> BarSpec {
        BarSpec {
            length: b.length,
            material,
            density: b.density,
            velocity: b.velocity,
            elements: elements as usize,
            points_per_cell: ppc as usize,
            steps_per_period: steps as usize,
            periods: b.periods,
            beta: b.beta,
            gamma: b.gamma,
            mass,
            newton: newton.settings(),
            rho_infinity: b.rho_infinity,
        }
    }

    /// The dynamic cantilever of one case: `elements` through the depth, `ppc` points per
    /// cell along each axis, `steps` per T₁.
    pub fn cantilever_spec(
        c: &CantileverSection,
        material: Material,
        newton: &NewtonSection,
        mass: MassMatrix,
        elements: i64,
        ppc: i64,
        steps: i64,
    ) -> DynamicCantileverSpec {
        let beam = CantileverSpec {
            length: c.length,
            depth: c.depth,
            material,
            load: c.load,
            element_size: c.depth / elements as f64,
            points_per_cell: ppc as usize,
            grid_below: c.grid_below,
            grid_margin: c.grid_margin,
            newton: newton.settings(),
            ..CantileverSpec::default()
        };
        DynamicCantileverSpec {
            beam,
            density: c.density,
            periods: c.periods,
            steps_per_period: steps as usize,
            beta: c.beta,
            gamma: c.gamma,
            mass,
            rho_infinity: c.rho_infinity,
        }
    }

    /// The spec of one case of `sweep` by `method` (`None`: the file gives no problem section,
    /// a manufactured sweep has no field or a cantilever sweep no reference; validation
    /// reports each).
    #[allow(clippy::too_many_arguments)]
    fn case_spec_of(
        &self,
        sweep: &DynamicSweep,
        method: Method,
        reference: Option<&SweepReference>,
        mass: MassMatrix,
        elements: i64,
        ppc: i64,
        steps: i64,
    ) -> Option<CaseSpec> {
        let m = self.material.material();
        if let Some(c) = &self.cantilever {
            let r = reference?;
            let spec = Self::cantilever_spec(c, m, &self.newton, mass, elements, ppc, steps);
            return Some(CaseSpec::Cantilever(CantileverCase {
                spec,
                reference: ReferenceRun {
                    method: r.method.unwrap_or(method),
                    spec: Self::cantilever_spec(
                        c,
                        m,
                        &self.newton,
                        mass,
                        r.elements,
                        ppc,
                        r.steps_per_period,
                    ),
                },
            }));
        }
        let spec = self.case_spec(sweep, mass, elements, ppc, steps)?;
        Some(match (spec, reference, &self.bar) {
            (CaseSpec::Bar(spec), Some(r), Some(b)) => CaseSpec::BarAgainst(BarCase {
                spec,
                reference: BarReferenceRun {
                    method: r.method.unwrap_or(method),
                    spec: Self::bar_spec(b, m, &self.newton, mass, r.elements, ppc, r.steps_per_period),
                },
            }),
            (spec, _, _) => spec,
        })
    }

    /// The spec of one case of `sweep` (`None`: the file gives neither problem section, or a
    /// manufactured sweep without its field; validation reports both). Not for the cantilever,
    /// whose cases also depend on their method and reference.
    pub fn case_spec(
        &self,
        sweep: &DynamicSweep,
        mass: MassMatrix,
        elements: i64,
        ppc: i64,
        steps: i64,
    ) -> Option<CaseSpec> {
        if let Some(b) = &self.bar {
            return Some(CaseSpec::Bar(Self::bar_spec(
                b,
                self.material.material(),
                &self.newton,
                mass,
                elements,
                ppc,
                steps,
            )));
        }
        let m = self.manufactured.as_ref()?;
        let field = sweep.field?;
        Some(CaseSpec::Manufactured(DynamicManufacturedSpec {
            field,
            amplitude: match field {
                Field::AxisAligned => m.amplitude.axis_aligned,
                Field::Vortex => m.amplitude.vortex,
            },
            material: self.material.material(),
            density: m.density,
            cells: elements as usize,
            points_per_cell: ppc as usize,
            steps_per_period: steps as usize,
            periods: m.periods,
            beta: m.beta,
            gamma: m.gamma,
            mass,
            newton: self.newton.settings(),
            domain_update: Default::default(),
            dimension: m.dimension,
            rho_infinity: m.rho_infinity,
        }))
    }

    /// `<method>[-<field>]-<mass>-e<elements>-p<ppc>-n<steps per period>`.
    pub fn case_id(method: Method, spec: &CaseSpec) -> String {
        let CaseLevels {
            field,
            mass,
            elements,
            points_per_cell: ppc,
            steps_per_period: steps,
        } = spec.levels();
        let mass = match mass {
            MassMatrix::Consistent => "cm",
            MassMatrix::Lumped => "lm",
        };
        let field = field.map_or(String::new(), |f| format!("-{}", f.name()));
        // A cantilever case names its reference: one discretisation may be measured against
        // two (a space and a time sweep).
        let reference = match spec {
            CaseSpec::Cantilever(c) => format!(
                "-vs-{}-e{}-n{}",
                c.reference.method.name(),
                through_depth(&c.reference.spec),
                c.reference.spec.steps_per_period
            ),
            CaseSpec::BarAgainst(c) => format!(
                "-vs-{}-e{}-n{}",
                c.reference.method.name(),
                c.reference.spec.elements,
                c.reference.spec.steps_per_period
            ),
            _ => String::new(),
        };
        format!(
            "{}{field}-{mass}-e{elements}-p{ppc}-n{steps}{reference}",
            method.name()
        )
    }

    /// The methods a case of this study may use.
    pub fn methods(&self) -> &'static [Method] {
        if self.cantilever.is_some() {
            return &CANTILEVER_METHODS;
        }
        match &self.manufactured {
            None => &BAR_METHODS,
            Some(m) if m.dimension == 3 => &MANUFACTURED_METHODS_3D,
            Some(_) => &MANUFACTURED_METHODS,
        }
    }

    fn sweep_cases(&self, s: &DynamicSweep, plan: &SweepPlan) -> Vec<DynamicCase> {
        let mut out = vec![];
        for &method in &plan.methods {
            for &mass in &s.mass {
                for &ppc in &s.points_per_cell {
                    for &e in &plan.elements {
                        for &n in &plan.steps_per_period {
                            let Some(spec) =
                                self.case_spec_of(s, method, plan.reference.as_ref(), mass, e, ppc, n)
                            else {
                                continue;
                            };
                            out.push(DynamicCase {
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

    pub fn cases(&self, tier: Tier) -> (Vec<DynamicCase>, SweepIndex) {
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
            expected_problem: "dynamics",
            name: &self.name,
            summary: &self.summary,
            report_file: &self.report_file,
        })?;
        chk.newton("newton", &self.newton)?;
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
