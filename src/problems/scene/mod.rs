//! Scenes: any box bodies, supports, loads (gravity, prescribed displacements, each with its
//! ramp) and measures, described as data ([`Scene`]) and solved by any material point family
//! or by the FEM elements of the dimension ([`solve`]). The study kind `problem = "scene"`
//! reads them from a study file.

mod build;
mod closed_form;
mod discrete;
mod fields;
pub mod geometry;
pub mod initial_stress;
mod measures;
mod solve;
mod spec;
mod strength;
mod validate;

pub use build::check_resolution;
pub use closed_form::Platen;
pub use discrete::{
    region_reactions, DiscreteGrid, DiscretePoints, DiscreteRegion, DiscreteScene, GravityLoad, PointLoad,
    Reactions,
};
pub use fields::{measures_of_fields, PointFields};
pub use solve::{methods, solve, MeasureValue, PointRecord, SceneOutcome};
pub use spec::{
    axis_index, region, Bind, Body, Bounds, ClosedForm, Components, GridSection, Load, LoadKind, Measure,
    MeasureKind, Plane, Reference, Region, Scene, SceneSettings, Shape, StrengthReductionSection, Support,
    AXES,
};
