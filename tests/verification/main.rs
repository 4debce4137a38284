//! Verification of the library, one module per topic: weight invariants, finite-difference
//! tangents, patch tests, constitutive checks, the FEM comparators, the paper's column and
//! compaction results, robustness and hostile input. One test binary (fenris's split), so that
//! the crate is linked once for all of them.

mod common;

/// The extension example, run by `families`.
#[path = "../../examples/custom_basis.rs"]
mod custom_basis;

/// The material extension example, checked by `examples`.
#[path = "../../examples/hardening_von_mises.rs"]
mod hardening_von_mises;

mod basis;
mod cam_clay;
mod cam_clay_paths;
mod column;
mod compaction;
mod drucker_prager;
mod dynamics;
mod elastica;
mod examples;
mod extreme_values;
mod families;
mod fbar;
mod fem;
mod fem2d;
mod fem3d;
mod footing_scene;
mod hostile;
mod layering;
mod manufactured;
mod mohr_coulomb;
mod multigrid;
mod patch;
mod plasticity;
mod point_penalty;
mod predictor;
mod prestress;
mod robustness;
mod scene;
mod scene_text;
mod strength_reduction;
mod tangent;
