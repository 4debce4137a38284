//! Implicit dynamics ([`igimp::dynamics`]): the effective tangent K + M/(βΔt²) against central
//! differences, Newmark's second order in time on the vibrating bar, its period against 4L/c,
//! its energy, and quadratic Newton with the effective tangent.

use igimp::assembly::LoadStepSystem;
use igimp::basis::Basis;
use igimp::dynamics::{MassMatrix, Newmark};
use igimp::load_stepping::LoadStepping;
use igimp::method::Method;
use igimp::mpm::MpmSolver;
use igimp::newton::{check_quadratic, NonlinearSystem};
use igimp::problems::bar::{self, BarSpec};

/// max |K − K_fd| / max |K| of a step's system at a deterministic increment of size `scale`.
pub fn fd_error<const D: usize>(sys: &mut LoadStepSystem<'_, D>, scale: f64) -> f64 {
    let n = sys.num_unknowns();
    let u0: Vec<f64> = (0..n)
        .map(|i| scale * ((i * 7919 % 101) as f64 / 50.0 - 1.0))
        .collect();
    let mut r = vec![0.0; n];
    sys.evaluate(&u0, &mut r).unwrap();
    sys.assemble_tangent();
    let k: Vec<Vec<f64>> = (0..n)
        .map(|i| (0..n).map(|j| sys.matrix.get(i, j)).collect())
        .collect();
    let h = 1e-6 * scale;
    let (mut rp, mut rm) = (vec![0.0; n], vec![0.0; n]);
    let (mut err, mut kmax) = (0.0f64, 0.0f64);
    for j in 0..n {
        let mut u = u0.clone();
        u[j] += h;
        sys.evaluate(&u, &mut rp).unwrap();
        u[j] -= 2.0 * h;
        sys.evaluate(&u, &mut rm).unwrap();
        for i in 0..n {
            err = err.max(((rp[i] - rm[i]) / (2.0 * h) - k[i][j]).abs());
            kmax = kmax.max(k[i][j].abs());
        }
    }
    err / kmax
}

/// [`fd_error`] of the material point solver's next step to `load_factor`.
fn effective_tangent_error<const D: usize>(solver: &mut MpmSolver<D>, load_factor: f64, scale: f64) -> f64 {
    solver
        .with_step_system(load_factor, |sys| fd_error(sys, scale))
        .unwrap()
}

/// The bar of every basis family, consistent and lumped mass, after 5 time steps of a
/// large-amplitude vibration (v₀/c = 0.05, so F departs from 1 by a few per cent).
#[test]
fn effective_tangent_matches_central_differences_every_family_1d() {
    for mass in [MassMatrix::Consistent, MassMatrix::Lumped] {
        for basis in Basis::ALL {
            let spec = BarSpec {
                velocity: 0.5,
                elements: 8,
                steps_per_period: 16,
                mass,
                ..BarSpec::default()
            };
            let mut solver = spec.mpm_solver(Method::MaterialPoint(basis)).unwrap();
            for _ in 0..5 {
                solver.step().unwrap();
            }
            let err = effective_tangent_error(&mut solver, 6.0 / 16.0, 1e-3);
            assert!(
                err < 1e-6,
                "{basis:?}, {mass:?} mass: relative tangent error {err:e}"
            );
        }
    }
}

/// Newton with the effective tangent converges quadratically on a large-amplitude vibration
/// (v₀/c = 0.05: stretches of ±5 %, so every step needs several iterations) for iGIMP and
/// CPDI2, consistent and lumped mass, and for Line2. Criterion as the column's: once
/// r_k ≤ 0.1, r_{k+1} ≤ 10 r_k² above the round-off floor 1e-11, observed order ≥ 1.8.
#[test]
fn newton_converges_quadratically_with_the_effective_tangent() {
    let mut ratio_checks = 0;
    for method in [Method::IGIMP, Method::CPDI, Method::FEM_LINEAR] {
        for mass in [MassMatrix::Consistent, MassMatrix::Lumped] {
            let spec = BarSpec {
                velocity: 0.5,
                elements: 16,
                steps_per_period: 32,
                periods: 0.5,
                mass,
                newton: igimp::newton::NewtonSettings {
                    tolerance: 1e-11,
                    max_iterations: 30,
                    ..Default::default()
                },
                ..BarSpec::default()
            };
            let o = bar::solve(&spec, method).unwrap();
            assert!(o.failure.is_none(), "{method:?} {mass:?}: {:?}", o.failure);
            for s in &o.steps {
                let c = check_quadratic(&s.newton.residuals, 0.1, 1e-11, 10.0, 1.8)
                    .unwrap_or_else(|e| panic!("{method:?} {mass:?}, step {}: {e}", s.step));
                ratio_checks += c.ratio_checks;
            }
        }
    }
    assert!(
        ratio_checks >= 20,
        "only {ratio_checks} quadratic ratio checks ran"
    );
}

/// The mass term enters the effective tangent of the finite elements too (Line2, Line3):
/// central differences of the residual at a random increment after 5 steps.
#[test]
fn fem_effective_tangent_matches_central_differences() {
    for method in [Method::FEM_LINEAR, Method::FEM_QUADRATIC] {
        for mass in [MassMatrix::Consistent, MassMatrix::Lumped] {
            let spec = BarSpec {
                velocity: 0.5,
                elements: 6,
                points_per_cell: 3,
                steps_per_period: 16,
                mass,
                ..BarSpec::default()
            };
            let element = if method == Method::FEM_LINEAR {
                igimp::fem::LineElement::Linear
            } else {
                igimp::fem::LineElement::Quadratic
            };
            let mut fem = bar::fem_solver(&spec, element).unwrap();
            for _ in 0..5 {
                fem.step().unwrap();
            }
            let err = fem
                .with_step_system(6.0 / 16.0, |sys| fd_error(sys, 1e-3))
                .unwrap();
            assert!(
                err < 1e-6,
                "{method:?}, {mass:?} mass: relative tangent error {err:e}"
            );
        }
    }
}

/// Bad Newmark and bar inputs are refused with the key named.
#[test]
fn bad_dynamic_inputs_name_their_key() {
    let cases: [(BarSpec, &str); 5] = [
        (
            BarSpec {
                beta: 0.0,
                ..BarSpec::default()
            },
            "dynamics.beta",
        ),
        (
            BarSpec {
                beta: 0.7,
                ..BarSpec::default()
            },
            "dynamics.beta",
        ),
        (
            BarSpec {
                gamma: 0.3,
                ..BarSpec::default()
            },
            "dynamics.gamma",
        ),
        (
            BarSpec {
                density: 0.0,
                ..BarSpec::default()
            },
            "bar.density",
        ),
        (
            BarSpec {
                density: -1.0,
                ..BarSpec::default()
            },
            "bar.density",
        ),
    ];
    for (spec, key) in cases {
        let e = bar::solve(&spec, Method::IGIMP).unwrap_err().to_string();
        assert!(e.contains(key), "{key}: {e}");
    }
    let mut n = Newmark::trapezoidal(1.0);
    n.duration = -1.0;
    assert!(n
        .validate()
        .unwrap_err()
        .to_string()
        .contains("dynamics.duration"));
}

/// A solver made dynamic: Newmark over `steps` steps of Δt = h/c (the mass term M/(βΔt²) of
/// the order of the stiffness, so that neither hides the other), from velocities that vary
/// over the points.
fn made_dynamic<const D: usize>(solver: &mut MpmSolver<D>, h: f64, young: f64) {
    let p = &mut solver.points;
    let rho = p.mass[0] / p.volume0[0];
    let dt = h / (young / rho).sqrt();
    let steps = solver.settings.load_steps as f64;
    solver.settings.dynamics = Some(Newmark::trapezoidal(steps * dt));
    for i in 0..p.len() {
        let x = p.position[i];
        for a in 0..D {
            p.velocity[i][a] = 0.01 * h / dt * (1.0 + a as f64 + x[(a + 1) % D]).sin();
        }
    }
}

/// The effective tangent in 2D (the plane-strain compaction block under sudden gravity, with
/// its ghost penalty) and 3D (the column prism), iGIMP and CPDI2, consistent and lumped mass,
/// after 3 steps. Measured 2.7e-8 to 3.5e-8 (2D) and 1.3e-7 to 2.0e-7 (3D; round-off of the
/// larger residual, 1.4e-6 with a ten times smaller increment).
#[test]
fn effective_tangent_matches_central_differences_2d_and_3d() {
    use igimp::problems::column::ColumnSpec;
    use igimp::problems::compaction::CompactionSpec;
    for mass in [MassMatrix::Consistent, MassMatrix::Lumped] {
        for basis in [Basis::Gimp, Basis::Cpdi] {
            let spec = CompactionSpec {
                basis,
                load_steps: 10,
                ..CompactionSpec::default()
            };
            let mut s2 = spec.mpm_solver().unwrap();
            made_dynamic(&mut s2, spec.element_size, spec.young_modulus);
            s2.settings.dynamics.as_mut().unwrap().mass = mass;
            for _ in 0..3 {
                s2.step().unwrap();
            }
            let err = effective_tangent_error(&mut s2, 0.4, 1e-3);
            assert!(
                err < 1e-6,
                "2D {basis:?}, {mass:?}: relative tangent error {err:e}"
            );
            let col = ColumnSpec {
                elements: 4,
                weight: 4e4,
                load_steps: 10,
                poisson_ratio: 0.3,
                ..ColumnSpec::default()
            };
            let mut s3 = col.mpm_solver_3d(basis).unwrap();
            made_dynamic(&mut s3, col.length / 4.0, col.young_modulus);
            s3.settings.dynamics.as_mut().unwrap().mass = mass;
            for _ in 0..3 {
                s3.step().unwrap();
            }
            let err = effective_tangent_error(&mut s3, 0.4, 1e-3);
            assert!(
                err < 1e-6,
                "3D {basis:?}, {mass:?}: relative tangent error {err:e}"
            );
        }
    }
}
