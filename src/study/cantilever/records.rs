//! What a cantilever study's `results.json` holds besides the envelope: the case records and
//! the kind's measures. The kind fills them, the checks and the renderer read them.

use super::CantileverStudy;
use crate::basis::method::Method;
use crate::mpm::{DomainUpdate, VolumeUpdate};
use crate::problems::cantilever::EndDisplacement;
use crate::study::results::{case_record, Envelope, SolveRecord};
use serde::{Deserialize, Serialize};

/// The elastica at one load: the end displacement in the model's axes.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ElasticaPoint {
    pub load: f64,
    /// α = PL²/EI.
    pub alpha: f64,
    pub u_over_l: f64,
    /// −(deflection in the load direction)/L.
    pub v_over_l: f64,
}

/// The elastica load path of one beam.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ElasticaPath {
    pub plane_strain: bool,
    pub bending_stiffness: f64,
    pub points: Vec<ElasticaPoint>,
}

/// Result of one case.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CantileverRecord {
    pub id: String,
    pub method: Method,
    pub domain_update: Option<DomainUpdate>,
    pub volume_update: Option<VolumeUpdate>,
    pub depth: f64,
    pub load: f64,
    pub element_size: f64,
    pub load_steps: usize,
    /// Status, failure, Newton iterations and residual histories (flattened into the record).
    #[serde(flatten)]
    pub solve: SolveRecord,
    /// End displacement (mean of the loaded points; FEM: the loaded node) after each converged step.
    pub end: Vec<EndDisplacement>,
    /// Final u/L and v/L (converged cases only).
    pub u_over_l: Option<f64>,
    pub v_over_l: Option<f64>,
    /// Plane-strain elastica of this beam at the full load, and the relative differences
    /// (continuum − elastica)/|elastica|.
    pub elastica: Option<ElasticaPoint>,
    pub difference_u: Option<f64>,
    pub difference_v: Option<f64>,
    /// Initial domain half-length and the smallest half-length after each converged step.
    pub initial_half_length: f64,
    pub min_half_length: Vec<f64>,
    /// Indices of the loaded points in the domain snapshots (3D: those in the snapshot's layer).
    pub loaded_points: Option<Vec<usize>>,
}

/// One row of the depth study.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DepthRow {
    pub case: String,
    pub elements_through_depth: i64,
    pub depth: f64,
    pub load: f64,
    pub element_size: f64,
    pub u_over_l: Option<f64>,
    pub v_over_l: Option<f64>,
    pub difference_u: Option<f64>,
    pub difference_v: Option<f64>,
}

/// One case of a refinement against the reference method at the same element size.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RefinementRow {
    pub refinement: String,
    pub case: String,
    pub method: Method,
    pub element_size: f64,
    pub u_over_l: Option<f64>,
    pub v_over_l: Option<f64>,
    /// u/u_ref − 1 and v/v_ref − 1 against the reference method's case at the same element
    /// size (positive: a longer displacement than the reference's).
    pub difference_u: Option<f64>,
    pub difference_v: Option<f64>,
}

/// The cantilever's measures in `results.json`: the elastica and the depth study.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct CantileverMeasures {
    /// Plane strain first, then plane stress when asked for.
    pub elastica: Vec<ElasticaPath>,
    pub depth_study: Vec<DepthRow>,
    /// Grid convergence index of the end displacement at each depth of the depth study, then
    /// of every method of every refinement.
    #[serde(default)]
    pub gci: Vec<crate::study::checks::GciRecord>,
    /// Every refinement case against its reference at the same element size.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub refinement: Vec<RefinementRow>,
}

/// `results.json` of the cantilever study.
pub type CantileverResults = Envelope<CantileverStudy, CantileverRecord, CantileverMeasures>;

case_record!(CantileverRecord);
