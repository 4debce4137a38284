//! Preconditioned Krylov solvers: CG (Saad, *Iterative Methods for Sparse Linear Systems*,
//! 2003, alg. 6.18) for the symmetric positive definite tangents and restarted
//! right-preconditioned GMRES (alg. 9.5) for the rest, over a row-compressed matrix and any
//! [`Preconditioner`] (the multigrid V-cycle of [`crate::solver::multigrid`]). Imports only
//! [`crate::solver::sparse`].

use crate::solver::error::SolverError;
use crate::solver::sparse::{Csr, CHUNK};
use rayon::prelude::*;

/// `x = M⁻¹ b` for a fixed preconditioner M.
pub trait Preconditioner {
    /// Write M⁻¹ `b` into `x`.
    fn apply(&self, b: &[f64], x: &mut [f64]) -> Result<(), SolverError>;
}

/// uᵀv with a summation order fixed by `CHUNK` alone: partial sums of fixed chunks in
/// parallel, added in order. (rayon's `sum` splits where work is stolen, so its result can
/// change from run to run in the last bits, and CG at an indefinite iterate can then break
/// down in one run and not in another.)
pub fn dot(u: &[f64], v: &[f64]) -> f64 {
    let parts: Vec<f64> = u
        .par_chunks(CHUNK)
        .zip(v.par_chunks(CHUNK))
        .map(|(a, b)| a.iter().zip(b).map(|(x, y)| x * y).sum::<f64>())
        .collect();
    parts.iter().sum()
}

/// What a preconditioned Krylov solve ([`pcg`] or [`gmres`]) did.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct KrylovReport {
    /// Krylov iterations taken.
    pub iterations: usize,
    /// ‖b − A x‖ / ‖b‖ at the end.
    pub relative_residual: f64,
}

impl KrylovReport {
    /// x = 0 solves b = 0.
    const EXACT: KrylovReport = KrylovReport {
        iterations: 0,
        relative_residual: 0.0,
    };
}

/// The start of a Krylov solve: x = 0, and ‖b‖ unless b = 0 (then x = 0 is the solution).
fn zero_start(b: &[f64], x: &mut [f64]) -> Option<f64> {
    x.iter_mut().for_each(|v| *v = 0.0);
    let bnorm = dot(b, b).sqrt();
    (bnorm != 0.0).then_some(bnorm)
}

/// Solve `A x = b` by CG preconditioned with `m`'s V-cycle (built for A or for an earlier
/// matrix of the same pattern: any fixed symmetric positive definite preconditioner serves),
/// from x = 0, until ‖b − A x‖ ≤ `rtol` ‖b‖ (Saad alg. 6.18). An error if `max_iterations`
/// pass first or the iteration breaks down (A or M not positive definite along the search
/// direction).
pub fn pcg(
    a: &Csr,
    m: &impl Preconditioner,
    b: &[f64],
    x: &mut [f64],
    rtol: f64,
    max_iterations: usize,
) -> Result<KrylovReport, SolverError> {
    let n = b.len();
    let Some(bnorm) = zero_start(b, x) else {
        return Ok(KrylovReport::EXACT);
    };
    let mut r = b.to_vec();
    let mut z = vec![0.0; n];
    m.apply(&r, &mut z)?;
    let mut p = z.clone();
    let mut q = vec![0.0; n];
    let mut rz = dot(&r, &z);
    for it in 1..=max_iterations {
        a.mul_vec(&p, &mut q);
        let pq = dot(&p, &q);
        if !(pq > 0.0 && rz > 0.0) {
            return Err(SolverError::Krylov(format!(
                "CG broke down at iteration {it} (pᵀAp = {pq:e}, rᵀz = {rz:e}): the tangent or the preconditioner is not positive definite"
            )));
        }
        let alpha = rz / pq;
        x.par_iter_mut()
            .zip(p.par_iter())
            .for_each(|(xi, pi)| *xi += alpha * pi);
        r.par_iter_mut()
            .zip(q.par_iter())
            .for_each(|(ri, qi)| *ri -= alpha * qi);
        let rel = dot(&r, &r).sqrt() / bnorm;
        if rel <= rtol {
            return Ok(KrylovReport {
                iterations: it,
                relative_residual: rel,
            });
        }
        m.apply(&r, &mut z)?;
        let rz_new = dot(&r, &z);
        let beta = rz_new / rz;
        rz = rz_new;
        p.par_iter_mut()
            .zip(z.par_iter())
            .for_each(|(pi, zi)| *pi = zi + beta * *pi);
    }
    Err(SolverError::Krylov(format!(
        "CG did not reach the relative residual {rtol:e} in {max_iterations} iterations"
    )))
}

/// Krylov vectors kept by [`gmres`] before it restarts.
pub const GMRES_RESTART: usize = 30;

/// Solve `A x = b` by restarted GMRES(`GMRES_RESTART`) right-preconditioned with `m`'s V-cycle
/// (Saad alg. 9.5), from x = 0, until ‖b − A x‖ ≤ `rtol` ‖b‖. Unlike [`pcg`] it needs
/// neither A nor M positive definite nor A symmetric: it serves the tangents on which CG
/// breaks down (a buckling cantilever's, far from equilibrium). Right preconditioning makes
/// the Arnoldi residual the true one, so the stopping test is on ‖b − A x‖; each cycle's
/// update is checked against a fresh residual before the next. An error if `max_iterations`
/// pass first or the Krylov space stops growing short of the tolerance.
pub fn gmres(
    a: &Csr,
    m: &impl Preconditioner,
    b: &[f64],
    x: &mut [f64],
    rtol: f64,
    max_iterations: usize,
) -> Result<KrylovReport, SolverError> {
    let n = b.len();
    let k = GMRES_RESTART;
    let Some(bnorm) = zero_start(b, x) else {
        return Ok(KrylovReport::EXACT);
    };
    let target = rtol * bnorm;
    let mut v: Vec<Vec<f64>> = (0..=k).map(|_| vec![0.0; n]).collect();
    let mut h = vec![[0.0; GMRES_RESTART]; GMRES_RESTART + 1];
    let (mut cs, mut sn) = ([0.0; GMRES_RESTART], [0.0; GMRES_RESTART]);
    let mut g = [0.0; GMRES_RESTART + 1];
    let mut z = vec![0.0; n];
    let mut w = vec![0.0; n];
    let mut r = b.to_vec();
    let mut beta = bnorm;
    let mut iterations = 0;
    while iterations < max_iterations {
        v[0].iter_mut().zip(&r).for_each(|(vi, ri)| *vi = ri / beta);
        g.iter_mut().for_each(|gi| *gi = 0.0);
        g[0] = beta;
        let mut used = 0;
        for j in 0..k {
            if iterations == max_iterations {
                break;
            }
            iterations += 1;
            m.apply(&v[j], &mut z)?;
            a.mul_vec(&z, &mut w);
            // Modified Gram–Schmidt against the basis so far.
            for i in 0..=j {
                let hij = dot(&w, &v[i]);
                h[i][j] = hij;
                w.par_iter_mut()
                    .zip(v[i].par_iter())
                    .for_each(|(wi, vi)| *wi -= hij * vi);
            }
            let norm = dot(&w, &w).sqrt();
            h[j + 1][j] = norm;
            // Earlier rotations, then the one that zeroes h[j+1][j].
            for i in 0..j {
                let t = cs[i] * h[i][j] + sn[i] * h[i + 1][j];
                h[i + 1][j] = -sn[i] * h[i][j] + cs[i] * h[i + 1][j];
                h[i][j] = t;
            }
            let d = h[j][j].hypot(h[j + 1][j]);
            if d == 0.0 {
                return Err(SolverError::Krylov(format!(
                    "GMRES broke down at iteration {iterations} (zero Hessenberg column)"
                )));
            }
            cs[j] = h[j][j] / d;
            sn[j] = h[j + 1][j] / d;
            h[j][j] = d;
            h[j + 1][j] = 0.0;
            g[j + 1] = -sn[j] * g[j];
            g[j] *= cs[j];
            used = j + 1;
            // A lucky breakdown (w = 0) means the solution is in the space: stop either way.
            if g[j + 1].abs() <= target || norm == 0.0 {
                break;
            }
            let inv = 1.0 / norm;
            v[j + 1]
                .par_iter_mut()
                .zip(w.par_iter())
                .for_each(|(vi, wi)| *vi = wi * inv);
        }
        // y = H⁻¹ g (upper triangular), x += M⁻¹ (V y).
        let mut y = [0.0; GMRES_RESTART];
        for i in (0..used).rev() {
            let s: f64 = (i + 1..used).map(|l| h[i][l] * y[l]).sum();
            y[i] = (g[i] - s) / h[i][i];
        }
        w.iter_mut().for_each(|wi| *wi = 0.0);
        for (vi, yi) in v.iter().zip(&y[..used]) {
            w.par_iter_mut()
                .zip(vi.par_iter())
                .for_each(|(wi, vij)| *wi += yi * vij);
        }
        m.apply(&w, &mut z)?;
        x.par_iter_mut().zip(z.par_iter()).for_each(|(xi, zi)| *xi += zi);
        // The true residual, so that rounding in the rotations cannot pass a wrong answer.
        a.residual(b, x, &mut r);
        beta = dot(&r, &r).sqrt();
        if !beta.is_finite() {
            return Err(SolverError::Krylov(format!(
                "GMRES diverged at iteration {iterations}"
            )));
        }
        if beta <= target {
            return Ok(KrylovReport {
                iterations,
                relative_residual: beta / bnorm,
            });
        }
    }
    Err(SolverError::Krylov(format!(
        "GMRES did not reach the relative residual {rtol:e} in {max_iterations} iterations (at {:e})",
        beta / bnorm
    )))
}
