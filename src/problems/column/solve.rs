//! The column by any method: the dispatch on the method and the dimension.

use super::fem::{solve_fem_3d, solve_fem_observed};
use super::material_points::{solve_mpm_3d, solve_mpm_observed};
use super::spec::{ColumnObserver, ColumnOutcome, ColumnSpec, METHODS, METHODS_3D};
use crate::basis::method::Method;
use crate::fem::{HexElement, LineElement};
use crate::solver::error::InputError;

/// Run the column with any method.
pub fn solve_column(spec: &ColumnSpec, method: Method) -> Result<ColumnOutcome, InputError> {
    solve_column_observed(spec, method, &mut |_, _| {})
}

/// [`solve_column`], showing the solver to `observer` before the first and after every
/// converged load step.
pub fn solve_column_observed(
    spec: &ColumnSpec,
    method: Method,
    observer: &mut ColumnObserver<'_>,
) -> Result<ColumnOutcome, InputError> {
    match (method, spec.dimension) {
        (Method::MaterialPoint(basis), 3) => solve_mpm_3d(spec, basis, observer),
        (Method::FEM_HEX8, 3) => solve_fem_3d(spec, HexElement::Hex8, observer),
        (Method::FEM_HEX20, 3) => solve_fem_3d(spec, HexElement::Hex20, observer),
        (_, 3) => Err(InputError::new(
            "dimension",
            3,
            format!(
                "the 3D column is solved by {}, not {} (a 1D method)",
                METHODS_3D.map(|m| m.name()).join(", "),
                method.name()
            ),
        )),
        (Method::FEM_HEX8 | Method::FEM_HEX20, _) => Err(InputError::new(
            "dimension",
            spec.dimension,
            format!("{} solves the 3D column (dimension = 3) only", method.name()),
        )),
        _ => match_1d(spec, method, observer),
    }
}

fn match_1d(
    spec: &ColumnSpec,
    method: Method,
    observer: &mut ColumnObserver<'_>,
) -> Result<ColumnOutcome, InputError> {
    match method {
        Method::MaterialPoint(basis) => solve_mpm_observed(spec, basis, observer),
        Method::FEM_LINEAR => solve_fem_observed(spec, LineElement::Linear, observer),
        Method::FEM_QUADRATIC => solve_fem_observed(spec, LineElement::Quadratic, observer),
        _ => Err(method.unsupported("column", &METHODS)),
    }
}
