//! The point kernels: a point's equations, its spatial gradients (eq 36) and its tangent block
//! (eq 27), and the runs of points that share equations, scattered by column blocks.

use super::local::{row_stretches, spatial_gradients};
use crate::discretise::dofs::{DofMap, SupportTable, MAX_POINT_NODES};
use crate::material::constitutive::ConstitutiveModel;
use crate::material::kinematics::{PointState, PointTrial};
use crate::material::tensor::ij;
use crate::solver::dynamics::{Inertia, MassMatrix};
use nalgebra::SVector;
use rayon::prelude::*;

/// Point `p`'s equations, node by node, D each (`None`: a fixed dof), into `eqs`; returns
/// their count.
#[inline]
pub(super) fn point_equations<const D: usize>(
    table: &SupportTable<D>,
    dofs: &DofMap,
    p: usize,
    eqs: &mut [Option<usize>; MAX_POINT_EQS],
) -> usize {
    let nodes = table.point(p).0;
    for (k, node) in nodes.iter().enumerate() {
        for a in 0..D {
            eqs[k * D + a] = dofs.eq(node * D + a);
        }
    }
    nodes.len() * D
}

/// One point's tangent block K_(a i),(b k) = Σ_jl ∂S_a/∂x_j a_ijkl ∂S_b/∂x_l V (eq 27), plus
/// the consistent mass term `mass` S_a S_b δ_ik, into `kl` column-major (column (b, k) at
/// `(b D + k) md`, md = nodes · D), so that the scatter reads each column contiguously.
///
/// The common node counts (a GIMP point inside one cell or across cells, 2D and 3D) are
/// compiled with the count fixed, so that the loops over the nodes unroll; every entry is
/// the same sum in the same order either way.
#[inline(never)]
fn point_block<const D: usize>(
    gx: &[SVector<f64, D>],
    weights: &[f64],
    a: &nalgebra::SMatrix<f64, 9, 9>,
    v: f64,
    mass: f64,
    kl: &mut [f64],
) {
    match gx.len() {
        4 => point_block_of::<D>(4, gx, weights, a, v, mass, kl),
        8 => point_block_of::<D>(8, gx, weights, a, v, mass, kl),
        9 => point_block_of::<D>(9, gx, weights, a, v, mass, kl),
        27 => point_block_of::<D>(27, gx, weights, a, v, mass, kl),
        m => point_block_of::<D>(m, gx, weights, a, v, mass, kl),
    }
}

/// [`point_block`] for `m` nodes (inlined where `m` is a constant).
#[inline(always)]
fn point_block_of<const D: usize>(
    m: usize,
    gx: &[SVector<f64, D>],
    weights: &[f64],
    a: &nalgebra::SMatrix<f64, 9, 9>,
    v: f64,
    mass: f64,
    kl: &mut [f64],
) {
    let (gx, weights) = (&gx[..m], &weights[..m]);
    let md = m * D;
    let kl = &mut kl[..md * md];
    for kb in 0..m {
        for k in 0..D {
            let mut c = [[0.0; 3]; 3];
            for i in 0..D {
                for j in 0..D {
                    let mut s = 0.0;
                    for l in 0..D {
                        s += a[(ij(i, j), ij(k, l))] * gx[kb][l];
                    }
                    c[i][j] = s * v;
                }
            }
            let out = &mut kl[(kb * D + k) * md..(kb * D + k + 1) * md];
            for ka in 0..m {
                for i in 0..D {
                    let mut sum = 0.0;
                    for j in 0..D {
                        sum += gx[ka][j] * c[i][j];
                    }
                    if i == k && mass != 0.0 {
                        sum += mass * weights[ka] * weights[kb];
                    }
                    out[ka * D + i] = sum;
                }
            }
        }
    }
}

/// Points whose runs of equal equations are cut at multiples of this count: the chunk of
/// points whose blocks an earlier assembly buffered at once, kept so that every entry sums
/// the same terms in the same order as before (the tangents are bit for bit those of the
/// committed studies). Not tuned.
const RUN_WINDOW: usize = 4096;

/// Most equations one point reaches (D ≤ 3).
pub(super) const MAX_POINT_EQS: usize = MAX_POINT_NODES * 3;

/// What forms a point's tangent block: the step's supports, equations, model and trial
/// states.
pub(super) struct PointKernel<'a, const D: usize> {
    pub(super) table: &'a SupportTable<D>,
    pub(super) dofs: &'a DofMap,
    pub(super) model: &'a dyn ConstitutiveModel,
    pub(super) states: &'a [PointState],
    pub(super) trials: &'a [Option<PointTrial<D>>],
    pub(super) inertia: Option<Inertia<'a>>,
    /// The F-bar treatment's patches and q, if on.
    pub(super) f_bar: Option<super::fbar::FBarView<'a>>,
}

impl<const D: usize> PointKernel<'_, D> {
    /// Point `p`'s equations ([`point_equations`]); returns their count.
    fn equations(&self, p: usize, eqs: &mut [Option<usize>; MAX_POINT_EQS]) -> usize {
        point_equations(self.table, self.dofs, p, eqs)
    }

    /// Point `p`'s block (eq 27 and the consistent mass) into `kl`, column-major.
    fn block(&self, p: usize, kl: &mut Vec<f64>) {
        let t = self.trials[p].as_ref().expect("evaluated");
        let weights = self.table.point(p).1;
        let mut gx = [SVector::<f64, D>::zeros(); MAX_POINT_NODES];
        let m = spatial_gradients(self.table, p, t, &mut gx);
        let md = m * D;
        kl.resize(md * md, 0.0);
        let a = match &self.f_bar {
            Some(f) => f.point_tangent::<D>(p),
            None => t.spatial_tangent(self.model, &self.states[p]),
        };
        // The inertia term's α m_p S_a S_b δ_ik (consistent mass).
        let mass = self
            .inertia
            .filter(|i| i.mass == MassMatrix::Consistent)
            .map_or(0.0, |i| i.step.tangent_mass_factor() * i.point_masses[p]);
        point_block::<D>(&gx[..m], weights, &a, t.volume, mass, kl);
    }

    /// The starts of the runs of consecutive points with equal equations (the Gauss points of
    /// one element, material points of one cell with the same support), cut at multiples of
    /// [`RUN_WINDOW`], then `n`.
    pub(super) fn runs(&self, n: usize) -> Vec<usize> {
        let windows: Vec<usize> = (0..n).step_by(RUN_WINDOW).collect();
        let mut runs: Vec<usize> = windows
            .into_par_iter()
            .flat_map_iter(|start| {
                let mut starts = vec![];
                let mut previous = [None; MAX_POINT_EQS];
                let mut previous_len = usize::MAX;
                let mut eqs = [None; MAX_POINT_EQS];
                for p in start..(start + RUN_WINDOW).min(n) {
                    let md = self.equations(p, &mut eqs);
                    if md != previous_len || eqs[..md] != previous[..md] {
                        starts.push(p);
                    }
                    previous[..md].copy_from_slice(&eqs[..md]);
                    previous_len = md;
                }
                starts
            })
            .collect();
        runs.push(n);
        runs
    }

    /// Add every run that reaches a column of `block` into those columns: each run's point
    /// blocks summed in point order first, then one update per entry, the run's rows found
    /// as stretches of consecutive equations.
    pub(super) fn add_runs(&self, block: &mut crate::solver::sparse::ColumnBlock<'_>, runs: &[usize]) {
        let (lo, hi) = block.columns();
        let owned = |c: &usize| (lo..hi).contains(c);
        let mut eqs = [None; MAX_POINT_EQS];
        let (mut sum, mut kl, mut stretches) = (Vec::new(), Vec::new(), Vec::new());
        let mut found: Vec<usize> = Vec::new();
        for w in runs.windows(2) {
            let (first, end) = (w[0], w[1]);
            let md = self.equations(first, &mut eqs);
            let eqs = &eqs[..md];
            if !eqs.iter().flatten().any(owned) {
                continue;
            }
            self.block(first, &mut sum);
            for p in first + 1..end {
                self.block(p, &mut kl);
                sum.iter_mut().zip(&kl).for_each(|(s, k)| *s += k);
            }
            if block.by_rows() {
                // The lines are K's rows: the block's rows are added as columns.
                transpose_square(&mut sum, md);
            }
            row_stretches(eqs, &mut stretches);
            // Interior nodes' columns share one shape (the rows of their 3^D neighbours), and
            // a stretch's offset from its column's start depends on where the column's node
            // sits among the point's nodes (a cell's lower corner finds the cell's rows above
            // itself, the upper corner below). So each stretch is first looked for at the
            // offset it had in the last column of the same local node, of this run or an
            // earlier one: one comparison instead of a search (with one offset for all
            // columns, the misses' binary searches took 5 % of a one-thread 3D assembly; 3D
            // compaction at h = 1/7, fastest of 8: 0.68-0.72 -> 0.61 s). A miss (a boundary
            // node, a run of another shape) falls back to the forward scan or the binary
            // search; the entry found is the same.
            let per_node = stretches.len();
            if found.len() < per_node * (md / D) {
                found.resize(per_node * (md / D), usize::MAX);
            }
            for (ci, col) in eqs.iter().enumerate() {
                let Some(col) = col.filter(owned) else { continue };
                let column = &sum[ci * md..(ci + 1) * md];
                let start = block.column_start(col);
                let mut hint = usize::MAX;
                let node = ci / D;
                let found = &mut found[node * per_node..(node + 1) * per_node];
                for (r, offset) in stretches.iter().zip(found.iter_mut()) {
                    if *offset != usize::MAX {
                        hint = start + *offset;
                    }
                    let values = block.stretch_with_hint(r.row, col, r.len, &mut hint);
                    *offset = hint - r.len - start;
                    values
                        .iter_mut()
                        .zip(&column[r.local..r.local + r.len])
                        .for_each(|(x, v)| *x += v);
                }
            }
        }
    }

    /// The rows of fixed dofs (their reactions, `ResidualNorm::Linearised`): (dof, column,
    /// K entry) in point order.
    pub(super) fn linearised_rows(&self, n: usize, rows: &mut Vec<(usize, usize, f64)>) {
        let mut eqs = [None; MAX_POINT_EQS];
        let mut kl = Vec::new();
        for p in 0..n {
            let md = self.equations(p, &mut eqs);
            let eqs = &eqs[..md];
            if eqs.iter().all(Option::is_some) {
                continue;
            }
            self.block(p, &mut kl);
            let nodes = self.table.point(p).0;
            for (ri, row) in eqs.iter().enumerate() {
                if row.is_some() {
                    continue;
                }
                let dof = nodes[ri / D] * D + ri % D;
                for (ci, col) in eqs.iter().enumerate() {
                    if let Some(col) = *col {
                        rows.push((dof, col, kl[ci * md + ri]));
                    }
                }
            }
        }
    }
}

/// Transpose the `n` × `n` column-major block `a` in place.
fn transpose_square(a: &mut [f64], n: usize) {
    for c in 0..n {
        for r in c + 1..n {
            a.swap(c * n + r, r * n + c);
        }
    }
}
