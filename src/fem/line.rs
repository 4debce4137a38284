//! One-dimensional Lagrange line elements and meshes of them.

use super::updated_lagrangian::FemMesh;
use crate::discretise::assembly::SupportTable;
use crate::solver::error::{InputError, StepFailure};
use nalgebra::SVector;
use serde::{Deserialize, Serialize};

/// Most nodes of a line element.
pub const MAX_LINE_NODES: usize = 3;

/// 1D element families of the comparators.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum LineElement {
    /// Two-noded linear element (local nodes at ξ = −1, 1).
    Linear,
    /// Three-noded quadratic element (local nodes at ξ = −1, 0, 1).
    Quadratic,
}

impl LineElement {
    /// Polynomial degree k: an element spans global nodes `k e ..= k e + k`.
    pub fn degree(self) -> usize {
        match self {
            LineElement::Linear => 1,
            LineElement::Quadratic => 2,
        }
    }

    /// Nodes per element, k + 1.
    pub fn nodes_per_element(self) -> usize {
        self.degree() + 1
    }

    /// The paper's Gauss rule (§5.1): 2 points for linear, 3 for quadratic elements, one more
    /// than the minimum that integrates the stiffness of an undistorted element exactly.
    pub fn default_gauss_points(self) -> usize {
        match self {
            LineElement::Linear => 2,
            LineElement::Quadratic => 3,
        }
    }

    /// Shape functions N_a(ξ) and derivatives dN_a/dξ in local node order (only the first
    /// [`Self::nodes_per_element`] entries are used).
    pub fn shape(self, xi: f64) -> ([f64; MAX_LINE_NODES], [f64; MAX_LINE_NODES]) {
        match self {
            LineElement::Linear => ([0.5 * (1.0 - xi), 0.5 * (1.0 + xi), 0.0], [-0.5, 0.5, 0.0]),
            LineElement::Quadratic => (
                [0.5 * xi * (xi - 1.0), 1.0 - xi * xi, 0.5 * xi * (xi + 1.0)],
                [xi - 0.5, -2.0 * xi, xi + 0.5],
            ),
        }
    }

    /// Position Σ N_a X_a and Jacobian dX/dξ = Σ dN_a/dξ X_a (eq 34) at ξ of an element with
    /// nodal coordinates `x` (local order).
    pub fn map(self, x: &[f64], xi: f64) -> (f64, f64) {
        let (n, dn) = self.shape(xi);
        let k = self.nodes_per_element();
        let pos = (0..k).map(|a| n[a] * x[a]).sum();
        let jac = (0..k).map(|a| dn[a] * x[a]).sum();
        (pos, jac)
    }
}

/// A mesh of line elements of one family. Nodes are numbered along the line: element `e`
/// uses nodes `k e ..= k e + k` (k the degree), so a quadratic element's mid node is `2e + 1`.
#[derive(Debug, Clone, PartialEq)]
pub struct LineMesh {
    /// The element family (linear or quadratic).
    pub element: LineElement,
    /// Node coordinates.
    pub nodes: Vec<f64>,
}

impl LineMesh {
    /// `elements` equal elements on `[lower, upper]`, mid nodes at element centres.
    pub fn uniform(
        element: LineElement,
        lower: f64,
        upper: f64,
        elements: usize,
    ) -> Result<Self, InputError> {
        crate::solver::error::require_count("elements", elements, 1)?;
        if !(lower.is_finite() && upper.is_finite() && upper > lower) {
            return Err(InputError::new(
                "mesh upper bound",
                upper,
                format!("must be finite and > lower bound {lower}"),
            ));
        }
        let k = element.degree();
        let n = k * elements;
        let h = (upper - lower) / n as f64;
        let mut nodes: Vec<f64> = (0..=n).map(|i| lower + i as f64 * h).collect();
        nodes[n] = upper;
        Self::try_new(element, nodes)
    }

    /// Straight elements between consecutive `vertices` (ascending), mid nodes at centres.
    pub fn from_vertices(element: LineElement, vertices: &[f64]) -> Result<Self, InputError> {
        let mut nodes = Vec::with_capacity(vertices.len() * element.degree());
        for (i, &v) in vertices.iter().enumerate() {
            if i > 0 && element == LineElement::Quadratic {
                nodes.push(0.5 * (vertices[i - 1] + v));
            }
            nodes.push(v);
        }
        Self::try_new(element, nodes)
    }

    /// A mesh from all node coordinates (mid nodes included). Every element must have a
    /// positive Jacobian on [−1, 1]; for a quadratic element that means the mid node lies in
    /// the middle half of the element.
    pub fn try_new(element: LineElement, nodes: Vec<f64>) -> Result<Self, InputError> {
        let k = element.degree();
        if nodes.len() < k + 1 || (nodes.len() - 1) % k != 0 {
            return Err(InputError::new(
                "mesh nodes",
                nodes.len(),
                format!("must be k * elements + 1 with k = {k} and elements >= 1"),
            ));
        }
        let mesh = Self { element, nodes };
        for e in 0..mesh.num_elements() {
            let x = mesh.element_coordinates(e);
            for xi in [-1.0, 1.0] {
                let (_, j) = element.map(&x[..k + 1], xi);
                if !(j > 0.0 && j.is_finite()) {
                    return Err(InputError::new(
                        format!("mesh element {e}"),
                        format!("{:?}", &x[..k + 1]),
                        "nodes must be finite and ordered so that dX/dξ > 0 on [-1, 1]",
                    ));
                }
            }
        }
        Ok(mesh)
    }

    /// Number of elements.
    pub fn num_elements(&self) -> usize {
        (self.nodes.len() - 1) / self.element.degree()
    }

    /// Number of nodes, mid nodes included.
    pub fn num_nodes(&self) -> usize {
        self.nodes.len()
    }

    /// First global node of element `e`; its nodes are `first .. first + nodes_per_element`.
    pub fn first_node(&self, e: usize) -> usize {
        self.element.degree() * e
    }

    /// Nodal coordinates of element `e` in local order (unused entries zero).
    pub fn element_coordinates(&self, e: usize) -> [f64; MAX_LINE_NODES] {
        let mut x = [0.0; MAX_LINE_NODES];
        let a = self.first_node(e);
        for (k, xk) in x.iter_mut().enumerate().take(self.element.nodes_per_element()) {
            *xk = self.nodes[a + k];
        }
        x
    }
}

impl FemMesh<1> for LineMesh {
    type Local = f64;

    fn num_nodes(&self) -> usize {
        self.nodes.len()
    }

    /// N_a(ξ_q) and ∂N_a/∂X̃ = (dX̃/dξ)⁻¹ dN_a/dξ on the current mesh (eqs 33–34).
    fn fill_supports(
        &self,
        elements: &[usize],
        xis: &[f64],
        table: &mut SupportTable<1>,
    ) -> Result<(), StepFailure> {
        let element = self.element;
        let k = element.nodes_per_element();
        table.clear();
        for (p, (&e, &xi)) in elements.iter().zip(xis).enumerate() {
            let x = self.element_coordinates(e);
            let (n, dn) = element.shape(xi);
            let (_, jac) = element.map(&x[..k], xi);
            if !(jac > 0.0 && jac.is_finite()) {
                return Err(StepFailure::Kinematics {
                    point: p,
                    reason: format!("element {e} has dX/dξ = {jac:e} <= 0 at its Gauss point"),
                });
            }
            let first = self.first_node(e);
            for a in 0..k {
                table.push_node(first + a, n[a], SVector::<f64, 1>::new(dn[a] / jac));
            }
            table.finish_point();
        }
        Ok(())
    }

    fn move_nodes(&mut self, du: &[f64]) {
        self.nodes.iter_mut().zip(du).for_each(|(x, d)| *x += d);
    }
}
