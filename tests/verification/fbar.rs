//! F-bar (reference/README.md item 69): the assembled tangent against central differences of
//! the residual for every material point family and Q4/Q8/Hex8, elastic and von Mises, 2D and
//! 3D; quadratic Newton; a patch of one point is the plain method to the bit; a homogeneous
//! deformation is unchanged by the averaging.

use igimp::basis::Basis;
use igimp::material::constitutive::Material;
use igimp::problems::compaction::CompactionSpec;
use igimp::solver::load_stepping::LoadStepping;

/// The compaction block (h = 1, 2×2 points per cell, 10 load steps) in `material`.
fn block(material: Material, dimension: usize) -> CompactionSpec {
    CompactionSpec {
        material,
        load_steps: 10,
        dimension,
        f_bar: true,
        ..Default::default()
    }
}

/// von Mises with σ_y = 2.5e4: half the base's 5e4 vertical stress at full load, so that the
/// lower block yields past half of it, and the block stands.
fn von_mises() -> Material {
    Material::von_mises(1e5, 0.3, YIELD)
}

const YIELD: f64 = 2.5e4;

/// max |K − K_fd| / max |K| of an F-bar solver after `steps` of its steps, at a random
/// increment of scale `scale` on the next one (and the fraction of points yielding there).
fn mpm_error<const D: usize>(
    solver: &mut igimp::mpm::MpmSolver<D>,
    steps: usize,
    scale: f64,
) -> (f64, usize) {
    for _ in 0..steps {
        solver.step().unwrap();
    }
    let next = (steps + 1) as f64 / solver.load_steps() as f64;
    let (err, _, rho) = solver
        .with_step_system(next, |sys| crate::common::fd_tangent_errors(sys, scale, 5))
        .unwrap();
    (err, rho.iter().filter(|&&r| r > (1.0 - 1e-6) * YIELD).count())
}

/// Every family in 2D, elastic and von Mises (yielding points counted, so the plastic branch
/// is exercised), within 1e-6.
#[test]
fn fbar_tangent_matches_central_differences_for_every_family_2d() {
    for basis in Basis::ALL {
        for (name, material) in [
            ("elastic", Material::linear_elastic(1e5, 0.3)),
            ("von Mises", von_mises()),
        ] {
            let spec = CompactionSpec {
                basis,
                ..block(material, 2)
            };
            let mut solver = spec.mpm_solver().unwrap();
            let (err, yielding) = mpm_error(&mut solver, 9, 2e-3);
            eprintln!("2D {basis:?} {name}: {err:.2e} ({yielding} points past yield)");
            assert!(err < 1e-6, "2D {basis:?} {name}: tangent error {err:e}");
            if name == "von Mises" {
                assert!(yielding > 0, "2D {basis:?}: no point yields");
            }
        }
    }
}

/// Every family in 3D (the quarter block, h = 2 over 4 × 4 × 8: few equations), elastic and
/// von Mises, within 1e-6.
#[test]
fn fbar_tangent_matches_central_differences_for_every_family_3d() {
    for basis in Basis::ALL {
        for (name, material) in [
            ("elastic", Material::linear_elastic(1e5, 0.3)),
            ("von Mises", von_mises()),
        ] {
            let spec = CompactionSpec {
                element_size: 2.0,
                basis,
                ..block(material, 3)
            };
            let mut solver = spec.mpm_solver_3d().unwrap();
            let (err, yielding) = mpm_error(&mut solver, 9, 2e-3);
            eprintln!("3D {basis:?} {name}: {err:.2e} ({yielding} points past yield)");
            assert!(err < 1e-6, "3D {basis:?} {name}: tangent error {err:e}");
        }
    }
}

/// Q4, Q8 and Hex8 with F-bar over each element, elastic and von Mises, within 1e-6.
#[test]
fn fbar_tangent_matches_central_differences_for_elements() {
    use igimp::fem::{HexElement, QuadElement};
    for (name, material) in [
        ("elastic", Material::linear_elastic(1e5, 0.3)),
        ("von Mises", von_mises()),
    ] {
        for element in [QuadElement::Q4, QuadElement::Q8] {
            let (mut fem, _) = igimp::problems::compaction::fem_solver(&block(material, 2), element).unwrap();
            for _ in 0..9 {
                fem.step().unwrap();
            }
            let (err, _, _) = fem
                .with_step_system(1.0, |sys| crate::common::fd_tangent_errors(sys, 2e-3, 7))
                .unwrap();
            eprintln!("{element:?} {name}: {err:.2e}");
            assert!(err < 1e-6, "{element:?} {name}: tangent error {err:e}");
        }
        let spec = CompactionSpec {
            element_size: 2.0,
            ..block(material, 3)
        };
        let (mut fem, _) = igimp::problems::compaction::fem_solver_3d(&spec, HexElement::Hex8).unwrap();
        for _ in 0..9 {
            fem.step().unwrap();
        }
        let (err, _, _) = fem
            .with_step_system(1.0, |sys| crate::common::fd_tangent_errors(sys, 2e-3, 7))
            .unwrap();
        eprintln!("Hex8 {name}: {err:.2e}");
        assert!(err < 1e-6, "Hex8 {name}: tangent error {err:e}");
    }
}

/// The yielding block by iGIMP, CPDI and Q4 with F-bar: every step converges quadratically
/// (the ratio test of `check_quadratic`).
#[test]
fn newton_is_quadratic_with_fbar() {
    use igimp::basis::method::Method;
    use igimp::problems::compaction::solve;
    use igimp::solver::newton::check_quadratic;
    for method in [Method::IGIMP, Method::CPDI, Method::FEM_Q4] {
        let spec = block(von_mises(), 2);
        let o = solve(&spec, method).unwrap();
        assert!(o.failure.is_none(), "{method}: {:?}", o.failure);
        let mut ratios = 0;
        for s in &o.steps {
            let c = check_quadratic(&s.newton.residuals, 1e-3, 1e-10, 10.0, 1.8)
                .unwrap_or_else(|e| panic!("{method}, step {}: {e}", s.step));
            ratios += c.ratio_checks;
        }
        assert!(ratios >= 5, "{method}: {ratios} quadratic ratios checked");
    }
}

/// With one point per cell, and a load (1 % of the compaction's) too small for a point to
/// leave its cell, every patch is one point and F-bar is the plain method to the bit.
#[test]
fn fbar_reduces_to_the_plain_method_where_it_has_nothing_to_average() {
    use igimp::basis::method::Method;
    use igimp::problems::compaction::solve;
    let one = CompactionSpec {
        points_per_cell: 1,
        weight: 4e3,
        ..block(Material::linear_elastic(1e5, 0.3), 2)
    };
    for method in [Method::MPM, Method::IGIMP] {
        let fbar = solve(&one, method).unwrap();
        let plain = solve(&CompactionSpec { f_bar: false, ..one }, method).unwrap();
        assert_eq!(
            plain.max_horizontal_displacement.to_bits(),
            fbar.max_horizontal_displacement.to_bits(),
            "{method}: one point per cell"
        );
    }
}

/// A small strip footing (the scene of `studies/footing.toml` on a 2 × 1.5 block, h = 1/4):
/// the F-bar tangent of every family against central differences of the residual at a random
/// increment of the first step, where the footing's prescribed settlement drives the points
/// under it past yield.
#[test]
fn fbar_tangent_matches_central_differences_under_a_footing() {
    use igimp::problems::scene::{DiscreteScene, SceneSettings};
    let scene = footing_scene();
    for basis in Basis::ALL {
        let settings = SceneSettings {
            element_size: 0.25,
            points_per_cell: 2,
            load_steps: 10,
            newton: Default::default(),
            ghost: Default::default(),
            domain_update: Default::default(),
            linear_solver: Default::default(),
            f_bar: true,
            pressure_projection: false,
            gauss_points: None,
        };
        let discrete = DiscreteScene::of(&scene, &settings).unwrap();
        let mut solver = discrete.solver::<2>(basis, &settings).unwrap();
        let (err, _, rho) = solver
            .with_step_system(0.1, |sys| crate::common::fd_tangent_errors(sys, 2e-3, 3))
            .unwrap();
        let yielding = rho.iter().filter(|&&r| r > (1.0 - 1e-6) * 3f64.sqrt()).count();
        eprintln!("footing {basis:?}: {err:.2e} ({yielding} points past yield)");
        assert!(err < 1e-6, "footing {basis:?}: tangent error {err:e}");
    }
}

/// The strip footing on a 2 × 1.5 block of von Mises soil (c = 1, E = 1e4, ν = 0.49), half
/// of a 1-wide footing settling by 0.02.
fn footing_scene() -> igimp::problems::scene::Scene {
    crate::scene_text::scene(
        2,
        r#"
grid = { origin = [0.0, 0.0], extent = [2.0, 2.0] }
bodies = [{ name = "soil", box = { min = [0.0, 0.0], max = [2.0, 1.5] }, material = "m" }]
supports = [
  { name = "symmetry", plane = { axis = "x", at = 0.0 }, fix = ["x"] },
  { name = "far", plane = { axis = "x", at = 2.0 }, fix = ["x"] },
  { name = "base", plane = { axis = "y", at = 0.0 }, fix = ["x", "y"] },
]
loads = [{ kind = "displacement", name = "footing", box = { min = [0.0, 1.5], max = [0.5, 1.5] }, displacement = { y = -0.02 } }]
"#,
        Material::von_mises(1e4, 0.49, 3f64.sqrt()),
    )
}

/// A friction model (`drucker-prager` or `mohr-coulomb`) with φ = 30°, dilatancy `psi` and
/// c = 50, so that 1 % of the block's load yields points.
fn friction(model: &str, psi: f64) -> Material {
    Material::new(
        model,
        &[
            ("young_modulus", 1e5),
            ("poisson_ratio", 0.3),
            ("cohesion", 50.0),
            ("friction_angle", 30.0),
            ("dilatancy_angle", psi),
            ("hardening_modulus", 0.0),
        ],
    )
    .unwrap()
}

/// The FD error, and the points whose update moved their plastic variable (all start at 0 in
/// the first step) at the last increment the check evaluated.
fn checked<const D: usize>(sys: &mut igimp::discretise::assembly::LoadStepSystem<'_, D>) -> (f64, usize) {
    let (err, _, _) = crate::common::fd_tangent_errors(sys, 2e-3, 11);
    let plastic = sys
        .trials
        .iter()
        .filter(|t| t.as_ref().is_some_and(|t| t.response.internal.get(0) != 0.0))
        .count();
    (err, plastic)
}

/// The pressure-dependent models under F-bar: the compaction block (h = 1, iGIMP and TLMPM,
/// and Q4) at 1 % of its load and a random increment, in Drucker–Prager and Mohr–Coulomb
/// (φ = 30°, associated and ψ = 5°, c = 50, so that the increment yields points) and modified
/// Cam-Clay (normally consolidated: compressed points yield; its initial stress −p₀ 1 out
/// of balance, which a tangent check does not need), within 1e-6, with points yielding.
#[test]
fn fbar_tangent_matches_central_differences_for_the_geomaterials() {
    use igimp::fem::QuadElement;
    let cam_clay = Material::new(
        "modified-cam-clay",
        &[
            ("shear_modulus", 3e4),
            ("swelling_index", 0.02),
            ("compression_index", 0.1),
            ("critical_state_slope", 1.2),
            ("reference_pressure", 1e4),
            ("preconsolidation_pressure", 1e4),
        ],
    )
    .unwrap();
    for (name, material) in [
        ("Drucker–Prager", friction("drucker-prager", 30.0)),
        ("Drucker–Prager ψ = 5°", friction("drucker-prager", 5.0)),
        ("Mohr–Coulomb", friction("mohr-coulomb", 30.0)),
        ("Mohr–Coulomb ψ = 5°", friction("mohr-coulomb", 5.0)),
        ("Cam-Clay", cam_clay),
    ] {
        for basis in [Basis::Gimp, Basis::Tlmpm] {
            let spec = CompactionSpec {
                basis,
                ..block(material, 2)
            };
            let mut solver = spec.mpm_solver().unwrap();
            let (err, plastic) = solver.with_step_system(0.01, checked).unwrap();
            eprintln!("{basis:?} {name}: {err:.2e} ({plastic} points yielding)");
            assert!(err < 1e-6, "{basis:?} {name}: tangent error {err:e}");
            assert!(plastic > 0, "{basis:?} {name}: no point yields");
        }
        let (mut fem, _) =
            igimp::problems::compaction::fem_solver(&block(material, 2), QuadElement::Q4).unwrap();
        let (err, plastic) = fem.with_step_system(0.01, checked).unwrap();
        eprintln!("Q4 {name}: {err:.2e} ({plastic} Gauss points yielding)");
        assert!(err < 1e-6, "Q4 {name}: tangent error {err:e}");
        assert!(plastic > 0, "Q4 {name}: no point yields");
    }
}

/// F-bar with the pressure projection (reference/README.md item 75) under the dilatant models:
/// the compaction block as above, within 1e-6, with points yielding; and von Mises, whose
/// points have no plastic dilation, where the projection still moves the pressure (the points
/// of a cell differ in their elastic volume only by round-off there, so the check is the same).
#[test]
fn fbar_with_pressure_projection_matches_central_differences() {
    use igimp::fem::QuadElement;
    for (name, material) in [
        ("von Mises", von_mises()),
        ("Drucker–Prager", friction("drucker-prager", 30.0)),
        ("Mohr–Coulomb", friction("mohr-coulomb", 30.0)),
        ("Mohr–Coulomb ψ = 5°", friction("mohr-coulomb", 5.0)),
    ] {
        for basis in [Basis::Mpm, Basis::Gimp, Basis::Tlmpm] {
            let spec = CompactionSpec {
                basis,
                ..block(material, 2)
            };
            let mut solver = spec.mpm_solver().unwrap();
            solver.set_pressure_projection(true);
            let (err, plastic) = solver.with_step_system(0.01, checked).unwrap();
            eprintln!("projected {basis:?} {name}: {err:.2e} ({plastic} points yielding)");
            assert!(err < 1e-6, "projected {basis:?} {name}: tangent error {err:e}");
        }
        let (mut fem, _) =
            igimp::problems::compaction::fem_solver(&block(material, 2), QuadElement::Q4).unwrap();
        fem.set_pressure_projection(true);
        let (err, plastic) = fem.with_step_system(0.01, checked).unwrap();
        eprintln!("projected Q4 {name}: {err:.2e} ({plastic} Gauss points yielding)");
        assert!(err < 1e-6, "projected Q4 {name}: tangent error {err:e}");
    }
}
