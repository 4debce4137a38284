//! What a scene measures: the kinds of measure, their references (values, closed forms,
//! FEM sweeps) and the stress components a stress line reads.

use super::geometry::AXES;
use serde::{Deserialize, Serialize};

/// What a measure reads from a case.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum MeasureKind {
    /// A displacement component of the material point whose initial position is nearest to
    /// `at` (FEM: of the mesh node nearest to it); with `domain_edge`, of the point's domain
    /// edge facing `at` (its displacement plus its half-length's growth).
    Displacement,
    /// The sum of one reaction component over a support's or a displacement load's nodes: the
    /// force they exert on the body.
    Reaction,
    /// Σ V₀ W over the points: W = μ εᵉ:εᵉ + λ/2 (tr εᵉ)² (Hencky, and von Mises' elastic
    /// part), W = μ/2 (tr b − 3) − μ ln J + λ/2 (ln J)² (neo-Hookean, b = exp 2εᵉ); needs the
    /// material's `young_modulus` and `poisson_ratio`.
    StrainEnergy,
    /// The column's stress error, eq (46), of a one-box scene under one gravity load along an
    /// axis: Σ_p |σ_p − σ(Z_p)| V₀_p / (ρ g V L) against σ(Z) = −ρ g (L − Z), Z the height above
    /// the base (reference/README.md item 66).
    ColumnStressError,
    /// A Cauchy stress component (`component` = `xx`, `yy`, `xy`, …) along the segment from
    /// `at` to `to` in the current configuration, at `samples` points, each the stress of the
    /// nearest integration point: written per case as a profile; its value is their mean.
    StressLine,
    /// The factor of safety: the strength reduction's factor F where the body fails (needs
    /// `[strength_reduction]`). It fails where no load step converges any more (F at the
    /// last converged state) or, with `at`, `component` and `limit`, where that displacement
    /// has moved `limit` since the reduction began (F interpolated between the steps),
    /// whichever comes first; absent if the body stood at every F.
    FactorOfSafety,
}

/// A stress component `xx`, `yy`, `xy`, … (plane strain also `zz`) as (row, column).
pub fn stress_component(c: &str, dimension: usize) -> Option<(usize, usize)> {
    let mut it = c.chars().map(|ch| AXES.iter().position(|a| a.starts_with(ch)));
    let (i, j) = (it.next()??, it.next()??);
    let in_plane = |a: usize| a < dimension || a == 2;
    (c.len() == 2 && in_plane(i) && in_plane(j)).then_some((i, j))
}

/// One named output of every case.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Measure {
    pub name: String,
    pub kind: MeasureKind,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub at: Option<Vec<f64>>,
    /// A stress line's end and its number of samples (2..=1000).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub to: Option<Vec<f64>>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub samples: Option<usize>,
    /// `x`, `y` or `z` (displacement and reaction); `xx`, `xy`, … (a stress line).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub component: Option<String>,
    /// A reaction's support or displacement load, by name.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub region: Option<String>,
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub domain_edge: bool,
    /// Also record the value after every load step.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub history: bool,
    /// A factor the value is multiplied by (e.g. −2/(B c) makes a strip footing's reaction
    /// its pressure over c); default 1.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub scale: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub reference: Option<Reference>,
    /// A factor of safety's displacement limit: the body has failed once the displacement
    /// `component` at `at` has moved this far since the strength reduction began.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub limit: Option<f64>,
}

/// A closed form a measure is compared with.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ClosedForm {
    /// The smooth-platen force (reference/README.md item 65): τ_yy A₀ / λ along the platen's
    /// axis, λ = 1 + δ / H.
    PlatenForce,
    /// The smooth-platen displacement (λ_i − 1)(at_i − min_i) of component i at `at`.
    PlatenDisplacement,
    /// The confined column's displacement along the gravity's axis at `at`, for a Hencky or
    /// neo-Hookean body (reference/README.md item 67).
    ColumnDisplacement,
}

/// The exact value a measure is compared with.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Reference {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub value: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub closed_form: Option<ClosedForm>,
    /// Or the scene itself solved by the one FEM method of this sweep (of the study), its three
    /// finest element sizes extrapolated (Richardson, with their grid convergence index).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fem_sweep: Option<String>,
    /// A closed form's body (its box and material) and displacement load (its platen).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub body: Option<String>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub load: Option<String>,
    /// Where the value or formula comes from.
    pub source: String,
}
