//! What a dense block of the tangent is made of and how it is scattered: a point's spatial
//! gradients (eq 36), and a block's equations as stretches of consecutive ones. Shared by the
//! point kernels ([`super::kernel`]), F-bar's patch blocks ([`super::fbar`]) and the pressure
//! projection ([`super::pressure`]), with the point's F-bar q both of the latter read.

use crate::discretise::dofs::{SupportTable, MAX_POINT_NODES};
use crate::material::constitutive::ConstitutiveModel;
use crate::material::kinematics::{PointState, PointTrial};
use crate::material::tensor::ij;
use nalgebra::{Matrix3, SVector};

/// ∂S/∂x_j = ∂S/∂X̃_i (ΔF⁻¹)_ij (eq 36) of point `p`'s nodes at trial `t` into `gx`; returns
/// the node count.
#[inline]
pub(super) fn spatial_gradients<const D: usize>(
    table: &SupportTable<D>,
    p: usize,
    t: &PointTrial<D>,
    gx: &mut [SVector<f64, D>; MAX_POINT_NODES],
) -> usize {
    let g = table.point(p).2;
    let inv_t = t.delta_f_inv.transpose();
    for (x, gk) in gx.iter_mut().zip(g) {
        *x = inv_t * gk;
    }
    g.len()
}

/// Local rows `local..local + len` whose equations are `row..row + len`.
#[derive(Debug, Clone, Copy)]
pub(super) struct RowStretch {
    pub(super) local: usize,
    pub(super) len: usize,
    pub(super) row: usize,
}

/// A point's equations as stretches of consecutive ones (a node's D dofs, and nodes next to
/// each other along the first axis), fixed dofs left out.
pub(super) fn row_stretches(eqs: &[Option<usize>], out: &mut Vec<RowStretch>) {
    out.clear();
    let mut open: Option<RowStretch> = None;
    for (ri, eq) in eqs.iter().enumerate() {
        match (*eq, open.as_mut()) {
            (Some(row), Some(r)) if row == r.row + r.len => r.len += 1,
            (eq, _) => {
                out.extend(open.take());
                open = eq.map(|row| RowStretch {
                    local: ri,
                    len: 1,
                    row,
                });
            }
        }
    }
    out.extend(open);
}

/// Point `t`'s q = D^alg : I_D / (D J̄) (in-plane; with `out_of_plane`, its out-of-plane
/// diagonal too) and the D^alg it is formed from.
pub(super) fn point_q<const D: usize>(
    model: &dyn ConstitutiveModel,
    state: &PointState,
    t: &PointTrial<D>,
    out_of_plane: bool,
) -> (Matrix3<f64>, crate::material::tensor::Tensor4) {
    let eps = if model.tangent_reads_strain() {
        t.eps_trial()
    } else {
        Matrix3::zeros()
    };
    let d_alg = model.tangent(&eps, &state.material);
    let scale = 1.0 / (D as f64 * t.j);
    let q = Matrix3::from_fn(|i, j| {
        if (i < D && j < D) || (out_of_plane && i == j) {
            scale * (0..D).map(|m| d_alg[(ij(i, j), ij(m, m))]).sum::<f64>()
        } else {
            0.0
        }
    });
    (q, d_alg)
}
