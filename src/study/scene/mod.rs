//! The scene study (`problem = "scene"`): any box bodies, supports, loads and measures from the
//! study file ([`crate::problems::scene`]), swept over methods, element sizes and points per
//! cell; each measure compared with its reference (a value or a closed form) and checked.
//! `studies/README.md` ("Scenes") documents the schema with an annotated example.

mod checks;
mod kind;
mod validate;

use super::material::MaterialTable;
use super::vocabulary::{ExpectedFailure, NewtonSection};
use crate::discretise::ghost::GhostSettings;
use crate::problems::scene::{
    Body, GridSection, Load, Measure, Scene, SceneSettings, StrengthReductionSection, Support,
};
use crate::study::external::{ExternalRecord, StudyMethod};
use crate::study::results::{case_record, Envelope, SolveRecord};
use crate::study::Tier;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// Quick-tier overrides of a sweep.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneSweepQuick {
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub skip: bool,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub methods: Option<Vec<StudyMethod>>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub element_sizes: Option<Vec<f64>>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub points_per_cell: Option<Vec<i64>>,
}

/// Methods × element sizes × points per cell.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneSweep {
    pub id: String,
    pub title: String,
    /// igimp's methods, and other codes' as `ext:<adapter>[@<method>]` (studies/PROTOCOL.md).
    pub methods: Vec<StudyMethod>,
    pub element_sizes: Vec<f64>,
    /// Points per cell along each axis (material point methods; FEM cases ignore it).
    pub points_per_cell: Vec<i64>,
    /// `cg`: multigrid-preconditioned conjugate gradients for every case (ids gain `-cg`);
    /// absent: the direct default (LDLᵀ for FEM; LDLᵀ where the tangent is symmetric, LU
    /// otherwise, for material points).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub linear_solver: Option<crate::solver::linear::LinearSolver>,
    /// Load steps of this sweep (default: the study's `load_steps`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub load_steps: Option<i64>,
    /// F-bar for every case (ids gain `-fbar`; reference/README.md item 69).
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub f_bar: bool,
    /// With `f_bar`, each cell's or element's points carry its mean pressure (ids gain `-p`;
    /// reference/README.md item 75).
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub pressure_projection: bool,
    /// Gauss points per axis of the FEM cases (1..=5; default: the element's own, 2 for
    /// Q4/Hex8 and 3 for Q8/Hex20); their ids gain `-gp<n>`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gauss_points: Option<i64>,
    /// Newton's start in an increment for this sweep's cases (default: the study's
    /// `newton.predictor`); `extrapolated` where the study's is `zero` adds `-extrapolated`
    /// to the ids (reference/README.md item 82).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub predictor: Option<crate::solver::newton::Predictor>,
    #[serde(default)]
    pub quick: SceneSweepQuick,
}

impl super::vocabulary::TieredSweep for SceneSweep {
    fn id(&self) -> &str {
        &self.id
    }
    fn runs_in(&self, tier: Tier) -> bool {
        tier == Tier::Full || !self.quick.skip
    }
}

/// Every converged case of `sweep` (of `methods`, default all) lies within `tolerance`
/// (relative to the reference's magnitude) of measure `measure`'s reference, at the end and,
/// for a history measure, after every step.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ReferenceExpectation {
    pub measure: String,
    pub sweep: String,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub methods: Vec<StudyMethod>,
    pub tolerance: f64,
    /// Only each method's finest element size of the sweep.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub finest: bool,
    /// Only in this tier; absent: both.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tier: Option<Tier>,
    pub source: String,
}

/// The GCI extrapolation (Celik et al. 2008) of `method`'s measure over the three finest
/// converged element sizes of `sweep` lies within `tolerance` (relative) of the measure's
/// reference; a series without a GCI in the asymptotic range fails. Not evaluated in a tier
/// that runs the method at fewer than three sizes.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ExtrapolationExpectation {
    pub measure: String,
    pub sweep: String,
    pub method: StudyMethod,
    pub tolerance: f64,
    pub source: String,
}

/// Newton converges quadratically in every step of every converged case of `sweep`
/// ([`crate::study::checks::QuadraticExpectation`]'s terms).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct QuadraticSweepExpectation {
    pub sweep: String,
    pub small: f64,
    pub floor: f64,
    pub constant: f64,
    pub source: String,
}

impl QuadraticSweepExpectation {
    /// The terms of the check.
    pub fn terms(&self) -> crate::study::checks::QuadraticExpectation {
        crate::study::checks::QuadraticExpectation {
            small: self.small,
            floor: self.floor,
            constant: self.constant,
            source: self.source.clone(),
        }
    }
}

/// Two methods of `sweep` agree point by point: at every element size and points per cell
/// both ran, the largest difference of a final point position, over the scene's largest
/// body extent, is at most `tolerance` (both solve the same points: an external code gets
/// igimp's through the case protocol).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AgreementExpectation {
    pub sweep: String,
    pub methods: [StudyMethod; 2],
    pub tolerance: f64,
    pub source: String,
}

/// The error of `measure` against its reference over the element sizes of `sweep` (one
/// series per method and points per cell) has a fitted log-log slope in `rate ± tolerance`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RateExpectation {
    pub measure: String,
    pub sweep: String,
    pub method: StudyMethod,
    pub rate: f64,
    pub tolerance: f64,
    pub source: String,
}

/// A scene study file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneStudy {
    pub schema: i64,
    pub name: String,
    pub summary: String,
    /// Always "scene".
    pub problem: String,
    pub report_file: String,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub expected_failures: Vec<ExpectedFailure>,
    /// 2 (plane strain) or 3.
    pub dimension: i64,
    pub grid: GridSection,
    pub bodies: Vec<Body>,
    pub materials: BTreeMap<String, MaterialTable>,
    #[serde(default)]
    pub supports: Vec<Support>,
    pub loads: Vec<Load>,
    #[serde(default)]
    pub measures: Vec<Measure>,
    /// The strength divided by a rising factor (a factor-of-safety study).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub strength_reduction: Option<StrengthReductionSection>,
    pub load_steps: i64,
    pub newton: NewtonSection,
    /// Ghost penalty of the material point cases (default off).
    #[serde(default)]
    pub ghost: GhostSettings,
    pub sweeps: Vec<SceneSweep>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub expect_reference: Vec<ReferenceExpectation>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub expect_rate: Vec<RateExpectation>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub expect_extrapolation: Vec<ExtrapolationExpectation>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub expect_agreement: Vec<AgreementExpectation>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub expect_quadratic: Vec<QuadraticSweepExpectation>,
}

/// One case to solve.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SceneCase {
    pub id: String,
    pub method: StudyMethod,
    /// Keep the final point positions (a sweep an agreement check compares).
    pub positions: bool,
    pub settings: SceneSettings,
}

/// One case's result: the measures at the end, and the histories asked for.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SceneRecord {
    pub id: String,
    pub method: StudyMethod,
    pub h: f64,
    /// `None` (null) for FEM.
    pub points_per_cell: Option<usize>,
    #[serde(flatten)]
    pub solve: SolveRecord,
    /// Final value of each measure (converged cases; a failed case's at its last converged step).
    pub measures: BTreeMap<String, f64>,
    /// Value after each converged load step, for the history measures.
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub histories: BTreeMap<String, Vec<f64>>,
    /// The samples of each stress line at the end.
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub profiles: BTreeMap<String, Vec<f64>>,
    /// Material points or elements.
    pub points: usize,
    /// Final point positions, for the agreement checks (converged steps only).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub positions: Vec<Vec<f64>>,
    /// An external code's case: the code, its timing and its files.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub external: Option<ExternalRecord>,
}

case_record!(SceneRecord);

/// A measure's reference: its value at the end and after each load step (closed forms), and
/// where it comes from.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ReferenceValue {
    pub value: f64,
    /// At load factor k / n for the study's n load steps (closed forms of history measures).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub history: Vec<f64>,
    pub source: String,
}

impl ReferenceValue {
    /// The error of `v` against this reference: relative to its magnitude, or absolute when
    /// the reference is 0 (a measure that is itself an error, e.g. the column's eq 46).
    pub fn error(&self, v: f64) -> f64 {
        let scale = if self.value == 0.0 { 1.0 } else { self.value.abs() };
        (v - self.value).abs() / scale
    }
}

/// A fitted rate of a measure's error.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RateRecord {
    pub sweep: String,
    pub measure: String,
    pub method: StudyMethod,
    pub points_per_cell: Option<usize>,
    /// (h, relative error) coarse to fine.
    pub errors: Vec<(f64, f64)>,
    pub slope: Option<f64>,
}

/// The scene study's measures in `results.json`.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct SceneMeasures {
    pub references: BTreeMap<String, ReferenceValue>,
    /// The grid convergence index of each FEM-sweep reference, and of every series of a sweep
    /// an `expect_extrapolation` names.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub gci: Vec<crate::study::checks::GciRecord>,
    #[serde(default)]
    pub rates: Vec<RateRecord>,
}

/// `results.json` of a scene study.
pub type SceneResults = Envelope<SceneStudy, SceneRecord, SceneMeasures>;

impl SceneStudy {
    /// The library scene of this file, materials resolved.
    ///
    /// # Panics
    /// If a material does not resolve (a study is checked when it is read).
    pub fn scene(&self) -> Scene {
        Scene {
            dimension: self.dimension as usize,
            grid: self.grid.clone(),
            bodies: self.bodies.clone(),
            materials: self
                .materials
                .iter()
                .map(|(k, t)| (k.clone(), t.material()))
                .collect(),
            supports: self.supports.clone(),
            loads: self.loads.clone(),
            measures: self.measures.clone(),
            strength_reduction: self.strength_reduction.clone(),
        }
    }

    /// (methods, element sizes, points per cell) of `sweep` in `tier`; `None` if skipped.
    pub fn plan(&self, s: &SceneSweep, tier: Tier) -> Option<(Vec<StudyMethod>, Vec<f64>, Vec<i64>)> {
        if tier == Tier::Quick && s.quick.skip {
            return None;
        }
        let q = tier == Tier::Quick;
        let pick = |full: &Vec<f64>, quick: &Option<Vec<f64>>| {
            if q {
                quick.clone().unwrap_or(full.clone())
            } else {
                full.clone()
            }
        };
        let methods = if q {
            s.quick.methods.clone().unwrap_or(s.methods.clone())
        } else {
            s.methods.clone()
        };
        let ppc = if q {
            s.quick
                .points_per_cell
                .clone()
                .unwrap_or(s.points_per_cell.clone())
        } else {
            s.points_per_cell.clone()
        };
        Some((methods, pick(&s.element_sizes, &s.quick.element_sizes), ppc))
    }

    /// The settings of a case of sweep `s`.
    pub fn settings(&self, s: &SceneSweep, h: f64, ppc: usize) -> SceneSettings {
        SceneSettings {
            element_size: h,
            points_per_cell: ppc,
            load_steps: s.load_steps.unwrap_or(self.load_steps) as usize,
            newton: crate::solver::newton::NewtonSettings {
                predictor: s.predictor.unwrap_or(self.newton.predictor),
                ..self.newton.settings()
            },
            ghost: self.ghost,
            domain_update: Default::default(),
            linear_solver: s.linear_solver.unwrap_or_default(),
            f_bar: s.f_bar,
            pressure_projection: s.pressure_projection,
            gauss_points: s.gauss_points.map(|n| n as usize),
        }
    }

    /// A case's id: method, h and points per cell (material points), and the load steps if
    /// the sweep sets its own.
    pub fn case_id(&self, s: &SceneSweep, method: &StudyMethod, settings: &SceneSettings) -> String {
        let mut id = format!(
            "{}-h{}",
            method.slug(),
            super::vocabulary::number(settings.element_size)
        );
        if method.uses_material_points() {
            id.push_str(&format!("-ppc{}", settings.points_per_cell));
        }
        if let Some(n) = s.load_steps {
            id.push_str(&format!("-steps{n}"));
        }
        if s.f_bar {
            id.push_str("-fbar");
        }
        if s.pressure_projection {
            id.push_str("-p");
        }
        if let (Some(n), false) = (s.gauss_points, method.uses_material_points()) {
            id.push_str(&format!("-gp{n}"));
        }
        if settings.newton.predictor != self.newton.predictor {
            id.push_str(&format!("-{}", settings.newton.predictor.name()));
        }
        match s.linear_solver {
            None | Some(crate::solver::linear::LinearSolver::Auto) => {}
            Some(crate::solver::linear::LinearSolver::Iterative) => id.push_str("-cg"),
            Some(other) => id.push_str(&format!(
                "-{}",
                serde_json::to_value(other)
                    .ok()
                    .and_then(|v| v.as_str().map(str::to_string))
                    .unwrap_or_default()
            )),
        }
        id
    }

    /// Every distinct case of the tier and the case ids of each sweep.
    pub fn cases(&self, tier: Tier) -> (Vec<SceneCase>, crate::study::results::SweepIndex) {
        let sweeps = self.sweeps.iter().filter_map(|s| {
            let (methods, sizes, ppcs) = self.plan(s, tier)?;
            let mut cases = vec![];
            let positions = self.expect_agreement.iter().any(|e| e.sweep == s.id);
            for method in &methods {
                for &h in &sizes {
                    // FEM cases have no points per cell: one case per h.
                    let ppcs: Vec<i64> = if method.uses_material_points() {
                        ppcs.clone()
                    } else {
                        ppcs.iter().take(1).copied().collect()
                    };
                    for &p in &ppcs {
                        let settings = self.settings(s, h, p.max(1) as usize);
                        let id = self.case_id(s, method, &settings);
                        cases.push(SceneCase {
                            id,
                            method: method.clone(),
                            positions,
                            settings,
                        });
                    }
                }
            }
            Some((s.id.clone(), cases))
        });
        crate::study::engine::distinct_cases(sweeps, |c: &SceneCase| &c.id)
    }
}
