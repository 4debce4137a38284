//! Verification studies as data: a study file (`studies/<name>.toml`) names the problem, the
//! sweeps (methods × loads × element counts × points per cell), the Newton settings, the
//! expected convergence rates with their bands and sources, and the figures to draw.
//!
//! Pipeline (compute → JSON → render): [`runner::run_study`] solves every case (rayon, results
//! in a fixed order) and [`runner::write_outputs`] writes `results.json` and the per-case point
//! CSVs; [`crate::render`] and [`crate::plot`] read only those files.
//!
//! Counts in the file are parsed as signed integers so that a negative value is reported by
//! [`StudySpec::validate`] with its key and allowed range instead of as a type error.

pub mod cantilever;
pub mod compaction;
pub mod plane;
pub mod rates;
pub mod registry;
pub mod results;
pub mod runner;
pub mod store;
pub mod vtk_output;

use crate::newton::NewtonSettings;
use crate::problems::column::{ColumnSpec, Method};
use serde::{Deserialize, Serialize};
use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use thiserror::Error;

/// Version of the study-file layout (the `schema` key).
pub const SCHEMA_VERSION: i64 = 1;

/// A study file could not be read, parsed or validated.
#[derive(Debug, Error)]
pub enum StudyError {
    /// TOML syntax, a misspelt (unknown) key, a missing key or a wrong type: the message from
    /// the parser names the key and the line.
    #[error("{file}: {message}")]
    Parse { file: String, message: String },
    /// A value outside its allowed range.
    #[error("{file}: invalid `{key}` = {value}: {allowed}")]
    Invalid {
        file: String,
        key: String,
        value: String,
        allowed: String,
    },
    #[error("{path}: {message}")]
    Io { path: String, message: String },
    /// `--shard`: this shard's cases are solved and stored; nothing else is written.
    #[error("shard {k}/{n}: solved and stored {solved} of {total} cases in {dir}; run with --merge once every shard is done")]
    ShardDone {
        k: usize,
        n: usize,
        solved: usize,
        total: usize,
        dir: String,
    },
    /// `--merge` with cases no shard has stored (for these inputs).
    #[error("{dir}: --merge: {} of {total} cases not stored by any shard (or stored for other inputs): {}", missing.len(), missing.join(", "))]
    MissingCases {
        dir: String,
        total: usize,
        missing: Vec<String>,
    },
}

/// How a run shares its cases between processes (`study --shard K/N`, `study --merge`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Distribution {
    /// Solve (or resume) every case and write the results.
    #[default]
    Whole,
    /// Solve only the cases whose index in the deterministic case order is ≡ k (mod n), store
    /// them in the case store and write nothing else ([`StudyError::ShardDone`]).
    Shard { k: usize, n: usize },
    /// Solve nothing: read every case from the store (the shards'), then fit, check and write
    /// the results as an unsharded run would ([`StudyError::MissingCases`] if one is absent).
    Merge,
}

impl Distribution {
    /// Does this process solve case `index`?
    pub fn owns(&self, index: usize) -> bool {
        match *self {
            Distribution::Shard { k, n } => index % n == k,
            _ => true,
        }
    }

    /// Parse `K/N` with 0 ≤ K < N.
    pub fn parse_shard(text: &str) -> Result<Self, String> {
        let (k, n) = text
            .split_once('/')
            .ok_or_else(|| format!("{text:?}: expected K/N, e.g. 0/4"))?;
        let k: usize = k
            .trim()
            .parse()
            .map_err(|_| format!("{text:?}: K must be an integer"))?;
        let n: usize = n
            .trim()
            .parse()
            .map_err(|_| format!("{text:?}: N must be an integer"))?;
        if n == 0 || k >= n {
            return Err(format!(
                "{text:?}: need 0 <= K < N (K is the 0-based shard index)"
            ));
        }
        Ok(Distribution::Shard { k, n })
    }
}

impl StudyError {
    pub(crate) fn io(path: &Path, err: impl std::fmt::Display) -> Self {
        StudyError::Io {
            path: path.display().to_string(),
            message: err.to_string(),
        }
    }
}

/// Which problem a column study file solves (the elastic and the plastic column of §5.1; the
/// plane-strain studies are dispatched by [`registry`]).
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

/// Which quick/full tier of a study to run.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Tier {
    /// Every sweep as written.
    Full,
    /// Each sweep with its `quick` overrides (the CI tier).
    Quick,
}

/// Material and geometry of the column (§5.1).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ColumnSection {
    /// Initial length L0 (m).
    pub length: f64,
    /// Young's modulus E (Pa).
    pub young_modulus: f64,
    /// Poisson's ratio ν, in [0, 0.5).
    pub poisson_ratio: f64,
    /// Initial density ρ0 (kg/m³).
    pub density: f64,
    /// Von Mises yield stress ρ_y (Pa), eq (48); absent for the elastic column.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub yield_stress: Option<f64>,
}

/// Newton settings as written in a study file.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NewtonSection {
    /// Converged when ‖f_int − f_ext‖ / ‖f_ext‖ ≤ tolerance; in (0, 1).
    pub tolerance: f64,
    /// Most Newton iterations per load step; 1..=1000.
    pub max_iterations: i64,
    /// Backtracking line search (default off: plain Newton as in the paper).
    #[serde(default)]
    pub line_search: bool,
    /// `external` (‖f_ext‖ over the free dofs, the default), `total` (‖f_ext + f_reaction‖
    /// over all dofs, exact reactions) or `linearised` (the paper's Tables 2–3: reactions
    /// updated by their linearised increment, their out-of-balance in the numerator).
    #[serde(default)]
    pub residual_norm: crate::newton::ResidualNorm,
    /// Adaptive load stepping: most halvings of a failing increment (0..=20, default 6:
    /// down to 1/64 of a load step; 0 = fixed steps).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_cutbacks: Option<u32>,
}

impl NewtonSection {
    pub fn settings(&self) -> NewtonSettings {
        NewtonSettings {
            tolerance: self.tolerance,
            max_iterations: self.max_iterations as usize,
            line_search: self.line_search,
            residual_norm: self.residual_norm,
            max_cutbacks: self.max_cutbacks.unwrap_or(crate::newton::DEFAULT_CUTBACKS),
        }
    }
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
    /// Identifier used by expectations and figures (see [`ident_ok`]).
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
    /// File stem of the SVG (see [`ident_ok`]).
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
}

/// A study file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StudySpec {
    /// Layout version; must equal [`SCHEMA_VERSION`].
    pub schema: i64,
    /// Name of the study and of its output folder (see [`ident_ok`]).
    pub name: String,
    /// One line for `study list` and `--help`.
    pub summary: String,
    pub problem: ProblemKind,
    /// File name of the Markdown report inside the study's output folder.
    pub report_file: String,
    pub column: ColumnSection,
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
    /// Ghost stabilisation of one point per cell ([`crate::ghost`]); absent: none.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ghost: Option<ColumnGhost>,
}

/// A column study's `[ghost]`: the settings of its one-point-per-cell cases (the odd-even
/// mode of one-point sampling, reference/README.md item 15) and where they come from. Cases
/// with more points per cell are untreated, so Table 1 is unaffected.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ColumnGhost {
    pub one_point_per_cell: crate::ghost::GhostSettings,
}

/// One case to solve.
#[derive(Debug, Clone, PartialEq)]
pub struct Case {
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
}

/// The one identifier rule of every study file (names, sweep, case and figure ids, report
/// files): [`IDENT_RULE`]. The leading letter or digit and the ban on `..` keep hidden and
/// parent paths out, so that an identifier used as a folder or file name stays inside the
/// output folder.
pub fn ident_ok(s: &str) -> bool {
    !s.is_empty()
        && s.len() <= 64
        && s.as_bytes()[0].is_ascii_alphanumeric()
        && !s.contains("..")
        && s.bytes()
            .all(|b| b.is_ascii_lowercase() || b.is_ascii_digit() || matches!(b, b'-' | b'_' | b'.'))
}

/// [`ident_ok`] in words, for error messages.
pub const IDENT_RULE: &str =
    "1-64 characters from [a-z0-9_.-], starting with a letter or digit, without \"..\"";

/// Most material points per cell of a study case in any dimension (per axis: 64 in 1D, 8 in
/// 2D, 4 in 3D): beyond it a point's share of a cell is below the quadrature's round-off.
pub const MAX_POINTS_PER_CELL: i64 = 64;

/// Largest points per cell along each axis in `dim` dimensions ([`MAX_POINTS_PER_CELL`]).
pub fn max_points_per_axis(dim: u32) -> i64 {
    (1..=MAX_POINTS_PER_CELL)
        .take_while(|n| n.pow(dim) <= MAX_POINTS_PER_CELL)
        .last()
        .unwrap_or(1)
}

/// Format a weight for case ids and labels without a trailing `.0`.
pub fn weight_label(w: f64) -> String {
    if w.fract() == 0.0 && w.abs() < 1e15 {
        format!("{}", w as i64)
    } else {
        format!("{w}")
    }
}

/// A float as written in an error: scientific notation when very large or small.
fn short(v: f64) -> String {
    if v != 0.0 && v.is_finite() && !(1e-4..1e15).contains(&v.abs()) {
        format!("{v:e}")
    } else {
        v.to_string()
    }
}

struct Checker<'a> {
    file: &'a str,
}

impl Checker<'_> {
    fn err(&self, key: impl Into<String>, value: impl ToString, allowed: impl Into<String>) -> StudyError {
        StudyError::Invalid {
            file: self.file.to_string(),
            key: key.into(),
            value: value.to_string(),
            allowed: allowed.into(),
        }
    }
    fn count(&self, key: &str, v: i64, lo: i64, hi: i64) -> Result<(), StudyError> {
        if (lo..=hi).contains(&v) {
            Ok(())
        } else {
            Err(self.err(key, v, format!("must be an integer in {lo}..={hi}")))
        }
    }
    fn positive(&self, key: &str, v: f64) -> Result<(), StudyError> {
        if v.is_finite() && v > 0.0 {
            Ok(())
        } else {
            Err(self.err(key, short(v), "must be finite and > 0"))
        }
    }
    fn ident(&self, key: &str, v: &str) -> Result<(), StudyError> {
        if ident_ok(v) {
            Ok(())
        } else {
            Err(self.err(key, format!("{v:?}"), format!("must be {IDENT_RULE}")))
        }
    }
    fn text(&self, key: &str, v: &str) -> Result<(), StudyError> {
        if v.trim().is_empty() {
            Err(self.err(key, "\"\"", "must not be empty"))
        } else {
            Ok(())
        }
    }
    fn non_empty<T>(&self, key: &str, v: &[T]) -> Result<(), StudyError> {
        if v.is_empty() {
            Err(self.err(key, "[]", "must list at least one value"))
        } else {
            Ok(())
        }
    }
    fn newton(&self, key: &str, n: &NewtonSection) -> Result<(), StudyError> {
        if !(n.tolerance.is_finite() && n.tolerance > 0.0 && n.tolerance < 1.0) {
            return Err(self.err(format!("{key}.tolerance"), n.tolerance, "must lie in (0, 1)"));
        }
        self.count(&format!("{key}.max_iterations"), n.max_iterations, 1, 1000)
    }
}

const MAX_ELEMENTS: i64 = 1_000_000;
/// Most material points of one case (elements × points per cell): ~0.6 GB of point state.
const MAX_POINTS_PER_CASE: i64 = 2_000_000;
/// Most cases of one sweep (methods × weights × points per cell × elements), checked before
/// the case list is built.
const MAX_CASES_PER_SWEEP: usize = 10_000;

impl StudySpec {
    /// Parse and validate a study file's text; `file` names it in errors.
    pub fn parse(text: &str, file: &str) -> Result<Self, StudyError> {
        let spec: StudySpec = toml::from_str(text).map_err(|e| StudyError::Parse {
            file: file.to_string(),
            message: e.to_string().trim_end().to_string(),
        })?;
        spec.validate(file)?;
        Ok(spec)
    }

    /// Read, parse and validate a study file.
    pub fn load(path: &Path) -> Result<Self, StudyError> {
        let text = std::fs::read_to_string(path).map_err(|e| StudyError::io(path, e))?;
        Self::parse(&text, &path.display().to_string())
    }

    /// Check every value; the error names the file, the key and its allowed range.
    pub fn validate(&self, file: &str) -> Result<(), StudyError> {
        let c = Checker { file };
        if self.schema != SCHEMA_VERSION {
            return Err(c.err("schema", self.schema, format!("must be {SCHEMA_VERSION}")));
        }
        c.ident("name", &self.name)?;
        c.text("summary", &self.summary)?;
        if let Some(g) = &self.ghost {
            g.one_point_per_cell
                .validate()
                .map_err(|e| c.err("ghost.one_point_per_cell", e.value.clone(), e.allowed.clone()))?;
        }
        if !(self.report_file.ends_with(".md") && ident_ok(self.report_file.trim_end_matches(".md"))) {
            return Err(c.err(
                "report_file",
                format!("{:?}", self.report_file),
                format!("must be a file name <identifier>.md ({IDENT_RULE})"),
            ));
        }
        let col = &self.column;
        c.positive("column.length", col.length)?;
        c.positive("column.young_modulus", col.young_modulus)?;
        if !(col.poisson_ratio.is_finite() && (0.0..0.5).contains(&col.poisson_ratio)) {
            return Err(c.err("column.poisson_ratio", col.poisson_ratio, "must lie in [0, 0.5)"));
        }
        c.positive("column.density", col.density)?;
        if let Some(ry) = col.yield_stress {
            c.positive("column.yield_stress", ry)?;
        }
        c.count("load_steps", self.load_steps, 1, 10_000)?;
        c.newton("newton", &self.newton)?;
        c.non_empty("sweeps", &self.sweeps)?;

        let mut ids = BTreeSet::new();
        for (i, s) in self.sweeps.iter().enumerate() {
            let k = |f: &str| format!("sweeps[{i}].{f}");
            c.ident(&k("id"), &s.id)?;
            if !ids.insert(s.id.as_str()) {
                return Err(c.err(k("id"), format!("{:?}", s.id), "must be unique among sweeps"));
            }
            c.text(&k("title"), &s.title)?;
            self.check_lists(
                &c,
                &k(""),
                &s.methods,
                &s.weights,
                &s.elements,
                &s.points_per_cell,
            )?;
            let q = &s.quick;
            self.check_lists(
                &c,
                &k("quick."),
                q.methods.as_deref().unwrap_or(&s.methods),
                q.weights.as_deref().unwrap_or(&s.weights),
                q.elements.as_deref().unwrap_or(&s.elements),
                q.points_per_cell.as_deref().unwrap_or(&s.points_per_cell),
            )?;
            if let Some(n) = s.fit_points {
                c.count(&k("fit_points"), n, 2, 1000)?;
            }
            if let Some(n) = s.load_steps {
                c.count(&k("load_steps"), n, 1, 10_000)?;
            }
            if let Some(n) = &s.newton {
                c.newton(&k("newton"), n)?;
            }
        }

        for (i, e) in self.expect.iter().enumerate() {
            let k = |f: &str| format!("expect[{i}].{f}");
            let sweep = self.sweep_ref(&c, &k("sweep"), &e.sweep)?;
            self.check_series_ref(&c, &k(""), sweep, e.method, e.weight, e.points_per_cell)?;
            if !e.rate.is_finite() {
                return Err(c.err(k("rate"), e.rate, "must be finite"));
            }
            c.positive(&k("tolerance"), e.tolerance)?;
            c.text(&k("source"), &e.source)?;
        }
        for (i, e) in self.compare.iter().enumerate() {
            let k = |f: &str| format!("compare[{i}].{f}");
            let sweep = self.sweep_ref(&c, &k("sweep"), &e.sweep)?;
            for (key, m) in [("lower", e.lower), ("higher", e.higher)] {
                if !sweep.methods.contains(&m) {
                    return Err(c.err(
                        k(key),
                        m.name(),
                        format!("must be a method of sweep `{}`", sweep.id),
                    ));
                }
            }
            if !sweep.weights.contains(&e.weight) {
                return Err(c.err(
                    k("weight"),
                    e.weight,
                    format!("must be a weight of sweep `{}`", sweep.id),
                ));
            }
            c.text(&k("source"), &e.source)?;
        }
        for (i, p) in self.paper.iter().enumerate() {
            let k = |f: &str| format!("paper[{i}].{f}");
            c.text(&k("table"), &p.table)?;
            let sweep = self.sweep_ref(&c, &k("sweep"), &p.sweep)?;
            self.check_series_ref(&c, &k(""), sweep, p.method, p.weight, p.points_per_cell)?;
            c.non_empty(&k("elements"), &p.elements)?;
            for (j, &n) in p.elements.iter().enumerate() {
                c.count(&k(&format!("elements[{j}]")), n, 1, MAX_ELEMENTS)?;
            }
            for (key, v) in [
                ("top_displacement", &p.top_displacement),
                ("base_f", &p.base_f),
                ("f_error", &p.f_error),
            ] {
                if v.len() != p.elements.len() {
                    return Err(c.err(
                        k(key),
                        format!("{} values", v.len()),
                        format!("must give one value per element count ({})", p.elements.len()),
                    ));
                }
            }
            c.positive(&k("analytical_base_f"), p.analytical_base_f)?;
        }
        let mut fig_ids = BTreeSet::new();
        for (i, f) in self.figures.iter().enumerate() {
            let k = |x: &str| format!("figures[{i}].{x}");
            c.ident(&k("id"), &f.id)?;
            if !fig_ids.insert(f.id.as_str()) {
                return Err(c.err(k("id"), format!("{:?}", f.id), "must be unique among figures"));
            }
            c.text(&k("title"), &f.title)?;
            let sweep = self.sweep_ref(&c, &k("sweep"), &f.sweep)?;
            if !sweep.weights.contains(&f.weight) {
                return Err(c.err(
                    k("weight"),
                    f.weight,
                    format!("must be a weight of sweep `{}`", sweep.id),
                ));
            }
            match (f.kind, f.measure) {
                (FigureKind::Convergence, None) => {
                    return Err(c.err(k("measure"), "(missing)", "convergence figures need a measure"))
                }
                (FigureKind::Profile, Some(m)) => {
                    return Err(c.err(k("measure"), m.name(), "profile figures take no measure"))
                }
                _ => {}
            }
        }
        Ok(())
    }

    fn check_lists(
        &self,
        c: &Checker,
        prefix: &str,
        methods: &[Method],
        weights: &[f64],
        elements: &[i64],
        ppc: &[i64],
    ) -> Result<(), StudyError> {
        let k = |f: &str| format!("{prefix}{f}");
        c.non_empty(&k("methods"), methods)?;
        for (j, m) in methods.iter().enumerate() {
            m.expect_one_of("column", &crate::problems::column::METHODS)
                .map_err(|e| c.err(format!("{}[{j}]", k("methods")), m.name(), e.allowed))?;
            if methods[..j].contains(m) {
                return Err(c.err(
                    format!("{}[{j}]", k("methods")),
                    m.name(),
                    "must not repeat a method",
                ));
            }
        }
        c.non_empty(&k("weights"), weights)?;
        let limit = 1e3 * self.column.young_modulus;
        for (j, &w) in weights.iter().enumerate() {
            let key = format!("{}[{j}]", k("weights"));
            c.positive(&key, w)?;
            if w > limit {
                return Err(c.err(
                    key,
                    short(w),
                    format!("must be <= 1000 × column.young_modulus = {limit}"),
                ));
            }
        }
        c.non_empty(&k("elements"), elements)?;
        for (j, &n) in elements.iter().enumerate() {
            c.count(&format!("{}[{j}]", k("elements")), n, 1, MAX_ELEMENTS)?;
        }
        c.non_empty(&k("points_per_cell"), ppc)?;
        for (j, &n) in ppc.iter().enumerate() {
            c.count(
                &format!("{}[{j}]", k("points_per_cell")),
                n,
                1,
                max_points_per_axis(1),
            )?;
        }
        let max_ppc = ppc.iter().copied().max().unwrap_or(1);
        if methods.iter().any(|&m| m.uses_material_points()) {
            for (j, &n) in elements.iter().enumerate() {
                if n * max_ppc > MAX_POINTS_PER_CASE {
                    return Err(c.err(
                        format!("{}[{j}]", k("elements")),
                        n,
                        format!(
                            "elements × points_per_cell ({n} × {max_ppc}) must be <= {MAX_POINTS_PER_CASE}"
                        ),
                    ));
                }
            }
        }
        let cases = methods.len() * weights.len() * elements.len() * ppc.len();
        if cases > MAX_CASES_PER_SWEEP {
            return Err(c.err(
                prefix.trim_end_matches('.'),
                format!("{cases} cases"),
                format!("methods × weights × elements × points_per_cell must be <= {MAX_CASES_PER_SWEEP}"),
            ));
        }
        Ok(())
    }

    fn sweep_ref<'a>(&'a self, c: &Checker, key: &str, id: &str) -> Result<&'a Sweep, StudyError> {
        self.sweep(id).ok_or_else(|| {
            let known: Vec<&str> = self.sweeps.iter().map(|s| s.id.as_str()).collect();
            c.err(
                key,
                format!("{id:?}"),
                format!("must name a sweep: one of {known:?}"),
            )
        })
    }

    fn check_series_ref(
        &self,
        c: &Checker,
        prefix: &str,
        sweep: &Sweep,
        method: Method,
        weight: f64,
        ppc: Option<i64>,
    ) -> Result<(), StudyError> {
        let k = |f: &str| format!("{prefix}{f}");
        if !sweep.methods.contains(&method) {
            return Err(c.err(
                k("method"),
                method.name(),
                format!("must be a method of sweep `{}`", sweep.id),
            ));
        }
        if !sweep.weights.contains(&weight) {
            return Err(c.err(
                k("weight"),
                weight,
                format!("must be a weight of sweep `{}`", sweep.id),
            ));
        }
        match (method.uses_material_points(), ppc) {
            (true, None) => Err(c.err(
                k("points_per_cell"),
                "(missing)",
                format!("is required for {}", method.name()),
            )),
            (true, Some(n)) if !sweep.points_per_cell.contains(&n) => Err(c.err(
                k("points_per_cell"),
                n,
                format!(
                    "must be one of sweep `{}`'s points_per_cell {:?}",
                    sweep.id, sweep.points_per_cell
                ),
            )),
            (false, Some(n)) => Err(c.err(
                k("points_per_cell"),
                n,
                format!(
                    "must be absent for {} (FEM has no material points)",
                    method.name()
                ),
            )),
            _ => Ok(()),
        }
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
        })
    }

    /// The column of one case. Fields the study file does not set (e.g. ones other branches
    /// add to `ColumnSpec`, such as FEM Gauss points) keep their defaults.
    #[allow(clippy::needless_update)]
    pub fn column_spec(&self, weight: f64, elements: usize, ppc: usize, plan: &SweepPlan) -> ColumnSpec {
        ColumnSpec {
            length: self.column.length,
            young_modulus: self.column.young_modulus,
            poisson_ratio: self.column.poisson_ratio,
            density: self.column.density,
            yield_stress: self.column.yield_stress,
            weight,
            elements,
            points_per_cell: ppc,
            load_steps: plan.load_steps,
            newton: plan.newton,
            ghost: match (ppc, self.ghost) {
                (1, Some(g)) => g.one_point_per_cell,
                _ => crate::ghost::GhostSettings::default(),
            },
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
        if spec.newton != self.newton.settings() {
            id.push_str(&format!(
                "-tol{:e}-it{}",
                spec.newton.tolerance, spec.newton.max_iterations
            ));
        }
        id
    }

    /// The cases of one sweep in order method, weight, points per cell, elements.
    pub fn sweep_cases(&self, plan: &SweepPlan) -> Vec<Case> {
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
                        out.push(Case {
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
    pub fn cases(&self, tier: Tier) -> Vec<Case> {
        let mut seen = BTreeSet::new();
        self.sweeps
            .iter()
            .filter_map(|s| self.plan(s, tier))
            .flat_map(|plan| self.sweep_cases(&plan))
            .filter(|c| seen.insert(c.id.clone()))
            .collect()
    }

    /// Which case ids each sweep of the tier uses.
    pub fn case_index(&self, tier: Tier) -> rates::CaseIndex {
        rates::CaseIndex {
            sweeps: self
                .sweeps
                .iter()
                .filter_map(|s| {
                    let plan = self.plan(s, tier)?;
                    Some((
                        s.id.clone(),
                        self.sweep_cases(&plan).into_iter().map(|c| c.id).collect(),
                    ))
                })
                .collect(),
        }
    }
}

/// The study files (`*.toml`) in a folder, sorted by name.
pub fn study_files(dir: &Path) -> Result<Vec<PathBuf>, StudyError> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(dir)
        .map_err(|e| StudyError::io(dir, e))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    files.sort();
    Ok(files)
}
