//! Residual and sparse tangent assembly over integration points, shared by the material point
//! solvers (points = material points, supports = GIMP/MPM weights) and the finite element
//! comparators (points = Gauss points, supports = element shape functions).
//!
//! Each point contributes `f_p = [G]ᵀ{σ} V_p` (eq 29) and `K_p = [G]ᵀ[a][G] V_p` (eq 27),
//! where \[G\] holds ∂S/∂x = ∂S/∂X̃ · ΔF⁻¹ (eqs 36, 41). The residual's points are evaluated
//! in parallel into per-point slots and summed in point order; the tangent's threads each own
//! a block of columns and add every point's block to them in point order, so results do not
//! depend on the thread count.

pub use crate::discretise::dofs::{DofMap, SupportTable, MAX_POINT_NODES};
use crate::discretise::ghost::GhostOperator;
use crate::material::constitutive::ConstitutiveModel;
use crate::material::kinematics::{evaluate_point, PointState, PointTrial};
use crate::material::tensor::ij;
use crate::solver::dynamics::{Inertia, MassMatrix};
use crate::solver::error::FailedAttempt;
use crate::solver::error::StepFailure;
use crate::solver::linear::SparseSystem;
use crate::solver::newton::{self, NewtonReport, NewtonSettings, NonlinearSystem, ResidualNorm};
use nalgebra::SVector;
use rayon::prelude::*;

/// Nodal external force of body forces carried by points: f_a = Σ_p S_ap b_p (eq 40).
pub fn map_point_forces<const D: usize>(
    table: &SupportTable<D>,
    forces: &[SVector<f64, D>],
    nodal: &mut [f64],
) {
    for (p, f) in forces.iter().enumerate() {
        let (nodes, s, _) = table.point(p);
        for (&n, &w) in nodes.iter().zip(s) {
            for i in 0..D {
                nodal[n * D + i] += w * f[i];
            }
        }
    }
}

/// M a for a nodal field a (per nodal dof), handing each contribution (nodal dof, force) to
/// `sink`: consistent, Σ_p m_p S_ap (Σ_b S_bp a_b); lumped, (Σ_p m_p S_ap) a_a.
fn mass_times<const D: usize>(
    table: &SupportTable<D>,
    inertia: &Inertia<'_>,
    a: impl Fn(usize) -> f64,
    mut sink: impl FnMut(usize, f64),
) {
    for p in 0..table.num_points() {
        let (nodes, s, _) = table.point(p);
        let m = inertia.point_masses[p];
        let mut ap = [0.0; 3];
        if inertia.mass == MassMatrix::Consistent {
            for (&n, &w) in nodes.iter().zip(s) {
                for (i, v) in ap.iter_mut().enumerate().take(D) {
                    *v += w * a(n * D + i);
                }
            }
        }
        for (&n, &w) in nodes.iter().zip(s) {
            for (i, &v) in ap.iter().enumerate().take(D) {
                let dof = n * D + i;
                sink(
                    dof,
                    m * w
                        * match inertia.mass {
                            MassMatrix::Consistent => v,
                            MassMatrix::Lumped => a(dof),
                        },
                );
            }
        }
    }
}

/// One load step's nonlinear system over a set of integration points.
pub struct LoadStepSystem<'a, const D: usize> {
    pub model: &'a dyn ConstitutiveModel,
    pub states: &'a [PointState],
    pub table: &'a SupportTable<D>,
    pub dofs: &'a DofMap,
    /// External force in equation order.
    pub f_ext: &'a [f64],
    pub matrix: &'a mut SparseSystem,
    /// Per-point trial results at the last evaluation (committed by the caller on convergence).
    pub trials: &'a mut Vec<Option<PointTrial<D>>>,
    /// Nodal displacement increment at the last evaluation.
    pub du_nodal: &'a mut Vec<f64>,
    /// Ghost penalty of the step (material point solvers), if on.
    pub ghost: Option<&'a GhostOperator<D>>,
    /// Internal force at the dofs without an equation (fixed ones: the support reactions
    /// plus the external force there), indexed by nodal dof, at the last evaluation.
    pub fixed_forces: &'a mut Vec<f64>,
    /// Linearised reaction update ([`ResidualNorm::Linearised`]); `None`: not tracked.
    pub linearised: Option<&'a mut LinearisedReactions>,
    /// The inertia term M a₁(Δu) of a dynamic step ([`crate::solver::dynamics`]); `None`: static.
    pub inertia: Option<Inertia<'a>>,
    /// The scale of the convergence test of a dynamic step; `None` (static): f_ext.
    pub dynamic_reference: Option<DynamicReference<'a>>,
}

/// What normalises the residual of a dynamic step: √(‖f_ext + M ã‖² + ‖M a₀‖²) over the free
/// dofs. f_ext + M ã is the effective load that drives the increment (the residual at Δu = 0
/// is f_int(u₀) − f_ext − M ã) and M a₀ the inertia force the step starts with. Either alone
/// vanishes at instants of a motion: f_ext of a free vibration always, and of a manufactured
/// body force at a(t) = 0 (where the static normalisation by ‖f_ext‖ made the relative residual
/// 1e19); f_ext + M ã where 4v₀/Δt + a₀ = 0 (β = 1/4), where the vibrating bar's steps
/// stalled at their round-off floor and were cut back, changing Δt (reference/README item 48).
/// a₀ and ã = 4v₀/Δt + a₀ vanish together only at rest, where the scale is ‖f_ext‖ as in a
/// static step.
#[derive(Debug, Clone, Copy)]
pub struct DynamicReference<'a> {
    /// f_ext + M ã in equation order.
    pub effective_load: &'a [f64],
    /// ‖M a₀‖ over the free dofs.
    pub start_inertia: f64,
}

/// The fixed rows of the tangent at the last assembly and the state they were formed at, for
/// the reactions as the paper's group updates them (AMPLE: f_rct += K_f δu − f^ob_f). After
/// an update to u the out-of-balance left at the fixed dofs telescopes to
/// f^ob_f(u) = −[f_int,f(u) − f_int,f(u_t) − K_f(u_t)(u − u_t)], u_t the tangent's state,
/// and f_ext,f + f_rct = f_int,f(u) + f^ob_f(u) (reference/README.md, item 18).
#[derive(Debug, Default)]
pub struct LinearisedReactions {
    /// (nodal dof, equation, value) entries of K_f (material part; the ghost part is added
    /// from the operator, it is linear).
    rows: Vec<(usize, usize, f64)>,
    /// u and f_int at the fixed dofs when the tangent was formed; empty before the first.
    u_t: Vec<f64>,
    fixed_t: Vec<f64>,
    /// The last evaluation's u and out-of-balance at the fixed dofs (nodal dof order).
    u_last: Vec<f64>,
    oob: Vec<f64>,
    scratch_nodal: Vec<f64>,
    scratch_eq: Vec<f64>,
}

impl LinearisedReactions {
    fn clear(&mut self) {
        self.rows.clear();
        self.u_t.clear();
        self.fixed_t.clear();
        self.oob.clear();
    }
}

impl<const D: usize> LoadStepSystem<'_, D> {
    /// Evaluate all points at the nodal increment and assemble the internal force (in
    /// equation order).
    pub fn assemble_residual(&mut self, f_int: &mut [f64]) -> Result<(), StepFailure> {
        crate::solver::profile::timed(crate::solver::profile::Phase::Constitutive, || {
            self.assemble_residual_untimed(f_int)
        })
    }

    fn assemble_residual_untimed(&mut self, f_int: &mut [f64]) -> Result<(), StepFailure> {
        let model = self.model;
        let table = self.table;
        let du = &*self.du_nodal;
        self.trials.resize(self.states.len(), None);
        let first_error = self
            .trials
            .par_iter_mut()
            .zip(self.states.par_iter())
            .enumerate()
            .map(|(p, (slot, state))| {
                let grad = table.gradient(p, du);
                match evaluate_point::<D>(model, state, &grad) {
                    Ok(t) => {
                        *slot = Some(t);
                        None
                    }
                    Err(e) => {
                        *slot = None;
                        Some((p, e.to_string()))
                    }
                }
            })
            .reduce(
                || None,
                |a, b| match (a, b) {
                    (Some(x), Some(y)) => Some(if x.0 <= y.0 { x } else { y }),
                    (x, None) => x,
                    (None, y) => y,
                },
            );
        if let Some((point, reason)) = first_error {
            return Err(StepFailure::Kinematics { point, reason });
        }
        f_int.iter_mut().for_each(|v| *v = 0.0);
        self.fixed_forces.clear();
        self.fixed_forces.resize(self.dofs.num_dofs(), 0.0);
        let mut gx = [SVector::<f64, D>::zeros(); MAX_POINT_NODES];
        let mut eqs = [None; MAX_POINT_EQS];
        for p in 0..self.states.len() {
            let t = self.trials[p].as_ref().expect("evaluated");
            let m = spatial_gradients(self.table, p, t, &mut gx);
            point_equations(self.table, self.dofs, p, &mut eqs);
            let v = t.volume;
            let sigma = t.sigma();
            let nodes = self.table.point(p).0;
            for k in 0..m {
                for i in 0..D {
                    let s: f64 = (0..D).map(|j| sigma[(i, j)] * gx[k][j]).sum();
                    match eqs[k * D + i] {
                        Some(e) => f_int[e] += s * v, // eq (29)
                        None => self.fixed_forces[nodes[k] * D + i] += s * v,
                    }
                }
            }
        }
        if let Some(g) = self.ghost {
            g.add_residual(self.dofs, self.du_nodal, f_int, Some(self.fixed_forces));
        }
        if let Some(inertia) = self.inertia {
            self.add_inertia_residual(&inertia, f_int);
        }
        Ok(())
    }

    /// f += M a₁ with a₁ = Δu/(βΔt²) − ã per nodal dof (generalised-α: M (c_m a₁ + c_a a₀),
    /// [`crate::solver::dynamics::GeneralizedAlpha`]): consistent, Σ_p m_p S_ap (Σ_b S_bp a₁_b); lumped,
    /// (Σ_p m_p S_ap) a₁_a. Fixed dofs take theirs into the reactions.
    fn add_inertia_residual(&mut self, inertia: &Inertia<'_>, f_int: &mut [f64]) {
        let (du, dofs, fixed) = (&*self.du_nodal, self.dofs, &mut *self.fixed_forces);
        mass_times(
            self.table,
            inertia,
            |dof| {
                inertia
                    .step
                    .inertia_acceleration(du[dof], inertia.predictor[dof], inertia.acceleration[dof])
            },
            |dof, f| match dofs.eq(dof) {
                Some(e) => f_int[e] += f,
                None => fixed[dof] += f,
            },
        );
    }

    /// The out-of-balance left at the fixed dofs by the linearised reaction update, at `u`
    /// (see [`LinearisedReactions`]); zero before the first tangent (exact reactions).
    fn update_fixed_out_of_balance(&mut self, u: &[f64]) {
        let Some(lin) = self.linearised.as_deref_mut() else {
            return;
        };
        lin.u_last.clear();
        lin.u_last.extend_from_slice(u);
        lin.oob.clear();
        if lin.u_t.len() != u.len() {
            return;
        }
        // −[f_int,f(u) − f_int,f(u_t) − K_f (u − u_t)]
        lin.oob
            .extend(self.fixed_forces.iter().zip(&lin.fixed_t).map(|(f, t)| t - f));
        for &(dof, col, k) in &lin.rows {
            lin.oob[dof] += k * (u[col] - lin.u_t[col]);
        }
        if let Some(g) = self.ghost {
            // u − u_t, expanded to the nodes; scratch_eq then takes the (unused) free rows.
            lin.scratch_eq.clear();
            lin.scratch_eq.extend(u.iter().zip(&lin.u_t).map(|(a, b)| a - b));
            lin.scratch_nodal.clear();
            lin.scratch_nodal.resize(self.dofs.num_dofs(), 0.0);
            self.dofs.expand(&lin.scratch_eq, &mut lin.scratch_nodal);
            lin.scratch_eq.fill(0.0);
            g.add_residual(
                self.dofs,
                &lin.scratch_nodal,
                &mut lin.scratch_eq,
                Some(&mut lin.oob),
            );
        }
    }

    /// Assemble the tangent `K = Σ_p [G]ᵀ[a][G] V_p` (eq 27) at the trial states of the last
    /// [`Self::assemble_residual`].
    ///
    /// Points are processed in chunks: their local matrices are formed in parallel into a
    /// buffer reused across chunks, then scattered in parallel by column blocks, each block
    /// owned by one thread and filled in point order. Every entry thus receives its
    /// contributions in the same order whatever the thread count.
    pub fn assemble_tangent(&mut self) {
        crate::solver::profile::timed(crate::solver::profile::Phase::Assembly, || {
            self.assemble_tangent_untimed()
        });
    }

    fn assemble_tangent_untimed(&mut self) {
        self.matrix.clear_values();
        if let Some(lin) = self.linearised.as_deref_mut() {
            lin.rows.clear();
            lin.u_t.clone_from(&lin.u_last);
            lin.fixed_t.clone_from(self.fixed_forces);
        }
        let n = self.states.len();
        #[cfg(feature = "seeded-bugs")]
        let inertia = self
            .inertia
            .filter(|_| !crate::seeded::active(crate::seeded::Bug::NoMassInTangent));
        #[cfg(not(feature = "seeded-bugs"))]
        let inertia = self.inertia;
        let kernel = PointKernel {
            table: self.table,
            dofs: self.dofs,
            model: self.model,
            states: self.states,
            trials: self.trials,
            inertia,
        };
        let runs = kernel.runs(n);
        // Each thread owns a block of columns and walks every run in point order, forming the
        // blocks of the runs that reach its columns (a run straddling two blocks is formed by
        // both) and adding them at once: no buffer of every point's block (4.6 KB a 3D point,
        // written and read again at memory speed), and every entry sums the same terms in the
        // same order whatever the thread count.
        let threads = rayon::current_num_threads();
        let runs = &runs;
        self.matrix
            .column_blocks(threads)
            .into_par_iter()
            .for_each(|mut block| kernel.add_runs(&mut block, runs));
        if let Some(lin) = self.linearised.as_deref_mut() {
            kernel.linearised_rows(n, &mut lin.rows);
        }
        if let Some(g) = self.ghost {
            g.add_tangent(self.dofs, self.matrix);
        }
        if let Some(i) = inertia.filter(|i| i.mass == MassMatrix::Lumped) {
            // α m_a on the diagonal, m_a = Σ_p m_p S_ap.
            for p in 0..n {
                let (nodes, s, _) = self.table.point(p);
                for (&node, &w) in nodes.iter().zip(s) {
                    for a in 0..D {
                        if let Some(e) = self.dofs.eq(node * D + a) {
                            self.matrix
                                .add(e, e, i.step.tangent_mass_factor() * i.point_masses[p] * w);
                        }
                    }
                }
            }
        }
    }
}

/// Point `p`'s equations, node by node, D each (`None`: a fixed dof), into `eqs`; returns
/// their count.
#[inline]
fn point_equations<const D: usize>(
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

/// ∂S/∂x_j = ∂S/∂X̃_i (ΔF⁻¹)_ij (eq 36) of point `p`'s nodes at trial `t` into `gx`; returns
/// the node count.
#[inline]
fn spatial_gradients<const D: usize>(
    table: &SupportTable<D>,
    p: usize,
    t: &PointTrial<D>,
    gx: &mut [SVector<f64, D>; MAX_POINT_NODES],
) -> usize {
    let g = table.point(p).2;
    let inv_t = t.delta_f_inv.transpose();
    for (x, gk) in gx.iter_mut().zip(g) {
        *x = inv_t * gk;
    }
    g.len()
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
const MAX_POINT_EQS: usize = MAX_POINT_NODES * 3;

/// What forms a point's tangent block: the step's supports, equations, model and trial
/// states.
struct PointKernel<'a, const D: usize> {
    table: &'a SupportTable<D>,
    dofs: &'a DofMap,
    model: &'a dyn ConstitutiveModel,
    states: &'a [PointState],
    trials: &'a [Option<PointTrial<D>>],
    inertia: Option<Inertia<'a>>,
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
        let a = t.spatial_tangent(self.model, &self.states[p]);
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
    fn runs(&self, n: usize) -> Vec<usize> {
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
    fn add_runs(&self, block: &mut crate::solver::sparse::ColumnBlock<'_>, runs: &[usize]) {
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
    fn linearised_rows(&self, n: usize, rows: &mut Vec<(usize, usize, f64)>) {
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

/// Local rows `local..local + len` whose equations are `row..row + len`.
#[derive(Debug, Clone, Copy)]
struct RowStretch {
    local: usize,
    len: usize,
    row: usize,
}

/// A point's equations as stretches of consecutive ones (a node's D dofs, and nodes next to
/// each other along the first axis), fixed dofs left out.
fn row_stretches(eqs: &[Option<usize>], out: &mut Vec<RowStretch>) {
    out.clear();
    let mut open: Option<RowStretch> = None;
    for (ri, eq) in eqs.iter().enumerate() {
        match (*eq, open.as_mut()) {
            (Some(row), Some(r)) if row == r.row + r.len => r.len += 1,
            (eq, _) => {
                out.extend(open.take());
                open = eq.map(|row| RowStretch {
                    local: ri,
                    len: 1,
                    row,
                });
            }
        }
    }
    out.extend(open);
}

impl<const D: usize> NonlinearSystem for LoadStepSystem<'_, D> {
    fn num_unknowns(&self) -> usize {
        self.dofs.len()
    }
    fn evaluate(&mut self, u: &[f64], residual: &mut [f64]) -> Result<(), StepFailure> {
        self.du_nodal.resize(self.dofs.num_dofs(), 0.0);
        self.dofs.expand(u, self.du_nodal);
        self.assemble_residual(residual)?;
        for (r, f) in residual.iter_mut().zip(self.f_ext) {
            *r -= f;
        }
        self.update_fixed_out_of_balance(u);
        Ok(())
    }
    fn fixed_out_of_balance_sq(&self) -> f64 {
        self.linearised
            .as_deref()
            .map_or(0.0, |l| l.oob.iter().map(|x| x * x).sum())
    }
    fn set_linear_tolerance(&mut self, relative: f64) {
        self.matrix.set_tolerance(relative);
    }
    fn solve_tangent(&mut self, rhs: &mut [f64]) -> Result<(), StepFailure> {
        self.assemble_tangent();
        self.matrix.solve_in_place(rhs).map_err(StepFailure::LinearSolve)
    }
    fn reference_norm(&self, norm: ResidualNorm) -> f64 {
        let (load, inertia) = match self.dynamic_reference {
            Some(d) => (d.effective_load, d.start_inertia),
            None => (self.f_ext, 0.0),
        };
        let ext: f64 = load.iter().map(|x| x * x).sum::<f64>() + inertia * inertia;
        match norm {
            ResidualNorm::External if inertia == 0.0 => crate::solver::norms::l2(load),
            ResidualNorm::External => crate::solver::norms::l2(&[crate::solver::norms::l2(load), inertia]),
            // ‖f_ext + f_reaction‖ over all dofs: f_ext at the free dofs and, at the fixed
            // ones, f_ext + reaction = f_int of the last evaluation.
            ResidualNorm::Total => {
                let sq = ext + self.fixed_forces.iter().map(|x| x * x).sum::<f64>();
                if sq.is_normal() {
                    sq.sqrt()
                } else {
                    crate::solver::norms::l2_of(&[load, self.fixed_forces, &[inertia]])
                }
            }
            // f_ext + f_rct at the fixed dofs = f_int + f^ob there.
            ResidualNorm::Linearised => {
                let fixed: f64 = match self.linearised.as_deref() {
                    Some(l) if !l.oob.is_empty() => self
                        .fixed_forces
                        .iter()
                        .zip(&l.oob)
                        .map(|(f, o)| (f + o).powi(2))
                        .sum(),
                    _ => self.fixed_forces.iter().map(|x| x * x).sum(),
                };
                (ext + fixed).sqrt()
            }
        }
    }
}

/// Per-step storage of a discretisation, reused from step to step so that the hot loops do
/// not allocate: the supports, the sparse tangent, the trial point states and the nodal
/// increment. Material point and finite element solvers fill [`StepWorkspace::table`] with
/// their weights or shape functions and then share everything else.
#[derive(Debug, Default)]
pub struct StepWorkspace<const D: usize> {
    pub table: SupportTable<D>,
    pub matrix: SparseSystem,
    pub trials: Vec<Option<PointTrial<D>>>,
    pub du_nodal: Vec<f64>,
    /// Internal force at the fixed dofs at the last evaluation (see [`LoadStepSystem`]).
    pub fixed_forces: Vec<f64>,
    /// Linearised reactions ([`ResidualNorm::Linearised`]).
    pub linearised: LinearisedReactions,
    /// Where the nodes sit, for an iterative solver's multigrid
    /// ([`crate::solver::linear::LinearSolver::Iterative`]); set by the solver before each step.
    pub node_geometry: Option<crate::solver::multigrid::NodeGeometry>,
    /// The connectivity never changes (FEM): the sparsity pattern, its symbolic factorisation
    /// and the equations' geometry are built at the first step and kept, as long as the
    /// number of equations stays the same.
    pub fixed_pattern: bool,
    /// What the current pattern was built from, to keep it for a step whose points still
    /// touch the same nodes ([`PatternKey`]).
    pub(crate) pattern_key: PatternKey,
}

/// Everything a step's sparsity pattern is a function of: the equation of every nodal dof,
/// every point's nodes and the ghost faces' nodes. A step whose key equals the last one's has
/// the same pattern to the entry, so the pattern and the direct solvers' symbolic analysis are
/// kept (detected, not assumed: a point that moved to another cell changes its nodes).
/// Stored as the last build's copies, node numbers in 4 bytes (at 1e6 3D points of 8 nodes
/// each, 32 MB).
#[derive(Debug, Default)]
pub(crate) struct PatternKey {
    dofs: DofMap,
    offsets: Vec<usize>,
    nodes: Vec<u32>,
    ghost: Vec<u32>,
    /// Set once a key was recorded (an empty table is a key too).
    valid: bool,
}

/// `kept` and `numbers` hold the same numbers, in the same order.
fn same_numbers(kept: &[u32], numbers: impl Iterator<Item = usize>) -> bool {
    let mut count = 0;
    for n in numbers {
        if kept.get(count).is_none_or(|&k| k as usize != n) {
            return false;
        }
        count += 1;
    }
    count == kept.len()
}

impl PatternKey {
    fn ghost_nodes<const D: usize>(ghost: Option<&GhostOperator<D>>) -> impl Iterator<Item = usize> + '_ {
        ghost
            .into_iter()
            .flat_map(|g| g.face_stencils().flatten().copied())
    }

    fn matches<const D: usize>(
        &self,
        dofs: &DofMap,
        table: &SupportTable<D>,
        ghost: Option<&GhostOperator<D>>,
    ) -> bool {
        let (offsets, nodes) = table.node_lists();
        self.valid
            && self.dofs == *dofs
            && self.offsets == offsets
            && same_numbers(&self.nodes, nodes.iter().copied())
            && same_numbers(&self.ghost, Self::ghost_nodes(ghost))
    }

    fn record<const D: usize>(
        &mut self,
        dofs: &DofMap,
        table: &SupportTable<D>,
        ghost: Option<&GhostOperator<D>>,
    ) {
        let (offsets, nodes) = table.node_lists();
        let narrow = |n: usize| u32::try_from(n).ok();
        self.dofs.clone_from(dofs);
        self.offsets.clear();
        self.offsets.extend_from_slice(offsets);
        self.nodes.clear();
        self.ghost.clear();
        // A node number of 2^32 or more (never on a grid that fits in memory) leaves the key
        // invalid: the pattern is then rebuilt every step.
        self.valid = nodes.iter().all(|&n| narrow(n).is_some())
            && Self::ghost_nodes(ghost).all(|n| narrow(n).is_some());
        if self.valid {
            self.nodes.extend(nodes.iter().map(|&n| n as u32));
            self.ghost.extend(Self::ghost_nodes(ghost).map(|n| n as u32));
        }
    }
}

/// What a load step applies, besides the material model and the committed states.
pub struct StepInput<'a, const D: usize> {
    pub model: &'a dyn ConstitutiveModel,
    pub states: &'a [PointState],
    pub num_nodes: usize,
    /// Homogeneous Dirichlet conditions (node, axis).
    pub fixed: &'a [(usize, usize)],
    /// Nodes tied to a master node (slave, master): u_slave = u_master.
    pub ties: &'a [(usize, usize)],
    /// Force carried by each point (body force × mass, point loads), mapped with the weights (eq 40).
    pub point_forces: &'a [SVector<f64, D>],
    /// Forces applied directly to nodal dofs (dof = node·D + axis).
    pub nodal_forces: &'a [(usize, f64)],
    /// Ghost penalty of the step, built on the same grid ([`crate::discretise::ghost`]).
    pub ghost: Option<&'a GhostOperator<D>>,
    /// The inertia term of a dynamic step; `None`: quasi-static.
    pub inertia: Option<Inertia<'a>>,
    /// Generalised-α only: the point and nodal forces at the step's start t₀, for its term
    /// c_f (f_int(u₀) − f_ext(t₀)) ([`crate::solver::dynamics::GeneralizedAlpha`]); `None`: Newmark.
    pub start_forces: Option<StartForces<'a, D>>,
}

/// The external forces at the start of a step, as [`StepInput`] gives those at its end.
#[derive(Debug, Clone, Copy)]
pub struct StartForces<'a, const D: usize> {
    pub point_forces: &'a [SVector<f64, D>],
    pub nodal_forces: &'a [(usize, f64)],
}

/// f_ext of `point_forces` (mapped with the weights, eq 40) and `nodal_forces`, gathered in
/// equation order.
fn external_force<const D: usize>(
    table: &SupportTable<D>,
    dofs: &DofMap,
    point_forces: &[SVector<f64, D>],
    nodal_forces: &[(usize, f64)],
) -> Vec<f64> {
    let mut nodal = vec![0.0; dofs.num_dofs()];
    map_point_forces(table, point_forces, &mut nodal);
    for &(dof, force) in nodal_forces {
        nodal[dof] += force;
    }
    let mut f_ext = vec![0.0; dofs.len()];
    dofs.gather_forces(&nodal, &mut f_ext);
    f_ext
}

impl<const D: usize> StepWorkspace<D> {
    /// From the filled [`Self::table`]: the dof map, sparsity pattern (and so a fresh symbolic
    /// factorisation, unless [`Self::fixed_pattern`] keeps the first step's) and external
    /// force of one load step; the resulting system is handed to `f`.
    pub fn with_system<R>(
        &mut self,
        input: &StepInput<'_, D>,
        f: impl FnOnce(&mut LoadStepSystem<'_, D>) -> R,
    ) -> R {
        self.with_system_tracking(input, false, f)
    }

    /// [`Self::with_system`], tracking the linearised reactions if `track`.
    fn with_system_tracking<R>(
        &mut self,
        input: &StepInput<'_, D>,
        track: bool,
        f: impl FnOnce(&mut LoadStepSystem<'_, D>) -> R,
    ) -> R {
        let start = std::time::Instant::now();
        let dofs = DofMap::build(input.num_nodes, &self.table, input.fixed, input.ties);
        // FEM: the connectivity never changes. Material points: they still touch the nodes
        // they touched when the pattern was built.
        let kept = self.matrix.nnz() > 0
            && self.matrix.dim() == dofs.len()
            && (self.fixed_pattern || self.pattern_key.matches(&dofs, &self.table, input.ghost));
        if kept {
            self.matrix.clear_values();
            if !self.fixed_pattern {
                // As a fresh pattern would, minus the work: the step's first CG solve still
                // builds its multigrid from the step's own tangent, so results are those of a
                // rebuilt pattern to the bit. The equations' geometry is unchanged with them.
                self.matrix.forget_preconditioner();
            }
        } else {
            let mut columns = dofs.pattern(&self.table);
            if let Some(g) = input.ghost {
                g.add_pattern(&dofs, &mut columns);
            }
            self.matrix.set_pattern(columns);
            if !self.fixed_pattern {
                self.pattern_key.record(&dofs, &self.table, input.ghost);
            }
            if self.matrix.solver() == crate::solver::linear::LinearSolver::Iterative {
                if let Some(g) = &self.node_geometry {
                    self.matrix
                        .set_geometry(crate::solver::multigrid::DofGeometry::of_equations(g, &dofs));
                }
            }
        }
        crate::solver::profile::charge(crate::solver::profile::Phase::Setup, start);
        let mut f_ext = external_force(&self.table, &dofs, input.point_forces, input.nodal_forces);
        if let (Some(i), Some(start)) = (input.inertia, input.start_forces) {
            let weight = i.step.start_force_weight();
            if weight != 0.0 {
                // f_ext(t₁) − c_f (f_int(u₀) − f_ext(t₀)): f_int(u₀) is the internal force at a
                // zero increment (the committed stresses on this step's grid or mesh).
                let f_ext0 = external_force(&self.table, &dofs, start.point_forces, start.nodal_forces);
                let mut f_int0 = vec![0.0; dofs.len()];
                self.du_nodal.clear();
                self.du_nodal.resize(dofs.num_dofs(), 0.0);
                let mut at_rest = LoadStepSystem {
                    model: input.model,
                    states: input.states,
                    table: &self.table,
                    dofs: &dofs,
                    f_ext: &f_ext0,
                    matrix: &mut self.matrix,
                    trials: &mut self.trials,
                    du_nodal: &mut self.du_nodal,
                    ghost: input.ghost,
                    fixed_forces: &mut self.fixed_forces,
                    linearised: None,
                    inertia: None,
                    dynamic_reference: None,
                };
                if at_rest.assemble_residual(&mut f_int0).is_ok() {
                    for ((f, fi), fe) in f_ext.iter_mut().zip(&f_int0).zip(&f_ext0) {
                        *f -= weight * (fi - fe);
                    }
                } else {
                    // The committed states evaluated at no increment cannot fail unless they
                    // are already invalid; Newton's first evaluation reports that failure.
                    f_ext.iter_mut().for_each(|f| *f = f64::NAN);
                }
            }
        }
        let reference = input.inertia.map(|i| {
            let mut load = f_ext.clone();
            let mut start = vec![0.0; dofs.len()];
            mass_times(
                &self.table,
                &i,
                |dof| i.step.inertia_predictor(i.predictor[dof], i.acceleration[dof]),
                |dof, f| {
                    if let Some(e) = dofs.eq(dof) {
                        load[e] += f;
                    }
                },
            );
            mass_times(
                &self.table,
                &i,
                |dof| i.acceleration[dof],
                |dof, f| {
                    if let Some(e) = dofs.eq(dof) {
                        start[e] += f;
                    }
                },
            );
            (load, crate::solver::norms::l2(&start))
        });
        let mut system = LoadStepSystem {
            model: input.model,
            states: input.states,
            table: &self.table,
            dofs: &dofs,
            f_ext: &f_ext,
            matrix: &mut self.matrix,
            trials: &mut self.trials,
            du_nodal: &mut self.du_nodal,
            ghost: input.ghost,
            fixed_forces: &mut self.fixed_forces,
            linearised: track.then_some(&mut self.linearised),
            inertia: input.inertia,
            dynamic_reference: reference.as_ref().map(|(load, start)| DynamicReference {
                effective_load: load,
                start_inertia: *start,
            }),
        };
        f(&mut system)
    }

    /// Newton on one load step from a zero increment. On success [`Self::trials`] and
    /// [`Self::du_nodal`] hold the converged state for the caller to commit.
    pub fn solve(
        &mut self,
        input: &StepInput<'_, D>,
        settings: &NewtonSettings,
    ) -> Result<NewtonReport, FailedAttempt> {
        self.linearised.clear();
        let track = settings.residual_norm == ResidualNorm::Linearised;
        self.with_system_tracking(input, track, |system| {
            let mut u = vec![0.0; system.num_unknowns()];
            newton::solve(system, &mut u, settings)
        })
    }

    /// The size of the last step's system and the Krylov iterations (CG and GMRES) since `iterations_before`
    /// (the matrix's count before the step's solves).
    pub fn linear_record(&self, iterations_before: usize) -> crate::solver::load_stepping::LinearRecord {
        crate::solver::load_stepping::LinearRecord {
            unknowns: self.matrix.dim(),
            nonzeros: self.matrix.nnz(),
            // A CG run's factor (of a fallback) is not its linear system's cost.
            factor_nonzeros: match self.matrix.solver() {
                crate::solver::linear::LinearSolver::Iterative => 0,
                _ => self.matrix.stats().factor_nnz,
            },
            iterations: self.matrix.stats().iterations - iterations_before,
        }
    }

    /// Replace each point's state (the step's start) by the converged step's.
    pub fn commit_states(&self, states: &mut [PointState]) {
        for (state, t) in states.iter_mut().zip(&self.trials) {
            *state = t.as_ref().expect("converged trial").committed(state);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two points on a line of four nodes, each touching two neighbours.
    fn table(nodes: [[usize; 2]; 2]) -> SupportTable<1> {
        let mut t = SupportTable::default();
        t.clear();
        for pair in nodes {
            for n in pair {
                t.push_node(n, 0.5, SVector::<f64, 1>::new(1.0));
            }
            t.finish_point();
        }
        t
    }

    /// The key keeps a pattern exactly when what the pattern is built from is unchanged: the
    /// same supports and equations match; a point that moved to another node pair, or a dof
    /// newly fixed, does not. And wherever the key matches, the pattern built afresh is the
    /// kept one, entry for entry.
    #[test]
    fn the_pattern_key_matches_exactly_the_unchanged_supports_and_equations() {
        let before = table([[0, 1], [1, 2]]);
        let dofs = DofMap::build(4, &before, &[], &[]);
        let mut key = PatternKey::default();
        assert!(!key.matches(&dofs, &before, None), "no key recorded yet");
        key.record(&dofs, &before, None);
        let same = table([[0, 1], [1, 2]]);
        let same_dofs = DofMap::build(4, &same, &[], &[]);
        assert!(key.matches(&same_dofs, &same, None));
        assert_eq!(dofs.pattern(&before), same_dofs.pattern(&same));
        let moved = table([[0, 1], [2, 3]]);
        let moved_dofs = DofMap::build(4, &moved, &[], &[]);
        assert!(!key.matches(&moved_dofs, &moved, None), "a point changed nodes");
        assert_ne!(dofs.pattern(&before), moved_dofs.pattern(&moved));
        let fixed_dofs = DofMap::build(4, &same, &[(0, 0)], &[]);
        assert!(!key.matches(&fixed_dofs, &same, None), "node 0 fixed");
    }
}
