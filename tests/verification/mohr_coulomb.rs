//! Mohr–Coulomb plasticity (issue 51's multi-surface model): the return lands on the main
//! plane, an edge or the apex and keeps the principal ordering, the consistent tangent matches
//! central differences on every branch (elastic, main plane, left and right edges, apex;
//! associated and not; perfect, hardening, softening) including trial strains with two equal
//! principal values, the update is objective, the triaxial and plane-strain limits are the
//! closed forms, and Newton on a yielding block converges quadratically.

use crate::common;

use common::Rng;
use igimp::material::constitutive::{ConstitutiveModel, InternalVariables, Material, MaterialState};
use igimp::material::constitutive::{MohrCoulomb, ReturnBranch};
use igimp::material::kinematics::sym_eigen;
use igimp::material::tensor::ij;
use nalgebra::{Matrix3, Rotation3, Vector3};

const E: f64 = 1e5;
const COHESION: f64 = 50.0;

fn mc(phi: f64, psi: f64, h: f64) -> MohrCoulomb {
    MohrCoulomb::try_new(E, 0.3, COHESION, phi, psi, h).unwrap()
}

fn state(ep: f64) -> MaterialState {
    MaterialState {
        internal: InternalVariables::from_slice(&[ep]),
        ..Default::default()
    }
}

fn rotation(rng: &mut Rng) -> Matrix3<f64> {
    Rotation3::from_euler_angles(
        rng.uniform(-3.0, 3.0),
        rng.uniform(-1.5, 1.5),
        rng.uniform(-3.0, 3.0),
    )
    .into_inner()
}

/// A trial strain of one of four kinds, `kind` mod 4: general; triaxial diag(a, b, b) with
/// its single value on a random axis (two equal principal values, met exactly by the closed
/// form eigen-decomposition); the same rotated; plane strain (one 2×2 block, ε_zz = 0). Each
/// carries a volumetric part that pulls some states past the apex.
fn trial_strain(rng: &mut Rng, kind: usize) -> Matrix3<f64> {
    let size = 4e-3;
    let vol = Matrix3::identity() * rng.uniform(-3e-3, 3e-3);
    match kind % 4 {
        0 => {
            let a = Matrix3::from_fn(|_, _| rng.uniform(-size, size));
            0.5 * (a + a.transpose()) + vol
        }
        1 | 2 => {
            let (a, b) = (rng.uniform(-size, size), rng.uniform(-size, size));
            let k = (rng.uniform(0.0, 3.0) as usize).min(2);
            let d = Matrix3::from_diagonal(&Vector3::from_fn(|i, _| if i == k { a } else { b }));
            let r = if kind % 4 == 2 {
                rotation(rng)
            } else {
                Matrix3::identity()
            };
            r * d * r.transpose() + vol
        }
        _ => {
            let mut e = Matrix3::zeros();
            e[(0, 0)] = rng.uniform(-size, size);
            e[(1, 1)] = rng.uniform(-size, size);
            e[(0, 1)] = rng.uniform(-size, size);
            e[(1, 0)] = e[(0, 1)];
            e + vol - Matrix3::from_diagonal(&Vector3::new(0.0, 0.0, vol[(2, 2)]))
        }
    }
}

fn index(b: ReturnBranch) -> usize {
    match b {
        ReturnBranch::Elastic => 0,
        ReturnBranch::MainPlane => 1,
        ReturnBranch::LeftEdge => 2,
        ReturnBranch::RightEdge => 3,
        ReturnBranch::Apex => 4,
    }
}

const NAMES: [&str; 5] = ["elastic", "main plane", "left edge", "right edge", "apex"];

/// Whether every state within 1 % of `eps` (scaled by 0.99 and 1.01, and moved by three random
/// perturbations of 1 % of its size) returns to the same branch: away from a kink.
fn away_from_kinks(m: &MohrCoulomb, eps: &Matrix3<f64>, s: &MaterialState, rng: &mut Rng) -> bool {
    let b = m.branch(eps, s).unwrap();
    let near = |e: &Matrix3<f64>| m.branch(e, s).map(|x| x == b).unwrap_or(false);
    let size = eps.amax();
    near(&(eps * 0.99))
        && near(&(eps * 1.01))
        && (0..3).all(|_| {
            let a = Matrix3::from_fn(|_, _| rng.uniform(-1.0, 1.0));
            near(&(eps + 0.5 * (a + a.transpose()) * (0.01 * size)))
        })
}

/// D^alg matches central differences to 1e-6 on every branch, for associated and
/// non-associated flow, perfect plasticity, hardening and softening, from a virgin and a
/// hardened state; each branch seen at least five times per model, states within 1 % of a
/// kink skipped.
#[test]
fn mohr_coulomb_tangent_matches_central_differences_on_every_branch() {
    let mut rng = Rng::new(71);
    let models = [
        mc(30.0, 30.0, 0.0),
        mc(30.0, 10.0, 0.0),
        mc(30.0, 30.0, 2e4),
        mc(25.0, 5.0, -2e3),
        mc(20.0, 20.0, 5e3),
    ];
    let mut seen = [[0usize; 5]; 5];
    // States whose trial strain has two exactly equal principal values (the unrotated
    // triaxial kind), by branch: where the tangent's limit of (τ_a − τ_b)/(ε_a − ε_b) acts.
    let mut coincident = [0usize; 5];
    let mut worst = [0.0f64; 5];
    for (i, m) in models.iter().enumerate() {
        for ep in [0.0, 0.01] {
            let s = state(ep);
            for n in 0..800 {
                let eps = trial_strain(&mut rng, n);
                if !away_from_kinks(m, &eps, &s, &mut rng) {
                    continue;
                }
                let b = index(m.branch(&eps, &s).unwrap());
                let e = common::material_tangent_error(m, &eps, &s, E);
                assert!(
                    e <= 1e-6,
                    "model {i}, ε̄ᵖ = {ep}, {}: tangent off by {e:e} at {eps}",
                    NAMES[b]
                );
                seen[i][b] += 1;
                coincident[b] += usize::from(n % 4 == 1);
                worst[b] = worst[b].max(e);
            }
        }
    }
    for (i, s) in seen.iter().enumerate() {
        eprintln!("model {i}: branches {NAMES:?} seen {s:?}");
        assert!(
            s.iter().all(|&n| n >= 5),
            "model {i}: branches {NAMES:?} seen {s:?}"
        );
    }
    eprintln!("two equal trial principal strains: {NAMES:?} seen {coincident:?}");
    assert!(
        [0, 2, 3, 4].iter().all(|&b| coincident[b] >= 5),
        "two equal trial principal strains: {NAMES:?} seen {coincident:?}"
    );
    for (b, w) in worst.iter().enumerate() {
        eprintln!("{}: worst FD tangent error {w:.1e}", NAMES[b]);
    }
}

/// The trial eigenvectors sorted by decreasing principal strain (the stress ordering).
fn sorted_vectors(eps: &Matrix3<f64>) -> Matrix3<f64> {
    let (e, q) = sym_eigen(eps);
    let mut order = [0usize, 1, 2];
    order.sort_by(|&a, &b| e[b].total_cmp(&e[a]));
    Matrix3::from_fn(|i, a| q[(i, order[a])])
}

/// A plastic trial state lands on its hardened surface(s) to 1e-10 c₀ and keeps the ordering
/// τ₁ ≥ τ₂ ≥ τ₃ along the trial eigenvectors: the main plane f = 0; an edge also its second
/// plane (its pair of principal stresses equal); the apex an isotropic stress at p = c cot φ.
#[test]
fn mohr_coulomb_return_lands_on_its_surfaces() {
    let mut rng = Rng::new(72);
    let mut seen = [0usize; 5];
    let mut worst: f64 = 0.0;
    for m in [mc(30.0, 30.0, 0.0), mc(30.0, 10.0, 1e4), mc(25.0, 5.0, -2e3)] {
        let (sp, cp) = m.friction_angle.to_radians().sin_cos();
        for n in 0..600 {
            let eps = trial_strain(&mut rng, n);
            let s = state(0.005);
            let b = m.branch(&eps, &s).unwrap();
            let r = m.update(&eps, &s).unwrap();
            let ep = r.internal.get(0);
            seen[index(b)] += 1;
            if b == ReturnBranch::Elastic {
                assert_eq!(ep, 0.005);
                continue;
            }
            let c = m.cohesion + m.hardening_modulus * ep;
            let q = sorted_vectors(&eps);
            let t = Vector3::from_fn(|a, _| (q.column(a).transpose() * r.tau * q.column(a))[0]);
            let plane = |x: f64, y: f64| (x - y) + (x + y) * sp - 2.0 * c * cp;
            let tol = 1e-10 * COHESION;
            let mut off = plane(t[0], t[2]).abs();
            match b {
                ReturnBranch::LeftEdge => off = off.max(plane(t[1], t[2]).abs()),
                ReturnBranch::RightEdge => off = off.max(plane(t[0], t[1]).abs()),
                ReturnBranch::Apex => {
                    let p = r.tau.trace() / 3.0;
                    off = off
                        .max((r.tau - Matrix3::identity() * p).amax())
                        .max((p - c * cp / sp).abs());
                }
                _ => {}
            }
            worst = worst.max(off / COHESION);
            assert!(off <= tol, "{b:?}: off its surface by {off:e}");
            assert!(
                t[0] >= t[1] - tol && t[1] >= t[2] - tol,
                "{b:?}: ordering broken, τ = {t}"
            );
        }
    }
    eprintln!("returns {NAMES:?}: {seen:?}, worst |f| / c₀ {worst:.1e}");
    assert!(seen.iter().all(|&n| n >= 20), "branches {NAMES:?} seen {seen:?}");
}

/// The stress invariants tr τ, |τ|² and det τ (1e-12 relative), against the scale s.
fn invariants(t: &Matrix3<f64>) -> [f64; 3] {
    [t.trace(), t.norm_squared(), t.determinant()]
}

/// A rigid rotation of the trial strain rotates the stress and leaves its invariants (1e-12
/// relative) and the plastic strain unchanged, on every plastic branch.
#[test]
fn mohr_coulomb_update_is_objective() {
    let mut rng = Rng::new(73);
    let m = mc(30.0, 10.0, 1e4);
    let (mut worst_tau, mut worst_inv): (f64, f64) = (0.0, 0.0);
    let mut seen = [0usize; 5];
    for n in 0..400 {
        let eps = trial_strain(&mut rng, n);
        let b = m.branch(&eps, &state(0.0)).unwrap();
        if b == ReturnBranch::Elastic {
            continue;
        }
        seen[index(b)] += 1;
        let q = rotation(&mut rng);
        let a = m.update(&eps, &state(0.0)).unwrap();
        let r = m.update(&(q * eps * q.transpose()), &state(0.0)).unwrap();
        let scale = a.tau.norm().max(COHESION);
        let e_tau = (q * a.tau * q.transpose() - r.tau).amax() / scale;
        let (ia, ib) = (invariants(&a.tau), invariants(&r.tau));
        let e_inv = [
            (ia[0] - ib[0]).abs() / scale,
            (ia[1] - ib[1]).abs() / (scale * scale),
            (ia[2] - ib[2]).abs() / (scale * scale * scale),
        ]
        .into_iter()
        .fold(0.0, f64::max);
        worst_tau = worst_tau.max(e_tau);
        worst_inv = worst_inv.max(e_inv);
        assert!(e_inv <= 1e-12, "{b:?}: invariants change by {e_inv:e}");
        assert!(e_tau <= 1e-11, "{b:?}: rotated stress off by {e_tau:e}");
        let (pa, pb) = (a.internal.get(0), r.internal.get(0));
        assert!((pa - pb).abs() <= 1e-12 * pa.abs(), "ε̄ᵖ {pa} against {pb}");
    }
    eprintln!("objectivity: branches {NAMES:?} {seen:?}, stress {worst_tau:.1e}, invariants {worst_inv:.1e}");
    assert!(
        seen[1..].iter().all(|&n| n >= 5),
        "plastic branches seen {seen:?}"
    );
}

/// Bad parameters are input errors naming their key; good ones build through the registry.
#[test]
fn mohr_coulomb_parameters_are_checked() {
    let bad = [
        (
            "young_modulus",
            MohrCoulomb::try_new(-1.0, 0.3, 1.0, 30.0, 0.0, 0.0).err(),
        ),
        (
            "poisson_ratio",
            MohrCoulomb::try_new(E, 0.5, 1.0, 30.0, 0.0, 0.0).err(),
        ),
        (
            "cohesion",
            MohrCoulomb::try_new(E, 0.3, -1.0, 30.0, 0.0, 0.0).err(),
        ),
        (
            "friction_angle",
            MohrCoulomb::try_new(E, 0.3, 1.0, 90.0, 0.0, 0.0).err(),
        ),
        (
            "friction_angle",
            MohrCoulomb::try_new(E, 0.3, 1.0, -1.0, 0.0, 0.0).err(),
        ),
        (
            "dilatancy_angle",
            MohrCoulomb::try_new(E, 0.3, 1.0, 30.0, 31.0, 0.0).err(),
        ),
        (
            "dilatancy_angle",
            MohrCoulomb::try_new(E, 0.3, 1.0, 30.0, -1.0, 0.0).err(),
        ),
        (
            "hardening_modulus",
            MohrCoulomb::try_new(E, 0.3, 1.0, 30.0, 0.0, f64::NAN).err(),
        ),
    ];
    for (key, e) in bad {
        let e = e.unwrap_or_else(|| panic!("{key} accepted"));
        assert_eq!(e.field, format!("material.{key}"));
    }
    let m = Material::new(
        "mohr-coulomb",
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
    let model = m.build().unwrap();
    assert!(!model.tangent_is_symmetric());
    assert!(mc(30.0, 30.0, 0.0).tangent_is_symmetric());
    assert_eq!(model.young_modulus(), E);
    // Frictionless or non-dilatant, the apex cannot be returned to: an error, not a NaN.
    let tension = Matrix3::identity() * 1e-2;
    assert!(mc(30.0, 0.0, 0.0).update(&tension, &state(0.0)).is_err());
    // Tresca (φ = 0) has no apex: isotropic tension is elastic.
    let r = mc(0.0, 0.0, 0.0).update(&tension, &state(0.0)).unwrap();
    assert_eq!(r.internal.get(0), 0.0);
}

/// One point driven by `axial` steps of −1e-4 on ε_zz (after an isotropic confinement), the
/// stresses of the `held` axes kept at `confining` by Newton on their strains with the model's
/// own tangent (the others' strains fixed); returns the final stress.
fn drive(m: &MohrCoulomb, confining: f64, held: &[usize], steps: usize) -> Matrix3<f64> {
    let k = E / (3.0 * (1.0 - 0.6));
    let mut eps_e = Matrix3::identity() * (confining / (3.0 * k));
    let mut committed = state(0.0);
    let mut tau = Matrix3::zeros();
    for _ in 0..steps {
        let mut du = [0.0; 3];
        let trial = |du: &[f64; 3]| {
            let mut t = eps_e;
            for (a, &x) in held.iter().enumerate() {
                t[(x, x)] += du[a];
            }
            t[(2, 2)] += -1e-4;
            t
        };
        for _ in 0..50 {
            let r = m.update(&trial(&du), &committed).unwrap();
            let res: Vec<f64> = held.iter().map(|&x| r.tau[(x, x)] - confining).collect();
            if res.iter().all(|v| v.abs() <= 1e-12 * confining.abs()) {
                break;
            }
            let d = m.tangent(&trial(&du), &committed);
            let j = |a: usize, b: usize| d[(ij(held[a], held[a]), ij(held[b], held[b]))];
            if held.len() == 1 {
                du[0] -= res[0] / j(0, 0);
            } else {
                let det = j(0, 0) * j(1, 1) - j(0, 1) * j(1, 0);
                du[0] -= (j(1, 1) * res[0] - j(0, 1) * res[1]) / det;
                du[1] -= (j(0, 0) * res[1] - j(1, 0) * res[0]) / det;
            }
        }
        let r = m.update(&trial(&du), &committed).unwrap();
        eps_e = r.eps_e;
        tau = r.tau;
        committed.internal = r.internal;
    }
    tau
}

/// Axisymmetric triaxial compression on one point (τ_xx = τ_yy = −100 held by Newton on
/// ε_xx, ε_yy, ε_zz driven in 300 steps of −1e-4, perfect plasticity, associated flow): the
/// state ends on the left edge τ₁ = τ₂ and the axial stress at Mohr–Coulomb's limit
/// τ_zz = −(σ₃ N_φ + 2c √N_φ), σ₃ = 100, N_φ = (1 + sin φ)/(1 − sin φ), to 1e-8 relative, for
/// φ = 20° and 30°. The plane-strain biaxial test (ε_yy = 0 instead of τ_yy held) reaches the
/// same limit, τ_yy being the intermediate stress.
#[test]
fn triaxial_and_plane_strain_limits_are_mohr_coulombs() {
    for phi in [20.0, 30.0] {
        let m = mc(phi, phi, 0.0);
        let confining = -100.0;
        let n_phi = (1.0 + phi.to_radians().sin()) / (1.0 - phi.to_radians().sin());
        let exact = confining * n_phi - 2.0 * COHESION * n_phi.sqrt();
        for (test, held) in [("triaxial", &[0usize, 1][..]), ("plane strain", &[0usize][..])] {
            let tau = drive(&m, confining, held, 300);
            for &x in held {
                assert!((tau[(x, x)] - confining).abs() <= 1e-10 * confining.abs());
            }
            let e = (tau[(2, 2)] - exact).abs() / exact.abs();
            eprintln!(
                "{test}, φ = {phi}: τ_zz {} against {exact}: {e:.1e} relative (τ_yy {})",
                tau[(2, 2)],
                tau[(1, 1)]
            );
            assert!(
                e <= 1e-8,
                "{test}, φ = {phi}: τ_zz = {} against {exact}",
                tau[(2, 2)]
            );
        }
    }
}

/// The compaction's block in Mohr–Coulomb (associated and ψ = 5°, c₀ = 1.02e4, φ = 30°,
/// W = 4e5: its unconfined strength 2c cos φ/(1 − sin φ) = 3.5e4 is below the base's 5e4, so
/// the block yields near its base) by iGIMP and Q8: every step converges and each step's
/// Newton is quadratic (the ratio test of `check_quadratic`), the non-associated tangent
/// (unsymmetric) included. Drucker–Prager's c₀ = 1.2e4 leaves this block elastic in
/// Mohr–Coulomb, and below 1e4 it collapses; at 1e4 and 1.05e4 one Q8 step meets a point
/// switching branch after the residual fell under 1e-3, which the ratio test fails.
#[test]
fn newton_is_quadratic_on_a_yielding_mohr_coulomb_block() {
    use igimp::basis::method::Method;
    use igimp::problems::compaction::{solve, CompactionSpec};
    use igimp::solver::newton::check_quadratic;
    for psi in [30.0, 5.0] {
        let material = Material::new(
            "mohr-coulomb",
            &[
                ("young_modulus", 1e5),
                ("poisson_ratio", 0.3),
                ("cohesion", 1.02e4),
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
            let (mut ratios, mut max_ratio, mut iterations) = (0, 0.0f64, 0);
            for s in &o.steps {
                let c = check_quadratic(&s.newton.residuals, 1e-3, 1e-10, 10.0, 1.8)
                    .unwrap_or_else(|e| panic!("ψ = {psi}, {method}, step {}: {e}", s.step));
                ratios += c.ratio_checks;
                max_ratio = max_ratio.max(c.max_ratio);
                iterations += s.newton.residuals.len() - 1;
            }
            eprintln!(
                "ψ = {psi}, {method}: u {u:.4e} (elastic {e:.4e}), {iterations} iterations, {ratios} ratios checked, largest r_k+1/r_k² {max_ratio:.2e}"
            );
            assert!(
                ratios >= 5,
                "ψ = {psi}, {method}: {ratios} quadratic ratios checked"
            );
        }
    }
}
