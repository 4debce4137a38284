//! What a dense block of the tangent is made of and how it is scattered: a point's spatial
//! gradients (eq 36), and a block's equations as stretches of consecutive ones. Shared by the
//! point kernels ([`super::kernel`]) and F-bar's patch blocks ([`super::fbar`]).

use crate::discretise::dofs::{SupportTable, MAX_POINT_NODES};
use crate::material::kinematics::PointTrial;
use nalgebra::SVector;

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
