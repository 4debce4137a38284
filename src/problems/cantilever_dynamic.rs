//! The dynamic cantilever: the paper's beam (§5.3, [`crate::problems::cantilever`]) released
//! from rest under its end load applied suddenly at t = 0⁺ and held, solved by Newmark time
//! stepping ([`crate::solver::dynamics`]) with every plane material point family and Q8 FEM.
//!
//! There is no closed-form answer at finite rotation, so each analysis is measured against a
//! reference analysis of the same beam (Q8 Newmark on a finer mesh and a finer Δt, a study's
//! choice): the tip deflection history and the period of the motion. The time unit is the
//! Euler–Bernoulli first-mode period of the plane-strain beam,
//!
//! ```text
//! T₁ = 2π / ω₁,   ω₁ = (β₁L)² √(EI / (ρ A L⁴)),   β₁L = 1.8751,   EI = E d³ / (12 (1 − ν²)),
//! ```
//!
//! (per unit width, A = d), which fixes Δt = T₁ / steps_per_period; the beam's own period
//! differs from T₁ by its shear and finite-rotation effects, which is what the reference
//! measures. The energy measure is the conservation of E = K + U − W with W = Σ f · u the work
//! of the dead end load: the trapezoidal rule conserves it for a linear system and nearly so
//! for this one.

use crate::basis::method::Method;
use crate::fem::{ElementFamily, PlaneFem};
use crate::mpm::MpmSolver;
use crate::problems::bar::{period_of, strain_energy, total_energy};
use crate::problems::cantilever::CantileverSpec;
use crate::solver::dynamics::{LoadHistory, MassMatrix, Newmark};
use crate::solver::error::{require_count, require_positive, InputError, SolveError};
use crate::solver::load_stepping::{steps_and_failure, LoadStepping, StepReport};
use nalgebra::SVector;
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// β₁L of the clamped–free Euler–Bernoulli beam: the first root of 1 + cos x cosh x = 0.
pub const FIRST_MODE_ROOT: f64 = 1.875_104_068_711_961;

/// One dynamic cantilever analysis.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DynamicCantileverSpec {
    /// The beam, its load, grid, points and solver settings (`load_steps` is not used: the
    /// time steps replace it).
    pub beam: CantileverSpec,
    /// ρ (kg/m³).
    pub density: f64,
    /// Simulated time in units of T₁ (module docs).
    pub periods: f64,
    /// Time steps per T₁.
    pub steps_per_period: usize,
    pub beta: f64,
    pub gamma: f64,
    pub mass: MassMatrix,
    /// Generalised-α's spectral radius ρ∞ ([`crate::solver::dynamics::GeneralizedAlpha`]); `None`:
    /// Newmark with `beta`, `gamma`.
    pub rho_infinity: Option<f64>,
}

/// What one analysis measured.
#[derive(Debug, Clone, PartialEq)]
pub struct DynamicCantileverOutcome {
    pub steps: Vec<StepReport>,
    pub failure: Option<SolveError>,
    /// (t, vertical tip displacement) at t = 0 and after every step: the mean of the loaded
    /// points (material points) or the tip node (L, d/2) (Q8).
    pub tip: Vec<(f64, f64)>,
    /// (K + U, W) at t = 0 and after every step: kinetic plus strain energy, work of the load.
    pub energy: Vec<(f64, f64)>,
    pub points: usize,
}

impl DynamicCantileverSpec {
    pub fn validate(&self) -> Result<(), InputError> {
        self.beam.elastic_constants()?;
        require_positive("cantilever.density", self.density)?;
        require_positive("cantilever.periods", self.periods)?;
        require_count("cantilever.steps_per_period", self.steps_per_period, 1)?;
        // The time scales derived from the beam and ρ, before the Newmark settings see them.
        crate::solver::load_stepping::require_time_scales(
            ("cantilever.periods", self.periods),
            self.steps_per_period,
            self.period(),
            (
                "cantilever.density",
                self.density,
                "(from the beam's E, ν, depth and length and ρ)",
            ),
        )?;
        self.newmark().validate()?;
        self.stepped_beam().validate()
    }

    /// The beam with its load steps set to the time steps (the stepping and Newton settings
    /// are validated with them).
    fn stepped_beam(&self) -> CantileverSpec {
        CantileverSpec {
            load_steps: self.time_steps(),
            ..self.beam
        }
    }

    /// T₁ (module docs); NaN for a material without E or ν (validation refuses it).
    pub fn period(&self) -> f64 {
        let b = &self.beam;
        let (e, nu) = b.elastic_constants().unwrap_or((f64::NAN, f64::NAN));
        let ei = e * b.depth.powi(3) / (12.0 * (1.0 - nu.powi(2)));
        let omega = FIRST_MODE_ROOT.powi(2) * (ei / (self.density * b.depth * b.length.powi(4))).sqrt();
        2.0 * PI / omega
    }

    pub fn time_steps(&self) -> usize {
        (self.periods * self.steps_per_period as f64).round().max(1.0) as usize
    }

    pub fn duration(&self) -> f64 {
        self.periods * self.period()
    }

    fn newmark(&self) -> Newmark {
        Newmark {
            duration: self.duration(),
            beta: self.beta,
            gamma: self.gamma,
            mass: self.mass,
            load: LoadHistory::Sudden,
            rho_infinity: self.rho_infinity,
        }
    }

    /// The material point beam of `method` ([`CantileverSpec::mpm_solver_2d`]) at rest, and
    /// its two loaded points.
    pub fn mpm_solver(&self, method: Method) -> Result<(MpmSolver<2>, [usize; 2]), InputError> {
        self.validate()?;
        let basis = method
            .basis()
            .ok_or_else(|| method.unsupported("dynamic cantilever", &METHODS))?;
        self.stepped_beam()
            .mpm_solver_2d(basis, self.density, Some(self.newmark()))
    }

    /// The Q8 beam ([`crate::problems::cantilever::fem_q8`]) at rest, and its tip node.
    pub fn fem_solver(&self) -> Result<(PlaneFem, usize), InputError> {
        self.validate()?;
        let (mut fem, tip) = crate::problems::cantilever::fem_q8(&self.stepped_beam(), self.density)?;
        let rest = vec![SVector::<f64, 2>::zeros(); fem.mesh.num_nodes()];
        // a₀ = M⁻¹ f_ext(0⁺) is not zero under a suddenly applied load, but the load's
        // discontinuity is at t = 0⁺ itself: starting from a₀ = 0 is the trapezoidal rule's
        // usual treatment of a step load (the material point solvers do the same: their
        // points start with zero acceleration).
        fem.set_dynamics(self.newmark(), &rest, None)?;
        Ok((fem, tip))
    }
}

/// The methods that solve the dynamic cantilever.
pub const METHODS: [Method; Method::FAMILIES + 1] = crate::problems::cantilever::METHODS;

/// Solve one analysis.
pub fn solve(spec: &DynamicCantileverSpec, method: Method) -> Result<DynamicCantileverOutcome, InputError> {
    match method {
        Method::FEM_Q8 => {
            let (fem, tip) = spec.fem_solver()?;
            let load = spec.beam.load;
            Ok(run_recorded(
                fem,
                PlaneFem::time,
                |s| s.displacement(tip)[1],
                move |s| (fem_energy(s, spec.mass), -load * s.displacement(tip)[1]),
                0,
            ))
        }
        Method::MaterialPoint(_) => {
            let (solver, loaded) = spec.mpm_solver(method)?;
            let points = solver.points.len();
            let tip = move |s: &MpmSolver<2>| {
                0.5 * (s.points.displacement(loaded[0])[1] + s.points.displacement(loaded[1])[1])
            };
            let load = spec.beam.load;
            Ok(run_recorded(
                solver,
                MpmSolver::time,
                tip,
                // Each loaded point carries −P/2 along y.
                move |s| (total_energy(s), -load * tip(s)),
                points,
            ))
        }
        _ => Err(method.unsupported("dynamic cantilever", &METHODS)),
    }
}

fn run_recorded<S: LoadStepping>(
    mut solver: S,
    time: impl Fn(&S) -> f64,
    tip: impl Fn(&S) -> f64,
    energy: impl Fn(&S) -> (f64, f64),
    points: usize,
) -> DynamicCantileverOutcome {
    let mut history = vec![(0.0, tip(&solver))];
    let mut energies = vec![energy(&solver)];
    let result = solver.run_observed(&mut |s, _| {
        history.push((time(s), tip(s)));
        energies.push(energy(s));
    });
    let (steps, failure) = steps_and_failure(result);
    DynamicCantileverOutcome {
        steps,
        failure,
        tip: history,
        energy: energies,
        points,
    }
}

/// K + U of the Q8 beam: ½ Σ_q m_q v_q² with v_q = Σ_a N_a(ξ_q) v_a (the consistent kinetic
/// energy ½ vᵀ M v, exact for the quadrature that builds M; with the lumped mass ½ Σ_a m_a
/// v_a²) plus Σ_q ½ τ : ε V_q0.
pub fn fem_energy(fem: &PlaneFem, mass: MassMatrix) -> f64 {
    let g = &fem.gauss;
    let v = fem.velocity();
    let k = fem.mesh.element.nodes_per_element();
    let mut lumped = vec![0.0; v.len() / 2];
    let mut energy = 0.0;
    for q in 0..g.len() {
        let (n, _) = fem.mesh.element.shape(&g.xi[q]);
        let nodes = fem.mesh.element_nodes(g.element[q]);
        let vq: SVector<f64, 2> = (0..k)
            .map(|a| SVector::<f64, 2>::new(v[2 * nodes[a]], v[2 * nodes[a] + 1]) * n[a])
            .sum();
        match mass {
            MassMatrix::Consistent => energy += 0.5 * g.mass[q] * vq.norm_squared(),
            MassMatrix::Lumped => (0..k).for_each(|a| lumped[nodes[a]] += n[a] * g.mass[q]),
        }
        energy += strain_energy(&g.state[q], g.volume0[q]);
    }
    energy
        + lumped
            .iter()
            .enumerate()
            .map(|(a, m)| 0.5 * m * (v[2 * a].powi(2) + v[2 * a + 1].powi(2)))
            .sum::<f64>()
}

impl DynamicCantileverOutcome {
    /// The largest downward tip deflection, −min_t v (positive).
    pub fn peak(&self) -> f64 {
        -self.tip.iter().map(|t| t.1).fold(0.0, f64::min)
    }

    /// The period of the tip's oscillation: the mean spacing of its downward crossings of half
    /// the peak deflection (the motion swings between rest and about twice the static
    /// deflection, so every cycle crosses that level twice); `None` below two crossings.
    pub fn period(&self) -> Option<f64> {
        let level = -0.5 * self.peak();
        let shifted: Vec<(f64, f64)> = self.tip.iter().map(|&(t, v)| (t, v - level)).collect();
        period_of(&shifted)
    }

    /// max_t |K + U − W| / max_t W: the energy conservation error relative to the work the
    /// load has done (E(0) = 0: the beam starts at rest and unstrained).
    pub fn energy_drift(&self) -> f64 {
        let scale = self.energy.iter().map(|e| e.1).fold(0.0, f64::max);
        self.energy
            .iter()
            .map(|(ku, w)| (ku - w).abs())
            .fold(0.0, f64::max)
            / scale
    }

    /// max_n |v(t_n) − v_ref(t_n)| / max_t |v_ref| over this analysis' steps, `reference`
    /// sampled at the same instants: its step count must be a whole multiple of this one's
    /// (`None` otherwise, or if either stopped early).
    pub fn tip_error(&self, reference: &DynamicCantileverOutcome) -> Option<f64> {
        let (n, m) = (self.tip.len() - 1, reference.tip.len() - 1);
        if n == 0 || m % n != 0 || self.failure.is_some() || reference.failure.is_some() {
            return None;
        }
        let k = m / n;
        // A step cut back still ends at its nominal time (one history entry per nominal
        // step), so the instants match; a mismatch means two different durations.
        let end = self.tip[n].0.abs().max(f64::MIN_POSITIVE);
        let mut err: f64 = 0.0;
        for i in 0..=n {
            let ((t, v), (tr, vr)) = (self.tip[i], reference.tip[i * k]);
            if (t - tr).abs() > 1e-9 * end {
                return None;
            }
            err = err.max((v - vr).abs());
        }
        Some(err / reference.peak())
    }
}
