//! The compaction problem's parameters, their checks, its material and its methods.

use crate::basis::method::Method;
use crate::basis::Basis;
use crate::discretise::ghost::{GhostFaces, GhostSettings};
use crate::material::constitutive::{ConstitutiveModel, Material};
use crate::mpm::{DomainUpdate, WeakNodeTreatment};
use crate::solver::error::{require_count, require_positive, InputError};
use crate::solver::linear::LinearSolver;
use crate::solver::newton::NewtonSettings;
use serde::{Deserialize, Serialize};

/// Parameters of the compaction problem (defaults: the paper's elastic case, h = 1, 2×2 points).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CompactionSpec {
    /// Half width of the block (the modelled part).
    pub half_width: f64,
    pub height: f64,
    /// Background grid extent along x and y (origin at the symmetry line / bottom).
    pub grid_extent: [f64; 2],
    /// Element size h (the same along both axes).
    pub element_size: f64,
    /// Material points per element along each axis.
    pub points_per_cell: usize,
    /// The material (the paper's: Hencky elasticity, or von Mises for Figure 18 and Table 3).
    pub material: Material,
    /// Weight of the full block, W.
    pub weight: f64,
    pub load_steps: usize,
    pub newton: NewtonSettings,
    /// See [`MpmSettings::weak_node_tolerance`](crate::mpm::MpmSettings::weak_node_tolerance).
    pub weak_node_tolerance: f64,
    #[serde(default)]
    pub weak_node_treatment: WeakNodeTreatment,
    pub basis: Basis,
    pub domain_update: DomainUpdate,
    /// Sparse factorisation; the default chooses LDLᵀ for the symmetric tangents (LU otherwise).
    #[serde(default)]
    pub linear_solver: LinearSolver,
    /// Ghost penalty of nearly empty cells ([`crate::discretise::ghost`]).
    #[serde(default)]
    pub ghost: GhostSettings,
    /// 2 (plane strain, the paper's) or 3: the quarter of a square block with two symmetry
    /// planes ([`CompactionSpec::mpm_solver_3d`], [`solve_fem_3d`](super::solve_fem_3d)). Not serialised at 2, so
    /// 2D case hashes stay what they were.
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

impl Default for CompactionSpec {
    fn default() -> Self {
        Self {
            half_width: 4.0,
            height: 8.0,
            grid_extent: [10.0, 10.0],
            element_size: 1.0,
            points_per_cell: 2,
            material: Material::linear_elastic(1e5, 0.3),
            weight: 4e5,
            load_steps: 20,
            newton: NewtonSettings::default(),
            // The ghost penalty is the default treatment of nearly empty cells (measured,
            // reference/README.md items 15-16); the weak-node tie stays available, off.
            weak_node_tolerance: 0.0,
            weak_node_treatment: WeakNodeTreatment::Tie,
            basis: Basis::Gimp,
            domain_update: DomainUpdate::Stretch,
            linear_solver: LinearSolver::Auto,
            // gamma: the plateau of the compaction study's ghost sweep: gamma in [0.1, 10] moves Figure 17 by <= 0.1 % at h <= 1/2.
            ghost: GhostSettings {
                gamma: 1.0,
                faces: GhostFaces::Cut,
                ..Default::default()
            },
            dimension: 2,
            f_bar: false,
        }
    }
}

impl CompactionSpec {
    pub fn validate(&self) -> Result<(), InputError> {
        if !matches!(self.dimension, 2 | 3) {
            return Err(InputError::new("dimension", self.dimension, "must be 2 or 3"));
        }
        self.ghost.validate()?;
        require_positive("half_width", self.half_width)?;
        require_positive("height", self.height)?;
        require_positive("element_size", self.element_size)?;
        require_positive("weight", self.weight)?;
        require_count("points_per_cell", self.points_per_cell, 1)?;
        if self.points_per_cell > 16 {
            return Err(InputError::new(
                "points_per_cell",
                self.points_per_cell,
                "must be <= 16",
            ));
        }
        crate::fem::validate_stepping(&self.newton, self.load_steps)?;
        self.newton.validate()?;
        for a in 0..2 {
            require_positive(&format!("grid_extent[{a}]"), self.grid_extent[a])?;
            let n = self.grid_extent[a] / self.element_size;
            if (n - n.round()).abs() > 1e-9 * n || n.round() > 100_000.0 {
                return Err(InputError::new(
                    format!("grid_extent[{a}]"),
                    self.grid_extent[a],
                    format!(
                        "must be a whole multiple (<= 100000) of element_size = {}",
                        self.element_size
                    ),
                ));
            }
        }
        if self.half_width > self.grid_extent[0] || self.height > self.grid_extent[1] {
            return Err(InputError::new(
                "grid_extent",
                format!("{:?}", self.grid_extent),
                format!("must contain the block {} x {}", self.half_width, self.height),
            ));
        }
        self.model()?;
        Ok(())
    }

    /// The constitutive model, built from [`Self::material`].
    pub fn model(&self) -> Result<Box<dyn ConstitutiveModel>, InputError> {
        self.material.build()
    }

    /// The material's yield stress, `None` for an elastic block (its plastic cases take the
    /// study's plastic ghost penalty and a `vm<yield stress>` case id).
    pub fn yield_stress(&self) -> Option<f64> {
        self.material.get("yield_stress")
    }

    /// ρ0 g of the block (density 1).
    pub fn unit_weight(&self) -> f64 {
        self.weight / (2.0 * self.half_width * self.height)
    }
}

/// The methods that solve the plane-strain compaction.
pub const METHODS: [Method; Method::FAMILIES + 2] = Method::listed(Some(2), &[]);

/// The methods that solve the 3D compaction.
pub const METHODS_3D: [Method; Method::FAMILIES + 2] = Method::listed(Some(3), &[]);

/// The methods of a compaction in `dimension` (2 or 3).
pub fn methods(dimension: usize) -> &'static [Method] {
    if dimension == 3 {
        &METHODS_3D
    } else {
        &METHODS
    }
}
