//! What a dynamics study's `results.json` holds besides the envelope: the case records
//! (errors; the bar's period and energy) and the fitted rates.

use super::{DynamicMeasure, DynamicStudy, Refinement};
use crate::basis::method::Method;
use crate::solver::dynamics::MassMatrix;
use crate::study::results::{case_record, Envelope, SolveRecord};
use serde::{Deserialize, Serialize};

/// Result of one case.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DynamicRecord {
    pub id: String,
    pub method: Method,
    /// The manufactured field (manufactured studies).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub field: Option<crate::problems::manufactured::Field>,
    pub mass: MassMatrix,
    pub elements: usize,
    pub points_per_cell: usize,
    pub steps_per_period: usize,
    /// Status, failure and Newton iterations (flattened into the record); of the residual
    /// histories only the last time step's is kept (a case runs up to 196,608 steps, whose
    /// histories made a 364 MB `results.json`), summarised by the two fields below.
    #[serde(flatten)]
    pub solve: SolveRecord,
    /// Converged time steps, and the most Newton iterations any of them took.
    pub time_steps: usize,
    pub max_newton_iterations: usize,
    /// Time steps accepted at their round-off floor (none silently: listed here by count).
    pub steps_at_floor: usize,
    /// Time steps whose increment Newton could not take at once and the load stepping cut
    /// (their Δt is smaller than the nominal one, so a convergence series with any is not at
    /// uniform Δt); absent in results written before they were counted.
    #[serde(default)]
    pub steps_cut_back: usize,
    /// Converged cases only.
    pub displacement_error: Option<f64>,
    /// The stress error at the end (manufactured fields; the bar has none).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stress_error: Option<f64>,
    /// The period measured from the free end's zero crossings, and its relative error.
    pub measured_period: Option<f64>,
    pub period_error: Option<f64>,
    pub energy_drift: Option<f64>,
    /// The cantilever: the tip deflection history's error against the sweep's reference
    /// ([`DynamicMeasure::Tip`]), and the largest downward tip deflection.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tip_error: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub peak_deflection: Option<f64>,
    /// Why the sweep's reference analysis has no result (its cases then have no reference
    /// measures).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub reference_failure: Option<String>,
    pub points: usize,
}

case_record!(DynamicRecord);

impl DynamicRecord {
    pub fn measure(&self, m: DynamicMeasure) -> Option<f64> {
        match m {
            DynamicMeasure::Displacement => self.displacement_error,
            DynamicMeasure::Stress => self.stress_error,
            DynamicMeasure::Period => self.period_error,
            DynamicMeasure::Energy => self.energy_drift,
            DynamicMeasure::Tip => self.tip_error,
        }
    }
    pub fn series(&self) -> Series {
        Series {
            method: self.method,
            mass: self.mass,
            points_per_cell: self.points_per_cell,
        }
    }
}

/// The cases of a sweep that differ only in the refined variable.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Serialize, Deserialize)]
pub struct Series {
    pub method: Method,
    pub mass: MassMatrix,
    pub points_per_cell: usize,
}

impl Series {
    pub fn label(&self) -> String {
        let mass = self.mass.name();
        format!(
            "{} ({mass} mass, {} ppc)",
            self.method.label(),
            self.points_per_cell
        )
    }
}

/// A band a rate is checked against.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ExpectedBand {
    pub rate: f64,
    pub tolerance: f64,
    pub source: String,
}

/// Fitted rate of one series under one measure: slope of log(measure) against log(h) or
/// log(Δt).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RateRecord {
    pub sweep: String,
    pub series: Series,
    pub measure: DynamicMeasure,
    pub refinement: Refinement,
    pub slope: Option<f64>,
    /// Elements (space) or steps per period (time) of the fitted levels.
    pub levels_used: Vec<usize>,
    pub expected: Option<ExpectedBand>,
}

#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct DynamicMeasures {
    pub rates: Vec<RateRecord>,
    /// The period of the motion: the bar's 4L/c, the manufactured forcing's 2/c; the
    /// cantilever's time unit T₁ (its periods are measured against its references).
    pub exact_period: f64,
}

/// `results.json` of a dynamics study.
pub type DynamicResults = Envelope<DynamicStudy, DynamicRecord, DynamicMeasures>;

impl DynamicResults {
    /// The series of a sweep in plan order.
    pub fn sweep_series(&self, sweep: &str) -> Vec<Series> {
        let mut out: Vec<Series> = vec![];
        for c in self.sweep(sweep) {
            if !out.contains(&c.series()) {
                out.push(c.series());
            }
        }
        out
    }

    /// One series' cases, coarse to fine in the sweep's refined variable.
    pub fn series_cases(&self, sweep: &str, s: &Series) -> Vec<&DynamicRecord> {
        let mut v: Vec<&DynamicRecord> = self
            .sweep(sweep)
            .into_iter()
            .filter(|c| c.series() == *s)
            .collect();
        v.sort_by_key(|c| (c.elements, c.steps_per_period));
        v
    }
}
