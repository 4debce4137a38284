//! The compaction by material points: the plane-strain half block and the 3D quarter block.

use super::spec::CompactionSpec;
use crate::material::constitutive::InternalVariables;
use crate::mesh::grid::Grid;
use crate::mpm::particles::MaterialPoints;
use crate::mpm::{Loads, MpmSettings, MpmSolver};
use crate::solver::error::{InputError, SolveError};
use crate::solver::load_stepping::{steps_and_failure, LoadStepping, StepReport};
use nalgebra::SVector;
use serde::{Deserialize, Serialize};

impl CompactionSpec {
    /// Solver settings of the material point block (2D or 3D).
    fn mpm_settings(&self) -> MpmSettings {
        MpmSettings {
            basis: self.basis,
            domain_update: self.domain_update,
            newton: self.newton,
            load_steps: self.load_steps,
            weak_node_tolerance: self.weak_node_tolerance,
            weak_node_treatment: self.weak_node_treatment,
            volume_update: Default::default(),
            linear_solver: self.linear_solver,
            ghost: self.ghost,
            dynamics: None,
            f_bar: self.f_bar,
        }
    }

    /// The plane-strain background grid: `grid_extent` from the origin in cells of h.
    pub fn grid_2d(&self) -> Result<Grid<2>, InputError> {
        let h = self.element_size;
        let cells = [
            (self.grid_extent[0] / h).round() as usize,
            (self.grid_extent[1] / h).round() as usize,
        ];
        Grid::try_new([0.0, 0.0], [h, h], cells)
    }

    /// The iGIMP/MPM solver of this problem.
    pub fn mpm_solver(&self) -> Result<MpmSolver<2>, InputError> {
        self.validate()?;
        let grid = self.grid_2d()?;
        let ppc = self.points_per_cell;
        let points =
            MaterialPoints::fill_box(&grid, [0.0, 0.0], [self.half_width, self.height], [ppc, ppc], 1.0)?;
        let mut fixed: Vec<(usize, usize)> =
            grid.nodes_on_plane(0, 0.0).into_iter().map(|n| (n, 0)).collect();
        fixed.extend(grid.nodes_on_plane(1, 0.0).into_iter().map(|n| (n, 1)));
        let loads = Loads {
            gravity: SVector::<f64, 2>::new(0.0, -self.unit_weight()),
            point_loads: vec![],
        };
        MpmSolver::try_new(grid, points, self.model()?, fixed, loads, self.mpm_settings())
    }
}

/// Final state of one material point.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct DomainRecord {
    pub x0: [f64; 2],
    pub x: [f64; 2],
    /// Initial and current domain half-lengths.
    pub half0: [f64; 2],
    pub half: [f64; 2],
    /// Cauchy stress σ_yy.
    pub sigma_yy: f64,
    /// The model's internal variable `plastic_multiplier` (von Mises'; 0 for a model without
    /// one), as `domains.json` stores it.
    pub plastic_multiplier: f64,
    /// The model's internal variables, for ParaView (not stored in `domains.json`).
    #[serde(skip)]
    pub internal: InternalVariables,
}

/// Final state of one material point of a 3D analysis (ParaView output).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Domain3dRecord {
    pub x0: [f64; 3],
    pub x: [f64; 3],
    /// Initial and current domain half-lengths.
    pub half0: [f64; 3],
    pub half: [f64; 3],
    /// Cauchy stress σ_zz (vertical).
    pub sigma_zz: f64,
    /// The model's internal variables.
    pub internal: InternalVariables,
}

/// Point `p`'s internal variable `plastic_multiplier`, 0 if the model has none.
fn plastic_multiplier<const D: usize>(solver: &MpmSolver<D>, p: usize) -> f64 {
    let declared = solver.model().internal_variables();
    let internal = &solver.points.state[p].material.internal;
    internal.named(declared, "plastic_multiplier").unwrap_or(0.0)
}

/// Outcome of one compaction analysis.
#[derive(Debug, Clone, PartialEq)]
pub struct CompactionOutcome {
    pub steps: Vec<StepReport>,
    pub failure: Option<SolveError>,
    /// Horizontal displacement of the bottom-right point plus half the growth of its domain
    /// (the measure of Figure 17).
    pub max_horizontal_displacement: f64,
    /// Total number of weak-node constraints applied over all steps.
    pub weak_nodes_treated: usize,
    /// Material points in the analysis.
    pub num_points: usize,
    /// Final domains: every point in 2D, the slice next to y = 0 in 3D ([`solve_mpm_3d`]).
    pub points: Vec<DomainRecord>,
    /// Every point's final 3D domain (empty in 2D).
    pub points_3d: Vec<Domain3dRecord>,
}

/// Run the compaction problem with material points.
pub fn solve_mpm(spec: &CompactionSpec) -> Result<CompactionOutcome, InputError> {
    let mut solver = spec.mpm_solver()?;
    let (steps, failure) = steps_and_failure(solver.run());
    let pts = &solver.points;
    // Bottom-right point: lowest row, largest x.
    let min_y = pts.position0.iter().map(|x| x[1]).fold(f64::INFINITY, f64::min);
    let corner = (0..pts.len())
        .filter(|&p| (pts.position0[p][1] - min_y).abs() < 1e-12)
        .max_by(|&a, &b| pts.position0[a][0].total_cmp(&pts.position0[b][0]))
        .expect("at least one point");
    let max_horizontal_displacement =
        pts.displacement(corner)[0] + (pts.half_length[corner][0] - pts.half_length0[corner][0]);
    let points = (0..pts.len())
        .map(|p| DomainRecord {
            x0: [pts.position0[p][0], pts.position0[p][1]],
            x: [pts.position[p][0], pts.position[p][1]],
            half0: [pts.half_length0[p][0], pts.half_length0[p][1]],
            half: [pts.half_length[p][0], pts.half_length[p][1]],
            sigma_yy: pts.state[p].cauchy()[(1, 1)],
            plastic_multiplier: plastic_multiplier(&solver, p),
            internal: pts.state[p].material.internal,
        })
        .collect();
    Ok(CompactionOutcome {
        num_points: pts.len(),
        weak_nodes_treated: steps.iter().map(|s| s.weak_nodes).sum(),
        steps,
        failure,
        max_horizontal_displacement,
        points,
        points_3d: vec![],
    })
}

impl CompactionSpec {
    /// Cells of the 3D quarter block's grid, x × y × z.
    fn grid_cells_3d(&self) -> [usize; 3] {
        let h = self.element_size;
        let (nx, nz) = (
            (self.grid_extent[0] / h).round() as usize,
            (self.grid_extent[1] / h).round() as usize,
        );
        [nx, nx, nz]
    }

    /// The 3D quarter block's background grid (cubic cells of h from the origin).
    pub fn grid_3d(&self) -> Result<Grid<3>, InputError> {
        let h = self.element_size;
        Grid::try_new([0.0; 3], [h; 3], self.grid_cells_3d())
    }

    /// The 3D quarter-block solver of this spec (iGIMP or MPM by `spec.basis`): the quarter
    /// of a square block of side 2 × `half_width` and height `height` (symmetry planes x = 0
    /// and y = 0 and the base z = 0 on rollers), on a cubic grid of `grid_extent[0]` ×
    /// `grid_extent[0]` × `grid_extent[1]`, `points_per_cell`³ points per cell, density 1,
    /// gravity along −z with the 2D unit weight.
    pub fn mpm_solver_3d(&self) -> Result<MpmSolver<3>, InputError> {
        self.validate()?;
        let grid = self.grid_3d()?;
        let ppc = self.points_per_cell;
        let points = MaterialPoints::fill_box(
            &grid,
            [0.0; 3],
            [self.half_width, self.half_width, self.height],
            [ppc; 3],
            1.0,
        )?;
        let mut fixed: Vec<(usize, usize)> = vec![];
        for axis in 0..3 {
            fixed.extend(grid.nodes_on_plane(axis, 0.0).into_iter().map(|n| (n, axis)));
        }
        let loads = Loads {
            // The 2D unit weight is per unit area of the full block's section; the same ρg.
            gravity: SVector::<f64, 3>::new(0.0, 0.0, -self.unit_weight()),
            point_loads: vec![],
        };
        MpmSolver::try_new(grid, points, self.model()?, fixed, loads, self.mpm_settings())
    }
}

/// Run the 3D quarter block with material points ([`CompactionSpec::mpm_solver_3d`]). The
/// measure is u_x of the bottom point at the largest x next to the symmetry plane y = 0 plus
/// half its domain's growth along x (Figure 17's, in 3D); the domains recorded are the layer
/// of points next to y = 0 (the full block's mid-plane), with (x, z) in the record's two
/// slots and σ_zz as the vertical stress.
pub fn solve_mpm_3d(spec: &CompactionSpec) -> Result<CompactionOutcome, InputError> {
    let mut solver = spec.mpm_solver_3d()?;
    let (steps, failure) = steps_and_failure(solver.run());
    let pts = &solver.points;
    let lowest = |a: usize| pts.position0.iter().map(|x| x[a]).fold(f64::INFINITY, f64::min);
    let (y0, z0) = (lowest(1), lowest(2));
    let in_slice = |p: usize| (pts.position0[p][1] - y0).abs() < 1e-12;
    let corner = (0..pts.len())
        .filter(|&p| in_slice(p) && (pts.position0[p][2] - z0).abs() < 1e-12)
        .max_by(|&a, &b| pts.position0[a][0].total_cmp(&pts.position0[b][0]))
        .expect("at least one point");
    let max_horizontal_displacement =
        pts.displacement(corner)[0] + (pts.half_length[corner][0] - pts.half_length0[corner][0]);
    let points = (0..pts.len())
        .filter(|&p| in_slice(p))
        .map(|p| DomainRecord {
            x0: [pts.position0[p][0], pts.position0[p][2]],
            x: [pts.position[p][0], pts.position[p][2]],
            half0: [pts.half_length0[p][0], pts.half_length0[p][2]],
            half: [pts.half_length[p][0], pts.half_length[p][2]],
            sigma_yy: pts.state[p].cauchy()[(2, 2)],
            plastic_multiplier: plastic_multiplier(&solver, p),
            internal: pts.state[p].material.internal,
        })
        .collect();
    let arr = |v: &SVector<f64, 3>| [v[0], v[1], v[2]];
    let points_3d = (0..pts.len())
        .map(|p| Domain3dRecord {
            x0: arr(&pts.position0[p]),
            x: arr(&pts.position[p]),
            half0: arr(&pts.half_length0[p]),
            half: arr(&pts.half_length[p]),
            sigma_zz: pts.state[p].cauchy()[(2, 2)],
            internal: pts.state[p].material.internal,
        })
        .collect();
    Ok(CompactionOutcome {
        num_points: pts.len(),
        weak_nodes_treated: steps.iter().map(|s| s.weak_nodes).sum(),
        steps,
        failure,
        max_horizontal_displacement,
        points,
        points_3d,
    })
}
