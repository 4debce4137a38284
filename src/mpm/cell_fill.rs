//! The material volume fraction of each grid cell, from which the ghost penalty
//! ([`crate::discretise::ghost`]) finds the cut cells.

use crate::basis::{BasisFamily, GridAxis};
use crate::mesh::grid::Grid;
use crate::mpm::particles::MaterialPoints;

/// Material volume fraction of every cell of `grid` (cell-major, axis 0 fastest): for the
/// families with a fill box ([`BasisFamily::fill_box`]: GIMP's domain, CPDI's corner bounds,
/// the B-splines' reach less a cell) the part of each box cut to the grid (Ω_p ∩ Ω) inside the
/// cell, weighted by V_p / |Ω_p ∩ Ω| so that a point contributes its volume; for MPM the
/// point's volume in the cell that holds it.
pub fn cell_fill<const D: usize>(
    grid: &Grid<D>,
    family: &dyn BasisFamily<D>,
    points: &MaterialPoints<D>,
    fill: &mut Vec<f64>,
) {
    let (o, h, c) = (grid.origin(), grid.spacing(), grid.cells());
    let axes: [GridAxis; D] = std::array::from_fn(|a| GridAxis::of(grid, a));
    let cell_volume: f64 = h.iter().product();
    fill.clear();
    fill.resize(grid.num_cells(), 0.0);
    // Per axis: first cell and overlap lengths (as many cells per axis as the basis allows).
    const MAX_CELLS: usize = crate::basis::MAX_AXIS_NODES - 1;
    let mut first = [0usize; D];
    let mut len = [0usize; D];
    let mut overlap = [[0.0f64; MAX_CELLS]; D];
    for p in 0..points.len() {
        let view = points.view(p);
        let v = points.state[p].volume;
        let boxed = family.fill_box(grid, &view);
        let x = view.position;
        let mut measure = 1.0;
        for a in 0..D {
            let n = c[a];
            let (lo, hi) = match boxed {
                None => {
                    let e = axes[a].cell_of(x[a]);
                    (e as f64 + 0.5, e as f64 + 0.5)
                }
                Some((b_lo, b_hi)) => (
                    ((b_lo[a] - o[a]) / h[a]).max(0.0),
                    ((b_hi[a] - o[a]) / h[a]).min(n as f64),
                ),
            };
            let e_lo = (lo.floor().max(0.0) as usize).min(n - 1);
            let e_hi = ((hi.ceil().max(1.0) as usize) - 1).min(n - 1).max(e_lo);
            first[a] = e_lo;
            len[a] = (e_hi - e_lo + 1).min(MAX_CELLS);
            if boxed.is_none() || hi <= lo {
                len[a] = 1;
                overlap[a][0] = 1.0;
            } else {
                for k in 0..len[a] {
                    let e = (e_lo + k) as f64;
                    overlap[a][k] = (hi.min(e + 1.0) - lo.max(e)).max(0.0);
                }
                measure *= hi - lo;
            }
        }
        if measure.is_nan() || measure <= 0.0 {
            continue;
        }
        let share = v / (measure * cell_volume);
        let count: usize = len.iter().product();
        for k in 0..count {
            let mut rest = k;
            let mut w = share;
            let mut flat = 0;
            let mut stride = 1;
            for a in 0..D {
                let i = rest % len[a];
                rest /= len[a];
                w *= overlap[a][i];
                flat += (first[a] + i) * stride;
                stride *= c[a];
            }
            fill[flat] += w;
        }
    }
}
