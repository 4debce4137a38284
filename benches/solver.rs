//! Speed of the solver core, sizes from `benches/sizes.toml`:
//! - `column_load_step`: one load step of the W = 400,000 column (2 points per element);
//! - `weights`: MPM and GIMP weights and gradients of many points (1D, 2D);
//! - `families_2d`, `families_3d`: every basis family's weights, and weights + per-point tangent
//!   blocks per node pair (throughput in node pairs per second: the per-pair cost against
//!   iGIMP's is what the support ratio bounds);
//! - `point_kernel`: kinematics + constitutive update + spatial tangent of one point, linear
//!   elastic and von Mises (plastic return);
//! - `assembly`: residual and tangent of a plane-strain Q4 mesh;
//! - `factorisation`: numeric LU / LDLᵀ / LLᵀ + solve of that tangent;
//! - `galerkin`: the multigrid's coarse operator Pᵀ (A P) of a plane 9-point, 2-component
//!   matrix, by the crate's row-wise product ([`igimp::solver::sparse::Csr::matmul`]) and by faer's
//!   `sparse_sparse_matmul` (symbolic + numeric each time, as a new hierarchy needs; faer is
//!   built without its rayon feature, so sequential: compare with `RAYON_NUM_THREADS=1`).
//!
//! `cargo bench --bench solver`

use criterion::{criterion_group, criterion_main, BatchSize, Criterion, Throughput};
use igimp::basis::{Basis, PointSupport, PointView, Support};
use igimp::fem::{PlaneFem, PlaneFemSettings, PlaneLoads, PlaneMesh, QuadElement};
use igimp::material::constitutive::{ConstitutiveModel, LinearElastic, VonMises};
use igimp::material::kinematics::{evaluate_point, PointState};
use igimp::mesh::grid::Grid;
use igimp::problems::column::ColumnSpec;
use igimp::solver::linear::LinearSolver;
use igimp::solver::load_stepping::LoadStepping;
use igimp::solver::multigrid::{prolongation, DofGeometry};
use igimp::solver::newton::NonlinearSystem;
use igimp::solver::sparse::Csr;
use nalgebra::{Matrix3, SMatrix, SVector};
use serde::Deserialize;
use std::hint::black_box;

#[derive(Deserialize)]
struct Sizes {
    load_step: LoadStepSizes,
    weights: WeightSizes,
    families: FamilySizes,
    assembly: MeshSizes,
    factorisation: FactorSizes,
    galerkin: GalerkinSizes,
}
#[derive(Deserialize)]
struct GalerkinSizes {
    nodes_per_axis: Vec<usize>,
}
#[derive(Deserialize)]
struct LoadStepSizes {
    column_elements: Vec<usize>,
}
#[derive(Deserialize)]
struct WeightSizes {
    points: usize,
    cells: usize,
}
#[derive(Deserialize)]
struct FamilySizes {
    cells_2d: usize,
    cells_3d: usize,
    weight_points_2d: usize,
    weight_points_3d: usize,
    tangent_points_2d: usize,
    tangent_points_3d: usize,
}
#[derive(Deserialize)]
struct MeshSizes {
    q4_cells: Vec<[usize; 2]>,
}
#[derive(Deserialize)]
struct FactorSizes {
    q4_cells: Vec<[usize; 2]>,
    solvers: Vec<LinearSolver>,
}

fn sizes() -> Sizes {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/benches/sizes.toml");
    let text = std::fs::read_to_string(path).expect("benches/sizes.toml");
    toml::from_str(&text).expect("benches/sizes.toml: invalid")
}

fn load_step(c: &mut Criterion) {
    let mut group = c.benchmark_group("column_load_step");
    for elements in sizes().load_step.column_elements {
        let spec = ColumnSpec {
            elements,
            weight: 400_000.0,
            ..ColumnSpec::default()
        };
        // The 10th of 20 steps: points have moved off the element edges.
        group.bench_function(format!("igimp_{elements}_elements"), |b| {
            b.iter_batched(
                || {
                    let mut s = spec.mpm_solver(Basis::Gimp).unwrap();
                    for _ in 0..9 {
                        s.step().unwrap();
                    }
                    s
                },
                |mut s| black_box(s.step().unwrap()),
                BatchSize::LargeInput,
            )
        });
    }
    group.finish();
}

/// Weights of `n` points spread over the grid (deterministic quasi-random positions).
fn weights_of<const D: usize>(c: &mut Criterion, n: usize, cells: usize) {
    let h = 1.0 / cells as f64;
    let grid = Grid::<D>::try_new([0.0; D], [h; D], [cells; D]).unwrap();
    let half = SVector::<f64, D>::repeat(0.25 * h);
    let points: Vec<SVector<f64, D>> = (0..n)
        .map(|p| {
            SVector::<f64, D>::from_fn(|a, _| {
                let t = ((p * (a + 1)) as f64 * 0.618_033_988_75).fract();
                h + t * (1.0 - 2.0 * h)
            })
        })
        .collect();
    let mut group = c.benchmark_group("weights");
    for basis in [Basis::Mpm, Basis::Gimp] {
        let mut sup = Support::<D>::default();
        group.bench_function(format!("{basis:?}_{D}d_{n}_points"), |b| {
            b.iter(|| {
                for x in &points {
                    basis.evaluate(&grid, x, &half, &mut sup).unwrap();
                    black_box(&sup);
                }
            })
        });
    }
    group.finish();
}

fn weights(c: &mut Criterion) {
    let s = sizes().weights;
    weights_of::<1>(c, s.points, s.cells);
    weights_of::<2>(c, s.points, s.cells);
}

/// `n` seeded points of `grid` (unit cells) at least a cell from its edges: half-lengths a
/// quarter cell, a sheared F, box corners moved by a tenth of the half-lengths.
struct FamilyPoints<const D: usize> {
    x: Vec<SVector<f64, D>>,
    r: SVector<f64, D>,
    f: Matrix3<f64>,
    corners: Vec<Vec<SVector<f64, D>>>,
}

fn family_points<const D: usize>(n: usize, cells: usize) -> FamilyPoints<D> {
    let r = SVector::<f64, D>::repeat(0.25);
    let x: Vec<SVector<f64, D>> = (0..n)
        .map(|p| {
            SVector::<f64, D>::from_fn(|a, _| {
                let t = ((p * (a + 1)) as f64 * 0.618_033_988_75).fract();
                1.5 + t * (cells as f64 - 3.0)
            })
        })
        .collect();
    let corners = x
        .iter()
        .enumerate()
        .map(|(p, x)| {
            let mut c = vec![];
            igimp::basis::cpdi::box_corners(x, &r, &mut c);
            for (k, v) in c.iter_mut().enumerate() {
                for a in 0..D {
                    v[a] += 0.1 * r[a] * (((p + 7 * k + 3 * a) as f64 * 0.754_877_666).fract() - 0.5);
                }
            }
            c
        })
        .collect();
    let mut f = Matrix3::identity();
    f[(0, 1)] = 0.1;
    f[(1, 0)] = -0.05;
    FamilyPoints { x, r, f, corners }
}

/// Σ over a point's node pairs of g_aᵀ A g_b (A: a fixed D²×D² spatial tangent), the dense
/// per-pair work of the tangent assembly without the scatter.
#[inline]
fn tangent_blocks<const D: usize>(sup: &PointSupport<D>, a: &[[f64; 9]; 9]) -> f64 {
    let mut acc = 0.0;
    for i in 0..sup.len() {
        let (_, _, ga) = sup.node(i);
        for j in 0..sup.len() {
            let (_, _, gb) = sup.node(j);
            for p in 0..D {
                for q in 0..D {
                    let mut k = 0.0;
                    for s in 0..D {
                        for t in 0..D {
                            k += ga[s] * a[p * D + s][q * D + t] * gb[t];
                        }
                    }
                    acc += k;
                }
            }
        }
    }
    acc
}

fn families_of<const D: usize>(c: &mut Criterion, cells: usize, weight_points: usize, tangent_points: usize) {
    let grid = Grid::<D>::try_new([0.0; D], [1.0; D], [cells; D]).unwrap();
    let pts = family_points::<D>(weight_points.max(tangent_points), cells);
    let mut a = [[0.0; 9]; 9];
    for (i, row) in a.iter_mut().enumerate() {
        for (j, v) in row.iter_mut().enumerate() {
            *v = if i == j { 2.0 } else { 0.1 / (1 + i + j) as f64 };
        }
    }
    let mut group = c.benchmark_group(format!("families_{D}d"));
    group.sample_size(10);
    for basis in Basis::ALL {
        let family = basis.family::<D>();
        let view = |p: usize| PointView {
            position: &pts.x[p],
            half_length: &pts.r,
            position0: &pts.x[p],
            half_length0: &pts.r,
            f: &pts.f,
            corners: &pts.corners[p],
        };
        let mut sup = PointSupport::<D>::default();
        group.throughput(Throughput::Elements(weight_points as u64));
        group.bench_function(format!("{basis:?}_weights_{weight_points}_points"), |b| {
            b.iter(|| {
                for p in 0..weight_points {
                    family.evaluate(&grid, &view(p), &mut sup).unwrap();
                    black_box(&sup);
                }
            })
        });
        let pairs: u64 = (0..tangent_points)
            .map(|p| {
                family.evaluate(&grid, &view(p), &mut sup).unwrap();
                (sup.len() * sup.len()) as u64
            })
            .sum();
        group.throughput(Throughput::Elements(pairs));
        group.bench_function(
            format!("{basis:?}_weights_and_tangent_{tangent_points}_points_per_node_pair"),
            |b| {
                b.iter(|| {
                    let mut acc = 0.0;
                    for p in 0..tangent_points {
                        family.evaluate(&grid, &view(p), &mut sup).unwrap();
                        acc += tangent_blocks(&sup, &a);
                    }
                    black_box(acc)
                })
            },
        );
    }
    group.finish();
}

fn families(c: &mut Criterion) {
    let s = sizes().families;
    families_of::<2>(c, s.cells_2d, s.weight_points_2d, s.tangent_points_2d);
    families_of::<3>(c, s.cells_3d, s.weight_points_3d, s.tangent_points_3d);
}

fn point_kernel(c: &mut Criterion) {
    let elastic = LinearElastic::try_new(1e6, 0.3).unwrap();
    // Yield stress below the trial stress of `g2`: the von Mises case takes the return map.
    let plastic = VonMises::try_new(1e6, 0.3, 1e3).unwrap();
    let state = PointState::undeformed(0.1);
    let g1 = SMatrix::<f64, 1, 1>::new(-0.05);
    let g2 = SMatrix::<f64, 2, 2>::new(-0.05, 0.02, 0.01, 0.03);
    let models: [(&str, &dyn ConstitutiveModel); 2] = [("elastic", &elastic), ("von_mises", &plastic)];
    let mut group = c.benchmark_group("point_kernel");
    for (name, model) in models {
        group.bench_function(format!("{name}_1d_with_tangent"), |b| {
            b.iter(|| {
                black_box(
                    evaluate_point::<1>(model, &state, black_box(&g1))
                        .unwrap()
                        .spatial_tangent(model, &state),
                )
            })
        });
        group.bench_function(format!("{name}_2d_with_tangent"), |b| {
            b.iter(|| {
                black_box(
                    evaluate_point::<2>(model, &state, black_box(&g2))
                        .unwrap()
                        .spatial_tangent(model, &state),
                )
            })
        });
    }
    group.finish();
}

/// A unit-weight elastic block of Q4 elements, fixed at its base.
fn q4_block(cells: [usize; 2], solver: LinearSolver) -> PlaneFem {
    let size = SVector::<f64, 2>::new(cells[0] as f64, cells[1] as f64);
    let mesh = PlaneMesh::rectangle(SVector::zeros(), size, (cells[0], cells[1]), QuadElement::Q4).unwrap();
    let fixed = mesh
        .nodes_at(1, 0.0, 1e-9)
        .into_iter()
        .flat_map(|n| [(n, 0), (n, 1)])
        .collect();
    let loads = PlaneLoads {
        gravity: SVector::<f64, 2>::new(0.0, -10.0),
        nodal_forces: vec![],
    };
    let settings = PlaneFemSettings {
        linear_solver: solver,
        ..PlaneFemSettings::default()
    };
    let model = Box::new(LinearElastic::try_new(1e6, 0.3).unwrap());
    PlaneFem::try_new(mesh, 1.0, model, fixed, loads, settings).unwrap()
}

fn assembly(c: &mut Criterion) {
    let mut group = c.benchmark_group("assembly");
    for cells in sizes().assembly.q4_cells {
        let mut fem = q4_block(cells, LinearSolver::Lu);
        let label = format!("q4_{}x{}", cells[0], cells[1]);
        fem.with_step_system(1.0, |sys| {
            let n = sys.num_unknowns();
            let u = vec![1e-4; n];
            let mut r = vec![0.0; n];
            group.bench_function(format!("residual_{label}"), |b| {
                b.iter(|| sys.evaluate(black_box(&u), &mut r).unwrap())
            });
            group.bench_function(format!("tangent_{label}"), |b| b.iter(|| sys.assemble_tangent()));
        })
        .unwrap();
    }
    group.finish();
}

fn factorisation(c: &mut Criterion) {
    let s = sizes().factorisation;
    let mut group = c.benchmark_group("factorisation");
    for cells in s.q4_cells {
        for &solver in &s.solvers {
            let mut fem = q4_block(cells, solver);
            fem.with_step_system(1.0, |sys| {
                let n = sys.num_unknowns();
                let mut r = vec![0.0; n];
                sys.evaluate(&vec![0.0; n], &mut r).unwrap();
                sys.assemble_tangent();
                let label = format!("{solver:?}_q4_{}x{}_{n}_unknowns", cells[0], cells[1]).to_lowercase();
                group.bench_function(label, |b| {
                    b.iter(|| {
                        let mut rhs = r.clone();
                        sys.matrix.solve_in_place(&mut rhs).unwrap();
                        black_box(rhs)
                    })
                });
            })
            .unwrap();
        }
    }
    group.finish();
}

/// A plane n × n node grid, two components per node, every component of every node coupled
/// to those of its 8 neighbours (the Q4 stencil), with deterministic values; and its geometry.
fn stencil_matrix(n: usize) -> (Csr, DofGeometry) {
    let (mut ptr, mut idx, mut val) = (vec![0], vec![], vec![]);
    let mut geometry = DofGeometry {
        dim: 2,
        spacing: [1.0, 1.0, 1.0],
        ..DofGeometry::default()
    };
    for j in 0..n {
        for i in 0..n {
            for c in 0..2 {
                geometry.positions.push([i as f64, j as f64, 0.0]);
                geometry.components.push(c as u8);
                for jj in j.saturating_sub(1)..(j + 2).min(n) {
                    for ii in i.saturating_sub(1)..(i + 2).min(n) {
                        for cc in 0..2 {
                            let col = 2 * (jj * n + ii) + cc;
                            idx.push(col as u32);
                            val.push(if col == 2 * (j * n + i) + c {
                                8.0
                            } else {
                                -1.0 / (1 + col % 7) as f64
                            });
                        }
                    }
                }
                ptr.push(idx.len());
            }
        }
    }
    let m = 2 * n * n;
    (Csr::new(m, m, ptr, idx, val), geometry)
}

/// `A B` of row-compressed matrices by faer: the row-compressed A is the column-compressed
/// Aᵀ, so faer's Bᵀ Aᵀ in column-compressed form is A B in row-compressed form.
fn faer_matmul(a: &Csr, b: &Csr) -> Csr {
    use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
    // faer wants one index type for pointers and indices: the (4-byte) indices widened.
    let (a_idx, b_idx): (Vec<usize>, Vec<usize>) = (
        a.idx.iter().map(|&j| j as usize).collect(),
        b.idx.iter().map(|&j| j as usize).collect(),
    );
    let at = SparseColMatRef::new(
        SymbolicSparseColMatRef::new_checked(a.cols, a.rows, &a.ptr, None, &a_idx),
        &a.val,
    );
    let bt = SparseColMatRef::new(
        SymbolicSparseColMatRef::new_checked(b.cols, b.rows, &b.ptr, None, &b_idx),
        &b.val,
    );
    let c = faer::sparse::linalg::matmul::sparse_sparse_matmul(bt, at, 1.0, faer::Par::Seq).unwrap();
    let (sym, val) = c.parts();
    Csr::new(
        a.rows,
        b.cols,
        sym.col_ptr().to_vec(),
        sym.row_idx().iter().map(|&i| i as u32).collect(),
        val.to_vec(),
    )
}

fn galerkin(c: &mut Criterion) {
    let mut group = c.benchmark_group("galerkin");
    group.sample_size(10);
    for n in sizes().galerkin.nodes_per_axis {
        let (a, geometry) = stencil_matrix(n);
        let (p, _) = prolongation(&geometry, [0.0; 3], [2.0, 2.0, 1.0]);
        let r = p.transpose();
        // Both products give the same coarse operator (same pattern, values to round-off).
        let (ours, theirs) = (r.matmul(&a.matmul(&p)), faer_matmul(&r, &faer_matmul(&a, &p)));
        assert_eq!(
            (&ours.ptr, &ours.idx),
            (&theirs.ptr, &theirs.idx),
            "galerkin: patterns differ"
        );
        let scale = ours.val.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let diff = ours
            .val
            .iter()
            .zip(&theirs.val)
            .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
        assert!(diff <= 1e-12 * scale, "galerkin: values differ by {diff:e}");
        let label = format!("{}_unknowns", a.rows);
        group.throughput(Throughput::Elements(a.nnz() as u64));
        group.bench_function(format!("csr_matmul_{label}"), |b| {
            b.iter(|| r.matmul(&a.matmul(&p)))
        });
        group.bench_function(format!("faer_matmul_{label}"), |b| {
            b.iter(|| faer_matmul(&r, &faer_matmul(&a, &p)))
        });
    }
    group.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(20);
    targets = load_step, weights, families, point_kernel, assembly, factorisation, galerkin
}
criterion_main!(benches);
