//! The names of the solution methods every problem and study uses: one enum, no solver code.
//! Problems dispatch on it ([`crate::problems`]); study files, `results.json` and the reports
//! name methods by [`Method::name`] (kebab-case, as serialised).

use crate::error::InputError;
use serde::{Deserialize, Serialize};

/// A discretisation method.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Method {
    /// Standard implicit MPM.
    Mpm,
    /// Implicit GIMP (the paper's method).
    Igimp,
    /// Updated-Lagrangian FEM, two-noded line elements (2 Gauss points by default).
    FemLinear,
    /// Updated-Lagrangian FEM, three-noded line elements (3 Gauss points by default).
    FemQuadratic,
    /// Updated-Lagrangian FEM, 4-node quadrilaterals, 2×2 Gauss points (Figure 17 reference).
    FemQ4,
    /// Updated-Lagrangian FEM, 8-node quadrilaterals, 3×3 Gauss points (Figure 21).
    FemQ8,
    /// Updated-Lagrangian FEM, 8-node hexahedra, 2×2×2 Gauss points (3D).
    FemHex8,
    /// Updated-Lagrangian FEM, 20-node serendipity hexahedra, 3×3×3 Gauss points (3D).
    FemHex20,
}

impl Method {
    /// Every method, in declaration order.
    pub const ALL: [Method; 8] = [
        Method::Mpm,
        Method::Igimp,
        Method::FemLinear,
        Method::FemQuadratic,
        Method::FemQ4,
        Method::FemQ8,
        Method::FemHex8,
        Method::FemHex20,
    ];

    /// The name in study files and `results.json`.
    pub fn name(self) -> &'static str {
        match self {
            Method::Mpm => "mpm",
            Method::Igimp => "igimp",
            Method::FemLinear => "fem-linear",
            Method::FemQuadratic => "fem-quadratic",
            Method::FemQ4 => "fem-q4",
            Method::FemQ8 => "fem-q8",
            Method::FemHex8 => "fem-hex8",
            Method::FemHex20 => "fem-hex20",
        }
    }

    /// The human name, as in the paper.
    pub fn label(self) -> &'static str {
        match self {
            Method::Mpm => "MPM",
            Method::Igimp => "iGIMP",
            Method::FemLinear => "linear FEM",
            Method::FemQuadratic => "quadratic FEM",
            Method::FemQ4 => "Q4 FEM",
            Method::FemQ8 => "Q8 FEM",
            Method::FemHex8 => "Hex8 FEM",
            Method::FemHex20 => "Hex20 FEM",
        }
    }

    pub fn is_fem(self) -> bool {
        !self.uses_material_points()
    }

    /// True for the methods whose points per cell matter (MPM, iGIMP).
    pub fn uses_material_points(self) -> bool {
        matches!(self, Method::Mpm | Method::Igimp)
    }

    /// `Ok` if `self` is one of `supported` (a problem's methods), else [`Self::unsupported`].
    pub fn expect_one_of(self, problem: &str, supported: &[Method]) -> Result<(), InputError> {
        if supported.contains(&self) {
            Ok(())
        } else {
            Err(self.unsupported(problem, supported))
        }
    }

    /// The error of a method `problem` has no solution for: it names the field `method` and
    /// the methods the problem has.
    pub fn unsupported(self, problem: &str, supported: &[Method]) -> InputError {
        let names: Vec<&str> = supported.iter().map(|m| m.name()).collect();
        InputError::new(
            "method",
            self.name(),
            format!("the {problem} is solved by {}", names.join(", ")),
        )
    }
}
