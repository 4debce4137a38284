//! Patch tests: a homogeneous finite deformation imposed on the grid nodes is reproduced at
//! every material point to round-off, and nodes whose support lies inside the material carry
//! no internal force (uniform stress is in equilibrium), for MPM and GIMP in 1D, 2D and 3D,
//! and for the domain-averaged B-splines.

use crate::common;
use igimp::basis::Basis;
use igimp::discretise::assembly::{DofMap, LoadStepSystem};
use igimp::material::constitutive::LinearElastic;
use igimp::mesh::grid::Grid;
use igimp::mpm::particles::MaterialPoints;
use igimp::mpm::MpmSolver;
use igimp::solver::linear::SparseSystem;
use igimp::solver::newton::NonlinearSystem;
use nalgebra::SMatrix;

/// `margin`: how many elements inside the material box a node must lie for its support (the
/// points its weights reach) to be complete.
fn patch<const D: usize>(
    basis: Basis,
    grid: Grid<D>,
    lower: [f64; D],
    upper: [f64; D],
    fbar: SMatrix<f64, D, D>,
    margin: f64,
) {
    let points = MaterialPoints::fill_box(&grid, lower, upper, [2; D], 3.0).unwrap();
    let model = LinearElastic::try_new(1e5, 0.3).unwrap();
    let settings = common::single_step_settings(basis, Default::default());
    let loads = common::no_loads::<D>();
    let mut solver =
        MpmSolver::try_new(grid.clone(), points, Box::new(model), vec![], loads, settings).unwrap();
    solver.build_supports().unwrap();
    let table = solver.supports().clone();
    let dofs = DofMap::build(grid.num_nodes(), &table, &[], &[]);
    let mut nodal = vec![0.0; dofs.num_dofs()];
    for n in 0..grid.num_nodes() {
        let u = (fbar - SMatrix::<f64, D, D>::identity()) * grid.node_position(n);
        for a in 0..D {
            nodal[n * D + a] = u[a];
        }
    }
    let mut u = vec![0.0; dofs.len()];
    dofs.gather(&nodal, &mut u);
    let mut matrix = SparseSystem::default();
    matrix.set_pattern(dofs.pattern(&table));
    let f_ext = vec![0.0; dofs.len()];
    let (mut trials, mut du) = (Vec::new(), Vec::new());
    let mut sys = LoadStepSystem {
        model: solver.model(),
        states: &solver.points.state,
        table: &table,
        dofs: &dofs,
        f_ext: &f_ext,
        matrix: &mut matrix,
        trials: &mut trials,
        du_nodal: &mut du,
        ghost: None,
        fixed_forces: &mut Vec::new(),
        prescribed: &[],
        linearised: None,
        inertia: None,
        dynamic_reference: None,
        f_bar: None,
        point_penalties: &[],
    };
    let mut r = vec![0.0; dofs.len()];
    sys.evaluate(&u, &mut r).unwrap();
    let first = trials[0].as_ref().unwrap();
    let sigma_scale = first.sigma().amax();
    assert!(sigma_scale > 1e3, "the patch must be stressed");
    for t in trials.iter().map(|t| t.as_ref().unwrap()) {
        for i in 0..D {
            for j in 0..D {
                assert!(
                    (t.delta_f[(i, j)] - fbar[(i, j)]).abs() < 1e-13,
                    "{basis:?}: ΔF not reproduced"
                );
            }
        }
        assert!(
            (t.sigma() - first.sigma()).amax() < 1e-10 * sigma_scale,
            "{basis:?}: stress not uniform"
        );
    }
    // Nodes at least `margin` elements inside the material box see a complete, tiled support.
    let h = grid.spacing().map(|h| h * margin);
    for n in 0..grid.num_nodes() {
        let x = grid.node_position(n);
        let interior = (0..D).all(|a| x[a] >= lower[a] + h[a] - 1e-12 && x[a] <= upper[a] - h[a] + 1e-12);
        if !interior {
            continue;
        }
        for a in 0..D {
            let e = dofs.eq(n * D + a).unwrap();
            let scale = sigma_scale * grid.spacing().iter().product::<f64>() / grid.spacing()[a];
            assert!(
                r[e].abs() < 1e-11 * scale,
                "{basis:?}: interior node {n} force {} (scale {scale})",
                r[e]
            );
        }
    }
}

/// 1D: compression F = 0.7 and stretch F = 1.3 on a column patch.
#[test]
fn gimp_and_mpm_1d_patch_homogeneous_deformation() {
    for basis in [Basis::Gimp, Basis::Mpm] {
        for f in [0.7, 1.3] {
            let grid = Grid::try_new([0.0], [0.5], [12]).unwrap();
            patch(basis, grid, [1.0], [5.0], SMatrix::<f64, 1, 1>::new(f), 1.0);
        }
    }
}

/// 2D: a general F with stretch, shear and rotation.
#[test]
fn gimp_and_mpm_2d_patch_homogeneous_deformation() {
    for basis in [Basis::Gimp, Basis::Mpm] {
        let grid = Grid::try_new([0.0, 0.0], [0.5, 0.25], [10, 16]).unwrap();
        let fbar = nalgebra::Matrix2::new(1.1, 0.25, -0.15, 0.85);
        patch(basis, grid, [1.0, 1.0], [4.0, 3.0], fbar, 1.0);
    }
}

/// 3D: a general F with stretch, shear and a rotation about an oblique axis.
#[test]
fn gimp_and_mpm_3d_patch_homogeneous_deformation() {
    for basis in [Basis::Gimp, Basis::Mpm] {
        let grid = Grid::try_new([0.0; 3], [0.5, 0.5, 0.4], [8, 8, 10]).unwrap();
        let fbar = nalgebra::Matrix3::new(1.1, 0.2, -0.05, -0.15, 0.9, 0.1, 0.05, -0.1, 1.05);
        patch(basis, grid, [1.0, 1.0, 1.0], [3.0, 3.0, 3.0], fbar, 1.0);
    }
}

/// The domain-averaged B-splines pass the patch test exactly as GIMP does: with domains tiling
/// the material, Σ_p V_p ∂S̄_vp = Σ_p ∫ over Ω_p of ∂S_v = ∫ of ∂S_v over the material, zero for
/// a node whose spline (1.5h quadratic, 2h cubic) lies inside it. 1D compression and stretch,
/// 2D and 3D general F as above.
#[test]
fn averaged_bspline_patch_homogeneous_deformation() {
    for (basis, margin) in [(Basis::Bspline2Gimp, 1.5), (Basis::Bspline3Gimp, 2.0)] {
        for f in [0.7, 1.3] {
            let grid = Grid::try_new([0.0], [0.5], [14]).unwrap();
            patch(basis, grid, [1.0], [6.0], SMatrix::<f64, 1, 1>::new(f), margin);
        }
        let grid = Grid::try_new([0.0, 0.0], [0.5, 0.25], [14, 24]).unwrap();
        let fbar = nalgebra::Matrix2::new(1.1, 0.25, -0.15, 0.85);
        patch(basis, grid, [1.0, 1.0], [6.0, 5.0], fbar, margin);
        let grid = Grid::try_new([0.0; 3], [0.5, 0.5, 0.4], [10, 10, 12]).unwrap();
        let fbar = nalgebra::Matrix3::new(1.1, 0.2, -0.05, -0.15, 0.9, 0.1, 0.05, -0.1, 1.05);
        patch(basis, grid, [1.0, 1.0, 1.0], [4.0, 4.0, 4.2], fbar, margin);
    }
}
