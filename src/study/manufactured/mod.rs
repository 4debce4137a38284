//! The manufactured-solution study kind: `studies/manufactured.toml` → `results.json` →
//! `report.md` and the convergence and domain figures. A sweep is one field × methods ×
//! iGIMP domain updates × cells per side × points per cell; each series (method, domain
//! update, points per cell) gets a rate fitted over its finest converged levels, and
//! `[[expect_rate]]` bands turn rates into checks.

mod checks;
pub mod kind;
mod plan;
pub mod records;

use super::material::MaterialTable;
use super::vocabulary::NewtonSection;
use crate::basis::method::Method;
use crate::mpm::DomainUpdate;
pub use crate::problems::manufactured::Field;
use crate::problems::manufactured::ManufacturedSpec;

/// The id of the check of one series' rate: `<sweep>-<method>[-<update>][-p<ppc>]-<measure>-rate`
/// (the cross-method report finds a rate's verdict by it).
pub fn rate_check_id(
    sweep: &str,
    method: Method,
    domain_update: Option<DomainUpdate>,
    points_per_cell: Option<usize>,
    measure: &str,
) -> String {
    format!(
        "{sweep}-{}{}{}-{measure}-rate",
        method.name(),
        domain_update.map_or(String::new(), |u| format!("-{}", plan::update_tag(u))),
        points_per_cell.map_or(String::new(), |p| format!("-p{p}")),
    )
}
/// A case's material or Gauss point, as the point files and `domains.json` store it.
pub use crate::problems::manufactured::PointValue;
use serde::{Deserialize, Serialize};

pub use records::{ManufacturedMeasures, ManufacturedRecord, ManufacturedResults, RateRecord};

/// The amplitude of each field: A of the axis-aligned field, θ₀ (radians) of the vortex.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AmplitudeSection {
    pub axis_aligned: f64,
    pub vortex: f64,
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
    pub cells: Option<Vec<i64>>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub points_per_cell: Option<Vec<i64>>,
}

/// One field × methods × domain updates × cells × points per cell.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ManufacturedSweep {
    pub id: String,
    pub title: String,
    pub field: Field,
    pub methods: Vec<Method>,
    /// iGIMP domain updates (eq 39 `stretch`, eq 37 `f-diagonal`, `fixed`); default stretch.
    #[serde(default = "default_updates")]
    pub domain_updates: Vec<DomainUpdate>,
    /// Cells (elements) per side of the unit square.
    pub cells: Vec<i64>,
    /// Material points per cell along each axis (MPM, iGIMP).
    pub points_per_cell: Vec<i64>,
    /// Rates are fitted over this many finest converged levels (>= 2); all if absent.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fit_points: Option<i64>,
    #[serde(default)]
    pub quick: SweepQuick,
}

fn plane() -> i64 {
    2
}

fn is_plane(d: &i64) -> bool {
    *d == 2
}

fn default_updates() -> Vec<DomainUpdate> {
    vec![DomainUpdate::Stretch]
}

/// Error measure of a case.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ErrorMeasure {
    /// ‖x_p − x(X_p)‖ / ‖u(X_p)‖.
    Displacement,
    /// Σ ‖σ_p − σ(X_p)‖ v_p0 / (σ_max |Ω₀|), the form of eq (46).
    Stress,
}

impl super::vocabulary::TieredSweep for ManufacturedSweep {
    fn id(&self) -> &str {
        &self.id
    }
    /// `quick = { skip = true }` makes it a full-tier sweep.
    fn runs_in(&self, tier: super::Tier) -> bool {
        tier == super::Tier::Full || !self.quick.skip
    }
}

impl super::vocabulary::SweepFigure for FigureSpec {
    fn sweep(&self) -> &str {
        &self.sweep
    }
}

impl ErrorMeasure {
    pub const ALL: [ErrorMeasure; 2] = [ErrorMeasure::Displacement, ErrorMeasure::Stress];
    pub fn name(self) -> &'static str {
        match self {
            ErrorMeasure::Displacement => "displacement",
            ErrorMeasure::Stress => "stress",
        }
    }
    pub fn label(self) -> &'static str {
        match self {
            ErrorMeasure::Displacement => "relative L2 displacement error",
            ErrorMeasure::Stress => "stress error, form of eq (46)",
        }
    }
}

/// The fitted rate of one series must lie in `rate ± tolerance`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RateExpectation {
    pub sweep: String,
    pub method: Method,
    /// iGIMP only; default stretch.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub domain_update: Option<DomainUpdate>,
    /// Required for MPM and iGIMP.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub points_per_cell: Option<i64>,
    pub measure: ErrorMeasure,
    pub rate: f64,
    pub tolerance: f64,
    /// Only in this tier (its levels differ: the quick tier fits coarser ones); absent: both.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tier: Option<super::Tier>,
    pub source: String,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FigureKind {
    /// Error against cells per side, log-log, every series of the sweep.
    Convergence,
    /// Final domains of one iGIMP case coloured by the pointwise stress error.
    Domains,
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
    pub measure: Option<ErrorMeasure>,
    /// Domain figures: the iGIMP case.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub domain_update: Option<DomainUpdate>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cells: Option<i64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub points_per_cell: Option<i64>,
}

/// `studies/manufactured.toml`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ManufacturedStudy {
    pub schema: i64,
    pub name: String,
    pub summary: String,
    /// Always "manufactured".
    pub problem: String,
    pub report_file: String,
    /// Cases expected to fail, and why; `study --check` fails on any other failed case.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub expected_failures: Vec<crate::study::vocabulary::ExpectedFailure>,
    /// 2 (the unit square, plane strain; the default) or 3 (the unit cube: methods mpm,
    /// igimp, fem-hex8, fem-hex20; points_per_cell³ points per cell; no domain figures).
    #[serde(default = "plane", skip_serializing_if = "is_plane")]
    pub dimension: i64,
    /// The material of every case (`[material]`): Hencky elasticity (`linear-elastic`), whose
    /// stresses and body force the exact solutions are.
    pub material: MaterialTable,
    pub amplitude: AmplitudeSection,
    pub load_steps: i64,
    pub newton: NewtonSection,
    pub sweeps: Vec<ManufacturedSweep>,
    #[serde(default)]
    pub expect_rate: Vec<RateExpectation>,
    #[serde(default)]
    pub figures: Vec<FigureSpec>,
}

/// One case to solve.
#[derive(Debug, Clone, PartialEq)]
pub struct ManufacturedCase {
    pub id: String,
    pub method: Method,
    pub spec: ManufacturedSpec,
}
