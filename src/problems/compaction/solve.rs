//! The compaction by any method: the dispatch on the method and the dimension.

use super::fem::{solve_fem, solve_fem_3d};
use super::material_points::{solve_mpm, solve_mpm_3d, Domain3dRecord, DomainRecord};
use super::spec::{methods, CompactionSpec};
use crate::basis::method::Method;
use crate::fem::{HexElement, QuadElement};
use crate::solver::error::{InputError, SolveError};
use crate::solver::load_stepping::StepReport;

/// One compaction analysis, whatever the method.
#[derive(Debug, Clone, PartialEq)]
pub struct CompactionSolution {
    pub steps: Vec<StepReport>,
    pub failure: Option<SolveError>,
    /// The measure of Figure 17 ([`CompactionOutcome`](super::CompactionOutcome), [`FemOutcome`](super::FemOutcome)).
    pub max_horizontal_displacement: f64,
    /// Weak-node constraints applied over all steps (0 for FEM).
    pub weak_nodes_treated: usize,
    /// Material points (MPM, iGIMP) or elements (FEM).
    pub size: usize,
    /// Final material point domains (none for FEM); in 3D the slice next to the symmetry
    /// plane y = 0 ([`solve_mpm_3d`]).
    pub domains: Vec<DomainRecord>,
    /// Every point's final 3D domain (3D material points only).
    pub domains_3d: Vec<Domain3dRecord>,
}

/// Solve the compaction by `method`: a material point family (the method sets
/// `spec.basis`), or Q4/Q8 FEM ([`solve_fem`]).
pub fn solve(spec: &CompactionSpec, method: Method) -> Result<CompactionSolution, InputError> {
    if spec.dimension == 3 {
        return solve_3d(spec, method);
    }
    let basis = match method {
        Method::MaterialPoint(basis) => basis,
        Method::FEM_Q4 | Method::FEM_Q8 => {
            let element = if method == Method::FEM_Q4 {
                QuadElement::Q4
            } else {
                QuadElement::Q8
            };
            let o = solve_fem(spec, element)?;
            return Ok(CompactionSolution {
                steps: o.steps,
                failure: o.failure,
                max_horizontal_displacement: o.max_horizontal_displacement,
                weak_nodes_treated: 0,
                size: o.elements,
                domains: vec![],
                domains_3d: vec![],
            });
        }
        _ => return Err(unsupported(spec, method)),
    };
    let o = solve_mpm(&CompactionSpec { basis, ..*spec })?;
    Ok(CompactionSolution {
        size: o.num_points,
        steps: o.steps,
        failure: o.failure,
        max_horizontal_displacement: o.max_horizontal_displacement,
        weak_nodes_treated: o.weak_nodes_treated,
        domains: o.points,
        domains_3d: o.points_3d,
    })
}

/// A method the compaction in `spec.dimension` does not have: an error naming `method` (and
/// the dimension) with the allowed methods.
fn unsupported(spec: &CompactionSpec, method: Method) -> InputError {
    let problem = if spec.dimension == 3 {
        "3D compaction (dimension = 3)"
    } else {
        "plane-strain compaction (dimension = 2)"
    };
    method.unsupported(problem, methods(spec.dimension))
}

/// The 3D compaction by `method` ([`solve_mpm_3d`], [`solve_fem_3d`]).
fn solve_3d(spec: &CompactionSpec, method: Method) -> Result<CompactionSolution, InputError> {
    let element = match method {
        Method::MaterialPoint(basis) => {
            let o = solve_mpm_3d(&CompactionSpec { basis, ..*spec })?;
            return Ok(CompactionSolution {
                size: o.num_points,
                steps: o.steps,
                failure: o.failure,
                max_horizontal_displacement: o.max_horizontal_displacement,
                weak_nodes_treated: o.weak_nodes_treated,
                domains: o.points,
                domains_3d: o.points_3d,
            });
        }
        Method::FEM_HEX8 => HexElement::Hex8,
        Method::FEM_HEX20 => HexElement::Hex20,
        _ => return Err(unsupported(spec, method)),
    };
    let o = solve_fem_3d(spec, element)?;
    Ok(CompactionSolution {
        steps: o.steps,
        failure: o.failure,
        max_horizontal_displacement: o.max_horizontal_displacement,
        weak_nodes_treated: 0,
        size: o.elements,
        domains: vec![],
        domains_3d: vec![],
    })
}
