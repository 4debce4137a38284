//! The paper's examples as problem definitions with their analytical references, and the
//! manufactured solutions that verify the 2D discretisations where the paper has none.

pub mod bar;
pub mod cantilever;
pub mod cantilever_dynamic;
pub mod column;
pub mod compaction;
pub mod elastica;
pub mod element_test;
pub mod manufactured;
pub mod manufactured3d;
pub mod manufactured_dynamic;
pub mod norms;
pub mod scene;
