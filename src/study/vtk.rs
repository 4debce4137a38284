//! ParaView output: a small VTK XML writer for unstructured grids (`.vtu`, ascii) and
//! collections (`.pvd`), and builders for the solver's objects.
//!
//! Numbers are written in Rust's shortest round-trip scientific form (`{:e}`), so a reader
//! gets back exactly the `f64` that was written. Coordinates are padded to three components:
//! axis a of a `D`-dimensional problem is VTK component a (the 1D column lies along x).
//!
//! Builders: [`material_points`] (vertex cells with position, domain extent, volume, σ, τ, F,
//! plastic multiplier, displacement), [`gauss_points`] (the same fields for FEM Gauss points,
//! without domains), [`background_grid`] (lines / quads / hexahedra with nodal vectors) and
//! [`line_mesh`] and [`element_mesh`] (FEM meshes with nodal displacement). Files are written with
//! [`crate::study::atomic_file::write_atomic`].
//!
//! # References
//! VTK File Formats, "XML File Formats" (Kitware, VTK User's Guide §19); ParaView's `.pvd`
//! collection format.

use crate::fem::{ElementFamily, ElementMesh, LineElement, LineMesh};
use crate::material::constitutive::InternalVariable;
use crate::material::kinematics::PointState;
use crate::mesh::grid::Grid;
use crate::mpm::particles::MaterialPoints;
use crate::study::atomic_file::write_atomic;
use nalgebra::{Matrix3, SVector};
use std::fmt::Write as _;
use std::path::Path;

/// VTK cell type ids.
pub mod cell {
    pub const VERTEX: u8 = 1;
    pub const LINE: u8 = 3;
    pub const QUAD: u8 = 9;
    pub const HEXAHEDRON: u8 = 12;
    pub const QUADRATIC_EDGE: u8 = 21;
    pub const QUADRATIC_QUAD: u8 = 23;
    pub const QUADRATIC_HEXAHEDRON: u8 = 25;
}

/// A named array of `components` values per point or per cell.
#[derive(Debug, Clone, PartialEq)]
pub struct DataArray {
    pub name: String,
    pub components: usize,
    pub values: Vec<f64>,
}

/// One piece of an unstructured grid.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct UnstructuredGrid {
    pub points: Vec<[f64; 3]>,
    /// Node lists of all cells, concatenated.
    pub connectivity: Vec<usize>,
    /// End of each cell's node list in `connectivity`.
    pub offsets: Vec<usize>,
    pub types: Vec<u8>,
    pub point_data: Vec<DataArray>,
    pub cell_data: Vec<DataArray>,
}

pub use crate::material::tensor::pad3;

/// Row-major components of a 3×3 tensor (VTK's 9-component tensor layout).
fn tensor9(m: &Matrix3<f64>) -> [f64; 9] {
    let mut out = [0.0; 9];
    for i in 0..3 {
        for j in 0..3 {
            out[3 * i + j] = m[(i, j)];
        }
    }
    out
}

fn xml_escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

impl UnstructuredGrid {
    /// Points with one vertex cell each (what ParaView needs to draw them).
    pub fn vertices(points: Vec<[f64; 3]>) -> Self {
        let n = points.len();
        Self {
            points,
            connectivity: (0..n).collect(),
            offsets: (1..=n).collect(),
            types: vec![cell::VERTEX; n],
            ..Self::default()
        }
    }

    /// Append a cell of VTK type `kind` on `nodes`.
    pub fn push_cell(&mut self, kind: u8, nodes: &[usize]) {
        self.connectivity.extend_from_slice(nodes);
        self.offsets.push(self.connectivity.len());
        self.types.push(kind);
    }

    /// Add a point array from per-point fixed-size rows.
    pub fn add_point_rows<const N: usize>(&mut self, name: &str, rows: impl IntoIterator<Item = [f64; N]>) {
        self.point_data.push(DataArray {
            name: name.to_string(),
            components: N,
            values: rows.into_iter().flatten().collect(),
        });
    }

    /// Add a scalar point array.
    pub fn add_point_scalars(&mut self, name: &str, values: impl IntoIterator<Item = f64>) {
        self.add_point_rows(name, values.into_iter().map(|v| [v]));
    }

    /// Check that every array has one row per point / cell and every cell's nodes exist.
    pub fn check(&self) -> Result<(), String> {
        let np = self.points.len();
        let nc = self.types.len();
        if self.offsets.len() != nc {
            return Err(format!("{} offsets for {nc} cells", self.offsets.len()));
        }
        if self.offsets.last().copied().unwrap_or(0) != self.connectivity.len() {
            return Err("last offset must equal the connectivity length".into());
        }
        if let Some(&n) = self.connectivity.iter().find(|&&n| n >= np) {
            return Err(format!("cell node {n} >= {np} points"));
        }
        for (arrays, rows, what) in [(&self.point_data, np, "point"), (&self.cell_data, nc, "cell")] {
            for a in arrays {
                if a.components == 0 || a.values.len() != rows * a.components {
                    return Err(format!(
                        "{what} array `{}`: {} values for {rows} rows of {}",
                        a.name,
                        a.values.len(),
                        a.components
                    ));
                }
            }
        }
        Ok(())
    }

    /// The `.vtu` document (ascii data).
    pub fn to_xml(&self) -> String {
        let mut s = String::with_capacity(64 * (self.points.len() + 1) * (self.point_data.len() + 2));
        s.push_str("<?xml version=\"1.0\"?>\n");
        s.push_str(
            "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n",
        );
        s.push_str("<UnstructuredGrid>\n");
        let _ = writeln!(
            s,
            "<Piece NumberOfPoints=\"{}\" NumberOfCells=\"{}\">",
            self.points.len(),
            self.types.len()
        );
        s.push_str("<Points>\n");
        write_array(&mut s, "Float64", "Points", 3, self.points.iter().flatten());
        s.push_str("</Points>\n<Cells>\n");
        write_array(&mut s, "Int64", "connectivity", 1, self.connectivity.iter());
        write_array(&mut s, "Int64", "offsets", 1, self.offsets.iter());
        write_array(&mut s, "UInt8", "types", 1, self.types.iter());
        s.push_str("</Cells>\n");
        for (tag, arrays) in [("PointData", &self.point_data), ("CellData", &self.cell_data)] {
            let _ = writeln!(s, "<{tag}>");
            for a in arrays {
                write_array(&mut s, "Float64", &a.name, a.components, a.values.iter());
            }
            let _ = writeln!(s, "</{tag}>");
        }
        s.push_str("</Piece>\n</UnstructuredGrid>\n</VTKFile>\n");
        s
    }
}

/// Numbers print in shortest round-trip form: floats as `{:e}`, integers plainly.
trait VtkNumber {
    fn put(&self, s: &mut String);
}
impl VtkNumber for f64 {
    fn put(&self, s: &mut String) {
        let _ = write!(s, "{self:e}");
    }
}
impl VtkNumber for usize {
    fn put(&self, s: &mut String) {
        let _ = write!(s, "{self}");
    }
}
impl VtkNumber for u8 {
    fn put(&self, s: &mut String) {
        let _ = write!(s, "{self}");
    }
}

fn write_array<'a, T: VtkNumber + 'a>(
    s: &mut String,
    ty: &str,
    name: &str,
    components: usize,
    values: impl Iterator<Item = &'a T>,
) {
    let _ = writeln!(
        s,
        "<DataArray type=\"{ty}\" Name=\"{}\" NumberOfComponents=\"{components}\" format=\"ascii\">",
        xml_escape(name)
    );
    for (i, v) in values.enumerate() {
        if i > 0 {
            s.push(if i % (components * 4).max(6) == 0 {
                '\n'
            } else {
                ' '
            });
        }
        v.put(s);
    }
    s.push_str("\n</DataArray>\n");
}

/// Write a `.vtu` file atomically after checking the grid's consistency.
pub fn write_vtu(path: &Path, grid: &UnstructuredGrid) -> std::io::Result<()> {
    grid.check().map_err(std::io::Error::other)?;
    write_atomic(path, grid.to_xml().as_bytes())
}

/// One dataset of a `.pvd` collection: `file` (relative to the `.pvd`) at `time`, as `part`.
#[derive(Debug, Clone, PartialEq)]
pub struct PvdEntry {
    pub time: f64,
    pub part: usize,
    pub file: String,
}

/// The `.pvd` document.
pub fn pvd_xml(entries: &[PvdEntry]) -> String {
    let mut s = String::from(
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n<Collection>\n",
    );
    for e in entries {
        let _ = writeln!(
            s,
            "<DataSet timestep=\"{:e}\" group=\"\" part=\"{}\" file=\"{}\"/>",
            e.time,
            e.part,
            xml_escape(&e.file)
        );
    }
    s.push_str("</Collection>\n</VTKFile>\n");
    s
}

/// Write a `.pvd` collection atomically.
pub fn write_pvd(path: &Path, entries: &[PvdEntry]) -> std::io::Result<()> {
    write_atomic(path, pvd_xml(entries).as_bytes())
}

/// Point arrays shared by material and Gauss points: volume, Cauchy stress σ, Kirchhoff
/// stress τ, deformation gradient F (row-major 9 components), and one array per internal
/// variable the model declares (`internal`, by name: von Mises' `plastic_multiplier`).
fn add_state_arrays(g: &mut UnstructuredGrid, states: &[PointState], internal: &[InternalVariable]) {
    g.add_point_scalars("volume", states.iter().map(|s| s.volume));
    g.add_point_rows("cauchy_stress", states.iter().map(|s| tensor9(&s.cauchy())));
    g.add_point_rows("kirchhoff_stress", states.iter().map(|s| tensor9(&s.tau)));
    g.add_point_rows("deformation_gradient", states.iter().map(|s| tensor9(&s.f)));
    for (i, v) in internal.iter().enumerate() {
        g.add_point_scalars(v.name, states.iter().map(|s| s.material.internal.get(i)));
    }
}

/// Material points as vertices at their current positions, with `position0`,
/// `displacement`, `domain_extent` (current domain lengths l_p = 2 × half-length per axis),
/// `volume0`, and the state arrays (`volume`, `cauchy_stress`, `kirchhoff_stress`,
/// `deformation_gradient`, then the model's internal variables `internal`).
pub fn material_points<const D: usize>(
    pts: &MaterialPoints<D>,
    internal: &[InternalVariable],
) -> UnstructuredGrid {
    let mut g = UnstructuredGrid::vertices(pts.position.iter().map(pad3).collect());
    g.add_point_rows("position0", pts.position0.iter().map(pad3));
    g.add_point_rows("displacement", (0..pts.len()).map(|p| pad3(&pts.displacement(p))));
    g.add_point_rows("domain_extent", pts.half_length.iter().map(|h| pad3(&(h * 2.0))));
    g.add_point_scalars("volume0", pts.volume0.iter().copied());
    add_state_arrays(&mut g, &pts.state, internal);
    g
}

/// Gauss points as vertices at their current positions with `position0`, `displacement`,
/// `volume0` and the state arrays (see [`material_points`]).
pub fn gauss_points(
    position: &[[f64; 3]],
    position0: &[[f64; 3]],
    volume0: &[f64],
    states: &[PointState],
    internal: &[InternalVariable],
) -> UnstructuredGrid {
    let mut g = UnstructuredGrid::vertices(position.to_vec());
    g.add_point_rows("position0", position0.iter().copied());
    g.add_point_rows(
        "displacement",
        position
            .iter()
            .zip(position0)
            .map(|(x, x0)| [x[0] - x0[0], x[1] - x0[1], x[2] - x0[2]]),
    );
    g.add_point_scalars("volume0", volume0.iter().copied());
    add_state_arrays(&mut g, states, internal);
    g
}

/// The background grid's elements (lines in 1D, quads in 2D, hexahedra in 3D) with nodal
/// vector arrays `nodal` (node-major, `D` values per node, as the solver stores them).
pub fn background_grid<const D: usize>(grid: &Grid<D>, nodal: &[(&str, &[f64])]) -> UnstructuredGrid {
    let mut g = UnstructuredGrid {
        points: (0..grid.num_nodes())
            .map(|n| pad3(&grid.node_position(n)))
            .collect(),
        ..UnstructuredGrid::default()
    };
    let cells = grid.cells();
    let corners: &[[usize; 3]] = match D {
        1 => &[[0, 0, 0], [1, 0, 0]],
        2 => &[[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]],
        _ => &[
            [0, 0, 0],
            [1, 0, 0],
            [1, 1, 0],
            [0, 1, 0],
            [0, 0, 1],
            [1, 0, 1],
            [1, 1, 1],
            [0, 1, 1],
        ],
    };
    let kind = [cell::LINE, cell::QUAD, cell::HEXAHEDRON][D.clamp(1, 3) - 1];
    let mut nodes = Vec::with_capacity(corners.len());
    for c in 0..grid.num_cells() {
        let mut idx = [0usize; D];
        let mut rest = c;
        for a in 0..D {
            idx[a] = rest % cells[a];
            rest /= cells[a];
        }
        nodes.clear();
        for corner in corners {
            let mut j = idx;
            for a in 0..D {
                j[a] += corner[a];
            }
            nodes.push(grid.node_index(j));
        }
        g.push_cell(kind, &nodes);
    }
    for (name, values) in nodal {
        g.add_point_rows(
            name,
            values
                .chunks(D)
                .map(|v| pad3(&SVector::<f64, D>::from_column_slice(v))),
        );
    }
    g
}

/// An FEM line mesh in its current configuration (two-node lines or three-node quadratic
/// edges) with nodal `position0` and `displacement` relative to `mesh0`.
pub fn line_mesh(mesh: &LineMesh, mesh0: &LineMesh) -> UnstructuredGrid {
    let mut g = UnstructuredGrid {
        points: mesh.nodes.iter().map(|&x| [x, 0.0, 0.0]).collect(),
        ..UnstructuredGrid::default()
    };
    for e in 0..mesh.num_elements() {
        let first = mesh.first_node(e);
        match mesh.element {
            LineElement::Linear => g.push_cell(cell::LINE, &[first, first + 1]),
            // VTK orders a quadratic edge as end, end, middle.
            LineElement::Quadratic => g.push_cell(cell::QUADRATIC_EDGE, &[first, first + 2, first + 1]),
        }
    }
    g.add_point_rows("position0", mesh0.nodes.iter().map(|&x| [x, 0.0, 0.0]));
    g.add_point_rows(
        "displacement",
        mesh.nodes
            .iter()
            .zip(&mesh0.nodes)
            .map(|(x, x0)| [x - x0, 0.0, 0.0]),
    );
    g
}

/// The VTK cell of an element with `nodes` nodes in `dim` dimensions: our Q4, Q8, Hex8 and
/// Hex20 node tables are VTK's (corners, then mid-edge nodes in VTK's edge order).
fn element_cell(dim: usize, nodes: usize) -> u8 {
    match (dim, nodes) {
        (2, 4) => cell::QUAD,
        (2, 8) => cell::QUADRATIC_QUAD,
        (3, 8) => cell::HEXAHEDRON,
        (3, 20) => cell::QUADRATIC_HEXAHEDRON,
        _ => unreachable!("no VTK cell for a {dim}D element of {nodes} nodes"),
    }
}

/// A quadrilateral or hexahedral FEM mesh in its current configuration (`mesh`) with nodal
/// `position0` and `displacement` relative to `mesh0`.
pub fn element_mesh<const D: usize, E: ElementFamily<D>>(
    mesh: &ElementMesh<D, E>,
    mesh0: &ElementMesh<D, E>,
) -> UnstructuredGrid {
    let mut g = UnstructuredGrid {
        points: mesh.nodes.iter().map(pad3).collect(),
        ..UnstructuredGrid::default()
    };
    let kind = element_cell(D, mesh.element.nodes_per_element());
    for e in 0..mesh.num_elements() {
        g.push_cell(kind, mesh.element_nodes(e));
    }
    g.add_point_rows("position0", mesh0.nodes.iter().map(pad3));
    g.add_point_rows(
        "displacement",
        mesh.nodes.iter().zip(&mesh0.nodes).map(|(x, x0)| pad3(&(x - x0))),
    );
    g
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn vtu_lists_every_array_and_round_trips_numbers() {
        let mut g = UnstructuredGrid::vertices(vec![[0.1, 0.0, 0.0], [1.0 / 3.0, 2.0, 0.0]]);
        g.add_point_scalars("s", [1e-300, -2.5]);
        g.check().unwrap();
        let xml = g.to_xml();
        assert!(xml.contains("Name=\"s\""));
        assert!(xml.contains(&format!("{:e}", 1.0 / 3.0)));
        let back: f64 = format!("{:e}", 1.0 / 3.0).parse().unwrap();
        assert_eq!(back, 1.0 / 3.0);
    }

    #[test]
    fn check_rejects_inconsistent_arrays() {
        let mut g = UnstructuredGrid::vertices(vec![[0.0; 3]; 3]);
        g.add_point_scalars("short", [1.0, 2.0]);
        assert!(g.check().unwrap_err().contains("short"));
        let mut g = UnstructuredGrid::vertices(vec![[0.0; 3]; 2]);
        g.push_cell(cell::LINE, &[0, 5]);
        assert!(g.check().is_err());
    }

    #[test]
    fn background_grid_2d_has_quads_on_existing_nodes() {
        let grid = Grid::<2>::try_new([0.0, 0.0], [1.0, 0.5], [3, 2]).unwrap();
        let du = vec![0.25; 2 * grid.num_nodes()];
        let g = background_grid(&grid, &[("du", &du)]);
        g.check().unwrap();
        assert_eq!(g.types, vec![cell::QUAD; 6]);
        assert_eq!(g.points.len(), 12);
    }
}
