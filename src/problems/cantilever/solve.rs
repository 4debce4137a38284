//! The cantilever by any method: the dispatch on the method and the dimension.

use super::fem::{solve_fem_3d, solve_fem_q8, FemOutcome};
use super::material_points::{solve_mpm_with, DomainSnapshot, SolidSnapshot};
use super::spec::{methods, CantileverSpec, EndDisplacement};
use crate::basis::method::Method;
use crate::fem::HexElement;
use crate::solver::error::{InputError, SolveError};
use crate::solver::load_stepping::StepReport;

/// One cantilever analysis, whatever the method.
#[derive(Debug, Clone, PartialEq)]
pub struct CantileverSolution {
    pub steps: Vec<StepReport>,
    pub end: Vec<EndDisplacement>,
    pub failure: Option<SolveError>,
    /// iGIMP only: snapshots, the smallest half-length after each step, the loaded points
    /// (indices into the snapshots' domains).
    pub snapshots: Vec<DomainSnapshot>,
    pub min_half_length: Vec<f64>,
    pub loaded_points: Option<Vec<usize>>,
    /// 3D iGIMP only: every point's domain at the snapshot steps ([`SolidSnapshot`]).
    pub solid_snapshots: Vec<SolidSnapshot>,
}

/// Solve the cantilever by `method`: iGIMP ([`solve_mpm`](super::solve_mpm), snapshots every
/// `snapshot_every` steps), Q8 FEM in 2D ([`solve_fem_q8`]), Hex8 or Hex20 FEM in 3D
/// ([`solve_fem_3d`]).
pub fn solve(
    spec: &CantileverSpec,
    method: Method,
    snapshot_every: usize,
) -> Result<CantileverSolution, InputError> {
    let fem = |o: FemOutcome| CantileverSolution {
        steps: o.steps,
        end: o.end,
        failure: o.failure,
        snapshots: vec![],
        min_half_length: vec![],
        loaded_points: None,
        solid_snapshots: vec![],
    };
    match (method, spec.dimension) {
        (Method::MaterialPoint(basis), _) => {
            solve_mpm_with(spec, basis, snapshot_every).map(|o| CantileverSolution {
                steps: o.steps,
                end: o.end,
                failure: o.failure,
                snapshots: o.snapshots,
                min_half_length: o.min_half_length,
                loaded_points: Some(o.loaded_points),
                solid_snapshots: o.solid_snapshots,
            })
        }
        (Method::FEM_Q8, 2) => solve_fem_q8(spec).map(fem),
        (Method::FEM_HEX8, 3) => solve_fem_3d(spec, HexElement::Hex8).map(fem),
        (Method::FEM_HEX20, 3) => solve_fem_3d(spec, HexElement::Hex20).map(fem),
        _ => Err(method.unsupported(
            if spec.dimension == 3 {
                "3D cantilever (dimension = 3)"
            } else {
                "plane-strain cantilever (dimension = 2)"
            },
            methods(spec.dimension),
        )),
    }
}
