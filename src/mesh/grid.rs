//! Regular background grid of `D`-dimensional linear elements (two-noded lines in 1D,
//! four-noded quadrilaterals in 2D), aligned with the coordinate axes (paper §4).
//!
//! Nodes are numbered with axis 0 fastest: `node = i0 + n0 * (i1 + n1 * i2)`.

use crate::solver::error::{require_count, require_finite, require_positive, InputError};
use nalgebra::SVector;

/// Most nodes a grid may have (checked before anything per node is allocated).
pub const MAX_GRID_NODES: usize = 20_000_000;

/// Axis-aligned regular grid.
#[derive(Debug, Clone, PartialEq)]
pub struct Grid<const D: usize> {
    origin: [f64; D],
    spacing: [f64; D],
    cells: [usize; D],
}

impl<const D: usize> Grid<D> {
    /// A grid starting at `origin` with `cells[a]` elements of size `spacing[a]` along axis `a`.
    pub fn try_new(origin: [f64; D], spacing: [f64; D], cells: [usize; D]) -> Result<Self, InputError> {
        if D == 0 || D > 3 {
            return Err(InputError::new("grid.dimension", D, "1, 2 or 3"));
        }
        for a in 0..D {
            require_finite(&format!("grid.origin[{a}]"), origin[a])?;
            require_positive(&format!("grid.spacing[{a}]"), spacing[a])?;
            require_count(&format!("grid.cells[{a}]"), cells[a], 1)?;
            if cells[a] > 50_000_000 {
                return Err(InputError::new(
                    format!("grid.cells[{a}]"),
                    cells[a],
                    "must be <= 50000000",
                ));
            }
        }
        // Nodal vectors (D values per node) are allocated every load step.
        let nodes = cells.iter().try_fold(1usize, |n, &c| n.checked_mul(c + 1));
        if nodes.is_none_or(|n| n > MAX_GRID_NODES) {
            return Err(InputError::new(
                "grid.cells",
                format!("{cells:?}"),
                format!("the grid must have at most {MAX_GRID_NODES} nodes"),
            ));
        }
        Ok(Self {
            origin,
            spacing,
            cells,
        })
    }

    /// The flat index of the cell holding `x` (a point outside, the nearest cell's; on a
    /// cell face, the upper cell's unless the face is the grid's upper bound).
    pub fn cell_holding(&self, x: &SVector<f64, D>) -> usize {
        let mut flat = 0;
        for a in (0..D).rev() {
            let t = ((x[a] - self.origin[a]) / self.spacing[a]).floor();
            let i = if t > 0.0 {
                (t as usize).min(self.cells[a] - 1)
            } else {
                0
            };
            flat = flat * self.cells[a] + i;
        }
        flat
    }

    /// Coordinates of the lower corner (node 0).
    pub fn origin(&self) -> [f64; D] {
        self.origin
    }
    /// Element size h along each axis.
    pub fn spacing(&self) -> [f64; D] {
        self.spacing
    }
    /// Number of elements along each axis.
    pub fn cells(&self) -> [usize; D] {
        self.cells
    }
    /// Upper corner of the grid along `axis`.
    pub fn upper(&self, axis: usize) -> f64 {
        self.origin[axis] + self.spacing[axis] * self.cells[axis] as f64
    }
    /// Number of nodes along `axis`.
    pub fn nodes_along(&self, axis: usize) -> usize {
        self.cells[axis] + 1
    }
    /// Total number of nodes.
    pub fn num_nodes(&self) -> usize {
        (0..D).map(|a| self.nodes_along(a)).product()
    }
    /// Total number of elements.
    pub fn num_cells(&self) -> usize {
        self.cells.iter().product()
    }
    /// Flat node number from per-axis node indices.
    #[inline]
    pub fn node_index(&self, idx: [usize; D]) -> usize {
        let mut flat = 0;
        for a in (0..D).rev() {
            flat = flat * self.nodes_along(a) + idx[a];
        }
        flat
    }
    /// Per-axis node indices of a flat node number.
    #[inline]
    pub fn node_coords(&self, mut flat: usize) -> [usize; D] {
        let mut idx = [0; D];
        for (a, i) in idx.iter_mut().enumerate() {
            let n = self.nodes_along(a);
            *i = flat % n;
            flat /= n;
        }
        idx
    }
    /// Position of a node.
    pub fn node_position(&self, flat: usize) -> SVector<f64, D> {
        let idx = self.node_coords(flat);
        SVector::<f64, D>::from_fn(|a, _| self.origin[a] + self.spacing[a] * idx[a] as f64)
    }
    /// Is the closed box `[x - r, x + r]` inside the grid?
    pub fn contains_box(&self, x: &SVector<f64, D>, half: &SVector<f64, D>) -> bool {
        (0..D).all(|a| {
            let tol = 1e-12 * self.spacing[a];
            x[a].is_finite()
                && half[a].is_finite()
                && x[a] - half[a] >= self.origin[a] - tol
                && x[a] + half[a] <= self.upper(a) + tol
        })
    }
    /// Flat node numbers of the nodes whose coordinate along `axis` equals the grid's
    /// lower (`upper == false`) or upper boundary.
    pub fn boundary_nodes(&self, axis: usize, upper: bool) -> Vec<usize> {
        let target = if upper { self.cells[axis] } else { 0 };
        (0..self.num_nodes())
            .filter(|&n| self.node_coords(n)[axis] == target)
            .collect()
    }
    /// Flat node numbers of the nodes lying on the plane `x[axis] = value` (within 1e-9 h).
    pub fn nodes_on_plane(&self, axis: usize, value: f64) -> Vec<usize> {
        let tol = 1e-9 * self.spacing[axis];
        (0..self.num_nodes())
            .filter(|&n| (self.node_position(n)[axis] - value).abs() <= tol)
            .collect()
    }
}

impl crate::solver::multigrid::NodeGeometry {
    /// The nodes of a background grid.
    pub fn of_grid<const D: usize>(grid: &Grid<D>) -> Self {
        let h = grid.spacing();
        crate::solver::multigrid::NodeGeometry {
            dim: D,
            positions: (0..grid.num_nodes())
                .map(|n| {
                    let x = grid.node_position(n);
                    std::array::from_fn(|a| if a < D { x[a] } else { 0.0 })
                })
                .collect(),
            spacing: std::array::from_fn(|a| if a < D { h[a] } else { 1.0 }),
        }
    }
}
