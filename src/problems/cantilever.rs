//! Cantilever under a dead end load (§5.3, Figures 19–21).
//!
//! A beam `length × depth` (plane strain by default) sits with its left end on the grid line
//! x = 0 and its neutral axis on a grid line. Supports as in the paper: every grid node on the
//! left boundary x = 0 is on a roller (u_x = 0) and the node on the neutral axis is also fixed
//! vertically. The end load P (vertical, fixed direction) is split equally between the two
//! end-most material points just above and just below the neutral axis, and applied over the
//! load steps. The background grid extends below the beam far enough for the deflected shape.
//!
//! In 3D (`dimension = 3`, reference/README.md items 29 and 38) the beam is `length × depth × depth` (a square section),
//! x along the beam, y up, z across. The supports are those of 2D on the end face x = 0 (u_x = 0
//! on every node, u_y = 0 along its neutral-axis line), plus u_z = 0 on the mid-plane
//! z = depth / 2, which is exact by symmetry and removes the rigid motions across. The end
//! load is split equally over the end-most points of the two rows straddling the neutral axis,
//! across the whole width (a line load); Hex8/Hex20 FEM carry it as the consistent line load on
//! the end edge along the neutral axis.

use crate::basis::method::Method;
use crate::basis::Basis;
use crate::discretise::ghost::{GhostFaces, GhostSettings};
use crate::fem::{
    ElementFamily, FemLoads, HexElement, HexMesh, PlaneFem, PlaneFemSettings, PlaneLoads, PlaneMesh,
    QuadElement, SolidFem,
};
use crate::material::constitutive::LinearElastic;
use crate::mesh::grid::Grid;
use crate::mpm::particles::MaterialPoints;
use crate::mpm::{DomainUpdate, Loads, MpmSettings, MpmSolver, VolumeUpdate, WeakNodeTreatment};
use crate::solver::error::{require_count, require_positive, InputError, SolveError};
use crate::solver::linear::LinearSolver;
use crate::solver::load_stepping::{LoadStepping, StepReport};
use crate::solver::newton::NewtonSettings;
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
    /// Ghost penalty of nearly empty cells ([`crate::discretise::ghost`]).
    #[serde(default)]
    pub ghost: GhostSettings,
    /// 2 (plane strain, the paper's) or 3 (a `depth × depth` section; see the module docs).
    /// Not serialised at 2, so 2D case hashes stay what they were.
    #[serde(default = "two", skip_serializing_if = "is_two")]
    pub dimension: usize,
}

fn two() -> usize {
    2
}

fn is_two(d: &usize) -> bool {
    *d == 2
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
                cut_share: 0.0,
            },
            dimension: 2,
        }
    }
}

impl CantileverSpec {
    pub fn validate(&self) -> Result<(), InputError> {
        if !matches!(self.dimension, 2 | 3) {
            return Err(InputError::new("dimension", self.dimension, "must be 2 or 3"));
        }
        self.ghost.validate()?;
        require_positive("length", self.length)?;
        require_positive("depth", self.depth)?;
        require_positive("element_size", self.element_size)?;
        require_positive("grid_below", self.grid_below)?;
        require_positive("grid_margin", self.grid_margin)?;
        // P acts downwards (along -y); a zero load has no elastica to compare with.
        require_positive("load", self.load)?;
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
        let through = (self.depth / self.element_size).round() as usize;
        if through % 2 != 0 {
            return Err(InputError::new(
                "element_size",
                self.element_size,
                format!(
                    "must divide depth = {} into an even number of elements (it gives {through}) so that the neutral axis is a grid line: e.g. element_size = {}",
                    self.depth,
                    self.depth / (through + 1) as f64
                ),
            ));
        }
        Ok(())
    }

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
        let model = Box::new(LinearElastic::try_new(self.young_modulus, self.poisson_ratio)?);
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
        let model = Box::new(LinearElastic::try_new(self.young_modulus, self.poisson_ratio)?);
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

/// What a FEM comparator reports: the steps and the end displacement after each.
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
    let (fem, tip) = fem_q8(spec, 1.0)?;
    Ok(run_fem(spec, fem, tip))
}

/// The Q8 beam of [`solve_fem_q8`] at density `density`, and its tip node (L, d/2).
pub fn fem_q8(spec: &CantileverSpec, density: f64) -> Result<(PlaneFem, usize), InputError> {
    spec.validate()?;
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
    let model = Box::new(LinearElastic::try_new(spec.young_modulus, spec.poisson_ratio)?);
    let fem = PlaneFem::try_new(mesh, density, model, fixed, loads, fem_settings(spec, Some(3)))?;
    Ok((fem, tip))
}

/// Updated-Lagrangian Hex8 (2×2×2 Gauss points) or Hex20 (3×3×3) FEM of the 3D beam on the
/// same `h` (20 × 2 × 2 elements for the paper's beam), the supports of the module docs (u_x
/// on the end face, u_y along its neutral-axis line, u_z on the mid-plane), and the end load
/// as the consistent line load on the end edge along the neutral axis (per element edge
/// ½, ½ for Hex8; ⅙, ⅔, ⅙ for Hex20). The end displacement is that of the edge's middle
/// node (L, d/2, d/2).
pub fn solve_fem_3d(spec: &CantileverSpec, element: HexElement) -> Result<FemOutcome, InputError> {
    spec.validate()?;
    let (h, d) = (spec.element_size, spec.depth);
    let n = |v: f64| (v / h).round() as usize;
    let mesh = HexMesh::cuboid(
        SVector::zeros(),
        SVector::<f64, 3>::new(spec.length, d, d),
        [n(spec.length), n(d), n(d)],
        element,
    )?;
    let tol = 1e-9 * h;
    let (axis, mid) = (0.5 * d, 0.5 * d);
    let mut fixed: Vec<(usize, usize)> = vec![];
    for node in mesh.nodes_at(0, 0.0, tol) {
        fixed.push((node, 0));
        if (mesh.nodes[node][1] - axis).abs() <= tol {
            fixed.push((node, 1));
        }
    }
    fixed.extend(mesh.nodes_at(2, mid, tol).into_iter().map(|node| (node, 2)));
    let edge = mesh.nodes_on_segment(
        SVector::<f64, 3>::new(spec.length, axis, 0.0),
        SVector::<f64, 3>::new(spec.length, axis, d),
        tol,
    );
    let weights: &[f64] = if element.quadratic() {
        &[1.0 / 6.0, 4.0 / 6.0, 1.0 / 6.0]
    } else {
        &[0.5, 0.5]
    };
    let per_edge = weights.len() - 1;
    let mut force = vec![0.0; edge.len()];
    let edges = (edge.len() - 1) / per_edge;
    for e in 0..edges {
        for (k, w) in weights.iter().enumerate() {
            force[e * per_edge + k] += w * spec.load / edges as f64;
        }
    }
    let tip = mesh.nearest_node(SVector::<f64, 3>::new(spec.length, axis, mid));
    let loads = FemLoads {
        gravity: SVector::<f64, 3>::zeros(),
        nodal_forces: edge
            .iter()
            .zip(&force)
            .map(|(&node, &f)| (node, SVector::<f64, 3>::new(0.0, -f, 0.0)))
            .collect(),
    };
    let model = Box::new(LinearElastic::try_new(spec.young_modulus, spec.poisson_ratio)?);
    let fem = SolidFem::try_new(mesh, 1.0, model, fixed, loads, fem_settings(spec, None))?;
    Ok(run_fem(spec, fem, tip))
}

fn fem_settings(spec: &CantileverSpec, gauss_points: Option<usize>) -> PlaneFemSettings {
    PlaneFemSettings {
        gauss_points,
        newton: spec.newton,
        load_steps: spec.load_steps,
        linear_solver: LinearSolver::Ldlt,
    }
}

/// Run a FEM beam step by step, recording the displacement of node `tip`.
fn run_fem<const D: usize, E: ElementFamily<D>>(
    spec: &CantileverSpec,
    mut fem: crate::fem::ContinuumFem<D, E>,
    tip: usize,
) -> FemOutcome {
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
    out
}

/// The methods that solve the plane-strain cantilever (its FEM comparator is Q8, the paper's
/// Figure 21).
pub const METHODS: [Method; Method::FAMILIES + 1] = Method::listed(Some(2), &[Method::FEM_Q4]);

/// The methods that solve the 3D cantilever.
pub const METHODS_3D: [Method; Method::FAMILIES + 2] = Method::listed(Some(3), &[]);

/// The methods of a cantilever in `dimension` (2 or 3).
pub fn methods(dimension: usize) -> &'static [Method] {
    if dimension == 3 {
        &METHODS_3D
    } else {
        &METHODS
    }
}

/// One cantilever analysis, whatever the method.
#[derive(Debug, Clone, PartialEq)]
pub struct CantileverSolution {
    pub steps: Vec<StepReport>,
    pub end: Vec<EndDisplacement>,
    pub failure: Option<SolveError>,
    /// iGIMP only: snapshots, the smallest half-length after each step, the loaded points
    /// (indices into the snapshots' domains).
    pub snapshots: Vec<DomainSnapshot>,
    pub min_half_length: Vec<f64>,
    pub loaded_points: Option<Vec<usize>>,
    /// 3D iGIMP only: every point's domain at the snapshot steps ([`SolidSnapshot`]).
    pub solid_snapshots: Vec<SolidSnapshot>,
}

/// Solve the cantilever by `method`: iGIMP ([`solve_mpm`], snapshots every
/// `snapshot_every` steps), Q8 FEM in 2D ([`solve_fem_q8`]), Hex8 or Hex20 FEM in 3D
/// ([`solve_fem_3d`]).
pub fn solve(
    spec: &CantileverSpec,
    method: Method,
    snapshot_every: usize,
) -> Result<CantileverSolution, InputError> {
    let fem = |o: FemOutcome| CantileverSolution {
        steps: o.steps,
        end: o.end,
        failure: o.failure,
        snapshots: vec![],
        min_half_length: vec![],
        loaded_points: None,
        solid_snapshots: vec![],
    };
    match (method, spec.dimension) {
        (Method::MaterialPoint(basis), _) => {
            solve_mpm_with(spec, basis, snapshot_every).map(|o| CantileverSolution {
                steps: o.steps,
                end: o.end,
                failure: o.failure,
                snapshots: o.snapshots,
                min_half_length: o.min_half_length,
                loaded_points: Some(o.loaded_points),
                solid_snapshots: o.solid_snapshots,
            })
        }
        (Method::FEM_Q8, 2) => solve_fem_q8(spec).map(fem),
        (Method::FEM_HEX8, 3) => solve_fem_3d(spec, HexElement::Hex8).map(fem),
        (Method::FEM_HEX20, 3) => solve_fem_3d(spec, HexElement::Hex20).map(fem),
        _ => Err(method.unsupported(
            if spec.dimension == 3 {
                "3D cantilever (dimension = 3)"
            } else {
                "plane-strain cantilever (dimension = 2)"
            },
            methods(spec.dimension),
        )),
    }
}
