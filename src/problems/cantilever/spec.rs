//! The cantilever's parameters, their checks, its methods and the end displacement.

use crate::basis::method::Method;
use crate::discretise::ghost::{GhostFaces, GhostSettings};
use crate::material::constitutive::{ConstitutiveModel, Material};
use crate::mpm::{DomainUpdate, VolumeUpdate, WeakNodeTreatment};
use crate::solver::error::{require_count, require_positive, InputError};
use crate::solver::newton::NewtonSettings;
use serde::{Deserialize, Serialize};

/// Parameters of the cantilever (defaults: the paper's 20×2 elements of 0.5 m, 3×3 points).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CantileverSpec {
    /// Beam length L (m).
    pub length: f64,
    /// Beam depth (m); unit width.
    pub depth: f64,
    /// The material (the paper's: Hencky elasticity, E = 12e6 Pa, ν = 0.2); the elastica the
    /// study compares with takes its `young_modulus` and `poisson_ratio`.
    pub material: Material,
    /// Total end load P (N), downwards.
    pub load: f64,
    pub load_steps: usize,
    /// Element size h (m); length and depth must be whole multiples of it.
    pub element_size: f64,
    /// Material points per element along each axis.
    pub points_per_cell: usize,
    /// Grid depth below the beam's underside (m), room for the deflection.
    pub grid_below: f64,
    /// Grid room beyond the beam's free end and above it (m).
    pub grid_margin: f64,
    pub domain_update: DomainUpdate,
    pub newton: NewtonSettings,
    pub weak_node_tolerance: f64,
    #[serde(default)]
    pub weak_node_treatment: WeakNodeTreatment,
    /// Point volume rule. Default: the paper's product of the domain lengths (§3.1), under
    /// which the F-diagonal update collapses (Figure 20a); with `jacobian` volumes the
    /// F-diagonal run completes although its domains shrink to a fraction of their size.
    #[serde(default)]
    pub volume_update: VolumeUpdate,
    /// Ghost penalty of nearly empty cells ([`crate::discretise::ghost`]).
    #[serde(default)]
    pub ghost: GhostSettings,
    /// 2 (plane strain, the paper's) or 3 (a `depth × depth` section; see the module docs).
    /// Not serialised at 2, so 2D case hashes stay what they were.
    #[serde(default = "two", skip_serializing_if = "is_two")]
    pub dimension: usize,
    /// F-bar over each cell or element ([`crate::discretise::assembly::FBar`]). Not serialised
    /// when off, so case hashes stay what they were.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub f_bar: bool,
}

fn two() -> usize {
    2
}

fn is_two(d: &usize) -> bool {
    *d == 2
}

impl Default for CantileverSpec {
    fn default() -> Self {
        Self {
            length: 10.0,
            depth: 1.0,
            material: Material::linear_elastic(12e6, 0.2),
            load: 100e3,
            load_steps: 50,
            element_size: 0.5,
            points_per_cell: 3,
            grid_below: 10.0,
            grid_margin: 1.0,
            domain_update: DomainUpdate::Stretch,
            newton: NewtonSettings::default(),
            // The ghost penalty is the default treatment of nearly empty cells (measured,
            // reference/README.md items 15-16); the weak-node tie stays available, off.
            weak_node_tolerance: 0.0,
            weak_node_treatment: WeakNodeTreatment::Tie,
            volume_update: VolumeUpdate::DomainProduct,
            // As the cantilever study (studies/cantilever.toml): gamma in [1e-3, 1e-1] spans
            // 0.15 % of u/L at h = 0.5 with cells filled below 5 % penalised.
            ghost: GhostSettings {
                gamma: 1e-2,
                faces: GhostFaces::Cut,
                cut_fill: 0.05,
                cut_share: 0.0,
            },
            dimension: 2,
            f_bar: false,
        }
    }
}

impl CantileverSpec {
    pub fn validate(&self) -> Result<(), InputError> {
        if !matches!(self.dimension, 2 | 3) {
            return Err(InputError::new("dimension", self.dimension, "must be 2 or 3"));
        }
        self.ghost.validate()?;
        require_positive("length", self.length)?;
        require_positive("depth", self.depth)?;
        require_positive("element_size", self.element_size)?;
        require_positive("grid_below", self.grid_below)?;
        require_positive("grid_margin", self.grid_margin)?;
        // P acts downwards (along -y); a zero load has no elastica to compare with.
        require_positive("load", self.load)?;
        crate::fem::validate_stepping(&self.newton, self.load_steps)?;
        require_count("points_per_cell", self.points_per_cell, 1)?;
        if self.points_per_cell > 16 {
            return Err(InputError::new(
                "points_per_cell",
                self.points_per_cell,
                "must be <= 16",
            ));
        }
        self.newton.validate()?;
        self.model()?;
        for (name, v) in [
            ("length", self.length),
            ("depth", self.depth),
            ("grid_below", self.grid_below),
            ("grid_margin", self.grid_margin),
        ] {
            let n = v / self.element_size;
            if (n - n.round()).abs() > 1e-9 * n.max(1.0) || n.round() > 100_000.0 {
                return Err(InputError::new(
                    name,
                    v,
                    format!("must be a whole multiple of element_size = {}", self.element_size),
                ));
            }
        }
        let rows = (self.depth / self.element_size).round() as usize * self.points_per_cell;
        if rows % 2 != 0 {
            return Err(InputError::new(
                "points_per_cell",
                self.points_per_cell,
                "points through the depth must be even so that two points straddle the neutral axis",
            ));
        }
        let through = (self.depth / self.element_size).round() as usize;
        if through % 2 != 0 {
            return Err(InputError::new(
                "element_size",
                self.element_size,
                format!(
                    "must divide depth = {} into an even number of elements (it gives {through}) so that the neutral axis is a grid line: e.g. element_size = {}",
                    self.depth,
                    self.depth / (through + 1) as f64
                ),
            ));
        }
        Ok(())
    }

    /// The constitutive model, built from [`Self::material`].
    pub fn model(&self) -> Result<Box<dyn ConstitutiveModel>, InputError> {
        self.material.build()
    }

    /// E and ν of the material, which the elastica's bending stiffness takes.
    pub fn elastic_constants(&self) -> Result<(f64, f64), InputError> {
        let what = "the cantilever's elastica (bending stiffness E d^3/12)";
        Ok((
            self.material.require("young_modulus", what)?,
            self.material.require("poisson_ratio", what)?,
        ))
    }
}

/// End displacement after one converged load step.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct EndDisplacement {
    pub step: usize,
    pub load: f64,
    /// Horizontal and vertical displacement of the loaded end (mean of the two loaded
    /// points), divided by L.
    pub u_over_l: f64,
    pub v_over_l: f64,
}

/// The methods that solve the plane-strain cantilever (its FEM comparator is Q8, the paper's
/// Figure 21).
pub const METHODS: [Method; Method::FAMILIES + 1] = Method::listed(Some(2), &[Method::FEM_Q4]);

/// The methods that solve the 3D cantilever.
pub const METHODS_3D: [Method; Method::FAMILIES + 2] = Method::listed(Some(3), &[]);

/// The methods of a cantilever in `dimension` (2 or 3).
pub fn methods(dimension: usize) -> &'static [Method] {
    if dimension == 3 {
        &METHODS_3D
    } else {
        &METHODS
    }
}
