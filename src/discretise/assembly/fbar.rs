//! F-bar: each point's deformation increment with its volume change replaced by its patch's,
//! ΔF̄_p = (ΔJ̄_c / ΔJ_p)^(1/D) ΔF_p with ΔJ̄_c = Σ_q V_q^n ΔJ_q / Σ_q V_q^n over the points q of
//! patch c (reference/README.md item 69; Coombs et al. 2018 for material points, de Souza Neto
//! et al. 1996 for elements). The point carries F̄ (its stress, volume and domain follow it);
//! only the shape-function gradients ∂S/∂x use the actual ΔF.
//!
//! The internal force f_a = Σ_p τ̄_p ∂S_a/∂x V_p^0 linearises to the plain tangent at F̄ plus
//! Σ_p v̄_p ∂_j S_a q_ij (Ḡ_k − ∂_k S_b), with q = D^alg : I_D / (D J̄) (D^alg = ∂τ/∂ε^e_trial,
//! I_D the in-plane identity) and Ḡ the patch's gradients averaged with the actual trial
//! volumes V_q^n ΔJ_q: the derivative of ln ΔJ̄_c. The −q ⊗ I part joins each point's block;
//! the Ḡ part is a rank-one block r gᵀ per patch over the nodes its points touch.

use super::local::{row_stretches, spatial_gradients, RowStretch};
use crate::discretise::dofs::{DofMap, SupportTable, MAX_POINT_NODES};
use crate::discretise::patches::VolumePatches;
use crate::material::constitutive::ConstitutiveModel;
use crate::material::kinematics::{spatial_tangent_eigen, PointState, PointTrial};
use crate::material::tensor::{ij, Tensor4};
use crate::solver::sparse::ColumnBlock;
use nalgebra::{Matrix3, SMatrix, SVector};
use rayon::prelude::*;

/// Per-step storage of the F-bar treatment, reused from iteration to iteration.
#[derive(Debug, Clone, Default)]
pub struct FBarScratch {
    /// Each point's actual ΔJ_p = det ΔF_p at the last evaluation.
    dj: Vec<f64>,
    /// Each point's scale (ΔJ̄_c / ΔJ_p)^(1/D) at the last evaluation.
    scale: Vec<f64>,
    /// Each patch's ΔJ̄_c at the last evaluation.
    patch_dj: Vec<f64>,
    /// Each point's q = D^alg : I_D / (D J̄) at the last tangent (with the pressure projection
    /// also its out-of-plane diagonal).
    q: Vec<Matrix3<f64>>,
    /// Whether each patch's points carry its mean Kirchhoff pressure ([`super::pressure`]).
    pub project_pressure: bool,
    /// With the projection, each point's trace tangent T (in-plane block) at the last tangent.
    trace: Vec<Matrix3<f64>>,
    /// Each point's spatial tangent with its F-bar (and projection) terms, its in-plane
    /// D⁴ entries (i, j, k, l < D) in a stride of D⁴: formed with q from one D^alg per point,
    /// where the point kernel formed D^alg a second time (reference/README.md item 78).
    tangents: Vec<f64>,
    /// The step's patch layout: what a patch block's rows and columns are, fixed within a
    /// step (the supports and equations are), so formed once per step, not per thread and
    /// iteration.
    layout: PatchLayout,
}

/// Per patch of two or more points: its nodes (ascending), their equations (D per node) and
/// those equations as stretches of consecutive ones, flat.
#[derive(Debug, Clone, Default)]
struct PatchLayout {
    /// Per patch, where its nodes start in `nodes` (and `D` times that in `eqs`); `count + 1`.
    node_start: Vec<usize>,
    nodes: Vec<usize>,
    eqs: Vec<Option<usize>>,
    stretch_start: Vec<usize>,
    stretches: Vec<RowStretch>,
}

impl PatchLayout {
    fn build<const D: usize>(&mut self, patches: &VolumePatches, table: &SupportTable<D>, dofs: &DofMap) {
        let (mut union, mut local) = (Vec::new(), Vec::new());
        self.node_start.clear();
        self.nodes.clear();
        self.eqs.clear();
        self.stretch_start.clear();
        self.stretches.clear();
        self.node_start.push(0);
        self.stretch_start.push(0);
        for c in 0..patches.count() {
            if patches.is_shared(c) {
                patches.nodes(table, c, &mut union);
                let first = self.eqs.len();
                self.nodes.extend_from_slice(&union);
                for &n in &union {
                    self.eqs.extend((0..D).map(|a| dofs.eq(n * D + a)));
                }
                row_stretches(&self.eqs[first..], &mut local);
                self.stretches.extend_from_slice(&local);
            }
            self.node_start.push(self.nodes.len());
            self.stretch_start.push(self.stretches.len());
        }
    }

    /// Patch `c`'s nodes, equations and row stretches.
    fn of<const D: usize>(&self, c: usize) -> (&[usize], &[Option<usize>], &[RowStretch]) {
        let (a, b) = (self.node_start[c], self.node_start[c + 1]);
        let (s, e) = (self.stretch_start[c], self.stretch_start[c + 1]);
        (&self.nodes[a..b], &self.eqs[a * D..b * D], &self.stretches[s..e])
    }
}

/// The F-bar treatment of a step: its patches and their storage.
pub struct FBar<'a> {
    patches: &'a VolumePatches,
    scratch: &'a mut FBarScratch,
}

/// Whether the tangent carries its F-bar terms (always, unless a seeded bug removes them).
#[inline(always)]
pub(super) fn fbar_terms() -> bool {
    #[cfg(feature = "seeded-bugs")]
    if crate::seeded::active(crate::seeded::Bug::FBarWithoutItsTangent) {
        return false;
    }
    true
}

/// ∂Δu/∂X̃ + I scaled by `s`, less I: the gradient whose ΔF is s ΔF.
#[inline]
pub(super) fn scaled_gradient<const D: usize>(grad: &SMatrix<f64, D, D>, s: f64) -> SMatrix<f64, D, D> {
    if s == 1.0 {
        return *grad;
    }
    let mut g = grad * s;
    for i in 0..D {
        g[(i, i)] += s - 1.0;
    }
    g
}

impl<'a> FBar<'a> {
    /// F-bar over `patches` for a step of supports `table` and equations `dofs`, in
    /// `scratch`: the patches' layout is formed here, once for the step.
    pub fn new<const D: usize>(
        patches: &'a VolumePatches,
        scratch: &'a mut FBarScratch,
        table: &SupportTable<D>,
        dofs: &DofMap,
    ) -> Self {
        scratch.layout.build(patches, table, dofs);
        Self { patches, scratch }
    }

    /// From the nodal increment `du`: every point's actual ΔJ and its scale to its patch's
    /// averaged volume change. A point whose actual increment inverts it is the error
    /// (point, reason). A patch of one point keeps its ΔF (scale 1).
    pub(super) fn average<const D: usize>(
        &mut self,
        table: &SupportTable<D>,
        states: &[PointState],
        du: &[f64],
    ) -> Result<(), (usize, String)> {
        let n = states.len();
        let scratch = &mut *self.scratch;
        scratch.dj.resize(n, 1.0);
        scratch.scale.resize(n, 1.0);
        scratch.dj.par_iter_mut().enumerate().for_each(|(p, dj)| {
            let df = crate::material::kinematics::delta_f_from_gradient(&table.gradient(p, du));
            *dj = df.determinant();
        });
        if let Some(p) = scratch.dj.iter().position(|j| !(*j > 0.0 && j.is_finite())) {
            return Err((
                p,
                crate::material::kinematics::PointError::Inverted(scratch.dj[p]).to_string(),
            ));
        }
        let patches = self.patches;
        let dj = &scratch.dj;
        scratch.patch_dj.resize(patches.count(), 1.0);
        scratch
            .patch_dj
            .par_iter_mut()
            .enumerate()
            .for_each(|(c, average)| {
                let (mut v, mut vj) = (0.0, 0.0);
                for &q in patches.points(c) {
                    v += states[q].volume;
                    vj += states[q].volume * dj[q];
                }
                *average = vj / v;
            });
        let averages = &scratch.patch_dj;
        scratch.scale.par_iter_mut().enumerate().for_each(|(p, s)| {
            let c = patches.of(p);
            *s = if patches.is_shared(c) {
                (averages[c] / dj[p]).powf(1.0 / D as f64)
            } else {
                1.0
            };
        });
        Ok(())
    }

    /// Point `p`'s scale at the last [`Self::average`].
    #[inline]
    pub(super) fn scale(&self, p: usize) -> f64 {
        self.scratch.scale[p]
    }

    /// Every point's q (with the projection also its trace tangent) and its spatial tangent
    /// with the F-bar terms, at the trial states of the last evaluation: one D^alg per point.
    pub(super) fn form_q<const D: usize>(
        &mut self,
        model: &dyn ConstitutiveModel,
        states: &[PointState],
        trials: &[Option<PointTrial<D>>],
    ) {
        let project = self.scratch.project_pressure;
        let n = states.len();
        let stride = D * D * D * D;
        let scratch = &mut *self.scratch;
        scratch.q.resize(n, Matrix3::zeros());
        scratch.trace.resize(n, Matrix3::zeros());
        scratch.tangents.resize(n * stride, 0.0);
        let patches = self.patches;
        scratch
            .q
            .par_iter_mut()
            .zip(scratch.trace.par_iter_mut())
            .zip(scratch.tangents.par_chunks_mut(stride))
            .enumerate()
            .for_each(|(p, ((qp, tp), out))| {
                let t = trials[p].as_ref().expect("evaluated");
                let (q, d_alg) = super::local::point_q::<D>(model, &states[p], t, project);
                *qp = q;
                if project {
                    *tp = super::pressure::trace_tangent::<D>(&d_alg, t, &q);
                }
                let mut a = spatial_tangent_eigen::<D>(
                    &d_alg,
                    &t.b_trial_eigenvalues,
                    &t.b_trial_eigenvectors,
                    &t.sigma(),
                    t.j,
                );
                if patches.is_shared(patches.of(p)) && fbar_terms() {
                    adjust_tangent::<D>(&q, project.then_some(&*tp), &mut a);
                }
                let mut e = 0;
                for i in 0..D {
                    for j in 0..D {
                        for k in 0..D {
                            for l in 0..D {
                                out[e] = a[(ij(i, j), ij(k, l))];
                                e += 1;
                            }
                        }
                    }
                }
            });
    }

    /// The views the point kernel and the patch blocks read.
    pub(super) fn view(&self) -> FBarView<'_> {
        FBarView {
            patches: self.patches,
            dj: &self.scratch.dj,
            q: &self.scratch.q,
            tangents: &self.scratch.tangents,
            layout: &self.scratch.layout,
            trace: self.scratch.project_pressure.then_some(&self.scratch.trace[..]),
        }
    }

    /// With the pressure projection on, give each shared patch's points its mean pressure.
    pub(super) fn project<const D: usize>(
        &self,
        states: &[PointState],
        trials: &mut [Option<PointTrial<D>>],
    ) {
        if self.scratch.project_pressure {
            super::pressure::project_residual(self.patches, states, trials);
        }
    }
}

/// What the tangent's assembly reads of the F-bar treatment.
#[derive(Clone, Copy)]
pub(super) struct FBarView<'a> {
    pub patches: &'a VolumePatches,
    dj: &'a [f64],
    q: &'a [Matrix3<f64>],
    tangents: &'a [f64],
    layout: &'a PatchLayout,
    /// The trace tangents, with the pressure projection on.
    trace: Option<&'a [Matrix3<f64>]>,
}

/// Most nodes a patch's points touch: a cell's points reach at most 4 nodes per axis beyond
/// the cell's own in GIMP, CPDI and the cubic B-splines.
const MAX_PATCH_NODES: usize = 7 * 7 * 7;

impl FBarView<'_> {
    /// Point `p`'s spatial tangent with its F-bar terms, as [`FBar::form_q`] formed it.
    pub fn point_tangent<const D: usize>(&self, p: usize) -> Tensor4 {
        let stride = D * D * D * D;
        let stored = &self.tangents[p * stride..(p + 1) * stride];
        let mut a = Tensor4::zeros();
        let mut e = 0;
        for i in 0..D {
            for j in 0..D {
                for k in 0..D {
                    for l in 0..D {
                        a[(ij(i, j), ij(k, l))] = stored[e];
                        e += 1;
                    }
                }
            }
        }
        a
    }
}

/// Subtract q_ij δ_kl from a point's spatial tangent `a` (the −q ⊗ I part) and, with the
/// pressure projection (its trace tangent `trace`), δ_ij T_kl / 3: the point keeps its
/// deviatoric rate only.
fn adjust_tangent<const D: usize>(q: &Matrix3<f64>, trace: Option<&Matrix3<f64>>, a: &mut Tensor4) {
    for i in 0..D {
        for j in 0..D {
            for k in 0..D {
                a[(ij(i, j), ij(k, k))] -= q[(i, j)];
            }
        }
    }
    if let Some(t) = trace {
        for i in 0..D {
            for k in 0..D {
                for l in 0..D {
                    a[(ij(i, i), ij(k, l))] -= t[(k, l)] / 3.0;
                }
            }
        }
    }
}

/// One patch's block r gᵀ over its nodes' dofs (the layout's order), plus R Pᵀ with the
/// pressure projection ([`super::pressure`]).
pub(super) struct PatchBlock {
    r: Vec<f64>,
    g: Vec<f64>,
    r2: Vec<f64>,
    g2: Vec<f64>,
}

impl PatchBlock {
    pub fn new() -> Self {
        Self {
            r: Vec::with_capacity(MAX_PATCH_NODES * 3),
            g: Vec::with_capacity(MAX_PATCH_NODES * 3),
            r2: Vec::new(),
            g2: Vec::new(),
        }
    }

    /// Patch `c`'s r and g at the trial states, over `nodes` (the patch's, ascending).
    fn form<const D: usize>(
        &mut self,
        f: &FBarView<'_>,
        table: &SupportTable<D>,
        trials: &[Option<PointTrial<D>>],
        states: &[PointState],
        c: usize,
        nodes: &[usize],
    ) {
        let md = nodes.len() * D;
        self.r.clear();
        self.r.resize(md, 0.0);
        self.g.clear();
        self.g.resize(md, 0.0);
        let mut gx = [SVector::<f64, D>::zeros(); MAX_POINT_NODES];
        let mut weight = 0.0;
        for &p in f.patches.points(c) {
            let t = trials[p].as_ref().expect("evaluated");
            let m = spatial_gradients(table, p, t, &mut gx);
            let w = states[p].volume * f.dj[p];
            weight += w;
            // With the projection the Ḡ part's trace goes to the patch pressure (R Pᵀ).
            let q = &match f.trace {
                Some(_) => super::pressure::deviator(&f.q[p]),
                None => f.q[p],
            };
            for (k, &node) in table.point(p).0[..m].iter().enumerate() {
                let local = nodes.binary_search(&node).expect("a patch node") * D;
                for i in 0..D {
                    let s: f64 = (0..D).map(|j| gx[k][j] * q[(i, j)]).sum();
                    self.r[local + i] += t.volume * s;
                    self.g[local + i] += w * gx[k][i];
                }
            }
        }
        self.g.iter_mut().for_each(|x| *x /= weight);
        self.r2.clear();
        self.g2.clear();
        if let Some(trace) = f.trace {
            super::pressure::form_block(
                f.patches.points(c),
                table,
                trials,
                states,
                f.q,
                trace,
                nodes,
                &self.g,
                &mut self.r2,
                &mut self.g2,
            );
        }
    }
}

/// Add the patch blocks that reach a column of `block`.
pub(super) fn add_patches<const D: usize>(
    f: &FBarView<'_>,
    table: &SupportTable<D>,
    trials: &[Option<PointTrial<D>>],
    states: &[PointState],
    block: &mut ColumnBlock<'_>,
) {
    if !fbar_terms() {
        return;
    }
    let (lo, hi) = block.columns();
    let owned = |c: &usize| (lo..hi).contains(c);
    let mut patch = PatchBlock::new();
    for c in 0..f.patches.count() {
        let (nodes, eqs, stretches) = f.layout.of::<D>(c);
        if nodes.is_empty() || !eqs.iter().flatten().any(owned) {
            continue;
        }
        patch.form(f, table, trials, states, c, nodes);
        // K = r gᵀ (+ R Pᵀ); stored by rows the lines are K's rows, so the roles swap.
        let pairs = [(&patch.r, &patch.g), (&patch.r2, &patch.g2)];
        for (r, g) in pairs.into_iter().filter(|(r, _)| !r.is_empty()) {
            let (line_factor, entries) = if block.by_rows() { (r, g) } else { (g, r) };
            for (ci, col) in eqs.iter().enumerate() {
                let Some(col) = col.filter(owned) else { continue };
                let factor = line_factor[ci];
                if factor == 0.0 {
                    continue;
                }
                let mut hint = usize::MAX;
                for s in stretches {
                    let values = block.stretch_with_hint(s.row, col, s.len, &mut hint);
                    for (x, e) in values.iter_mut().zip(&entries[s.local..s.local + s.len]) {
                        *x += e * factor;
                    }
                }
            }
        }
    }
}

/// The patch blocks' entries in the rows of fixed dofs: (dof, column, value).
pub(super) fn linearised_rows<const D: usize>(
    f: &FBarView<'_>,
    table: &SupportTable<D>,
    trials: &[Option<PointTrial<D>>],
    states: &[PointState],
    rows: &mut Vec<(usize, usize, f64)>,
) {
    if !fbar_terms() {
        return;
    }
    let mut patch = PatchBlock::new();
    for c in 0..f.patches.count() {
        let (nodes, eqs, _) = f.layout.of::<D>(c);
        if nodes.is_empty() || eqs.iter().all(Option::is_some) {
            continue;
        }
        patch.form(f, table, trials, states, c, nodes);
        for (ri, row) in eqs.iter().enumerate() {
            if row.is_some() {
                continue;
            }
            let dof = nodes[ri / D] * D + ri % D;
            for (ci, col) in eqs.iter().enumerate() {
                if let Some(col) = *col {
                    let extra = if patch.r2.is_empty() {
                        0.0
                    } else {
                        patch.r2[ri] * patch.g2[ci]
                    };
                    rows.push((dof, col, patch.r[ri] * patch.g[ci] + extra));
                }
            }
        }
    }
}
