//! Newton on the strip footing of Mohr–Coulomb soil (`studies/footing-friction*.toml`) is
//! checked for its quadratic rate at h = B/4; the same check fails when the model's tangent is
//! off its update's derivative by a hundredth of the way to the elastic stiffness.

use igimp::material::constitutive::registry::{register, Parameter, POISSON_RATIO, YOUNG_MODULUS};
use igimp::material::constitutive::{
    ConstitutiveModel, LinearElastic, MaterialError, MaterialResponse, MaterialState, ModelEntry, MohrCoulomb,
};
use igimp::material::tensor::Tensor4;
use igimp::study::engine::{run_in_memory, StudyKind};
use igimp::study::scene::SceneStudy;
use igimp::study::Tier;
use nalgebra::Matrix3;
use std::path::PathBuf;

/// Mohr–Coulomb whose tangent is D^alg + (D^e − D^alg)/100: right where the point is elastic,
/// off by a hundredth of the plastic softening where it yields.
struct BlendedTangent(MohrCoulomb, Tensor4);

impl ConstitutiveModel for BlendedTangent {
    fn update(&self, eps: &Matrix3<f64>, s: &MaterialState) -> Result<MaterialResponse, MaterialError> {
        self.0.update(eps, s)
    }
    fn tangent(&self, eps: &Matrix3<f64>, s: &MaterialState) -> Tensor4 {
        let d = self.0.tangent(eps, s);
        d + (self.1 - d) * 0.01
    }
    fn tangent_reads_strain(&self) -> bool {
        self.0.tangent_reads_strain()
    }
    fn tangent_is_symmetric(&self) -> bool {
        self.0.tangent_is_symmetric()
    }
    fn young_modulus(&self) -> f64 {
        self.0.young_modulus()
    }
    fn internal_variables(&self) -> &'static [igimp::material::constitutive::InternalVariable] {
        self.0.internal_variables()
    }
}

const fn parameter(name: &'static str, unit: &'static str, meaning: &'static str) -> Parameter {
    Parameter { name, unit, meaning }
}

static BLENDED: ModelEntry = ModelEntry {
    name: "mohr-coulomb-with-blended-tangent",
    summary: "Mohr–Coulomb whose tangent is a hundredth of the way to the elastic stiffness (deliberately inconsistent)",
    parameters: &[
        YOUNG_MODULUS,
        POISSON_RATIO,
        parameter("cohesion", "Pa", "c₀"),
        parameter("friction_angle", "deg", "φ"),
        parameter("dilatancy_angle", "deg", "ψ"),
        parameter("hardening_modulus", "Pa", "H"),
    ],
    build: |m| {
        let (e, nu) = (m.value("young_modulus"), m.value("poisson_ratio"));
        Ok(Box::new(BlendedTangent(
            MohrCoulomb::try_new(
                e,
                nu,
                m.value("cohesion"),
                m.value("friction_angle"),
                m.value("dilatancy_angle"),
                m.value("hardening_modulus"),
            )?,
            *LinearElastic::try_new(e, nu)?.stiffness(),
        )))
    },
};

/// The Newton check of `name`'s quick tier with the soil's model `model`: (pass, measured).
fn newton_check(name: &str, model: &str) -> (Option<bool>, Option<f64>) {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(root.join(format!("studies/{name}.toml"))).unwrap();
    assert_eq!(text.matches("model = \"mohr-coulomb\"").count(), 1);
    let text = text.replace("model = \"mohr-coulomb\"", &format!("model = \"{model}\""));
    let study = SceneStudy::parse(&text, "footing.toml").unwrap();
    let run = run_in_memory(&study, "footing.toml", Tier::Quick).unwrap();
    let c = run
        .results
        .checks
        .iter()
        .find(|c| c.id == "q8-coarse-newton-quadratic")
        .expect("the study checks Newton's rate")
        .clone();
    for case in &run.results.cases {
        eprintln!(
            "{name}, {model}: {} {:?} {:?}",
            case.id, case.solve.status, case.solve.failure
        );
    }
    eprintln!("{name}, {model}: {:?} {}", c.measured, c.description);
    (c.pass, c.measured)
}

#[test]
fn newton_on_the_footing_is_quadratic_and_the_check_fails_on_an_inconsistent_tangent() {
    register(&BLENDED).unwrap();
    for name in ["footing-friction", "footing-friction-30"] {
        assert_eq!(newton_check(name, "mohr-coulomb").0, Some(true), "{name}");
        assert_eq!(
            newton_check(name, "mohr-coulomb-with-blended-tangent").0,
            Some(false),
            "{name}"
        );
    }
}
