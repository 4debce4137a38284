//! The pressure projection that completes F-bar under plastic dilation: every point of a
//! patch carries the patch's mean Kirchhoff pressure p̄_c = Σ_q w_q p_q / Σ_q w_q (w_q = V_q^n /
//! J_q^n, the weight τ_q has in the internal force), its deviator its own:
//! τ̂_p = τ_p + (p̄_c − p_p) 1. F-bar alone gives a patch's points one volume change, but each
//! point's plastic dilation is its own, so their pressures differ by K (εᵥᵖ_a − εᵥᵖ_b)
//! (reference/README.md item 75); projecting the pressure as the three-field Q1/P0 form of
//! Simo, Taylor & Pister 1985 does removes that spread. Without plastic dilation the points'
//! pressures agree already and the projection changes nothing.
//!
//! Its tangent: δτ̂_p = dev δτ_p + δp̄_c 1. The deviatoric part is the point's block less
//! δ_ij T_kl / 3 (T the trace tangent, [`crate::material::kinematics::spatial_trace_tangent`],
//! less tr q δ_kl for F-bar's own term) and F-bar's r with dev q; δp̄_c adds a rank-one block
//! R Pᵀ per patch, R_ai = Σ_p w_p ∂_i S_a and P_bk = Σ_q v_q (Σ_l T_kl ∂_l S_b + tr q_q Ḡ_bk) / 3W.

use super::local::spatial_gradients;
use crate::discretise::dofs::{SupportTable, MAX_POINT_NODES};
use crate::discretise::patches::VolumePatches;
use crate::material::kinematics::{spatial_trace_tangent, PointState, PointTrial};
use nalgebra::{Matrix3, SVector};

/// q less its trace over the three axes: dev q.
#[inline]
pub(super) fn deviator(q: &Matrix3<f64>) -> Matrix3<f64> {
    q - Matrix3::identity() * (q.trace() / 3.0)
}

/// The weight of point `p`'s τ in the internal force: V^n / J^n (= v / J at any trial).
#[inline]
fn weight(state: &PointState) -> f64 {
    state.volume / state.f.determinant()
}

/// Give every point of each shared patch the patch's mean Kirchhoff pressure.
pub(super) fn project_residual<const D: usize>(
    patches: &VolumePatches,
    states: &[PointState],
    trials: &mut [Option<PointTrial<D>>],
) {
    for c in 0..patches.count() {
        if !patches.is_shared(c) {
            continue;
        }
        let (mut w, mut wp) = (0.0, 0.0);
        for &q in patches.points(c) {
            let (t, wq) = (trials[q].as_ref().expect("evaluated"), weight(&states[q]));
            w += wq;
            wp += wq * t.response.tau.trace() / 3.0;
        }
        let p_bar = wp / w;
        for &q in patches.points(c) {
            let tau = &mut trials[q].as_mut().expect("evaluated").response.tau;
            let shift = p_bar - tau.trace() / 3.0;
            for i in 0..3 {
                tau[(i, i)] += shift;
            }
        }
    }
}

/// A point's trace tangent T − tr q δ_kl from its D^alg `d_alg` and q (with its out-of-plane
/// diagonal) at trial `t`.
pub(super) fn trace_tangent<const D: usize>(
    d_alg: &crate::material::tensor::Tensor4,
    t: &PointTrial<D>,
    q: &Matrix3<f64>,
) -> Matrix3<f64> {
    let mut tr = spatial_trace_tangent::<D>(d_alg, &t.b_trial_eigenvalues, &t.b_trial_eigenvectors, t.j);
    for k in 0..D {
        tr[(k, k)] -= q.trace();
    }
    tr
}

/// Patch `points`' R (into `r`) and P (into `p`) over `nodes`, with F-bar's Ḡ `g`.
#[allow(clippy::too_many_arguments)]
pub(super) fn form_block<const D: usize>(
    points: &[usize],
    table: &SupportTable<D>,
    trials: &[Option<PointTrial<D>>],
    states: &[PointState],
    q: &[Matrix3<f64>],
    trace: &[Matrix3<f64>],
    nodes: &[usize],
    g: &[f64],
    r: &mut Vec<f64>,
    p: &mut Vec<f64>,
) {
    let md = nodes.len() * D;
    r.clear();
    r.resize(md, 0.0);
    p.clear();
    p.resize(md, 0.0);
    let mut gx = [SVector::<f64, D>::zeros(); MAX_POINT_NODES];
    let (mut total, mut q_trace) = (0.0, 0.0);
    for &pt in points {
        let t = trials[pt].as_ref().expect("evaluated");
        let m = spatial_gradients(table, pt, t, &mut gx);
        let w = weight(&states[pt]);
        total += w;
        q_trace += t.volume * q[pt].trace();
        let tr = &trace[pt];
        for (k, &node) in table.point(pt).0[..m].iter().enumerate() {
            let local = nodes.binary_search(&node).expect("a patch node") * D;
            for i in 0..D {
                r[local + i] += w * gx[k][i];
                let s: f64 = (0..D).map(|l| tr[(i, l)] * gx[k][l]).sum();
                p[local + i] += t.volume * s;
            }
        }
    }
    for (pk, gk) in p.iter_mut().zip(g) {
        *pk = (*pk + q_trace * gk) / (3.0 * total);
    }
    #[cfg(feature = "seeded-bugs")]
    if crate::seeded::active(crate::seeded::Bug::PressureProjectionWithoutItsBlock) {
        p.fill(0.0);
    }
}
