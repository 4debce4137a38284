//! Drucker–Prager plasticity (issue 51's first model): the return lands on the cone or its
//! apex, the consistent tangent matches central differences on every branch (elastic, cone
//! associated and non-associated, hardening, softening, apex), the update is objective, and
//! Newton on a yielding block converges quadratically.

use crate::common;

use common::Rng;
use igimp::material::constitutive::{ConstitutiveModel, DruckerPrager, MaterialState};
use igimp::material::constitutive::{InternalVariables, Material};
use nalgebra::Matrix3;

const E: f64 = 1e5;
const COHESION: f64 = 50.0;

fn dp(phi: f64, psi: f64, h: f64) -> DruckerPrager {
    DruckerPrager::try_new(E, 0.3, COHESION, phi, psi, h).unwrap()
}

fn state(ep: f64) -> MaterialState {
    MaterialState {
        internal: InternalVariables::from_slice(&[ep]),
        ..Default::default()
    }
}

fn random_strain(rng: &mut Rng, size: f64) -> Matrix3<f64> {
    let a = Matrix3::from_fn(|_, _| rng.uniform(-size, size));
    0.5 * (a + a.transpose())
}

/// Which branch the update took: 0 elastic, 1 cone, 2 apex.
fn branch(m: &DruckerPrager, eps: &Matrix3<f64>, s: &MaterialState) -> usize {
    let r = m.update(eps, s).unwrap();
    if r.internal.get(0) == s.internal.get(0) {
        0
    } else if (r.tau - Matrix3::identity() * (r.tau.trace() / 3.0)).amax() == 0.0 {
        2
    } else {
        1
    }
}

/// Random trial strains, each on a branch away from its edges (f_t, the cone's q and the apex
/// margin not within 1 % of a kink): D^alg matches central differences to 1e-6 on every
/// branch, for associated and non-associated flow, perfect plasticity, hardening and
/// softening, from a virgin and a hardened state.
#[test]
fn drucker_prager_tangent_matches_central_differences_on_every_branch() {
    let mut rng = Rng::new(61);
    let mut seen = [[0usize; 3]; 5];
    let models = [
        dp(30.0, 30.0, 0.0),
        dp(30.0, 10.0, 0.0),
        dp(30.0, 30.0, 2e4),
        dp(25.0, 5.0, -2e3),
        dp(20.0, 20.0, 5e3),
    ];
    for (i, m) in models.iter().enumerate() {
        for ep in [0.0, 0.01] {
            let s = state(ep);
            for _ in 0..300 {
                // A volumetric part pulls some states past the apex (tension).
                let eps = random_strain(&mut rng, 4e-3) + Matrix3::identity() * rng.uniform(-3e-3, 3e-3);
                let b = branch(m, &eps, &s);
                // Away from the kinks: the branch is the same a little way off.
                let near = [0.99, 1.01].iter().any(|f| branch(m, &(eps * *f), &s) != b);
                if near {
                    continue;
                }
                let e = common::material_tangent_error(m, &eps, &s, E);
                assert!(
                    e <= 1e-6,
                    "model {i}, ε̄ᵖ = {ep}, branch {b}: tangent off by {e:e}"
                );
                seen[i][b] += 1;
            }
        }
    }
    for (i, s) in seen.iter().enumerate() {
        assert!(
            s.iter().all(|&n| n >= 5),
            "model {i}: branches elastic, cone, apex seen {s:?}"
        );
    }
}

/// A plastic trial state lands on the yield surface of its hardened cohesion (|f| ≤ 1e-10 c₀);
/// past the apex the deviator vanishes and p = (ξ/η) c.
#[test]
fn drucker_prager_return_lands_on_the_cone_or_its_apex() {
    let mut rng = Rng::new(62);
    let (mut cone, mut apex) = (0, 0);
    for m in [dp(30.0, 30.0, 0.0), dp(30.0, 10.0, 1e4)] {
        let (eta, xi, _) = m.cone();
        for _ in 0..200 {
            let eps = random_strain(&mut rng, 4e-3) + Matrix3::identity() * rng.uniform(-3e-3, 3e-3);
            let r = m.update(&eps, &state(0.0)).unwrap();
            let ep = r.internal.get(0);
            if ep == 0.0 {
                continue;
            }
            let f = m.yield_function(&r.tau, ep);
            assert!(f.abs() <= 1e-10 * COHESION, "f = {f:e} after the return");
            let dev = (r.tau - Matrix3::identity() * (r.tau.trace() / 3.0)).amax();
            if dev == 0.0 {
                let c = m.cohesion + m.hardening_modulus * ep;
                assert!((r.tau.trace() / 3.0 - xi / eta * c).abs() <= 1e-10 * COHESION);
                apex += 1;
            } else {
                cone += 1;
            }
        }
    }
    assert!(cone >= 20 && apex >= 20, "cone {cone}, apex {apex}");
}

/// A rigid rotation of the trial strain rotates the stress and leaves its invariants and the
/// plastic strain unchanged (1e-12 relative), on every branch.
#[test]
fn drucker_prager_update_is_objective() {
    let mut rng = Rng::new(63);
    let m = dp(30.0, 10.0, 1e4);
    for _ in 0..100 {
        let eps = random_strain(&mut rng, 4e-3) + Matrix3::identity() * rng.uniform(-3e-3, 3e-3);
        let q = nalgebra::Rotation3::from_euler_angles(
            rng.uniform(-3.0, 3.0),
            rng.uniform(-1.5, 1.5),
            rng.uniform(-3.0, 3.0),
        )
        .into_inner();
        let a = m.update(&eps, &state(0.0)).unwrap();
        let b = m.update(&(q * eps * q.transpose()), &state(0.0)).unwrap();
        let scale = a.tau.amax().max(COHESION);
        assert!((q * a.tau * q.transpose() - b.tau).amax() <= 1e-12 * scale * 10.0);
        assert!((a.tau.trace() - b.tau.trace()).abs() <= 1e-12 * scale * 10.0);
        assert!((a.internal.get(0) - b.internal.get(0)).abs() <= 1e-12 * a.internal.get(0).abs().max(1e-12));
    }
}

/// Bad parameters are input errors naming their key.
#[test]
fn drucker_prager_parameters_are_checked() {
    let bad = [
        (
            "cohesion",
            DruckerPrager::try_new(E, 0.3, -1.0, 30.0, 0.0, 0.0).err(),
        ),
        (
            "friction_angle",
            DruckerPrager::try_new(E, 0.3, 1.0, 90.0, 0.0, 0.0).err(),
        ),
        (
            "dilatancy_angle",
            DruckerPrager::try_new(E, 0.3, 1.0, 30.0, 31.0, 0.0).err(),
        ),
        (
            "hardening_modulus",
            DruckerPrager::try_new(E, 0.3, 1.0, 30.0, 0.0, f64::NAN).err(),
        ),
    ];
    for (key, e) in bad {
        let e = e.unwrap_or_else(|| panic!("{key} accepted"));
        assert_eq!(e.field, format!("material.{key}"));
    }
    let m = Material::new(
        "drucker-prager",
        &[
            ("young_modulus", E),
            ("poisson_ratio", 0.3),
            ("cohesion", COHESION),
            ("friction_angle", 30.0),
            ("dilatancy_angle", 0.0),
            ("hardening_modulus", 0.0),
        ],
    )
    .unwrap();
    m.build().unwrap();
}

/// The compaction's block in Drucker–Prager (associated and non-associated, c₀ = 1.2e4,
/// φ = 30°, W = 4e5: its unconfined strength 4.2e4 is below the base's 5e4, and the free
/// corner yields, so the answer differs from the elastic one) by iGIMP and Q8: every step
/// converges and each step's Newton is quadratic (the ratio test of `check_quadratic`), the
/// non-associated tangent (unsymmetric) included.
#[test]
fn newton_is_quadratic_on_a_yielding_drucker_prager_block() {
    use igimp::basis::method::Method;
    use igimp::problems::compaction::{solve, CompactionSpec};
    use igimp::solver::newton::check_quadratic;
    for psi in [30.0, 5.0] {
        let material = Material::new(
            "drucker-prager",
            &[
                ("young_modulus", 1e5),
                ("poisson_ratio", 0.3),
                ("cohesion", 1.2e4),
                ("friction_angle", 30.0),
                ("dilatancy_angle", psi),
                ("hardening_modulus", 0.0),
            ],
        )
        .unwrap();
        for method in [Method::IGIMP, Method::FEM_Q8] {
            let spec = CompactionSpec {
                material,
                element_size: 1.0,
                load_steps: 10,
                ..Default::default()
            };
            let o = solve(&spec, method).unwrap();
            assert!(o.failure.is_none(), "ψ = {psi}, {method}: {:?}", o.failure);
            let elastic = CompactionSpec {
                material: Material::new(
                    "linear-elastic",
                    &[("young_modulus", 1e5), ("poisson_ratio", 0.3)],
                )
                .unwrap(),
                ..spec
            };
            let e = solve(&elastic, method).unwrap().max_horizontal_displacement;
            let u = o.max_horizontal_displacement;
            assert!(
                (u - e).abs() > 1e-3 * e.abs(),
                "ψ = {psi}, {method}: no yielding (u = {u}, elastic {e})"
            );
            let mut ratios = 0;
            for s in &o.steps {
                let c = check_quadratic(&s.newton.residuals, 1e-3, 1e-10, 10.0, 1.8)
                    .unwrap_or_else(|e| panic!("ψ = {psi}, {method}, step {}: {e}", s.step));
                ratios += c.ratio_checks;
            }
            assert!(
                ratios >= 5,
                "ψ = {psi}, {method}: {ratios} quadratic ratios checked"
            );
        }
    }
}

/// A plane-strain biaxial test on one point (ε_zz = 0, τ_xx held at the confining −σ₃ by
/// Newton on ε_xx, ε_yy driven in compression): with associated flow, the plane-strain-matched
/// cone's limit state is Mohr–Coulomb's, τ₁ = τ₃ N_φ + 2c √N_φ, N_φ = (1 + sin φ)/(1 − sin φ)
/// (de Souza Neto et al. 2008, §8.3.4): reached to 1e-8 relative, for φ = 20° and 30°.
#[test]
fn plane_strain_biaxial_limit_is_mohr_coulombs() {
    use igimp::material::tensor::ij;
    for phi in [20.0, 30.0] {
        let m = dp(phi, phi, 0.0);
        let confining = -100.0;
        let mut committed = state(0.0);
        let mut tau = Matrix3::zeros();
        // An isotropic confinement first, then 300 steps of 1e-4 axial compression.
        let mut eps_e = Matrix3::identity() * (confining / (3.0 * (E / (3.0 * (1.0 - 0.6)))));
        for _ in 0..300 {
            let mut dxx = 0.0;
            for _ in 0..50 {
                let mut trial = eps_e;
                trial[(0, 0)] += dxx;
                trial[(1, 1)] += -1e-4;
                let r = m.update(&trial, &committed).unwrap();
                let residual = r.tau[(0, 0)] - confining;
                if residual.abs() <= 1e-12 * confining.abs() {
                    break;
                }
                let d = m.tangent(&trial, &committed);
                dxx -= residual / d[(ij(0, 0), ij(0, 0))];
            }
            let mut trial = eps_e;
            trial[(0, 0)] += dxx;
            trial[(1, 1)] += -1e-4;
            let r = m.update(&trial, &committed).unwrap();
            eps_e = r.eps_e;
            tau = r.tau;
            committed.internal = r.internal;
        }
        let n_phi = (1.0 + phi.to_radians().sin()) / (1.0 - phi.to_radians().sin());
        let exact = confining * n_phi - 2.0 * COHESION * n_phi.sqrt();
        assert!((tau[(0, 0)] - confining).abs() <= 1e-10 * confining.abs());
        eprintln!(
            "φ = {phi}: τ_yy {} against {exact}: {:.1e} relative",
            tau[(1, 1)],
            (tau[(1, 1)] - exact).abs() / exact.abs()
        );
        assert!(
            (tau[(1, 1)] - exact).abs() <= 1e-8 * exact.abs(),
            "φ = {phi}: τ_yy = {} against Mohr–Coulomb's {exact} (τ_zz = {})",
            tau[(1, 1)],
            tau[(2, 2)]
        );
    }
}
