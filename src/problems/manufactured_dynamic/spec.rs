//! The parameters of one dynamic manufactured analysis, its time scales and checks.

use crate::basis::method::Method;
use crate::basis::DomainUpdate;
use crate::material::constitutive::{Material, LINEAR_ELASTIC};
use crate::problems::manufactured::{Field, ManufacturedSpec};
use crate::problems::manufactured3d::METHODS_3D;
use crate::solver::dynamics::{LoadHistory, MassMatrix, Newmark};
use crate::solver::error::{require_count, require_positive, InputError};
use crate::solver::newton::NewtonSettings;
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// The methods that solve the dynamic manufactured problem.
pub const METHODS: [Method; Method::FAMILIES + 2] = crate::problems::manufactured::METHODS;

/// One dynamic manufactured analysis.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DynamicManufacturedSpec {
    pub field: Field,
    /// A of the axis-aligned field or θ₀ (radians) of the vortex: the peak amplitude.
    pub amplitude: f64,
    /// Hencky elasticity (`linear-elastic`), as the static fields'.
    pub material: Material,
    /// ρ₀, mass per unit reference volume.
    pub density: f64,
    /// Cells along each side of the unit square: h = 1 / cells.
    pub cells: usize,
    /// Material points per cell along each axis; Gauss points per axis of the elements are
    /// the element's (2 for Q4, 3 for Q8).
    pub points_per_cell: usize,
    /// Time steps per period T = 2/c of the forcing.
    pub steps_per_period: usize,
    /// Simulated time in periods.
    pub periods: f64,
    pub beta: f64,
    pub gamma: f64,
    pub mass: MassMatrix,
    pub newton: NewtonSettings,
    /// Generalised-α's spectral radius ρ∞ instead of `beta`, `gamma`
    /// ([`crate::solver::dynamics::GeneralizedAlpha`]); not serialised when absent (Newmark cases keep
    /// their keys).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rho_infinity: Option<f64>,
    pub domain_update: DomainUpdate,
    /// 2 (the unit square, plane strain) or 3 (the unit cube). Not serialised at 2.
    #[serde(default = "plane", skip_serializing_if = "is_plane")]
    pub dimension: usize,
}

fn plane() -> usize {
    2
}

fn is_plane(d: &usize) -> bool {
    *d == 2
}

impl Default for DynamicManufacturedSpec {
    /// The axis-aligned field at A = 0.05 (F_xx from 0.84 to 1.16), E = ρ₀ = 1 (c = 1, T = 2),
    /// ν = 0.3, 8 × 8 cells of 2 × 2 points, 32 steps per period over 5/8 of a period (the end
    /// at ωt = 5π/4, where both a(t) and ȧ(t) are non-zero, so that a phase error shows in the
    /// displacement at first order), trapezoidal rule, consistent mass.
    fn default() -> Self {
        DynamicManufacturedSpec {
            field: Field::AxisAligned,
            amplitude: 0.05,
            material: Material::linear_elastic(1.0, 0.3),
            density: 1.0,
            cells: 8,
            points_per_cell: 2,
            steps_per_period: 32,
            periods: 0.625,
            beta: 0.25,
            gamma: 0.5,
            mass: MassMatrix::Consistent,
            newton: NewtonSettings::default(),
            rho_infinity: None,
            domain_update: DomainUpdate::Stretch,
            dimension: 2,
        }
    }
}

impl DynamicManufacturedSpec {
    pub fn validate(&self) -> Result<(), InputError> {
        let hencky = crate::problems::manufactured::HENCKY_ONLY;
        self.material.require_model(&LINEAR_ELASTIC, hencky)?;
        self.material.build()?;
        require_positive("density", self.density)?;
        require_count("cells", self.cells, 1)?;
        // 1024² cells are 4e6 points at 2 × 2 per cell; 128³ are 1.7e7 at 2 × 2 × 2.
        let max_cells = if self.dimension == 3 { 128 } else { 1024 };
        if self.cells > max_cells {
            return Err(InputError::new(
                "cells",
                self.cells,
                format!("must be <= {max_cells} in {}D", self.dimension),
            ));
        }
        // Points per cell, the amplitude's range, the dimension and the material: the static
        // field's checks (below).
        require_count("steps_per_period", self.steps_per_period, 1)?;
        require_positive("periods", self.periods)?;
        // The step count first: the static spec's checks read it as `load_steps`.
        crate::solver::load_stepping::require_time_steps("periods", self.periods, self.steps_per_period)?;
        self.static_spec().validate()?;
        crate::solver::load_stepping::require_time_scales(
            ("periods", self.periods),
            self.steps_per_period,
            self.period(),
            ("density", self.density, "(T = 2/c, c = √(E/ρ0))"),
        )?;
        self.newmark().validate()
    }

    /// Wave speed c = √(E/ρ₀) (NaN for a material without E, which validation refuses).
    pub fn wave_speed(&self) -> f64 {
        let e = self.material.get("young_modulus").unwrap_or(f64::NAN);
        (e / self.density).sqrt()
    }

    /// ω = πc (Wallstedt & Guilkey's sin(cπt)).
    pub fn omega(&self) -> f64 {
        PI * self.wave_speed()
    }

    /// T = 2π/ω.
    pub fn period(&self) -> f64 {
        2.0 * PI / self.omega()
    }

    /// The end time, `periods` × T.
    pub fn duration(&self) -> f64 {
        self.periods * self.period()
    }

    pub fn time_steps(&self) -> usize {
        (self.periods * self.steps_per_period as f64).round().max(1.0) as usize
    }

    pub fn element_size(&self) -> f64 {
        1.0 / self.cells as f64
    }

    /// The static spec of the same field at the peak amplitude (for validation and the
    /// static field's functions).
    pub(super) fn static_spec(&self) -> ManufacturedSpec {
        ManufacturedSpec {
            field: self.field,
            amplitude: self.amplitude,
            material: self.material,
            cells: self.cells,
            points_per_cell: self.points_per_cell,
            load_steps: self.time_steps(),
            newton: self.newton,
            domain_update: self.domain_update,
            dimension: self.dimension,
        }
    }

    /// The methods of this spec's dimension.
    pub fn methods(&self) -> &'static [Method] {
        if self.dimension == 3 {
            &METHODS_3D
        } else {
            &METHODS
        }
    }

    pub fn newmark(&self) -> Newmark {
        Newmark {
            duration: self.duration(),
            beta: self.beta,
            gamma: self.gamma,
            mass: self.mass,
            load: LoadHistory::None,
            rho_infinity: self.rho_infinity,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bad_inputs_name_their_key() {
        let bad = |f: &dyn Fn(&mut DynamicManufacturedSpec), key: &str| {
            let mut s = DynamicManufacturedSpec::default();
            f(&mut s);
            let e = s.validate().unwrap_err().to_string();
            assert!(e.contains(key), "{e}");
        };
        bad(&|s| s.density = 0.0, "density");
        bad(&|s| s.density = -1.0, "density");
        bad(&|s| s.periods = 0.0, "periods");
        bad(&|s| s.steps_per_period = 0, "steps_per_period");
        bad(&|s| s.beta = 0.7, "dynamics.beta");
        bad(&|s| s.gamma = 0.3, "dynamics.gamma");
        bad(&|s| s.amplitude = 0.5, "amplitude");
    }
}
