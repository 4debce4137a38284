//! A displacement imposed on material points instead of grid nodes, by a penalty.
//!
//! The background grid is reset every step, so a prescribed node moves whatever material its
//! weights reach in that step: a footing on a row of nodes holds the soil under it only while
//! the soil's surface lies on that row, and lets go of it as the soil settles below the row
//! (reference/README.md item 81). A displacement bound to points moves with the material, as
//! a finite element's node does. Each bound point p and axis a adds to the step's energy
//!
//! ```text
//! ½ k_p (Σ_i S_ip Δu_ia − t_pa)²,   t_pa = X_pa + ū_a(λ) − x_pa
//! ```
//!
//! (the target increment: what takes the point from its committed position x_p to its
//! initial one X_p moved by the prescribed ū(λ), so a lag left by one step is not carried into
//! the next). The residual gains k_p S_ip e_p and the tangent the constant, symmetric
//! k_p S_ip S_jp (Newton stays quadratic; the point's nodes already share a block of the
//! pattern). The force the soil exerts on the load along a is −Σ_p k_p e_pa, the counterpart
//! of a prescribed node's reaction. The penalty's compliance is measured, not assumed
//! (item 81 sweeps its factor).

use crate::discretise::dofs::{DofMap, SupportTable};
use crate::solver::linear::SparseSystem;
use crate::solver::ramp::Ramp;
use nalgebra::SVector;

/// Default penalty factor β of [`crate::mpm::MpmSolver::bind_points`] (k_p = β E V_p⁰ / h²):
/// from 1e2 to 1e3 the strip footing's pressure moves by 2e-6, while 1e4 already changes its
/// cut-back path (reference/README.md item 81).
pub const DEFAULT_POINT_PENALTY: f64 = 1.0e3;

/// Points whose components follow prescribed values, with their penalty stiffnesses and the
/// force they exerted at the last converged step.
#[derive(Debug, Clone)]
pub struct BoundPoints<const D: usize> {
    pub(crate) points: Vec<usize>,
    /// (axis, value at full load).
    pub(crate) values: Vec<(usize, f64)>,
    pub(crate) ramp: Ramp,
    /// k_p per point of `points`.
    pub(crate) stiffness: Vec<f64>,
    /// The force the points exert on the load (−Σ k_p e_p per axis) at the last commit.
    pub(crate) reaction: SVector<f64, D>,
}

/// One bound component of one point for one step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PointPenalty {
    /// The material point.
    pub point: usize,
    /// The bound axis.
    pub axis: usize,
    /// Its penalty stiffness k_p (force per length).
    pub stiffness: f64,
    /// The increment the point's displacement along `axis` should take in this step.
    pub target: f64,
}

impl PointPenalty {
    /// The penalty's misfit e = Σ_i S_ip Δu_ia − t at the nodal increment `du` (dof =
    /// node·D + axis).
    pub fn misfit<const D: usize>(&self, table: &SupportTable<D>, du: &[f64]) -> f64 {
        let (nodes, weights, _) = table.point(self.point);
        let moved: f64 = nodes
            .iter()
            .zip(weights)
            .map(|(&n, &w)| w * du[n * D + self.axis])
            .sum();
        moved - self.target
    }
}

/// Add every penalty's force k_p S_ip e_p to the internal force `f_int` (equation order) or,
/// at a dof without an equation, to `fixed_forces` (nodal dof order).
pub fn add_residual<const D: usize>(
    penalties: &[PointPenalty],
    table: &SupportTable<D>,
    dofs: &DofMap,
    du: &[f64],
    f_int: &mut [f64],
    fixed_forces: &mut [f64],
) {
    for p in penalties {
        let force = p.stiffness * p.misfit(table, du);
        let (nodes, weights, _) = table.point(p.point);
        for (&n, &w) in nodes.iter().zip(weights) {
            let dof = n * D + p.axis;
            match dofs.eq(dof) {
                Some(e) => f_int[e] += w * force,
                None => fixed_forces[dof] += w * force,
            }
        }
    }
}

/// Add every penalty's k_p S_ip S_jp to the tangent, over the point's nodes with equations.
pub fn add_tangent<const D: usize>(
    penalties: &[PointPenalty],
    table: &SupportTable<D>,
    dofs: &DofMap,
    matrix: &mut SparseSystem,
) {
    #[cfg(feature = "seeded-bugs")]
    if crate::seeded::active(crate::seeded::Bug::PointPenaltyWithoutItsTangent) {
        return;
    }
    for p in penalties {
        let (nodes, weights, _) = table.point(p.point);
        for (&ni, &wi) in nodes.iter().zip(weights) {
            let Some(ei) = dofs.eq(ni * D + p.axis) else {
                continue;
            };
            for (&nj, &wj) in nodes.iter().zip(weights) {
                if let Some(ej) = dofs.eq(nj * D + p.axis) {
                    matrix.add(ei, ej, p.stiffness * wi * wj);
                }
            }
        }
    }
}
