//! The paper's examples as problem definitions with their analytical references.

pub mod cantilever;
pub mod column;
pub mod compaction;
pub mod elastica;
