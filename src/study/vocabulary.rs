//! The one validation vocabulary of every study file: the identifier rule, the limits, the
//! [`Checker`] whose errors name the file, the key, the value and the allowed range, and the
//! sections several kinds share (`[newton]`, `[weak_nodes]`, `[ghost]`).

use super::{StudyError, SCHEMA_VERSION};
/// Settings the study files (and so `results.json`) hold, for the renderers to read.
pub use crate::discretise::ghost::{GhostFaces, GhostSettings};
pub use crate::mpm::WeakNodeTreatment;
use crate::solver::newton::NewtonSettings;
pub use crate::solver::newton::ResidualNorm;
use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};
use std::collections::BTreeSet;

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
    pub residual_norm: crate::solver::newton::ResidualNorm,
    /// Adaptive load stepping: most halvings of a failing increment (0..=20, default 6:
    /// down to 1/64 of a load step; 0 = fixed steps).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_cutbacks: Option<u32>,
    /// Newton's start in an increment: `zero` (the default, the paper's) or `extrapolated`
    /// (the last converged increment scaled to this one's load; static studies only).
    #[serde(default, skip_serializing_if = "crate::solver::newton::Predictor::is_zero")]
    pub predictor: crate::solver::newton::Predictor,
}

impl NewtonSection {
    pub fn settings(&self) -> NewtonSettings {
        NewtonSettings {
            tolerance: self.tolerance,
            max_iterations: self.max_iterations as usize,
            line_search: self.line_search,
            residual_norm: self.residual_norm,
            max_cutbacks: self
                .max_cutbacks
                .unwrap_or(crate::solver::newton::DEFAULT_CUTBACKS),
            predictor: self.predictor,
        }
    }
}

/// Weak-node treatment as written in a study file (see [`crate::mpm::MpmSettings`]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WeakNodeSection {
    /// Nodes whose material volume share is below this fraction of an element are treated;
    /// in [0, 1), 0 disables the treatment.
    pub tolerance: f64,
    pub treatment: WeakNodeTreatment,
}

/// Ghost stabilisation as written in a study file ([`crate::discretise::ghost`]): γ and the faces for
/// two or more points per cell, the settings for one point per cell (every face), and those
/// of plastic cases.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GhostSection {
    /// Penalty factor γ for two or more points per cell (0 = off); in [0, 1000].
    pub gamma: f64,
    #[serde(default)]
    pub faces: crate::discretise::ghost::GhostFaces,
    /// Fill fraction below which a cell is cut, in (0, 1]; default
    /// [`crate::discretise::ghost::DEFAULT_CUT_FILL`].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cut_fill: Option<f64>,
    /// Node share below which a node's cells are cut too ([`crate::discretise::ghost::GhostSettings::cut_share`]);
    /// default 0 (off).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cut_share: Option<f64>,
    /// Settings for one point per cell; default: the ones above.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub one_point_per_cell: Option<crate::discretise::ghost::GhostSettings>,
    /// Settings for plastic (von Mises) cases with two or more points per cell; default: the
    /// ones above.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub plastic: Option<crate::discretise::ghost::GhostSettings>,
    /// Where the defaults come from (the measurement that chose them).
    pub source: String,
}

impl GhostSection {
    /// The settings of a case with `ppc` points per cell, plastic or not; `gamma` (a sweep's
    /// value) replaces the default γ.
    pub fn settings(
        &self,
        ppc: usize,
        plastic: bool,
        gamma: Option<f64>,
    ) -> crate::discretise::ghost::GhostSettings {
        let mut g = match (ppc, self.one_point_per_cell, plastic, self.plastic) {
            (1, Some(one), _, _) => one,
            (_, _, true, Some(p)) => p,
            _ => crate::discretise::ghost::GhostSettings {
                gamma: self.gamma,
                faces: self.faces,
                cut_fill: self
                    .cut_fill
                    .unwrap_or(crate::discretise::ghost::DEFAULT_CUT_FILL),
                cut_share: self.cut_share.unwrap_or(0.0),
            },
        };
        if let Some(gamma) = gamma {
            g.gamma = gamma;
        }
        g
    }

    pub fn validate(&self) -> Result<(), crate::solver::error::InputError> {
        self.settings(2, false, None).validate()?;
        self.settings(2, true, None).validate()?;
        self.settings(1, false, None).validate()
    }
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

/// Format a weight for case ids and labels: [`number`].
pub fn weight_label(w: f64) -> String {
    number(w)
}

/// A float as written in an error: scientific notation when very large or small.
pub fn short(v: f64) -> String {
    if v != 0.0 && v.is_finite() && !(1e-4..1e15).contains(&v.abs()) {
        format!("{v:e}")
    } else {
        v.to_string()
    }
}

/// A number in a case id or label: the shortest text that reads back to the same float,
/// without a trailing `.0` (`40000`, `0.25`, `1e300`, `1e-300`): Rust's `Display` writes
/// every digit of 1e300, which made a 301-character file name of a case id.
pub fn number(x: f64) -> String {
    crate::solver::error::shortest(x)
}

/// Validation of one study file: every error names the file, the key, the value and the
/// allowed range.
pub struct Checker<'a> {
    pub file: &'a str,
}

impl Checker<'_> {
    pub fn err(
        &self,
        key: impl Into<String>,
        value: impl ToString,
        allowed: impl Into<String>,
    ) -> StudyError {
        invalid(self.file, key, value, allowed)
    }
    /// Case `case` of the section `scope` (`sweeps[0]`, `cases[2]`) is an invalid problem
    /// input `e`, whose field the problem names ([`super::locate`] finds the file's key).
    pub fn case_input(&self, scope: &str, case: &str, e: crate::solver::error::InputError) -> StudyError {
        StudyError::CaseInput(Box::new(super::CaseInput {
            file: self.file.to_string(),
            scope: scope.to_string(),
            case: case.to_string(),
            field: e.field,
            value: e.value,
            allowed: e.allowed,
        }))
    }
    pub fn count(&self, key: &str, v: i64, lo: i64, hi: i64) -> Result<(), StudyError> {
        if (lo..=hi).contains(&v) {
            Ok(())
        } else {
            Err(self.err(key, v, format!("must be an integer in {lo}..={hi}")))
        }
    }
    pub fn positive(&self, key: &str, v: f64) -> Result<(), StudyError> {
        if v.is_finite() && v > 0.0 {
            Ok(())
        } else {
            Err(self.err(key, short(v), "must be finite and > 0"))
        }
    }
    pub fn ident(&self, key: &str, v: &str) -> Result<(), StudyError> {
        if ident_ok(v) {
            Ok(())
        } else {
            Err(self.err(key, format!("{v:?}"), format!("must be {IDENT_RULE}")))
        }
    }

    /// A Newton-order check's terms at `key`: `small`, `floor` and `constant` positive, a
    /// source given.
    pub fn quadratic(
        &self,
        key: &str,
        q: &crate::study::checks::QuadraticExpectation,
    ) -> Result<(), StudyError> {
        for (k, v) in [("small", q.small), ("floor", q.floor), ("constant", q.constant)] {
            self.positive(&format!("{key}.{k}"), v)?;
        }
        self.text(&format!("{key}.source"), &q.source)
    }

    pub fn text(&self, key: &str, v: &str) -> Result<(), StudyError> {
        if v.trim().is_empty() {
            Err(self.err(key, "\"\"", "must not be empty"))
        } else {
            Ok(())
        }
    }
    pub fn non_empty<T>(&self, key: &str, v: &[T]) -> Result<(), StudyError> {
        if v.is_empty() {
            Err(self.err(key, "[]", "must list at least one value"))
        } else {
            Ok(())
        }
    }
    /// An identifier unique among those `seen` so far (which it joins).
    pub fn unique_ident<'s>(
        &self,
        key: &str,
        v: &'s str,
        seen: &mut BTreeSet<&'s str>,
    ) -> Result<(), StudyError> {
        self.ident(key, v)?;
        if seen.insert(v) {
            Ok(())
        } else {
            Err(self.err(key, format!("{v:?}"), "must be unique: another entry has this id"))
        }
    }
    /// A Markdown file name `<identifier>.md`.
    pub fn markdown_file(&self, key: &str, v: &str) -> Result<(), StudyError> {
        if v.ends_with(".md") && ident_ok(v.trim_end_matches(".md")) {
            Ok(())
        } else {
            Err(self.err(
                key,
                format!("{v:?}"),
                format!("must be a file name <identifier>.md ({IDENT_RULE})"),
            ))
        }
    }
    /// The keys every study file starts with: `schema`, `problem`, `name`, `summary` and
    /// `report_file`.
    pub fn header(&self, h: Header<'_>) -> Result<(), StudyError> {
        if h.schema != SCHEMA_VERSION {
            return Err(self.err("schema", h.schema, format!("must be {SCHEMA_VERSION}")));
        }
        if h.problem != h.expected_problem {
            return Err(self.err(
                "problem",
                format!("{:?}", h.problem),
                format!("must be {:?}", h.expected_problem),
            ));
        }
        self.ident("name", h.name)?;
        self.text("summary", h.summary)?;
        self.markdown_file("report_file", h.report_file)
    }
    pub fn newton(&self, key: &str, n: &NewtonSection) -> Result<(), StudyError> {
        let min = crate::solver::newton::MIN_TOLERANCE;
        if !(n.tolerance.is_finite() && (min..1.0).contains(&n.tolerance)) {
            return Err(self.err(
                format!("{key}.tolerance"),
                short(n.tolerance),
                format!("must lie in [{min:e}, 1) (below it the force balance is under round-off: every case would fail)"),
            ));
        }
        self.count(&format!("{key}.max_iterations"), n.max_iterations, 1, 1000)?;
        if let Some(m) = n.max_cutbacks {
            let max = crate::solver::newton::MAX_CUTBACKS;
            if m > max {
                return Err(self.err(
                    format!("{key}.max_cutbacks"),
                    m,
                    format!("must be an integer in 0..={max} (the smallest increment is 2^-max_cutbacks of a load step)"),
                ));
            }
        }
        Ok(())
    }
    /// A weak-node volume fraction: in [0, 1) (0 disables the treatment).
    pub fn weak_node_tolerance(&self, key: &str, v: f64) -> Result<(), StudyError> {
        if v.is_finite() && (0.0..1.0).contains(&v) {
            Ok(())
        } else {
            Err(self.err(
                key,
                short(v),
                "must lie in [0, 1) (a fraction of an element's volume; 0 = off)",
            ))
        }
    }
}

/// The keys every study file starts with, for [`Checker::header`].
pub struct Header<'a> {
    pub schema: i64,
    pub problem: &'a str,
    pub expected_problem: &'a str,
    pub name: &'a str,
    pub summary: &'a str,
    pub report_file: &'a str,
}

/// A value outside its allowed range in a study file.
pub fn invalid(
    file: &str,
    key: impl Into<String>,
    value: impl ToString,
    allowed: impl Into<String>,
) -> StudyError {
    StudyError::Invalid {
        file: file.to_string(),
        key: key.into(),
        value: crate::solver::error::tidy_numbers(&value.to_string()),
        allowed: crate::solver::error::tidy_numbers(&allowed.into()),
    }
}

/// Parse a study file's TOML into `T` (unknown keys are errors through `deny_unknown_fields`).
pub fn parse_toml<T: DeserializeOwned>(text: &str, file: &str) -> Result<T, StudyError> {
    toml::from_str(text).map_err(|e| {
        let message = e.to_string().trim_end().to_string();
        // A key missing from the top level is reported at the document's span, line 1 column 1
        // (often a comment): say where it belongs instead.
        let top_level = e.span().is_some_and(|s| s.start == 0 && !text.starts_with('['));
        let missing = message
            .lines()
            .last()
            .and_then(|l| l.strip_prefix("missing field `"))
            .and_then(|l| l.strip_suffix('`'));
        match (top_level, missing) {
            (true, Some(key)) => StudyError::Parse {
                file: file.to_string(),
                message: format!(
                    "missing required key `{key}` at the top level of the file (with `schema`, `name` and `problem`, before the first [section])"
                ),
            },
            _ => StudyError::Parse {
                file: file.to_string(),
                message,
            },
        }
    })
}

/// Deserialize exactly two numbers (TOML's array into `[f64; 2]` would drop a third value
/// silently): an error names the length found.
pub fn exactly_two<'de, D: serde::Deserializer<'de>>(d: D) -> Result<[f64; 2], D::Error> {
    let v: Vec<f64> = Vec::deserialize(d)?;
    <[f64; 2]>::try_from(v.as_slice()).map_err(|_| {
        serde::de::Error::invalid_length(
            v.len(),
            &"2 values (the horizontal extent and the height, in 2D and in 3D)",
        )
    })
}

/// Points per cell as a grid, `p` per axis in `dimension` axes: "2×2" in 2D, "2×2×2" in 3D.
pub fn points_grid(p: usize, dimension: usize) -> String {
    vec![p.to_string(); dimension.max(1)].join("×")
}

/// A sweep that may run in the full tier only, and a figure drawing one: what a renderer needs
/// to leave a full-tier sweep's figures out of a quick run.
pub trait TieredSweep {
    fn id(&self) -> &str;
    /// Whether the sweep solves any case in `tier`.
    fn runs_in(&self, tier: super::Tier) -> bool;
}

/// A figure of one sweep.
pub trait SweepFigure {
    fn sweep(&self) -> &str;
}

/// Cases a study expects to fail (`[[expected_failures]]`): a failure the study means to show
/// (e.g. Figure 9's untreated one-point series), not a regression. `study --check` fails on
/// any failed case that no declaration matches, and the run's summary says which failures were
/// expected.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ExpectedFailure {
    /// Case ids; `*` matches any run of characters.
    pub cases: Vec<String>,
    /// Why these cases fail, for the summary and the report.
    pub reason: String,
}

/// Whether `id` matches `pattern`, whose `*` matches any run of characters (none included).
pub fn glob_match(pattern: &str, id: &str) -> bool {
    let mut parts = pattern.split('*');
    let first = parts.next().unwrap_or("");
    let Some(mut rest) = id.strip_prefix(first) else {
        return false;
    };
    let parts: Vec<&str> = parts.collect();
    let Some((last, middle)) = parts.split_last() else {
        return rest.is_empty();
    };
    for p in middle {
        match rest.find(p) {
            Some(i) => rest = &rest[i + p.len()..],
            None => return false,
        }
    }
    rest.len() >= last.len() && rest.ends_with(last)
}

/// The reason of the declaration in `declared` matching case `id`, if any.
pub fn expected_reason<'a>(declared: &'a [ExpectedFailure], id: &str) -> Option<&'a str> {
    declared
        .iter()
        .find(|e| e.cases.iter().any(|p| glob_match(p, id)))
        .map(|e| e.reason.as_str())
}

#[cfg(test)]
mod glob_tests {
    use super::glob_match;

    #[test]
    fn glob_matches_runs_and_anchors_both_ends() {
        assert!(glob_match(
            "igimp-*-p1-*-untreated",
            "igimp-w1e4-e128-p1-s20-untreated"
        ));
        assert!(glob_match("a*", "a"));
        assert!(glob_match("*", ""));
        assert!(glob_match("f-diagonal", "f-diagonal"));
        assert!(!glob_match("f-diagonal", "f-diagonal-untreated"));
        assert!(!glob_match("a*b", "ab-c"));
        assert!(!glob_match("ab*ba", "aba"));
    }
}
