//! What a column study's `results.json` holds besides the envelope: the case records, the
//! fitted rates and comparisons and the analytical column. The kind fills it, the renderer
//! reads it only.

use super::{ColumnStudy, Measure};
use crate::basis::method::Method;
use crate::solver::newton::NewtonSettings;
use crate::study::results::{case_record, Envelope, SolveRecord};
use serde::{Deserialize, Serialize};

/// Header of the per-case point files; the material's internal variables follow by name.
pub const POINTS_HEADER: &str = "z0,z,volume0,sigma_zz,f_zz";
/// Header of the per-case point files of plastic studies (adds the lateral stress), before
/// the internal variables.
pub const POINTS_HEADER_PLASTIC: &str = "z0,z,volume0,sigma_zz,f_zz,sigma_xx";

/// Result of one case.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ColumnRecord {
    pub id: String,
    pub method: Method,
    /// Total weight W.
    pub load: f64,
    pub elements: usize,
    /// `None` (null) for FEM.
    pub points_per_cell: Option<usize>,
    pub load_steps: usize,
    pub newton: NewtonSettings,
    /// Status, failure, Newton iterations and residual histories (flattened into the record).
    #[serde(flatten)]
    pub solve: SolveRecord,
    /// Eq (46), converged cases only.
    pub stress_error: Option<f64>,
    /// Eq (47) against the exact analytical base F, converged cases only.
    pub f_error: Option<f64>,
    /// Eq (46) on σ_xx (plastic studies only).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sigma_xx_error: Option<f64>,
    /// Yield height seen by the points (plastic studies only).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub yield_height: Option<f64>,
    /// |yield_height − analytical| / L0 (plastic studies only).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub yield_height_error: Option<f64>,
    pub top_displacement: Option<f64>,
    pub base_f: Option<f64>,
    /// Number of material or Gauss points (rows of the point file).
    pub points: usize,
}

case_record!(ColumnRecord);

/// The column's measures in `results.json`: fitted rates, comparisons and the analytical
/// column, all evaluated when the study is solved (so that rendering reads only this file).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct ColumnMeasures {
    pub rates: Vec<RateRecord>,
    pub comparisons: Vec<ComparisonRecord>,
    /// The analytical column at every load the cases, tables and figures use.
    #[serde(default)]
    pub analytical: Vec<AnalyticalRecord>,
}

/// `results.json` of a column study.
pub type ColumnResults = Envelope<ColumnStudy, ColumnRecord, ColumnMeasures>;

/// Samples of the analytical profile ([`AnalyticalRecord::profile`]): 401 equally spaced
/// reference heights, 0 to L0.
pub const PROFILE_SAMPLES: usize = 400;

/// The analytical column (eqs 42–45, Appendix A) at one load.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AnalyticalRecord {
    pub load: f64,
    /// u(L0).
    pub top_displacement: f64,
    /// F(0), the base deformation gradient of eq (47).
    pub base_f: f64,
    /// Height where yield starts (Kirchhoff criterion); `None` if elastic throughout.
    pub yield_height: Option<f64>,
    /// The paper's L0 − ρy/(ρ0 g) (Cauchy criterion), for plastic studies.
    pub paper_yield_height: Option<f64>,
    /// (Z, z = Z + u(Z), σzz, σxx) at [`PROFILE_SAMPLES`] + 1 reference heights Z.
    pub profile: Vec<[f64; 4]>,
}

impl ColumnResults {
    /// The analytical column at `load`, if the run recorded it.
    pub fn analytical_at(&self, load: f64) -> Option<&AnalyticalRecord> {
        self.measures.analytical.iter().find(|a| a.load == load)
    }
}

/// The band a fitted rate must fall in, with its source.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ExpectedBand {
    pub rate: f64,
    pub tolerance: f64,
    pub source: String,
}

/// Fitted rate of one series.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RateRecord {
    pub sweep: String,
    pub method: Method,
    pub load: f64,
    pub points_per_cell: Option<usize>,
    pub measure: Measure,
    /// Slope of log(error) against log(h); `None` with fewer than two converged cases.
    pub slope: Option<f64>,
    /// Element counts the fit used.
    pub elements_used: Vec<usize>,
    pub expected: Option<ExpectedBand>,
    /// `None` when nothing is expected, or the series was not run in this tier.
    pub pass: Option<bool>,
}

/// Outcome of an `[[compare]]` check.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ComparisonRecord {
    pub sweep: String,
    pub load: f64,
    pub measure: Measure,
    pub lower: Method,
    pub higher: Method,
    /// Element counts where both methods converged.
    pub elements_checked: Vec<usize>,
    /// error(lower) / error(higher) at each checked element count.
    pub ratios: Vec<f64>,
    /// `None` when no element count could be checked.
    pub pass: Option<bool>,
    pub source: String,
}
