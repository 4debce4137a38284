//! What a column study's results.json holds: the case records, the fitted rates and
//! comparisons, the sweep index and the timing. The runner fills it, the rate analysis reads
//! and extends it, the renderer reads it only; this module imports none of them.

use super::{Measure, StudySpec, Tier};
use crate::newton::NewtonSettings;
use crate::problems::column::Method;
use serde::{Deserialize, Serialize};

/// Header of the per-case point files.
pub const POINTS_HEADER: &str = "z0,z,volume0,sigma_zz,f_zz";
/// Header of the per-case point files of plastic studies (adds the lateral stress).
pub const POINTS_HEADER_PLASTIC: &str = "z0,z,volume0,sigma_zz,f_zz,sigma_xx";

#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum CaseStatus {
    /// Every load step converged.
    Converged,
    /// A load step failed (see `failure`); errors are not reported.
    Failed,
    /// The solver refused the input (see `failure.reason`); nothing was solved.
    Rejected,
}

/// Newton residual history of one converged load step.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StepRecord {
    pub step: usize,
    pub load_factor: f64,
    /// Normalised out-of-balance force before the first and after each Newton update.
    pub residuals: Vec<f64>,
}

/// Why a case did not converge.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FailureRecord {
    /// Load step that failed (from 1); 0 when the input was rejected.
    pub step: usize,
    pub reason: String,
    /// Residual history of the failing step.
    pub residuals: Vec<f64>,
}

/// Result of one case.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CaseRecord {
    pub id: String,
    pub method: Method,
    /// Total weight W.
    pub load: f64,
    pub elements: usize,
    /// `None` (null) for FEM.
    pub points_per_cell: Option<usize>,
    pub load_steps: usize,
    pub newton: NewtonSettings,
    pub status: CaseStatus,
    pub failure: Option<FailureRecord>,
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
    /// Newton iterations summed over the converged steps.
    pub newton_iterations: usize,
    pub steps: Vec<StepRecord>,
    pub wall_seconds: f64,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Software {
    pub name: String,
    pub version: String,
}

/// Wall-clock data: the only part of `results.json` that changes from run to run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Timing {
    pub wall_seconds: f64,
    pub threads: usize,
}

/// Everything the renderers need: `results.json`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StudyResults {
    pub software: Software,
    /// File name of the study file the inputs came from.
    pub study_file: String,
    pub tier: Tier,
    /// The study inputs as parsed.
    pub study: StudySpec,
    /// Case ids of each sweep.
    pub sweep_cases: CaseIndex,
    pub cases: Vec<CaseRecord>,
    pub rates: Vec<RateRecord>,
    pub comparisons: Vec<ComparisonRecord>,
    /// The analytical column at every load the cases, tables and figures use, evaluated when
    /// the study is solved (so that rendering reads only this file).
    #[serde(default)]
    pub analytical: Vec<AnalyticalRecord>,
    pub timing: Timing,
}

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

impl StudyResults {
    /// The analytical column at `load`, if the run recorded it.
    pub fn analytical_at(&self, load: f64) -> Option<&AnalyticalRecord> {
        self.analytical.iter().find(|a| a.load == load)
    }

    pub fn case(&self, id: &str) -> Option<&CaseRecord> {
        self.cases.iter().find(|c| c.id == id)
    }

    /// Copy with every wall-clock field zeroed, for comparing two runs.
    pub fn without_timing(&self) -> Self {
        let mut r = self.clone();
        r.timing = Timing {
            wall_seconds: 0.0,
            threads: 0,
        };
        r.cases.iter_mut().for_each(|c| c.wall_seconds = 0.0);
        r
    }

    /// Rates and comparisons with an expectation: (passed, failed, not evaluated).
    pub fn check_counts(&self) -> (usize, usize, usize) {
        let passes = self
            .rates
            .iter()
            .filter(|r| r.expected.is_some())
            .map(|r| r.pass)
            .chain(self.comparisons.iter().map(|c| c.pass));
        let mut n = (0, 0, 0);
        for p in passes {
            match p {
                Some(true) => n.0 += 1,
                Some(false) => n.1 += 1,
                None => n.2 += 1,
            }
        }
        n
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

/// Which case ids belong to which sweep (a case may belong to several).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct CaseIndex {
    /// (sweep id, case ids in run order).
    pub sweeps: Vec<(String, Vec<String>)>,
}

impl CaseIndex {
    pub fn of_sweep(&self, id: &str) -> &[String] {
        self.sweeps
            .iter()
            .find(|(s, _)| s == id)
            .map_or(&[], |(_, v)| v.as_slice())
    }
}
