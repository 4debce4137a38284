//! Every derivative against central differences: ∂ln b/∂b (eq 26), the constitutive tangent,
//! and the assembled global tangent (eqs 25, 27, 36) against differences of the global
//! residual, in 1D and 2D, at non-trivial deformed states. Also objectivity of the update.

use crate::common;

use common::Rng;
use igimp::basis::Basis;
use igimp::discretise::assembly::{DofMap, LoadStepSystem};
use igimp::material::constitutive::{ConstitutiveModel, LinearElastic, Material, MaterialState};
use igimp::material::kinematics::{dlog, evaluate_point, log_strain, sym_eigen, PointState};
use igimp::material::tensor::{contract, ij};
use igimp::mesh::grid::Grid;
use igimp::mpm::particles::MaterialPoints;
use igimp::mpm::MpmSolver;
use igimp::problems::column::ColumnSpec;
use igimp::solver::linear::SparseSystem;
use igimp::solver::load_stepping::LoadStepping;
use igimp::solver::newton::NonlinearSystem;
use nalgebra::{Matrix2, Matrix3, SMatrix, SVector};

fn random_spd(rng: &mut Rng, spread: f64) -> Matrix3<f64> {
    let a = Matrix3::from_fn(|_, _| rng.uniform(-spread, spread));
    Matrix3::identity() + 0.5 * (a + a.transpose()) + a.transpose() * a * 0.2
}

/// L = ∂ln(b)/∂b (Daleckii–Krein) matches central differences of the matrix logarithm,
/// including nearly repeated eigenvalues.
#[test]
fn dlog_matches_central_differences() {
    let mut rng = Rng::new(11);
    let mut cases: Vec<Matrix3<f64>> = (0..50).map(|_| random_spd(&mut rng, 0.4)).collect();
    cases.push(Matrix3::from_diagonal(&nalgebra::Vector3::new(
        1.3,
        1.3 + 1e-9,
        0.7,
    )));
    cases.push(Matrix3::identity() * 0.8);
    for b in cases {
        let (lam, q) = sym_eigen(&b);
        let l = dlog(&lam, &q);
        let eps = 1e-6;
        for p in 0..3 {
            for qq in 0..3 {
                let mut h = Matrix3::zeros();
                h[(p, qq)] += 0.5;
                h[(qq, p)] += 0.5;
                let fd = (log_strain(&(b + h * eps)).unwrap() - log_strain(&(b - h * eps)).unwrap())
                    * (2.0 / (2.0 * eps));
                let an = contract(&l, &h);
                assert!(
                    (fd - an).amax() < 1e-7,
                    "dlog mismatch: fd {fd} an {an} for b {b}"
                );
            }
        }
    }
}

/// D^alg of the elastic models (Hencky, neo-Hookean) matches central differences of their
/// stress update, at strains up to ±0.3 (the neo-Hookean tangent is not constant).
#[test]
fn constitutive_tangent_matches_central_differences() {
    let hencky = LinearElastic::try_new(2.1e5, 0.3).unwrap();
    let neo = igimp::material::constitutive::NeoHookean::try_new(2.1e5, 0.3).unwrap();
    for (model, spread) in [
        (&hencky as &dyn ConstitutiveModel, 0.05),
        (&neo, 0.05),
        (&neo, 0.3),
    ] {
        constitutive_tangent_check(model, spread);
    }
}

fn constitutive_tangent_check(model: &dyn ConstitutiveModel, spread: f64) {
    let mut rng = Rng::new(12);
    let state = MaterialState::default();
    for _ in 0..20 {
        let a = Matrix3::from_fn(|_, _| rng.uniform(-spread, spread));
        let eps = 0.5 * (a + a.transpose());
        model.update(&eps, &state).unwrap();
        let h = 1e-7;
        for k in 0..3 {
            for l in 0..3 {
                let mut d = Matrix3::zeros();
                d[(k, l)] += 0.5;
                d[(l, k)] += 0.5;
                let fd = (model.update(&(eps + d * h), &state).unwrap().tau
                    - model.update(&(eps - d * h), &state).unwrap().tau)
                    / (2.0 * h);
                let d_alg = model.tangent(&eps, &state);
                let an = contract(&d_alg, &d);
                assert!(
                    (fd - an).amax() <= 1e-6 * d_alg.amax(),
                    "D^alg mismatch: {fd} against {an}"
                );
            }
        }
    }
}

/// Compare the assembled tangent with central differences of the residual at `u0`.
/// Returns max |K − K_fd| / max |K|.
fn global_tangent_error<const D: usize>(solver: &mut MpmSolver<D>, u0_scale: f64, seed: u64) -> f64 {
    tangent_error_with(solver, u0_scale, seed, false)
}

/// [`global_tangent_error`]; `wrong_ghost` leaves the ghost term out of the tangent (but not
/// the residual): the deliberately wrong variant the check must catch.
fn tangent_error_with<const D: usize>(
    solver: &mut MpmSolver<D>,
    u0_scale: f64,
    seed: u64,
    wrong_ghost: bool,
) -> f64 {
    assembled_at(solver, u0_scale, seed, wrong_ghost, |sys, u0| {
        let n = u0.len();
        let k: Vec<Vec<f64>> = (0..n)
            .map(|i| (0..n).map(|j| sys.matrix.get(i, j)).collect())
            .collect();
        let h = 1e-6 * u0_scale.max(1e-3);
        let mut max_err: f64 = 0.0;
        let mut max_k: f64 = 0.0;
        let (mut rp, mut rm) = (vec![0.0; n], vec![0.0; n]);
        for j in 0..n {
            let mut up = u0.to_vec();
            up[j] += h;
            let mut um = u0.to_vec();
            um[j] -= h;
            sys.evaluate(&up, &mut rp).unwrap();
            sys.evaluate(&um, &mut rm).unwrap();
            for i in 0..n {
                let fd = (rp[i] - rm[i]) / (2.0 * h);
                max_err = max_err.max((fd - k[i][j]).abs());
                max_k = max_k.max(k[i][j].abs());
            }
        }
        max_err / max_k
    })
}

/// The step system of `solver`'s committed state (with its ghost faces when its settings have
/// them) evaluated at a random increment u0 of scale `u0_scale` and its tangent assembled
/// (`wrong_ghost`: without the ghost term, which the residual keeps); `check` gets the system
/// and u0.
fn assembled_at<const D: usize, R>(
    solver: &mut MpmSolver<D>,
    u0_scale: f64,
    seed: u64,
    wrong_ghost: bool,
    check: impl FnOnce(&mut LoadStepSystem<'_, D>, &[f64]) -> R,
) -> R {
    solver.build_supports().unwrap();
    solver.build_ghost();
    let ghost = solver.settings.ghost.is_on().then(|| solver.ghost().clone());
    let table = solver.supports().clone();
    let dofs = DofMap::build(solver.grid.num_nodes(), &table, &solver.fixed, &[]);
    let n = dofs.len();
    let mut matrix = SparseSystem::default();
    // The solver's layout: by rows for CG, by columns for the factorisations.
    matrix.set_solver(solver.settings.linear_solver);
    let mut columns = dofs.pattern(&table);
    if let Some(g) = &ghost {
        g.add_pattern(&dofs, &mut columns);
    }
    matrix.set_pattern(columns);
    let f_ext = vec![0.0; n];
    let mut trials = Vec::new();
    let mut du = Vec::new();
    let mut rng = Rng::new(seed);
    let u0: Vec<f64> = (0..n).map(|_| rng.uniform(-u0_scale, u0_scale)).collect();
    let mut sys = LoadStepSystem {
        model: solver.model(),
        states: &solver.points.state,
        table: &table,
        dofs: &dofs,
        f_ext: &f_ext,
        matrix: &mut matrix,
        trials: &mut trials,
        du_nodal: &mut du,
        ghost: ghost.as_ref(),
        fixed_forces: &mut Vec::new(),
        prescribed: &[],
        linearised: None,
        inertia: None,
        dynamic_reference: None,
        f_bar: None,
        point_penalties: &[],
    };
    let mut r0 = vec![0.0; n];
    sys.evaluate(&u0, &mut r0).unwrap();
    let ghost_ref = sys.ghost;
    if wrong_ghost {
        sys.ghost = None;
    }
    sys.assemble_tangent();
    sys.ghost = ghost_ref;
    check(&mut sys, &u0)
}

/// 1D column of every basis family after 8 load steps at W = 400,000 (F ≈ 0.85 at the base), ν = 0.3 so the
/// out-of-plane stresses enter, evaluated at a random trial increment.
#[test]
fn gimp_1d_global_tangent_matches_central_differences() {
    for basis in Basis::ALL {
        let spec = ColumnSpec {
            elements: 12,
            weight: 400_000.0,
            material: Material::linear_elastic(1e6, 0.3),
            ..ColumnSpec::default()
        };
        let mut solver = spec.mpm_solver(basis).unwrap();
        for _ in 0..8 {
            solver.step().unwrap();
        }
        let err = global_tangent_error(&mut solver, 0.05, 21);
        assert!(err < 1e-6, "{basis:?}: relative tangent error {err:e}");
    }
}

/// A 2D plane-strain GIMP patch whose committed state is rotated by 0.6 rad and stretched
/// (F_n = R U), evaluated at a random trial increment.
#[test]
fn gimp_2d_global_tangent_matches_central_differences_rotated_stretched_state() {
    use igimp::discretise::ghost::{GhostFaces, GhostSettings};
    let off = GhostSettings::default();
    let all = GhostSettings {
        gamma: 0.5,
        faces: GhostFaces::All,
        ..Default::default()
    };
    // Cells half filled count as cut below a fill of 0.6.
    let cut = GhostSettings {
        gamma: 0.5,
        faces: GhostFaces::Cut,
        cut_fill: 0.6,
        ..Default::default()
    };
    // (basis, ghost, upper corner of the material): [3.5, 2.5] leaves half-filled cells.
    let variants = [
        (Basis::Gimp, off, [4.0, 3.0]),
        (Basis::Mpm, off, [4.0, 3.0]),
        (Basis::Cpdi, off, [4.0, 3.0]),
        (Basis::Bspline2, off, [4.0, 3.0]),
        (Basis::Bspline3, off, [4.0, 3.0]),
        (Basis::Tlmpm, off, [4.0, 3.0]),
        (Basis::Bspline2Gimp, off, [4.0, 3.0]),
        (Basis::Bspline3Gimp, off, [4.0, 3.0]),
        (Basis::Bspline2, cut, [3.5, 2.5]),
        (Basis::Bspline3Gimp, cut, [3.5, 2.5]),
        (Basis::Cpdi, cut, [3.5, 2.5]),
        (Basis::Gimp, all, [4.0, 3.0]),
        (Basis::Gimp, cut, [3.5, 2.5]),
        (Basis::Mpm, cut, [3.5, 2.5]),
    ];
    for (basis, ghost, upper) in variants {
        let grid = Grid::try_new([0.0, 0.0], [1.0, 1.0], [5, 5]).unwrap();
        let mut points = MaterialPoints::fill_box(&grid, [1.0, 1.0], upper, [2, 2], 10.0).unwrap();
        let model = LinearElastic::try_new(1e5, 0.3).unwrap();
        let th: f64 = 0.6;
        let r = Matrix2::new(th.cos(), -th.sin(), th.sin(), th.cos());
        let u = Matrix2::new(1.15, 0.1, 0.1, 0.92);
        let f2 = r * u;
        let mut f = Matrix3::identity();
        f.fixed_view_mut::<2, 2>(0, 0).copy_from(&f2);
        common::commit_stretched(
            points.state.iter_mut().map(|s| {
                let v0 = s.volume;
                (s, v0)
            }),
            &f,
            &model,
        );
        let fixed: Vec<(usize, usize)> = grid
            .boundary_nodes(1, false)
            .iter()
            .flat_map(|&n| [(n, 0), (n, 1)])
            .collect();
        let settings = common::single_step_settings(basis, ghost);
        let loads = common::no_loads::<2>();
        let mut solver = MpmSolver::try_new(grid, points, Box::new(model), fixed, loads, settings).unwrap();
        let err = global_tangent_error(&mut solver, 0.05, 22);
        assert!(err < 1e-6, "{basis:?} {ghost:?}: relative tangent error {err:e}");
        if ghost.is_on() {
            assert!(
                solver.ghost().num_faces() > 0,
                "{basis:?} {ghost:?}: no ghost face"
            );
            let wrong = tangent_error_with(&mut solver, 0.05, 22, true);
            assert!(
                wrong > 1e-3,
                "{basis:?} {ghost:?}: tangent without the ghost term passes ({wrong:e})"
            );
        }
    }
}

/// Superposing a rigid rotation Q on the increment (ΔF → QΔF) rotates τ to QτQᵀ and leaves
/// the strain invariants (and so any internal variables) unchanged.
#[test]
fn stress_update_is_objective_under_superposed_rotation() {
    let model = LinearElastic::try_new(1e5, 0.25).unwrap();
    let mut rng = Rng::new(31);
    for _ in 0..20 {
        let state = PointState::undeformed(1.0);
        let g = SMatrix::<f64, 2, 2>::from_fn(|_, _| rng.uniform(-0.2, 0.2));
        let t1 = evaluate_point::<2>(&model, &state, &g).unwrap();
        let th = rng.uniform(-3.0, 3.0);
        let q = Matrix2::new(th.cos(), -th.sin(), th.sin(), th.cos());
        let df = Matrix2::identity() + g;
        let g2 = q * df - Matrix2::identity();
        let t2 = evaluate_point::<2>(&model, &state, &g2).unwrap();
        let mut q3 = Matrix3::identity();
        q3.fixed_view_mut::<2, 2>(0, 0).copy_from(&q);
        let rotated = q3 * t1.response.tau * q3.transpose();
        assert!((rotated - t2.response.tau).amax() < 1e-9 * t1.response.tau.amax().max(1.0));
        assert!((t1.response.internal.get(0) - t2.response.internal.get(0)).abs() < 1e-15);
        let _ = ij(0, 0);
    }
}

/// The fast eigenbasis form of the spatial tangent equals eq (25) written literally,
/// (1/2J) D L B − σ_il δ_jk, for general and block-structured b, and the closed-form block
/// eigen-decomposition reconstructs b.
#[test]
fn spatial_tangent_eigen_form_equals_literal_eq25() {
    use igimp::material::kinematics::{spatial_tangent, spatial_tangent_eigen};
    let model = LinearElastic::try_new(3e4, 0.2).unwrap();
    let mut rng = Rng::new(41);
    for case in 0..40 {
        let mut b = random_spd(&mut rng, 0.3);
        if case % 2 == 0 {
            for k in 0..2 {
                b[(k, 2)] = 0.0;
                b[(2, k)] = 0.0;
            }
        }
        if case % 4 == 0 {
            b[(0, 1)] = 0.0;
            b[(1, 0)] = 0.0;
        }
        let (lam, q) = sym_eigen(&b);
        let rebuilt = q * Matrix3::from_diagonal(&lam) * q.transpose();
        assert!((rebuilt - b).amax() < 1e-14 * b.amax());
        assert!((q.transpose() * q - Matrix3::identity()).amax() < 1e-14);
        let eps = log_strain(&b).unwrap();
        let resp = model.update(&eps, &MaterialState::default()).unwrap();
        let j = 1.3;
        let sigma = resp.tau / j;
        let d_alg = model.tangent(&eps, &MaterialState::default());
        let literal = spatial_tangent::<2>(&d_alg, &dlog(&lam, &q), &b, &sigma, j);
        let fast = spatial_tangent_eigen::<2>(&d_alg, &lam, &q, &sigma, j);
        assert!((literal - fast).amax() < 1e-10 * literal.amax(), "case {case}");
    }
}

/// A 3D GIMP/MPM block whose committed state is rotated by 0.6 rad about the oblique axis
/// (1, 2, 3)/√14 and stretched (F_n = R U), elastic and von Mises (yield stress 2e3: the
/// trial states are far outside the surface, so every point is on the plastic branch),
/// evaluated at a random trial increment: the assembled tangent equals central differences of
/// the residual within 1e-6 relative.
#[test]
fn gimp_3d_global_tangent_matches_central_differences_rotated_stretched_plastic_state() {
    let every = Basis::ALL.into_iter().flat_map(|b| [(b, false), (b, true)]);
    for (basis, plastic) in every {
        let mut solver = stretched_block::<3>(basis, plastic);
        let err = global_tangent_error(&mut solver, 0.02, 23);
        assert!(
            err < 1e-6,
            "{basis:?} plastic {plastic}: relative tangent error {err:e}"
        );
    }
}

/// 3D objectivity: a rigid rotation Q about a random oblique axis superposed on the increment
/// (ΔF → QΔF) rotates τ to QτQᵀ, for the elastic and the von Mises update (plastic multiplier
/// unchanged), at random stretched and sheared increments.
#[test]
fn stress_update_is_objective_under_oblique_rotation_3d() {
    use igimp::material::constitutive::VonMises;
    use igimp::material::constitutive::{DruckerPrager, ModifiedCamClay, MohrCoulomb, NeoHookean};
    use nalgebra::{Rotation3, Unit, Vector3};
    // Every built-in model: Hencky, von Mises, neo-Hookean, Drucker–Prager (associated
    // and not, yielding on the cone and at the apex at these strains), Mohr–Coulomb
    // (non-associated, hardening) and modified Cam-Clay (yielding from its initial isotropic
    // stress −p₀ 1).
    let models: [Box<dyn ConstitutiveModel>; 7] = [
        Box::new(LinearElastic::try_new(1e5, 0.25).unwrap()),
        Box::new(VonMises::try_new(1e5, 0.25, 3e3).unwrap()),
        Box::new(NeoHookean::try_new(1e5, 0.25).unwrap()),
        Box::new(DruckerPrager::try_new(1e5, 0.25, 2e3, 30.0, 30.0, 0.0).unwrap()),
        Box::new(DruckerPrager::try_new(1e5, 0.25, 2e3, 30.0, 10.0, 1e4).unwrap()),
        Box::new(MohrCoulomb::try_new(1e5, 0.25, 2e3, 30.0, 10.0, 1e4).unwrap()),
        Box::new(ModifiedCamClay::try_new(3e3, 0.05, 0.2, 1.2, 100.0, 150.0).unwrap()),
    ];
    assert_eq!(
        models.len(),
        igimp::material::constitutive::registry::BUILT_IN.len() + 1,
        "a new built-in model joins this objectivity check"
    );
    let mut rng = Rng::new(41);
    for model in &models {
        for _ in 0..20 {
            let state = PointState::undeformed(1.0);
            let g = SMatrix::<f64, 3, 3>::from_fn(|_, _| rng.uniform(-0.2, 0.2));
            let t1 = evaluate_point::<3>(model.as_ref(), &state, &g).unwrap();
            let axis = Unit::new_normalize(Vector3::new(
                rng.uniform(-1.0, 1.0),
                rng.uniform(-1.0, 1.0),
                rng.uniform(0.1, 1.0),
            ));
            let q = Rotation3::from_axis_angle(&axis, rng.uniform(-3.0, 3.0)).into_inner();
            let g2 = q * (Matrix3::identity() + g) - Matrix3::identity();
            let t2 = evaluate_point::<3>(model.as_ref(), &state, &g2).unwrap();
            let rotated = q * t1.response.tau * q.transpose();
            assert!((rotated - t2.response.tau).amax() < 1e-9 * t1.response.tau.amax().max(1.0));
            assert!(
                (t1.response.internal.get(0) - t2.response.internal.get(0)).abs()
                    <= 1e-12 * t1.response.internal.get(0).abs().max(1.0)
            );
        }
    }
}

/// A block of 2^D points per cell over the middle of a 4^D grid, its committed state rotated
/// by 0.6 rad about an oblique axis and stretched (F_n = R U), elastic or von Mises (yield
/// stress 2e3: every trial state is far outside the surface), fixed on its lower face along
/// the last axis.
fn stretched_block<const D: usize>(basis: Basis, plastic: bool) -> MpmSolver<D> {
    use igimp::material::constitutive::VonMises;
    let model: Box<dyn ConstitutiveModel> = if plastic {
        Box::new(VonMises::try_new(1e5, 0.3, 2e3).unwrap())
    } else {
        Box::new(LinearElastic::try_new(1e5, 0.3).unwrap())
    };
    stretched_block_of(basis, plastic, model)
}

/// [`stretched_block`] with a given model (`plastic`: the committed state is checked to lie
/// outside the von Mises surface of the block's yield stress).
fn stretched_block_of<const D: usize>(
    basis: Basis,
    plastic: bool,
    model: Box<dyn ConstitutiveModel>,
) -> MpmSolver<D> {
    use igimp::material::constitutive::VonMises;
    use nalgebra::{Rotation3, Unit, Vector3};
    let grid = Grid::try_new([0.0; D], [1.0; D], [4; D]).unwrap();
    let mut points = MaterialPoints::fill_box(&grid, [1.0; D], [3.0; D], [2; D], 10.0).unwrap();
    let elastic = LinearElastic::try_new(1e5, 0.3).unwrap();
    let axis = if D == 3 {
        Vector3::new(1.0, 2.0, 3.0)
    } else {
        Vector3::z()
    };
    let r = Rotation3::from_axis_angle(&Unit::new_normalize(axis), 0.6).into_inner();
    let mut u = Matrix3::new(1.15, 0.1, 0.05, 0.1, 0.92, 0.03, 0.05, 0.03, 1.05);
    for a in D..3 {
        // Plane strain: the out-of-plane axis is neither stretched nor sheared.
        for b in 0..3 {
            u[(a, b)] = if a == b { 1.0 } else { 0.0 };
            u[(b, a)] = if a == b { 1.0 } else { 0.0 };
        }
    }
    let f = r * u;
    let eps = log_strain(&(f * f.transpose())).unwrap();
    if plastic {
        let vm = VonMises::try_new(1e5, 0.3, 2e3).unwrap();
        let tau = elastic.update(&eps, &MaterialState::default()).unwrap().tau;
        assert!(
            vm.yield_function(&tau) > 0.0,
            "the committed state must be outside the surface"
        );
    }
    common::commit_stretched(
        points.state.iter_mut().map(|s| {
            let v0 = s.volume;
            (s, v0)
        }),
        &f,
        &elastic,
    );
    let fixed: Vec<(usize, usize)> = grid
        .boundary_nodes(D - 1, false)
        .iter()
        .flat_map(|&n| (0..D).map(move |a| (n, a)))
        .collect();
    let settings = common::single_step_settings(basis, Default::default());
    let loads = common::no_loads::<D>();
    MpmSolver::try_new(grid, points, model, fixed, loads, settings).unwrap()
}

/// max |K − K_literal| / max |K_literal| at a random trial increment of size `u0_scale`, where
/// K is the assembled tangent and K_literal sums eq (27) entry by entry in the plainest order,
/// K_(a i),(b k) = Σ_p Σ_jl g_a,j a_ijkl g_b,l V_p with g = ΔF⁻ᵀ ∂S/∂X̃ (eq 36), or with
/// g = ∂S/∂X̃ (eq 36 left out) if `wrong`.
fn literal_kernel_error<const D: usize>(
    solver: &mut MpmSolver<D>,
    u0_scale: f64,
    seed: u64,
    wrong: bool,
) -> f64 {
    assert!(
        !solver.settings.ghost.is_on(),
        "the literal sum leaves the ghost term out"
    );
    assembled_at(solver, u0_scale, seed, false, |sys, u0| {
        let n = u0.len();
        let mut literal = vec![vec![0.0; n]; n];
        for (p, trial) in sys.trials.iter().enumerate() {
            let t = trial.as_ref().unwrap();
            let a = t.spatial_tangent(sys.model, &sys.states[p]);
            let (nodes, _, g) = sys.table.point(p);
            let map = if wrong {
                SMatrix::<f64, D, D>::identity()
            } else {
                t.delta_f_inv.transpose()
            };
            let gx: Vec<SVector<f64, D>> = g.iter().map(|g| map * g).collect();
            for (na, ga) in nodes.iter().zip(&gx) {
                for (nb, gb) in nodes.iter().zip(&gx) {
                    for i in 0..D {
                        for k in 0..D {
                            let (Some(r), Some(c)) = (sys.dofs.eq(na * D + i), sys.dofs.eq(nb * D + k))
                            else {
                                continue;
                            };
                            for j in 0..D {
                                for l in 0..D {
                                    literal[r][c] += ga[j] * a[(ij(i, j), ij(k, l))] * gb[l] * t.volume;
                                }
                            }
                        }
                    }
                }
            }
        }
        let (mut err, mut max): (f64, f64) = (0.0, 0.0);
        for (r, row) in literal.iter().enumerate() {
            for (c, &v) in row.iter().enumerate() {
                err = err.max((sys.matrix.get(r, c) - v).abs());
                max = max.max(v.abs());
            }
        }
        err / max
    })
}

/// The assembled tangent equals eq (27) summed entry by entry to round-off (1e-12 relative,
/// the sums differ only in their order), for every family, 2D and 3D, elastic and von Mises;
/// the same comparison with eq (36) left out of the literal sum differs by more than 1e-3, so
/// the check can fail.
#[test]
fn assembled_tangent_equals_the_literal_kernel_every_family_2d_3d_elastic_plastic() {
    for basis in Basis::ALL {
        for plastic in [false, true] {
            let err2 = literal_kernel_error(&mut stretched_block::<2>(basis, plastic), 0.05, 24, false);
            let err3 = literal_kernel_error(&mut stretched_block::<3>(basis, plastic), 0.05, 25, false);
            assert!(
                err2 < 1e-12 && err3 < 1e-12,
                "{basis:?} plastic {plastic}: 2D {err2:e}, 3D {err3:e}"
            );
        }
        let wrong = literal_kernel_error(&mut stretched_block::<3>(basis, true), 0.05, 25, true);
        assert!(wrong > 1e-3, "{basis:?}: eq (36) left out passes ({wrong:e})");
    }
}

/// Linear elasticity with a skew part added to its tangent: a stand-in for a model whose
/// tangent lacks major symmetry (non-associative flow), so that the assembled K is not
/// symmetric. Hencky elasticity and associative von Mises plasticity give symmetric tangents,
/// on which a block added by rows without its transpose would go unnoticed.
struct Skewed(LinearElastic);

impl ConstitutiveModel for Skewed {
    fn update(
        &self,
        eps_trial: &Matrix3<f64>,
        committed: &MaterialState,
    ) -> Result<igimp::material::constitutive::MaterialResponse, igimp::material::constitutive::MaterialError>
    {
        self.0.update(eps_trial, committed)
    }
    fn tangent(
        &self,
        eps_trial: &Matrix3<f64>,
        committed: &MaterialState,
    ) -> igimp::material::tensor::Tensor4 {
        let mut d = self.0.tangent(eps_trial, committed);
        let e = self.0.young_modulus();
        for (i, j, v) in [(0, 4, 0.3), (1, 8, -0.2), (3, 5, 0.1)] {
            d[(i, j)] += v * e;
            d[(j, i)] -= v * e;
        }
        d
    }
    fn young_modulus(&self) -> f64 {
        self.0.young_modulus()
    }
}

/// The tangent assembled by rows (CG's layout) equals the one assembled by columns (the
/// direct factorisations') entry for entry and to the bit, for every family in 3D with ghost
/// faces, von Mises with a plastic trial state and a model with a non-symmetric tangent
/// ([`Skewed`]): each entry sums the same terms in the same order. The second's K is far from
/// symmetric, so a dense block added by rows untransposed would fail.
#[test]
fn tangent_by_rows_equals_tangent_by_columns_to_the_bit() {
    use igimp::discretise::ghost::{GhostFaces, GhostSettings};
    use igimp::solver::linear::LinearSolver;
    let dense = |solver: &mut MpmSolver<3>| {
        assembled_at(solver, 0.05, 26, false, |sys, u0| {
            let n = u0.len();
            (0..n * n)
                .map(|k| sys.matrix.get(k / n, k % n))
                .collect::<Vec<f64>>()
        })
    };
    for basis in Basis::ALL {
        let skewed = Box::new(Skewed(LinearElastic::try_new(1e5, 0.3).unwrap()));
        for (symmetric, mut solver) in [
            (true, stretched_block::<3>(basis, true)),
            (false, stretched_block_of::<3>(basis, false, skewed)),
        ] {
            solver.settings.ghost = GhostSettings {
                gamma: 0.5,
                faces: GhostFaces::All,
                ..Default::default()
            };
            let by_columns = dense(&mut solver);
            solver.settings.linear_solver = LinearSolver::Iterative;
            let by_rows = dense(&mut solver);
            let n = (by_rows.len() as f64).sqrt() as usize;
            let max = by_columns.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            let asym = (0..n * n).fold(0.0f64, |m, k| {
                m.max((by_columns[k] - by_columns[(k % n) * n + k / n]).abs())
            });
            assert_eq!(
                asym < 1e-12 * max,
                symmetric,
                "{basis:?}: asymmetry {asym:e} of {max:e}"
            );
            let differ = by_rows
                .iter()
                .zip(&by_columns)
                .filter(|(a, b)| a.to_bits() != b.to_bits())
                .count();
            assert_eq!(differ, 0, "{basis:?}: {differ} of {} entries differ", n * n);
        }
    }
}

/// The neo-Hookean model's Kirchhoff stress at F = [[1.1, 0.05], [0.02, 0.9]] (plane strain,
/// E = 1e5, ν = 0.3) equals Kratos MPM 10.4.4's `HyperElasticNeoHookeanPlaneStrain2DLaw`
/// (its `CalculateMaterialResponseKirchhoff`, printed to 12 digits: reference/README.md item
/// 67), to 1e-10 relative: τ_xx, τ_yy, τ_xy.
#[test]
fn neo_hookean_stress_equals_kratos_law() {
    let model = igimp::material::constitutive::NeoHookean::try_new(1e5, 0.3).unwrap();
    let f = Matrix3::new(1.1, 0.05, 0.0, 0.02, 0.9, 0.0, 0.0, 0.0, 1.0);
    let eps = log_strain(&(f * f.transpose())).unwrap();
    let tau = model.update(&eps, &MaterialState::default()).unwrap().tau;
    let kratos = [7534.94534465, -7930.43927074, 2576.92307692];
    for (got, want) in [tau[(0, 0)], tau[(1, 1)], tau[(0, 1)]].iter().zip(kratos) {
        assert!(
            (got - want).abs() <= 1e-10 * 7930.0,
            "{got} against Kratos' {want}"
        );
    }
}
