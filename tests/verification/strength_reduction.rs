//! Strength reduction (src/material/strength_reduction.rs, src/problems/scene/strength.rs):
//! what a factor divides, what the input refuses, and how a run's end becomes its factor of
//! safety. The slope it is run on, against Bishop's 1.380, is the study
//! `slope-strength-reduction` (its checks run in CI; its seeded bug in tests/seeded.rs).

use igimp::material::constitutive::Material;
use igimp::material::strength_reduction::{reduced, StrengthReduction};
use igimp::problems::scene::{Scene, StrengthReductionSection};
use igimp::solver::error::{SolveError, StepFailure};
use igimp::solver::ramp::Ramp;

fn mohr_coulomb() -> Material {
    Material::new(
        "mohr-coulomb",
        &[
            ("young_modulus", 1e5),
            ("poisson_ratio", 0.3),
            ("cohesion", 10.0),
            ("friction_angle", 20.0),
            ("dilatancy_angle", 10.0),
            ("hardening_modulus", 5.0),
        ],
    )
    .unwrap()
}

#[test]
fn a_factor_divides_the_cohesion_and_the_tangents_of_the_angles() {
    let m = reduced(&mohr_coulomb(), 2.0);
    let tan = |deg: f64| deg.to_radians().tan();
    assert_eq!(m.get("cohesion"), Some(5.0));
    approx::assert_relative_eq!(
        tan(m.get("friction_angle").unwrap()),
        tan(20.0) / 2.0,
        max_relative = 1e-14
    );
    approx::assert_relative_eq!(
        tan(m.get("dilatancy_angle").unwrap()),
        tan(10.0) / 2.0,
        max_relative = 1e-14
    );
    // Elasticity and hardening set how the body deforms, not what it carries: kept.
    for k in ["young_modulus", "poisson_ratio", "hardening_modulus"] {
        assert_eq!(m.get(k), mohr_coulomb().get(k), "{k}");
    }
    let vm = reduced(&Material::von_mises(1e4, 0.3, 3.0), 1.5);
    assert_eq!(vm.get("yield_stress"), Some(2.0));
    // A factor of 1 is the material itself.
    let same = reduced(&mohr_coulomb(), 1.0);
    for (k, v) in mohr_coulomb().parameters() {
        approx::assert_relative_eq!(same.get(k).unwrap(), v, max_relative = 1e-15);
    }
}

#[test]
fn a_reduction_refuses_a_linear_ramp_a_factor_not_above_zero_and_a_model_without_strength() {
    let table = |rows: &[[f64; 2]]| Ramp::Table(rows.to_vec());
    let e = StrengthReduction::new("strength_reduction.ramp", mohr_coulomb(), Ramp::Linear).unwrap_err();
    assert!(e.to_string().contains("strength_reduction.ramp"), "{e}");
    let e = StrengthReduction::new(
        "strength_reduction.ramp",
        mohr_coulomb(),
        table(&[[0.0, 1.0], [0.5, 0.0], [1.0, 2.0]]),
    )
    .unwrap_err();
    assert!(e.to_string().contains("strength_reduction.ramp[1][1]"), "{e}");
    let e = StrengthReduction::new(
        "strength_reduction.ramp",
        Material::linear_elastic(1e4, 0.3),
        table(&[[0.0, 1.0], [1.0, 2.0]]),
    )
    .unwrap_err();
    assert!(e.to_string().contains("strength"), "{e}");
    let r =
        StrengthReduction::new("k", mohr_coulomb(), table(&[[0.0, 1.0], [0.2, 1.0], [1.0, 1.8]])).unwrap();
    approx::assert_relative_eq!(r.factor(0.6), 1.4, max_relative = 1e-14);
}

/// A 10 × 10 block under gravity, F rising from 1 at λ = 0.2 to 2 at λ = 1, measured by
/// `measures`.
fn block(measures: &str) -> Scene {
    let mut s = crate::scene_text::scene(
        2,
        r#"
grid = { origin = [0.0, 0.0], extent = [12.0, 12.0] }
bodies = [{ name = "soil", box = { min = [0.0, 0.0], max = [10.0, 10.0] }, material = "m" }]
supports = [{ name = "base", plane = { axis = "y", at = 0.0 }, fix = ["x", "y"] }]
loads = [{ kind = "gravity", vector = [0.0, -10.0], ramp = { table = [[0.0, 0.0], [0.2, 1.0], [1.0, 1.0]] } }]
"#,
        mohr_coulomb(),
    );
    s.strength_reduction = Some(StrengthReductionSection {
        ramp: Ramp::Table(vec![[0.0, 1.0], [0.2, 1.0], [1.0, 2.0]]),
    });
    s.measures =
        toml::from_str::<std::collections::BTreeMap<String, Vec<igimp::problems::scene::Measure>>>(measures)
            .unwrap()
            .remove("measures")
            .unwrap_or_default();
    s
}

fn failed_at(load_factor: f64, reached: f64) -> SolveError {
    SolveError {
        step: 1,
        failure: StepFailure::NotConverged {
            iterations: 40,
            last: 1e-3,
        },
        residuals: vec![],
        attempts: 7,
        load_factor,
        reached,
    }
}

#[test]
fn a_run_collapses_only_where_the_factor_rises_and_its_factor_of_safety_is_the_last_converged_one() {
    let s = block("");
    s.validate().unwrap();
    // A failure while gravity comes on (F = 1) is a failure, not a factor of safety.
    let early = failed_at(0.1, 0.05);
    assert!(!s.collapsed(Some(&early)));
    assert!(s.factor_of_safety(Some(&early), None, 10).is_nan());
    // Past λ = 0.2 it is the collapse: F at the last committed state, not the failed attempt's.
    let late = failed_at(0.61, 0.6);
    assert!(s.collapsed(Some(&late)));
    approx::assert_relative_eq!(
        s.factor_of_safety(Some(&late), None, 10),
        1.5,
        max_relative = 1e-14
    );
    // A body that stood at every F has no factor of safety.
    assert!(!s.collapsed(None));
    assert!(s.factor_of_safety(None, None, 10).is_nan());
}

#[test]
fn a_displacement_limit_fails_the_body_where_it_is_first_reached_between_two_steps() {
    let s = block("");
    // 10 steps: F = 1 at steps 1 and 2 (λ ≤ 0.2), then 1.125, 1.25, … The displacement after
    // step 2 (−0.1, the body under its weight) is the one the limit is measured from.
    let moved = [-0.05, -0.1, -0.11, -0.13, -0.2, -0.5, -1.0];
    // 0.08 beyond −0.1 is passed between step 4 (0.03) and step 5 (0.1): 5/7 of the way.
    let f = s.factor_of_safety(None, Some((0.08, &moved)), 10);
    approx::assert_relative_eq!(f, 1.25 + (0.05 / 0.07) * 0.125, max_relative = 1e-14);
    // Reached at the first step past the reduction's start: interpolated from F = 1 and 0.
    let f = s.factor_of_safety(None, Some((0.005, &moved)), 10);
    approx::assert_relative_eq!(f, 1.0 + 0.5 * 0.125, max_relative = 1e-14);
    // Not reached before the collapse: the collapse's F.
    let late = failed_at(0.71, 0.7);
    let f = s.factor_of_safety(Some(&late), Some((5.0, &moved)), 10);
    approx::assert_relative_eq!(f, 1.625, max_relative = 1e-14);
    // Not reached and no collapse: none.
    assert!(s.factor_of_safety(None, Some((5.0, &moved)), 10).is_nan());
}

#[test]
fn a_factor_of_safety_measure_needs_a_reduction_and_a_limit_needs_its_point() {
    let mut s = block(
        r#"measures = [{ name = "fos", kind = "factor-of-safety", at = [5.0, 10.0], component = "y", limit = 0.05 }]"#,
    );
    s.validate().unwrap();
    let bad = |text: &str| -> String {
        let mut s = block(text);
        if text.contains("no-reduction") {
            s.strength_reduction = None;
        }
        s.validate().unwrap_err().to_string()
    };
    let e = bad(r#"measures = [{ name = "no-reduction", kind = "factor-of-safety" }]"#);
    assert!(
        e.contains("measures[0].kind") && e.contains("strength_reduction"),
        "{e}"
    );
    let e = bad(r#"measures = [{ name = "fos", kind = "factor-of-safety", limit = 0.05 }]"#);
    assert!(e.contains("measures[0].at"), "{e}");
    let e = bad(
        r#"measures = [{ name = "fos", kind = "factor-of-safety", at = [5.0, 10.0], component = "y", limit = -1.0 }]"#,
    );
    assert!(e.contains("measures[0].limit"), "{e}");
    let e = bad(
        r#"measures = [{ name = "d", kind = "displacement", at = [5.0, 10.0], component = "y", limit = 0.05 }]"#,
    );
    assert!(e.contains("measures[0].limit"), "{e}");
    let e = bad(r#"measures = [{ name = "fos", kind = "factor-of-safety", scale = 2.0 }]"#);
    assert!(e.contains("measures[0].scale"), "{e}");
    s.strength_reduction = Some(StrengthReductionSection { ramp: Ramp::Linear });
    let e = s.validate().unwrap_err().to_string();
    assert!(e.contains("strength_reduction.ramp"), "{e}");
}
