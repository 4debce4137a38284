//! The element-test kind (`problem = "element"`): the committed study passes every check, its
//! Newton check fails on a model whose tangent is not its update's derivative, and every
//! malformed file is refused with its key and line, never a panic.

use igimp::material::constitutive::registry::{register, Parameter, POISSON_RATIO, YOUNG_MODULUS};
use igimp::material::constitutive::{
    ConstitutiveModel, MaterialError, MaterialResponse, MaterialState, ModelEntry, VonMises,
};
use igimp::material::tensor::Tensor4;
use igimp::study::element::ElementStudy;
use igimp::study::engine::{run_in_memory, StudyKind};
use igimp::study::Tier;
use nalgebra::Matrix3;
use std::path::PathBuf;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

#[test]
fn the_element_tests_pass_every_check() {
    let study = ElementStudy::load(&root().join("studies/element-tests.toml")).unwrap();
    let run = run_in_memory(&study, "element-tests.toml", Tier::Quick).unwrap();
    assert!(run.results.checks.len() >= 7);
    for c in &run.results.checks {
        assert_eq!(
            c.pass,
            Some(true),
            "{}: {:?} against {}",
            c.id,
            c.measured,
            c.limit
        );
    }
}

/// von Mises with its elastic stiffness as the tangent: the update is right, the tangent is
/// not its derivative once the point yields.
struct ElasticTangent(VonMises);

impl ConstitutiveModel for ElasticTangent {
    fn update(&self, eps: &Matrix3<f64>, s: &MaterialState) -> Result<MaterialResponse, MaterialError> {
        self.0.update(eps, s)
    }
    fn tangent(&self, _eps: &Matrix3<f64>, _s: &MaterialState) -> Tensor4 {
        *igimp::material::constitutive::LinearElastic::try_new(self.0.young_modulus, self.0.poisson_ratio)
            .unwrap()
            .stiffness()
    }
    fn young_modulus(&self) -> f64 {
        self.0.young_modulus
    }
    fn internal_variables(&self) -> &'static [igimp::material::constitutive::InternalVariable] {
        self.0.internal_variables()
    }
}

static ELASTIC_TANGENT: ModelEntry = ModelEntry {
    name: "von-mises-with-elastic-tangent",
    summary: "von Mises whose tangent is the elastic stiffness (a deliberately inconsistent model)",
    parameters: &[
        YOUNG_MODULUS,
        POISSON_RATIO,
        Parameter {
            name: "yield_stress",
            unit: "Pa",
            meaning: "ρ_y",
        },
    ],
    build: |m| {
        Ok(Box::new(ElasticTangent(VonMises::try_new(
            m.value("young_modulus"),
            m.value("poisson_ratio"),
            m.value("yield_stress"),
        )?)))
    },
};

/// The same plane-strain biaxial test on von Mises with its consistent tangent passes the Newton
/// check; with the elastic stiffness as its tangent, Newton on the held lateral stresses
/// converges linearly once the point yields (the biaxial path, because
/// on it the deviator turns and the held stress is nonlinear in its strain; on the triaxial path
/// von Mises' return is linear in the lateral strain and one iteration solves it) and the check fails.
#[test]
fn the_newton_check_fails_on_an_inconsistent_tangent() {
    register(&ELASTIC_TANGENT).unwrap();
    let text = |model: &str| {
        format!(
            r#"schema = 1
name = "newton-order"
summary = "s"
problem = "element"
report_file = "report.md"

[materials.m]
model = "{model}"
young_modulus = 1.0e5
poisson_ratio = 0.3
yield_stress = 200.0

[[tests]]
id = "biaxial"
material = "m"
path = "plane-strain-biaxial"
confining = 100.0
strain = 0.02
steps = 20

[expect_quadratic]
small = 1e-2
floor = 1e-12
constant = 10.0
source = "s"
"#
        )
    };
    let outcome = |model: &str| {
        let study = ElementStudy::parse(&text(model), "newton.toml").unwrap();
        let run = run_in_memory(&study, "newton.toml", Tier::Quick).unwrap();
        let c = run
            .results
            .checks
            .iter()
            .find(|c| c.id == "newton-quadratic")
            .unwrap()
            .clone();
        eprintln!("{model}: {:?} {}", c.measured, c.description);
        c.pass
    };
    assert_eq!(outcome("von-mises"), Some(true));
    assert_eq!(outcome("von-mises-with-elastic-tangent"), Some(false));
}

fn example() -> String {
    std::fs::read_to_string(root().join("studies/element-tests.toml")).unwrap()
}

/// (what, text replaced, replacement, the key the error must name).
const MALFORMED: &[(&str, &str, &str, &str)] = &[
    ("wrong problem", "problem = \"element\"", "problem = \"scene\"", "problem"),
    ("unknown path", "path = \"oedometer\"", "path = \"triaxial\"", "path"),
    ("unknown material", "material = \"hencky\"", "material = \"steel\"", "tests[0].material"),
    ("negative strain", "strain = 0.3", "strain = -0.3", "tests[0].strain"),
    ("huge strain", "strain = 0.3", "strain = 50.0", "tests[0].strain"),
    ("no steps", "steps = 10", "steps = 0", "tests[0].steps"),
    ("negative confining", "confining = 100.0", "confining = -100.0", "tests[2].confining"),
    ("NaN confining", "confining = 100.0", "confining = nan", "tests[2].confining"),
    ("zero confining steps", "strain = 0.3", "strain = 0.3\nconfining_steps = 0", "tests[0].confining_steps"),
    ("loose tolerance", "strain = 0.3", "strain = 0.3\ntolerance = 0.5", "tests[0].tolerance"),
    ("duplicate id", "id = \"hencky-simple-shear\"", "id = \"hencky-oedometer\"", "tests[1].id"),
    ("unknown key", "strain = 0.3", "strain = 0.3\nstrian = 1.0", "strian"),
    ("closed form on another path", "closed_form = \"elastic-k0\"", "closed_form = \"hencky-simple-shear\"", "closed_form"),
    ("closed form lacking a parameter", "closed_form = \"von-mises-compression\"\ntolerance = 1e-10\nsource = \"perfect plasticity: q = √(3 J₂) = ρ_y on the yield surface (paper eqs 48–49)\"\n\n[[expect_closed_form]]\ntest = \"von-mises-undrained\"", "closed_form = \"mohr-coulomb-compression\"\ntolerance = 1e-10\nsource = \"perfect plasticity: q = √(3 J₂) = ρ_y on the yield surface (paper eqs 48–49)\"\n\n[[expect_closed_form]]\ntest = \"von-mises-undrained\"", "materials.von-mises.cohesion"),
    ("unknown closed form", "closed_form = \"elastic-k0\"", "closed_form = \"k0\"", "closed_form"),
    ("closed form of no test", "test = \"hencky-oedometer\"", "test = \"oedometer\"", "expect_closed_form[0].test"),
    ("zero tolerance", "tolerance = 1e-12", "tolerance = 0.0", "expect_closed_form[0].tolerance"),
    ("bad material value", "poisson_ratio = 0.3\n\n[materials.von-mises]", "poisson_ratio = 0.6\n\n[materials.von-mises]", "materials.hencky.poisson_ratio"),
    ("negative Newton constant", "constant = 10.0", "constant = -1.0", "expect_quadratic.constant"),
    ("no tests", "[[tests]]\nid = \"hencky-oedometer\"", "[[nottests]]\nid = \"hencky-oedometer\"", "nottests"),
];

#[test]
fn every_malformed_element_study_is_refused_with_its_key_and_line() {
    let valid = example();
    ElementStudy::parse(&valid, "element.toml").expect("the committed study is valid");
    let mut wrong = vec![];
    for (what, from, to, key) in MALFORMED {
        assert!(valid.contains(from), "{what}: the study has no {from:?}");
        let text = valid.replacen(from, to, 1);
        let outcome = std::panic::catch_unwind(|| ElementStudy::parse(&text, "element.toml"));
        let message = match outcome {
            Err(_) => {
                wrong.push(format!("{what}: panicked"));
                continue;
            }
            Ok(Ok(_)) => {
                wrong.push(format!("{what}: accepted"));
                continue;
            }
            Ok(Err(e)) => e.to_string(),
        };
        if !message.contains(key) {
            wrong.push(format!("{what}: the error does not name {key:?}: {message}"));
        }
        let has_line = message.contains("element.toml:") || message.contains("at line ");
        if !has_line {
            wrong.push(format!("{what}: the error gives no line: {message}"));
        }
    }
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
}
