//! What a manufactured-solution study's `results.json` holds besides the envelope: the case
//! records (the two error measures) and the fitted rates.

use super::{ErrorMeasure, ManufacturedStudy};
use crate::basis::method::Method;
use crate::mpm::DomainUpdate;
use crate::problems::manufactured::{Field, PointValue};
use crate::problems::manufactured3d::PointValue3;
use crate::study::results::{case_record, Envelope, SolveRecord};
use serde::{Deserialize, Serialize};

/// Result of one case.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ManufacturedRecord {
    pub id: String,
    pub field: Field,
    pub method: Method,
    /// iGIMP only.
    pub domain_update: Option<DomainUpdate>,
    /// Cells per side; h = 1 / cells.
    pub cells: usize,
    /// MPM and iGIMP only.
    pub points_per_cell: Option<usize>,
    /// Status, failure, Newton iterations and residual histories (flattened into the record).
    #[serde(flatten)]
    pub solve: SolveRecord,
    /// Converged cases only.
    pub displacement_error: Option<f64>,
    pub stress_error: Option<f64>,
    /// Material or Gauss points.
    pub points: usize,
}

case_record!(ManufacturedRecord);

impl ManufacturedRecord {
    pub fn error(&self, m: ErrorMeasure) -> Option<f64> {
        match m {
            ErrorMeasure::Displacement => self.displacement_error,
            ErrorMeasure::Stress => self.stress_error,
        }
        .filter(|e| e.is_finite() && *e > 0.0)
    }
}

/// One series of a sweep: method, iGIMP domain update and points per cell.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Series {
    pub method: Method,
    pub domain_update: Option<DomainUpdate>,
    pub points_per_cell: Option<usize>,
}

impl Series {
    pub fn of(r: &ManufacturedRecord) -> Self {
        Series {
            method: r.method,
            domain_update: r.domain_update,
            points_per_cell: r.points_per_cell,
        }
    }

    /// The series' name in tables and legends; `dimension` (2 or 3) counts the points per cell.
    pub fn label(&self, dimension: usize) -> String {
        let mut s = self.method.label().to_string();
        if let Some(u) = self.domain_update {
            s.push_str(match u {
                DomainUpdate::Stretch => " (U, eq 39)",
                DomainUpdate::FDiagonal => " (F-diagonal, eq 37)",
                DomainUpdate::Fixed => " (fixed domains)",
            });
        }
        if let Some(p) = self.points_per_cell {
            let per_cell = vec![p.to_string(); dimension.max(1)].join("×");
            s.push_str(&format!(", {per_cell} points"));
        }
        s
    }
}

/// The expected band of a rate, with its source.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ExpectedBand {
    pub rate: f64,
    pub tolerance: f64,
    pub source: String,
}

/// Fitted rate of one series under one measure.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RateRecord {
    pub sweep: String,
    #[serde(flatten)]
    pub series: Series,
    pub measure: ErrorMeasure,
    /// Slope of log(error) against log(h); `None` with fewer than two converged levels.
    pub slope: Option<f64>,
    /// Cells per side of the levels the fit used.
    pub cells_used: Vec<usize>,
    pub expected: Option<ExpectedBand>,
}

/// The manufactured study's measures in `results.json`: the fitted rates.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct ManufacturedMeasures {
    pub rates: Vec<RateRecord>,
}

/// `results.json` of a manufactured-solution study.
pub type ManufacturedResults = Envelope<ManufacturedStudy, ManufacturedRecord, ManufacturedMeasures>;

/// A case's points and each one's stress error ‖σ_p − σ(X_p)‖_F / σ_max (the summand of the
/// stress measure, for the domain figures and ParaView): `points` in 2D, `points_3d` in 3D.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CasePoints {
    pub points: Vec<PointValue>,
    pub stress_error: Vec<f64>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub points_3d: Vec<PointValue3>,
}

impl ManufacturedResults {
    /// The cases of one series of a sweep, coarse to fine.
    pub fn series_cases(&self, sweep: &str, s: &Series) -> Vec<&ManufacturedRecord> {
        let mut v: Vec<&ManufacturedRecord> = self
            .sweep(sweep)
            .into_iter()
            .filter(|c| Series::of(c) == *s)
            .collect();
        v.sort_by_key(|c| c.cells);
        v
    }

    /// The series of a sweep, in plan order.
    pub fn sweep_series(&self, sweep: &str) -> Vec<Series> {
        let mut out: Vec<Series> = vec![];
        for c in self.sweep(sweep) {
            if !out.contains(&Series::of(c)) {
                out.push(Series::of(c));
            }
        }
        out
    }
}
