//! Scenes: any box bodies, supports, loads (gravity, prescribed displacements, each with its
//! ramp) and measures, described as data ([`Scene`]) and solved by any material point family
//! or by the FEM elements of the dimension ([`solve`]). The study kind `problem = "scene"`
//! reads them from a study file.

mod closed_form;
mod solve;
mod spec;
mod validate;

pub use closed_form::Platen;
pub use solve::{check_resolution, methods, solve, MeasureValue, PointRecord, SceneOutcome, SceneSettings};
pub use spec::{
    axis_index, region, Body, Bounds, ClosedForm, Components, GridSection, Load, LoadKind, Measure,
    MeasureKind, Plane, Reference, Region, Scene, Support, AXES,
};
