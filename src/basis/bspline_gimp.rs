//! Domain-integrated B-splines ("B-spline GIMP" in NairnMPM): the uniform quadratic and cubic
//! splines of [`bspline`](super::bspline) averaged over each point's domain x_p ± r, as GIMP
//! averages the hat (eq 3 with the top hat of eq 6):
//!
//! S̄_v(x_p, r) = (1/2r) ∫ S_v(x) dx over [x_p − r, x_p + r],
//! ∂S̄_v/∂x_p = (S_v(x_p + r) − S_v(x_p − r)) / 2r.
//!
//! Both are closed forms: the spline is piecewise polynomial, so the average is a difference of
//! its antiderivative ([`spline_integral`]), exact to round-off (no quadrature). With domains
//! that tile the material, Σ_p V_p ∂S̄_vp is the exact integral of ∂S_v over it (the patch test
//! holds exactly, tests/verification/patch.rs), where point evaluation leaves a quadrature error
//! that stalls the point-evaluated splines' stress error on the column (reference/README.md
//! item 39).
//!
//! Boundary. Nodes beyond the grid are folded onto the two nodes inside by the linear
//! extrapolation of [`bspline`](super::bspline) (u₋ₖ = (1 + k) u₀ − k u₁). The fold is linear
//! in the weights, so it commutes with the average: each node inside the grid carries an
//! extended spline defined on the whole line, whose average keeps Σ S̄ = 1 and Σ S̄ x_v = x_p
//! exactly also for a domain that reaches past the grid's edge. The domain is therefore not cut
//! to the grid as GIMP's is (eq 3's Ω_p ∩ Ω): cutting would move the reproduced point to the
//! centre of the cut domain. Past the edge the extrapolated splines are not all non-negative
//! (node 1's falls below zero beyond node 0), so a domain that reaches across the edge may give
//! node 1 a slightly negative weight; a domain inside the grid, as every domain starts
//! (`MpmSolver::try_new` requires it), has non-negative weights.
//!
//! Tangent. As for GIMP (`has_domain`, so the domain update rule applies), the weights are those
//! of the start of the load step and the domain is updated only when the step is committed
//! (eqs 37/39, src/mpm.rs `commit`); within the step the kernel enters the consistent tangent
//! through ∂S̄/∂x mapped by ΔF⁻¹ (eq 36) alone, so nothing beyond the weights and their gradient
//! is needed (no derivative with respect to r).

use super::bspline::{add_folded, folded_range, spline, SplineDegree};
use super::{AxisKernel, AxisWeights, BasisError, GridAxis, MAX_AXIS_NODES};

/// ∫ N(s) ds from −∞ to `t` of the centred uniform spline N of [`spline`] (t in units of h):
/// 0 below the support, 1 above it.
#[inline]
pub fn spline_integral(degree: SplineDegree, t: f64) -> f64 {
    // The spline is even, so G(t) = 1 − G(−t); the left half is written out.
    let left = |u: f64| -> f64 {
        match degree {
            SplineDegree::Quadratic => {
                if u <= -1.5 {
                    0.0
                } else if u <= -0.5 {
                    let b = u + 1.5;
                    b * b * b / 6.0
                } else {
                    // G(−1/2) = 1/6 plus ∫ (3/4 − s²) ds from −1/2 to u.
                    1.0 / 6.0 + 0.75 * (u + 0.5) - (u * u * u + 0.125) / 3.0
                }
            }
            SplineDegree::Cubic => {
                if u <= -2.0 {
                    0.0
                } else if u <= -1.0 {
                    let b = u + 2.0;
                    b * b * b * b / 24.0
                } else {
                    // G(−1) = 1/24 plus ∫ (2/3 − s² − s³/2) ds from −1 to u (s ≤ 0).
                    let u2 = u * u;
                    1.0 / 24.0 + 2.0 / 3.0 * (u + 1.0) - (u2 * u + 1.0) / 3.0 - (u2 * u2 - 1.0) / 8.0
                }
            }
        }
    };
    if t <= 0.0 {
        left(t)
    } else {
        1.0 - left(-t)
    }
}

/// The domain-averaged B-spline kernel along one axis.
#[derive(Debug, Clone, Copy)]
pub struct BsplineGimpKernel {
    pub degree: SplineDegree,
}

impl BsplineGimpKernel {
    /// Half-width of a node's spline in units of h: 1.5 (quadratic), 2 (cubic).
    fn reach(&self) -> f64 {
        match self.degree {
            SplineDegree::Quadratic => 1.5,
            SplineDegree::Cubic => 2.0,
        }
    }

    /// The spline knot nearest `t` (grid units): half-integers for the quadratic (its pieces
    /// meet at x_v ± h/2, x_v ± 3h/2), integers for the cubic.
    fn nearest_knot(&self, t: f64) -> f64 {
        match self.degree {
            SplineDegree::Quadratic => (t - 0.5).round() + 0.5,
            SplineDegree::Cubic => t.round(),
        }
    }
}

impl AxisKernel for BsplineGimpKernel {
    /// With a cell-sized domain (r = h/2) a node is reached within 2h (quadratic) or 2.5h
    /// (cubic) of the point: 4 or 5 nodes in general position.
    fn support_nodes(&self) -> usize {
        match self.degree {
            SplineDegree::Quadratic => 4,
            SplineDegree::Cubic => 5,
        }
    }

    fn has_domain(&self) -> bool {
        true
    }

    /// The reach less one cell, as for the point-evaluated splines
    /// ([`super::BsplineKernel`]'s rule): a point reaches the nodes within 1.5h + r (2h + r) of
    /// it, so a box of r + h/2 (r + h) overlaps a cell of every node it reaches and the ghost
    /// penalty sees each of them.
    fn fill_half_width(&self, spacing: f64, r: f64) -> Option<f64> {
        Some(r + (self.reach() - 1.0) * spacing)
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
        let t_c = (x - origin) / h;
        if !(t_c >= -1e-12 && t_c <= cells as f64 + 1e-12) {
            return Err(BasisError::OutsideGrid { axis });
        }
        // Domain edges within 1e-10 of a knot are snapped onto it (as GIMP snaps them onto grid
        // lines): tiled domains end on knots, and an edge a round-off past one would give the
        // node whose spline starts there a weight of order (1e-16)³ and so a singular row.
        let snap = |t: f64| {
            let k = self.nearest_knot(t);
            if (t - k).abs() < 1e-10 {
                k
            } else {
                t
            }
        };
        let t_lo = snap((x - r - origin) / h);
        let t_hi = snap((x + r - origin) / h);
        let width = t_hi - t_lo; // 2r/h
        if width <= 0.0 {
            return Err(BasisError::DegenerateDomain { axis });
        }
        // The nodes whose spline overlaps the domain: |t − i| < reach for some t in it, an open
        // interval of 2r/h + 2 reach, so at most that many nodes wherever the point is. The
        // limit is set on the length, not on the count at this position, so that whether a
        // domain is too long does not depend on where it lies: r ≤ h (quadratic), h/2 (cubic).
        let reach = self.reach();
        if width + 2.0 * reach > MAX_AXIS_NODES as f64 {
            return Err(BasisError::DomainTooLarge { axis });
        }
        let i_lo = (t_lo - reach).floor() as i64 + 1;
        let i_hi = (t_hi + reach).ceil() as i64 - 1;
        debug_assert!(i_hi - i_lo < MAX_AXIS_NODES as i64);
        // The last node; the nodes inside the grid, widened to the two an extrapolated node
        // folds onto (as src/basis/bspline.rs).
        let n = cells as i64;
        let (lo, hi) = folded_range(i_lo, i_hi, n, true);
        out.first = lo as usize;
        out.len = (hi - lo + 1) as usize;
        for i in i_lo..=i_hi {
            let (a, b) = (t_lo - i as f64, t_hi - i as f64);
            let s = (spline_integral(self.degree, b) - spline_integral(self.degree, a)) / width;
            let ds = (spline(self.degree, b).0 - spline(self.degree, a).0) / (width * h);
            add_folded(out, i, lo, n, true, s, ds);
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::basis::{BsplineKernel, SplineBoundary};

    const DEGREES: [SplineDegree; 2] = [SplineDegree::Quadratic, SplineDegree::Cubic];

    /// A grid axis of 7 cells whose origin and spacing are not binary fractions, so that
    /// positions carry round-off.
    const AXIS: GridAxis = GridAxis {
        axis: 0,
        origin: -0.3,
        spacing: 0.7,
        cells: 7,
    };

    /// A deterministic sequence in [0, 1) (golden-ratio steps) for sample positions.
    fn samples(count: usize, seed: f64) -> impl Iterator<Item = f64> {
        (0..count).map(move |k| (seed + k as f64 * 0.618_033_988_749_894_9).fract())
    }

    /// Gauss–Legendre nodes and weights on [−1, 1] (Newton on the Legendre recurrence).
    fn gauss_legendre(n: usize) -> Vec<(f64, f64)> {
        let mut out = Vec::with_capacity(n);
        for k in 0..n {
            let mut z = (std::f64::consts::PI * (k as f64 + 0.75) / (n as f64 + 0.5)).cos();
            let mut dp = 0.0;
            for _ in 0..100 {
                let (mut p0, mut p1) = (1.0, z);
                for j in 2..=n {
                    let p2 = ((2 * j - 1) as f64 * z * p1 - (j - 1) as f64 * p0) / j as f64;
                    p0 = p1;
                    p1 = p2;
                }
                dp = n as f64 * (z * p1 - p0) / (z * z - 1.0);
                let dz = p1 / dp;
                z -= dz;
                if dz.abs() < 1e-16 {
                    break;
                }
            }
            out.push((z, 2.0 / ((1.0 - z * z) * dp * dp)));
        }
        out
    }

    /// The point-evaluated spline weights of every grid node at grid coordinate `t`, nodes
    /// beyond the grid folded by linear extrapolation, for any `t` (also outside the grid,
    /// where the folded splines extend the ones inside): written independently of the kernel.
    fn folded_point(degree: SplineDegree, t: f64, cells: usize) -> Vec<f64> {
        let n = cells as i64;
        let mut w = vec![0.0; cells + 1];
        for i in (t.floor() as i64 - 3)..=(t.ceil() as i64 + 3) {
            let s = spline(degree, t - i as f64).0;
            if i < 0 {
                w[0] += (1 - i) as f64 * s;
                w[1] += i as f64 * s;
            } else if i > n {
                w[cells] += (1 + i - n) as f64 * s;
                w[cells - 1] -= (i - n) as f64 * s;
            } else {
                w[i as usize] += s;
            }
        }
        w
    }

    /// Dense weights and gradients over the grid's nodes of a point at `x` with half-length `r`.
    fn averaged(degree: SplineDegree, x: f64, r: f64) -> (Vec<f64>, Vec<f64>) {
        let mut w = AxisWeights::default();
        BsplineGimpKernel { degree }
            .axis_weights(AXIS, x, r, &mut w)
            .unwrap();
        let (mut s, mut g) = (vec![0.0; AXIS.cells + 1], vec![0.0; AXIS.cells + 1]);
        for k in 0..w.len {
            s[w.first + k] = w.w[k];
            g[w.first + k] = w.dw[k];
        }
        (s, g)
    }

    /// Points over the whole axis with half-lengths 0.02h to 0.5h; a quarter of them within
    /// one cell of an edge, where domains reach across it.
    fn points(count: usize) -> Vec<(f64, f64)> {
        let h = AXIS.spacing;
        let len = AXIS.cells as f64 * h;
        samples(count, 0.3)
            .zip(samples(count, 0.77))
            .enumerate()
            .map(|(k, (u, v))| {
                let x = match k % 8 {
                    0 => AXIS.origin + u * h,
                    1 => AXIS.origin + len - u * h,
                    _ => AXIS.origin + u * len,
                };
                (x, h * (0.02 + 0.48 * v))
            })
            .collect()
    }

    /// The antiderivative against a 2000-point Gauss–Legendre rule on every unit piece.
    #[test]
    fn spline_integral_is_the_antiderivative() {
        let rule = gauss_legendre(2000);
        for degree in DEGREES {
            let reach = BsplineGimpKernel { degree }.reach();
            assert_eq!(spline_integral(degree, -reach), 0.0);
            assert_eq!(spline_integral(degree, reach), 1.0);
            assert!((spline_integral(degree, 0.0) - 0.5).abs() < 1e-15);
            for t in samples(40, 0.1).map(|u| -reach + 2.0 * reach * u) {
                let mut sum = 0.0;
                let mut a = -reach;
                while a < t {
                    let b = (a + 0.5).min(t);
                    let (m, half) = (0.5 * (a + b), 0.5 * (b - a));
                    sum += half
                        * rule
                            .iter()
                            .map(|&(z, w)| w * spline(degree, m + half * z).0)
                            .sum::<f64>();
                    a = b;
                }
                let g = spline_integral(degree, t);
                assert!((g - sum).abs() < 1e-13, "{degree:?} at {t}: {g} against {sum}");
            }
        }
    }

    /// The test's folded point spline is the point-evaluated kernel's inside the grid.
    #[test]
    fn folded_point_weights_are_the_point_kernels() {
        for degree in DEGREES {
            let kernel = BsplineKernel {
                degree,
                boundary: SplineBoundary::LinearExtrapolation,
            };
            for (x, _) in points(80) {
                let mut w = AxisWeights::default();
                kernel.axis_weights(AXIS, x, 0.0, &mut w).unwrap();
                let mine = folded_point(degree, (x - AXIS.origin) / AXIS.spacing, AXIS.cells);
                for (v, m) in mine.iter().enumerate() {
                    let k = v.wrapping_sub(w.first);
                    let theirs = if k < w.len { w.w[k] } else { 0.0 };
                    assert!((m - theirs).abs() < 1e-14, "{degree:?} x {x} node {v}");
                }
            }
        }
    }

    /// The averaged weights equal a 2000-point Gauss–Legendre quadrature, on every knot span
    /// of the domain, of the point-evaluated folded spline weights, to 1e-12: interior points,
    /// points near the edges and domains across them.
    #[test]
    fn averaged_weights_equal_quadrature_of_the_point_spline() {
        let rule = gauss_legendre(2000);
        let h = AXIS.spacing;
        for degree in DEGREES {
            for (x, r) in points(64) {
                let (s, _) = averaged(degree, x, r);
                let (t_lo, t_hi) = ((x - r - AXIS.origin) / h, (x + r - AXIS.origin) / h);
                // Split the domain at every half-integer (both degrees' knots are among them).
                let mut cuts = vec![t_lo];
                let mut k = (2.0 * t_lo).floor() + 1.0;
                while 0.5 * k < t_hi {
                    cuts.push(0.5 * k);
                    k += 1.0;
                }
                cuts.push(t_hi);
                let mut quad = [0.0; AXIS.cells + 1];
                for span in cuts.windows(2) {
                    let (m, half) = (0.5 * (span[0] + span[1]), 0.5 * (span[1] - span[0]));
                    for &(z, wq) in &rule {
                        let pw = folded_point(degree, m + half * z, AXIS.cells);
                        for (q, p) in quad.iter_mut().zip(pw) {
                            *q += wq * half * p;
                        }
                    }
                }
                for (v, q) in quad.iter().enumerate() {
                    let expect = q / (t_hi - t_lo);
                    assert!(
                        (s[v] - expect).abs() < 1e-12,
                        "{degree:?} x {x} r {r} node {v}: {} against {expect}",
                        s[v]
                    );
                }
            }
        }
    }

    /// ∂S̄/∂x_p equals central differences of the averaged weights (step 1e-6 h).
    #[test]
    fn gradient_equals_differences_of_the_weights() {
        let d = 1e-6 * AXIS.spacing;
        for degree in DEGREES {
            for (x, r) in points(200) {
                let x = x.clamp(
                    AXIS.origin + d,
                    AXIS.origin + AXIS.cells as f64 * AXIS.spacing - d,
                );
                let (_, g) = averaged(degree, x, r);
                let (sp, _) = averaged(degree, x + d, r);
                let (sm, _) = averaged(degree, x - d, r);
                for v in 0..g.len() {
                    let fd = (sp[v] - sm[v]) / (2.0 * d);
                    assert!(
                        (g[v] - fd).abs() < 1e-7 / AXIS.spacing,
                        "{degree:?} x {x} r {r} node {v}: {} against {fd}",
                        g[v]
                    );
                }
            }
        }
    }

    /// Σ S̄ = 1, Σ S̄ x_v = x_p, Σ ∂S̄ = 0 and Σ ∂S̄ x_v = 1 to 1e-12, at the edges and for
    /// domains across them too.
    #[test]
    fn weights_partition_unity_and_reproduce_linear_fields() {
        for degree in DEGREES {
            for (x, r) in points(400) {
                let (s, g) = averaged(degree, x, r);
                let xv = |v: usize| AXIS.origin + v as f64 * AXIS.spacing;
                let sum: f64 = s.iter().sum();
                let first: f64 = s.iter().enumerate().map(|(v, w)| w * xv(v)).sum();
                let gsum: f64 = g.iter().sum();
                let gfirst: f64 = g.iter().enumerate().map(|(v, w)| w * xv(v)).sum();
                assert!((sum - 1.0).abs() < 1e-12, "{degree:?} x {x} r {r}: Σ S {sum}");
                assert!(
                    (first - x).abs() < 1e-12,
                    "{degree:?} x {x} r {r}: Σ S x_v {first}"
                );
                assert!(gsum.abs() < 1e-12, "{degree:?} x {x} r {r}: Σ ∂S {gsum}");
                assert!(
                    (gfirst - 1.0).abs() < 1e-12,
                    "{degree:?} x {x} r {r}: Σ ∂S x_v {gfirst}"
                );
                // Non-negative while the domain is inside the grid (an average of the folded
                // point weights, which are); past the edge the extrapolated spline is not.
                let (t_lo, t_hi) = (
                    (x - r - AXIS.origin) / AXIS.spacing,
                    (x + r - AXIS.origin) / AXIS.spacing,
                );
                if t_lo >= 0.0 && t_hi <= AXIS.cells as f64 {
                    assert!(s.iter().all(|&w| w >= -1e-15), "{degree:?} x {x} r {r}: {s:?}");
                }
            }
        }
    }

    /// As r → 0 the weights tend to the point-evaluated spline's (|S̄ − S| ≤ max|S''| r²/6h²)
    /// and the gradients to its gradient (≤ max|S''| r/h²).
    #[test]
    fn vanishing_domains_give_the_point_spline() {
        let h = AXIS.spacing;
        for degree in DEGREES {
            let kernel = BsplineKernel {
                degree,
                boundary: SplineBoundary::LinearExtrapolation,
            };
            for (x, _) in points(100) {
                let mut p = AxisWeights::default();
                kernel.axis_weights(AXIS, x, 0.0, &mut p).unwrap();
                for rho in [1e-2, 1e-3, 1e-4] {
                    let (s, g) = averaged(degree, x, rho * h);
                    let mut err = 0.0f64;
                    let mut gerr = 0.0f64;
                    for v in 0..s.len() {
                        let k = v.wrapping_sub(p.first);
                        let (ps, pg) = if k < p.len { (p.w[k], p.dw[k]) } else { (0.0, 0.0) };
                        err = err.max((s[v] - ps).abs());
                        gerr = gerr.max((g[v] - pg).abs() * h);
                    }
                    assert!(
                        err <= 2.0 * rho * rho + 1e-13 / rho,
                        "{degree:?} x {x} rho {rho}: {err}"
                    );
                    assert!(
                        gerr <= 10.0 * rho + 1e-13 / rho,
                        "{degree:?} x {x} rho {rho}: {gerr}"
                    );
                }
            }
        }
    }

    /// Tiled domains end on knots (2 points per cell: edges on cell faces and mid-cells); the
    /// snap keeps a round-off overlap from adding a node: exactly 3 (quadratic) and 4 (cubic)
    /// nodes, each with a weight well above round-off.
    #[test]
    fn domains_ending_on_knots_add_no_round_off_nodes() {
        let h = AXIS.spacing;
        for (degree, nodes) in [(SplineDegree::Quadratic, 3), (SplineDegree::Cubic, 4)] {
            for cell in 2..5 {
                for frac in [0.25, 0.75] {
                    let x = AXIS.origin + (cell as f64 + frac) * h;
                    let mut w = AxisWeights::default();
                    BsplineGimpKernel { degree }
                        .axis_weights(AXIS, x, 0.25 * h, &mut w)
                        .unwrap();
                    assert_eq!(w.len, nodes, "{degree:?} at cell {cell} + {frac}: {w:?}");
                    assert!(w.w[..w.len].iter().all(|&s| s > 1e-3), "{degree:?}: {w:?}");
                }
            }
        }
    }

    /// Collapsed domains and points off the grid are errors; so is a domain that could reach
    /// more than [`MAX_AXIS_NODES`] nodes: the quadratic takes r up to h, the cubic up to h/2.
    #[test]
    fn invalid_points_and_domains_are_errors() {
        let h = AXIS.spacing;
        let mid = AXIS.origin + 3.5 * h;
        let mut w = AxisWeights::default();
        for degree in DEGREES {
            let k = BsplineGimpKernel { degree };
            for r in [0.0, -0.1, f64::NAN, f64::INFINITY] {
                assert_eq!(
                    k.axis_weights(AXIS, mid, r, &mut w),
                    Err(BasisError::DegenerateDomain { axis: 0 })
                );
            }
            for x in [AXIS.origin - 0.01 * h, AXIS.origin + 7.01 * h, f64::NAN] {
                assert_eq!(
                    k.axis_weights(AXIS, x, 0.2 * h, &mut w),
                    Err(BasisError::OutsideGrid { axis: 0 })
                );
            }
        }
        let quadratic = BsplineGimpKernel {
            degree: SplineDegree::Quadratic,
        };
        let cubic = BsplineGimpKernel {
            degree: SplineDegree::Cubic,
        };
        assert!(quadratic.axis_weights(AXIS, mid, 0.99 * h, &mut w).is_ok());
        assert_eq!(
            quadratic.axis_weights(AXIS, mid, 1.01 * h, &mut w),
            Err(BasisError::DomainTooLarge { axis: 0 })
        );
        assert!(cubic.axis_weights(AXIS, mid, 0.49 * h, &mut w).is_ok());
        // Too long wherever it lies: at 3.5h it would reach 6 nodes, at 3.3h 5.
        for x in [mid, AXIS.origin + 3.3 * h] {
            assert_eq!(
                cubic.axis_weights(AXIS, x, 0.51 * h, &mut w),
                Err(BasisError::DomainTooLarge { axis: 0 })
            );
        }
    }
}
