//! A body that starts stressed (`initial_stress`, [`igimp::material::prestress`]) and a
//! traction on part of a face (`box` on a traction): every model holds a stress inside its
//! elastic domain to round-off and refuses one outside it; a prestressed block under the
//! surcharge that balances it stays at rest; a partial traction carries exactly its part of
//! the face to the supports (reference/README.md item 77).

use igimp::material::constitutive::Material;
use igimp::material::kinematics::left_cauchy_green_from_strain;
use igimp::material::prestress::prestressed;
use igimp::problems::scene::{self, SceneSettings};
use igimp::solver::newton::{NewtonSettings, ResidualNorm};
use nalgebra::Matrix3;

use crate::scene_text::scene;

/// One load step at h = 1/2, 2 points per cell, with `newton`.
fn one_step(newton: NewtonSettings) -> SceneSettings {
    SceneSettings {
        element_size: 0.5,
        points_per_cell: 2,
        load_steps: 1,
        newton,
        ghost: Default::default(),
        domain_update: Default::default(),
        linear_solver: Default::default(),
        f_bar: false,
        pressure_projection: false,
        gauss_points: None,
    }
}

fn friction(model: &str, cohesion: f64) -> Material {
    Material::new(
        model,
        &[
            ("young_modulus", 1e5),
            ("poisson_ratio", 0.3),
            ("cohesion", cohesion),
            ("friction_angle", 20.0),
            ("dilatancy_angle", 20.0),
            ("hardening_modulus", 0.0),
        ],
    )
    .unwrap()
}

fn cam_clay() -> Material {
    Material::new(
        "modified-cam-clay",
        &[
            ("shear_modulus", 2e3),
            ("swelling_index", 0.01),
            ("compression_index", 0.05),
            ("critical_state_slope", 1.0),
            ("reference_pressure", 1.0),
            ("preconsolidation_pressure", 3.0),
        ],
    )
    .unwrap()
}

/// A compressive, anisotropic stress with shear, inside every model's elastic domain below.
fn stress() -> Matrix3<f64> {
    Matrix3::new(-1.2, 0.1, 0.0, 0.1, -1.5, 0.0, 0.0, 0.0, -1.3)
}

/// Every built-in model's prestressed state gives back its stress: the update at the state's
/// elastic strain returns τ₀ to round-off (64 ε_mach E), the state is elastic (internal variables initial) and
/// b^e = exp(2 ε^e). Cam-Clay's pressure-dependent elasticity takes Newton more than one
/// iteration.
#[test]
fn every_model_holds_a_stress_inside_its_elastic_domain() {
    let materials = [
        Material::linear_elastic(1e5, 0.3),
        Material::new("neo-hookean", &[("young_modulus", 1e5), ("poisson_ratio", 0.3)]).unwrap(),
        Material::von_mises(1e5, 0.3, 10.0),
        friction("drucker-prager", 0.0),
        friction("mohr-coulomb", 0.0),
        cam_clay(),
    ];
    let tau0 = stress();
    for m in &materials {
        let model = m.build().unwrap();
        let s = prestressed(model.as_ref(), &tau0, 2.5).unwrap_or_else(|e| panic!("{}: {e}", m.model()));
        assert_eq!(s.volume, 2.5);
        assert_eq!(s.f, Matrix3::identity());
        let r = model.update(&s.material.eps_e, &s.material).unwrap();
        // The round-off of a stress of stiffness E: 64 ε_mach E (1.4e-9 here).
        let floor = (1e-12 * tau0.norm()).max(64.0 * f64::EPSILON * model.young_modulus());
        let miss = (r.tau - tau0).norm();
        assert!(miss <= floor, "{}: τ(ε^e) misses τ₀ by {miss:e}", m.model());
        assert!((s.tau - tau0).norm() <= floor, "{}", m.model());
        assert_eq!(r.internal, s.material.internal, "{}: not elastic", m.model());
        let b = left_cauchy_green_from_strain(&s.material.eps_e);
        assert!((b - s.material.b_e).norm() <= 1e-15, "{}", m.model());
    }
}

/// A stress the model would return from is refused with the reason, never held: von Mises
/// beyond its yield stress, cohesionless Mohr–Coulomb in tension, Cam-Clay outside its
/// ellipse (p beyond the preconsolidation pressure).
#[test]
fn a_stress_outside_the_elastic_domain_is_refused() {
    let cases = [
        (
            Material::von_mises(1e5, 0.3, 1.0),
            Matrix3::from_diagonal(&[-10.0, 0.0, 0.0].into()),
        ),
        (friction("mohr-coulomb", 0.0), Matrix3::identity()),
        (cam_clay(), Matrix3::identity() * -5.0),
    ];
    for (m, tau0) in cases {
        let model = m.build().unwrap();
        let e = prestressed(model.as_ref(), &tau0, 1.0).unwrap_err();
        assert!(
            e.0.contains("outside the model's elastic domain"),
            "{}: {e}",
            m.model()
        );
    }
    let model = Material::linear_elastic(1e5, 0.3).build().unwrap();
    let mut skew = stress();
    skew[(0, 1)] += 1.0;
    let e = prestressed(model.as_ref(), &skew, 1.0).unwrap_err();
    assert!(e.0.contains("symmetric"), "{e}");
}

/// The footing's surcharge in miniature: a block prestressed to −q₀ 1 with the surcharge q₀
/// on the top face beside a held footing, the surcharge at full value from the first step
/// (a table ramp from 1). It is in equilibrium as it stands: FEM's consistent nodal forces
/// leave a residual of round-off and the footing carries q₀ over its width; every method's
/// supports carry the whole surcharge. Without the initial stress the same loads compress
/// the block: the footing then carries nothing of it at the start.
#[test]
fn a_prestressed_block_under_its_surcharge_is_at_rest() {
    let q0 = 100.0;
    let text = |prestress: bool| {
        format!(
            r#"
grid = {{ origin = [0.0, 0.0], extent = [3.0, 3.0] }}
bodies = [{{ name = "soil", box = {{ min = [0.0, 0.0], max = [2.0, 2.0] }}, material = "m"{} }}]
supports = [
  {{ name = "symmetry", plane = {{ axis = "x", at = 0.0 }}, fix = ["x"] }},
  {{ name = "far", plane = {{ axis = "x", at = 2.0 }}, fix = ["x"] }},
  {{ name = "base", plane = {{ axis = "y", at = 0.0 }}, fix = ["x", "y"] }},
]
loads = [
  {{ kind = "traction", body = "soil", face = "y+", box = {{ min = [0.5, 2.0], max = [2.0, 2.0] }}, vector = [0.0, -{q0}], ramp = {{ table = [[0.0, 1.0], [1.0, 1.0]] }} }},
  {{ kind = "displacement", name = "footing", box = {{ min = [0.0, 2.0], max = [0.5, 2.0] }}, displacement = {{ y = 0.0 }} }},
]
measures = [
  {{ name = "footing", kind = "reaction", region = "footing", component = "y" }},
  {{ name = "base", kind = "reaction", region = "base", component = "y" }},
  {{ name = "top", kind = "displacement", at = [1.5, 2.0], component = "y" }},
]
"#,
            if prestress {
                format!(", initial_stress = {{ xx = -{q0}, yy = -{q0}, zz = -{q0} }}")
            } else {
                String::new()
            }
        )
    };
    let settings = one_step(NewtonSettings {
        tolerance: 1e-12,
        residual_norm: ResidualNorm::Total,
        ..Default::default()
    });
    // Elastic: the material point families' point loads sit a quarter cell below the face,
    // which a cohesionless soil at the surface would not hold.
    let material = Material::linear_elastic(1e5, 0.3);
    let held = scene(2, &text(true), material);
    for &method in scene::methods(2) {
        let o = scene::solve(&held, &settings, method).unwrap();
        assert!(o.failure.is_none(), "{method}: {:?}", o.failure);
        let (footing, base, top) = (o.measures[0].value, o.measures[1].value, o.measures[2].value);
        // The base and the footing carry the surcharge between them (q₀ over 1.5).
        assert!(
            (base + footing - 1.5 * q0).abs() <= 1e-9 * q0,
            "{method}: base {base}, footing {footing}"
        );
        if method.is_fem() {
            // The base carries the footing's share too: q₀ over the width 2.
            assert!((base - 2.0 * q0).abs() <= 1e-9 * q0, "{method}: base {base}");
            assert!(
                (footing + 0.5 * q0).abs() <= 1e-9 * q0,
                "{method}: footing {footing}"
            );
            assert!(top.abs() <= 1e-12, "{method}: the top moved {top:e}");
        }
    }
    // The check can fail: without the initial stress the soil starts unstressed, the
    // surcharge compresses it and the held footing carries only what the deformation sends it.
    let unheld = scene(2, &text(false), material);
    let fem = *scene::methods(2).iter().find(|m| m.is_fem()).unwrap();
    let o = scene::solve(&unheld, &settings, fem).unwrap();
    assert!(o.failure.is_none(), "{:?}", o.failure);
    assert!(o.measures[2].value < -1e-4, "top {}", o.measures[2].value);
    assert!(
        (o.measures[0].value + 0.5 * q0).abs() > 0.1 * q0,
        "footing {}",
        o.measures[0].value
    );
}

/// A traction on part of a face carries exactly that part's resultant: t times the covered
/// length, with the box's edges inside a cell and a point domain (clipped for points, and
/// over the clipped ξ interval for elements), for every family and element.
#[test]
fn a_partial_traction_carries_its_part_of_the_face() {
    let text = r#"
grid = { origin = [0.0, 0.0], extent = [3.0, 3.0] }
bodies = [{ name = "block", box = { min = [0.0, 0.0], max = [2.0, 2.0] }, material = "m" }]
supports = [
  { name = "left", plane = { axis = "x", at = 0.0 }, fix = ["x"] },
  { name = "base", plane = { axis = "y", at = 0.0 }, fix = ["y"] },
]
loads = [{ kind = "traction", body = "block", face = "y+", box = { min = [0.3, 1.0], max = [1.66, 2.5] }, vector = [0.0, -50.0] }]
measures = [{ name = "base", kind = "reaction", region = "base", component = "y" }]
"#;
    let s = scene(2, text, Material::linear_elastic(1e5, 0.3));
    let settings = one_step(NewtonSettings {
        tolerance: 1e-12,
        ..Default::default()
    });
    for &method in scene::methods(2) {
        let o = scene::solve(&s, &settings, method).unwrap();
        assert!(o.failure.is_none(), "{method}: {:?}", o.failure);
        let expected = 50.0 * (1.66 - 0.3);
        let base = o.measures[0].value;
        assert!(
            (base - expected).abs() <= 1e-9 * expected,
            "{method}: base {base} against {expected}"
        );
    }
}

/// Bad input names its key: a traction's box that misses its face, two tractions on two
/// ramps, out-of-plane shear in a plane-strain initial stress, bodies that start in two
/// stresses, and a stress the model cannot hold (at solve time, naming `initial_stress`).
#[test]
fn bad_initial_stresses_and_partial_tractions_are_refused_by_key() {
    let base = |bodies: &str, loads: &str| {
        format!(
            r#"
grid = {{ origin = [0.0, 0.0], extent = [4.0, 3.0] }}
bodies = [{bodies}]
supports = [{{ name = "base", plane = {{ axis = "y", at = 0.0 }}, fix = ["x", "y"] }}]
loads = [{loads}]
"#
        )
    };
    let block = r#"{ name = "a", box = { min = [0.0, 0.0], max = [2.0, 2.0] }, material = "m" }"#;
    let top = r#"{ kind = "traction", body = "a", face = "y+", vector = [0.0, -1.0] }"#;
    let parse = |t: &str| -> igimp::problems::scene::Scene {
        #[derive(serde::Deserialize)]
        struct Parts {
            grid: scene::GridSection,
            bodies: Vec<scene::Body>,
            supports: Vec<scene::Support>,
            loads: Vec<scene::Load>,
        }
        let p: Parts = toml::from_str(t).unwrap();
        scene::Scene {
            dimension: 2,
            grid: p.grid,
            materials: [("m".to_string(), Material::von_mises(1e5, 0.3, 1.0))]
                .into_iter()
                .collect(),
            bodies: p.bodies,
            supports: p.supports,
            loads: p.loads,
            measures: vec![],
            strength_reduction: None,
        }
    };
    let cases = [
        (
            base(
                block,
                r#"{ kind = "traction", body = "a", face = "y+", box = { min = [0.0, 1.0], max = [2.0, 1.5] }, vector = [0.0, -1.0] }"#,
            ),
            "loads[0].box",
        ),
        (
            base(
                block,
                &format!(
                    r#"{top}, {{ kind = "traction", body = "a", face = "x+", vector = [1.0, 0.0], ramp = {{ table = [[0.0, 1.0], [1.0, 1.0]] }} }}"#
                ),
            ),
            "loads[1].ramp",
        ),
        (
            base(
                r#"{ name = "a", box = { min = [0.0, 0.0], max = [2.0, 2.0] }, material = "m", initial_stress = { xx = -1.0, xz = 0.5 } }"#,
                top,
            ),
            "bodies[0].initial_stress.xz",
        ),
        (
            base(
                r#"{ name = "a", box = { min = [0.0, 0.0], max = [2.0, 2.0] }, material = "m", initial_stress = { xx = -1.0 } },
                   { name = "b", box = { min = [2.5, 0.0], max = [3.5, 2.0] }, material = "m" }"#,
                top,
            ),
            "bodies[1].initial_stress",
        ),
    ];
    for (text, key) in cases {
        let e = parse(&text).validate().unwrap_err();
        assert_eq!(e.field, key, "{e}");
    }
    // Valid as data, but von Mises of yield stress 1 cannot hold a deviator of 10.
    let s = parse(&base(
        r#"{ name = "a", box = { min = [0.0, 0.0], max = [2.0, 2.0] }, material = "m", initial_stress = { xx = -10.0 } }"#,
        top,
    ));
    s.validate().unwrap();
    let settings = one_step(Default::default());
    for &method in scene::methods(2) {
        let e = scene::solve(&s, &settings, method).unwrap_err();
        assert!(e.field.ends_with("initial_stress"), "{method}: {e}");
        assert!(e.to_string().contains("elastic domain"), "{method}: {e}");
    }
}

/// A level layer 3 deep under its own weight (ρ g = 20), starting in its geostatic stress
/// σ_yy = −20 d, σ_xx = σ_zz = K₀ σ_yy at depth d with K₀ = 0.5 (not the elastic ν/(1 − ν) =
/// 0.43: any K₀ is in equilibrium on level ground), gravity at full value from the first
/// step: FEM stays at rest to round-off, the base carries the weight, and the points' stress
/// is the initial one. Without the initial stress the same gravity settles the surface.
#[test]
fn a_layer_starting_in_its_geostatic_stress_stays_at_rest_under_its_weight() {
    let text = |initial: &str| {
        format!(
            r#"
grid = {{ origin = [0.0, 0.0], extent = [4.0, 4.0] }}
bodies = [{{ name = "soil", box = {{ min = [0.0, 0.0], max = [4.0, 3.0] }}, material = "m", density = 2.0{initial} }}]
supports = [
  {{ name = "left", plane = {{ axis = "x", at = 0.0 }}, fix = ["x"] }},
  {{ name = "right", plane = {{ axis = "x", at = 4.0 }}, fix = ["x"] }},
  {{ name = "base", plane = {{ axis = "y", at = 0.0 }}, fix = ["x", "y"] }},
]
loads = [{{ kind = "gravity", vector = [0.0, -10.0], ramp = {{ table = [[0.0, 1.0], [1.0, 1.0]] }} }}]
measures = [
  {{ name = "base", kind = "reaction", region = "base", component = "y" }},
  {{ name = "top", kind = "displacement", at = [2.0, 3.0], component = "y" }},
  {{ name = "sigma_yy", kind = "stress-line", at = [2.0, 0.3], to = [2.0, 2.7], samples = 5, component = "yy" }},
]
"#
        )
    };
    let geostatic =
        ", initial_stress = { per_depth = { surface = 3.0, yy = -20.0, xx = -10.0, zz = -10.0 } }";
    let settings = one_step(NewtonSettings {
        tolerance: 1e-12,
        residual_norm: ResidualNorm::Total,
        ..Default::default()
    });
    let weight = 20.0 * 4.0 * 3.0;
    for material in [Material::linear_elastic(1e4, 0.3), friction("mohr-coulomb", 5.0)] {
        let held = scene(2, &text(geostatic), material);
        for &method in scene::methods(2) {
            let o = scene::solve(&held, &settings, method).unwrap();
            assert!(o.failure.is_none(), "{method}: {:?}", o.failure);
            let (base, top) = (o.measures[0].value, o.measures[1].value);
            assert!(
                (base - weight).abs() <= 1e-9 * weight,
                "{method}: base {base} against {weight}"
            );
            // Each sample reads the integration point nearest to it, at most 0.15 deeper or
            // shallower (2 × 2 points or Gauss points in cells of 0.5): σ_yy = −20 d to 3.
            let samples = &o.measures[2].profile;
            for (k, s) in samples.iter().enumerate() {
                let d = 3.0 - (0.3 + 0.6 * k as f64);
                assert!((s + 20.0 * d).abs() <= 3.0, "{method}: σ_yy {s} at depth {d}");
            }
            if method.is_fem() {
                assert!(top.abs() <= 1e-12, "{method}: the surface moved {top:e}");
            } else {
                // The points' weight and stress divergence differ by O(h) at the surface cells.
                assert!(top.abs() <= 1e-4, "{method}: the surface moved {top:e}");
            }
        }
    }
    // The check can fail: unstressed, the same gravity settles the surface by about
    // ρ g H² / (2 E_oed) = 20 · 9 / (2 · 1.35e4) = 6.7e-3.
    let fem = *scene::methods(2).iter().find(|m| m.is_fem()).unwrap();
    let o = scene::solve(
        &scene(2, &text(""), Material::linear_elastic(1e4, 0.3)),
        &settings,
        fem,
    )
    .unwrap();
    assert!(o.measures[1].value < -1e-3, "top {}", o.measures[1].value);
}
