//! Strength reduction (Zienkiewicz, Humpheson & Lewis 1975; Griffiths & Lane 1999): the
//! soil's strength divided by a factor F that grows over the load steps until the body can no
//! longer stand. The factor at which it collapses is its factor of safety, the one limit
//! equilibrium defines: c_f = c / F, tan φ_f = tan φ / F (reference/README.md item 79).
//!
//! The dilatancy angle is reduced as φ is, tan ψ_f = tan ψ / F, so that associated flow stays
//! associated and ψ ≤ φ holds at every F; a von Mises yield stress (a Tresca soil's 2c/√3·√3)
//! is divided by F. Elasticity and the hardening modulus are left as they are: they set how
//! the body deforms, not the load it can carry.

use crate::material::constitutive::{ConstitutiveModel, Material};
use crate::solver::error::InputError;
use crate::solver::ramp::Ramp;

/// The strength parameters a factor of safety divides: a stress divided by F, an angle whose
/// tangent is.
const STRESSES: [&str; 2] = ["cohesion", "yield_stress"];
const ANGLES: [&str; 2] = ["friction_angle", "dilatancy_angle"];

/// `material` with its strength divided by `factor` (> 0): its stresses (cohesion, yield
/// stress) by F, its angles' tangents (friction, dilatancy) by F.
pub fn reduced(material: &Material, factor: f64) -> Material {
    #[cfg(feature = "seeded-bugs")]
    let factor_of_angles = if crate::seeded::active(crate::seeded::Bug::StrengthReductionCohesionOnly) {
        1.0
    } else {
        factor
    };
    #[cfg(not(feature = "seeded-bugs"))]
    let factor_of_angles = factor;
    let reduce = |key: &str, v: f64| {
        if STRESSES.contains(&key) {
            v / factor
        } else if ANGLES.contains(&key) {
            (v.to_radians().tan() / factor_of_angles).atan().to_degrees()
        } else {
            v
        }
    };
    let values: Vec<(&str, f64)> = material.parameters().map(|(k, v)| (k, reduce(k, v))).collect();
    Material::of(material.entry(), &values).expect("the same model's parameters")
}

/// Does `material` have a strength to reduce (a cohesion, a friction angle or a yield stress)?
pub fn has_strength(material: &Material) -> bool {
    material
        .parameters()
        .any(|(k, _)| STRESSES.contains(&k) || k == "friction_angle")
}

/// A material whose strength is divided by a factor that follows a ramp over the load steps.
#[derive(Debug, Clone, PartialEq)]
pub struct StrengthReduction {
    material: Material,
    ramp: Ramp,
}

impl StrengthReduction {
    /// `material` reduced by the factor `ramp` gives at each load factor: a table whose
    /// factors are finite and positive (`field` names it in the error), for a material with
    /// a strength to reduce.
    pub fn new(field: &str, material: Material, ramp: Ramp) -> Result<Self, InputError> {
        let Ramp::Table(rows) = &ramp else {
            return Err(InputError::new(
                field,
                "\"linear\"",
                "must be a table of [load fraction, factor] rows: a linear ramp starts at factor 0, an infinite strength",
            ));
        };
        // Finite factors: the table's own check.
        ramp.validate(field)?;
        if let Some((i, r)) = rows.iter().enumerate().find(|(_, r)| r[1] <= 0.0) {
            return Err(InputError::new(
                format!("{field}[{i}][1]"),
                r[1],
                "must be a factor greater than 0",
            ));
        }
        if !has_strength(&material) {
            return Err(InputError::new(
                field,
                material.model(),
                "applies to a model with a strength to reduce (a cohesion, a friction angle or a yield stress)",
            ));
        }
        // Every row's reduced material is checked here, so that the solver's rebuild cannot
        // fail: between rows F lies between two checked factors, and each reduced parameter
        // is monotone in F.
        for (i, r) in rows.iter().enumerate() {
            reduced(&material, r[1]).build().map_err(|e| {
                InputError::new(
                    format!("{field}[{i}][1]"),
                    r[1],
                    format!("reduces the material to one it refuses: {e}"),
                )
            })?;
        }
        Ok(Self { material, ramp })
    }

    /// The factor F at load factor `load_factor`.
    pub fn factor(&self, load_factor: f64) -> f64 {
        self.ramp.factor(load_factor)
    }

    /// The model with its strength divided by the factor at `load_factor`.
    pub fn model_at(&self, load_factor: f64) -> Box<dyn ConstitutiveModel> {
        reduced(&self.material, self.factor(load_factor))
            .build()
            .expect("checked at every row by StrengthReduction::new")
    }
}
