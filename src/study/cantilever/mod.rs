//! The cantilever study (§5.3): `studies/cantilever.toml` → `results.json` → `report.md` and
//! Figures 19–21.
//!
//! Each `[[cases]]` entry is one analysis of the beam (iGIMP with a domain and volume update
//! rule, or a FEM comparator). The elastica (plane strain, optionally plane stress too) gives
//! the analytical end displacement at every load step. The depth study repeats a case at
//! smaller depths with the load scaled by depth³ (so PL²/EI, hence the elastica, is unchanged)
//! and the element size scaled with the depth (two elements through it): the continuum beam's
//! shear and axial flexibility, which the elastica ignores, shrink with the depth, and so
//! should its difference from the elastica.
//!
//! Signs: u/L and v/L are the displacements along +x and +y over L. The load acts along −y,
//! so the elastica's deflection (positive in the load direction) is stored as −v/L.

mod checks;
pub mod kind;
mod plan;
pub mod records;

use super::material::MaterialTable;
use super::vocabulary::{GhostSection, NewtonSection, WeakNodeSection};
use crate::basis::method::Method;
use crate::mpm::{DomainUpdate, VolumeUpdate};
use crate::problems::cantilever::CantileverSpec;
use serde::{Deserialize, Serialize};

/// The beam, load and discretisation (the paper's §5.3 values in the study file); its
/// material is the study's `[material]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BeamSection {
    pub length: f64,
    pub depth: f64,
    /// End load P (N per unit width), downwards, ramped over `load_steps`.
    pub load: f64,
    pub load_steps: i64,
    pub element_size: f64,
    /// Material points per element along each axis.
    pub points_per_cell: i64,
    /// Background grid below the beam and beyond its end/top (room for the deflection).
    pub grid_below: f64,
    pub grid_margin: f64,
    /// 2 (default: plane strain, the paper's) or 3: a `depth × depth` section
    /// ([`CantileverSpec::dimension`]), methods igimp, fem-hex8 and fem-hex20, the elastica
    /// with EI = E d⁴/12, domain figures of the layer next to the mid-plane z = d/2.
    #[serde(default = "two", skip_serializing_if = "is_two")]
    pub dimension: i64,
}

fn two() -> i64 {
    2
}

fn is_two(d: &i64) -> bool {
    *d == 2
}

/// One analysis of the beam.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CaseSection {
    pub id: String,
    pub title: String,
    pub method: Method,
    /// iGIMP domain update: `stretch` (eq 39, the default) or `f-diagonal` (eq 37).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub domain_update: Option<DomainUpdate>,
    /// iGIMP volume rule: `domain-product` (the paper's, the default) or `jacobian`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub volume_update: Option<VolumeUpdate>,
    /// Ghost penalty factor γ of this case (0 = off); default: the `[ghost]` section's.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ghost_gamma: Option<f64>,
    /// Weak-node tolerance of this case (the tie/fix alternative); default: `[weak_nodes]`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub weak_node_tolerance: Option<f64>,
    /// Element size of this case (a refinement of the beam); default: `beam.element_size`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub element_size: Option<f64>,
    /// Keep the domains every this many steps (and the last) for the figures; 0: none.
    #[serde(default)]
    pub snapshot_every: i64,
    /// Leave the case out of the quick tier.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub full_only: bool,
}

/// The depth study: `case` repeated at each depth with P ∝ depth³ and h ∝ depth.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DepthStudy {
    pub case: String,
    /// Depths other than the beam's own (which is the case itself).
    pub depths: Vec<f64>,
    /// Elements through the depth, one series each (h = depth / n); the beam's own n is the
    /// case itself at its depth.
    pub elements_through_depth: Vec<i64>,
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub full_only: bool,
    pub source: String,
}

/// A refinement: every method of `methods` at each element size (the beam's depth over an
/// even number of elements), on the base case's domain and volume update; case ids
/// `{id}-{method}-h{h}`. Sizes not in `quick_element_sizes` are full-tier only.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RefinementSection {
    pub id: String,
    pub title: String,
    pub methods: Vec<Method>,
    pub element_sizes: Vec<f64>,
    /// The quick tier's element sizes (default: all of them).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub quick_element_sizes: Option<Vec<f64>>,
    /// The method every other is compared with at the same element size, and whose GCI
    /// extrapolation is the converged continuum.
    pub reference: Method,
    /// What the report says about the comparison (e.g. the reference's own singularities).
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub note: String,
}

/// Every case of `methods` in `refinement` with h ≤ `max_element_size`: final u/L and v/L
/// within `tolerance` (relative) of the reference method's at the same element size.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RefinedExpectation {
    pub refinement: String,
    pub methods: Vec<Method>,
    pub max_element_size: f64,
    pub tolerance: f64,
    pub source: String,
}

/// The GCI extrapolation of `method`'s final u/L over the three finest element sizes of
/// `refinement` within `tolerance` (relative) of the reference method's; evaluated only in a
/// tier that runs three sizes (the check is absent otherwise, and the report says so).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ExtrapolatedExpectation {
    pub refinement: String,
    pub method: Method,
    pub tolerance: f64,
    pub source: String,
}

/// Final u/L and v/L of `case` within `tolerance` (relative) of the elastica.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ElasticaExpectation {
    pub case: String,
    pub tolerance: f64,
    pub source: String,
}

/// Final u/L and v/L of `case` within `tolerance` (relative) of `reference`'s.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AgreementExpectation {
    pub case: String,
    pub reference: String,
    pub tolerance: f64,
    pub source: String,
}

/// `case` completes every load step.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CompletionExpectation {
    pub case: String,
    pub source: String,
}

/// `case` fails part-way (recorded with step, reason and residuals) after its smallest domain
/// half-length fell below `fraction` of its initial value, without growing over the last
/// `window` converged steps.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CollapseExpectation {
    pub case: String,
    pub fraction: f64,
    pub window: i64,
    pub source: String,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum CantileverFigureKind {
    /// Domains of one case at several load steps (Figures 19, 20).
    Domains,
    /// u/L and v/L against load for several cases and the elastica (Figure 21).
    EndDisplacement,
    /// Final u/L over the reference's GCI extrapolation against h, every method of a
    /// refinement (`refinement`).
    Refinement,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CantileverFigure {
    pub id: String,
    pub title: String,
    pub kind: CantileverFigureKind,
    pub cases: Vec<String>,
    /// Domain figures: the load steps to draw (0 = initial); absent: every stored snapshot.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub steps: Option<Vec<i64>>,
    /// Domain figures: mark the loaded points.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub mark_loads: bool,
    /// Refinement figures: the refinement drawn.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub refinement: Option<String>,
}

/// `studies/cantilever.toml`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CantileverStudy {
    pub schema: i64,
    pub name: String,
    pub summary: String,
    /// Always "cantilever".
    pub problem: String,
    pub report_file: String,
    /// Cases expected to fail, and why; `study --check` fails on any other failed case.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub expected_failures: Vec<crate::study::vocabulary::ExpectedFailure>,
    /// Also draw and tabulate the plane-stress elastica (the solver is plane strain).
    #[serde(default)]
    pub plane_stress_elastica: bool,
    pub beam: BeamSection,
    /// The material (`[material]`; the paper's is Hencky elasticity): the elastica takes its
    /// `young_modulus` and `poisson_ratio`.
    pub material: MaterialTable,
    pub newton: NewtonSection,
    pub weak_nodes: WeakNodeSection,
    pub ghost: GhostSection,
    pub cases: Vec<CaseSection>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub depth_study: Option<DepthStudy>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub refinement: Vec<RefinementSection>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub expect_refined: Vec<RefinedExpectation>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub expect_extrapolated: Vec<ExtrapolatedExpectation>,
    #[serde(default)]
    pub expect_completes: Vec<CompletionExpectation>,
    #[serde(default)]
    pub expect_elastica: Vec<ElasticaExpectation>,
    #[serde(default)]
    pub expect_agreement: Vec<AgreementExpectation>,
    #[serde(default)]
    pub expect_collapse: Vec<CollapseExpectation>,
    #[serde(default)]
    pub figures: Vec<CantileverFigure>,
}

/// One analysis to run.
#[derive(Debug, Clone, PartialEq)]
pub struct CantileverCase {
    pub id: String,
    pub method: Method,
    pub spec: CantileverSpec,
    pub snapshot_every: usize,
}

/// Material point domains at one step, as `domains.json` stores them.
pub use crate::problems::cantilever::DomainSnapshot;
pub use records::{
    CantileverMeasures, CantileverRecord, CantileverResults, DepthRow, ElasticaPath, ElasticaPoint,
    RefinementRow,
};
