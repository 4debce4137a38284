//! The paper's examples as problem definitions with their analytical references.

pub mod column;
pub mod elastica;
