//! One size cap for every case, material point or finite element: an estimate of a case's
//! memory peak from its nodes, unknowns, matrix non-zeros and material (or Gauss) points,
//! checked before anything per node or point is allocated. A case over the cap is an input
//! error naming its estimate, so that a study records it as rejected and solves the others,
//! instead of the process aborting on an allocation of tens of gigabytes.

use crate::solver::error::InputError;

/// The cap on a case's estimated memory peak: 16 GiB, two thirds of the 24 GiB machines the
/// project runs on (reference/README.md item 58), so that one case over it is refused before
/// it starts, not killed half way.
pub const MAX_CASE_BYTES: f64 = 16.0 * 1024.0 * 1024.0 * 1024.0;

/// Bytes per material or Gauss point (its state, trial state and support table) and per
/// non-zero of the tangent (values, indices, the multigrid's levels and the solver's
/// vectors spread over them): fitted to two measured resident peaks with the multigrid CG
/// solver, the 3D compaction's 1e6 points (2.1 GiB) and the 1,002,528-element Q4 reference
/// (5.5 GB), reference/README.md item 58. A direct factorisation adds its fill on top.
const BYTES_PER_POINT: f64 = 1000.0;
const BYTES_PER_NONZERO: f64 = 40.0;

/// The size of one case, counted in floating point so that no product overflows.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CaseSize {
    /// Spatial dimension (unknowns per node).
    pub dimension: usize,
    /// Nodes of the grid or mesh.
    pub nodes: f64,
    /// Material points, or the Gauss points of a finite element mesh.
    pub points: f64,
    /// Nodes each node is coupled to in the tangent (its stencil, itself included).
    pub coupled_nodes: f64,
}

impl CaseSize {
    /// Unknowns: `dimension` per node.
    pub fn unknowns(&self) -> f64 {
        self.nodes * self.dimension as f64
    }

    /// Non-zeros of the tangent: each unknown couples to every component of its stencil.
    pub fn nonzeros(&self) -> f64 {
        self.unknowns() * self.coupled_nodes * self.dimension as f64
    }

    /// Estimated memory peak in bytes.
    pub fn bytes(&self) -> f64 {
        BYTES_PER_POINT * self.points + BYTES_PER_NONZERO * self.nonzeros()
    }

    /// An error naming `field` (with its `value`) and the estimate if the case is over
    /// [`MAX_CASE_BYTES`].
    pub fn check(&self, field: &str, value: impl ToString) -> Result<(), InputError> {
        let bytes = self.bytes();
        if bytes.is_finite() && bytes <= MAX_CASE_BYTES {
            return Ok(());
        }
        Err(InputError::new(
            field,
            value,
            format!(
                "gives a case of {} nodes, {} unknowns and {} points, an estimated memory peak of {} GB; \
                 the cap is {} GB (igimp::mesh::budget::MAX_CASE_BYTES)",
                count(self.nodes),
                count(self.unknowns()),
                count(self.points),
                gigabytes(bytes),
                gigabytes(MAX_CASE_BYTES)
            ),
        ))
    }
}

/// A count as an integer up to 1e15, in scientific notation beyond.
fn count(n: f64) -> String {
    if n < 1e15 {
        format!("{n:.0}")
    } else {
        format!("{n:.2e}")
    }
}

fn gigabytes(bytes: f64) -> String {
    let gb = bytes / 1e9;
    if gb < 1e6 {
        format!("{gb:.1}")
    } else {
        format!("{gb:.2e}")
    }
}

/// Nodes coupled to a node of a grid or mesh whose supports reach `reach` cells either side
/// (1: linear elements and hats; 2: quadratic elements, GIMP domains and B-splines).
pub fn stencil(dimension: usize, reach: usize) -> f64 {
    ((2 * reach + 1) as f64).powi(dimension as i32)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The calibration cases are under the cap, within a factor 2 of their measured peaks;
    /// a case 100 times the Q4 reference is over it.
    #[test]
    fn calibration_cases_fit_and_a_hundredfold_case_does_not() {
        let mpm_3d = CaseSize {
            dimension: 3,
            nodes: 51.0f64.powi(3),
            points: 1e6,
            coupled_nodes: stencil(3, 1),
        };
        let q4 = CaseSize {
            dimension: 2,
            nodes: 1_003_590.0,
            points: 4.0 * 1_002_528.0,
            coupled_nodes: stencil(2, 1),
        };
        for (c, measured) in [(mpm_3d, 2.1 * 1024f64.powi(3)), (q4, 5.5e9)] {
            let ratio = c.bytes() / measured;
            assert!(
                (0.5..2.0).contains(&ratio),
                "{c:?}: estimate / measured = {ratio}"
            );
            assert!(c.check("x", 1).is_ok());
        }
        let big = CaseSize {
            nodes: 100.0 * q4.nodes,
            points: 100.0 * q4.points,
            ..q4
        };
        let e = big.check("element_size", 1e-4).unwrap_err();
        assert!(e.allowed.contains("estimated memory peak"), "{e}");
        assert!(CaseSize {
            nodes: f64::INFINITY,
            ..q4
        }
        .check("x", 1)
        .is_err());
    }
}
