//! Weighting functions S_vp and their gradients: plain MPM (point-evaluated linear hats) and
//! GIMP with the material-point domain split per background element (eqs 7–10).
//!
//! Both are computed one axis at a time ([`AxisWeights`]) and combined by tensor product
//! ([`Support`]), as the paper does for 2D (§2.2). Evaluation fills caller-owned values and
//! never allocates.

use crate::grid::Grid;
use nalgebra::SVector;
use serde::{Deserialize, Serialize};

/// Most nodes a point may touch along one axis: a GIMP domain up to two elements long.
pub const MAX_AXIS_NODES: usize = 5;

/// Which weighting functions to use.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Hash)]
#[serde(rename_all = "lowercase")]
pub enum Basis {
    /// Standard MPM: linear shape functions evaluated at the point, χ_p = δ V_p (eq 5).
    Mpm,
    /// GIMP with a top-hat characteristic function (eq 6), split per element (eqs 7–10).
    Gimp,
}

/// Weights along one axis: nodes `first .. first + len` with values `w` and derivatives `dw`
/// with respect to the grid coordinate.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct AxisWeights {
    pub first: usize,
    pub len: usize,
    pub w: [f64; MAX_AXIS_NODES],
    pub dw: [f64; MAX_AXIS_NODES],
}

/// Why weights could not be evaluated.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum BasisError {
    /// The point (or its domain) is not inside the grid along this axis.
    OutsideGrid { axis: usize },
    /// The domain spans more than `MAX_AXIS_NODES - 1` elements.
    DomainTooLarge { axis: usize },
    /// The domain half-length is not positive and finite (a collapsed GIMP domain).
    DegenerateDomain { axis: usize },
}

impl std::fmt::Display for BasisError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            BasisError::OutsideGrid { axis } => write!(f, "outside the background grid along axis {axis}"),
            BasisError::DomainTooLarge { axis } => {
                write!(
                    f,
                    "domain longer than {} elements along axis {axis}",
                    MAX_AXIS_NODES - 2
                )
            }
            BasisError::DegenerateDomain { axis } => {
                write!(f, "domain length collapsed to <= 0 along axis {axis}")
            }
        }
    }
}

/// GIMP weights of the two nodes of one element for the part of a domain inside it,
/// eqs (7)–(10).
///
/// `xi_p` is the point's local coordinate in the element (−1..1 spans the element), `l_local`
/// the full domain length in local units (2·2r/h) and `l_global` the full length in grid
/// units (2r). Returns `(S_a, S_b, ∂S_a/∂x, ∂S_b/∂x)` for the element's left node a and right
/// node b. Eq (7) divides by the local length and eq (10) by the global one; the paper uses
/// the symbol l_p for both (see reference/README.md).
#[inline]
pub fn gimp_element_weights(xi_p: f64, l_local: f64, l_global: f64) -> (f64, f64, f64, f64) {
    let xi1 = (xi_p - 0.5 * l_local).max(-1.0); // eq (8)
    let xi2 = (xi_p + 0.5 * l_local).min(1.0); // eq (9)
    if xi2 <= xi1 {
        return (0.0, 0.0, 0.0, 0.0);
    }
    let s_a = (2.0 * xi2 - xi2 * xi2 - 2.0 * xi1 + xi1 * xi1) / (4.0 * l_local);
    let s_b = (2.0 * xi2 + xi2 * xi2 - 2.0 * xi1 - xi1 * xi1) / (4.0 * l_local);
    let ds_a = (xi1 - xi2) / (2.0 * l_global);
    let ds_b = (xi2 - xi1) / (2.0 * l_global);
    (s_a, s_b, ds_a, ds_b)
}

/// One axis of a background grid.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GridAxis {
    /// Which axis (for error messages).
    pub axis: usize,
    pub origin: f64,
    /// Element size h.
    pub spacing: f64,
    pub cells: usize,
}

impl Basis {
    /// Weights along one grid axis for a point at `x` whose domain half-length is `r`
    /// (ignored by MPM).
    pub fn axis_weights(
        self,
        grid_axis: GridAxis,
        x: f64,
        r: f64,
        out: &mut AxisWeights,
    ) -> Result<(), BasisError> {
        let GridAxis {
            axis,
            origin,
            spacing: h,
            cells,
        } = grid_axis;
        *out = AxisWeights::default();
        match self {
            Basis::Mpm => {
                let upper = origin + h * cells as f64;
                if !(x >= origin - 1e-12 * h && x <= upper + 1e-12 * h) {
                    return Err(BasisError::OutsideGrid { axis });
                }
                let e = (((x - origin) / h).floor().max(0.0) as usize).min(cells - 1);
                let xi = 2.0 * (x - origin - (e as f64 + 0.5) * h) / h;
                out.first = e;
                out.len = 2;
                out.w[0] = 0.5 * (1.0 - xi);
                out.w[1] = 0.5 * (1.0 + xi);
                out.dw[0] = -1.0 / h;
                out.dw[1] = 1.0 / h;
            }
            Basis::Gimp => {
                if !(r > 0.0 && r.is_finite()) {
                    return Err(BasisError::DegenerateDomain { axis });
                }
                // Work in grid units t = (x − origin)/h, where element e spans [e, e + 1].
                // Domain edges within 1e-10 of a grid line are snapped onto it, so a domain
                // that ends on an element edge does not touch the next element with a
                // round-off sized (and so singular) share of the stiffness.
                let snap = |t: f64| {
                    if (t - t.round()).abs() < 1e-10 {
                        t.round()
                    } else {
                        t
                    }
                };
                let t_c = (x - origin) / h;
                if !(t_c >= -1e-12 && t_c <= cells as f64 + 1e-12) {
                    return Err(BasisError::OutsideGrid { axis });
                }
                // Eq (3) integrates over Ω_p ∩ Ω: the part of a domain beyond the grid (a
                // rigid boundary or symmetry plane of the problem) is cut off, and the weights
                // are normalised by the remaining length so that they still sum to one.
                let t_lo = snap((x - r - origin) / h).max(0.0);
                let t_hi = snap((x + r - origin) / h).min(cells as f64);
                if t_hi <= t_lo {
                    return Err(BasisError::DegenerateDomain { axis });
                }
                let e_lo = (t_lo.floor().max(0.0) as usize).min(cells - 1);
                let e_hi = ((t_hi.ceil().max(1.0) as usize) - 1).min(cells - 1).max(e_lo);
                if e_hi - e_lo + 2 > MAX_AXIS_NODES {
                    return Err(BasisError::DomainTooLarge { axis });
                }
                out.first = e_lo;
                out.len = e_hi - e_lo + 2;
                let l_global = h * (t_hi - t_lo);
                let l_local = 2.0 * (t_hi - t_lo);
                let t_c = 0.5 * (t_lo + t_hi);
                #[cfg(feature = "seeded-bugs")]
                if crate::seeded::active(crate::seeded::Bug::NoElementSplit) {
                    // The seeded mistake: eqs (7)-(10) with ξ1, ξ2 not clipped to the element
                    // (eqs 8-9) on the centre's element only.
                    let e = (t_c.floor().max(0.0) as usize).min(cells - 1);
                    let xi_p = 2.0 * (t_c - e as f64) - 1.0;
                    let (xi1, xi2) = (xi_p - 0.5 * l_local, xi_p + 0.5 * l_local);
                    *out = AxisWeights::default();
                    out.first = e;
                    out.len = 2;
                    out.w[0] = (2.0 * xi2 - xi2 * xi2 - 2.0 * xi1 + xi1 * xi1) / (4.0 * l_local);
                    out.w[1] = (2.0 * xi2 + xi2 * xi2 - 2.0 * xi1 - xi1 * xi1) / (4.0 * l_local);
                    out.dw[0] = (xi1 - xi2) / (2.0 * l_global);
                    out.dw[1] = (xi2 - xi1) / (2.0 * l_global);
                    return Ok(());
                }
                for e in e_lo..=e_hi {
                    let xi_p = 2.0 * (t_c - e as f64) - 1.0;
                    let (sa, sb, dsa, dsb) = gimp_element_weights(xi_p, l_local, l_global);
                    let k = e - e_lo;
                    out.w[k] += sa;
                    out.w[k + 1] += sb;
                    out.dw[k] += dsa;
                    out.dw[k + 1] += dsb;
                }
            }
        }
        Ok(())
    }

    /// Weights of a point at `x` with domain half-lengths `r` on `grid`, one axis at a time.
    pub fn evaluate<const D: usize>(
        self,
        grid: &Grid<D>,
        x: &SVector<f64, D>,
        r: &SVector<f64, D>,
        out: &mut Support<D>,
    ) -> Result<(), BasisError> {
        let (o, h, c) = (grid.origin(), grid.spacing(), grid.cells());
        for a in 0..D {
            let ga = GridAxis {
                axis: a,
                origin: o[a],
                spacing: h[a],
                cells: c[a],
            };
            self.axis_weights(ga, x[a], r[a], &mut out.axes[a])?;
        }
        Ok(())
    }
}

/// Tensor-product support of one point: the nodes it touches with their weights and gradients.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Support<const D: usize> {
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
