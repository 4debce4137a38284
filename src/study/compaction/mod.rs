//! The compaction study (§5.2): `studies/compaction.toml` → `results.json` → `report.md`,
//! `table2.md`, `table3.md` and Figures 15–18.
//!
//! A sweep is methods × element sizes × points per cell × weak-node tolerances for one
//! material: the study's `[material]`, or the `[materials.<name>]` it names (`material =
//! "<name>"`; the plastic sweeps' von Mises). Figure 17 normalises the
//! maximum horizontal displacement by a reference: the converged Q4 FEM value of the
//! `reference.fem_sweep` (Richardson-extrapolated over its finest three meshes when they allow
//! it, else its finest mesh), or, when no FEM case converged, the finest iGIMP case of the
//! Figure 17 sweep (smallest element size, most points per cell), which the report and
//! captions then state.

mod checks;
pub mod kind;
mod plan;
pub mod records;

use super::material::MaterialTable;
use super::vocabulary::{GhostSection, NewtonSection, WeakNodeSection};
use crate::basis::method::Method;
use crate::problems::compaction::CompactionSpec;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// Geometry and loading of the block (the paper's §5.2 values in the study file).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BlockSection {
    /// Half width of the block, the modelled half (the full block is twice as wide).
    pub half_width: f64,
    pub height: f64,
    /// Background grid extent along x and y from the symmetry line / base (in 3D: the
    /// horizontal extent of both horizontal axes, and the height).
    #[serde(deserialize_with = "crate::study::vocabulary::exactly_two")]
    pub grid_extent: [f64; 2],
    /// Weight w of the full block at the end of loading.
    pub weight: f64,
    /// Gravity is ramped linearly over this many load steps.
    pub load_steps: i64,
    /// 2 (default: plane strain, the paper's) or 3: the quarter of a square block with
    /// symmetry planes x = 0 and y = 0 ([`CompactionSpec::dimension`]); its methods are
    /// igimp, mpm, fem-hex8 and fem-hex20, and its domain figures show the slice next to the
    /// symmetry plane y = 0 in the (x, z) plane.
    #[serde(default = "two", skip_serializing_if = "is_two")]
    pub dimension: i64,
}

fn two() -> i64 {
    2
}

fn is_two(d: &i64) -> bool {
    *d == 2
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
    pub element_sizes: Option<Vec<f64>>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub points_per_cell: Option<Vec<i64>>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub weak_node_tolerances: Option<Vec<f64>>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ghost_gammas: Option<Vec<f64>>,
}

/// Methods × element sizes × points per cell × weak-node tolerances, one material.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CompactionSweep {
    pub id: String,
    pub title: String,
    pub methods: Vec<Method>,
    /// The name of the `[materials.<name>]` table the sweep solves; absent: `[material]`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub material: Option<String>,
    pub element_sizes: Vec<f64>,
    /// Material points per element along each axis (iGIMP only).
    pub points_per_cell: Vec<i64>,
    /// Defaults to `[weak_nodes.tolerance]`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub weak_node_tolerances: Option<Vec<f64>>,
    /// Ghost penalty factors γ (0 = off); defaults to the `[ghost]` section's.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ghost_gammas: Option<Vec<f64>>,
    /// `cg`: the multigrid-preconditioned conjugate gradients ([`crate::solver::linear::LinearSolver::Iterative`]) for
    /// every case of the sweep (ids gain `-cg`); `lu`, `ldlt`, `llt`: that factorisation
    /// (ids gain `-lu`, …); absent or `auto`: the direct default (LDLᵀ where the tangent is
    /// symmetric to round-off, LU otherwise: reference/README.md item 64).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub linear_solver: Option<crate::solver::linear::LinearSolver>,
    #[serde(default)]
    pub quick: SweepQuick,
}

impl super::vocabulary::TieredSweep for CompactionSweep {
    fn id(&self) -> &str {
        &self.id
    }
    /// `quick = { skip = true }` makes it a full-tier sweep.
    fn runs_in(&self, tier: super::Tier) -> bool {
        tier == super::Tier::Full || !self.quick.skip
    }
}

impl super::vocabulary::SweepFigure for CompactionFigure {
    fn sweep(&self) -> &str {
        &self.sweep
    }
}

/// The result does not depend on γ beyond `tolerance` (relative spread) for h ≤
/// `max_element_size`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GhostSpreadExpectation {
    pub sweep: String,
    /// The material point methods checked, each on its own (default: iGIMP only).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub methods: Vec<Method>,
    pub max_element_size: f64,
    pub tolerance: f64,
    pub source: String,
}

/// The iterative solver stays O(n): every converged case of `sweep` solved by CG needs at
/// most `max_per_solve` CG iterations per Newton solve on average over its load steps.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LinearIterationsExpectation {
    pub sweep: String,
    pub max_per_solve: f64,
    pub source: String,
}

/// The Figure 17 normalisation.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ReferenceSection {
    /// Sweep whose FEM cases give the reference: Richardson-extrapolated over its three
    /// finest meshes when they refine by a constant ratio and converge monotonically, else
    /// its finest mesh.
    pub fem_sweep: String,
    /// The Figure 17 sweep; its finest iGIMP case is the fallback reference when no FEM case
    /// converged.
    pub igimp_sweep: String,
    pub source: String,
}

/// Every converged iGIMP case of `sweep` with h ≤ `max_element_size` lies within `tolerance`
/// (relative) of the reference.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DeviationExpectation {
    pub sweep: String,
    /// The material point methods checked (default: iGIMP only).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub methods: Vec<Method>,
    pub max_element_size: f64,
    pub tolerance: f64,
    pub source: String,
}

/// The GCI extrapolation (Celik et al. 2008) of one method's series in `sweep` (the study's
/// default treatment, the three finest element sizes) lies within `tolerance` (relative) of
/// the Figure 17 reference, and the series is in the asymptotic range; a series outside it
/// fails the check.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ExtrapolationExpectation {
    pub sweep: String,
    pub method: Method,
    pub tolerance: f64,
    pub source: String,
}

/// For each points-per-cell series of `sweep`, the distance to the reference does not grow
/// by more than `slack` (relative) from one element size to the next smaller one.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ConvergenceExpectation {
    pub sweep: String,
    /// The material point methods checked, each series on its own (default: iGIMP only).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub methods: Vec<Method>,
    pub slack: f64,
    pub source: String,
}

/// At each element size of `sweep`, the spread (max − min) / min of the displacement over
/// the non-zero weak-node tolerances is at most `tolerance`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SpreadExpectation {
    pub sweep: String,
    pub tolerance: f64,
    pub source: String,
}

/// Newton residuals printed in the paper (Tables 2 and 3), shown beside this code's.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PaperResiduals {
    /// e.g. "Table 2".
    pub table: String,
    /// Output file, e.g. `table2.md`.
    pub file: String,
    pub title: String,
    /// The iGIMP case: sweep, element size and points per cell.
    pub sweep: String,
    pub element_size: f64,
    pub points_per_cell: i64,
    pub steps: Vec<i64>,
    /// Per step, the normalised out-of-balance force after Newton iterations 1, 2, ….
    pub residuals: Vec<Vec<f64>>,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum CompactionFigureKind {
    /// Initial (grey) and final domains coloured by σ_yy (Figures 15, 18).
    Domains,
    /// Residual against Newton iteration of one load step, log scale (Figure 16).
    Residuals,
    /// Normalised maximum horizontal displacement against element size (Figure 17).
    DisplacementConvergence,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CompactionFigure {
    pub id: String,
    pub title: String,
    pub kind: CompactionFigureKind,
    pub sweep: String,
    /// The case of domain and residual figures.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub element_size: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub points_per_cell: Option<i64>,
    /// Load step of residual figures.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub step: Option<i64>,
}

/// `studies/compaction.toml`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CompactionStudy {
    pub schema: i64,
    pub name: String,
    pub summary: String,
    /// Always "compaction".
    pub problem: String,
    /// Main report file name in the output folder.
    pub report_file: String,
    /// Cases expected to fail, and why; `study --check` fails on any other failed case.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub expected_failures: Vec<crate::study::vocabulary::ExpectedFailure>,
    pub block: BlockSection,
    /// The material of every sweep that names no other (`[material]`; the paper's Hencky
    /// elasticity).
    pub material: MaterialTable,
    /// Further materials by name (`[materials.<name>]`; the paper's von Mises), for the sweeps
    /// that name them.
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub materials: BTreeMap<String, MaterialTable>,
    pub newton: NewtonSection,
    pub weak_nodes: WeakNodeSection,
    pub ghost: GhostSection,
    pub sweeps: Vec<CompactionSweep>,
    pub reference: ReferenceSection,
    #[serde(default)]
    pub expect_deviation: Vec<DeviationExpectation>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub expect_extrapolation: Vec<ExtrapolationExpectation>,
    #[serde(default)]
    pub expect_convergence: Vec<ConvergenceExpectation>,
    #[serde(default)]
    pub expect_weak_node_spread: Vec<SpreadExpectation>,
    /// Spread of the result over the ghost penalty factors of a sweep, per element size
    /// (and points per cell), for h ≤ `max_element_size`.
    #[serde(default)]
    pub expect_ghost_spread: Vec<GhostSpreadExpectation>,
    /// CG iterations per Newton solve of a sweep's iterative cases.
    #[serde(default)]
    pub expect_linear_iterations: Vec<LinearIterationsExpectation>,
    #[serde(default)]
    pub paper_residuals: Vec<PaperResiduals>,
    #[serde(default)]
    pub figures: Vec<CompactionFigure>,
}

/// One case to solve.
#[derive(Debug, Clone, PartialEq)]
pub struct CompactionCase {
    pub id: String,
    pub method: Method,
    pub spec: CompactionSpec,
}

/// A final material point domain, as `domains.json` stores it.
pub use crate::problems::compaction::DomainRecord;
pub use records::{CompactionMeasures, CompactionRecord, CompactionResults, ReferenceRecord};
