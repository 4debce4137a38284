//! The vibrating bar (Sulsky, Chen & Schreyer 1994 §5; Bardenhagen & Kober 2004 §5.1): a
//! fixed–free elastic bar of length L, set moving in its first mode,
//!
//! ```text
//! v(X, 0) = v₀ sin(πX / 2L),   u(X, t) = (v₀/ω) sin(πX / 2L) sin(ωt),   ω = πc / 2L,
//! ```
//!
//! c = √(M/ρ) with the uniaxial-strain modulus M = λ + 2μ (E at ν = 0, the studies'), period
//! T = 4L/c. It is solved by
//! Newmark time stepping ([`crate::solver::dynamics`]) with the material point methods in 1D and the
//! updated-Lagrangian line elements as comparators. The
//! measures are the top point's displacement history, the period measured from its zero
//! crossings, the total energy (kinetic + strain; no external work) and the displacement error
//! at the end against the analytical field. At small v₀/c the finite-deformation solution is
//! the linear one to O(v₀/c) (the strain amplitude).

use crate::basis::method::Method;
use crate::basis::DomainUpdate;
use crate::fem::{LineElement, LineFem, LineFemSettings, LineLoads, LineMesh};
use crate::material::constitutive::{lame, ConstitutiveModel, Material, LINEAR_ELASTIC};
use crate::material::kinematics::{log_strain, PointState};
use crate::mesh::grid::Grid;
use crate::mpm::particles::MaterialPoints;
use crate::mpm::{Loads, MpmSettings, MpmSolver};
use crate::solver::dynamics::{LoadHistory, MassMatrix, Newmark};
use crate::solver::error::{require_count, require_positive, InputError, SolveError};
use crate::solver::load_stepping::{steps_and_failure, LoadStepping, StepReport};
use crate::solver::newton::NewtonSettings;
use nalgebra::SVector;
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// One vibrating bar analysis.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BarSpec {
    pub length: f64,
    /// Hencky elasticity (`linear-elastic`): the closed form and the strain energy are its.
    /// The bar is in uniaxial strain, so its modulus is M = λ + 2μ, E at the study's ν = 0.
    pub material: Material,
    pub density: f64,
    /// Peak initial velocity v₀ (at the free end).
    pub velocity: f64,
    pub elements: usize,
    pub points_per_cell: usize,
    /// Time steps per period T = 4L/c.
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
}

impl Default for BarSpec {
    /// A unit bar (E = 100, ρ = 1: c = 10, T = 0.4) at strain amplitude v₀/c = 1e-4, 16
    /// elements of 2 points, 64 steps per period, one period, trapezoidal rule, consistent mass.
    fn default() -> Self {
        BarSpec {
            length: 1.0,
            material: Material::linear_elastic(100.0, 0.0),
            density: 1.0,
            velocity: 1e-3,
            elements: 16,
            points_per_cell: 2,
            steps_per_period: 64,
            periods: 1.0,
            beta: 0.25,
            gamma: 0.5,
            mass: MassMatrix::Consistent,
            newton: NewtonSettings::default(),
            rho_infinity: None,
        }
    }
}

/// What one analysis measured.
#[derive(Debug, Clone, PartialEq)]
pub struct BarOutcome {
    pub steps: Vec<StepReport>,
    pub failure: Option<SolveError>,
    /// (t, u of the free-end point) at t = 0 and after every step.
    pub top_history: Vec<(f64, f64)>,
    /// Total energy (kinetic + strain) at t = 0 and after every step.
    pub energy: Vec<f64>,
    /// The period from the top point's downward zero crossings of u (linear interpolation
    /// between steps); `None` if fewer than two were seen.
    pub measured_period: Option<f64>,
    /// (X_p, u_p, V_p0) of every point at the end.
    pub points: Vec<[f64; 3]>,
    /// Line elements only: the end displacement field, to measure other analyses against.
    pub field: Option<LineField>,
}

/// The displacement field of a line-element analysis: its element and (X, u) of every node of
/// the reference mesh.
#[derive(Debug, Clone, PartialEq)]
pub struct LineField {
    pub element: LineElement,
    pub nodes: Vec<(f64, f64)>,
}

impl LineField {
    /// u(X) by the element's shape functions, X clamped into the mesh (the elements are straight
    /// with their middle node centred, so ξ is affine in X).
    pub fn at(&self, x: f64) -> f64 {
        let per = self.element.nodes_per_element() - 1;
        let elements = (self.nodes.len() - 1) / per;
        let vertex = |e: usize| self.nodes[e * per].0;
        // The last element whose first vertex is at or before x.
        let e = (0..elements)
            .collect::<Vec<_>>()
            .partition_point(|&e| vertex(e) <= x)
            .saturating_sub(1);
        let (a, b) = (vertex(e), vertex(e + 1));
        let xi = (2.0 * (x - a) / (b - a) - 1.0).clamp(-1.0, 1.0);
        let (n, _) = self.element.shape(xi);
        (0..=per).map(|i| n[i] * self.nodes[e * per + i].1).sum()
    }
}

impl BarSpec {
    pub fn validate(&self) -> Result<(), InputError> {
        require_positive("bar.length", self.length)?;
        let hencky = "the bar's closed form (uniaxial strain, modulus λ + 2μ) and strain energy are Hencky elasticity's";
        self.material.require_model(&LINEAR_ELASTIC, hencky)?;
        self.model()?;
        require_positive("bar.density", self.density)?;
        crate::solver::error::require_finite("bar.velocity", self.velocity)?;
        require_count("bar.elements", self.elements, 1)?;
        require_count("bar.points_per_cell", self.points_per_cell, 1)?;
        require_count("bar.steps_per_period", self.steps_per_period, 1)?;
        require_positive("bar.periods", self.periods)?;
        // The closed form's scales, derived from L, E and ρ.
        crate::solver::load_stepping::require_time_scales(
            ("bar.periods", self.periods),
            self.steps_per_period,
            self.period(),
            ("bar.length", self.length, "(T = 4L/c)"),
        )?;
        crate::solver::error::require_finite("bar.velocity", self.velocity / self.omega())?;
        self.newmark().validate()
    }

    /// The constitutive model, built from [`Self::material`].
    pub fn model(&self) -> Result<Box<dyn ConstitutiveModel>, InputError> {
        self.material.build()
    }

    /// The bar's modulus M = λ + 2μ (uniaxial strain; E when ν = 0), NaN for a material
    /// without E or ν (validation refuses it).
    pub fn modulus(&self) -> f64 {
        let get = |k| self.material.get(k).unwrap_or(f64::NAN);
        let (lambda, mu) = lame(get("young_modulus"), get("poisson_ratio"));
        lambda + 2.0 * mu
    }

    /// Wave speed c = √(M/ρ).
    pub fn wave_speed(&self) -> f64 {
        (self.modulus() / self.density).sqrt()
    }

    /// T = 4L/c.
    pub fn period(&self) -> f64 {
        4.0 * self.length / self.wave_speed()
    }

    /// ω = 2π / T.
    pub fn omega(&self) -> f64 {
        2.0 * PI / self.period()
    }

    /// The analytical displacement u(X, t).
    pub fn exact_displacement(&self, x: f64, t: f64) -> f64 {
        self.velocity / self.omega() * (PI * x / (2.0 * self.length)).sin() * (self.omega() * t).sin()
    }

    /// Total time steps.
    pub fn time_steps(&self) -> usize {
        (self.periods * self.steps_per_period as f64).round().max(1.0) as usize
    }

    /// The simulated time, `periods` × T (the end of the last step, however the step count
    /// was rounded).
    pub fn duration(&self) -> f64 {
        self.periods * self.period()
    }

    fn newmark(&self) -> Newmark {
        Newmark {
            duration: self.duration(),
            beta: self.beta,
            gamma: self.gamma,
            mass: self.mass,
            load: LoadHistory::None,
            rho_infinity: self.rho_infinity,
        }
    }

    /// The solver: grid [0, L + k h] (k ≥ 1 cells beyond the free end, room for its domain and
    /// its motion), node 0 fixed, points with v_p = v₀ sin(πX_p / 2L).
    pub fn mpm_solver(&self, method: Method) -> Result<MpmSolver<1>, InputError> {
        self.mpm_solver_in::<1>(method)
    }

    /// The bar in D = 1, 2 or 3 dimensions: in 2D and 3D a prism one cell of side h across
    /// (h = L / elements), `points_per_cell` points per cell along every axis, the fixed end's
    /// nodes held along x and rollers on the lateral faces. With ν = 0 the prism moves as the
    /// 1D bar (a test compares them).
    pub fn mpm_solver_in<const D: usize>(&self, method: Method) -> Result<MpmSolver<D>, InputError> {
        self.validate()?;
        let basis = method
            .basis()
            .ok_or_else(|| method.unsupported("bar", &Method::MATERIAL_POINT))?;
        let h = self.length / self.elements as f64;
        // Room beyond the free end for its motion: twice the linear amplitude v₀/ω (a large
        // amplitude's exceeds it a little), at least one cell (the free end's domain); the
        // small-amplitude bars keep exactly one, as they always had.
        let room = ((2.0 * self.velocity.abs() / self.omega() + 0.5 * h) / h)
            .ceil()
            .max(1.0) as usize;
        let cells = std::array::from_fn(|a| if a == 0 { self.elements + room } else { 1 });
        let grid = Grid::try_new([0.0; D], [h; D], cells)?;
        let upper = std::array::from_fn(|a| if a == 0 { self.length } else { h });
        let mut points =
            MaterialPoints::fill_box(&grid, [0.0; D], upper, [self.points_per_cell; D], self.density)?;
        for p in 0..points.len() {
            let x = points.position0[p][0];
            points.velocity[p][0] = self.velocity * (PI * x / (2.0 * self.length)).sin();
        }
        let mut fixed: Vec<(usize, usize)> =
            grid.nodes_on_plane(0, 0.0).into_iter().map(|n| (n, 0)).collect();
        for a in 1..D {
            for value in [0.0, h] {
                fixed.extend(grid.nodes_on_plane(a, value).into_iter().map(|n| (n, a)));
            }
        }
        let settings = MpmSettings {
            basis,
            domain_update: DomainUpdate::Stretch,
            newton: self.newton,
            load_steps: self.time_steps(),
            weak_node_tolerance: 0.0,
            weak_node_treatment: Default::default(),
            volume_update: Default::default(),
            linear_solver: Default::default(),
            ghost: Default::default(),
            dynamics: Some(self.newmark()),
            f_bar: false,
        };
        let loads = Loads {
            gravity: SVector::zeros(),
            point_loads: vec![],
        };
        let model = self.model()?;
        MpmSolver::try_new(grid, points, model, fixed, loads, settings)
    }
}

/// Kinetic plus strain energy of the points: Σ ½ m_p v_p² + Σ ½ τ_p : ε_p v_p0 (Hencky: the
/// stored energy per reference volume is ½ τ : ε with ε the logarithmic strain).
pub fn total_energy<const D: usize>(solver: &MpmSolver<D>) -> f64 {
    let p = &solver.points;
    (0..p.len())
        .map(|i| 0.5 * p.mass[i] * p.velocity[i].norm_squared() + strain_energy(&p.state[i], p.volume0[i]))
        .sum()
}

/// ½ τ : ε v₀ of one integration point (Hencky, ε the logarithmic strain of its F).
pub(crate) fn strain_energy(s: &PointState, volume0: f64) -> f64 {
    let eps = log_strain(&(s.f * s.f.transpose())).unwrap_or_else(nalgebra::Matrix3::zeros);
    0.5 * s.tau.component_mul(&eps).sum() * volume0
}

/// Run `solver` to the end, recording the free end's displacement `top` and the energy
/// `energy` at t = 0 and after every step, and finish the outcome with the final
/// (X, u, v₀) of every integration point.
fn run_recorded<S: LoadStepping>(
    mut solver: S,
    time: impl Fn(&S) -> f64,
    top: impl Fn(&S) -> f64,
    energy: impl Fn(&S) -> f64,
    points: impl FnOnce(&S) -> Vec<[f64; 3]>,
) -> BarOutcome {
    let mut top_history = vec![(0.0, top(&solver))];
    let mut energies = vec![energy(&solver)];
    let result = solver.run_observed(&mut |s, _| {
        top_history.push((time(s), top(s)));
        energies.push(energy(s));
    });
    let (steps, failure) = steps_and_failure(result);
    BarOutcome {
        steps,
        failure,
        measured_period: period_of(&top_history),
        top_history,
        energy: energies,
        points: points(&solver),
        field: None,
    }
}

/// Solve one bar analysis: material point families and line elements (Line2, Line3).
pub fn solve(spec: &BarSpec, method: Method) -> Result<BarOutcome, InputError> {
    match method {
        Method::FEM_LINEAR => solve_fem(spec, LineElement::Linear),
        Method::FEM_QUADRATIC => solve_fem(spec, LineElement::Quadratic),
        _ => solve_mpm(spec, method),
    }
}

/// The bar by updated-Lagrangian line elements: node 0 fixed, nodal velocities v₀ sin(πX/2L),
/// `points_per_cell` Gauss points per element (the measures are taken at them).
pub fn fem_solver(spec: &BarSpec, element: LineElement) -> Result<LineFem, InputError> {
    spec.validate()?;
    let mesh = LineMesh::uniform(element, 0.0, spec.length, spec.elements)?;
    let settings = LineFemSettings {
        gauss_points: spec.points_per_cell,
        newton: spec.newton,
        load_steps: spec.time_steps(),
    };
    let loads = LineLoads {
        gravity: 0.0,
        nodal_forces: vec![],
    };
    let model = spec.model()?;
    let velocity: Vec<f64> = mesh
        .nodes
        .iter()
        .map(|&x| spec.velocity * (PI * x / (2.0 * spec.length)).sin())
        .collect();
    let mut fem = LineFem::try_new(mesh, spec.density, model, vec![0], loads, settings)?;
    fem.set_dynamics(spec.newmark(), velocity)?;
    Ok(fem)
}

/// Kinetic plus strain energy of a line-element bar: ½ Σ_q m_q (Σ_a N_a(ξ_q) v_a)² (the
/// consistent kinetic energy; with the lumped mass ½ Σ_a m_a v_a²) + Σ_q ½ τ ε v_q0.
pub fn fem_energy(fem: &LineFem, mass: MassMatrix) -> f64 {
    let g = &fem.gauss;
    let v = fem.velocity();
    let k = fem.mesh.element.nodes_per_element();
    let mut lumped = vec![0.0; v.len()];
    let mut energy = 0.0;
    for q in 0..g.len() {
        let (n, _) = fem.mesh.element.shape(g.xi[q]);
        let first = fem.mesh.first_node(g.element[q]);
        let vq: f64 = (0..k).map(|a| n[a] * v[first + a]).sum();
        match mass {
            MassMatrix::Consistent => energy += 0.5 * g.mass[q] * vq * vq,
            MassMatrix::Lumped => (0..k).for_each(|a| lumped[first + a] += n[a] * g.mass[q]),
        }
        energy += strain_energy(&g.state[q], g.volume0[q]);
    }
    energy + lumped.iter().zip(v).map(|(m, v)| 0.5 * m * v * v).sum::<f64>()
}

fn solve_fem(spec: &BarSpec, element: LineElement) -> Result<BarOutcome, InputError> {
    let fem = fem_solver(spec, element)?;
    let top = fem.mesh.num_nodes() - 1;
    let reference_nodes = fem.mesh0.nodes.clone();
    let mut field = None;
    let outcome = run_recorded(
        fem,
        LineFem::time,
        |s| s.displacement(top),
        |s| fem_energy(s, spec.mass),
        |s| {
            field = Some(LineField {
                element,
                nodes: reference_nodes
                    .iter()
                    .enumerate()
                    .map(|(a, &x)| (x, s.displacement(a)))
                    .collect(),
            });
            (0..s.gauss.len())
                .map(|q| {
                    let x0 = s.gauss.position0[q];
                    [x0, s.gauss_point_map(q).0 - x0, s.gauss.volume0[q]]
                })
                .collect()
        },
    );
    Ok(BarOutcome { field, ..outcome })
}

fn solve_mpm(spec: &BarSpec, method: Method) -> Result<BarOutcome, InputError> {
    solve_mpm_in::<1>(spec, method)
}

/// The bar as a prism in `dimension` = 2 or 3 ([`BarSpec::mpm_solver_in`]) by a material point
/// method; the measures are the 1D bar's, taken along x.
pub fn solve_prism(spec: &BarSpec, method: Method, dimension: usize) -> Result<BarOutcome, InputError> {
    match dimension {
        2 => solve_mpm_in::<2>(spec, method),
        3 => solve_mpm_in::<3>(spec, method),
        _ => Err(InputError::new(
            "dimension",
            dimension,
            "must be 2 or 3 for the prism",
        )),
    }
}

fn solve_mpm_in<const D: usize>(spec: &BarSpec, method: Method) -> Result<BarOutcome, InputError> {
    let solver = spec.mpm_solver_in::<D>(method)?;
    let p0 = &solver.points.position0;
    let top = (0..p0.len())
        .max_by(|&a, &b| p0[a][0].total_cmp(&p0[b][0]))
        .expect("points");
    let u = |s: &MpmSolver<D>, i: usize| s.points.position[i][0] - s.points.position0[i][0];
    Ok(run_recorded(
        solver,
        MpmSolver::time,
        |s| u(s, top),
        total_energy,
        |s| {
            (0..s.points.len())
                .map(|i| [s.points.position0[i][0], u(s, i), s.points.volume0[i]])
                .collect()
        },
    ))
}

/// The mean spacing of the downward zero crossings of u(t) (u from positive to non-positive),
/// each located by linear interpolation between its two samples.
pub fn period_of(history: &[(f64, f64)]) -> Option<f64> {
    let crossings: Vec<f64> = history
        .windows(2)
        .filter(|w| w[0].1 > 0.0 && w[1].1 <= 0.0)
        .map(|w| w[0].0 + (w[1].0 - w[0].0) * w[0].1 / (w[0].1 - w[1].1))
        .collect();
    (crossings.len() >= 2)
        .then(|| (crossings[crossings.len() - 1] - crossings[0]) / (crossings.len() - 1) as f64)
}

impl BarOutcome {
    /// ‖u_h − u‖ / ‖u‖ over the points at time `t` (volume-weighted L2, the discrete form of
    /// eq (46) for displacements).
    pub fn displacement_error(&self, spec: &BarSpec, t: f64) -> f64 {
        let (mut num, mut den) = (0.0, 0.0);
        let amplitude = spec.velocity / spec.omega();
        for [x, u, v] in &self.points {
            let e = spec.exact_displacement(*x, t);
            num += v * (u - e).powi(2);
            den += v * (amplitude * (PI * x / (2.0 * spec.length)).sin()).powi(2);
        }
        (num / den).sqrt()
    }

    /// ‖u_h − u_ref‖ / ‖U sin(πX/2L)‖ over the points at the end, against a line-element
    /// `reference` analysis of the same duration (its field at each point's X), U the largest
    /// free-end displacement of the reference: the discrete form of eq (46) where no closed form
    /// exists (a large amplitude). `None` if the reference is not a line-element analysis.
    pub fn displacement_error_against(&self, spec: &BarSpec, reference: &BarOutcome) -> Option<f64> {
        let field = reference.field.as_ref()?;
        let amplitude = reference
            .top_history
            .iter()
            .map(|h| h.1.abs())
            .fold(0.0, f64::max);
        let (mut num, mut den) = (0.0, 0.0);
        for [x, u, v] in &self.points {
            num += v * (u - field.at(*x)).powi(2);
            den += v * (amplitude * (PI * x / (2.0 * spec.length)).sin()).powi(2);
        }
        Some((num / den).sqrt())
    }

    /// max_t |E(t) − E(0)| / E(0).
    pub fn energy_drift(&self) -> f64 {
        let e0 = self.energy[0];
        self.energy.iter().map(|e| (e - e0).abs()).fold(0.0, f64::max) / e0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A line-element field reads back what its shape functions hold: Line3 reproduces a
    /// quadratic and Line2 a linear field exactly anywhere on the mesh (clamped outside it);
    /// a wrong element (Line2 reading Line3 nodes) does not.
    #[test]
    fn line_field_interpolates_with_the_element_shape_functions() {
        let field = |element: LineElement, f: fn(f64) -> f64| {
            let mesh = LineMesh::uniform(element, 0.0, 2.0, 5).unwrap();
            LineField {
                element,
                nodes: mesh.nodes.iter().map(|&x| (x, f(x))).collect(),
            }
        };
        let quad = |x: f64| 0.3 - 0.7 * x + 1.3 * x * x;
        let line3 = field(LineElement::Quadratic, quad);
        let line2 = field(LineElement::Linear, |x| 0.3 - 0.7 * x);
        for i in 0..=97 {
            let x = 2.0 * i as f64 / 97.0;
            assert!((line3.at(x) - quad(x)).abs() < 1e-13, "Line3 at {x}");
            assert!((line2.at(x) - (0.3 - 0.7 * x)).abs() < 1e-13, "Line2 at {x}");
        }
        assert!(
            (line3.at(2.5) - quad(2.0)).abs() < 1e-13,
            "clamped beyond the end"
        );
        let wrong = LineField {
            element: LineElement::Linear,
            nodes: line3.nodes.clone(),
        };
        assert!(
            (wrong.at(0.37) - quad(0.37)).abs() > 1e-3,
            "a wrong element reads the same"
        );
    }
}
