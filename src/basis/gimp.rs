//! GIMP with a top-hat characteristic function (eq 6), the domain split per background element
//! (eqs 7–10): the paper's basis.

use super::{AxisKernel, AxisWeights, BasisError, GridAxis, MAX_AXIS_NODES};

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

/// The GIMP kernel along one axis: the domain x ± r cut to the grid (eq 3's Ω_p ∩ Ω) and
/// integrated against the linear hats element by element.
#[derive(Debug, Clone, Copy, Default)]
pub struct GimpKernel;

impl AxisKernel for GimpKernel {
    fn support_nodes(&self) -> usize {
        3
    }

    fn has_domain(&self) -> bool {
        true
    }

    fn axis_weights(
        &self,
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
        if !(r > 0.0 && r.is_finite()) {
            return Err(BasisError::DegenerateDomain { axis });
        }
        // Work in grid units t = (x − origin)/h, where element e spans [e, e + 1]. Domain
        // edges within 1e-10 of a grid line are snapped onto it, so a domain that ends on an
        // element edge does not touch the next element with a round-off sized (and so
        // singular) share of the stiffness.
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
        // Eq (3) integrates over Ω_p ∩ Ω: the part of a domain beyond the grid (a rigid
        // boundary or symmetry plane of the problem) is cut off, and the weights are
        // normalised by the remaining length so that they still sum to one.
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
        Ok(())
    }
}
