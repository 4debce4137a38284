//! Gauss–Legendre quadrature on the reference interval ξ ∈ [−1, 1], used by the finite element
//! comparators ([`crate::fem`]).
//!
//! An n-point rule integrates polynomials of degree ≤ 2n − 1 exactly. Rules with 1 to
//! [`MAX_GAUSS_POINTS`] points are given in closed form (abscissae are roots of the Legendre
//! polynomial P_n; w_i = 2 / ((1 − ξ_i²) P_n'(ξ_i)²)).

use crate::solver::error::InputError;

/// Most points a rule may have.
pub const MAX_GAUSS_POINTS: usize = 5;

/// An n-point Gauss–Legendre rule: abscissae ascending in (−1, 1) and their weights (sum 2).
#[derive(Debug, Clone, PartialEq)]
pub struct GaussRule {
    points: Vec<f64>,
    weights: Vec<f64>,
}

impl GaussRule {
    /// The `n`-point rule, `1 <= n <= MAX_GAUSS_POINTS`.
    pub fn try_new(n: usize) -> Result<Self, InputError> {
        let (p, w): (Vec<f64>, Vec<f64>) = match n {
            1 => (vec![0.0], vec![2.0]),
            2 => {
                let a = 1.0 / 3f64.sqrt();
                (vec![-a, a], vec![1.0, 1.0])
            }
            3 => {
                let a = 0.6f64.sqrt();
                (vec![-a, 0.0, a], vec![5.0 / 9.0, 8.0 / 9.0, 5.0 / 9.0])
            }
            4 => {
                let r = 2.0 / 7.0 * (6.0f64 / 5.0).sqrt();
                let (a, b) = ((3.0 / 7.0 - r).sqrt(), (3.0 / 7.0 + r).sqrt());
                let s = 30f64.sqrt();
                let (wa, wb) = ((18.0 + s) / 36.0, (18.0 - s) / 36.0);
                (vec![-b, -a, a, b], vec![wb, wa, wa, wb])
            }
            5 => {
                let r = 2.0 * (10.0f64 / 7.0).sqrt();
                let (a, b) = ((5.0 - r).sqrt() / 3.0, (5.0 + r).sqrt() / 3.0);
                let s = 13.0 * 70f64.sqrt();
                let (wa, wb) = ((322.0 + s) / 900.0, (322.0 - s) / 900.0);
                (vec![-b, -a, 0.0, a, b], vec![wb, wa, 128.0 / 225.0, wa, wb])
            }
            _ => {
                return Err(InputError::new(
                    "gauss_points",
                    n,
                    format!("must be an integer in 1..={MAX_GAUSS_POINTS}"),
                ))
            }
        };
        Ok(Self {
            points: p,
            weights: w,
        })
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.points.len()
    }

    /// Always false: a rule has at least one point.
    pub fn is_empty(&self) -> bool {
        self.points.is_empty()
    }

    /// Abscissae ξ_q, ascending.
    pub fn points(&self) -> &[f64] {
        &self.points
    }

    /// Weights w_q.
    pub fn weights(&self) -> &[f64] {
        &self.weights
    }

    /// ∫₋₁¹ f(ξ) dξ ≈ Σ_q w_q f(ξ_q).
    pub fn integrate(&self, f: impl Fn(f64) -> f64) -> f64 {
        self.points
            .iter()
            .zip(&self.weights)
            .map(|(&x, &w)| w * f(x))
            .sum()
    }
}

/// The tensor-product Gauss rule on [−1, 1]^D with `n` points per axis: points and weights
/// Π_d w_{i_d}, the first axis fastest (the element loops of [`crate::fem`] rely on it).
pub fn tensor_rule<const D: usize>(n: usize) -> Result<Vec<(nalgebra::SVector<f64, D>, f64)>, InputError> {
    let rule = GaussRule::try_new(n)?;
    let total = n.pow(D as u32);
    let mut out = Vec::with_capacity(total);
    for flat in 0..total {
        let mut xi = nalgebra::SVector::<f64, D>::zeros();
        let mut w = 1.0;
        let mut rest = flat;
        for d in 0..D {
            let i = rest % n;
            rest /= n;
            xi[d] = rule.points()[i];
            w *= rule.weights()[i];
        }
        out.push((xi, w));
    }
    Ok(out)
}
