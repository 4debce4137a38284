//! Tensor-product families: a one-axis kernel applied along every axis, and the support
//! of one point as per-axis weights.

use super::{AxisKernel, AxisWeights, BasisError, BasisFamily, GridAxis, PointSupport, PointView};
use crate::mesh::grid::Grid;
use nalgebra::SVector;

/// A tensor product of one axis kernel (the same along every axis).
#[derive(Debug, Clone, Copy, Default)]
pub struct TensorProduct<K>(pub K);

impl<K: AxisKernel> TensorProduct<K> {
    /// The per-axis weights of a point at `x` with half-lengths `r`.
    pub fn axes<const D: usize>(
        &self,
        grid: &Grid<D>,
        x: &SVector<f64, D>,
        r: &SVector<f64, D>,
        out: &mut Support<D>,
    ) -> Result<(), BasisError> {
        for a in 0..D {
            self.0
                .axis_weights(GridAxis::of(grid, a), x[a], r[a], &mut out.axes[a])?;
        }
        Ok(())
    }
}

impl<const D: usize, K: AxisKernel> BasisFamily<D> for TensorProduct<K> {
    fn support_nodes(&self) -> usize {
        self.0.support_nodes()
    }

    fn evaluate(
        &self,
        grid: &Grid<D>,
        point: &PointView<'_, D>,
        out: &mut PointSupport<D>,
    ) -> Result<(), BasisError> {
        let mut axes = Support::<D>::default();
        self.axes(grid, point.position, point.half_length, &mut axes)?;
        out.clear();
        for k in 0..axes.len() {
            let (node, s, g) = axes.node(grid, k);
            out.push(node, s, g);
        }
        Ok(())
    }

    fn fill_box(
        &self,
        grid: &Grid<D>,
        point: &PointView<'_, D>,
    ) -> Option<(SVector<f64, D>, SVector<f64, D>)> {
        let h = grid.spacing();
        let mut w = SVector::<f64, D>::zeros();
        for a in 0..D {
            w[a] = self.0.fill_half_width(h[a], point.half_length[a])?;
        }
        Some((point.position - w, point.position + w))
    }
}

/// Tensor-product support of one point: the nodes it touches with their weights and gradients.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Support<const D: usize> {
    /// The point's weights along each axis; the support is their tensor product.
    pub axes: [AxisWeights; D],
}

impl<const D: usize> Default for Support<D> {
    fn default() -> Self {
        Self {
            axes: [AxisWeights::default(); D],
        }
    }
}

impl<const D: usize> Support<D> {
    /// Number of nodes in the tensor-product support.
    #[inline]
    pub fn len(&self) -> usize {
        self.axes.iter().map(|a| a.len).product()
    }
    /// True if some axis touches no node.
    #[inline]
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
    /// Per-axis local indices of local node `k` (axis 0 fastest).
    #[inline]
    fn local(&self, mut k: usize) -> [usize; D] {
        let mut idx = [0; D];
        for (a, i) in idx.iter_mut().enumerate() {
            *i = k % self.axes[a].len;
            k /= self.axes[a].len;
        }
        idx
    }
    /// Local node `k`: (flat grid node, S_vp, ∂S_vp/∂x).
    #[inline]
    pub fn node(&self, grid: &Grid<D>, k: usize) -> (usize, f64, SVector<f64, D>) {
        let loc = self.local(k);
        let mut gidx = [0; D];
        let mut s = 1.0;
        let mut g = SVector::<f64, D>::repeat(1.0);
        for a in 0..D {
            let ax = &self.axes[a];
            gidx[a] = ax.first + loc[a];
            s *= ax.w[loc[a]];
            for b in 0..D {
                g[b] *= if a == b { ax.dw[loc[a]] } else { ax.w[loc[a]] };
            }
        }
        (grid.node_index(gidx), s, g)
    }
}
