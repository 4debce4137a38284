//! The column problem's parameters, their checks, and what one analysis reports.

use super::analytical::AnalyticalColumn;
use crate::basis::method::Method;
use crate::discretise::ghost::GhostSettings;
use crate::fem::{LineFem, SolidFem};
use crate::material::constitutive::{lame, ConstitutiveModel, InternalVariables, Material};
use crate::mpm::MpmSolver;
use crate::problems::norms;
use crate::solver::error::{require_count, require_derived, require_positive, InputError, SolveError};
use crate::solver::load_stepping::StepReport;
use crate::solver::newton::NewtonSettings;
use serde::{Deserialize, Serialize};

/// The methods that solve the column.
pub const METHODS: [Method; Method::FAMILIES + 2] = Method::listed(Some(1), &[]);

/// The methods that solve the 3D column (`dimension = 3`).
pub const METHODS_3D: [Method; Method::FAMILIES + 2] = Method::listed(Some(3), &[]);

/// The column problem's parameters (defaults: §5.1 with W = 40,000).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ColumnSpec {
    /// Initial length L0.
    pub length: f64,
    /// The material: the closed form ([`Self::analytical`]) is Hencky elasticity with its
    /// `young_modulus` and `poisson_ratio`, and von Mises perfect plasticity when it has a
    /// `yield_stress`.
    pub material: Material,
    /// Initial density ρ0.
    pub density: f64,
    /// Total weight W = ρ0 g L0 at the end of loading; sets g.
    pub weight: f64,
    /// Background elements along the column.
    pub elements: usize,
    /// Material points per element (MPM/GIMP).
    pub points_per_cell: usize,
    pub load_steps: usize,
    pub newton: NewtonSettings,
    /// Gauss points per element of the FEM comparators, 1..=5 (default: 2 for linear, 3 for
    /// quadratic elements, as in the paper). Not used by MPM/GIMP.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gauss_points: Option<usize>,
    /// Ghost penalty (MPM/GIMP only; off by default: the column has no nearly empty cells,
    /// but one point per cell needs it on every face).
    #[serde(default, skip_serializing_if = "is_off")]
    pub ghost: GhostSettings,
    /// 1: the column of the paper; 3: the same column as a 1 × 1 × n prism of unit cross
    /// section with rollers on its lateral faces (uniaxial strain, as in 1D), on a 3D grid of
    /// one cell across (MPM/GIMP only so far).
    #[serde(default = "one", skip_serializing_if = "is_one")]
    pub dimension: usize,
    /// F-bar over each cell (material points) ([`crate::discretise::assembly::FBar`]). Not serialised
    /// when off, so case hashes stay what they were.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub f_bar: bool,
}

fn is_off(g: &GhostSettings) -> bool {
    !g.is_on()
}

fn one() -> usize {
    1
}

fn is_one(d: &usize) -> bool {
    *d == 1
}

impl Default for ColumnSpec {
    fn default() -> Self {
        Self {
            length: 50.0,
            material: Material::linear_elastic(1e6, 0.0),
            density: 80.0,
            weight: 40_000.0,
            elements: 50,
            points_per_cell: 2,
            load_steps: 20,
            newton: NewtonSettings::default(),
            gauss_points: None,
            ghost: GhostSettings::default(),
            dimension: 1,
            f_bar: false,
        }
    }
}

impl ColumnSpec {
    /// Check every field; the error names the field and its allowed range.
    pub fn validate(&self) -> Result<(), InputError> {
        if !matches!(self.dimension, 1 | 3) {
            return Err(InputError::new("dimension", self.dimension, "must be 1 or 3"));
        }
        require_positive("length", self.length)?;
        self.model()?;
        require_positive("density", self.density)?;
        require_positive("weight", self.weight)?;
        require_count("elements", self.elements, 1)?;
        if self.elements > 10_000_000 {
            return Err(InputError::new("elements", self.elements, "must be <= 10000000"));
        }
        require_count("points_per_cell", self.points_per_cell, 1)?;
        if self.points_per_cell > 64 {
            return Err(InputError::new(
                "points_per_cell",
                self.points_per_cell,
                "must be <= 64",
            ));
        }
        crate::fem::validate_stepping(&self.newton, self.load_steps)?;
        self.newton.validate()?;
        if let Some(n) = self.gauss_points {
            crate::mesh::quadrature::GaussRule::try_new(n)?;
        }
        // The load and the closed form's scales (eq 45): g, ρ0 g and M L0 / W.
        let (w, rho, l) = (self.weight, self.density, self.length);
        let with = |what: &str| format!("{what}, with W = {w:e}, ρ0 = {rho:e} and L0 = {l:e},");
        require_derived("length", l, &with("the gravity g = W/(ρ0 L0)"), self.gravity())?;
        require_derived("length", l, &with("the unit weight W/L0"), w / l)?;
        let (e, nu) = self.elastic_constants()?;
        let (lambda, mu) = lame(e, nu);
        let m = lambda + 2.0 * mu;
        require_derived("length", l, &with("the closed form's scale M L0/W"), m * l / w)?;
        if let Some(y) = self.yield_stress() {
            require_derived(
                "material.yield_stress",
                y,
                &with("the yield height scale σy L0/W"),
                y * l / w,
            )?;
        }
        let s = -self.weight / e;
        if s < -1e3 {
            return Err(InputError::new(
                "weight",
                self.weight,
                "weight / young_modulus must be <= 1000",
            ));
        }
        Ok(())
    }
    /// Gravitational acceleration g = W / (ρ0 L0).
    pub fn gravity(&self) -> f64 {
        self.weight / (self.density * self.length)
    }
    /// The analytical solution of this column.
    pub fn analytical(&self) -> AnalyticalColumn {
        // NaN for a material without E or ν, which validation refuses.
        let (e, nu) = self.elastic_constants().unwrap_or((f64::NAN, f64::NAN));
        let (lambda, mu) = lame(e, nu);
        AnalyticalColumn {
            lambda,
            mu,
            unit_weight: self.density * self.gravity(),
            length: self.length,
            yield_stress: self.yield_stress(),
        }
    }

    /// The constitutive model, built from [`Self::material`].
    pub fn model(&self) -> Result<Box<dyn ConstitutiveModel>, InputError> {
        self.material.build()
    }

    /// E and ν of the material, which the closed form takes.
    pub fn elastic_constants(&self) -> Result<(f64, f64), InputError> {
        let what = "the column's closed form (eqs 42-45)";
        Ok((
            self.material.require("young_modulus", what)?,
            self.material.require("poisson_ratio", what)?,
        ))
    }

    /// The material's yield stress ρ_y (eq 48), `None` for an elastic column.
    pub fn yield_stress(&self) -> Option<f64> {
        self.material.get("yield_stress")
    }
}

/// Final values at one integration point.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct PointRecord {
    /// Initial height Z.
    pub z0: f64,
    /// Current height z.
    pub z: f64,
    /// Initial volume (length) v_p0.
    pub volume0: f64,
    /// Vertical Cauchy stress.
    pub sigma_zz: f64,
    /// Out-of-plane Cauchy stress.
    pub sigma_xx: f64,
    /// Vertical stretch F_zz.
    pub f_zz: f64,
    /// The model's internal variables ([`ConstitutiveModel::internal_variables`]).
    pub internal: InternalVariables,
    /// Whether an internal variable has left its initial value (the point yielded, for von
    /// Mises).
    pub inelastic: bool,
}

impl PointRecord {
    /// The values of one point from its committed `state` under `model`, the vertical axis
    /// `axis` and the lateral one `lateral`.
    pub fn of(
        model: &dyn ConstitutiveModel,
        state: &crate::material::kinematics::PointState,
        (z0, z, volume0): (f64, f64, f64),
        axis: usize,
        lateral: usize,
    ) -> Self {
        let sigma = state.cauchy();
        let internal = state.material.internal;
        PointRecord {
            z0,
            z,
            volume0,
            sigma_zz: sigma[(axis, axis)],
            sigma_xx: sigma[(lateral, lateral)],
            f_zz: state.f[(axis, axis)],
            internal,
            inelastic: internal.has_evolved(model.internal_variables()),
        }
    }
}

/// Yield height seen by a discretisation: the deviatoric measure ρ = |τ_xx − τ_zz| (eq 50,
/// τ = σ F) of the two lowest unyielded points, extrapolated linearly to ρ = ρ_y. `None` if
/// no point yielded or fewer than two stayed elastic.
pub fn yield_height_estimate(points: &[PointRecord], yield_stress: f64) -> Option<f64> {
    if !points.iter().any(|p| p.inelastic) {
        return None;
    }
    let mut elastic: Vec<&PointRecord> = points.iter().filter(|p| !p.inelastic).collect();
    elastic.sort_by(|a, b| a.z0.total_cmp(&b.z0));
    let rho = |p: &PointRecord| ((p.sigma_xx - p.sigma_zz) * p.f_zz).abs();
    // Extrapolate from the lowest elastic point and the next one with a different ρ (linear
    // elements have equal stresses at both Gauss points of an element).
    let a = *elastic.first()?;
    let ra = rho(a);
    let b = elastic[1..]
        .iter()
        .find(|p| (rho(p) - ra).abs() > 1e-12 * ra.abs().max(1.0))?;
    let z = a.z0 + (yield_stress - ra) * (b.z0 - a.z0) / (rho(b) - ra);
    z.is_finite().then_some(z)
}

/// Outcome of one column analysis.
#[derive(Debug, Clone, PartialEq)]
pub struct ColumnOutcome {
    pub points: Vec<PointRecord>,
    pub steps: Vec<StepReport>,
    /// Set if a load step failed; the other fields then describe the last converged step.
    pub failure: Option<SolveError>,
    /// Displacement of the top-most point.
    pub top_displacement: f64,
    /// F_zz of the bottom-most point.
    pub base_f: f64,
    /// Eq (46).
    pub stress_error: f64,
    /// Eq (47) against the exact analytical base value.
    pub f_error: f64,
    /// Eq (46) applied to the lateral stress σ_xx (plastic column, §5.1).
    pub sigma_xx_error: f64,
    /// Yield height seen by the discretisation ([`yield_height_estimate`]); `None` when
    /// elastic or when no point yielded.
    pub yield_height: Option<f64>,
}

impl ColumnOutcome {
    /// Error measures from point records, shared by every method so that they are computed
    /// by the same code.
    pub fn from_records(
        spec: &ColumnSpec,
        points: Vec<PointRecord>,
        top_displacement: f64,
        steps: Vec<StepReport>,
        failure: Option<SolveError>,
    ) -> Self {
        let exact = spec.analytical();
        let sig_exact: Vec<f64> = points.iter().map(|p| exact.stress(p.z0)).collect();
        let sig_h: Vec<f64> = points.iter().map(|p| p.sigma_zz).collect();
        let v0: Vec<f64> = points.iter().map(|p| p.volume0).collect();
        let stress_error = norms::stress_error(&sig_exact, &sig_h, &v0, spec.weight, spec.length);
        let base = points
            .iter()
            .min_by(|a, b| a.z0.total_cmp(&b.z0))
            .map_or(f64::NAN, |p| p.f_zz);
        let f_error = norms::f_error(base, exact.deformation_gradient(0.0));
        let sxx_exact: Vec<f64> = points.iter().map(|p| exact.lateral_stress(p.z0)).collect();
        let sxx_h: Vec<f64> = points.iter().map(|p| p.sigma_xx).collect();
        let sigma_xx_error = norms::stress_error(&sxx_exact, &sxx_h, &v0, spec.weight, spec.length);
        let yield_height = spec
            .yield_stress()
            .and_then(|ry| yield_height_estimate(&points, ry));
        Self {
            points,
            steps,
            failure,
            top_displacement,
            base_f: base,
            stress_error,
            f_error,
            sigma_xx_error,
            yield_height,
        }
    }
}

/// The solver of a column case between load steps, handed to a [`ColumnObserver`].
#[derive(Clone, Copy)]
pub enum ColumnState<'a> {
    Mpm(&'a MpmSolver<1>),
    Fem(&'a LineFem),
    /// The 3D prism (`dimension = 3`) by iGIMP or MPM.
    Mpm3(&'a MpmSolver<3>),
    /// The 3D prism by Hex8 or Hex20.
    Fem3(&'a SolidFem),
}

/// Called with the load step number (0 before the first step) and the solver after the
/// initial state and after every converged step, e.g. to write VTK files.
pub type ColumnObserver<'a> = dyn FnMut(usize, ColumnState<'_>) + 'a;
