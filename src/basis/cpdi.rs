//! CPDI2 (Sadeghirad, Brannon & Guilkey 2013): each point's domain is a quadrilateral (2D),
//! hexahedron (3D) or segment (1D) tracked by its corners, which move with the grid.
//!
//! The grid's linear hats N_v are replaced on the domain by their multilinear interpolant
//! through the corners, N_v ≈ Σ_α N_v(x_α) M_α, so that
//! S_vp = Σ_α w^f_α N_v(x_α) and ∇S_vp = Σ_α w^g_α N_v(x_α), with
//! w^f_α = ∫_Ωp M_α dΩ / V_p and w^g_α = ∫_Ωp ∇M_α dΩ / V_p, V_p = |Ω_p|.
//! Both integrals are exact with 2 Gauss points per axis on the multilinear map (the
//! integrands are at most cubic per axis: det J is quadratic per axis in 3D, linear in 2D),
//! so in 2D they are the closed forms of the paper. Σ_v S_vp = Σ_α w^f_α = 1 and
//! Σ_v ∇S_vp = 0 hold for any corner positions; Σ_v S_vp x_v is the domain's centroid.
//!
//! Corners are updated with the grid: x_α ← x_α + Σ_v N_v(x_α) Δu_v (CPDI2's corner
//! update), so a domain follows shear and rotation without the F-based domain rule of eq (39).

use super::linear::LinearKernel;
use super::{AxisKernel, AxisWeights, BasisError, BasisFamily, GridAxis, PointSupport, PointView};
use crate::grid::Grid;
use nalgebra::{SMatrix, SVector};

/// CPDI2 with multilinear domains.
#[derive(Debug, Clone, Copy, Default)]
pub struct Cpdi;

/// Most corners of a domain (a hexahedron).
pub const MAX_CORNERS: usize = 8;

/// Corner `k` of `D` axes: its sign along axis `a` (axis 0 fastest, as the grid's nodes).
#[inline]
fn corner_sign(k: usize, a: usize) -> f64 {
    if (k >> a) & 1 == 1 {
        1.0
    } else {
        -1.0
    }
}

/// The corners of the box `x ± r`, in corner order.
pub fn box_corners<const D: usize>(x: &SVector<f64, D>, r: &SVector<f64, D>, out: &mut Vec<SVector<f64, D>>) {
    for k in 0..(1usize << D) {
        out.push(SVector::<f64, D>::from_fn(|a, _| x[a] + corner_sign(k, a) * r[a]));
    }
}

/// CPDI2's corner weights of a domain: (w^f_α, w^g_α) for every corner and the volume V_p,
/// by 2-point Gauss quadrature per axis on the multilinear map. Fails if the map folds
/// (det J ≤ 0 at a Gauss point: the domain is inverted or degenerate).
pub fn corner_weights<const D: usize>(
    corners: &[SVector<f64, D>],
    wf: &mut [f64; MAX_CORNERS],
    wg: &mut [SVector<f64, D>; MAX_CORNERS],
) -> Result<f64, BasisError> {
    let nc = 1usize << D;
    let g = 1.0 / 3f64.sqrt();
    *wf = [0.0; MAX_CORNERS];
    *wg = [SVector::<f64, D>::zeros(); MAX_CORNERS];
    let mut volume = 0.0;
    let mut m = [0.0; MAX_CORNERS];
    let mut dm = [SVector::<f64, D>::zeros(); MAX_CORNERS];
    for q in 0..nc {
        let xi = SVector::<f64, D>::from_fn(|a, _| corner_sign(q, a) * g);
        let mut jac = SMatrix::<f64, D, D>::zeros();
        for k in 0..nc {
            let f = |a: usize| 0.5 * (1.0 + corner_sign(k, a) * xi[a]);
            m[k] = (0..D).map(f).product();
            for b in 0..D {
                dm[k][b] = 0.5 * corner_sign(k, b) * (0..D).filter(|&a| a != b).map(f).product::<f64>();
            }
            jac += corners[k] * dm[k].transpose();
        }
        let jac3 = super::padded(&jac);
        let det = jac3.determinant();
        if !(det > 0.0 && det.is_finite()) {
            return Err(BasisError::InvertedDomain);
        }
        let inv_t = super::block::<D>(&jac3.try_inverse().ok_or(BasisError::InvertedDomain)?).transpose();
        volume += det;
        for k in 0..nc {
            wf[k] += m[k] * det;
            wg[k] += inv_t * dm[k] * det;
        }
    }
    for k in 0..nc {
        wf[k] /= volume;
        wg[k] /= volume;
    }
    Ok(volume)
}

/// The grid's linear hats at `x` along every axis.
fn hats<const D: usize>(
    grid: &Grid<D>,
    x: &SVector<f64, D>,
    axes: &mut [AxisWeights; D],
) -> Result<(), BasisError> {
    for (a, out) in axes.iter_mut().enumerate() {
        LinearKernel.axis_weights(GridAxis::of(grid, a), x[a], 0.0, out)?;
    }
    Ok(())
}

/// Node `k` (of 2^D) of the linear hats at one corner: (flat node, N_v).
#[inline]
fn hat_node<const D: usize>(grid: &Grid<D>, axes: &[AxisWeights; D], k: usize) -> (usize, f64) {
    let mut idx = [0usize; D];
    let mut n = 1.0;
    for a in 0..D {
        let i = (k >> a) & 1;
        idx[a] = axes[a].first + i;
        n *= axes[a].w[i];
    }
    (grid.node_index(idx), n)
}

impl<const D: usize> BasisFamily<D> for Cpdi {
    fn support_nodes(&self) -> usize {
        3
    }

    fn needs_corners(&self) -> bool {
        true
    }

    fn evaluate(
        &self,
        grid: &Grid<D>,
        point: &PointView<'_, D>,
        out: &mut PointSupport<D>,
    ) -> Result<(), BasisError> {
        out.clear();
        let corners = point.corners;
        let mut wf = [0.0; MAX_CORNERS];
        let mut wg = [SVector::<f64, D>::zeros(); MAX_CORNERS];
        corner_weights(corners, &mut wf, &mut wg)?;
        let mut axes = [AxisWeights::default(); D];
        for (k, x) in corners.iter().enumerate() {
            hats(grid, x, &mut axes)?;
            for j in 0..(1usize << D) {
                let (node, n) = hat_node(grid, &axes, j);
                out.accumulate(node, wf[k] * n, wg[k] * n);
            }
        }
        Ok(())
    }

    fn fill_box(
        &self,
        _grid: &Grid<D>,
        point: &PointView<'_, D>,
    ) -> Option<(SVector<f64, D>, SVector<f64, D>)> {
        let c = point.corners;
        let lo = SVector::<f64, D>::from_fn(|a, _| c.iter().map(|x| x[a]).fold(f64::INFINITY, f64::min));
        let hi = SVector::<f64, D>::from_fn(|a, _| c.iter().map(|x| x[a]).fold(f64::NEG_INFINITY, f64::max));
        Some((lo, hi))
    }

    fn update_corners(
        &self,
        grid: &Grid<D>,
        du_nodal: &[f64],
        corners: &mut [SVector<f64, D>],
    ) -> Result<(), BasisError> {
        let mut axes = [AxisWeights::default(); D];
        #[cfg(feature = "seeded-bugs")]
        let sign = if crate::seeded::active(crate::seeded::Bug::CornersAgainstGrid) {
            -1.0
        } else {
            1.0
        };
        #[cfg(not(feature = "seeded-bugs"))]
        let sign = 1.0;
        for x in corners.iter_mut() {
            hats(grid, x, &mut axes)?;
            let mut du = SVector::<f64, D>::zeros();
            for j in 0..(1usize << D) {
                let (node, n) = hat_node(grid, &axes, j);
                for a in 0..D {
                    du[a] += n * du_nodal[node * D + a];
                }
            }
            *x += du * sign;
        }
        Ok(())
    }
}
