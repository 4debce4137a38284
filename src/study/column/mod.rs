//! The column study kind (§5.1): `studies/column.toml` and `column-plastic.toml` → the
//! sweeps (methods × weights × element counts × points per cell) of the elastic or plastic
//! column, the errors of eqs (46)–(47), fitted rates with their bands, the paper's Table 1.

pub mod kind;
pub mod rates;
pub mod records;
mod validate;

use super::material::MaterialTable;
use super::results::SweepIndex;
use super::vocabulary::{weight_label, NewtonSection};
use super::Tier;
use crate::basis::method::Method;
use crate::problems::column::ColumnSpec;
use crate::solver::newton::NewtonSettings;
use serde::{Deserialize, Serialize};
use std::collections::BTreeSet;

/// The `problem` of a column study file: the elastic and the plastic column of §5.1
/// ([`crate::study::kinds`] dispatches every kind on this key).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ProblemKind {
    Column,
}

/// Error measure of a convergence series.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Measure {
    /// Dimensionless stress error, eq (46).
    StressError,
    /// Relative error of F at the base, eq (47).
    FError,
    /// Eq (46) applied to the lateral stress σ_xx (plastic column).
    SigmaXxError,
    /// |Z_y,h − Z_y| / L0: yield height seen by the points against the analytical one.
    YieldHeightError,
}

impl Measure {
    /// The measures a study reports: the plastic ones only when it has a yield stress.
    pub fn all(plastic: bool) -> &'static [Measure] {
        if plastic {
            &[
                Measure::StressError,
                Measure::FError,
                Measure::SigmaXxError,
                Measure::YieldHeightError,
            ]
        } else {
            &[Measure::StressError, Measure::FError]
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            Measure::StressError => "stress_error",
            Measure::FError => "f_error",
            Measure::SigmaXxError => "sigma_xx_error",
            Measure::YieldHeightError => "yield_height_error",
        }
    }
    /// Axis / table label.
    pub fn label(self) -> &'static str {
        match self {
            Measure::StressError => "stress error, eq (46)",
            Measure::FError => "base F error, eq (47)",
            Measure::SigmaXxError => "σxx error, eq (46) on σxx",
            Measure::YieldHeightError => "yield height error |Zy,h − Zy| / L0",
        }
    }
}

/// Geometry and density of the column (§5.1); its material is the study's `[material]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ColumnSection {
    /// Initial length L0 (m).
    pub length: f64,
    /// Initial density ρ0 (kg/m³).
    pub density: f64,
}

/// Overrides applied to a sweep in the quick tier (each key optional).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct QuickOverrides {
    /// Leave this sweep out of the quick tier.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub skip: bool,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub methods: Option<Vec<Method>>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub weights: Option<Vec<f64>>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub elements: Option<Vec<i64>>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub points_per_cell: Option<Vec<i64>>,
}

/// One sweep: the cartesian product methods × weights × elements × points per cell.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Sweep {
    /// Identifier used by expectations and figures (see [`ident_ok`](crate::study::vocabulary::ident_ok)).
    pub id: String,
    /// One line saying what the sweep reproduces.
    pub title: String,
    pub methods: Vec<Method>,
    /// Total weights W = ρ0 g L0 (N per unit area).
    pub weights: Vec<f64>,
    /// Background elements (MPM/iGIMP) or finite elements (FEM).
    pub elements: Vec<i64>,
    /// Material points per element; ignored by the FEM methods (their Gauss rules are fixed).
    pub points_per_cell: Vec<i64>,
    /// Rates are fitted over this many finest element counts (≥ 2); all if absent.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fit_points: Option<i64>,
    /// Overrides the study's `load_steps` for this sweep.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub load_steps: Option<i64>,
    /// Overrides the study's `[newton]` for this sweep.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub newton: Option<NewtonSection>,
    #[serde(default)]
    pub quick: QuickOverrides,
    /// Solve without the study's `[ghost]` penalty (the paper's untreated method, e.g. for
    /// Figure 9 at one point per cell beside the stabilised series); cases it changes carry
    /// `-untreated` in their ids.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub untreated: bool,
}

/// An expected convergence rate: the fitted slope of log(error) against log(h) of one series
/// must lie in `rate ± tolerance`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RateExpectation {
    pub sweep: String,
    pub method: Method,
    pub weight: f64,
    /// Required for MPM/iGIMP, absent for FEM.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub points_per_cell: Option<i64>,
    pub measure: Measure,
    pub rate: f64,
    pub tolerance: f64,
    /// Where the expectation comes from (paper section/figure, theory, or a dated measurement).
    pub source: String,
}

/// Expect `lower`'s error below `higher`'s at every element count both ran.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ErrorComparison {
    pub sweep: String,
    pub weight: f64,
    pub measure: Measure,
    pub lower: Method,
    pub higher: Method,
    pub source: String,
}

/// Values printed in a table of the paper, reproduced beside this code's values.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PaperRows {
    /// e.g. "Table 1".
    pub table: String,
    pub sweep: String,
    pub method: Method,
    pub weight: f64,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub points_per_cell: Option<i64>,
    pub elements: Vec<i64>,
    pub top_displacement: Vec<f64>,
    pub base_f: Vec<f64>,
    pub f_error: Vec<f64>,
    /// The analytical base F as printed (rounded) in the paper; its F errors use it.
    pub analytical_base_f: f64,
}

/// What a figure shows.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FigureKind {
    /// Vertical Cauchy stress against height at the end of loading, every case of the sweep
    /// at `weight`, with the analytical solution.
    Profile,
    /// Error against element count (log-log), one series per method and points per cell.
    Convergence,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FigureSpec {
    /// File stem of the SVG (see [`ident_ok`](crate::study::vocabulary::ident_ok)).
    pub id: String,
    pub title: String,
    pub kind: FigureKind,
    pub sweep: String,
    pub weight: f64,
    /// Convergence figures only.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub measure: Option<Measure>,
    /// Draw a slope triangle at the fine end of each series (convergence figures).
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub slope_triangles: bool,
    /// Further sweeps whose series join the figure's (convergence figures), labelled
    /// "untreated" where the sweep is.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub overlay: Vec<String>,
}

/// A study file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ColumnStudy {
    /// Layout version; must equal [`SCHEMA_VERSION`](crate::study::SCHEMA_VERSION).
    pub schema: i64,
    /// Name of the study and of its output folder (see [`ident_ok`](crate::study::vocabulary::ident_ok)).
    pub name: String,
    /// One line for `study list` and `--help`.
    pub summary: String,
    pub problem: ProblemKind,
    /// File name of the Markdown report inside the study's output folder.
    pub report_file: String,
    /// Cases expected to fail, and why; `study --check` fails on any other failed case.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub expected_failures: Vec<crate::study::vocabulary::ExpectedFailure>,
    pub column: ColumnSection,
    /// The material (`[material]`): Hencky elasticity (`linear-elastic`) or, for the plastic
    /// column, von Mises (`von-mises`, whose `yield_stress` adds the plastic measures); its
    /// Poisson's ratio in [0, 0.5).
    pub material: MaterialTable,
    /// Load steps (gravity ramped linearly); 1..=10000.
    pub load_steps: i64,
    pub newton: NewtonSection,
    pub sweeps: Vec<Sweep>,
    #[serde(default)]
    pub expect: Vec<RateExpectation>,
    #[serde(default)]
    pub compare: Vec<ErrorComparison>,
    #[serde(default)]
    pub paper: Vec<PaperRows>,
    #[serde(default)]
    pub figures: Vec<FigureSpec>,
    /// Ghost stabilisation of one point per cell ([`crate::discretise::ghost`]); absent: none.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ghost: Option<ColumnGhost>,
    /// 1 (default) or 3: the column as a 1 × 1 × n prism with lateral rollers
    /// ([`ColumnSpec::dimension`]; MPM and iGIMP only).
    #[serde(default = "one", skip_serializing_if = "is_one")]
    pub dimension: i64,
}

fn one() -> i64 {
    1
}

fn is_one(d: &i64) -> bool {
    *d == 1
}

/// A column study's `[ghost]`: the settings of its one-point-per-cell cases (the odd-even
/// mode of one-point sampling, reference/README.md item 15) and where they come from. Cases
/// with more points per cell are untreated, so Table 1 is unaffected.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ColumnGhost {
    pub one_point_per_cell: crate::discretise::ghost::GhostSettings,
}

/// One case to solve.
#[derive(Debug, Clone, PartialEq)]
pub struct ColumnCase {
    /// Unique and file-name safe, e.g. `igimp-w400000-e256-p2-s20`.
    pub id: String,
    pub method: Method,
    /// `None` for FEM.
    pub points_per_cell: Option<usize>,
    pub spec: ColumnSpec,
}

/// Cases of one sweep after the tier's overrides.
#[derive(Debug, Clone, PartialEq)]
pub struct SweepPlan {
    pub methods: Vec<Method>,
    pub weights: Vec<f64>,
    pub elements: Vec<usize>,
    pub points_per_cell: Vec<usize>,
    pub load_steps: usize,
    pub newton: NewtonSettings,
    /// The sweep's `untreated`.
    pub untreated: bool,
}

impl ColumnStudy {
    /// Whether the material has a yield stress: the plastic column, with its measures
    /// σ_xx error and yield height.
    pub fn plastic(&self) -> bool {
        self.material.get("yield_stress").is_some()
    }

    pub fn sweep(&self, id: &str) -> Option<&Sweep> {
        self.sweeps.iter().find(|s| s.id == id)
    }

    /// The sweep's lists after the tier's overrides, or `None` if the tier skips it.
    pub fn plan(&self, sweep: &Sweep, tier: Tier) -> Option<SweepPlan> {
        let q = &sweep.quick;
        let quick = tier == Tier::Quick;
        if quick && q.skip {
            return None;
        }
        let pick = |full: &Vec<i64>, over: &Option<Vec<i64>>| -> Vec<usize> {
            let v = if quick {
                over.as_ref().unwrap_or(full)
            } else {
                full
            };
            v.iter().map(|&n| n as usize).collect()
        };
        Some(SweepPlan {
            methods: if quick { q.methods.clone() } else { None }.unwrap_or_else(|| sweep.methods.clone()),
            weights: if quick { q.weights.clone() } else { None }.unwrap_or_else(|| sweep.weights.clone()),
            elements: pick(&sweep.elements, &q.elements),
            points_per_cell: pick(&sweep.points_per_cell, &q.points_per_cell),
            load_steps: sweep.load_steps.unwrap_or(self.load_steps) as usize,
            newton: sweep.newton.unwrap_or(self.newton).settings(),
            untreated: sweep.untreated,
        })
    }

    /// The column of one case. Fields the study file does not set (e.g. ones other branches
    /// add to `ColumnSpec`, such as FEM Gauss points) keep their defaults.
    #[allow(clippy::needless_update)]
    pub fn column_spec(&self, weight: f64, elements: usize, ppc: usize, plan: &SweepPlan) -> ColumnSpec {
        ColumnSpec {
            length: self.column.length,
            material: self.material.material(),
            density: self.column.density,
            weight,
            elements,
            points_per_cell: ppc,
            load_steps: plan.load_steps,
            newton: plan.newton,
            ghost: match (ppc, self.ghost, plan.untreated) {
                (1, Some(g), false) => g.one_point_per_cell,
                _ => crate::discretise::ghost::GhostSettings::default(),
            },
            dimension: self.dimension.max(1) as usize,
            ..ColumnSpec::default()
        }
    }

    /// Case id: method, weight, elements, points per cell (MPM/iGIMP), load steps, and the
    /// Newton settings when they differ from the study's.
    pub fn case_id(&self, method: Method, ppc: Option<usize>, spec: &ColumnSpec) -> String {
        let mut id = format!(
            "{}-w{}-e{}",
            method.name(),
            weight_label(spec.weight),
            spec.elements
        );
        if let Some(p) = ppc {
            id.push_str(&format!("-p{p}"));
        }
        id.push_str(&format!("-s{}", spec.load_steps));
        let treated = match (ppc, self.ghost) {
            (Some(1), Some(g)) => g.one_point_per_cell,
            _ => crate::discretise::ghost::GhostSettings::default(),
        };
        if spec.ghost != treated {
            id.push_str("-untreated");
        }
        if spec.newton != self.newton.settings() {
            id.push_str(&format!(
                "-tol{:e}-it{}",
                spec.newton.tolerance, spec.newton.max_iterations
            ));
        }
        id
    }

    /// The cases of one sweep in order method, weight, points per cell, elements.
    pub fn sweep_cases(&self, plan: &SweepPlan) -> Vec<ColumnCase> {
        let mut out = Vec::new();
        for &method in &plan.methods {
            let ppcs: Vec<Option<usize>> = if method.uses_material_points() {
                plan.points_per_cell.iter().map(|&p| Some(p)).collect()
            } else {
                vec![None]
            };
            for &weight in &plan.weights {
                for &ppc in &ppcs {
                    for &elements in &plan.elements {
                        let spec = self.column_spec(
                            weight,
                            elements,
                            ppc.unwrap_or(ColumnSpec::default().points_per_cell),
                            plan,
                        );
                        out.push(ColumnCase {
                            id: self.case_id(method, ppc, &spec),
                            method,
                            points_per_cell: ppc,
                            spec,
                        });
                    }
                }
            }
        }
        out
    }

    /// Every distinct case of the tier, in file order; a case shared by two sweeps appears
    /// once.
    pub fn cases(&self, tier: Tier) -> Vec<ColumnCase> {
        let mut seen = BTreeSet::new();
        self.sweeps
            .iter()
            .filter_map(|s| self.plan(s, tier))
            .flat_map(|plan| self.sweep_cases(&plan))
            .filter(|c| seen.insert(c.id.clone()))
            .collect()
    }

    /// Which case ids each sweep of the tier uses.
    pub fn case_index(&self, tier: Tier) -> SweepIndex {
        self.sweeps
            .iter()
            .filter_map(|s| {
                let plan = self.plan(s, tier)?;
                Some((
                    s.id.clone(),
                    self.sweep_cases(&plan).into_iter().map(|c| c.id).collect(),
                ))
            })
            .collect()
    }
}
