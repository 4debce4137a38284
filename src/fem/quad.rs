//! Plane quadrilateral elements (4-node bilinear, 8-node serendipity) and meshes of them.
//!
//! Local coordinates ξ = (ξ, η) ∈ [−1, 1]². Local nodes are numbered counter-clockwise:
//! corners 0–3 at (−1,−1), (1,−1), (1,1), (−1,1); for Q8 the mid-side nodes 4–7 at
//! (0,−1), (1,0), (0,1), (−1,0). Shape functions and meshes are those of [`super::mesh`].

use super::mesh::{ElementFamily, ElementMesh};
use crate::solver::error::InputError;
use nalgebra::SVector;
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

impl ElementFamily<2> for QuadElement {
    fn local_nodes(self) -> &'static [[f64; 2]] {
        match self {
            QuadElement::Q4 => &LOCAL_NODES[..4],
            QuadElement::Q8 => &LOCAL_NODES,
        }
    }
    fn quadratic(self) -> bool {
        self == QuadElement::Q8
    }
}

impl QuadElement {
    /// The tensor-product Gauss rule with `n` points per axis: points (ξ_i, η_j) and weights
    /// w_i w_j, ξ fastest.
    pub fn tensor_rule(n: usize) -> Result<Vec<(V2, f64)>, InputError> {
        crate::mesh::quadrature::tensor_rule::<2>(n)
    }
}

/// A mesh of quadrilaterals of one family.
pub type PlaneMesh = ElementMesh<2, QuadElement>;

impl ElementMesh<2, QuadElement> {
    /// A structured mesh of `cells.0 × cells.1` equal rectangles covering
    /// `[origin, origin + size]` ([`ElementMesh::structured`]): nodes row by row from the
    /// bottom-left, x fastest; element `e = j nx + i` is cell (i, j).
    pub fn rectangle(
        origin: V2,
        size: V2,
        cells: (usize, usize),
        element: QuadElement,
    ) -> Result<Self, InputError> {
        Self::structured(origin, size, [cells.0, cells.1], element)
    }
}
