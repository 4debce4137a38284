//! Invariants of the weighting functions (MPM and GIMP, 1D and 2D): partition of unity,
//! zero gradient sum, linear reproduction, the per-element split of eqs (7)–(10) against the
//! closed-form GIMP weight, and continuity across element edges.

use crate::common;

use common::Rng;
use igimp::basis::{gimp_element_weights, AxisWeights, Basis, GridAxis, Support};
use igimp::mesh::grid::Grid;
use nalgebra::{SMatrix, SVector};

/// Closed-form uGIMP weight of a node at distance `d` for a domain of half-length `lp <= h/2`
/// (Bardenhagen & Kober 2004, eq 40), an independent reference for the per-element split.
fn ugimp_closed_form(d: f64, h: f64, lp: f64) -> f64 {
    let d = d.abs();
    if d < lp {
        1.0 - (d * d + lp * lp) / (2.0 * h * lp)
    } else if d <= h - lp {
        1.0 - d / h
    } else if d < h + lp {
        (h + lp - d).powi(2) / (4.0 * h * lp)
    } else {
        0.0
    }
}

fn sums<const D: usize>(
    grid: &Grid<D>,
    sup: &Support<D>,
) -> (f64, SVector<f64, D>, SVector<f64, D>, SMatrix<f64, D, D>) {
    let mut s = 0.0;
    let mut g = SVector::<f64, D>::zeros();
    let mut xs = SVector::<f64, D>::zeros();
    let mut xg = SMatrix::<f64, D, D>::zeros();
    for k in 0..sup.len() {
        let (n, w, grad) = sup.node(grid, k);
        let xn = grid.node_position(n);
        s += w;
        g += grad;
        xs += xn * w;
        xg += xn * grad.transpose();
    }
    (s, g, xs, xg)
}

fn random_interior_points<const D: usize>(
    grid: &Grid<D>,
    rng: &mut Rng,
    n: usize,
    max_half: f64,
) -> Vec<(SVector<f64, D>, SVector<f64, D>)> {
    let h = grid.spacing();
    (0..n)
        .map(|_| {
            let r = SVector::<f64, D>::from_fn(|a, _| rng.uniform(0.01, max_half) * h[a]);
            let x =
                SVector::<f64, D>::from_fn(|a, _| rng.uniform(grid.origin()[a] + r[a], grid.upper(a) - r[a]));
            (x, r)
        })
        .collect()
}

fn check_invariants<const D: usize>(grid: &Grid<D>, basis: Basis, seed: u64) {
    let mut rng = Rng::new(seed);
    let mut sup = Support::<D>::default();
    // Half-lengths up to 0.9 h: domains up to 1.8 elements long touch up to 4 nodes per axis.
    for (x, r) in random_interior_points(grid, &mut rng, 2000, 0.9) {
        basis.evaluate(grid, &x, &r, &mut sup).unwrap();
        let (s, g, xs, xg) = sums(grid, &sup);
        let scale = 1.0 / grid.spacing()[0];
        assert!(
            (s - 1.0).abs() < 1e-13,
            "{basis:?}: partition of unity {s} at {x:?}"
        );
        assert!(g.norm() < 1e-12 * scale, "{basis:?}: gradient sum {g:?} at {x:?}");
        // Linear reproduction: Σ S_v x_v = x_p and Σ x_v ⊗ ∇S_v = I.
        assert!(
            (xs - x).norm() < 1e-12 * (1.0 + x.norm()),
            "{basis:?}: Σ S x = {xs:?} != {x:?}"
        );
        assert!(
            (xg - SMatrix::<f64, D, D>::identity()).norm() < 1e-11,
            "{basis:?}: Σ x ⊗ ∇S = {xg:?}"
        );
        for k in 0..sup.len() {
            assert!(sup.node(grid, k).1 >= -1e-15, "negative weight");
        }
    }
}

/// Partition of unity, Σ∇S = 0 and linear reproduction at 2000 seeded random points in 1D.
#[test]
fn mpm_and_gimp_1d_partition_of_unity_and_linear_reproduction() {
    let grid = Grid::try_new([-1.5], [0.37], [20]).unwrap();
    check_invariants(&grid, Basis::Mpm, 1);
    check_invariants(&grid, Basis::Gimp, 2);
}

/// The same invariants in 2D (tensor product of the 1D weights), anisotropic spacing.
#[test]
fn mpm_and_gimp_2d_partition_of_unity_and_linear_reproduction() {
    let grid = Grid::try_new([0.0, -2.0], [0.5, 0.25], [10, 16]).unwrap();
    check_invariants(&grid, Basis::Mpm, 3);
    check_invariants(&grid, Basis::Gimp, 4);
}

/// Summing the per-element weights of eqs (7)–(10) over the elements a domain overlaps gives
/// the closed-form GIMP weight and its derivative (Bardenhagen & Kober 2004).
#[test]
fn gimp_per_element_split_sums_to_closed_form_weight() {
    let h = 0.8;
    let mut rng = Rng::new(5);
    let mut ax = AxisWeights::default();
    for _ in 0..2000 {
        let lp = rng.uniform(0.01, 0.5) * h;
        let x = rng.uniform(lp, 8.0 - lp);
        Basis::Gimp
            .axis_weights(
                GridAxis {
                    axis: 0,
                    origin: 0.0,
                    spacing: h,
                    cells: 10,
                },
                x,
                lp,
                &mut ax,
            )
            .unwrap();
        for k in 0..ax.len {
            let xv = (ax.first + k) as f64 * h;
            let exact = ugimp_closed_form(x - xv, h, lp);
            assert!(
                (ax.w[k] - exact).abs() < 1e-13,
                "S at x={x}, lp={lp}: {} vs {exact}",
                ax.w[k]
            );
            let eps = 1e-6 * h;
            let fd = (ugimp_closed_form(x + eps - xv, h, lp) - ugimp_closed_form(x - eps - xv, h, lp))
                / (2.0 * eps);
            // Eq (4): ∇S_vp = (1/V_p)∫χ_p ∇N_v = ∂S_vp/∂x_p, which the closed form gives by differences.
            assert!(
                (ax.dw[k] - fd).abs() < 1e-6 / h,
                "dS at x={x}, lp={lp}: {} vs {fd}",
                ax.dw[k]
            );
        }
    }
}

/// Eqs (7) and (10) for a domain wholly inside an element reduce to the linear shape
/// function and its derivative at the point (the "constant gradient" zone of Figure 5).
#[test]
fn gimp_element_weights_inside_element_equal_fem_shape_functions() {
    let h = 2.0;
    for &(xi, l_local) in &[(0.0, 0.5), (0.3, 0.2), (-0.6, 0.7)] {
        let (sa, sb, dsa, dsb) = gimp_element_weights(xi, l_local, l_local * h / 2.0);
        assert!((sa - 0.5 * (1.0 - xi)).abs() < 1e-15);
        assert!((sb - 0.5 * (1.0 + xi)).abs() < 1e-15);
        assert!((dsa + 1.0 / h).abs() < 1e-15 && (dsb - 1.0 / h).abs() < 1e-15);
    }
}

/// GIMP weights and gradients are continuous as a point crosses an element edge; MPM's
/// gradients jump there (the cell-crossing error GIMP removes, §2.1).
#[test]
fn gimp_continuous_across_element_edges_mpm_gradient_jumps() {
    let h = 1.0;
    let grid = Grid::try_new([0.0], [h], [8]).unwrap();
    let r = SVector::<f64, 1>::new(0.25);
    let eps = 1e-9;
    let node_values = |basis: Basis, x: f64| {
        let mut sup = Support::<1>::default();
        basis
            .evaluate(&grid, &SVector::<f64, 1>::new(x), &r, &mut sup)
            .unwrap();
        let mut w = [0.0; 9];
        let mut g = [0.0; 9];
        for k in 0..sup.len() {
            let (n, s, d) = sup.node(&grid, k);
            w[n] = s;
            g[n] = d[0];
        }
        (w, g)
    };
    for edge in [2.0, 3.0, 5.0] {
        // Crossing of the point itself and of each domain end over the edge.
        for x in [edge, edge - r[0], edge + r[0]] {
            let (w0, g0) = node_values(Basis::Gimp, x - eps);
            let (w1, g1) = node_values(Basis::Gimp, x + eps);
            for n in 0..9 {
                assert!((w0[n] - w1[n]).abs() < 1e-8, "GIMP weight jumps at {x}");
                assert!((g0[n] - g1[n]).abs() < 1e-7, "GIMP gradient jumps at {x}");
            }
        }
        let (_, g0) = node_values(Basis::Mpm, edge - eps);
        let (_, g1) = node_values(Basis::Mpm, edge + eps);
        let jump: f64 = (0..9).map(|n| (g0[n] - g1[n]).abs()).sum();
        assert!(jump > 1.0 / h, "MPM gradient should jump at an element edge");
    }
}

const AXIS: GridAxis = GridAxis {
    axis: 0,
    origin: 0.0,
    spacing: 1.0,
    cells: 4,
};

/// A point outside the grid and a collapsed domain are errors, not silent weights.
#[test]
fn points_outside_grid_and_degenerate_domains_are_errors() {
    let mut ax = AxisWeights::default();
    for (x, r) in [
        (-0.1, 0.2),
        (4.1, 0.2),
        (2.0, 0.0),
        (2.0, -0.1),
        (2.0, f64::NAN),
        (f64::NAN, 0.1),
    ] {
        assert!(
            Basis::Gimp.axis_weights(AXIS, x, r, &mut ax).is_err(),
            "GIMP ({x}, {r})"
        );
    }
    for x in [-0.1, 4.1, f64::NAN] {
        assert!(Basis::Mpm.axis_weights(AXIS, x, 0.2, &mut ax).is_err(), "MPM {x}");
    }
    // A domain may touch at most MAX_AXIS_NODES - 1 = 4 elements: [2.9, 7.1] touches 6.
    let wide = igimp::basis::GridAxis { cells: 10, ..AXIS };
    assert!(
        Basis::Gimp.axis_weights(wide, 5.0, 2.1, &mut ax).is_err(),
        "domain too long"
    );
    assert!(
        Basis::Gimp.axis_weights(wide, 5.0, 1.4, &mut ax).is_ok(),
        "3-element domain"
    );
}

/// A domain protruding past the grid boundary (a rigid wall or symmetry plane) is cut at it,
/// eq (3)'s Ω_p ∩ Ω, and the weights of the remaining part still form a partition of unity
/// with zero gradient sum.
#[test]
fn gimp_domain_is_clipped_at_the_grid_boundary() {
    let mut ax = AxisWeights::default();
    for (x, r) in [(0.1, 0.2), (3.95, 0.2), (0.05, 0.3)] {
        Basis::Gimp.axis_weights(AXIS, x, r, &mut ax).unwrap();
        let s: f64 = ax.w[..ax.len].iter().sum();
        let g: f64 = ax.dw[..ax.len].iter().sum();
        assert!((s - 1.0).abs() < 1e-14 && g.abs() < 1e-13, "({x}, {r}): {s} {g}");
        // Equal to the weights of the clipped domain itself.
        let (lo, hi) = ((x - r).max(0.0), (x + r).min(4.0));
        let mut clipped = AxisWeights::default();
        Basis::Gimp
            .axis_weights(AXIS, 0.5 * (lo + hi), 0.5 * (hi - lo), &mut clipped)
            .unwrap();
        assert_eq!(ax.len, clipped.len);
        for k in 0..ax.len {
            assert!((ax.w[k] - clipped.w[k]).abs() < 1e-14);
        }
    }
}

/// The same invariants in 3D (tensor product of the per-element 1D split), anisotropic spacing.
#[test]
fn mpm_and_gimp_3d_partition_of_unity_and_linear_reproduction() {
    let grid = Grid::try_new([0.0, -1.0, 0.5], [0.5, 0.25, 0.4], [6, 8, 5]).unwrap();
    check_invariants(&grid, Basis::Mpm, 5);
    check_invariants(&grid, Basis::Gimp, 6);
}
