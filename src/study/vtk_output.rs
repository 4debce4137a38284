//! `study --vtk`: ParaView files of each case of a study: the column's solver states
//! ([`ColumnVtkWriter`]) and the other kinds' material point domains with their background
//! grid ([`write_domain_frames`]).
//!
//! Layout inside the study folder: `vtk/<case-id>.pvd` (a collection with time = load factor,
//! part 0 the material or Gauss points, part 1 the background grid or FEM mesh) and
//! `vtk/<case-id>/{points,grid}_<step>.vtu` for step 0 (initial state), every `every`-th load
//! step and the last converged step. The point arrays are those of [`crate::study::vtk`]; the MPM
//! grid carries `displacement_increment` (Δu of the step) and `displacement` (Σ Δu over the
//! steps at the fixed node; the grid itself never moves), the FEM mesh its nodal
//! `displacement`.

use super::store::confined;
use super::StudyError;
use crate::fem::{ElementFamily, HexElement};
use crate::problems::column::ColumnState;
use crate::study::vtk::{self, pad3, PvdEntry, UnstructuredGrid};
use std::path::{Path, PathBuf};

/// Which load steps to write.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct VtkOptions {
    /// Also write every `every`-th load step (0: only the initial and the final state).
    pub every: usize,
}

/// Folder of a study's VTK files.
pub fn vtk_dir(study_dir: &Path) -> PathBuf {
    study_dir.join("vtk")
}

/// `<study_dir>/vtk/<case_id>/`, emptied of an earlier run's files.
fn fresh_case_dir(study_dir: &Path, case_id: &str) -> Result<PathBuf, StudyError> {
    let case_dir = confined(&vtk_dir(study_dir), case_id)?;
    if case_dir.exists() {
        std::fs::remove_dir_all(&case_dir).map_err(|e| StudyError::io(&case_dir, e))?;
    }
    std::fs::create_dir_all(&case_dir).map_err(|e| StudyError::io(&case_dir, e))?;
    Ok(case_dir)
}

/// `.pvd` file of a case.
pub fn pvd_path(study_dir: &Path, case_id: &str) -> Result<PathBuf, StudyError> {
    confined(&vtk_dir(study_dir), &format!("{case_id}.pvd"))
}

/// Writes the VTK files of one column case as the solver reports its steps.
pub struct ColumnVtkWriter {
    root: PathBuf,
    case_id: String,
    case_dir: PathBuf,
    load_steps: usize,
    options: VtkOptions,
    entries: Vec<PvdEntry>,
    /// Σ Δu at the grid nodes (MPM).
    total_du: Vec<f64>,
    /// The last state seen but not yet written (the final step is always written).
    pending: Option<(usize, UnstructuredGrid, UnstructuredGrid)>,
    error: Option<StudyError>,
}

impl ColumnVtkWriter {
    /// A writer for case `case_id` into `<study_dir>/vtk/`; stale files of the case are
    /// removed.
    pub fn new(
        study_dir: &Path,
        case_id: &str,
        load_steps: usize,
        options: VtkOptions,
    ) -> Result<Self, StudyError> {
        let case_dir = fresh_case_dir(study_dir, case_id)?;
        Ok(Self {
            root: vtk_dir(study_dir),
            case_id: case_id.to_string(),
            case_dir,
            load_steps: load_steps.max(1),
            options,
            entries: vec![],
            total_du: vec![],
            pending: None,
            error: None,
        })
    }

    /// Record the solver state after `step` (0: initial).
    pub fn observe(&mut self, step: usize, state: ColumnState<'_>) {
        if self.error.is_some() {
            return;
        }
        let (points, grid) = match state {
            ColumnState::Mpm(s) => self.material_point_parts(step, s),
            ColumnState::Mpm3(s) => self.material_point_parts(step, s),
            ColumnState::Fem(s) => {
                let g = &s.gauss;
                let x: Vec<[f64; 3]> = (0..g.len())
                    .map(|p| pad3(&nalgebra::SVector::<f64, 1>::new(s.gauss_point_map(p).0)))
                    .collect();
                let x0: Vec<[f64; 3]> = g.position0.iter().map(|&z| [z, 0.0, 0.0]).collect();
                let points = vtk::gauss_points(&x, &x0, &g.volume0, &g.state, s.model().internal_variables());
                (points, vtk::line_mesh(&s.mesh, &s.mesh0))
            }
            ColumnState::Fem3(s) => {
                let g = &s.gauss;
                let x: Vec<[f64; 3]> = (0..g.len()).map(|p| pad3(&s.gauss_point_position(p))).collect();
                let x0: Vec<[f64; 3]> = g.position0.iter().map(pad3).collect();
                let points = vtk::gauss_points(&x, &x0, &g.volume0, &g.state, s.model().internal_variables());
                (points, vtk::element_mesh(&s.mesh, &s.mesh0))
            }
        };
        let due = step == 0 || (self.options.every > 0 && step % self.options.every == 0);
        if due {
            self.pending = None;
            self.write(step, &points, &grid);
        } else {
            self.pending = Some((step, points, grid));
        }
    }

    /// The points and the background grid of a material point solver after `step`, the grid
    /// with the step's nodal displacement increment and the running sum Σ Δu (zeros at step 0
    /// and while the solver's increment is not sized to the grid).
    fn material_point_parts<const D: usize>(
        &mut self,
        step: usize,
        s: &crate::mpm::MpmSolver<D>,
    ) -> (UnstructuredGrid, UnstructuredGrid) {
        let len = D * s.grid.num_nodes();
        let du = s.step_increment();
        let zeros;
        let (inc, total) = if step == 0 || du.len() != len {
            zeros = vec![0.0; len];
            (&zeros[..], &zeros[..])
        } else {
            self.total_du.resize(len, 0.0);
            self.total_du.iter_mut().zip(du).for_each(|(t, d)| *t += d);
            (du, &self.total_du[..])
        };
        let grid = vtk::background_grid(
            &s.grid,
            &[("displacement_increment", inc), ("displacement", total)],
        );
        (
            vtk::material_points(&s.points, s.model().internal_variables()),
            grid,
        )
    }

    fn write(&mut self, step: usize, points: &UnstructuredGrid, grid: &UnstructuredGrid) {
        let time = step as f64 / self.load_steps as f64;
        for (part, (stem, data)) in [("points", points), ("grid", grid)].into_iter().enumerate() {
            let name = format!("{stem}_{step:05}.vtu");
            let path = self.case_dir.join(&name);
            if let Err(e) = vtk::write_vtu(&path, data) {
                self.error = Some(StudyError::io(&path, e));
                return;
            }
            self.entries.push(PvdEntry {
                time,
                part,
                file: format!("{}/{name}", self.case_id),
            });
        }
    }

    /// Write the last state if it is still pending, and the `.pvd` collection.
    pub fn finish(mut self) -> Result<PathBuf, StudyError> {
        if let Some((step, p, g)) = self.pending.take() {
            self.write(step, &p, &g);
        }
        if let Some(e) = self.error {
            return Err(e);
        }
        let path = confined(&self.root, &format!("{}.pvd", self.case_id))?;
        vtk::write_pvd(&path, &self.entries).map_err(|e| StudyError::io(&path, e))?;
        Ok(path)
    }
}

/// A material point domain: its centre and half-lengths (z zero in 2D).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DomainBox {
    pub centre: [f64; 3],
    pub half: [f64; 3],
}

impl DomainBox {
    /// The domain centred at `centre` with half-lengths `half`, in D = 2 or 3 dimensions (a
    /// plane domain lies in z = 0 with no half-length along z).
    pub fn new<const D: usize>(centre: [f64; D], half: [f64; D]) -> Self {
        let pad = |v: [f64; D]| std::array::from_fn(|a| if a < D { v[a] } else { 0.0 });
        DomainBox {
            centre: pad(centre),
            half: pad(half),
        }
    }
}

impl From<[f64; 4]> for DomainBox {
    /// A plane domain from (x, y, half-length x, half-length y).
    fn from(d: [f64; 4]) -> Self {
        DomainBox {
            centre: [d[0], d[1], 0.0],
            half: [d[2], d[3], 0.0],
        }
    }
}

/// One frame of a case for ParaView: material point domains at `time` (the load factor),
/// with per-point scalars; quadrilaterals in 2D, hexahedra in 3D.
#[derive(Debug, Clone, PartialEq)]
pub struct DomainFrame {
    pub time: f64,
    pub step: usize,
    /// 2 or 3.
    pub dimension: usize,
    pub domains: Vec<DomainBox>,
    pub scalars: Vec<(String, Vec<f64>)>,
}

/// The domains of a frame as quadrilaterals (2D) or hexahedra (3D, VTK node order): cell `p`
/// is point `p`'s domain, its scalars as cell data, so that ParaView draws the GIMP domains
/// as the paper's figures do.
pub fn domains_grid(frame: &DomainFrame) -> UnstructuredGrid {
    // The Hex8 corners are in VTK order, and their first four are the quadrilateral's
    // (counter-clockwise; a plane domain has no half-length along z).
    let corners = HexElement::Hex8.local_nodes();
    let (k, kind) = if frame.dimension == 3 {
        (8, vtk::cell::HEXAHEDRON)
    } else {
        (4, vtk::cell::QUAD)
    };
    let mut pts = Vec::with_capacity(k * frame.domains.len());
    for d in &frame.domains {
        for c in &corners[..k] {
            pts.push(std::array::from_fn(|a| d.centre[a] + c[a] * d.half[a]));
        }
    }
    let mut g = UnstructuredGrid {
        points: pts,
        ..UnstructuredGrid::default()
    };
    let mut nodes = Vec::with_capacity(k);
    for p in 0..frame.domains.len() {
        nodes.clear();
        nodes.extend(k * p..k * (p + 1));
        g.push_cell(kind, &nodes);
    }
    let cell = |name: &str, components: usize, values: Vec<f64>| vtk::DataArray {
        name: name.to_string(),
        components,
        values,
    };
    g.cell_data.push(cell(
        "centre",
        3,
        frame.domains.iter().flat_map(|d| d.centre).collect(),
    ));
    g.cell_data.push(cell(
        "half_length",
        3,
        frame.domains.iter().flat_map(|d| d.half).collect(),
    ));
    for (name, values) in &frame.scalars {
        g.cell_data.push(cell(name, 1, values.clone()));
    }
    g
}

/// The background grid of a case for [`write_domain_frames`]: `plane()`'s grid in 2D,
/// `solid()`'s in 3D; `None` if the case has none (a rejected input: its frames are written
/// alone).
pub fn grid_part<E>(
    dimension: usize,
    plane: impl FnOnce() -> Result<crate::mesh::grid::Grid<2>, E>,
    solid: impl FnOnce() -> Result<crate::mesh::grid::Grid<3>, E>,
) -> Option<UnstructuredGrid> {
    if dimension == 3 {
        solid().ok().map(|g| vtk::background_grid(&g, &[]))
    } else {
        plane().ok().map(|g| vtk::background_grid(&g, &[]))
    }
}

/// Write `<study_dir>/vtk/<case_id>.pvd` and one `.vtu` per frame (`<case_id>/domains_<step>.vtu`,
/// part 0 of each time step), replacing stale files of the case. With `grid`, the background
/// grid is written once (`<case_id>/grid.vtu`, its elements as quadrilaterals or hexahedra)
/// and is part 1 of every time step: an MPM grid never moves, so one file serves them all.
pub fn write_domain_frames(
    study_dir: &Path,
    case_id: &str,
    frames: &[DomainFrame],
    grid: Option<&UnstructuredGrid>,
) -> Result<PathBuf, StudyError> {
    let case_dir = fresh_case_dir(study_dir, case_id)?;
    let grid_file = match grid {
        Some(g) => {
            let path = case_dir.join("grid.vtu");
            vtk::write_vtu(&path, g).map_err(|e| StudyError::io(&path, e))?;
            Some(format!("{case_id}/grid.vtu"))
        }
        None => None,
    };
    let mut entries = vec![];
    for f in frames {
        let name = format!("domains_{:05}.vtu", f.step);
        let path = case_dir.join(&name);
        vtk::write_vtu(&path, &domains_grid(f)).map_err(|e| StudyError::io(&path, e))?;
        entries.push(PvdEntry {
            time: f.time,
            part: 0,
            file: format!("{case_id}/{name}"),
        });
        if let Some(file) = &grid_file {
            entries.push(PvdEntry {
                time: f.time,
                part: 1,
                file: file.clone(),
            });
        }
    }
    let path = pvd_path(study_dir, case_id)?;
    vtk::write_pvd(&path, &entries).map_err(|e| StudyError::io(&path, e))?;
    Ok(path)
}
