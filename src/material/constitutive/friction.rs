//! What the two friction models, Drucker–Prager and Mohr–Coulomb, share: their four plastic
//! parameters (c₀, φ, ψ, H) with one check, and their hardening variable ε̄ᵖ. Each model's
//! file keeps its own surface, return and tangent.

use super::registry::{Parameter, POISSON_RATIO, YOUNG_MODULUS};
use super::{InternalVariable, Material};
use crate::solver::error::InputError;

/// The parameters of a friction model, in the order its `try_new` takes them.
pub const PARAMETERS: [Parameter; 6] = [
    YOUNG_MODULUS,
    POISSON_RATIO,
    Parameter {
        name: "cohesion",
        unit: "Pa",
        meaning: "Mohr–Coulomb cohesion c₀, ≥ 0",
    },
    Parameter {
        name: "friction_angle",
        unit: "°",
        meaning: "Mohr–Coulomb friction angle φ, in [0, 90)",
    },
    Parameter {
        name: "dilatancy_angle",
        unit: "°",
        meaning: "dilatancy angle ψ, in [0, φ] (ψ = φ: associated flow)",
    },
    Parameter {
        name: "hardening_modulus",
        unit: "Pa",
        meaning: "H of the cohesion c = c₀ + H ε̄ᵖ (< 0 softens)",
    },
];

/// A friction model's parameter values from a `[material]` table, in [`PARAMETERS`]' order.
pub fn values(m: &Material) -> [f64; 6] {
    PARAMETERS.map(|p| m.value(p.name))
}

/// c₀ ≥ 0, 0 ≤ ψ ≤ φ < 90°, H finite (E and ν are checked by the elastic law); an error
/// names `material.<key>`.
pub fn check(
    cohesion: f64,
    friction_angle: f64,
    dilatancy_angle: f64,
    hardening_modulus: f64,
) -> Result<(), InputError> {
    if !(cohesion.is_finite() && cohesion >= 0.0) {
        return Err(InputError::new(
            "material.cohesion",
            cohesion,
            "must be finite and ≥ 0",
        ));
    }
    if !(friction_angle.is_finite() && (0.0..90.0).contains(&friction_angle)) {
        return Err(InputError::new(
            "material.friction_angle",
            friction_angle,
            "must lie in [0, 90) degrees",
        ));
    }
    if !(dilatancy_angle.is_finite() && (0.0..=friction_angle).contains(&dilatancy_angle)) {
        return Err(InputError::new(
            "material.dilatancy_angle",
            dilatancy_angle,
            format!("must lie in [0, friction_angle = {friction_angle}] degrees"),
        ));
    }
    if !hardening_modulus.is_finite() {
        return Err(InputError::new(
            "material.hardening_modulus",
            hardening_modulus,
            "must be finite",
        ));
    }
    Ok(())
}

/// The friction models' internal variable: the accumulated plastic strain ε̄ᵖ that hardens
/// the cohesion (each model's file states its rate on each branch).
pub const EQUIVALENT_PLASTIC_STRAIN: InternalVariable = InternalVariable {
    name: "equivalent_plastic_strain",
    initial: 0.0,
    meaning: "accumulated plastic strain ε̄ᵖ of the cohesion's hardening, 0 where the point never yielded",
};
