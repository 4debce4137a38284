//! A displacement bound to material points by a penalty (`on = "points"`,
//! [`igimp::discretise::point_penalty`], reference/README.md item 81): which points it binds,
//! its tangent against finite differences, Newton quadratic with it, its force in balance with
//! the supports, and the penalty's effect shrinking as its factor grows.

use igimp::basis::method::Method;
use igimp::basis::Basis;
use igimp::material::constitutive::Material;
use igimp::problems::scene::{self, DiscreteScene};

use crate::footing_scene::{footing, penalty_tangent_error, settings};

/// The bound points are the top row under the footing: their domains reach the footing's line
/// and lie within its width; the nodes are left free.
#[test]
fn the_bound_points_are_the_row_under_the_footing() {
    let s = footing(Material::linear_elastic(1e4, 0.3), -0.01, "");
    let d = DiscreteScene::of(&s, &settings(1, false)).unwrap();
    let r = d.regions.iter().find(|r| r.name == "footing").unwrap();
    assert!(r.nodes.is_empty());
    // h = 1/2, 2 points per cell: 4 points across x in [0, 1], at y = 2 − h/4.
    let mut xs: Vec<f64> = r.points.iter().map(|&p| d.points.position[p][0]).collect();
    xs.sort_by(f64::total_cmp);
    assert_eq!(xs, vec![0.125, 0.375, 0.625, 0.875]);
    for &p in &r.points {
        assert_eq!(d.points.position[p][1], 1.875);
    }
}

/// The footing's force is what the supports carry: the bound points' −Σ k e against the base's
/// reaction, to round-off, for every updated-Lagrangian family and TLMPM, plain and F-bar,
/// elastic and von Mises.
#[test]
fn the_footing_force_balances_the_base() {
    for material in [
        Material::linear_elastic(1e4, 0.3),
        Material::von_mises(1e4, 0.3, 3f64.sqrt()),
    ] {
        for basis in [Basis::Mpm, Basis::Gimp, Basis::Cpdi, Basis::Tlmpm] {
            for f_bar in [false, true] {
                let s = footing(material, -0.02, "");
                let o = scene::solve(&s, &settings(4, f_bar), Method::MaterialPoint(basis)).unwrap();
                assert!(o.failure.is_none(), "{basis:?} {f_bar}: {:?}", o.failure);
                let (f, base) = (o.measures[0].value, o.measures[1].value);
                println!(
                    "{:?} {basis:?} f_bar {f_bar}: footing {f:e} base {base:e}",
                    material.model()
                );
                assert!(f < 0.0, "{basis:?}: the soil must push the footing up: {f:e}");
                assert!((f + base).abs() <= 1e-8 * f.abs(), "{basis:?}: {f:e} + {base:e}");
            }
        }
    }
}

/// The step's tangent with the penalty against central differences of its residual, and
/// Newton quadratic with it (elastic: the penalty is the only new term).
#[test]
fn the_penalty_tangent_is_consistent_and_newton_quadratic() {
    for basis in [Basis::Mpm, Basis::Gimp, Basis::Cpdi, Basis::Tlmpm] {
        let err = penalty_tangent_error(basis);
        println!("{basis:?}: tangent FD error {err:e}");
        assert!(err < 1e-6, "{basis:?}: {err:e}");
        let s = footing(Material::linear_elastic(1e4, 0.3), -0.05, "");
        let o = scene::solve(&s, &settings(1, false), Method::MaterialPoint(basis)).unwrap();
        let r = &o.steps[0].newton.residuals;
        println!("{basis:?}: residuals {r:?}");
        // Quadratic: relative to the first residual, each at most C times the square of the
        // last (measured C ≈ 2e3 for MPM), until the round-off floor (1e-14).
        let rel: Vec<f64> = r.iter().map(|x| x / r[0]).collect();
        let ratios: Vec<f64> = rel
            .windows(2)
            .skip(1)
            .filter(|w| w[1] > 1e-14)
            .map(|w| w[1] / (w[0] * w[0]))
            .collect();
        assert!(r.len() <= 7, "{basis:?}: {r:?}");
        assert!(
            !ratios.is_empty() && ratios.iter().all(|&q| q < 1e5),
            "{basis:?}: {ratios:?}"
        );
    }
}

/// The penalty's compliance: the footing's force moves less with each tenfold β, about tenfold
/// less (an O(1/β) error).
#[test]
fn the_penalty_error_falls_as_its_factor_grows() {
    let force = |beta: f64| {
        let s = footing(
            Material::linear_elastic(1e4, 0.3),
            -0.01,
            &format!(", penalty = {beta:?}"),
        );
        let o = scene::solve(&s, &settings(1, false), Method::IGIMP).unwrap();
        o.measures[0].value
    };
    let f: Vec<f64> = [1e1, 1e2, 1e3, 1e4].into_iter().map(force).collect();
    let steps: Vec<f64> = f.windows(2).map(|w| (w[1] - w[0]).abs() / w[1].abs()).collect();
    println!("forces {f:?}, relative changes {steps:?}");
    for w in steps.windows(2) {
        assert!(w[1] < w[0] / 5.0 && w[1] > w[0] / 20.0, "{steps:?}");
    }
}

/// Bad input names its key: a penalty without points, a penalty ≤ 0, points on gravity.
#[test]
fn a_misplaced_binding_is_refused_by_key() {
    let base = footing(Material::linear_elastic(1e4, 0.3), -0.01, "");
    let mut s = base.clone();
    s.loads[0].on = scene::Bind::Nodes;
    s.loads[0].penalty = Some(10.0);
    let e = s.validate().unwrap_err();
    assert_eq!(e.field, "loads[0].penalty", "{e}");
    let mut s = base.clone();
    s.loads[0].penalty = Some(-1.0);
    assert_eq!(s.validate().unwrap_err().field, "loads[0].penalty");
    let mut s = base.clone();
    s.loads.push(scene::Load {
        kind: scene::LoadKind::Gravity,
        vector: Some(vec![0.0, -10.0]),
        on: scene::Bind::Points,
        ..base.loads[0].clone()
    });
    s.loads[1].name = None;
    s.loads[1].bounds = None;
    s.loads[1].displacement = None;
    let e = s.validate().unwrap_err();
    assert_eq!(e.field, "loads[1].on", "{e}");
}
