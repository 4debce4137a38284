//! Modified Cam-Clay on one point along triaxial and isotropic paths, against closed forms:
//! drained and undrained triaxial compression of a normally consolidated sample end on the
//! critical state line where the closed forms put them, isotropic compression follows the
//! normal compression line with slope 1/λ̂ and unloading the swelling line with slope 1/κ̂, and
//! the driver's Newton on the stress-controlled components converges quadratically with the
//! model's tangent.
//!
//! The paths keep their principal axes, so log strains add exactly: the trial strain of a step
//! is the committed elastic strain plus the step's log-strain increment.

use crate::cam_clay::{mcc, state, KAPPA, LAMBDA, M, P0};
use igimp::material::constitutive::{ConstitutiveModel, MaterialState, ModifiedCamClay};
use igimp::material::tensor::ij;
use igimp::solver::newton::check_quadratic;
use nalgebra::{Matrix2, Matrix3, Vector2};

/// One material point: its committed state and stress.
struct Point {
    committed: MaterialState,
    tau: Matrix3<f64>,
}

impl Point {
    /// Normally consolidated at p₀: ε^e = 0, τ = −p₀ 1, εᵥᵖ = 0.
    fn new() -> Self {
        Self {
            committed: state(0.0),
            tau: -Matrix3::identity() * P0,
        }
    }

    /// (p, q) of the stress.
    fn pq(&self) -> (f64, f64) {
        let p = -self.tau.trace() / 3.0;
        let s = self.tau + Matrix3::identity() * p;
        (p, (1.5 * s.norm_squared()).sqrt())
    }

    fn commit(&mut self, m: &ModifiedCamClay, trial: &Matrix3<f64>) {
        let r = m.update(trial, &self.committed).unwrap();
        self.committed.eps_e = r.eps_e;
        self.committed.internal = r.internal;
        self.tau = r.tau;
    }

    /// A strain-controlled step by the log-strain increment `d`.
    fn strain_step(&mut self, m: &ModifiedCamClay, d: &Matrix3<f64>) {
        let trial = self.committed.eps_e + d;
        self.commit(m, &trial);
    }

    /// A drained triaxial step: axial increment `da` on axis 0, the lateral stresses τ₁₁, τ₂₂
    /// held at `lateral` by Newton on ε₁₁, ε₂₂ with the model's tangent. Returns the history of
    /// max |τ_ii − lateral| / p₀, from the first guess (no lateral increment) on.
    fn drained_step(&mut self, m: &ModifiedCamClay, da: f64, lateral: f64) -> Vec<f64> {
        let mut x = Vector2::zeros();
        let mut history = vec![];
        for _ in 0..30 {
            let trial =
                self.committed.eps_e + Matrix3::from_diagonal(&nalgebra::Vector3::new(da, x[0], x[1]));
            let r = m.update(&trial, &self.committed).unwrap();
            let res = Vector2::new(r.tau[(1, 1)] - lateral, r.tau[(2, 2)] - lateral);
            history.push(res.amax() / P0);
            if res.amax() <= 1e-13 * P0 {
                self.commit(m, &trial);
                return history;
            }
            let d = m.tangent(&trial, &self.committed);
            let (a, b) = (ij(1, 1), ij(2, 2));
            let j = Matrix2::new(d[(a, a)], d[(a, b)], d[(b, a)], d[(b, b)]);
            x -= j.lu().solve(&res).unwrap();
        }
        panic!("the drained step did not converge: {history:?}");
    }
}

/// Drained triaxial compression of a normally consolidated sample (p_c0 = p₀, lateral Kirchhoff
/// stress held at −p₀, axial log strain driven in steps of 1e-3): the path p = p₀ + q/3 meets
/// q = M p at p_f = 3p₀/(3 − M), reached to 1e-8 relative (with q_f = M p_f). The approach is
/// asymptotic: the axial strain needed for 1e-8 is measured and reported. Each step's Newton on
/// the lateral strains converges quadratically (check_quadratic, r_{k+1} ≤ 10 r_k², order ≥ 1.8).
#[test]
fn drained_triaxial_compression_ends_at_the_critical_state() {
    let m = mcc(P0);
    let mut pt = Point::new();
    let p_f = 3.0 * P0 / (3.0 - M);
    let q_f = M * p_f;
    let (mut reached, mut ratios, mut max_ratio, mut iterations) = (None, 0, 0.0f64, 0);
    let steps = 4000;
    for step in 1..=steps {
        let history = pt.drained_step(&m, -1e-3, -P0);
        iterations = iterations.max(history.len() - 1);
        let c =
            check_quadratic(&history, 1e-2, 1e-13, 10.0, 1.8).unwrap_or_else(|e| panic!("step {step}: {e}"));
        ratios += c.ratio_checks;
        max_ratio = max_ratio.max(c.max_ratio);
        let (p, q) = pt.pq();
        assert!((p - (P0 + q / 3.0)).abs() <= 1e-12 * p, "off the drained path");
        let err = ((p - p_f) / p_f).abs().max(((q - q_f) / q_f).abs());
        if err <= 1e-8 && reached.is_none() {
            reached = Some(step as f64 * 1e-3);
        }
    }
    let (p, q) = pt.pq();
    let (ep, eq) = ((p - p_f).abs() / p_f, (q - q_f).abs() / q_f);
    eprintln!(
        "drained: p {p} against {p_f} ({ep:.1e}), q {q} against {q_f} ({eq:.1e}); 1e-8 reached at axial strain {reached:?}; εᵥᵖ {}; Newton ≤ {iterations} iterations per step, {ratios} quadratic ratios, max r_k+1/r_k² {max_ratio:.2e}",
        pt.committed.internal.get(0)
    );
    assert!(ep <= 1e-8 && eq <= 1e-8);
    assert!(reached.is_some() && ratios >= 5);
}

/// Undrained (isochoric: tr ε = 0 each step, so the path is strain controlled, the lateral
/// strains −½ the axial one by symmetry) triaxial compression from the normally consolidated
/// isotropic state. With εᵥᵉ = −κ̂ ln(p/p₀) and εᵥᵖ = −(λ̂ − κ̂) ln(p_c/p₀) exactly in log strain,
/// tr ε = 0 gives (p/p₀)^κ̂ (p_c/p₀)^(λ̂−κ̂) = 1 along the whole path; at the critical state
/// p_c = 2p, so p_f = p₀ 2^(−Λ), Λ = (λ̂ − κ̂)/λ̂, q_f = M p_f: reached to 1e-8 relative. The
/// invariant (p/p₀)^κ̂ (p_c/p₀)^(λ̂−κ̂) = 1 is checked at every step to 1e-12.
#[test]
fn undrained_triaxial_compression_ends_at_the_closed_form() {
    let m = mcc(P0);
    let mut pt = Point::new();
    let big_lambda = (LAMBDA - KAPPA) / LAMBDA;
    let p_f = P0 * 2f64.powf(-big_lambda);
    let q_f = M * p_f;
    let d = Matrix3::from_diagonal(&nalgebra::Vector3::new(-1e-3, 5e-4, 5e-4));
    let mut reached = None;
    let steps = 4000;
    for step in 1..=steps {
        pt.strain_step(&m, &d);
        let (p, q) = pt.pq();
        let pc = m.preconsolidation(pt.committed.internal.get(0));
        let invariant = KAPPA * (p / P0).ln() + (LAMBDA - KAPPA) * (pc / P0).ln();
        assert!(invariant.abs() <= 1e-12, "step {step}: tr ε ≠ 0 ({invariant:e})");
        let err = ((p - p_f) / p_f).abs().max(((q - q_f) / q_f).abs());
        if err <= 1e-8 && reached.is_none() {
            reached = Some(step as f64 * 1e-3);
        }
    }
    let (p, q) = pt.pq();
    let (ep, eq) = ((p - p_f).abs() / p_f, (q - q_f).abs() / q_f);
    eprintln!(
        "undrained: p {p} against {p_f} ({ep:.1e}), q {q} against {q_f} ({eq:.1e}); 1e-8 reached at axial strain {reached:?}"
    );
    assert!(ep <= 1e-8 && eq <= 1e-8);
}

/// Isotropic compression from the normally consolidated state (steps of tr ε = −1e-3): the
/// point stays on the normal compression line, d ln p / d tr ε = −1/λ̂ each step and
/// ln(p/p₀) = −tr ε/λ̂ overall, to 1e-10; unloading from there is elastic with slope −1/κ̂.
#[test]
fn isotropic_compression_follows_the_normal_compression_line() {
    let m = mcc(P0);
    let mut pt = Point::new();
    let d = Matrix3::identity() * (-1e-3 / 3.0);
    let (mut ev, mut worst_load, mut worst_unload) = (0.0, 0.0f64, 0.0f64);
    for _ in 0..200 {
        let ln_p = pt.pq().0.ln();
        pt.strain_step(&m, &d);
        ev += -1e-3;
        let p = pt.pq().0;
        let slope = (p.ln() - ln_p) / -1e-3;
        worst_load = worst_load
            .max((slope * LAMBDA + 1.0).abs())
            .max(((p / P0).ln() + ev / LAMBDA).abs());
        assert!(pt.committed.internal.get(0) < 0.0);
    }
    let evp = pt.committed.internal.get(0);
    for _ in 0..100 {
        let ln_p = pt.pq().0.ln();
        pt.strain_step(&m, &(-d));
        let slope = (pt.pq().0.ln() - ln_p) / 1e-3;
        worst_unload = worst_unload.max((slope * KAPPA + 1.0).abs());
        assert_eq!(pt.committed.internal.get(0), evp, "unloading yielded");
    }
    eprintln!(
        "isotropic: loading slope·λ̂ + 1 within {worst_load:.1e}, unloading slope·κ̂ + 1 within {worst_unload:.1e} (εᵥᵖ = {evp})"
    );
    assert!(worst_load <= 1e-10 && worst_unload <= 1e-10);
}

/// A boundary-value problem from the initial stress −p₀ 1. The problem definitions ramp their
/// loads from zero (a traction p₀ on a free face would be out of balance in the first steps),
/// so the block is confined: a 2 × 2 square of Q4 and of Q8 elements (4 × 4) on rollers on all
/// four sides, whose reactions hold the uniform −p₀ 1 exactly, loaded by an oblique body force
/// ρg = (25, −50) per unit volume (ρg·side ≈ p₀, so the lower corner yields, p_c0 = p₀).
/// Every step converges, Gauss points yield, and each step's Newton with the model's
/// unsymmetric tangent (LU) is quadratic (check_quadratic from r_k ≤ 1e-3 down to 1e-12,
/// r_{k+1} ≤ 10 r_k², order ≥ 1.8).
#[test]
fn newton_is_quadratic_on_a_confined_cam_clay_block() {
    use igimp::fem::{ContinuumFem, FemLoads, PlaneFemSettings, PlaneMesh, QuadElement};
    use igimp::solver::load_stepping::LoadStepping;
    use nalgebra::SVector;
    for element in [QuadElement::Q4, QuadElement::Q8] {
        let mesh = PlaneMesh::structured(
            SVector::zeros(),
            SVector::<f64, 2>::new(2.0, 2.0),
            [4, 4],
            element,
        )
        .unwrap();
        let mut fixed = vec![];
        for (axis, at) in [(0, 0.0), (0, 2.0), (1, 0.0), (1, 2.0)] {
            fixed.extend(mesh.nodes_at(axis, at, 1e-9).into_iter().map(|n| (n, axis)));
        }
        let loads = FemLoads {
            gravity: SVector::<f64, 2>::new(25.0, -50.0),
            nodal_forces: vec![],
        };
        let settings = PlaneFemSettings {
            load_steps: 10,
            ..Default::default()
        };
        let mut fem = ContinuumFem::try_new(mesh, 1.0, Box::new(mcc(P0)), fixed, loads, settings).unwrap();
        let steps = fem.run().unwrap_or_else(|e| panic!("{element:?}: {e}"));
        let yielded = fem
            .gauss
            .state
            .iter()
            .filter(|s| s.material.internal.get(0) < 0.0)
            .count();
        let (mut ratios, mut max_ratio, mut iterations) = (0, 0.0f64, 0);
        for s in &steps {
            let c = check_quadratic(&s.newton.residuals, 1e-3, 1e-12, 10.0, 1.8)
                .unwrap_or_else(|e| panic!("{element:?}, step {}: {e}", s.step));
            ratios += c.ratio_checks;
            max_ratio = max_ratio.max(c.max_ratio);
            iterations = iterations.max(s.newton.residuals.len());
        }
        eprintln!(
            "{element:?}: {} steps, {yielded}/{} Gauss points yielded, ≤ {iterations} residuals per step, {ratios} quadratic ratios, max r_k+1/r_k² {max_ratio:.2e}",
            steps.len(),
            fem.gauss.len()
        );
        assert!(steps.len() == 10 && yielded > 0 && ratios >= 5);
    }
}
