//! The material point solver's settings: basis, domain update, Newton, load steps, volume
//! update, weak nodes, ghost penalty, linear solver and dynamics.

use crate::basis::{Basis, DomainUpdate};
use crate::discretise::ghost::GhostSettings;
use crate::solver::dynamics::Newmark;
use crate::solver::error::{require_count, InputError};
use crate::solver::load_stepping::MAX_LOAD_STEPS;
use crate::solver::newton::NewtonSettings;
use serde::{Deserialize, Serialize};

/// Solver settings.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct MpmSettings {
    /// The basis family of the weights S_vp.
    pub basis: Basis,
    /// How the domain half-lengths follow the deformation at each commit (§3.3).
    pub domain_update: DomainUpdate,
    /// Newton iteration settings of each load step.
    pub newton: NewtonSettings,
    /// Number of equal load increments.
    pub load_steps: usize,
    /// Weak nodes: a grid node whose share of material volume Σ_p S_vp V_p is below this
    /// fraction of an element's volume (a domain grazing an element) makes the tangent nearly
    /// singular and is treated by `weak_node_treatment` for the step. 0 disables.
    #[serde(default)]
    pub weak_node_tolerance: f64,
    /// What is done to a weak node (see `weak_node_tolerance`).
    #[serde(default)]
    pub weak_node_treatment: WeakNodeTreatment,
    /// How a point's committed volume is obtained (eq 28).
    #[serde(default)]
    pub volume_update: VolumeUpdate,
    /// Sparse factorisation of the tangent: LU (default) or, for the symmetric tangents of
    /// hyperelastic and associative plastic models, LDLᵀ/LLᵀ with LU as fallback.
    #[serde(default)]
    pub linear_solver: crate::solver::linear::LinearSolver,
    /// Ghost penalty on the grid faces of nearly empty cells ([`crate::discretise::ghost`]); off by
    /// default here, chosen per problem from measurements.
    #[serde(default)]
    pub ghost: GhostSettings,
    /// Newmark time integration ([`crate::solver::dynamics`]): the load steps become time steps over
    /// `duration`; `None` (default): quasi-static.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub dynamics: Option<Newmark>,
    /// F-bar: each point's volume change replaced by its cell's average
    /// ([`crate::discretise::assembly::FBar`]); off by default (reference/README.md item 69).
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub f_bar: bool,
}

/// The paper's method: iGIMP (eqs 7–10) with the stretch-tensor domain update (eq 39), the
/// default Newton settings ([`NewtonSettings::default`]), 20 load steps (§5's examples), no
/// weak-node treatment and no ghost penalty (both chosen per problem by measurement), the
/// Jacobian volume update, the default direct solver, quasi-static.
impl Default for MpmSettings {
    fn default() -> Self {
        MpmSettings {
            basis: Basis::Gimp,
            domain_update: DomainUpdate::Stretch,
            newton: NewtonSettings::default(),
            load_steps: 20,
            weak_node_tolerance: 0.0,
            weak_node_treatment: WeakNodeTreatment::default(),
            volume_update: VolumeUpdate::default(),
            linear_solver: crate::solver::linear::LinearSolver::default(),
            ghost: GhostSettings::default(),
            dynamics: None,
            f_bar: false,
        }
    }
}

/// How the committed volume V_p^n of a material point is obtained (eq 28).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum VolumeUpdate {
    /// V_p^n = det(F) v_p0, accumulated as det(ΔF) V_p^(n−1): conserves mass under any
    /// deformation, and keeps the volume independent of the domain-update rule.
    #[default]
    Jacobian,
    /// V_p^n = Π l_i, the product of the updated domain lengths, as §3.1 states. Equal to
    /// the Jacobian in 1D; with the F-diagonal domain update it collapses under rotation,
    /// which is how the paper's Figure 20(a) analysis fails.
    DomainProduct,
}

/// How weak nodes are treated in a load step.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum WeakNodeTreatment {
    /// Tie the node to its strongest grid neighbour (same increment): moves the sliver of
    /// material with its neighbour instead of pinning it. Falls back to `Fix` when no
    /// neighbour has enough material.
    #[default]
    Tie,
    /// Fix the node's increment at zero.
    Fix,
}

impl MpmSettings {
    /// Check every setting against its range.
    pub fn validate(&self) -> Result<(), InputError> {
        self.newton.validate()?;
        self.ghost.validate()?;
        if !(self.weak_node_tolerance >= 0.0 && self.weak_node_tolerance < 1.0) {
            return Err(InputError::new(
                "weak_node_tolerance",
                self.weak_node_tolerance,
                "must lie in [0, 1)",
            ));
        }
        require_count("load_steps", self.load_steps, 1)?;
        if let Some(n) = &self.dynamics {
            n.validate()?;
            if !self.newton.predictor.is_zero() {
                return Err(InputError::new(
                    "newton.predictor",
                    self.newton.predictor.name(),
                    "must be \"zero\" with dynamics: the Newmark predictor starts each time step",
                ));
            }
        }
        if self.load_steps > MAX_LOAD_STEPS {
            return Err(InputError::new(
                "load_steps",
                self.load_steps,
                format!("must be <= {MAX_LOAD_STEPS}"),
            ));
        }
        Ok(())
    }
}
