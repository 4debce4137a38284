//! Plane quadrilateral elements (4-node bilinear, 8-node serendipity) and meshes of them.
//!
//! Local coordinates ξ = (ξ, η) ∈ [−1, 1]². Local nodes are numbered counter-clockwise:
//! corners 0–3 at (−1,−1), (1,−1), (1,1), (−1,1); for Q8 the mid-side nodes 4–7 at
//! (0,−1), (1,0), (0,1), (−1,0). The maps are isoparametric, x(ξ) = Σ N_a(ξ) x_a.

use super::updated_lagrangian::FemMesh;
use crate::assembly::SupportTable;
use crate::error::{require_count, InputError, StepFailure};
use crate::quadrature::GaussRule;
use nalgebra::{Matrix2, SVector};
use serde::{Deserialize, Serialize};

/// Most nodes of a quadrilateral element.
pub const MAX_QUAD_NODES: usize = 8;

type V2 = SVector<f64, 2>;

/// Local coordinates of the nodes in local order (Q4 uses the first four).
const LOCAL_NODES: [[f64; 2]; MAX_QUAD_NODES] = [
    [-1.0, -1.0],
    [1.0, -1.0],
    [1.0, 1.0],
    [-1.0, 1.0],
    [0.0, -1.0],
    [1.0, 0.0],
    [0.0, 1.0],
    [-1.0, 0.0],
];

/// Plane quadrilateral element families.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum QuadElement {
    /// 4-node bilinear quadrilateral.
    Q4,
    /// 8-node serendipity quadrilateral (quadratic edges, no centre node).
    Q8,
}

impl QuadElement {
    pub fn nodes_per_element(self) -> usize {
        match self {
            QuadElement::Q4 => 4,
            QuadElement::Q8 => 8,
        }
    }

    /// Gauss points per axis of the default tensor rule: 2×2 for Q4 and 3×3 for Q8 (the
    /// paper's comparators, §5.2–5.3), both integrating the stiffness of an undistorted
    /// element exactly.
    pub fn default_gauss_points(self) -> usize {
        match self {
            QuadElement::Q4 => 2,
            QuadElement::Q8 => 3,
        }
    }

    /// Local coordinates of local node `a`.
    pub fn local_node(self, a: usize) -> V2 {
        V2::new(LOCAL_NODES[a][0], LOCAL_NODES[a][1])
    }

    /// Shape functions N_a(ξ) and local gradients ∂N_a/∂ξ in local node order (only the
    /// first [`Self::nodes_per_element`] entries are used).
    ///
    /// Q4: N_a = ¼(1 + ξ_a ξ)(1 + η_a η).
    /// Q8 corners: N_a = ¼(1 + ξ_a ξ)(1 + η_a η)(ξ_a ξ + η_a η − 1); mid-sides with ξ_a = 0:
    /// N_a = ½(1 − ξ²)(1 + η_a η), with η_a = 0: N_a = ½(1 + ξ_a ξ)(1 − η²).
    #[inline]
    pub fn shape(self, xi: &V2) -> ([f64; MAX_QUAD_NODES], [V2; MAX_QUAD_NODES]) {
        let (x, y) = (xi[0], xi[1]);
        let mut n = [0.0; MAX_QUAD_NODES];
        let mut dn = [V2::zeros(); MAX_QUAD_NODES];
        match self {
            QuadElement::Q4 => {
                for a in 0..4 {
                    let [xa, ya] = LOCAL_NODES[a];
                    let (sx, sy) = (1.0 + xa * x, 1.0 + ya * y);
                    n[a] = 0.25 * sx * sy;
                    dn[a] = V2::new(0.25 * xa * sy, 0.25 * ya * sx);
                }
            }
            QuadElement::Q8 => {
                for a in 0..4 {
                    let [xa, ya] = LOCAL_NODES[a];
                    let (sx, sy) = (1.0 + xa * x, 1.0 + ya * y);
                    let t = xa * x + ya * y - 1.0;
                    n[a] = 0.25 * sx * sy * t;
                    dn[a] = V2::new(0.25 * xa * sy * (t + sx), 0.25 * ya * sx * (t + sy));
                }
                for a in 4..8 {
                    let [xa, ya] = LOCAL_NODES[a];
                    if xa == 0.0 {
                        let sy = 1.0 + ya * y;
                        n[a] = 0.5 * (1.0 - x * x) * sy;
                        dn[a] = V2::new(-x * sy, 0.5 * (1.0 - x * x) * ya);
                    } else {
                        let sx = 1.0 + xa * x;
                        n[a] = 0.5 * sx * (1.0 - y * y);
                        dn[a] = V2::new(0.5 * xa * (1.0 - y * y), -y * sx);
                    }
                }
            }
        }
        (n, dn)
    }

    /// Position x(ξ) = Σ N_a x_a and Jacobian J = ∂x/∂ξ = Σ x_a ⊗ ∂N_a/∂ξ (eq 34) of an
    /// element with nodal coordinates `x` (local order), with the shape function values.
    #[inline]
    pub fn map(self, x: &[V2], xi: &V2) -> (V2, Matrix2<f64>, [f64; MAX_QUAD_NODES], [V2; MAX_QUAD_NODES]) {
        let (n, dn) = self.shape(xi);
        let mut pos = V2::zeros();
        let mut jac = Matrix2::zeros();
        for a in 0..self.nodes_per_element() {
            pos += x[a] * n[a];
            jac += x[a] * dn[a].transpose();
        }
        (pos, jac, n, dn)
    }

    /// The tensor-product Gauss rule with `n` points per axis: points (ξ_i, η_j) and weights
    /// w_i w_j, ξ fastest.
    pub fn tensor_rule(n: usize) -> Result<Vec<(V2, f64)>, InputError> {
        let rule = GaussRule::try_new(n)?;
        let mut out = Vec::with_capacity(n * n);
        for (&y, &wy) in rule.points().iter().zip(rule.weights()) {
            for (&x, &wx) in rule.points().iter().zip(rule.weights()) {
                out.push((V2::new(x, y), wx * wy));
            }
        }
        Ok(out)
    }

    /// Where an element is checked for a positive Jacobian: the nodes, the centre and the
    /// 3×3 Gauss points. For Q4 det J is bilinear-free (a₀ + a₁ξ + a₂η), so positive
    /// corners imply a positive Jacobian everywhere; for Q8 it is a necessary check.
    fn check_points(self) -> impl Iterator<Item = V2> {
        let g = 0.6f64.sqrt();
        let nodes = (0..self.nodes_per_element()).map(move |a| self.local_node(a));
        let inner = [-g, 0.0, g]
            .into_iter()
            .flat_map(move |y| [-g, 0.0, g].into_iter().map(move |x| V2::new(x, y)));
        nodes.chain(inner)
    }
}

/// A mesh of quadrilaterals of one family: node coordinates and element connectivity
/// (local node order of [`QuadElement`], flat, [`QuadElement::nodes_per_element`] per element).
#[derive(Debug, Clone, PartialEq)]
pub struct PlaneMesh {
    pub element: QuadElement,
    /// Node coordinates.
    pub nodes: Vec<V2>,
    /// Element `e` uses nodes `connectivity[k e .. k (e + 1)]`, k nodes per element.
    pub connectivity: Vec<usize>,
}

impl PlaneMesh {
    /// A mesh from nodes and connectivity. Every element must reference existing, distinct
    /// nodes and have det(∂x/∂ξ) > 0 at its nodes, centre and 3×3 Gauss points
    /// (counter-clockwise, not degenerate).
    pub fn try_new(
        element: QuadElement,
        nodes: Vec<V2>,
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
                    "element must be counter-clockwise and not degenerate (det ∂x/∂ξ > 0)",
                ));
            }
        }
        Ok(mesh)
    }

    /// A structured mesh of `cells.0 × cells.1` equal rectangles covering
    /// `[origin, origin + size]`, mid-side nodes (Q8) at edge midpoints.
    ///
    /// Nodes are numbered row by row from the bottom-left, x fastest, on the lattice of
    /// corner (Q4) or corner and mid-side (Q8) positions; element `e = j nx + i` is cell (i, j).
    pub fn rectangle(
        origin: V2,
        size: V2,
        cells: (usize, usize),
        element: QuadElement,
    ) -> Result<Self, InputError> {
        let (nx, ny) = cells;
        require_count("mesh cells x", nx, 1)?;
        require_count("mesh cells y", ny, 1)?;
        for a in 0..2 {
            crate::error::require_finite(&format!("mesh origin[{a}]"), origin[a])?;
            crate::error::require_positive(&format!("mesh size[{a}]"), size[a])?;
        }
        // Lattice with spacing h/r (r = 1 for Q4, 2 for Q8); Q8 skips cell-centre positions.
        let r = if element == QuadElement::Q8 { 2 } else { 1 };
        let (mx, my) = (r * nx + 1, r * ny + 1);
        let cell = V2::new(size[0] / nx as f64, size[1] / ny as f64);
        let mut index = vec![usize::MAX; mx * my];
        let mut nodes = Vec::with_capacity(mx * my);
        for j in 0..my {
            for i in 0..mx {
                if r == 2 && i % 2 == 1 && j % 2 == 1 {
                    continue;
                }
                index[j * mx + i] = nodes.len();
                // Exact end coordinates, so that boundary lookups need no tolerance games.
                let x = if i + 1 == mx {
                    origin[0] + size[0]
                } else {
                    origin[0] + cell[0] * i as f64 / r as f64
                };
                let y = if j + 1 == my {
                    origin[1] + size[1]
                } else {
                    origin[1] + cell[1] * j as f64 / r as f64
                };
                nodes.push(V2::new(x, y));
            }
        }
        let k = element.nodes_per_element();
        let mut connectivity = Vec::with_capacity(nx * ny * k);
        for cj in 0..ny {
            for ci in 0..nx {
                let (i0, j0) = (r * ci, r * cj);
                for a in 0..k {
                    let [lx, ly] = LOCAL_NODES[a];
                    let i = (i0 as f64 + (lx + 1.0) * 0.5 * r as f64) as usize;
                    let j = (j0 as f64 + (ly + 1.0) * 0.5 * r as f64) as usize;
                    connectivity.push(index[j * mx + i]);
                }
            }
        }
        Self::try_new(element, nodes, connectivity)
    }

    pub fn num_elements(&self) -> usize {
        self.connectivity.len() / self.element.nodes_per_element()
    }

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
    pub fn element_coordinates(&self, e: usize) -> [V2; MAX_QUAD_NODES] {
        let mut x = [V2::zeros(); MAX_QUAD_NODES];
        for (xa, &n) in x.iter_mut().zip(self.element_nodes(e)) {
            *xa = self.nodes[n];
        }
        x
    }

    /// Position x(ξ) and Jacobian ∂x/∂ξ in element `e`.
    pub fn map(&self, e: usize, xi: &V2) -> (V2, Matrix2<f64>) {
        let x = self.element_coordinates(e);
        let (pos, jac, _, _) = self.element.map(&x, xi);
        (pos, jac)
    }

    /// Smallest det(∂x/∂ξ) of element `e` over its check points (NaN if one is not finite).
    pub fn min_jacobian(&self, e: usize) -> f64 {
        let x = self.element_coordinates(e);
        let mut min = f64::INFINITY;
        for xi in self.element.check_points() {
            let (_, jac, _, _) = self.element.map(&x, &xi);
            let d = jac.determinant();
            if !d.is_finite() {
                return f64::NAN;
            }
            min = min.min(d);
        }
        min
    }

    /// Nodes within `tol` of the segment from `a` to `b`, ordered along it.
    pub fn nodes_on_segment(&self, a: V2, b: V2, tol: f64) -> Vec<usize> {
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

    /// Nodes whose coordinate `axis` is within `tol` of `value` (e.g. an edge of a rectangle).
    pub fn nodes_at(&self, axis: usize, value: f64, tol: f64) -> Vec<usize> {
        (0..self.num_nodes())
            .filter(|&i| (self.nodes[i][axis] - value).abs() <= tol)
            .collect()
    }

    /// The node nearest to `x`.
    pub fn nearest_node(&self, x: V2) -> usize {
        (0..self.num_nodes())
            .min_by(|&i, &j| {
                (self.nodes[i] - x)
                    .norm_squared()
                    .total_cmp(&(self.nodes[j] - x).norm_squared())
            })
            .expect("a mesh has nodes")
    }
}

impl FemMesh<2> for PlaneMesh {
    type Local = V2;

    fn num_nodes(&self) -> usize {
        self.nodes.len()
    }

    /// N_a(ξ_q) and ∂N_a/∂X̃ = J⁻ᵀ ∂N_a/∂ξ with J = ∂X̃/∂ξ on the current mesh (eqs 33–34).
    fn fill_supports(
        &self,
        elements: &[usize],
        xis: &[V2],
        table: &mut SupportTable<2>,
    ) -> Result<(), StepFailure> {
        let k = self.element.nodes_per_element();
        table.clear();
        for (p, (&e, xi)) in elements.iter().zip(xis).enumerate() {
            let x = self.element_coordinates(e);
            let (_, jac, n, dn) = self.element.map(&x, xi);
            let det = jac.determinant();
            let inv_t = match jac.try_inverse() {
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
            *x += V2::new(du[2 * n], du[2 * n + 1]);
        }
    }
}
