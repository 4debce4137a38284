//! The cantilever by material points (iGIMP and the other families), 2D and 3D.

use super::spec::{CantileverSpec, EndDisplacement};
use crate::basis::Basis;
use crate::mesh::grid::Grid;
use crate::mpm::particles::MaterialPoints;
use crate::mpm::{Loads, MpmSettings, MpmSolver};
use crate::solver::error::{InputError, SolveError};
use crate::solver::load_stepping::{LoadStepping, StepReport};
use nalgebra::SVector;
use serde::{Deserialize, Serialize};

impl CantileverSpec {
    /// Solver settings of the material point beam (2D or 3D).
    fn mpm_settings(&self, basis: Basis) -> MpmSettings {
        MpmSettings {
            basis,
            domain_update: self.domain_update,
            newton: self.newton,
            load_steps: self.load_steps,
            weak_node_tolerance: self.weak_node_tolerance,
            weak_node_treatment: self.weak_node_treatment,
            volume_update: self.volume_update,
            linear_solver: Default::default(),
            ghost: self.ghost,
            dynamics: None,
            f_bar: self.f_bar,
        }
    }

    /// The plane-strain background grid: from the support (x = 0) to `grid_margin` past the
    /// free end, `grid_below` under the beam to `grid_margin` above it.
    pub fn grid_2d(&self) -> Result<Grid<2>, InputError> {
        let h = self.element_size;
        let x_cells = ((self.length + self.grid_margin) / h).round() as usize;
        let y_cells = ((self.grid_below + self.depth + self.grid_margin) / h).round() as usize;
        Grid::try_new([0.0, -self.grid_below], [h, h], [x_cells, y_cells])
    }

    /// The 3D background grid: the plane grid extended `grid_margin` to either side of the
    /// beam's width.
    pub fn grid_3d(&self) -> Result<Grid<3>, InputError> {
        let h = self.element_size;
        let m = self.grid_margin;
        let cells = [
            ((self.length + m) / h).round() as usize,
            ((self.grid_below + self.depth + m) / h).round() as usize,
            ((self.depth + 2.0 * m) / h).round() as usize,
        ];
        Grid::try_new([0.0, -self.grid_below, -m], [h; 3], cells)
    }

    /// The plane-strain solver, and the indices of the two loaded points (below, above the
    /// neutral axis).
    pub fn mpm_solver(&self) -> Result<(MpmSolver<2>, [usize; 2]), InputError> {
        self.mpm_solver_with(Basis::Gimp)
    }

    /// [`Self::mpm_solver`] with the basis family `basis`.
    pub fn mpm_solver_with(&self, basis: Basis) -> Result<(MpmSolver<2>, [usize; 2]), InputError> {
        self.mpm_solver_2d(basis, 1.0, None)
    }

    /// The plane-strain solver of density `density` (a quasi-static analysis has no use for
    /// it), Newmark time stepping if `dynamics` is given (its steps replace `load_steps`).
    pub fn mpm_solver_2d(
        &self,
        basis: Basis,
        density: f64,
        dynamics: Option<crate::solver::dynamics::Newmark>,
    ) -> Result<(MpmSolver<2>, [usize; 2]), InputError> {
        self.validate()?;
        let h = self.element_size;
        let grid = self.grid_2d()?;
        let ppc = self.points_per_cell;
        let points =
            MaterialPoints::fill_box(&grid, [0.0, 0.0], [self.length, self.depth], [ppc, ppc], density)?;
        let axis_y = 0.5 * self.depth;
        let mut fixed: Vec<(usize, usize)> =
            grid.nodes_on_plane(0, 0.0).into_iter().map(|n| (n, 0)).collect();
        let pin = grid
            .nodes_on_plane(0, 0.0)
            .into_iter()
            .find(|&n| (grid.node_position(n)[1] - axis_y).abs() < 1e-9 * h)
            .expect("neutral axis node");
        fixed.push((pin, 1));
        let loaded = end_points_at_axis(&points, axis_y);
        let loaded = [loaded[0], loaded[1]];
        let force = SVector::<f64, 2>::new(0.0, -0.5 * self.load);
        let loads = Loads {
            gravity: SVector::<f64, 2>::zeros(),
            point_loads: vec![(loaded[0], force), (loaded[1], force)],
        };
        let model = self.model()?;
        let settings = MpmSettings {
            dynamics,
            ..self.mpm_settings(basis)
        };
        Ok((
            MpmSolver::try_new(grid, points, model, fixed, loads, settings)?,
            loaded,
        ))
    }

    /// The 3D solver (module docs), and the loaded points: the end-most points of the two rows
    /// straddling the neutral axis, across the width, in order of (y, z).
    pub fn mpm_solver_3d(&self) -> Result<(MpmSolver<3>, Vec<usize>), InputError> {
        self.mpm_solver_3d_with(Basis::Gimp)
    }

    /// [`Self::mpm_solver_3d`] with the basis family `basis`.
    pub fn mpm_solver_3d_with(&self, basis: Basis) -> Result<(MpmSolver<3>, Vec<usize>), InputError> {
        self.validate()?;
        let h = self.element_size;
        let grid = self.grid_3d()?;
        let ppc = self.points_per_cell;
        let d = self.depth;
        let points = MaterialPoints::fill_box(&grid, [0.0; 3], [self.length, d, d], [ppc; 3], 1.0)?;
        let (axis_y, mid_z) = (0.5 * d, 0.5 * d);
        let on = |n: usize, a: usize, v: f64| (grid.node_position(n)[a] - v).abs() < 1e-9 * h;
        let mut fixed: Vec<(usize, usize)> = vec![];
        for n in grid.nodes_on_plane(0, 0.0) {
            fixed.push((n, 0));
            if on(n, 1, axis_y) {
                fixed.push((n, 1));
            }
        }
        fixed.extend((0..grid.num_nodes()).filter(|&n| on(n, 2, mid_z)).map(|n| (n, 2)));
        let loaded = end_points_at_axis(&points, axis_y);
        let force = SVector::<f64, 3>::new(0.0, -self.load / loaded.len() as f64, 0.0);
        let loads = Loads {
            gravity: SVector::<f64, 3>::zeros(),
            point_loads: loaded.iter().map(|&p| (p, force)).collect(),
        };
        let model = self.model()?;
        Ok((
            MpmSolver::try_new(grid, points, model, fixed, loads, self.mpm_settings(basis))?,
            loaded,
        ))
    }
}

/// The end-most points (largest initial x) of the two rows nearest the neutral axis y =
/// `axis_y`, ordered by initial y, then z.
fn end_points_at_axis<const D: usize>(points: &MaterialPoints<D>, axis_y: f64) -> Vec<usize> {
    let x0 = |p: usize| points.position0[p];
    let x_end = points.position0.iter().map(|x| x[0]).fold(f64::MIN, f64::max);
    let end: Vec<usize> = (0..points.len())
        .filter(|&p| (x0(p)[0] - x_end).abs() < 1e-9)
        .collect();
    let gap = end
        .iter()
        .map(|&p| (x0(p)[1] - axis_y).abs())
        .fold(f64::INFINITY, f64::min);
    let mut loaded: Vec<usize> = end
        .into_iter()
        .filter(|&p| ((x0(p)[1] - axis_y).abs() - gap).abs() < 1e-9)
        .collect();
    loaded.sort_by(|&a, &b| {
        let (xa, xb) = (x0(a), x0(b));
        (xa[1], xa[D - 1])
            .partial_cmp(&(xb[1], xb[D - 1]))
            .expect("finite positions")
    });
    loaded
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
    /// Snapshots at the start and after every `snapshot_every` steps (and the last): every
    /// point in 2D, in 3D the layer of points next to the mid-plane z = depth/2 (x, y only).
    pub snapshots: Vec<DomainSnapshot>,
    /// Smallest domain half-length (any axis) over all points after each step.
    pub min_half_length: Vec<f64>,
    /// The loaded points, as indices into the snapshots' domains.
    pub loaded_points: Vec<usize>,
    /// 3D only: every point's domain at the snapshot steps, for ParaView.
    pub solid_snapshots: Vec<SolidSnapshot>,
}

/// Every material point's domain at one instant of a 3D analysis: (x, y, z, half-lengths
/// x, y, z) per point.
#[derive(Debug, Clone, PartialEq)]
pub struct SolidSnapshot {
    pub step: usize,
    pub domains: Vec<[f64; 6]>,
}

fn solid_snapshot<const D: usize>(solver: &MpmSolver<D>, step: usize) -> SolidSnapshot {
    let p = &solver.points;
    let pad = |v: &SVector<f64, D>, a: usize| if a < D { v[a] } else { 0.0 };
    SolidSnapshot {
        step,
        domains: (0..p.len())
            .map(|i| {
                std::array::from_fn(|k| {
                    if k < 3 {
                        pad(&p.position[i], k)
                    } else {
                        pad(&p.half_length[i], k - 3)
                    }
                })
            })
            .collect(),
    }
}

fn snapshot<const D: usize>(solver: &MpmSolver<D>, shown: &[usize], step: usize) -> DomainSnapshot {
    let p = &solver.points;
    DomainSnapshot {
        step,
        domains: shown
            .iter()
            .map(|&i| {
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

/// Run the cantilever with iGIMP (2D or 3D by `spec.dimension`), recording the end
/// displacement after every step.
pub fn solve_mpm(spec: &CantileverSpec, snapshot_every: usize) -> Result<CantileverOutcome, InputError> {
    solve_mpm_with(spec, Basis::Gimp, snapshot_every)
}

/// [`solve_mpm`] with the basis family `basis`.
pub fn solve_mpm_with(
    spec: &CantileverSpec,
    basis: Basis,
    snapshot_every: usize,
) -> Result<CantileverOutcome, InputError> {
    if spec.dimension == 3 {
        let (solver, loaded) = spec.mpm_solver_3d_with(basis)?;
        // The layer just below the mid-plane z = d/2.
        let p0 = &solver.points.position0;
        let mid = 0.5 * spec.depth;
        let z = p0
            .iter()
            .map(|x| x[2])
            .filter(|&z| z < mid)
            .fold(f64::MIN, f64::max);
        let shown: Vec<usize> = (0..p0.len()).filter(|&p| (p0[p][2] - z).abs() < 1e-12).collect();
        run_mpm(spec, solver, &loaded, shown, snapshot_every)
    } else {
        let (solver, loaded) = spec.mpm_solver_with(basis)?;
        let shown = (0..solver.points.len()).collect();
        run_mpm(spec, solver, &loaded, shown, snapshot_every)
    }
}

fn run_mpm<const D: usize>(
    spec: &CantileverSpec,
    mut solver: MpmSolver<D>,
    loaded: &[usize],
    shown: Vec<usize>,
    snapshot_every: usize,
) -> Result<CantileverOutcome, InputError> {
    // 3D runs also keep every point's domain, for ParaView (the snapshots hold a layer).
    let solid = |solver: &MpmSolver<D>, step: usize| (D == 3).then(|| solid_snapshot(solver, step));
    let mut out = CantileverOutcome {
        steps: vec![],
        end: vec![],
        failure: None,
        solid_snapshots: solid(&solver, 0).into_iter().collect(),
        snapshots: vec![snapshot(&solver, &shown, 0)],
        min_half_length: vec![],
        loaded_points: shown
            .iter()
            .enumerate()
            .filter(|(_, p)| loaded.contains(p))
            .map(|(i, _)| i)
            .collect(),
    };
    while solver.steps_done() < solver.load_steps() {
        match solver.step() {
            Ok(r) => {
                let d = loaded
                    .iter()
                    .map(|&p| solver.points.displacement(p))
                    .sum::<SVector<f64, D>>()
                    / loaded.len() as f64;
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
                        .map(|h| h.min())
                        .fold(f64::INFINITY, f64::min),
                );
                if snapshot_every > 0 && (r.step % snapshot_every == 0 || r.step == solver.load_steps()) {
                    out.snapshots.push(snapshot(&solver, &shown, r.step));
                    out.solid_snapshots.extend(solid(&solver, r.step));
                }
                out.steps.push(r);
            }
            Err(e) => {
                out.snapshots.push(snapshot(&solver, &shown, solver.steps_done()));
                out.solid_snapshots.extend(solid(&solver, solver.steps_done()));
                out.failure = Some(e);
                break;
            }
        }
    }
    Ok(out)
}
