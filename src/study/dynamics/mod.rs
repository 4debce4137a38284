//! The dynamics study kind (implicit dynamics, `problem = "dynamics"`): a study file of one
//! dynamic problem, the vibrating bar (`[bar]`, `studies/vibrating-bar.toml`) or the dynamic
//! manufactured fields (`[manufactured]`, `studies/manufactured-dynamic.toml`) → `results.json`
//! → `report.md` and its figures. A sweep is methods × mass matrices × elements (cells) ×
//! points per cell × time steps per period, with either the elements (space convergence at a
//! small Δt) or the time steps (time convergence on a fine grid) varied; each series gets a
//! rate fitted against h or Δt, and `[[expect_rate]]` / `[[expect_at_most]]` turn rates, errors,
//! periods and energy drifts into checks.

mod cases;
pub mod kind;
pub mod records;
mod validate;

pub use cases::*;

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
