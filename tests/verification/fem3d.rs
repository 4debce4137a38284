//! The 3D updated-Lagrangian FEM comparator: Hex8 and Hex20 shape functions, the
//! structured hexahedral mesh, a patch test for homogeneous finite deformation on distorted
//! meshes, and the global tangent against central differences at a rotated (oblique axis),
//! stretched, partly plastic state.
//!
//! Run in release mode: `cargo test --release --test verification fem3d`.

// Index loops mirror the index notation (N_a, ∂N_a/∂ξ_d).
#![allow(clippy::needless_range_loop)]

use crate::common::Rng;
use igimp::fem::{ElementFamily, HexElement, HexMesh, SolidFem, SolidLoads};
use igimp::material::constitutive::{ConstitutiveModel, LinearElastic, VonMises};
use igimp::solver::newton::NonlinearSystem;
use nalgebra::{Matrix3, Rotation3, Unit, Vector3};

type V3 = Vector3<f64>;

const ELEMENTS: [HexElement; 2] = [HexElement::Hex8, HexElement::Hex20];

fn elastic(e: f64, nu: f64) -> Box<dyn ConstitutiveModel> {
    Box::new(LinearElastic::try_new(e, nu).unwrap())
}

/// Rotation by `angle` about the oblique axis (1, 2, 3)/√14.
fn oblique_rotation(angle: f64) -> Matrix3<f64> {
    *Rotation3::from_axis_angle(&Unit::new_normalize(V3::new(1.0, 2.0, 3.0)), angle).matrix()
}

/// Homogeneous deformation with stretch, shear and an oblique rotation.
fn f_bar() -> Matrix3<f64> {
    oblique_rotation(0.5) * Matrix3::new(1.2, 0.15, 0.0, 0.05, 0.85, 0.1, -0.05, 0.0, 1.1)
}

fn on_boundary(x: &V3, size: V3) -> bool {
    let tol = 1e-12 * size.amax();
    (0..3).any(|a| x[a].abs() < tol || (x[a] - size[a]).abs() < tol)
}

/// A box mesh whose interior nodes are moved randomly by up to `amp` × the cell size (Hex20:
/// mid-edge nodes too, which curves the edges); the boundary stays planar.
fn distorted_box(element: HexElement, size: V3, cells: [usize; 3], amp: f64, seed: u64) -> HexMesh {
    let mut mesh = HexMesh::cuboid(V3::zeros(), size, cells, element).unwrap();
    let h = V3::from_fn(|a, _| size[a] / cells[a] as f64);
    let mut rng = Rng::new(seed);
    for x in mesh.nodes.iter_mut() {
        let shift = V3::from_fn(|a, _| rng.uniform(-1.0, 1.0) * h[a] * amp);
        if !on_boundary(x, size) {
            *x += shift;
        }
    }
    HexMesh::try_new(element, mesh.nodes, mesh.connectivity).expect("distorted mesh stays valid")
}

// ---------------------------------------------------------------------------------------------
// Elements

/// Hex8 and Hex20 shape functions are nodal (N_a(ξ_b) = δ_ab), a partition of unity with
/// Σ∂N/∂ξ = 0, reproduce linear fields (Hex20 also every quadratic monomial, the serendipity
/// space contains the complete quadratics), and their gradients match central differences.
#[test]
fn hex_shape_functions_are_nodal_complete_and_differentiated_correctly() {
    let mut rng = Rng::new(5);
    for element in ELEMENTS {
        let k = element.nodes_per_element();
        for b in 0..k {
            let (n, _) = element.shape(&element.local_node(b));
            for a in 0..k {
                let expect = if a == b { 1.0 } else { 0.0 };
                assert!(
                    (n[a] - expect).abs() < 1e-15,
                    "{element:?} N_{a}(ξ_{b}) = {}",
                    n[a]
                );
            }
        }
        for _ in 0..20 {
            let xi = V3::from_fn(|_, _| rng.uniform(-1.0, 1.0));
            let (n, dn) = element.shape(&xi);
            let sum: f64 = n[..k].iter().sum();
            let dsum: V3 = dn[..k].iter().sum();
            let lin: V3 = (0..k).map(|a| element.local_node(a) * n[a]).sum();
            assert!(
                (sum - 1.0).abs() < 1e-14 && dsum.amax() < 1e-14,
                "{element:?} partition of unity"
            );
            assert!((lin - xi).amax() < 1e-14, "{element:?} linear reproduction");
            if element == HexElement::Hex20 {
                for i in 0..3 {
                    for j in i..3 {
                        let q: f64 = (0..k)
                            .map(|a| {
                                let xa = element.local_node(a);
                                xa[i] * xa[j] * n[a]
                            })
                            .sum();
                        assert!((q - xi[i] * xi[j]).abs() < 1e-14, "Hex20 reproduces ξ_{i} ξ_{j}");
                    }
                }
            }
            let h = 1e-6;
            for d in 0..3 {
                let mut e = V3::zeros();
                e[d] = h;
                let (np, _) = element.shape(&(xi + e));
                let (nm, _) = element.shape(&(xi - e));
                for a in 0..k {
                    let fd = (np[a] - nm[a]) / (2.0 * h);
                    assert!((fd - dn[a][d]).abs() < 1e-9, "{element:?} dN_{a}/dξ_{d}");
                }
            }
        }
    }
}

/// Hex8 meshes have Π(n_a + 1) nodes, Hex20 meshes the corners plus one node per edge; both
/// fill the box's volume exactly, and the face lookup finds a face's nodes.
#[test]
fn hex_mesh_counts_volume_and_face_lookup() {
    let (nx, ny, nz) = (4, 3, 2);
    for element in ELEMENTS {
        let mesh = HexMesh::cuboid(
            V3::new(1.0, -2.0, 0.5),
            V3::new(4.0, 1.5, 2.0),
            [nx, ny, nz],
            element,
        )
        .unwrap();
        let corners = (nx + 1) * (ny + 1) * (nz + 1);
        let edges = nx * (ny + 1) * (nz + 1) + ny * (nx + 1) * (nz + 1) + nz * (nx + 1) * (ny + 1);
        let expect = if element == HexElement::Hex8 {
            corners
        } else {
            corners + edges
        };
        assert_eq!(mesh.num_nodes(), expect, "{element:?} node count");
        assert_eq!(mesh.num_elements(), nx * ny * nz);
        let rule = igimp::mesh::quadrature::tensor_rule::<3>(element.default_gauss_points()).unwrap();
        let volume: f64 = (0..mesh.num_elements())
            .map(|e| {
                rule.iter()
                    .map(|(xi, w)| w * mesh.map(e, xi).1.determinant())
                    .sum::<f64>()
            })
            .sum();
        assert!((volume - 12.0).abs() < 1e-12, "{element:?} volume {volume}");
        let face = mesh.nodes_at(0, 5.0, 1e-12);
        let per_face = if element == HexElement::Hex8 {
            (ny + 1) * (nz + 1)
        } else {
            (ny + 1) * (nz + 1) + ny * (nz + 1) + nz * (ny + 1)
        };
        assert_eq!(face.len(), per_face, "{element:?} nodes on x = 5");
        assert_eq!(mesh.nearest_node(V3::new(1.01, -2.02, 0.49)), 0);
    }
}

/// An inverted hexahedron is refused with an error naming the element.
#[test]
fn hex_mesh_rejects_an_inverted_element() {
    let mesh = HexMesh::cuboid(V3::zeros(), V3::new(1.0, 1.0, 1.0), [1, 1, 1], HexElement::Hex8).unwrap();
    let mut conn = mesh.connectivity.clone();
    conn.swap(0, 4); // bottom and top corner swapped: the element folds through itself
    let err = HexMesh::try_new(HexElement::Hex8, mesh.nodes, conn).unwrap_err();
    assert!(err.to_string().contains("mesh element 0"), "{err}");
}

// ---------------------------------------------------------------------------------------------
// Patch test

/// Hex8 and Hex20 on distorted meshes: imposing u = (F̄ − I) X on every node gives every Gauss
/// point ΔF = F̄ and zero internal force at every interior node, to round-off; F̄ stretches,
/// shears and rotates about an oblique axis.
#[test]
fn fem3d_patch_imposed_homogeneous_deformation_is_exact() {
    let f = f_bar();
    let size = V3::new(2.0, 1.5, 1.0);
    for element in ELEMENTS {
        for amp in [0.0, 0.2] {
            let mesh = distorted_box(element, size, [2, 2, 2], amp, 7);
            let nodes = mesh.nodes.clone();
            let mut fem = SolidFem::try_new(
                mesh,
                1.0,
                elastic(1e5, 0.3),
                vec![],
                SolidLoads::default(),
                Default::default(),
            )
            .unwrap();
            let (df_err, interior, boundary_max) = fem
                .with_step_system(0.0, |sys| {
                    let n = sys.num_unknowns();
                    assert_eq!(n, 3 * nodes.len());
                    let mut u = vec![0.0; n];
                    for (i, x) in nodes.iter().enumerate() {
                        let d = (f - Matrix3::identity()) * x;
                        u[3 * i..3 * i + 3].copy_from_slice(d.as_slice());
                    }
                    let mut r = vec![0.0; n];
                    sys.evaluate(&u, &mut r).unwrap();
                    let df_err = sys
                        .trials
                        .iter()
                        .map(|t| (t.as_ref().unwrap().delta_f - f).amax())
                        .fold(0.0, f64::max);
                    let (mut interior, mut bmax) = (0.0f64, 0.0f64);
                    for (i, x) in nodes.iter().enumerate() {
                        let ri = (0..3).map(|a| r[3 * i + a].abs()).fold(0.0, f64::max);
                        if on_boundary(x, size) {
                            bmax = bmax.max(ri);
                        } else {
                            interior = interior.max(ri);
                        }
                    }
                    (df_err, interior, bmax)
                })
                .unwrap();
            println!(
                "{element:?} amp {amp}: max |ΔF − F̄| = {df_err:.2e}, max interior |f_int| = {interior:.2e} \
                 (boundary max {boundary_max:.2e})"
            );
            assert!(df_err < 1e-13, "{element:?}: ΔF error {df_err:e}");
            assert!(
                interior < 1e-11 * boundary_max,
                "{element:?}: interior force {interior:e}"
            );
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Tangent

/// Set every Gauss point and node to the committed homogeneous state F_n (x = F_n X,
/// V = det F_n V_0, elastic b^e = F_n F_nᵀ), as if a previous step had converged there.
fn impose_committed_state(fem: &mut SolidFem, f_n: &Matrix3<f64>, young: f64, nu: f64) {
    let elastic = LinearElastic::try_new(young, nu).unwrap();
    for x in fem.mesh.nodes.iter_mut() {
        *x = f_n * *x;
    }
    let states = fem.gauss.state.iter_mut().zip(fem.gauss.volume0.iter().copied());
    crate::common::commit_stretched(states, f_n, &elastic);
}

/// Assembled tangent vs central differences of the global residual: max |K − K_fd| / max |K|
/// and the trial von Mises stresses ([`crate::common::fd_tangent_errors`]).
fn tangent_error(fem: &mut SolidFem, u0_scale: f64, seed: u64) -> (f64, Vec<f64>) {
    let (err, _, rho) = fem
        .with_step_system(0.5, |sys| crate::common::fd_tangent_errors(sys, u0_scale, seed))
        .unwrap();
    (err, rho)
}

/// Global tangent (eqs 25, 27, 36) vs central differences for Hex8 and Hex20 on a distorted
/// mesh whose committed state is rotated by 0.6 rad about an oblique axis and stretched, at a
/// random trial increment: elastic, and von Mises with ρ_y in the widest gap of the trial
/// stresses, so that some Gauss points are plastic and none is within 2 % of yield.
#[test]
fn fem3d_global_tangent_matches_central_differences_rotated_stretched_plastic_state() {
    let (young, nu) = (1e5, 0.3);
    let f_n = oblique_rotation(0.6) * Matrix3::new(1.15, 0.1, 0.0, 0.1, 0.92, 0.05, 0.0, 0.05, 1.05);
    for element in ELEMENTS {
        let cells = if element == HexElement::Hex8 {
            [2, 2, 1]
        } else {
            [2, 1, 1]
        };
        let build = |model: Box<dyn ConstitutiveModel>| {
            let mesh = distorted_box(element, V3::new(2.0, 1.5, 1.0), cells, 0.15, 17);
            let fixed: Vec<(usize, usize)> = mesh
                .nodes_at(2, 0.0, 1e-12)
                .into_iter()
                .flat_map(|n| [(n, 0), (n, 1), (n, 2)])
                .collect();
            let loads = SolidLoads {
                gravity: V3::new(0.0, 0.0, -1e3),
                nodal_forces: vec![],
            };
            let mut fem = SolidFem::try_new(mesh, 1.0, model, fixed, loads, Default::default()).unwrap();
            impose_committed_state(&mut fem, &f_n, young, nu);
            fem
        };
        let (u0, seed) = (0.1, 29);
        let (err, rho) = tangent_error(&mut build(elastic(young, nu)), u0, seed);
        println!("{element:?} elastic: tangent rel. error {err:.2e}");
        assert!(err < 1e-6, "{element:?} elastic: relative tangent error {err:e}");
        let mut sorted = rho.clone();
        sorted.sort_by(f64::total_cmp);
        let m = sorted.len();
        let (gap_at, _) = (m / 4..3 * m / 4)
            .map(|i| (i, sorted[i + 1] - sorted[i]))
            .max_by(|a, b| a.1.total_cmp(&b.1))
            .unwrap();
        let rho_y = 0.5 * (sorted[gap_at] + sorted[gap_at + 1]);
        let margin = rho
            .iter()
            .map(|r| (r - rho_y).abs() / rho_y)
            .fold(f64::INFINITY, f64::min);
        let plastic = rho.iter().filter(|&&r| r > rho_y).count();
        assert!(
            margin > 0.02,
            "{element:?}: trial stresses too close to yield ({margin:e})"
        );
        let vm = Box::new(VonMises::try_new(young, nu, rho_y).unwrap());
        let (err, _) = tangent_error(&mut build(vm), u0, seed);
        println!(
            "{element:?} von Mises (ρ_y = {rho_y:.4e}, {plastic}/{m} points plastic, margin {margin:.3}): \
             tangent rel. error {err:.2e}"
        );
        assert!(plastic > 0 && plastic < m);
        assert!(
            err < 1e-6,
            "{element:?} von Mises: relative tangent error {err:e}"
        );
    }
}
