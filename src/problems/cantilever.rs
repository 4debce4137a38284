//! Cantilever under a dead end load (§5.3, Figures 19–21).
//!
//! A beam `length × depth` (plane strain by default) sits with its left end on the grid line
//! x = 0 and its neutral axis on a grid line. Supports as in the paper: every grid node on the
//! left boundary x = 0 is on a roller (u_x = 0) and the node on the neutral axis is also fixed
//! vertically. The end load P (vertical, fixed direction) is split equally between the two
//! end-most material points just above and just below the neutral axis, and applied over the
//! load steps. The background grid extends below the beam far enough for the deflected shape.

use crate::basis::Basis;
use crate::constitutive::LinearElastic;
use crate::error::{require_count, require_positive, InputError, SolveError};
use crate::fem::{PlaneFem, PlaneFemSettings, PlaneLoads, PlaneMesh, QuadElement};
use crate::ghost::{GhostFaces, GhostSettings};
use crate::grid::Grid;
use crate::linear::LinearSolver;
use crate::load_stepping::{LoadStepping, StepReport};
use crate::method::Method;
use crate::mpm::{DomainUpdate, Loads, MpmSettings, MpmSolver, VolumeUpdate, WeakNodeTreatment};
use crate::newton::NewtonSettings;
use crate::particles::MaterialPoints;
use nalgebra::SVector;
use serde::{Deserialize, Serialize};

/// Parameters of the cantilever (defaults: the paper's 20×2 elements of 0.5 m, 3×3 points).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CantileverSpec {
    /// Beam length L (m).
    pub length: f64,
    /// Beam depth (m); unit width.
    pub depth: f64,
    /// Young's modulus E (Pa).
    pub young_modulus: f64,
    pub poisson_ratio: f64,
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
    /// Ghost penalty of nearly empty cells ([`crate::ghost`]).
    #[serde(default)]
    pub ghost: GhostSettings,
}

impl Default for CantileverSpec {
    fn default() -> Self {
        Self {
            length: 10.0,
            depth: 1.0,
            young_modulus: 12e6,
            poisson_ratio: 0.2,
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
            },
        }
    }
}

impl CantileverSpec {
    pub fn validate(&self) -> Result<(), InputError> {
        self.ghost.validate()?;
        require_positive("length", self.length)?;
        require_positive("depth", self.depth)?;
        require_positive("element_size", self.element_size)?;
        require_positive("grid_below", self.grid_below)?;
        require_positive("grid_margin", self.grid_margin)?;
        crate::error::require_finite("load", self.load)?;
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
        LinearElastic::try_new(self.young_modulus, self.poisson_ratio)?;
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
        if (self.depth / self.element_size).round() as usize % 2 != 0 {
            return Err(InputError::new(
                "depth",
                self.depth,
                "must be an even number of elements so that the neutral axis is a grid line",
            ));
        }
        Ok(())
    }

    /// The solver, and the indices of the two loaded points (below, above the neutral axis).
    pub fn mpm_solver(&self) -> Result<(MpmSolver<2>, [usize; 2]), InputError> {
        self.validate()?;
        let h = self.element_size;
        let x_cells = ((self.length + self.grid_margin) / h).round() as usize;
        let y_cells = ((self.grid_below + self.depth + self.grid_margin) / h).round() as usize;
        let grid = Grid::try_new([0.0, -self.grid_below], [h, h], [x_cells, y_cells])?;
        let ppc = self.points_per_cell;
        let points = MaterialPoints::fill_box(&grid, [0.0, 0.0], [self.length, self.depth], [ppc, ppc], 1.0)?;
        let axis_y = 0.5 * self.depth;
        let mut fixed: Vec<(usize, usize)> =
            grid.nodes_on_plane(0, 0.0).into_iter().map(|n| (n, 0)).collect();
        let pin = grid
            .nodes_on_plane(0, 0.0)
            .into_iter()
            .find(|&n| (grid.node_position(n)[1] - axis_y).abs() < 1e-9 * h)
            .expect("neutral axis node");
        fixed.push((pin, 1));
        // End-most column of points; the two nearest the neutral axis.
        let x_end = points.position0.iter().map(|x| x[0]).fold(f64::MIN, f64::max);
        let mut end: Vec<usize> = (0..points.len())
            .filter(|&p| (points.position0[p][0] - x_end).abs() < 1e-9)
            .collect();
        end.sort_by(|&a, &b| {
            (points.position0[a][1] - axis_y)
                .abs()
                .total_cmp(&(points.position0[b][1] - axis_y).abs())
        });
        let mut loaded = [end[0], end[1]];
        loaded.sort_by(|&a, &b| points.position0[a][1].total_cmp(&points.position0[b][1]));
        let force = SVector::<f64, 2>::new(0.0, -0.5 * self.load);
        let loads = Loads {
            gravity: SVector::<f64, 2>::zeros(),
            point_loads: vec![(loaded[0], force), (loaded[1], force)],
        };
        let settings = MpmSettings {
            basis: Basis::Gimp,
            domain_update: self.domain_update,
            newton: self.newton,
            load_steps: self.load_steps,
            weak_node_tolerance: self.weak_node_tolerance,
            weak_node_treatment: self.weak_node_treatment,
            volume_update: self.volume_update,
            linear_solver: Default::default(),
            ghost: self.ghost,
        };
        let model = Box::new(LinearElastic::try_new(self.young_modulus, self.poisson_ratio)?);
        Ok((
            MpmSolver::try_new(grid, points, model, fixed, loads, settings)?,
            loaded,
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

/// Material point domains at one instant, for Figures 19–20.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DomainSnapshot {
    pub step: usize,
    /// (x, y, half-length x, half-length y) per point.
    pub domains: Vec<[f64; 4]>,
}

/// Outcome of a cantilever analysis.
#[derive(Debug, Clone, PartialEq)]
pub struct CantileverOutcome {
    pub steps: Vec<StepReport>,
    pub end: Vec<EndDisplacement>,
    pub failure: Option<SolveError>,
    /// Snapshots at the start and after every `snapshot_every` steps (and the last).
    pub snapshots: Vec<DomainSnapshot>,
    /// Smallest domain half-length (either axis) over all points after each step.
    pub min_half_length: Vec<f64>,
    pub loaded_points: [usize; 2],
}

fn snapshot(solver: &MpmSolver<2>, step: usize) -> DomainSnapshot {
    let p = &solver.points;
    DomainSnapshot {
        step,
        domains: (0..p.len())
            .map(|i| {
                [
                    p.position[i][0],
                    p.position[i][1],
                    p.half_length[i][0],
                    p.half_length[i][1],
                ]
            })
            .collect(),
    }
}

/// Run the cantilever with iGIMP, recording the end displacement after every step.
pub fn solve_mpm(spec: &CantileverSpec, snapshot_every: usize) -> Result<CantileverOutcome, InputError> {
    let (mut solver, loaded) = spec.mpm_solver()?;
    let mut out = CantileverOutcome {
        steps: vec![],
        end: vec![],
        failure: None,
        snapshots: vec![snapshot(&solver, 0)],
        min_half_length: vec![],
        loaded_points: loaded,
    };
    while solver.steps_done() < solver.load_steps() {
        match solver.step() {
            Ok(r) => {
                let d = (solver.points.displacement(loaded[0]) + solver.points.displacement(loaded[1])) * 0.5;
                out.end.push(EndDisplacement {
                    step: r.step,
                    load: spec.load * r.load_factor,
                    u_over_l: d[0] / spec.length,
                    v_over_l: d[1] / spec.length,
                });
                out.min_half_length.push(
                    solver
                        .points
                        .half_length
                        .iter()
                        .map(|h| h[0].min(h[1]))
                        .fold(f64::INFINITY, f64::min),
                );
                if snapshot_every > 0 && (r.step % snapshot_every == 0 || r.step == solver.load_steps()) {
                    out.snapshots.push(snapshot(&solver, r.step));
                }
                out.steps.push(r);
            }
            Err(e) => {
                out.snapshots.push(snapshot(&solver, solver.steps_done()));
                out.failure = Some(e);
                break;
            }
        }
    }
    Ok(out)
}

/// What the Q8 comparator reports: the steps and the end displacement after each.
#[derive(Debug, Clone, PartialEq)]
pub struct FemOutcome {
    pub steps: Vec<StepReport>,
    pub end: Vec<EndDisplacement>,
    pub failure: Option<SolveError>,
}

/// Updated-Lagrangian Q8 FEM (3×3 Gauss points, LDLᵀ) on the same elements (h, so 20×2 for
/// the paper's beam), the same supports (left edge on rollers, its neutral-axis node pinned)
/// and the end load as a dead nodal force on the neutral-axis end node, as in the paper
/// (Figure 21). The end displacement is that node's.
pub fn solve_fem_q8(spec: &CantileverSpec) -> Result<FemOutcome, InputError> {
    let h = spec.element_size;
    let cells = (
        (spec.length / h).round() as usize,
        (spec.depth / h).round() as usize,
    );
    let mesh = PlaneMesh::rectangle(
        SVector::<f64, 2>::zeros(),
        SVector::<f64, 2>::new(spec.length, spec.depth),
        cells,
        QuadElement::Q8,
    )?;
    let axis = 0.5 * spec.depth;
    let mut fixed: Vec<(usize, usize)> = mesh
        .nodes_at(0, 0.0, 1e-9 * h)
        .into_iter()
        .map(|n| (n, 0))
        .collect();
    fixed.push((mesh.nearest_node(SVector::<f64, 2>::new(0.0, axis)), 1));
    let tip = mesh.nearest_node(SVector::<f64, 2>::new(spec.length, axis));
    let loads = PlaneLoads {
        gravity: SVector::<f64, 2>::zeros(),
        nodal_forces: vec![(tip, SVector::<f64, 2>::new(0.0, -spec.load))],
    };
    let settings = PlaneFemSettings {
        gauss_points: Some(3),
        newton: spec.newton,
        load_steps: spec.load_steps,
        linear_solver: LinearSolver::Ldlt,
    };
    let model = Box::new(LinearElastic::try_new(spec.young_modulus, spec.poisson_ratio)?);
    let mut fem = PlaneFem::try_new(mesh, 1.0, model, fixed, loads, settings)?;
    let mut out = FemOutcome {
        steps: vec![],
        end: vec![],
        failure: None,
    };
    while fem.steps_done() < fem.load_steps() {
        match fem.step() {
            Ok(r) => {
                let d = fem.displacement(tip);
                out.end.push(EndDisplacement {
                    step: r.step,
                    load: spec.load * r.load_factor,
                    u_over_l: d[0] / spec.length,
                    v_over_l: d[1] / spec.length,
                });
                out.steps.push(r);
            }
            Err(e) => {
                out.failure = Some(e);
                break;
            }
        }
    }
    Ok(out)
}

/// The methods that solve the cantilever.
pub const METHODS: [Method; 2] = [Method::Igimp, Method::FemQ8];

/// One cantilever analysis, whatever the method.
#[derive(Debug, Clone, PartialEq)]
pub struct CantileverSolution {
    pub steps: Vec<StepReport>,
    pub end: Vec<EndDisplacement>,
    pub failure: Option<SolveError>,
    /// iGIMP only: snapshots, the smallest half-length after each step, the loaded points.
    pub snapshots: Vec<DomainSnapshot>,
    pub min_half_length: Vec<f64>,
    pub loaded_points: Option<[usize; 2]>,
}

/// Solve the cantilever by `method`: iGIMP ([`solve_mpm`], snapshots every
/// `snapshot_every` steps) or Q8 FEM ([`solve_fem_q8`]).
pub fn solve(
    spec: &CantileverSpec,
    method: Method,
    snapshot_every: usize,
) -> Result<CantileverSolution, InputError> {
    match method {
        Method::Igimp => solve_mpm(spec, snapshot_every).map(|o| CantileverSolution {
            steps: o.steps,
            end: o.end,
            failure: o.failure,
            snapshots: o.snapshots,
            min_half_length: o.min_half_length,
            loaded_points: Some(o.loaded_points),
        }),
        Method::FemQ8 => solve_fem_q8(spec).map(|o| CantileverSolution {
            steps: o.steps,
            end: o.end,
            failure: o.failure,
            snapshots: vec![],
            min_half_length: vec![],
            loaded_points: None,
        }),
        _ => Err(method.unsupported("cantilever", &METHODS)),
    }
}
