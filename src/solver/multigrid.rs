//! Geometric multigrid on the structured background grid (or FEM mesh), as the preconditioner
//! of a conjugate-gradient solve of the Newton systems ([`crate::solver::linear::LinearSolver::Iterative`]),
//! and of restarted GMRES where CG breaks down (indefinite or non-symmetric tangents).
//!
//! The grids of this code are structured, which is where multigrid is optimal: each coarse
//! level is the grid of twice the spacing, and the prolongation P interpolates every
//! displacement component multilinearly from the coarse grid's nodes to the fine level's
//! dofs, located at their nodes. Partially filled cells, fixed and tied dofs need no special
//! case: P maps to the free equations only (a fixed dof is not a row of P), and a coarse dof
//! exists where some fine equation draws on it. The coarse operators are Galerkin products
//! A_{l+1} = Pᵀ A_l P, so the ghost penalty, the contact of slivers and the material tangent
//! all pass to the coarse levels; the coarsest (at most [`COARSE_SIZE`] equations) is
//! factorised directly (LDLᵀ, or LU if it is not symmetric). Smoothing is Chebyshev of degree [`CHEBYSHEV_DEGREE`] on D_ℓ1⁻¹A,
//! D_ℓ1 = diag(Σ_j |a_ij|), whose spectrum Gershgorin bounds by 1: the interval needs no
//! eigenvalue estimate and cannot fall short of λ_max, which made the smoother diverge at
//! 2e6 unknowns with a power-method estimate, and nearly empty cells (tiny diagonals) do not
//! stretch it (the same polynomial before and after the coarse correction, so the V-cycle is
//! a symmetric preconditioner and CG applies).
//!
//! The hierarchy needs no symbolic analysis: P depends only on where the equations sit, and
//! the Galerkin products are computed with a sparse accumulator.
//!
//! # References
//! Trottenberg, Oosterlee & Schüller, *Multigrid* (2001), ch. 2 and 7 (Galerkin coarse
//! operators); Adams, Brezina, Hu & Tuminaro, "Parallel multigrid smoothing: polynomial
//! versus Gauss–Seidel", J. Comput. Phys. 188 (2003) (Chebyshev smoothers); Baker, Falgout,
//! Kolev & Yang, "Multigrid smoothers for ultraparallel computing", SIAM J. Sci. Comput. 33
//! (2011) (ℓ1-Jacobi); Saad, *Iterative Methods for Sparse Linear Systems* (2003), alg. 6.18 (PCG), alg. 9.5
//! (right-preconditioned GMRES) and alg. 12.1 (Chebyshev).

use crate::solver::direct::{DirectSolver, Factorisation};
use crate::solver::error::SolverError;
use crate::solver::krylov::Preconditioner;
use crate::solver::sparse::{Csr, SparseMatrix};
use rayon::prelude::*;

/// The coarsest level is solved directly once it has at most this many equations.
pub const COARSE_SIZE: usize = 2_000;
/// Degree of the Chebyshev smoother (matrix–vector products per smoothing).
pub const CHEBYSHEV_DEGREE: usize = 3;
/// Chebyshev smooths the eigenvalues of D_ℓ1⁻¹A in [1 / `CHEBYSHEV_RATIO`, 1].
pub const CHEBYSHEV_RATIO: f64 = 10.0;
/// Most levels (a grid of 2^20 cells per axis has 21).
pub const MAX_LEVELS: usize = 24;

/// Where each equation sits: the position of its node (padded to three components) and the
/// displacement component it carries; `spacing` is the fine grid's (or mesh's element) size
/// per axis, `dim` the problem's dimension.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct DofGeometry {
    /// The problem's dimension (1, 2 or 3).
    pub dim: usize,
    /// The level's grid spacing per axis (on the finest level, the grid's or mesh's element size).
    pub spacing: [f64; 3],
    /// Position of each equation's node, padded with zeros to three components.
    pub positions: Vec<[f64; 3]>,
    /// Displacement component (axis) each equation carries.
    pub components: Vec<u8>,
}

/// Where the nodes of a discretisation sit (padded to three components) and its fine spacing
/// per axis: what a solver hands its workspace so that the equations can be located
/// ([`DofGeometry::of_equations`]).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct NodeGeometry {
    /// The problem's dimension (1, 2 or 3).
    pub dim: usize,
    /// Position of each node, padded with zeros to three components.
    pub positions: Vec<[f64; 3]>,
    /// The fine grid spacing (or mesh element size) per axis.
    pub spacing: [f64; 3],
}

/// The prolongation from the grid of spacing `coarse` (origin `origin`) to the equations of
/// `fine`: row i interpolates component `components[i]` multilinearly from the 2^dim coarse
/// nodes around `positions[i]`; weights below 1e-12 are dropped. Returns P and the coarse
/// level's geometry (its equations numbered in order of first use, so deterministically).
pub fn prolongation(fine: &DofGeometry, origin: [f64; 3], coarse: [f64; 3]) -> (Csr, DofGeometry) {
    let dim = fine.dim;
    // The coarse nodes that can be touched: a box of node indices around the fine positions.
    let mut hi = [0i64; 3];
    for x in &fine.positions {
        for a in 0..dim {
            hi[a] = hi[a].max(((x[a] - origin[a]) / coarse[a]).floor() as i64 + 1);
        }
    }
    let extent: [usize; 3] = std::array::from_fn(|a| if a < dim { (hi[a] + 1) as usize } else { 1 });
    let nodes = extent[0] * extent[1] * extent[2];
    let mut number = vec![usize::MAX; nodes * dim];
    let mut out = DofGeometry {
        dim,
        spacing: coarse,
        positions: vec![],
        components: vec![],
    };
    let mut ptr = Vec::with_capacity(fine.positions.len() + 1);
    let (mut p_idx, mut p_val): (Vec<u32>, Vec<f64>) = (vec![], vec![]);
    ptr.push(0);
    for (x, &c) in fine.positions.iter().zip(&fine.components) {
        let mut cell = [0usize; 3];
        let mut t = [0.0; 3];
        for a in 0..dim {
            let s = ((x[a] - origin[a]) / coarse[a]).max(0.0);
            let k = (s.floor() as usize).min(extent[a].saturating_sub(2));
            cell[a] = k;
            t[a] = (s - k as f64).clamp(0.0, 1.0);
        }
        let start = p_idx.len();
        for corner in 0..1usize << dim {
            let mut w = 1.0;
            let mut node = [0usize; 3];
            for a in 0..dim {
                let up = (corner >> a) & 1 == 1;
                node[a] = cell[a] + up as usize;
                #[cfg(feature = "seeded-bugs")]
                let up = up != crate::seeded::active(crate::seeded::Bug::SwappedProlongation);
                w *= if up { t[a] } else { 1.0 - t[a] };
            }
            if w.abs() < 1e-12 {
                continue;
            }
            let flat = (node[2] * extent[1] + node[1]) * extent[0] + node[0];
            let slot = &mut number[flat * dim + c as usize];
            if *slot == usize::MAX {
                *slot = out.positions.len();
                out.positions.push(std::array::from_fn(|a| {
                    if a < dim {
                        origin[a] + node[a] as f64 * coarse[a]
                    } else {
                        0.0
                    }
                }));
                out.components.push(c);
            }
            p_idx.push(u32::try_from(*slot).expect("a coarse level has fewer than 2^32 equations"));
            p_val.push(w);
        }
        // Sorted columns per row (the accumulator products expect nothing more).
        let (idx, val) = (&mut p_idx[start..], &mut p_val[start..]);
        let mut pairs: Vec<(u32, f64)> = idx.iter().copied().zip(val.iter().copied()).collect();
        pairs.sort_unstable_by_key(|e| e.0);
        for (k, (i, v)) in pairs.into_iter().enumerate() {
            idx[k] = i;
            val[k] = v;
        }
        ptr.push(p_idx.len());
    }
    let p = Csr::new(fine.positions.len(), out.positions.len(), ptr, p_idx, p_val);
    (p, out)
}

/// One level of the hierarchy: its operator, the prolongation from the next coarser level,
/// the inverse diagonal and the Chebyshev interval.
#[derive(Debug, Clone)]
struct Level {
    /// The level's operator (on the finest, a copy of the values of the matrix the hierarchy
    /// was built from, sharing the solver's pattern ([`Csr`]'s clone)): the finest level must
    /// match the coarse operators built from it, or the preconditioner degrades (tripled CG
    /// iterations when it did not, reference/README.md item 59).
    a: Csr,
    p: Csr,
    r: Csr,
    /// 1 / Σ_j |a_ij| per row (ℓ1-Jacobi).
    inv_diag: Vec<f64>,
}

/// Is `a` symmetric to rounding (|a_ij − a_ji| ≤ 1e-10 max |a|, same pattern both ways)?
fn is_symmetric(a: &Csr) -> bool {
    let t = a.transpose();
    let scale = a.val.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    t.ptr == a.ptr
        && t.idx == a.idx
        && t.val
            .iter()
            .zip(&a.val)
            .all(|(x, y)| (x - y).abs() <= 1e-10 * scale)
}

/// A multigrid V-cycle for one matrix.
#[derive(Debug)]
pub struct Hierarchy {
    levels: Vec<Level>,
    coarse: DirectSolver,
    /// The V-cycle's work vectors, one set per level, allocated once with the hierarchy (a
    /// preconditioner application allocates nothing). Behind a lock because
    /// [`Preconditioner::apply`] takes `&self`; a Krylov solve applies it from one thread.
    work: std::sync::Mutex<Vec<LevelWork>>,
}

/// One level's work vectors: residual and Chebyshev direction (the level's size), the
/// restricted residual and the coarse correction (the next level's size).
#[derive(Debug)]
struct LevelWork {
    r: Vec<f64>,
    d: Vec<f64>,
    bc: Vec<f64>,
    xc: Vec<f64>,
}

impl Hierarchy {
    /// The hierarchy of `a` (symmetric, the equations of `geometry`): coarse levels of twice
    /// the spacing until at most [`COARSE_SIZE`] equations remain or a level stops shrinking.
    pub fn build(fine: &Csr, geometry: &DofGeometry) -> Result<Self, SolverError> {
        let a = fine;
        if geometry.positions.len() != a.rows || geometry.components.len() != a.rows {
            return Err(SolverError::Multigrid(format!(
                "multigrid: {} equations but geometry for {}",
                a.rows,
                geometry.positions.len()
            )));
        }
        let mut origin = [0.0; 3];
        for a_ in 0..geometry.dim {
            origin[a_] = geometry
                .positions
                .iter()
                .map(|x| x[a_])
                .fold(f64::INFINITY, f64::min);
        }
        let mut levels: Vec<Level> = vec![];
        let mut geo = geometry.clone();
        // The operator of the level being coarsened: the borrowed fine matrix, then owned
        // Galerkin products.
        let mut owned: Option<Csr> = None;
        let mut spacing = geometry.spacing;
        loop {
            let a = owned.as_ref().unwrap_or(a);
            if a.rows <= COARSE_SIZE || levels.len() >= MAX_LEVELS {
                break;
            }
            spacing.iter_mut().for_each(|h| *h *= 2.0);
            let (p, coarse_geo) = prolongation(&geo, origin, spacing);
            if p.cols * 10 > a.rows * 9 {
                // Not shrinking by at least 10 % (e.g. a grid one cell thick along every
                // coarsened axis): another level would cost a Galerkin product and a
                // smoother for almost no coarsening. A structured grid coarsens by about
                // 2^dim per level, so the bound only stops degenerate cases.
                break;
            }
            let r = p.transpose();
            let coarse = r.matmul(&a.matmul(&p));
            let diag = a.diagonal();
            if let Some(i) = diag.iter().position(|&d| !(d > 0.0 && d.is_finite())) {
                // Not positive definite: CG could not use it either.
                return Err(SolverError::Multigrid(format!(
                    "multigrid: diagonal entry {i} is {} (not positive)",
                    diag[i]
                )));
            }
            // ℓ1-Jacobi: D_ℓ1 = diag(Σ_j |a_ij|) bounds λ_max(D_ℓ1⁻¹A) by 1 (Gershgorin), so
            // the Chebyshev interval needs no eigenvalue estimate and can never fall short.
            let inv_diag: Vec<f64> = (0..a.rows)
                .map(|i| 1.0 / a.val[a.ptr[i]..a.ptr[i + 1]].iter().map(|v| v.abs()).sum::<f64>())
                .collect();
            levels.push(Level {
                a: match owned.take() {
                    Some(m) => m,
                    None => fine.clone(),
                },
                p,
                r,
                inv_diag,
            });
            owned = Some(coarse);
            geo = coarse_geo;
        }
        let a = owned.as_ref().unwrap_or(a);
        // The coarsest operator, factorised directly: LDLᵀ if it is symmetric (to rounding),
        // LU if not, so that the coarse correction is exact for GMRES on a non-symmetric
        // tangent. The pattern is structurally symmetric (every tangent's is), so the rows'
        // patterns are the columns'.
        let mut matrix = SparseMatrix::default();
        let columns: Vec<Vec<usize>> = (0..a.rows)
            .map(|i| {
                a.idx[a.ptr[i]..a.ptr[i + 1]]
                    .iter()
                    .map(|&j| j as usize)
                    .collect()
            })
            .collect();
        matrix.set_pattern(columns);
        for i in 0..a.rows {
            for k in a.ptr[i]..a.ptr[i + 1] {
                matrix.add(i, a.idx[k] as usize, a.val[k]);
            }
        }
        let mut coarse = DirectSolver::default();
        if a.rows > 0 {
            let kind = if is_symmetric(a) {
                Factorisation::Ldlt
            } else {
                Factorisation::Lu
            };
            coarse.factorize(matrix.csc().transpose_as_csc(), kind)?;
        }
        let work = levels
            .iter()
            .map(|lv| LevelWork {
                r: vec![0.0; lv.a.rows],
                d: vec![0.0; lv.a.rows],
                bc: vec![0.0; lv.p.cols],
                xc: vec![0.0; lv.p.cols],
            })
            .collect();
        Ok(Hierarchy {
            levels,
            coarse,
            work: std::sync::Mutex::new(work),
        })
    }

    /// `x = M⁻¹ b`: one V-cycle from a zero guess.
    pub fn apply(&self, b: &[f64], x: &mut [f64]) -> Result<(), SolverError> {
        let mut work = self
            .work
            .lock()
            .map_err(|_| SolverError::Multigrid("multigrid: work vectors poisoned".into()))?;
        self.cycle(0, b, x, &mut work)
    }

    /// Level `l` of the V-cycle; every work vector is overwritten before it is read, so
    /// reusing them across applications changes nothing.
    fn cycle(&self, l: usize, b: &[f64], x: &mut [f64], work: &mut [LevelWork]) -> Result<(), SolverError> {
        if l == self.levels.len() {
            x.copy_from_slice(b);
            return self.coarse.solve_in_place(x);
        }
        let (w, rest) = work.split_first_mut().expect("a work set per level");
        let lv = &self.levels[l];
        let a = &lv.a;
        x.iter_mut().for_each(|v| *v = 0.0);
        let (r, d) = (&mut w.r[..], &mut w.d[..]);
        chebyshev(lv, b, x, r, d, true);
        a.residual(b, x, r);
        lv.r.mul_vec(r, &mut w.bc);
        self.cycle(l + 1, &w.bc, &mut w.xc, rest)?;
        lv.p.mul_vec(&w.xc, r);
        x.par_iter_mut().zip(&*r).for_each(|(xi, ei)| *xi += ei);
        chebyshev(lv, b, x, r, d, false);
        Ok(())
    }
}

/// [`CHEBYSHEV_DEGREE`] Chebyshev iterations on the level's A x = b preconditioned by D_ℓ1⁻¹
/// over [1 / [`CHEBYSHEV_RATIO`], 1] (Saad alg. 12.1), from x = 0 if `zero_guess`; `r`, `d`
/// are work vectors.
fn chebyshev(lv: &Level, b: &[f64], x: &mut [f64], r: &mut [f64], d: &mut [f64], zero_guess: bool) {
    let a = &lv.a;
    let (lo, hi) = (1.0 / CHEBYSHEV_RATIO, 1.0);
    let theta = 0.5 * (hi + lo);
    let delta = 0.5 * (hi - lo);
    let sigma = theta / delta;
    let mut rho = 1.0 / sigma;
    if zero_guess {
        // r = b − A·0: one matrix product saved per V-cycle and level.
        r.copy_from_slice(b);
    } else {
        a.residual(b, x, r);
    }
    d.par_iter_mut()
        .zip(r.par_iter())
        .zip(lv.inv_diag.par_iter())
        .for_each(|((di, ri), w)| *di = ri * w / theta);
    for k in 0..CHEBYSHEV_DEGREE {
        x.par_iter_mut().zip(d.par_iter()).for_each(|(xi, di)| *xi += di);
        if k + 1 == CHEBYSHEV_DEGREE {
            break;
        }
        a.residual(b, x, r);
        let rho_new = 1.0 / (2.0 * sigma - rho);
        let (c1, c2) = (rho_new * rho, 2.0 * rho_new / delta);
        d.par_iter_mut()
            .zip(r.par_iter())
            .zip(lv.inv_diag.par_iter())
            .for_each(|((di, ri), w)| *di = c1 * *di + c2 * ri * w);
        rho = rho_new;
    }
}

impl Preconditioner for Hierarchy {
    fn apply(&self, b: &[f64], x: &mut [f64]) -> Result<(), SolverError> {
        Hierarchy::apply(self, b, x)
    }
}
