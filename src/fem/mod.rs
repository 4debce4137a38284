//! Updated-Lagrangian finite element comparators (issue 4: in progress).

use crate::error::InputError;
use crate::problems::column::{ColumnOutcome, ColumnSpec};

/// 1D element families of the column comparators.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LineElement {
    /// Two-noded linear element.
    Linear,
    /// Three-noded quadratic element.
    Quadratic,
}

/// Run the column with updated-Lagrangian FEM.
pub fn solve_column(_spec: &ColumnSpec, element: LineElement) -> Result<ColumnOutcome, InputError> {
    Err(InputError::new(
        "method",
        format!("{element:?}"),
        "FEM comparators are not built yet",
    ))
}
