//! Uniform quadratic and cubic B-splines centred on the grid nodes (Steffen, Kirby & Berzins
//! 2008), with the nodes beyond the grid folded back by linear extrapolation.
//!
//! Boundary treatment. A spline of node i reaches 1.5h (quadratic) or 2h (cubic) from it, so a
//! point within that distance of the grid's edge draws on nodes i < 0 or i > N the grid does not
//! have; dropped, the weights lose the partition of unity and linear reproduction there (the
//! defect of geomechanics/mpm's B-splines within 1.5h of a boundary). Here each missing node
//! −k (k ≥ 1) is given the value u₋ₖ = (1 + k) u₀ − k u₁ (the linear extrapolation of the two
//! nodes inside), i.e. its weight is folded as S₀ += (1 + k) S₋ₖ and S₁ −= k S₋ₖ (likewise at
//! the far edge). Folding keeps Σ S = 1 and Σ S x_v = x_p exactly (a linear field is its own
//! extrapolation) and keeps the weights non-negative (S₁ − S₋₁ ≥ 0 because the splines fall
//! off with distance). On a fixed edge (u₀ = 0) it is the odd reflection u₋₁ = −u₁ of the
//! boundary-modified splines' clamped knots. Measured against dropping the nodes in
//! reference/README.md (item 39).

use super::{AxisKernel, AxisWeights, BasisError, GridAxis};

/// The spline degree.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SplineDegree {
    /// Quadratic: reaches 1.5h from its node, 3 nodes per axis.
    Quadratic,
    /// Cubic: reaches 2h from its node, 4 nodes per axis.
    Cubic,
}

/// What happens to the spline weights of nodes beyond the grid.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SplineBoundary {
    /// Fold them onto the first two nodes by linear extrapolation (the default; see the module
    /// documentation).
    LinearExtrapolation,
    /// Drop them: the plain truncated splines, which lose Σ S = 1 within the support radius of
    /// the grid's edge. Kept to measure the treatment against.
    Truncated,
}

/// The B-spline kernel along one axis.
#[derive(Debug, Clone, Copy)]
pub struct BsplineKernel {
    /// Quadratic or cubic splines.
    pub degree: SplineDegree,
    /// What becomes of the weights of nodes beyond the grid.
    pub boundary: SplineBoundary,
}

/// Value and derivative (in units of t) of the centred uniform spline at t = (x − x_v)/h.
#[inline]
pub fn spline(degree: SplineDegree, t: f64) -> (f64, f64) {
    let a = t.abs();
    let sign = if t < 0.0 { -1.0 } else { 1.0 };
    match degree {
        SplineDegree::Quadratic => {
            if a <= 0.5 {
                (0.75 - t * t, -2.0 * t)
            } else if a < 1.5 {
                let b = 1.5 - a;
                (0.5 * b * b, -sign * b)
            } else {
                (0.0, 0.0)
            }
        }
        SplineDegree::Cubic => {
            if a <= 1.0 {
                (2.0 / 3.0 - t * t + 0.5 * a * a * a, -2.0 * t + 1.5 * t * a)
            } else if a < 2.0 {
                let b = 2.0 - a;
                (b * b * b / 6.0, -sign * 0.5 * b * b)
            } else {
                (0.0, 0.0)
            }
        }
    }
}

impl AxisKernel for BsplineKernel {
    fn support_nodes(&self) -> usize {
        match self.degree {
            SplineDegree::Quadratic => 3,
            SplineDegree::Cubic => 4,
        }
    }

    /// The spline's reach less one cell: h/2 (quadratic), h (cubic). A point reaches the nodes
    /// within 1.5h (2h) of it; the cell between such a node and the point has its near face
    /// within 0.5h (h) of the point, so the box overlaps a cell of every node the point reaches
    /// and the ghost penalty (src/discretise/ghost.rs) sees every node the tangent holds. Counted in the
    /// point's own cell only, a spline body's outer layer of nodes (weights of a few 1e-3 from
    /// points up to 1.5h or 2h away) sits in empty cells, carries no penalty, and the tangent
    /// turns singular there (measured in reference/README.md, item 39). The quadratic box is
    /// also the spline's own construction: the hat convolved with a box of width h.
    fn fill_half_width(&self, spacing: f64, _r: f64) -> Option<f64> {
        Some(match self.degree {
            SplineDegree::Quadratic => 0.5 * spacing,
            SplineDegree::Cubic => spacing,
        })
    }

    fn axis_weights(
        &self,
        grid_axis: GridAxis,
        x: f64,
        _r: f64,
        out: &mut AxisWeights,
    ) -> Result<(), BasisError> {
        let GridAxis {
            axis,
            origin,
            spacing: h,
            cells,
        } = grid_axis;
        *out = AxisWeights::default();
        let t_c = (x - origin) / h;
        if !(t_c >= -1e-12 && t_c <= cells as f64 + 1e-12) {
            return Err(BasisError::OutsideGrid { axis });
        }
        let t_c = t_c.clamp(0.0, cells as f64);
        let n = cells as i64; // the last node
        let (i_lo, count) = match self.degree {
            SplineDegree::Quadratic => ((t_c - 0.5).floor() as i64, 3),
            SplineDegree::Cubic => (t_c.floor() as i64 - 1, 4),
        };
        let i_hi = i_lo + count - 1;
        let folds = self.boundary == SplineBoundary::LinearExtrapolation;
        let (lo, hi) = folded_range(i_lo, i_hi, n, folds);
        out.first = lo as usize;
        out.len = (hi - lo + 1) as usize;
        for i in i_lo..=i_hi {
            let (s, ds) = spline(self.degree, t_c - i as f64);
            let ds = ds / h;
            add_folded(out, i, lo, n, folds, s, ds);
        }
        Ok(())
    }
}

/// The nodes inside the grid that spline nodes `i_lo..=i_hi` reach on a grid whose last node is
/// `n`, widened (if `folds`) to the two an extrapolated node folds onto.
pub(super) fn folded_range(i_lo: i64, i_hi: i64, n: i64, folds: bool) -> (i64, i64) {
    let mut lo = i_lo.max(0);
    let mut hi = i_hi.min(n);
    if folds && i_lo < 0 {
        hi = hi.max(1.min(n));
    }
    if folds && i_hi > n {
        lo = lo.min((n - 1).max(0));
    }
    (lo, hi)
}

/// Add node `i`'s weight `s` and gradient `ds` to `out` (whose first node is `lo`): as they
/// are inside the grid, else (if `folds`) folded onto the edge node and its inner neighbour
/// by linear extrapolation (the module documentation), else dropped.
#[inline]
pub(super) fn add_folded(out: &mut AxisWeights, i: i64, lo: i64, n: i64, folds: bool, s: f64, ds: f64) {
    if (0..=n).contains(&i) {
        let k = (i - lo) as usize;
        out.w[k] += s;
        out.dw[k] += ds;
        return;
    }
    #[cfg(feature = "seeded-bugs")]
    if crate::seeded::active(crate::seeded::Bug::SplineWithoutBoundary) {
        return;
    }
    if !folds || n < 1 {
        return;
    }
    // Node i beyond the grid: k nodes past the edge node e, folded onto e and its inner
    // neighbour f as u_i = (1 + k) u_e − k u_f.
    let (e, f, k) = if i < 0 { (0, 1, -i) } else { (n, n - 1, i - n) };
    let (ke, kf) = ((e - lo) as usize, (f - lo) as usize);
    let k = k as f64;
    out.w[ke] += (1.0 + k) * s;
    out.dw[ke] += (1.0 + k) * ds;
    out.w[kf] -= k * s;
    out.dw[kf] -= k * ds;
}
