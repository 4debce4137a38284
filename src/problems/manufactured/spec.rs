//! The parameters of one manufactured-solution analysis and their checks.

use crate::basis::method::Method;
use crate::material::constitutive::{lame, ConstitutiveModel, Material, LINEAR_ELASTIC};
use crate::mpm::DomainUpdate;
use crate::solver::error::{require_count, InputError};
use crate::solver::newton::NewtonSettings;
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// Which manufactured motion.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Field {
    /// x = X + A (sin πX, sin πY).
    AxisAligned,
    /// x = c + R(θ(r)) (X − c), θ = θ₀ (1 − 4r²)³ inside r ≤ ½.
    Vortex,
}

impl Field {
    pub fn name(self) -> &'static str {
        match self {
            Field::AxisAligned => "axis-aligned",
            Field::Vortex => "vortex",
        }
    }
}

/// The methods that solve the manufactured problem.
pub const METHODS: [Method; Method::FAMILIES + 2] = Method::listed(Some(2), &[]);

/// One manufactured-solution analysis.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ManufacturedSpec {
    pub field: Field,
    /// A of the axis-aligned field or θ₀ (radians) of the vortex.
    pub amplitude: f64,
    /// Hencky elasticity (`linear-elastic`): the exact solution's stresses and body force are
    /// its.
    pub material: Material,
    /// Cells (elements) along each side of the unit square: h = 1 / cells.
    pub cells: usize,
    /// Material points per cell along each axis (MPM, iGIMP).
    pub points_per_cell: usize,
    pub load_steps: usize,
    pub newton: NewtonSettings,
    /// Domain update of iGIMP (MPM has no domains; ignored by FEM).
    pub domain_update: DomainUpdate,
    /// 2 (the unit square, plane strain) or 3 (the unit cube,
    /// [`crate::problems::manufactured3d::solve_3d`]). Not serialised at 2, so that the case hashes of
    /// the plane study stay as they were.
    #[serde(default = "plane", skip_serializing_if = "is_plane")]
    pub dimension: usize,
}

fn plane() -> usize {
    2
}

fn is_plane(d: &usize) -> bool {
    *d == 2
}

impl Default for ManufacturedSpec {
    fn default() -> Self {
        Self {
            field: Field::AxisAligned,
            amplitude: 0.1,
            material: Material::linear_elastic(1.0, 0.3),
            cells: 8,
            points_per_cell: 2,
            load_steps: 10,
            newton: NewtonSettings::default(),
            domain_update: DomainUpdate::Stretch,
            dimension: 2,
        }
    }
}

impl ManufacturedSpec {
    pub fn validate(&self) -> Result<(), InputError> {
        self.material.require_model(&LINEAR_ELASTIC, HENCKY_ONLY)?;
        require_count("cells", self.cells, 1)?;
        require_count("points_per_cell", self.points_per_cell, 1)?;
        if !matches!(self.dimension, 2 | 3) {
            return Err(InputError::new("dimension", self.dimension, "must be 2 or 3"));
        }
        // 3D: 256³ cells are 1.7e7 cells, beyond what the direct solver holds.
        let max_cells = if self.dimension == 3 { 256 } else { 4096 };
        if self.cells > max_cells {
            return Err(InputError::new(
                "cells",
                self.cells,
                format!("must be <= {max_cells} in {}D", self.dimension),
            ));
        }
        if self.points_per_cell > 8 {
            return Err(InputError::new(
                "points_per_cell",
                self.points_per_cell,
                "must be <= 8",
            ));
        }
        let max_amplitude = match self.field {
            // F_xx = 1 + Aπ cos πX must stay positive.
            Field::AxisAligned => 1.0 / PI,
            Field::Vortex => PI,
        };
        let key = match self.field {
            Field::AxisAligned => "amplitude.axis_aligned",
            Field::Vortex => "amplitude.vortex",
        };
        if self.amplitude == 0.0 {
            // The undeformed body: every error is zero and no rate can be fitted.
            return Err(InputError::new(
                key,
                self.amplitude,
                "must not be 0 (the field would leave the body undeformed: every error 0, no rate)",
            ));
        }
        if !(self.amplitude.is_finite() && self.amplitude.abs() < max_amplitude) {
            return Err(InputError::new(
                key,
                self.amplitude,
                format!(
                    "must be finite with |amplitude| < {max_amplitude:.4} for {}",
                    self.field.name()
                ),
            ));
        }
        crate::fem::validate_stepping(&self.newton, self.load_steps)?;
        self.newton.validate()?;
        self.model()?;
        Ok(())
    }

    /// The constitutive model, built from [`Self::material`].
    pub fn model(&self) -> Result<Box<dyn ConstitutiveModel>, InputError> {
        self.material.build()
    }

    /// Lamé's (λ, μ) of the material, which the exact solution takes (NaN for a material
    /// validation refuses).
    pub fn lame(&self) -> (f64, f64) {
        let get = |k| self.material.get(k).unwrap_or(f64::NAN);
        lame(get("young_modulus"), get("poisson_ratio"))
    }

    pub fn element_size(&self) -> f64 {
        1.0 / self.cells as f64
    }
}

/// What the manufactured fields need of their material ([`Material::require_model`]).
pub const HENCKY_ONLY: &str = "the manufactured solutions' stresses and body force are Hencky elasticity's";
