//! One-dimensional column compressed under its own weight (§5.1).
//!
//! The column of initial length L0 stands on a fixed base; gravity is ramped linearly over the
//! load steps to g = W/(ρ0 L0). Axis 0 is the vertical z; the out-of-plane stretches stay one
//! (uniaxial strain).

use crate::basis::Basis;
use crate::constitutive::LinearElastic;
use crate::error::{require_count, require_positive, InputError, SolveError};
use crate::grid::Grid;
use crate::mpm::{DomainUpdate, Loads, MpmSettings, MpmSolver, StepReport};
use crate::newton::NewtonSettings;
use crate::norms;
use crate::particles::MaterialPoints;
use nalgebra::SVector;
use serde::{Deserialize, Serialize};

/// Analytical solution of the elastic column, eqs (42)–(45).
///
/// Equilibrium in the Lagrangian coordinate Z gives the Cauchy stress exactly,
/// σ(Z) = −ρ0 g (L0 − Z) (eq 42, compression negative). With τ = E ln F (eq 44) and σ = τ/F
/// (eq 16, J = F in uniaxial strain), F(Z) solves E ln F / F = σ(Z) (eq 45). The displacement
/// u(Z) = ∫₀^Z (F − 1) dZ' has a closed form after substituting dZ = dσ/(ρ0 g) and
/// dσ = E (1 − ln F)/F² dF:
///
/// u(Z) = (E / ρ0 g) [H(F(Z)) − H(F(0))],  H(F) = ln F − ½ ln² F − ln F / F.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ElasticColumn {
    pub young_modulus: f64,
    /// ρ0 g, the weight per unit initial volume.
    pub unit_weight: f64,
    pub length: f64,
}

impl ElasticColumn {
    /// Cauchy stress at initial height Z, eq (42).
    pub fn stress(&self, z0: f64) -> f64 {
        -self.unit_weight * (self.length - z0)
    }

    /// F at initial height Z: the root of E ln F / F = σ(Z), eq (45).
    pub fn deformation_gradient(&self, z0: f64) -> f64 {
        f_from_cauchy_stress(self.stress(z0) / self.young_modulus)
    }

    /// Displacement at initial height Z.
    pub fn displacement(&self, z0: f64) -> f64 {
        let h = |f: f64| {
            let l = f.ln();
            l - 0.5 * l * l - l / f
        };
        let f0 = self.deformation_gradient(0.0);
        let fz = self.deformation_gradient(z0);
        self.young_modulus / self.unit_weight * (h(fz) - h(f0))
    }
}

/// Solve ln F / F = s for F (s = σ/E < 1/e, the compressive branch F ≤ 1 when s ≤ 0).
///
/// Works in y = ln F: ψ(y) = y − s e^y is monotone on the bracket ([s, 0] for s ≤ 0, [0, 1]
/// for 0 < s < 1/e); safeguarded Newton converges to round-off.
pub fn f_from_cauchy_stress(s: f64) -> f64 {
    assert!(
        s < std::f64::consts::E.recip(),
        "ln F / F = {s} has no solution (s >= 1/e)"
    );
    let (mut lo, mut hi) = if s <= 0.0 { (s, 0.0) } else { (0.0, 1.0) };
    let mut y: f64 = if s <= 0.0 { 0.0 } else { 0.5 };
    for _ in 0..200 {
        let psi = y - s * y.exp();
        if psi == 0.0 {
            break;
        }
        if psi > 0.0 {
            hi = y;
        } else {
            lo = y;
        }
        let mut next = y - psi / (1.0 - s * y.exp());
        if !(next > lo && next < hi) {
            next = 0.5 * (lo + hi);
        }
        if (next - y).abs() <= 1e-16 * (1.0 + y.abs()) {
            y = next;
            break;
        }
        y = next;
    }
    y.exp()
}

/// Discretisation method of a column case.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Method {
    /// Standard implicit MPM.
    Mpm,
    /// Implicit GIMP (the paper's method).
    Igimp,
    /// Updated-Lagrangian FEM, two-noded linear elements (2 Gauss points by default).
    FemLinear,
    /// Updated-Lagrangian FEM, three-noded quadratic elements (3 Gauss points by default).
    FemQuadratic,
}

impl Method {
    pub fn name(self) -> &'static str {
        match self {
            Method::Mpm => "mpm",
            Method::Igimp => "igimp",
            Method::FemLinear => "fem-linear",
            Method::FemQuadratic => "fem-quadratic",
        }
    }
}

/// The column problem's parameters (defaults: §5.1 with W = 40,000).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ColumnSpec {
    /// Initial length L0.
    pub length: f64,
    pub young_modulus: f64,
    pub poisson_ratio: f64,
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
}

impl Default for ColumnSpec {
    fn default() -> Self {
        Self {
            length: 50.0,
            young_modulus: 1e6,
            poisson_ratio: 0.0,
            density: 80.0,
            weight: 40_000.0,
            elements: 50,
            points_per_cell: 2,
            load_steps: 20,
            newton: NewtonSettings::default(),
            gauss_points: None,
        }
    }
}

impl ColumnSpec {
    /// Check every field; the error names the field and its allowed range.
    pub fn validate(&self) -> Result<(), InputError> {
        require_positive("length", self.length)?;
        LinearElastic::try_new(self.young_modulus, self.poisson_ratio)?;
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
        require_count("load_steps", self.load_steps, 1)?;
        self.newton.validate()?;
        if let Some(n) = self.gauss_points {
            crate::quadrature::GaussRule::try_new(n)?;
        }
        let s = -self.weight / self.young_modulus;
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
    pub fn analytical(&self) -> ElasticColumn {
        ElasticColumn {
            young_modulus: self.young_modulus,
            unit_weight: self.density * self.gravity(),
            length: self.length,
        }
    }

    /// The MPM/GIMP solver for this column: grid [0, L0], base node fixed, gravity along −z.
    pub fn mpm_solver(&self, basis: Basis) -> Result<MpmSolver<1>, InputError> {
        self.validate()?;
        let h = self.length / self.elements as f64;
        let grid = Grid::try_new([0.0], [h], [self.elements])?;
        let points =
            MaterialPoints::fill_box(&grid, [0.0], [self.length], [self.points_per_cell], self.density)?;
        let model = Box::new(LinearElastic::try_new(self.young_modulus, self.poisson_ratio)?);
        let loads = Loads {
            gravity: SVector::<f64, 1>::new(-self.gravity()),
            point_loads: vec![],
        };
        let settings = MpmSettings {
            basis,
            domain_update: DomainUpdate::Stretch,
            newton: self.newton,
            load_steps: self.load_steps,
        };
        MpmSolver::try_new(grid, points, model, vec![(0, 0)], loads, settings)
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
        Self {
            points,
            steps,
            failure,
            top_displacement,
            base_f: base,
            stress_error,
            f_error,
        }
    }
}

/// Run the column with any method.
pub fn solve_column(spec: &ColumnSpec, method: Method) -> Result<ColumnOutcome, InputError> {
    match method {
        Method::Mpm => solve_mpm(spec, Basis::Mpm),
        Method::Igimp => solve_mpm(spec, Basis::Gimp),
        Method::FemLinear => crate::fem::solve_column(spec, crate::fem::LineElement::Linear),
        Method::FemQuadratic => crate::fem::solve_column(spec, crate::fem::LineElement::Quadratic),
    }
}

/// Run the column with MPM or GIMP weights.
pub fn solve_mpm(spec: &ColumnSpec, basis: Basis) -> Result<ColumnOutcome, InputError> {
    let mut solver = spec.mpm_solver(basis)?;
    let (steps, failure) = match solver.run() {
        Ok(s) => (s, None),
        Err((s, e)) => (s, Some(e)),
    };
    let pts = &solver.points;
    let records: Vec<PointRecord> = (0..pts.len())
        .map(|p| {
            let st = &pts.state[p];
            let sigma = st.cauchy();
            PointRecord {
                z0: pts.position0[p][0],
                z: pts.position[p][0],
                volume0: pts.volume0[p],
                sigma_zz: sigma[(0, 0)],
                sigma_xx: sigma[(1, 1)],
                f_zz: st.f[(0, 0)],
            }
        })
        .collect();
    let top = (0..pts.len())
        .max_by(|&a, &b| pts.position0[a][0].total_cmp(&pts.position0[b][0]))
        .map_or(f64::NAN, |p| pts.displacement(p)[0]);
    Ok(ColumnOutcome::from_records(spec, records, top, steps, failure))
}
