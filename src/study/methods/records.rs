//! `<out>/methods/methods.json`'s records, and how they are read out of a study's results.

use crate::study::external::StudyMethod as Method;
use crate::study::results::Software;
use serde::{Deserialize, Serialize};
use serde_json::Value;

/// `<out>/methods/methods.json`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MethodsResults {
    pub software: Software,
    /// Each study read: name, tier and its results' software line.
    pub sources: Vec<Source>,
    /// Fitted log-log slopes.
    pub rates: Vec<RateRow>,
    /// End values against a reference (compaction, cantilever).
    pub references: Vec<ReferenceRow>,
    /// Overlay figures: one per group with at least [`MIN_METHODS_PER_FIGURE`] methods.
    pub groups: Vec<Group>,
}

/// Groups with fewer methods are tabulated but not drawn (their own study's report draws
/// them).
pub const MIN_METHODS_PER_FIGURE: usize = 3;

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Source {
    pub study: String,
    pub tier: String,
    pub software: String,
}

/// One fitted rate.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RateRow {
    pub study: String,
    /// The group's keys in words (e.g. "W = 40000, 2 points per cell").
    pub group: String,
    pub measure: String,
    pub sweep: String,
    pub method: Method,
    pub slope: Option<f64>,
    /// The resolutions fitted (elements or cells per side).
    pub levels: Vec<f64>,
    /// The study's asserted band (rate ± tolerance), if any, and whether it held.
    pub expected: Option<(f64, f64)>,
    pub pass: Option<bool>,
}

/// One method's end value against the study's reference: at each element size and, where the
/// three finest are in the asymptotic range, the GCI extrapolation.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ReferenceRow {
    pub study: String,
    pub sweep: String,
    pub measure: String,
    pub method: Method,
    /// What the values are divided by, in words.
    pub reference: String,
    /// (h, value / reference) of each converged case.
    pub ratios: Vec<(f64, f64)>,
    pub extrapolated_ratio: Option<f64>,
    pub observed_order: Option<f64>,
    pub gci_note: String,
}

/// An overlay: one series per method, on the same axes.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Group {
    pub id: String,
    pub title: String,
    pub x_desc: String,
    pub y_desc: String,
    pub log_y: bool,
    pub series: Vec<(Method, Vec<(f64, f64)>)>,
}

pub(super) fn f(v: &Value) -> Option<f64> {
    v.as_f64()
}

pub(super) fn method_of(v: &Value) -> Option<Method> {
    serde_json::from_value(v.clone()).ok()
}

/// The error field of a rate's measure in a case record.
pub(super) fn case_field(measure: &str) -> &str {
    match measure {
        "displacement" => "displacement_error",
        "stress" => "stress_error",
        "period" => "period_error",
        "tip" => "tip_error",
        m => m,
    }
}
