//! The element-test study (`problem = "element"`): one material point per test under a
//! prescribed path ([`crate::problems::element_test`]), each test's measures against the closed
//! forms the file names, and the local Newton's convergence order checked.
//! `studies/README.md` ("Element tests") documents the schema.

mod kind;

use super::material::MaterialTable;
use super::vocabulary::{Checker, ExpectedFailure, Header};
use crate::problems::element_test::{ClosedForm, ElementPath, ElementTest};
use crate::study::checks::QuadraticExpectation;
use crate::study::results::{case_record, Envelope, SolveRecord};
use crate::study::StudyError;
use serde::{Deserialize, Serialize};
use std::collections::{BTreeMap, BTreeSet};

fn default_confining_steps() -> i64 {
    10
}
fn default_tolerance() -> f64 {
    1e-12
}
fn default_max_iterations() -> i64 {
    25
}

/// One test of the file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TestSection {
    pub id: String,
    /// A `[materials.<name>]` table.
    pub material: String,
    pub path: ElementPath,
    /// Isotropic pressure applied first and held laterally (compression positive; default 0).
    #[serde(default)]
    pub confining: f64,
    #[serde(default = "default_confining_steps")]
    pub confining_steps: i64,
    /// The driven strain at the end (compression positive; γ in simple shear).
    pub strain: f64,
    pub steps: i64,
    #[serde(default = "default_tolerance")]
    pub tolerance: f64,
    #[serde(default = "default_max_iterations")]
    pub max_iterations: i64,
}

impl TestSection {
    pub fn test(&self) -> ElementTest {
        ElementTest {
            path: self.path,
            confining: self.confining,
            confining_steps: self.confining_steps.max(0) as usize,
            strain: self.strain,
            steps: self.steps.max(0) as usize,
            tolerance: self.tolerance,
            max_iterations: self.max_iterations.max(0) as usize,
        }
    }
}

/// A test's measure equals a closed form within `tolerance` (relative).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ClosedFormExpectation {
    pub test: String,
    pub closed_form: ClosedForm,
    pub tolerance: f64,
    pub source: String,
}

/// An element-test study file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ElementStudy {
    pub schema: i64,
    pub name: String,
    pub summary: String,
    /// Always "element".
    pub problem: String,
    pub report_file: String,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub expected_failures: Vec<ExpectedFailure>,
    pub materials: BTreeMap<String, MaterialTable>,
    pub tests: Vec<TestSection>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub expect_closed_form: Vec<ClosedFormExpectation>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub expect_quadratic: Option<QuadraticExpectation>,
}

/// One test's result.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ElementRecord {
    pub id: String,
    pub model: String,
    pub path: ElementPath,
    #[serde(flatten)]
    pub solve: SolveRecord,
    /// The final state's measures (a failed test's at its last converged step).
    pub measures: BTreeMap<String, f64>,
    /// The measures after each converged step of the path (the confinement left out).
    pub histories: BTreeMap<String, Vec<f64>>,
    /// The state at the start of the path (after the confinement): p and q.
    pub start: BTreeMap<String, f64>,
}

case_record!(ElementRecord);

/// A closed form's value and the test's measure against it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ClosedFormRecord {
    pub test: String,
    pub closed_form: ClosedForm,
    pub measure: String,
    /// `None`: the test did not reach the end of its path.
    pub value: Option<f64>,
    pub measured: Option<f64>,
    pub error: Option<f64>,
    pub source: String,
}

/// The element study's measures in `results.json`.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct ElementMeasures {
    pub closed_forms: Vec<ClosedFormRecord>,
}

/// `results.json` of an element study.
pub type ElementResults = Envelope<ElementStudy, ElementRecord, ElementMeasures>;

impl ElementStudy {
    pub(super) fn check(&self, file: &str) -> Result<(), StudyError> {
        let chk = Checker { file };
        chk.header(Header {
            schema: self.schema,
            problem: &self.problem,
            expected_problem: "element",
            name: &self.name,
            summary: &self.summary,
            report_file: &self.report_file,
        })?;
        if self.materials.is_empty() {
            return Err(chk.err(
                "materials",
                "{}",
                "must define at least one [materials.<name>] table",
            ));
        }
        let mut materials = BTreeMap::new();
        for (name, table) in &self.materials {
            chk.ident(&format!("materials.{name}"), name)?;
            materials.insert(name.as_str(), chk.material(&format!("materials.{name}"), table)?);
        }
        chk.non_empty("tests", &self.tests)?;
        let mut ids = BTreeSet::new();
        for (i, t) in self.tests.iter().enumerate() {
            let key = format!("tests[{i}]");
            chk.unique_ident(&format!("{key}.id"), &t.id, &mut ids)?;
            if !materials.contains_key(t.material.as_str()) {
                let known: Vec<&str> = materials.keys().copied().collect();
                return Err(chk.err(
                    format!("{key}.material"),
                    format!("{:?}", t.material),
                    format!("must name a [materials.<name>] table: {}", known.join(", ")),
                ));
            }
            chk.count(&format!("{key}.steps"), t.steps, 1, 1_000_000)?;
            chk.count(&format!("{key}.confining_steps"), t.confining_steps, 1, 100_000)?;
            chk.count(&format!("{key}.max_iterations"), t.max_iterations, 1, 100)?;
            t.test()
                .validate(&key)
                .map_err(|e| chk.err(e.field, e.value, e.allowed))?;
        }
        for (i, e) in self.expect_closed_form.iter().enumerate() {
            let key = format!("expect_closed_form[{i}]");
            let Some(t) = self.tests.iter().find(|t| t.id == e.test) else {
                return Err(chk.err(
                    format!("{key}.test"),
                    format!("{:?}", e.test),
                    "must name a test's id",
                ));
            };
            if !(e.tolerance.is_finite() && e.tolerance > 0.0) {
                return Err(chk.err(format!("{key}.tolerance"), e.tolerance, "must be finite and > 0"));
            }
            chk.text(&format!("{key}.source"), &e.source)?;
            // The form must hold on the test's path and find its parameters.
            e.closed_form
                .value(&materials[t.material.as_str()], &t.test(), &Default::default())
                .map_err(|x| {
                    let field = match x.field.strip_prefix("material") {
                        Some(rest) => format!("materials.{}{rest}", t.material),
                        None => format!("{key}.closed_form"),
                    };
                    chk.err(field, x.value, x.allowed)
                })?;
        }
        if let Some(q) = &self.expect_quadratic {
            chk.quadratic("expect_quadratic", q)?;
        }
        Ok(())
    }

    /// The material of test `t`, checked when the file was read.
    pub fn material(&self, t: &TestSection) -> crate::material::constitutive::Material {
        self.materials[&t.material].material()
    }
}
