//! Meshes of tensor-product elements in 2D and 3D: the linear (Q4, Hex8) and serendipity
//! quadratic (Q8, Hex20) families share one shape-function formula and one mesh type, so the
//! plane and solid comparators differ only in their node tables.
//!
//! Local coordinates ξ ∈ [−1, 1]^D. Corners come first, then (quadratic) the mid-edge nodes,
//! each with exactly one zero local coordinate. The maps are isoparametric,
//! x(ξ) = Σ N_a(ξ) x_a, with J = ∂x/∂ξ = Σ x_a ⊗ ∂N_a/∂ξ (eq 34).

use super::updated_lagrangian::FemMesh;
use crate::discretise::assembly::SupportTable;
use crate::solver::error::{require_count, InputError, StepFailure};
use nalgebra::{Matrix3, SMatrix, SVector};
use std::fmt::Debug;

/// Most nodes of an element of [`ElementFamily`] (Hex20).
pub const MAX_ELEMENT_NODES: usize = 20;

/// Shape values and local gradients of one element at one ξ (the first
/// [`ElementFamily::nodes_per_element`] entries are used).
pub type Shape<const D: usize> = ([f64; MAX_ELEMENT_NODES], [SVector<f64, D>; MAX_ELEMENT_NODES]);

/// A family of tensor-product elements: its node table and whether it is quadratic.
pub trait ElementFamily<const D: usize>: Copy + Debug + PartialEq + Send + Sync {
    /// Local coordinates of the nodes in local order.
    fn local_nodes(self) -> &'static [[f64; D]];
    /// Serendipity quadratic (mid-edge nodes) rather than linear.
    fn quadratic(self) -> bool;
    /// Gauss points per axis of the default rule: 2 for linear, 3 for quadratic elements, both
    /// integrating the stiffness of an undistorted element exactly (the paper's comparators).
    fn default_gauss_points(self) -> usize {
        if self.quadratic() {
            3
        } else {
            2
        }
    }
    /// Nodes per element.
    fn nodes_per_element(self) -> usize {
        self.local_nodes().len()
    }
    /// Local coordinates of local node `a`.
    fn local_node(self, a: usize) -> SVector<f64, D> {
        SVector::from(self.local_nodes()[a])
    }
    /// N_a(ξ) and ∂N_a/∂ξ in local node order ([`serendipity_shape`]).
    fn shape(self, xi: &SVector<f64, D>) -> Shape<D> {
        serendipity_shape(self.local_nodes(), self.quadratic(), xi)
    }
}

/// Shape functions of the linear and serendipity quadratic tensor-product elements in D
/// dimensions, with s_j = 1 + ξ_a,j ξ_j:
/// - linear: N_a = 2^−D Π_j s_j;
/// - quadratic corner: N_a = 2^−D Π_j s_j (Σ_j ξ_a,j ξ_j − (D − 1));
/// - quadratic mid-edge (ξ_a,k = 0): N_a = 2^−(D−1) (1 − ξ_k²) Π_{j≠k} s_j.
///
/// For D = 2 these are Q4 and Q8, for D = 3 Hex8 and Hex20 (Zienkiewicz & Taylor §8.7).
pub fn serendipity_shape<const D: usize>(
    nodes: &[[f64; D]],
    quadratic: bool,
    xi: &SVector<f64, D>,
) -> Shape<D> {
    let mut n = [0.0; MAX_ELEMENT_NODES];
    let mut dn = [SVector::<f64, D>::zeros(); MAX_ELEMENT_NODES];
    let scale = 0.5f64.powi(D as i32);
    for (a, xa) in nodes.iter().enumerate() {
        let s: [f64; D] = std::array::from_fn(|j| 1.0 + xa[j] * xi[j]);
        // Π_{j≠i} s_j (and, for the mid-edge node, without the zero axis k).
        let prod_but =
            |skip: &[usize]| -> f64 { (0..D).filter(|j| !skip.contains(j)).map(|j| s[j]).product() };
        match (quadratic, xa.iter().position(|&c| c == 0.0)) {
            (false, _) => {
                n[a] = scale * prod_but(&[]);
                for i in 0..D {
                    dn[a][i] = scale * xa[i] * prod_but(&[i]);
                }
            }
            (true, None) => {
                let t: f64 = (0..D).map(|j| xa[j] * xi[j]).sum::<f64>() - (D as f64 - 1.0);
                let p = prod_but(&[]);
                n[a] = scale * p * t;
                for i in 0..D {
                    dn[a][i] = scale * xa[i] * prod_but(&[i]) * (t + s[i]);
                }
            }
            (true, Some(k)) => {
                let q = 1.0 - xi[k] * xi[k];
                let c = 2.0 * scale;
                n[a] = c * q * prod_but(&[k]);
                for i in 0..D {
                    dn[a][i] = if i == k {
                        -2.0 * c * xi[k] * prod_but(&[k])
                    } else {
                        c * q * xa[i] * prod_but(&[k, i])
                    };
                }
            }
        }
    }
    (n, dn)
}

/// det J and J⁻¹ of a D×D Jacobian (D ≤ 3), through its embedding in a 3×3 matrix with
/// unit diagonal padding, since nalgebra's closed-form inverse and determinant are per size.
#[inline]
pub(crate) fn det_inverse<const D: usize>(jac: &SMatrix<f64, D, D>) -> (f64, Option<SMatrix<f64, D, D>>) {
    let mut m = Matrix3::identity();
    m.view_mut((0, 0), (D, D)).copy_from(jac);
    let det = m.determinant();
    let inv = m
        .try_inverse()
        .map(|i| SMatrix::<f64, D, D>::from_fn(|r, c| i[(r, c)]));
    (det, inv)
}

/// A mesh of one element family: node coordinates and connectivity (local node order, flat,
/// [`ElementFamily::nodes_per_element`] per element).
#[derive(Debug, Clone, PartialEq)]
pub struct ElementMesh<const D: usize, E> {
    /// The element family of every element.
    pub element: E,
    /// Node coordinates.
    pub nodes: Vec<SVector<f64, D>>,
    /// Element `e` uses nodes `connectivity[k e .. k (e + 1)]`, k nodes per element.
    pub connectivity: Vec<usize>,
}

impl<const D: usize, E: ElementFamily<D>> ElementMesh<D, E> {
    /// A mesh from nodes and connectivity. Every element must reference existing, distinct
    /// nodes and have det(∂x/∂ξ) > 0 at its nodes and its 3^D check points (positively
    /// oriented, not degenerate).
    pub fn try_new(
        element: E,
        nodes: Vec<SVector<f64, D>>,
        connectivity: Vec<usize>,
    ) -> Result<Self, InputError> {
        let k = element.nodes_per_element();
        if connectivity.is_empty() || connectivity.len() % k != 0 {
            return Err(InputError::new(
                "mesh connectivity",
                format!("{} entries", connectivity.len()),
                format!("must be a positive multiple of {k} (nodes per {element:?} element)"),
            ));
        }
        if let Some((i, x)) = nodes
            .iter()
            .enumerate()
            .find(|(_, x)| !x.iter().all(|v| v.is_finite()))
        {
            return Err(InputError::new(
                format!("mesh node {i}"),
                format!("{:?}", x.as_slice()),
                "coordinates must be finite",
            ));
        }
        let mesh = Self {
            element,
            nodes,
            connectivity,
        };
        for e in 0..mesh.num_elements() {
            let ids = mesh.element_nodes(e);
            for (a, &n) in ids.iter().enumerate() {
                if n >= mesh.num_nodes() || ids[..a].contains(&n) {
                    return Err(InputError::new(
                        format!("mesh element {e}"),
                        format!("nodes {ids:?}"),
                        format!("nodes must be distinct and < {}", mesh.num_nodes()),
                    ));
                }
            }
            let det = mesh.min_jacobian(e);
            if det.is_nan() || det <= 0.0 {
                return Err(InputError::new(
                    format!("mesh element {e}"),
                    format!("nodes {ids:?}, min det J = {det:e}"),
                    "element must be positively oriented (counter-clockwise in 2D) and not degenerate (det ∂x/∂ξ > 0)",
                ));
            }
        }
        Ok(mesh)
    }

    /// A structured mesh of `cells[0] × … × cells[D−1]` equal boxes covering
    /// `[origin, origin + size]`, mid-edge nodes (quadratic) at edge midpoints.
    ///
    /// Nodes are numbered on the lattice of corner (linear) or corner and mid-edge (quadratic)
    /// positions, the first axis fastest; the quadratic lattice skips face and cell centres
    /// (lattice points with two or more odd indices). Element `e` is cell
    /// `(i, j, …)` with `e = i + n_x (j + n_y k)`.
    pub fn structured(
        origin: SVector<f64, D>,
        size: SVector<f64, D>,
        cells: [usize; D],
        element: E,
    ) -> Result<Self, InputError> {
        const AXES: [&str; 3] = ["x", "y", "z"];
        for a in 0..D {
            require_count(&format!("mesh cells {}", AXES[a]), cells[a], 1)?;
            crate::solver::error::require_finite(&format!("mesh origin[{a}]"), origin[a])?;
            crate::solver::error::require_positive(&format!("mesh size[{a}]"), size[a])?;
        }
        let r = if element.quadratic() { 2 } else { 1 };
        // Checked in floating point before any product of counts can overflow or allocate:
        // the lattice's nodes (an upper bound of the mesh's) and Gauss points (r + 1 per axis).
        let cells_f: f64 = cells.iter().map(|&c| c as f64).product();
        crate::mesh::budget::CaseSize {
            dimension: D,
            nodes: cells.iter().map(|&c| r as f64 * c as f64 + 1.0).product(),
            points: cells_f * ((r + 1) as f64).powi(D as i32),
            coupled_nodes: crate::mesh::budget::stencil(D, r),
        }
        .check("mesh cells", format!("{cells:?}"))?;
        let m: [usize; D] = std::array::from_fn(|a| r * cells[a] + 1);
        let total: usize = m.iter().product();
        let lattice = |mut flat: usize| -> [usize; D] {
            std::array::from_fn(|a| {
                let i = flat % m[a];
                flat /= m[a];
                i
            })
        };
        let mut index = vec![usize::MAX; total];
        let mut nodes = Vec::with_capacity(total);
        for (flat, slot) in index.iter_mut().enumerate() {
            let idx = lattice(flat);
            if r == 2 && idx.iter().filter(|&&i| i % 2 == 1).count() >= 2 {
                continue;
            }
            *slot = nodes.len();
            // Exact end coordinates, so that boundary lookups need no tolerance games.
            nodes.push(SVector::<f64, D>::from_fn(|a, _| {
                if idx[a] + 1 == m[a] {
                    origin[a] + size[a]
                } else {
                    origin[a] + size[a] / cells[a] as f64 * idx[a] as f64 / r as f64
                }
            }));
        }
        let k = element.nodes_per_element();
        let num_cells: usize = cells.iter().product();
        let mut connectivity = Vec::with_capacity(num_cells * k);
        for c in 0..num_cells {
            let mut rest = c;
            let cell: [usize; D] = std::array::from_fn(|a| {
                let i = rest % cells[a];
                rest /= cells[a];
                i
            });
            for local in element.local_nodes() {
                let mut flat = 0;
                for a in (0..D).rev() {
                    let i = r * cell[a] + ((local[a] + 1.0) * 0.5 * r as f64).round() as usize;
                    flat = flat * m[a] + i;
                }
                connectivity.push(index[flat]);
            }
        }
        Self::try_new(element, nodes, connectivity)
    }

    /// Number of elements.
    pub fn num_elements(&self) -> usize {
        self.connectivity.len() / self.element.nodes_per_element()
    }

    /// Number of nodes.
    pub fn num_nodes(&self) -> usize {
        self.nodes.len()
    }

    /// Global nodes of element `e` in local order.
    #[inline]
    pub fn element_nodes(&self, e: usize) -> &[usize] {
        let k = self.element.nodes_per_element();
        &self.connectivity[k * e..k * (e + 1)]
    }

    /// Nodal coordinates of element `e` in local order (unused entries zero).
    #[inline]
    pub fn element_coordinates(&self, e: usize) -> [SVector<f64, D>; MAX_ELEMENT_NODES] {
        let mut x = [SVector::zeros(); MAX_ELEMENT_NODES];
        for (xa, &n) in x.iter_mut().zip(self.element_nodes(e)) {
            *xa = self.nodes[n];
        }
        x
    }

    /// Position, Jacobian ∂x/∂ξ (eq 34) and shape functions of element `e` at ξ.
    #[inline]
    fn map_full(&self, e: usize, xi: &SVector<f64, D>) -> (SVector<f64, D>, SMatrix<f64, D, D>, Shape<D>) {
        let x = self.element_coordinates(e);
        let (n, dn) = self.element.shape(xi);
        let mut pos = SVector::zeros();
        let mut jac = SMatrix::zeros();
        for a in 0..self.element.nodes_per_element() {
            pos += x[a] * n[a];
            jac += x[a] * dn[a].transpose();
        }
        (pos, jac, (n, dn))
    }

    /// Position x(ξ) and Jacobian ∂x/∂ξ in element `e`.
    pub fn map(&self, e: usize, xi: &SVector<f64, D>) -> (SVector<f64, D>, SMatrix<f64, D, D>) {
        let (pos, jac, _) = self.map_full(e, xi);
        (pos, jac)
    }

    /// Where an element is checked for a positive Jacobian: its nodes and the 3^D points of
    /// the 3-point Gauss rule's abscissae and the centre. For the linear elements det J is
    /// multilinear, so positive corners imply a positive Jacobian; for the quadratic ones
    /// it is a necessary check.
    fn check_points(&self) -> impl Iterator<Item = SVector<f64, D>> + '_ {
        let g = 0.6f64.sqrt();
        let nodes = (0..self.element.nodes_per_element()).map(|a| self.element.local_node(a));
        let inner = (0..3usize.pow(D as u32)).map(move |mut flat| {
            SVector::<f64, D>::from_fn(|_, _| {
                let v = [-g, 0.0, g][flat % 3];
                flat /= 3;
                v
            })
        });
        nodes.chain(inner)
    }

    /// Smallest det(∂x/∂ξ) of element `e` over its check points (NaN if one is not finite).
    pub fn min_jacobian(&self, e: usize) -> f64 {
        let mut min = f64::INFINITY;
        for xi in self.check_points() {
            let d = det_inverse(&self.map(e, &xi).1).0;
            if !d.is_finite() {
                return f64::NAN;
            }
            min = min.min(d);
        }
        min
    }

    /// Nodes within `tol` of the segment from `a` to `b`, ordered along it.
    pub fn nodes_on_segment(&self, a: SVector<f64, D>, b: SVector<f64, D>, tol: f64) -> Vec<usize> {
        let d = b - a;
        let len2 = d.norm_squared();
        let mut found: Vec<(f64, usize)> = self
            .nodes
            .iter()
            .enumerate()
            .filter_map(|(i, x)| {
                let t = if len2 > 0.0 {
                    ((x - a).dot(&d) / len2).clamp(0.0, 1.0)
                } else {
                    0.0
                };
                ((x - (a + d * t)).norm() <= tol).then_some((t, i))
            })
            .collect();
        found.sort_by(|p, q| p.0.total_cmp(&q.0));
        found.into_iter().map(|(_, i)| i).collect()
    }

    /// Nodes whose coordinate `axis` is within `tol` of `value` (e.g. a face of a box).
    pub fn nodes_at(&self, axis: usize, value: f64, tol: f64) -> Vec<usize> {
        (0..self.num_nodes())
            .filter(|&i| (self.nodes[i][axis] - value).abs() <= tol)
            .collect()
    }

    /// The node nearest to `x`.
    pub fn nearest_node(&self, x: SVector<f64, D>) -> usize {
        (0..self.num_nodes())
            .min_by(|&i, &j| {
                (self.nodes[i] - x)
                    .norm_squared()
                    .total_cmp(&(self.nodes[j] - x).norm_squared())
            })
            .expect("a mesh has nodes")
    }
}

impl<const D: usize, E: ElementFamily<D>> FemMesh<D> for ElementMesh<D, E> {
    type Local = SVector<f64, D>;

    fn num_nodes(&self) -> usize {
        self.nodes.len()
    }

    /// N_a(ξ_q) and ∂N_a/∂X̃ = J⁻ᵀ ∂N_a/∂ξ with J = ∂X̃/∂ξ on the current mesh (eqs 33–34).
    fn fill_supports(
        &self,
        elements: &[usize],
        xis: &[SVector<f64, D>],
        table: &mut SupportTable<D>,
    ) -> Result<(), StepFailure> {
        let k = self.element.nodes_per_element();
        table.clear();
        for (p, (&e, xi)) in elements.iter().zip(xis).enumerate() {
            let (_, jac, (n, dn)) = self.map_full(e, xi);
            let (det, inv) = det_inverse(&jac);
            let inv_t = match inv {
                Some(inv) if det > 0.0 && det.is_finite() => inv.transpose(),
                _ => {
                    return Err(StepFailure::Kinematics {
                        point: p,
                        reason: format!("element {e} has det(∂x/∂ξ) = {det:e} <= 0 at a Gauss point"),
                    })
                }
            };
            let nodes = self.element_nodes(e);
            for a in 0..k {
                table.push_node(nodes[a], n[a], inv_t * dn[a]);
            }
            table.finish_point();
        }
        Ok(())
    }

    fn move_nodes(&mut self, du: &[f64]) {
        for (n, x) in self.nodes.iter_mut().enumerate() {
            for a in 0..D {
                x[a] += du[D * n + a];
            }
        }
    }
}

/// The multigrid's view of a mesh (its geometry adapter lives with the mesh, so the solver
/// layers need not know the FEM types).
impl crate::solver::multigrid::NodeGeometry {
    /// The nodes of an FEM mesh; the spacing is that of the first element's nodes (its
    /// extent per axis, halved for quadratic elements, whose mid-edge nodes halve it).
    pub fn of_mesh<const D: usize, E: ElementFamily<D>>(mesh: &ElementMesh<D, E>) -> Self {
        let mut spacing = [1.0; 3];
        if mesh.num_elements() > 0 {
            let nodes = mesh.element_nodes(0);
            for (a, h) in spacing.iter_mut().enumerate().take(D) {
                let (lo, hi) = nodes
                    .iter()
                    .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &n| {
                        (lo.min(mesh.nodes[n][a]), hi.max(mesh.nodes[n][a]))
                    });
                *h = (hi - lo) / if mesh.element.quadratic() { 2.0 } else { 1.0 };
            }
        }
        crate::solver::multigrid::NodeGeometry {
            dim: D,
            positions: mesh.nodes.iter().map(crate::material::tensor::pad3).collect(),
            spacing,
        }
    }
}
