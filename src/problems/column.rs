//! One-dimensional column compressed under its own weight (§5.1).
//!
//! The column of initial length L0 stands on a fixed base; gravity is ramped linearly over the
//! load steps to g = W/(ρ0 L0). Axis 0 is the vertical z; the out-of-plane stretches stay one
//! (uniaxial strain).

use crate::basis::Basis;
use crate::discretise::ghost::GhostSettings;
use crate::fem::{
    HexElement, HexMesh, LineElement, LineFem, LineFemSettings, LineLoads, LineMesh, PlaneFemSettings,
    SolidFem, SolidLoads,
};
use crate::material::constitutive::{lame, ConstitutiveModel, LinearElastic};
use crate::mesh::grid::Grid;
use crate::mpm::particles::MaterialPoints;
use crate::mpm::{DomainUpdate, Loads, MpmSettings, MpmSolver};
use crate::problems::norms;
use crate::solver::error::{require_count, require_derived, require_positive, InputError, SolveError};
use crate::solver::load_stepping::{steps_and_failure, LoadStepping, StepReport};
use crate::solver::newton::NewtonSettings;
use nalgebra::SVector;
use serde::{Deserialize, Serialize};

/// Analytical solution of the column under self weight, elastic (eqs 42–45) and von Mises
/// elasto-plastic (eqs 48–54, Appendix A), derived here for any ν (the paper takes ν = 0).
///
/// **Equilibrium.** In the Lagrangian coordinate Z the vertical Cauchy stress is exact and
/// independent of the material: σ_zz(Z) = −ρ0 g (L0 − Z) (eq 42, compression negative).
///
/// **Kinematics.** F = diag(F, 1, 1) (lateral stretches fixed), J = F, total log strains
/// ε_zz = ln F = y, ε_xx = 0. Cauchy stress σ = τ / F (eq 16).
///
/// **Elastic** (Hencky, eq 14, Lamé λ, μ; M = λ + 2μ): τ_zz = M y, τ_xx = λ y. With ν = 0,
/// M = E and σ = E ln F / F is eq (45).
///
/// **Yield** (ρ = |τ_xx − τ_zz| = 2μ|y|, eq 50): at y_y = −ρ_y/(2μ), i.e. when the *Kirchhoff*
/// stress τ_zz reaches −M ρ_y/(2μ) (= −ρ_y for ν = 0). The Cauchy stress there is
/// τ_zz/F = −ρ_y e^{ρ_y/E} (ν = 0), so yield starts at Z_y = L0 − ρ_y e^{ρ_y/E}/(ρ0 g), not at
/// the paper's L0 − ρ_y/(ρ0 g), which equates the Cauchy stress with ρ_y.
///
/// **Plastic.** Associated flow gives ε^p_xx = −½ ε^p_zz (deviatoric direction diag(1, −½, −½),
/// proportional loading). Elastic strains ε^e_xx = ½ε^p_zz and ε^e_zz = y − ε^p_zz on the yield
/// surface τ_xx − τ_zz = 2μ(ε^e_xx − ε^e_zz) = ρ_y give ε^p_zz = ⅔(y + ρ_y/(2μ)); with
/// K = λ + ⅔μ and tr ε^e = y (plastic incompressibility):
///   τ_zz = K y − ⅔ ρ_y,   τ_xx = K y + ⅓ ρ_y.
/// For ν = 0 (K = E/3) this is the paper's eq (53): with F^e_zz = exp(ε^e_zz),
/// F = (F^e_zz)³ e^{2ρ_y/E} and σ_zz = E ln F^e_zz / ((F^e_zz)³ e^{2ρ_y/E}); and eq (54),
/// σ_xx = E ln F^e_xx / F_zz. Appendix A's (A.17) divides by F^e_zz instead of J = F_zz, which
/// is inconsistent with eq (16); see reference/README.md.
///
/// F(Z) solves τ_zz(ln F)/F = σ_zz(Z): τ_zz(y) e^{−y} is increasing for y < 0, so the root is
/// unique and is found by safeguarded Newton in y.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AnalyticalColumn {
    /// Lamé λ.
    pub lambda: f64,
    /// Shear modulus μ.
    pub mu: f64,
    /// ρ0 g, the weight per unit initial volume.
    pub unit_weight: f64,
    pub length: f64,
    /// Von Mises yield stress ρ_y; `None` for an elastic column.
    pub yield_stress: Option<f64>,
}

impl AnalyticalColumn {
    /// Vertical Cauchy stress at initial height Z, eq (42).
    pub fn stress(&self, z0: f64) -> f64 {
        -self.unit_weight * (self.length - z0)
    }

    /// Log strain at first yield (−ρ_y/2μ), or −∞ when elastic.
    fn yield_strain(&self) -> f64 {
        self.yield_stress
            .map_or(f64::NEG_INFINITY, |ry| -ry / (2.0 * self.mu))
    }

    /// Kirchhoff stresses (τ_zz, τ_xx) at vertical log strain y ≤ 0.
    pub fn kirchhoff(&self, y: f64) -> (f64, f64) {
        if y >= self.yield_strain() {
            ((self.lambda + 2.0 * self.mu) * y, self.lambda * y)
        } else {
            let ry = self.yield_stress.expect("plastic branch");
            let k = self.lambda + 2.0 * self.mu / 3.0;
            (k * y - 2.0 * ry / 3.0, k * y + ry / 3.0)
        }
    }

    /// F at initial height Z: the root of τ_zz(ln F)/F = σ_zz(Z).
    pub fn deformation_gradient(&self, z0: f64) -> f64 {
        let sigma = self.stress(z0);
        if sigma >= 0.0 {
            return 1.0;
        }
        let m = self.lambda + 2.0 * self.mu;
        if self.yield_stress.is_none() {
            return f_from_cauchy_stress(sigma / m);
        }
        // ψ(y) = τ_zz(y) e^{−y} − σ is increasing on y < 0 with ψ(0) = −σ > 0.
        let psi = |y: f64| self.kirchhoff(y).0 * (-y).exp() - sigma;
        let (mut lo, mut hi) = (-1.0, 0.0);
        while psi(lo) > 0.0 {
            lo *= 2.0;
            assert!(lo > -1e6, "no root for column stress {sigma}");
        }
        let mut y = 0.5 * (lo + hi);
        for _ in 0..200 {
            let v = psi(y);
            if v > 0.0 {
                hi = y;
            } else {
                lo = y;
            }
            let dy = 1e-7 * (1.0 + y.abs());
            let slope = (psi(y + dy) - psi(y - dy)) / (2.0 * dy);
            let mut next = y - v / slope;
            if !(next > lo && next < hi && next.is_finite()) {
                next = 0.5 * (lo + hi);
            }
            if (next - y).abs() <= 1e-15 * (1.0 + y.abs()) || hi - lo <= 1e-15 {
                y = next;
                break;
            }
            y = next;
        }
        y.exp()
    }

    /// Lateral Cauchy stress σ_xx = σ_yy at initial height Z.
    pub fn lateral_stress(&self, z0: f64) -> f64 {
        let f = self.deformation_gradient(z0);
        self.kirchhoff(f.ln()).1 / f
    }

    /// Initial height below which the column is plastic (`None` if it never yields).
    pub fn yield_height(&self) -> Option<f64> {
        let y = self.yield_strain();
        if !y.is_finite() {
            return None;
        }
        let sigma_y = (self.lambda + 2.0 * self.mu) * y / y.exp();
        let z = self.length + sigma_y / self.unit_weight;
        (z > 0.0).then_some(z)
    }

    /// Displacement at initial height Z: closed form when elastic (see
    /// [`AnalyticalColumn::elastic_displacement`]), 64-point Gauss–Legendre on each smooth
    /// piece of ∫₀^Z (F − 1) dZ' otherwise.
    pub fn displacement(&self, z0: f64) -> f64 {
        if self.yield_stress.is_none() {
            return self.elastic_displacement(z0);
        }
        let mut breaks = vec![0.0];
        if let Some(zy) = self.yield_height() {
            if zy < z0 {
                breaks.push(zy);
            }
        }
        breaks.push(z0);
        let (xs, ws) = gauss_legendre_64();
        let mut u = 0.0;
        for w in breaks.windows(2) {
            let (a, b) = (w[0], w[1]);
            for (x, wt) in xs.iter().zip(&ws) {
                let z = 0.5 * (a + b) + 0.5 * (b - a) * x;
                u += 0.5 * (b - a) * wt * (self.deformation_gradient(z) - 1.0);
            }
        }
        u
    }

    /// Elastic displacement in closed form: substituting dZ = dσ/(ρ0 g) and
    /// dσ = M (1 − ln F)/F² dF in u(Z) = ∫₀^Z (F − 1) dZ' gives
    /// u(Z) = (M / ρ0 g) [H(F(Z)) − H(F(0))],  H(F) = ln F − ½ ln² F − ln F / F.
    pub fn elastic_displacement(&self, z0: f64) -> f64 {
        let h = |f: f64| {
            let l = f.ln();
            l - 0.5 * l * l - l / f
        };
        let m = self.lambda + 2.0 * self.mu;
        let elastic = Self {
            yield_stress: None,
            ..*self
        };
        let f0 = elastic.deformation_gradient(0.0);
        let fz = elastic.deformation_gradient(z0);
        m / self.unit_weight * (h(fz) - h(f0))
    }
}

/// 64-point Gauss–Legendre nodes and weights on [−1, 1] (Newton on P_64).
fn gauss_legendre_64() -> (Vec<f64>, Vec<f64>) {
    let n = 64;
    let mut xs = Vec::with_capacity(n);
    let mut ws = Vec::with_capacity(n);
    for i in 0..n {
        let mut x = (std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
        let mut dp = 0.0;
        for _ in 0..100 {
            let (mut p0, mut p1) = (1.0, x);
            for k in 2..=n {
                let p2 = ((2 * k - 1) as f64 * x * p1 - (k - 1) as f64 * p0) / k as f64;
                p0 = p1;
                p1 = p2;
            }
            dp = n as f64 * (x * p1 - p0) / (x * x - 1.0);
            let dx = p1 / dp;
            x -= dx;
            if dx.abs() < 1e-16 {
                break;
            }
        }
        xs.push(x);
        ws.push(2.0 / ((1.0 - x * x) * dp * dp));
    }
    (xs, ws)
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

pub use crate::basis::method::Method;

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
    /// Von Mises yield stress ρ_y (eq 48); absent for an elastic column.
    #[serde(default)]
    pub yield_stress: Option<f64>,
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
            young_modulus: 1e6,
            poisson_ratio: 0.0,
            density: 80.0,
            weight: 40_000.0,
            elements: 50,
            points_per_cell: 2,
            load_steps: 20,
            newton: NewtonSettings::default(),
            yield_stress: None,
            gauss_points: None,
            ghost: GhostSettings::default(),
            dimension: 1,
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
        crate::fem::validate_stepping(&self.newton, self.load_steps)?;
        self.newton.validate()?;
        self.model()?;
        if let Some(n) = self.gauss_points {
            crate::mesh::quadrature::GaussRule::try_new(n)?;
        }
        // The load and the closed form's scales (eq 45): g, ρ0 g and M L0 / W.
        let (w, rho, l) = (self.weight, self.density, self.length);
        let with = |what: &str| format!("{what}, with W = {w:e}, ρ0 = {rho:e} and L0 = {l:e},");
        require_derived("length", l, &with("the gravity g = W/(ρ0 L0)"), self.gravity())?;
        require_derived("length", l, &with("the unit weight W/L0"), w / l)?;
        let (lambda, mu) = lame(self.young_modulus, self.poisson_ratio);
        let m = lambda + 2.0 * mu;
        require_derived("length", l, &with("the closed form's scale M L0/W"), m * l / w)?;
        if let Some(y) = self.yield_stress {
            require_derived(
                "yield_stress",
                y,
                &with("the yield height scale σy L0/W"),
                y * l / w,
            )?;
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
    pub fn analytical(&self) -> AnalyticalColumn {
        let (lambda, mu) = lame(self.young_modulus, self.poisson_ratio);
        AnalyticalColumn {
            lambda,
            mu,
            unit_weight: self.density * self.gravity(),
            length: self.length,
            yield_stress: self.yield_stress,
        }
    }

    /// The constitutive model: linear elastic, or von Mises when `yield_stress` is set.
    pub fn model(&self) -> Result<Box<dyn ConstitutiveModel>, InputError> {
        crate::material::constitutive::elastic_or_von_mises(
            self.young_modulus,
            self.poisson_ratio,
            self.yield_stress,
        )
    }

    /// Solver settings of the material point column (1D or 3D).
    fn mpm_settings(&self, basis: Basis) -> MpmSettings {
        MpmSettings {
            basis,
            domain_update: DomainUpdate::Stretch,
            newton: self.newton,
            load_steps: self.load_steps,
            weak_node_tolerance: 0.0,
            weak_node_treatment: Default::default(),
            volume_update: Default::default(),
            linear_solver: Default::default(),
            ghost: self.ghost,
            dynamics: None,
        }
    }

    /// The MPM/GIMP solver for this column: grid [0, L0], base node fixed, gravity along −z.
    pub fn mpm_solver(&self, basis: Basis) -> Result<MpmSolver<1>, InputError> {
        self.validate()?;
        let h = self.length / self.elements as f64;
        let grid = Grid::try_new([0.0], [h], [self.elements])?;
        let points =
            MaterialPoints::fill_box(&grid, [0.0], [self.length], [self.points_per_cell], self.density)?;
        let model = self.model()?;
        let loads = Loads {
            gravity: SVector::<f64, 1>::new(-self.gravity()),
            point_loads: vec![],
        };
        let settings = self.mpm_settings(basis);
        MpmSolver::try_new(grid, points, model, vec![(0, 0)], loads, settings)
    }
}

impl ColumnSpec {
    /// The 3D prism of this column (`dimension = 3`): a grid of 1 × 1 × `elements` cells of
    /// 1 × 1 × h (unit cross section), points 2 × 2 × `points_per_cell` per cell, every lateral
    /// node on rollers (u_x = u_y = 0, so the strain is uniaxial as in 1D), the base fixed,
    /// gravity along −z. Two points across, not one: with one, the mode u_z ∝ (x − ½)(y − ½)
    /// of each level's four nodes has no stiffness (the point sits where its value and
    /// gradient vanish) and the tangent is singular.
    pub fn mpm_solver_3d(&self, basis: Basis) -> Result<MpmSolver<3>, InputError> {
        self.validate()?;
        let h = self.length / self.elements as f64;
        let grid = Grid::try_new([0.0; 3], [1.0, 1.0, h], [1, 1, self.elements])?;
        let points = MaterialPoints::fill_box(
            &grid,
            [0.0; 3],
            [1.0, 1.0, self.length],
            [2, 2, self.points_per_cell],
            self.density,
        )?;
        let mut fixed: Vec<(usize, usize)> = (0..grid.num_nodes()).flat_map(|n| [(n, 0), (n, 1)]).collect();
        fixed.extend(grid.nodes_on_plane(2, 0.0).into_iter().map(|n| (n, 2)));
        let loads = Loads {
            gravity: SVector::<f64, 3>::new(0.0, 0.0, -self.gravity()),
            point_loads: vec![],
        };
        let settings = self.mpm_settings(basis);
        MpmSolver::try_new(grid, points, self.model()?, fixed, loads, settings)
    }
}

fn solve_mpm_3d(
    spec: &ColumnSpec,
    basis: Basis,
    observer: &mut ColumnObserver<'_>,
) -> Result<ColumnOutcome, InputError> {
    let mut solver = spec.mpm_solver_3d(basis)?;
    observer(0, ColumnState::Mpm3(&solver));
    let (steps, failure) =
        steps_and_failure(solver.run_observed(&mut |s, r| observer(r.step, ColumnState::Mpm3(s))));
    Ok(mpm_outcome(spec, &solver.points, 2, 0, steps, failure))
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
    /// Accumulated plastic multiplier (0 where the point never yielded).
    pub plastic_multiplier: f64,
}

/// Yield height seen by a discretisation: the deviatoric measure ρ = |τ_xx − τ_zz| (eq 50,
/// τ = σ F) of the two lowest unyielded points, extrapolated linearly to ρ = ρ_y. `None` if
/// no point yielded or fewer than two stayed elastic.
pub fn yield_height_estimate(points: &[PointRecord], yield_stress: f64) -> Option<f64> {
    if !points.iter().any(|p| p.plastic_multiplier > 0.0) {
        return None;
    }
    let mut elastic: Vec<&PointRecord> = points.iter().filter(|p| p.plastic_multiplier == 0.0).collect();
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
            .yield_stress
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

/// Run the column with any method.
pub fn solve_column(spec: &ColumnSpec, method: Method) -> Result<ColumnOutcome, InputError> {
    solve_column_observed(spec, method, &mut |_, _| {})
}

/// [`solve_column`], showing the solver to `observer` before the first and after every
/// converged load step.
pub fn solve_column_observed(
    spec: &ColumnSpec,
    method: Method,
    observer: &mut ColumnObserver<'_>,
) -> Result<ColumnOutcome, InputError> {
    match (method, spec.dimension) {
        (Method::MaterialPoint(basis), 3) => solve_mpm_3d(spec, basis, observer),
        (Method::FEM_HEX8, 3) => solve_fem_3d(spec, HexElement::Hex8, observer),
        (Method::FEM_HEX20, 3) => solve_fem_3d(spec, HexElement::Hex20, observer),
        (_, 3) => Err(InputError::new(
            "dimension",
            3,
            format!(
                "the 3D column is solved by {}, not {} (a 1D method)",
                METHODS_3D.map(|m| m.name()).join(", "),
                method.name()
            ),
        )),
        (Method::FEM_HEX8 | Method::FEM_HEX20, _) => Err(InputError::new(
            "dimension",
            spec.dimension,
            format!("{} solves the 3D column (dimension = 3) only", method.name()),
        )),
        _ => match_1d(spec, method, observer),
    }
}

fn match_1d(
    spec: &ColumnSpec,
    method: Method,
    observer: &mut ColumnObserver<'_>,
) -> Result<ColumnOutcome, InputError> {
    match method {
        Method::MaterialPoint(basis) => solve_mpm_observed(spec, basis, observer),
        Method::FEM_LINEAR => solve_fem_observed(spec, LineElement::Linear, observer),
        Method::FEM_QUADRATIC => solve_fem_observed(spec, LineElement::Quadratic, observer),
        _ => Err(method.unsupported("column", &METHODS)),
    }
}

/// Run the column with a material point method of basis `basis`.
pub fn solve_mpm(spec: &ColumnSpec, basis: Basis) -> Result<ColumnOutcome, InputError> {
    solve_mpm_observed(spec, basis, &mut |_, _| {})
}

fn solve_mpm_observed(
    spec: &ColumnSpec,
    basis: Basis,
    observer: &mut ColumnObserver<'_>,
) -> Result<ColumnOutcome, InputError> {
    let mut solver = spec.mpm_solver(basis)?;
    observer(0, ColumnState::Mpm(&solver));
    let (steps, failure) =
        steps_and_failure(solver.run_observed(&mut |s, r| observer(r.step, ColumnState::Mpm(s))));
    Ok(mpm_outcome(spec, &solver.points, 0, 1, steps, failure))
}

/// The outcome of a material point column whose axis is `axis` (1D: 0; the 3D prism: 2):
/// one [`PointRecord`] per point (σ_xx from the lateral axis `lateral`) and the top point's
/// displacement.
fn mpm_outcome<const D: usize>(
    spec: &ColumnSpec,
    pts: &MaterialPoints<D>,
    axis: usize,
    lateral: usize,
    steps: Vec<StepReport>,
    failure: Option<SolveError>,
) -> ColumnOutcome {
    let records: Vec<PointRecord> = (0..pts.len())
        .map(|p| {
            let st = &pts.state[p];
            let sigma = st.cauchy();
            PointRecord {
                z0: pts.position0[p][axis],
                z: pts.position[p][axis],
                volume0: pts.volume0[p],
                sigma_zz: sigma[(axis, axis)],
                sigma_xx: sigma[(lateral, lateral)],
                f_zz: st.f[(axis, axis)],
                plastic_multiplier: st.material.plastic_multiplier,
            }
        })
        .collect();
    let top = (0..pts.len())
        .max_by(|&a, &b| pts.position0[a][axis].total_cmp(&pts.position0[b][axis]))
        .map_or(f64::NAN, |p| pts.displacement(p)[axis]);
    ColumnOutcome::from_records(spec, records, top, steps, failure)
}

impl ColumnSpec {
    /// The FEM solver for this column: `elements` equal elements on [0, L0], base node fixed,
    /// gravity along −z, `gauss_points` (default: the element's) per element.
    pub fn fem_solver(&self, element: LineElement) -> Result<LineFem, InputError> {
        self.validate()?;
        let mesh = LineMesh::uniform(element, 0.0, self.length, self.elements)?;
        let model = self.model()?;
        let loads = LineLoads {
            gravity: -self.gravity(),
            nodal_forces: vec![],
        };
        let settings = LineFemSettings {
            gauss_points: self.gauss_points.unwrap_or(element.default_gauss_points()),
            newton: self.newton,
            load_steps: self.load_steps,
        };
        LineFem::try_new(mesh, self.density, model, vec![0], loads, settings)
    }
}

/// The 3D column by updated-Lagrangian FEM: a 1 × 1 × n prism of Hex8 (2×2×2 Gauss points)
/// or Hex20 (3×3×3) elements, `gauss_points` per axis when set, rollers on every lateral
/// node (uniaxial strain) and the base on rollers. Every Gauss point of one level carries
/// the value of the 1D element's Gauss point at that height (the strain is uniaxial), with
/// volumes summing to the 1D point's, so eq (46), weighted by initial volume, is the 1D
/// linear (Hex8) or quadratic (Hex20) FEM column's.
fn solve_fem_3d(
    spec: &ColumnSpec,
    element: HexElement,
    observer: &mut ColumnObserver<'_>,
) -> Result<ColumnOutcome, InputError> {
    spec.validate()?;
    let size = SVector::<f64, 3>::new(1.0, 1.0, spec.length);
    let mesh = HexMesh::cuboid(SVector::zeros(), size, [1, 1, spec.elements], element)?;
    let mut fixed: Vec<(usize, usize)> = (0..mesh.num_nodes()).flat_map(|n| [(n, 0), (n, 1)]).collect();
    fixed.extend(mesh.nodes_at(2, 0.0, 1e-12).into_iter().map(|n| (n, 2)));
    let top_node = mesh.nearest_node(size);
    let loads = SolidLoads {
        gravity: SVector::<f64, 3>::new(0.0, 0.0, -spec.gravity()),
        nodal_forces: vec![],
    };
    let settings = PlaneFemSettings {
        gauss_points: spec.gauss_points,
        newton: spec.newton,
        load_steps: spec.load_steps,
        linear_solver: Default::default(),
    };
    let mut fem = SolidFem::try_new(mesh, spec.density, spec.model()?, fixed, loads, settings)?;
    observer(0, ColumnState::Fem3(&fem));
    let (steps, failure) =
        steps_and_failure(fem.run_observed(&mut |s, r| observer(r.step, ColumnState::Fem3(s))));
    let g = &fem.gauss;
    let records = (0..g.len())
        .map(|p| {
            let st = &g.state[p];
            let sigma = st.cauchy();
            PointRecord {
                z0: g.position0[p][2],
                z: fem.gauss_point_position(p)[2],
                volume0: g.volume0[p],
                sigma_zz: sigma[(2, 2)],
                sigma_xx: sigma[(0, 0)],
                f_zz: st.f[(2, 2)],
                plastic_multiplier: st.material.plastic_multiplier,
            }
        })
        .collect();
    let top = fem.displacement(top_node)[2];
    Ok(ColumnOutcome::from_records(spec, records, top, steps, failure))
}

/// Run the column with updated-Lagrangian FEM. Records one [`PointRecord`] per Gauss point
/// (their initial volumes weight eq 46); the top displacement is that of the top node and the
/// base F that of the bottom-most Gauss point (eq 47), through the same
/// [`ColumnOutcome::from_records`] as the material point methods.
pub fn solve_fem(spec: &ColumnSpec, element: LineElement) -> Result<ColumnOutcome, InputError> {
    solve_fem_observed(spec, element, &mut |_, _| {})
}

/// [`solve_fem`] showing the solver to `observer` before the first and after every
/// converged load step.
pub fn solve_fem_observed(
    spec: &ColumnSpec,
    element: LineElement,
    observer: &mut ColumnObserver<'_>,
) -> Result<ColumnOutcome, InputError> {
    let mut solver = spec.fem_solver(element)?;
    observer(0, ColumnState::Fem(&solver));
    let (steps, failure) =
        steps_and_failure(solver.run_observed(&mut |s, r| observer(r.step, ColumnState::Fem(s))));
    let records = fem_records(&solver);
    let top = solver.displacement(solver.mesh.num_nodes() - 1);
    Ok(ColumnOutcome::from_records(spec, records, top, steps, failure))
}

/// Final values at every Gauss point.
pub fn fem_records(solver: &LineFem) -> Vec<PointRecord> {
    let g = &solver.gauss;
    (0..g.len())
        .map(|p| {
            let sigma = g.state[p].cauchy();
            PointRecord {
                z0: g.position0[p],
                z: solver.gauss_point_map(p).0,
                volume0: g.volume0[p],
                sigma_zz: sigma[(0, 0)],
                sigma_xx: sigma[(1, 1)],
                f_zz: g.state[p].f[(0, 0)],
                plastic_multiplier: g.state[p].material.plastic_multiplier,
            }
        })
        .collect()
}
