//! Hexahedral elements (8-node trilinear, 20-node serendipity) and meshes of them: the 3D
//! comparators of the issue-15 examples.
//!
//! Local coordinates ξ ∈ [−1, 1]³, nodes in VTK order: corners 0–3 on ζ = −1 and 4–7 on
//! ζ = +1, each face counter-clockwise seen from +ζ; for Hex20 the mid-edge nodes 8–11 of
//! the bottom face, 12–15 of the top face (edges 0–1, 1–2, 2–3, 3–0 and 4–5, …) and 16–19 of
//! the vertical edges 0–4, 1–5, 2–6, 3–7. Shape functions and meshes are those of
//! [`super::mesh`], so a hexahedron is written to ParaView with its own node order.

use super::mesh::{ElementFamily, ElementMesh};
use crate::solver::error::InputError;
use nalgebra::SVector;
use serde::{Deserialize, Serialize};

type V3 = SVector<f64, 3>;

/// Local coordinates of the nodes in local order (Hex8 uses the first eight).
const LOCAL_NODES: [[f64; 3]; 20] = [
    [-1.0, -1.0, -1.0],
    [1.0, -1.0, -1.0],
    [1.0, 1.0, -1.0],
    [-1.0, 1.0, -1.0],
    [-1.0, -1.0, 1.0],
    [1.0, -1.0, 1.0],
    [1.0, 1.0, 1.0],
    [-1.0, 1.0, 1.0],
    [0.0, -1.0, -1.0],
    [1.0, 0.0, -1.0],
    [0.0, 1.0, -1.0],
    [-1.0, 0.0, -1.0],
    [0.0, -1.0, 1.0],
    [1.0, 0.0, 1.0],
    [0.0, 1.0, 1.0],
    [-1.0, 0.0, 1.0],
    [-1.0, -1.0, 0.0],
    [1.0, -1.0, 0.0],
    [1.0, 1.0, 0.0],
    [-1.0, 1.0, 0.0],
];

/// Hexahedral element families.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum HexElement {
    /// 8-node trilinear hexahedron (2 × 2 × 2 Gauss points by default).
    Hex8,
    /// 20-node serendipity hexahedron (3 × 3 × 3 Gauss points by default).
    Hex20,
}

impl ElementFamily<3> for HexElement {
    fn local_nodes(self) -> &'static [[f64; 3]] {
        match self {
            HexElement::Hex8 => &LOCAL_NODES[..8],
            HexElement::Hex20 => &LOCAL_NODES,
        }
    }
    fn quadratic(self) -> bool {
        self == HexElement::Hex20
    }
}

/// A mesh of hexahedra of one family.
pub type HexMesh = ElementMesh<3, HexElement>;

impl ElementMesh<3, HexElement> {
    /// A structured mesh of `cells` equal boxes covering `[origin, origin + size]`
    /// ([`ElementMesh::structured`]): nodes x fastest, then y, then z.
    pub fn cuboid(origin: V3, size: V3, cells: [usize; 3], element: HexElement) -> Result<Self, InputError> {
        Self::structured(origin, size, cells, element)
    }
}
