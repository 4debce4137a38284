//! What a compaction study's `results.json` holds besides the envelope: the case records and
//! the kind's measures. The kind fills them, the checks and the renderer read them.

use super::CompactionStudy;
use crate::basis::method::Method;
use crate::study::results::{case_record, Envelope, SolveRecord};
use serde::{Deserialize, Serialize};

/// Result of one case.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CompactionRecord {
    pub id: String,
    pub method: Method,
    /// Element size h.
    pub h: f64,
    /// Points per element along each axis; `None` (null) for FEM.
    pub points_per_cell: Option<usize>,
    pub yield_stress: Option<f64>,
    pub weak_node_tolerance: f64,
    /// Ghost penalty factor γ of the case (0: off; FEM: 0).
    pub ghost_gamma: f64,
    /// Faces carrying the ghost penalty (`cut` or `all`).
    pub ghost_faces: crate::discretise::ghost::GhostFaces,
    /// Load steps that needed cutbacks, and the failed attempts in all.
    pub steps_cut: usize,
    pub cutbacks: usize,
    /// Status, failure, Newton iterations and residual histories (flattened into the record).
    #[serde(flatten)]
    pub solve: SolveRecord,
    /// Bottom-right point's horizontal displacement plus half its domain's growth (Figure 17);
    /// converged cases only.
    pub max_horizontal_displacement: Option<f64>,
    /// The same measure at the last converged step of a failed case.
    pub last_converged_displacement: Option<f64>,
    /// Weak-node constraints applied, summed over the load steps.
    pub weak_nodes_treated: usize,
    /// Material points (iGIMP) or elements (FEM).
    pub points: usize,
}

/// The value Figure 17 is normalised by.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ReferenceRecord {
    pub value: f64,
    pub method: Method,
    /// The case(s) it comes from.
    pub cases: Vec<String>,
    /// Observed convergence order when Richardson-extrapolated.
    pub observed_order: Option<f64>,
    /// One sentence for captions and the report.
    pub description: String,
}

/// The compaction's measures in `results.json`: the Figure 17 reference.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct CompactionMeasures {
    pub reference: Option<ReferenceRecord>,
    /// Grid convergence index of each series with three or more element sizes.
    #[serde(default)]
    pub gci: Vec<crate::study::checks::GciRecord>,
}

/// `results.json` of the compaction study.
pub type CompactionResults = Envelope<CompactionStudy, CompactionRecord, CompactionMeasures>;

case_record!(CompactionRecord);

impl CompactionResults {
    /// The iGIMP case of a sweep at (h, points per cell) with the study's weak-node tolerance.
    pub fn igimp_case(&self, sweep: &str, h: f64, ppc: usize) -> Option<&CompactionRecord> {
        self.sweep(sweep).into_iter().find(|c| {
            c.method == Method::IGIMP && c.h == h && c.points_per_cell == Some(ppc) && self.is_default(c)
        })
    }

    /// Does the case use the study's default treatment of nearly empty cells (weak-node
    /// tolerance and ghost γ)? FEM cases always do.
    pub fn is_default(&self, c: &CompactionRecord) -> bool {
        match c.points_per_cell {
            None => true,
            Some(p) => {
                c.weak_node_tolerance == self.study.weak_nodes.tolerance
                    && c.ghost_gamma == self.study.ghost.settings(p, c.yield_stress.is_some(), None).gamma
            }
        }
    }
}
