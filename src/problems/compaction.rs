//! Plane-strain compaction of a block under its own weight (§5.2, Figures 15–18, Tables 2–3).
//!
//! Geometry as we read the paper: the full block is `2 × half_width` wide and `height` high; by
//! symmetry the half `0 ≤ x ≤ half_width` is modelled, with a roller (u_x = 0) on the symmetry
//! line x = 0 and u_y = 0 on the bottom edge y = 0. It sits in a background grid covering
//! `[0, grid_extent[0]] × [0, grid_extent[1]]`, which leaves room for the material to spread.
//! `weight` is the weight of the full block; the modelled half carries half of it, applied by
//! gravity ramped over the load steps (ρ0 g = weight / (2 half_width · height), density 1).

use crate::basis::method::Method;
use crate::basis::Basis;
use crate::discretise::ghost::{GhostFaces, GhostSettings};
use crate::fem::{
    ContinuumFem, ElementFamily, ElementMesh, FemLoads, HexElement, HexMesh, PlaneFemSettings, PlaneMesh,
    QuadElement,
};
use crate::material::constitutive::ConstitutiveModel;
use crate::mesh::grid::Grid;
use crate::mpm::particles::MaterialPoints;
use crate::mpm::{DomainUpdate, Loads, MpmSettings, MpmSolver, WeakNodeTreatment};
use crate::solver::error::{require_count, require_positive, InputError, SolveError};
use crate::solver::linear::LinearSolver;
use crate::solver::load_stepping::{steps_and_failure, LoadStepping, StepReport};
use crate::solver::newton::NewtonSettings;
use nalgebra::SVector;
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
    pub young_modulus: f64,
    pub poisson_ratio: f64,
    /// Weight of the full block, W.
    pub weight: f64,
    /// Von Mises yield stress ρ_y; absent for the elastic case.
    #[serde(default)]
    pub yield_stress: Option<f64>,
    pub load_steps: usize,
    pub newton: NewtonSettings,
    /// See [`MpmSettings::weak_node_tolerance`].
    pub weak_node_tolerance: f64,
    #[serde(default)]
    pub weak_node_treatment: WeakNodeTreatment,
    pub basis: Basis,
    pub domain_update: DomainUpdate,
    /// Sparse factorisation; LDLᵀ suits this symmetric tangent (LU fallback).
    #[serde(default)]
    pub linear_solver: LinearSolver,
    /// Ghost penalty of nearly empty cells ([`crate::discretise::ghost`]).
    #[serde(default)]
    pub ghost: GhostSettings,
    /// 2 (plane strain, the paper's) or 3: the quarter of a square block with two symmetry
    /// planes ([`CompactionSpec::mpm_solver_3d`], [`solve_fem_3d`]). Not serialised at 2, so
    /// 2D case hashes stay what they were.
    #[serde(default = "two", skip_serializing_if = "is_two")]
    pub dimension: usize,
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
            young_modulus: 1e5,
            poisson_ratio: 0.3,
            weight: 4e5,
            yield_stress: None,
            load_steps: 20,
            newton: NewtonSettings::default(),
            // The ghost penalty is the default treatment of nearly empty cells (measured,
            // reference/README.md items 15-16); the weak-node tie stays available, off.
            weak_node_tolerance: 0.0,
            weak_node_treatment: WeakNodeTreatment::Tie,
            basis: Basis::Gimp,
            domain_update: DomainUpdate::Stretch,
            linear_solver: LinearSolver::Lu,
            // gamma: the plateau of the compaction study's ghost sweep: gamma in [0.1, 10] moves Figure 17 by <= 0.1 % at h <= 1/2.
            ghost: GhostSettings {
                gamma: 1.0,
                faces: GhostFaces::Cut,
                ..Default::default()
            },
            dimension: 2,
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

    /// Linear elastic, or von Mises when `yield_stress` is set.
    pub fn model(&self) -> Result<Box<dyn ConstitutiveModel>, InputError> {
        crate::material::constitutive::elastic_or_von_mises(
            self.young_modulus,
            self.poisson_ratio,
            self.yield_stress,
        )
    }

    /// ρ0 g of the block (density 1).
    pub fn unit_weight(&self) -> f64 {
        self.weight / (2.0 * self.half_width * self.height)
    }

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
    pub plastic_multiplier: f64,
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
    pub plastic_multiplier: f64,
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
            plastic_multiplier: pts.state[p].material.plastic_multiplier,
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

/// What the FEM comparator reports.
#[derive(Debug, Clone, PartialEq)]
pub struct FemOutcome {
    pub steps: Vec<StepReport>,
    pub failure: Option<SolveError>,
    /// Horizontal displacement of the bottom-right node.
    pub max_horizontal_displacement: f64,
    pub elements: usize,
}

/// Updated-Lagrangian FEM of the modelled half block with the same supports (roller on
/// x = 0, u_y = 0 on the base), material and gravity ramp: Q4 with 2×2 Gauss points (the
/// paper's Figure 17 reference) or Q8 with 3×3 (a comparison for plastic flow, where Q4
/// locks). LDLᵀ solves.
pub fn solve_fem(spec: &CompactionSpec, element: QuadElement) -> Result<FemOutcome, InputError> {
    let (fem, corner) = fem_solver(spec, element)?;
    Ok(run_fem_block(fem, corner))
}

/// The plane-strain FEM solver of `spec` with `element` (Q4 or Q8 on the modelled half block,
/// h = `element_size`), undeformed, and the node whose u_x is Figure 17's measure.
pub fn fem_solver(
    spec: &CompactionSpec,
    element: QuadElement,
) -> Result<(crate::fem::PlaneFem, usize), InputError> {
    let h = spec.element_size;
    let cells = [
        (spec.half_width / h).round() as usize,
        (spec.height / h).round() as usize,
    ];
    let size = SVector::<f64, 2>::new(spec.half_width, spec.height);
    fem_block(
        spec,
        PlaneMesh::structured(SVector::zeros(), size, cells, element)?,
    )
}

/// The FEM block of either dimension on `mesh` (the modelled part, from the origin): rollers
/// on every coordinate plane through the origin (the symmetry planes and the base), gravity
/// along the last axis, the element's default Gauss rule (2 per axis for Q4/Hex8, 3 for
/// Q8/Hex20), LDLᵀ (or the spec's iterative solver). Returns the solver and the node at
/// (half_width, 0, …), whose u_x is the measure.
fn fem_block<const D: usize, E: ElementFamily<D>>(
    spec: &CompactionSpec,
    mesh: ElementMesh<D, E>,
) -> Result<(ContinuumFem<D, E>, usize), InputError> {
    let tol = 1e-9 * spec.element_size;
    let mut fixed: Vec<(usize, usize)> = vec![];
    for axis in 0..D {
        fixed.extend(mesh.nodes_at(axis, 0.0, tol).into_iter().map(|node| (node, axis)));
    }
    let mut corner = SVector::<f64, D>::zeros();
    corner[0] = spec.half_width;
    let corner = mesh.nearest_node(corner);
    let mut gravity = SVector::<f64, D>::zeros();
    gravity[D - 1] = -spec.unit_weight();
    let loads = FemLoads {
        gravity,
        nodal_forces: vec![],
    };
    let settings = PlaneFemSettings {
        gauss_points: None,
        newton: spec.newton,
        load_steps: spec.load_steps,
        // LDLᵀ unless the spec asks for the iterative solver (its LU default is the material
        // point methods').
        linear_solver: if spec.linear_solver == LinearSolver::Iterative {
            LinearSolver::Iterative
        } else {
            LinearSolver::Ldlt
        },
    };
    let fem = ContinuumFem::try_new(mesh, 1.0, spec.model()?, fixed, loads, settings)?;
    Ok((fem, corner))
}

/// Run the FEM block of [`fem_block`] to the end.
fn solve_fem_block<const D: usize, E: ElementFamily<D>>(
    spec: &CompactionSpec,
    mesh: ElementMesh<D, E>,
) -> Result<FemOutcome, InputError> {
    let (fem, corner) = fem_block(spec, mesh)?;
    Ok(run_fem_block(fem, corner))
}

/// All load steps of an FEM block; the measure is u_x of `corner`.
fn run_fem_block<const D: usize, E: ElementFamily<D>>(
    mut fem: ContinuumFem<D, E>,
    corner: usize,
) -> FemOutcome {
    let elements = fem.mesh.num_elements();
    let (steps, failure) = steps_and_failure(fem.run());
    FemOutcome {
        steps,
        failure,
        max_horizontal_displacement: fem.displacement(corner)[0],
        elements,
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

/// One compaction analysis, whatever the method.
#[derive(Debug, Clone, PartialEq)]
pub struct CompactionSolution {
    pub steps: Vec<StepReport>,
    pub failure: Option<SolveError>,
    /// The measure of Figure 17 ([`CompactionOutcome`], [`FemOutcome`]).
    pub max_horizontal_displacement: f64,
    /// Weak-node constraints applied over all steps (0 for FEM).
    pub weak_nodes_treated: usize,
    /// Material points (MPM, iGIMP) or elements (FEM).
    pub size: usize,
    /// Final material point domains (none for FEM); in 3D the slice next to the symmetry
    /// plane y = 0 ([`solve_mpm_3d`]).
    pub domains: Vec<DomainRecord>,
    /// Every point's final 3D domain (3D material points only).
    pub domains_3d: Vec<Domain3dRecord>,
}

/// Solve the compaction by `method`: a material point family (the method sets
/// `spec.basis`), or Q4/Q8 FEM ([`solve_fem`]).
pub fn solve(spec: &CompactionSpec, method: Method) -> Result<CompactionSolution, InputError> {
    if spec.dimension == 3 {
        return solve_3d(spec, method);
    }
    let basis = match method {
        Method::MaterialPoint(basis) => basis,
        Method::FEM_Q4 | Method::FEM_Q8 => {
            let element = if method == Method::FEM_Q4 {
                QuadElement::Q4
            } else {
                QuadElement::Q8
            };
            let o = solve_fem(spec, element)?;
            return Ok(CompactionSolution {
                steps: o.steps,
                failure: o.failure,
                max_horizontal_displacement: o.max_horizontal_displacement,
                weak_nodes_treated: 0,
                size: o.elements,
                domains: vec![],
                domains_3d: vec![],
            });
        }
        _ => return Err(unsupported(spec, method)),
    };
    let o = solve_mpm(&CompactionSpec { basis, ..*spec })?;
    Ok(CompactionSolution {
        size: o.num_points,
        steps: o.steps,
        failure: o.failure,
        max_horizontal_displacement: o.max_horizontal_displacement,
        weak_nodes_treated: o.weak_nodes_treated,
        domains: o.points,
        domains_3d: o.points_3d,
    })
}

/// A method the compaction in `spec.dimension` does not have: an error naming `method` (and
/// the dimension) with the allowed methods.
fn unsupported(spec: &CompactionSpec, method: Method) -> InputError {
    let problem = if spec.dimension == 3 {
        "3D compaction (dimension = 3)"
    } else {
        "plane-strain compaction (dimension = 2)"
    };
    method.unsupported(problem, methods(spec.dimension))
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
            plastic_multiplier: pts.state[p].material.plastic_multiplier,
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
            plastic_multiplier: pts.state[p].material.plastic_multiplier,
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

/// Updated-Lagrangian FEM of the 3D quarter block with the same supports (rollers on x = 0,
/// y = 0 and the base), material and gravity ramp: Hex8 with 2×2×2 Gauss points or Hex20 with
/// 3×3×3, LDLᵀ. The measure is u_x of the node at (half_width, 0, 0).
pub fn solve_fem_3d(spec: &CompactionSpec, element: HexElement) -> Result<FemOutcome, InputError> {
    spec.validate()?;
    let h = spec.element_size;
    let (n, nz) = (
        (spec.half_width / h).round() as usize,
        (spec.height / h).round() as usize,
    );
    let size = SVector::<f64, 3>::new(spec.half_width, spec.half_width, spec.height);
    solve_fem_block(
        spec,
        HexMesh::cuboid(SVector::zeros(), size, [n, n, nz], element)?,
    )
}

/// The 3D compaction by `method` ([`solve_mpm_3d`], [`solve_fem_3d`]).
fn solve_3d(spec: &CompactionSpec, method: Method) -> Result<CompactionSolution, InputError> {
    let element = match method {
        Method::MaterialPoint(basis) => {
            let o = solve_mpm_3d(&CompactionSpec { basis, ..*spec })?;
            return Ok(CompactionSolution {
                size: o.num_points,
                steps: o.steps,
                failure: o.failure,
                max_horizontal_displacement: o.max_horizontal_displacement,
                weak_nodes_treated: o.weak_nodes_treated,
                domains: o.points,
                domains_3d: o.points_3d,
            });
        }
        Method::FEM_HEX8 => HexElement::Hex8,
        Method::FEM_HEX20 => HexElement::Hex20,
        _ => return Err(unsupported(spec, method)),
    };
    let o = solve_fem_3d(spec, element)?;
    Ok(CompactionSolution {
        steps: o.steps,
        failure: o.failure,
        max_horizontal_displacement: o.max_horizontal_displacement,
        weak_nodes_treated: 0,
        size: o.elements,
        domains: vec![],
        domains_3d: vec![],
    })
}
