//! Fourth-order tensors on 3×3 matrices stored as 9×9 matrices: entry `(3i+j, 3k+l)` is
//! `A_ijkl`, so `A : X` is a matrix–vector product on the row-major flattening of `X`.

use nalgebra::{Matrix3, SMatrix, SVector};

/// A fourth-order tensor `A_ijkl` as a 9×9 matrix.
pub type Tensor4 = SMatrix<f64, 9, 9>;

/// Row index of component `(i, j)` in a [`Tensor4`].
#[inline(always)]
pub const fn ij(i: usize, j: usize) -> usize {
    3 * i + j
}

/// Row-major flattening of a 3×3 matrix.
#[inline]
pub fn flatten(m: &Matrix3<f64>) -> SVector<f64, 9> {
    SVector::<f64, 9>::from_fn(|r, _| m[(r / 3, r % 3)])
}

/// Inverse of [`flatten`].
#[inline]
pub fn unflatten(v: &SVector<f64, 9>) -> Matrix3<f64> {
    Matrix3::from_fn(|i, j| v[ij(i, j)])
}

/// The deviator `X − (tr X / 3) 1`.
#[inline]
pub fn deviator(m: &Matrix3<f64>) -> Matrix3<f64> {
    m - Matrix3::identity() * (m.trace() / 3.0)
}

/// `A : X` for a fourth-order `A` and second-order `X`.
#[inline]
pub fn contract(a: &Tensor4, x: &Matrix3<f64>) -> Matrix3<f64> {
    unflatten(&(a * flatten(x)))
}

/// The entries of [`identity_sym`] (`sym`) or [`identity_outer`], column by column, formed
/// at compile time: the constitutive tangents ask for them at every point and Newton
/// iteration, where forming them took a tenth of an F-bar tangent (reference/README.md
/// item 78).
const fn identity_columns(sym: bool) -> [[f64; 9]; 9] {
    let mut out = [[0.0; 9]; 9];
    let mut c = 0;
    while c < 9 {
        let mut r = 0;
        while r < 9 {
            let (i, j, k, l) = (r / 3, r % 3, c / 3, c % 3);
            out[c][r] = if sym {
                0.5 * ((((i == k) && (j == l)) as u8 + ((i == l) && (j == k)) as u8) as f64)
            } else {
                ((i == j) && (k == l)) as u8 as f64
            };
            r += 1;
        }
        c += 1;
    }
    out
}

const IDENTITY_SYM: Tensor4 = Tensor4::from_array_storage(nalgebra::ArrayStorage(identity_columns(true)));
const IDENTITY_OUTER: Tensor4 = Tensor4::from_array_storage(nalgebra::ArrayStorage(identity_columns(false)));

/// Symmetric fourth-order identity `½(δ_ik δ_jl + δ_il δ_jk)`.
#[inline]
pub fn identity_sym() -> Tensor4 {
    IDENTITY_SYM
}

/// `δ_ij δ_kl`.
#[inline]
pub fn identity_outer() -> Tensor4 {
    IDENTITY_OUTER
}

/// Outer product `A_ij B_kl`.
pub fn outer(a: &Matrix3<f64>, b: &Matrix3<f64>) -> Tensor4 {
    flatten(a) * flatten(b).transpose()
}

/// Pad a `D`-vector to three components.
pub fn pad3<const D: usize>(v: &nalgebra::SVector<f64, D>) -> [f64; 3] {
    let mut out = [0.0; 3];
    for a in 0..D.min(3) {
        out[a] = v[a];
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The compile-time identities are the formulas' entries.
    #[test]
    fn the_identities_are_their_formulas() {
        let sym = Tensor4::from_fn(|r, c| {
            let (i, j, k, l) = (r / 3, r % 3, c / 3, c % 3);
            0.5 * (((i == k) && (j == l)) as u8 as f64 + ((i == l) && (j == k)) as u8 as f64)
        });
        let outer = Tensor4::from_fn(|r, c| ((r / 3 == r % 3) && (c / 3 == c % 3)) as u8 as f64);
        assert_eq!(identity_sym(), sym);
        assert_eq!(identity_outer(), outer);
    }
}
