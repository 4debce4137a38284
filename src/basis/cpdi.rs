//! CPDI2 (Sadeghirad, Brannon & Guilkey 2013): each point's domain is a quadrilateral (2D),
//! hexahedron (3D) or segment (1D) tracked by its corners, which move with the grid.
//!
//! The grid's linear hats N_v are replaced on the domain by their multilinear interpolant
//! through the corners, N_v ≈ Σ_α N_v(x_α) M_α, so that
//! S_vp = Σ_α w^f_α N_v(x_α) and ∇S_vp = Σ_α w^g_α N_v(x_α), with
//! w^f_α = ∫_Ωp M_α dΩ / V_p and w^g_α = ∫_Ωp ∇M_α dΩ / V_p, V_p = |Ω_p|.
//! Both integrals are exact with 2 Gauss points per axis on the multilinear map (the
//! integrands are at most cubic per axis: det J is quadratic per axis in 3D, linear in 2D),
//! so in 2D they are the closed forms of the paper. Σ_v S_vp = Σ_α w^f_α = 1 and
//! Σ_v ∇S_vp = 0 hold for any corner positions; Σ_v S_vp x_v is the domain's centroid.
//!
//! Corners are updated with the grid: x_α ← x_α + Σ_v N_v(x_α) Δu_v (CPDI2's corner
//! update), so a domain follows shear and rotation without the F-based domain rule of eq (39).

use super::linear::LinearKernel;
use super::{AxisKernel, AxisWeights, BasisError, BasisFamily, GridAxis, PointSupport, PointView};
use crate::mesh::grid::Grid;
use nalgebra::{SMatrix, SVector};

/// CPDI2 with multilinear domains.
#[derive(Debug, Clone, Copy, Default)]
pub struct Cpdi;

/// Most corners of a domain (a hexahedron).
pub const MAX_CORNERS: usize = 8;

/// Nodes per axis of the dense node map of [`Cpdi::evaluate`]: CPDI2 reaches 3 nodes per
/// axis while a domain spans at most a cell; 4 covers domains up to two cells long, and
/// longer ones take the search path.
const MAP_SPAN: usize = 4;
const MAP_SLOTS: usize = MAP_SPAN * MAP_SPAN * MAP_SPAN;

/// Corner `k` of `D` axes: its sign along axis `a` (axis 0 fastest, as the grid's nodes).
#[inline]
fn corner_sign(k: usize, a: usize) -> f64 {
    if (k >> a) & 1 == 1 {
        1.0
    } else {
        -1.0
    }
}

/// The corners of the box `x ± r`, in corner order.
pub fn box_corners<const D: usize>(x: &SVector<f64, D>, r: &SVector<f64, D>, out: &mut Vec<SVector<f64, D>>) {
    for k in 0..(1usize << D) {
        out.push(SVector::<f64, D>::from_fn(|a, _| x[a] + corner_sign(k, a) * r[a]));
    }
}

/// The multilinear shape functions M_k and their derivatives ∂M_k/∂ξ_b at the 2^D Gauss points
/// (±1/√3 per axis) of dimension D: constants, computed once per dimension rather than at
/// every point (the same expressions in the same order as evaluated inline before, so the
/// weights are bit for bit the same).
struct GaussTable {
    m: [[f64; MAX_CORNERS]; MAX_CORNERS],
    dm: [[[f64; 3]; MAX_CORNERS]; MAX_CORNERS],
}

fn gauss_table(d: usize) -> &'static GaussTable {
    static TABLES: std::sync::OnceLock<[GaussTable; 4]> = std::sync::OnceLock::new();
    &TABLES.get_or_init(|| {
        std::array::from_fn(|d| {
            let nc = 1usize << d;
            let g = 1.0 / 3f64.sqrt();
            let mut t = GaussTable {
                m: [[0.0; MAX_CORNERS]; MAX_CORNERS],
                dm: [[[0.0; 3]; MAX_CORNERS]; MAX_CORNERS],
            };
            for q in 0..nc {
                let xi: [f64; 3] = std::array::from_fn(|a| corner_sign(q, a) * g);
                for k in 0..nc {
                    let f = |a: usize| 0.5 * (1.0 + corner_sign(k, a) * xi[a]);
                    t.m[q][k] = (0..d).map(f).product();
                    for b in 0..d {
                        t.dm[q][k][b] =
                            0.5 * corner_sign(k, b) * (0..d).filter(|&a| a != b).map(f).product::<f64>();
                    }
                }
            }
            t
        })
    })[d]
}

/// CPDI2's corner weights of a domain: (w^f_α, w^g_α) for every corner and the volume V_p,
/// by 2-point Gauss quadrature per axis on the multilinear map. Fails if the map folds
/// (det J ≤ 0 at a Gauss point: the domain is inverted or degenerate).
pub fn corner_weights<const D: usize>(
    corners: &[SVector<f64, D>],
    wf: &mut [f64; MAX_CORNERS],
    wg: &mut [SVector<f64, D>; MAX_CORNERS],
) -> Result<f64, BasisError> {
    let nc = 1usize << D;
    let table = gauss_table(D);
    *wf = [0.0; MAX_CORNERS];
    *wg = [SVector::<f64, D>::zeros(); MAX_CORNERS];
    let mut volume = 0.0;
    let mut dm = [SVector::<f64, D>::zeros(); MAX_CORNERS];
    for q in 0..nc {
        let m = &table.m[q];
        let mut jac = SMatrix::<f64, D, D>::zeros();
        for k in 0..nc {
            dm[k] = SVector::<f64, D>::from_fn(|b, _| table.dm[q][k][b]);
            jac += corners[k] * dm[k].transpose();
        }
        let jac3 = super::padded(&jac);
        let det = jac3.determinant();
        if !(det > 0.0 && det.is_finite()) {
            return Err(BasisError::InvertedDomain);
        }
        let inv_t = super::block::<D>(&jac3.try_inverse().ok_or(BasisError::InvertedDomain)?).transpose();
        volume += det;
        for k in 0..nc {
            wf[k] += m[k] * det;
            wg[k] += inv_t * dm[k] * det;
        }
    }
    for k in 0..nc {
        wf[k] /= volume;
        wg[k] /= volume;
    }
    Ok(volume)
}

/// The grid's linear hats at `x` along every axis.
fn hats<const D: usize>(
    grid: &Grid<D>,
    x: &SVector<f64, D>,
    axes: &mut [AxisWeights; D],
) -> Result<(), BasisError> {
    for (a, out) in axes.iter_mut().enumerate() {
        LinearKernel.axis_weights(GridAxis::of(grid, a), x[a], 0.0, out)?;
    }
    Ok(())
}

/// Node `k` (of 2^D) of the linear hats at one corner: (flat node, N_v).
#[inline]
fn hat_node<const D: usize>(grid: &Grid<D>, axes: &[AxisWeights; D], k: usize) -> (usize, f64) {
    let mut idx = [0usize; D];
    let mut n = 1.0;
    for a in 0..D {
        let i = (k >> a) & 1;
        idx[a] = axes[a].first + i;
        n *= axes[a].w[i];
    }
    (grid.node_index(idx), n)
}

impl<const D: usize> BasisFamily<D> for Cpdi {
    fn support_nodes(&self) -> usize {
        3
    }

    fn needs_corners(&self) -> bool {
        true
    }

    fn evaluate(
        &self,
        grid: &Grid<D>,
        point: &PointView<'_, D>,
        out: &mut PointSupport<D>,
    ) -> Result<(), BasisError> {
        out.clear();
        let corners = point.corners;
        let mut wf = [0.0; MAX_CORNERS];
        let mut wg = [SVector::<f64, D>::zeros(); MAX_CORNERS];
        corner_weights(corners, &mut wf, &mut wg)?;
        // Every corner's hats first, then the nodes they reach accumulated in the same order
        // as a search of the support would (so the weights are bit for bit the same), but
        // located through a dense map of the box of first nodes: 2^D corners × 2^D nodes
        // each, 64 look-ups in 3D, instead of a linear search of up to 27 listed nodes.
        let nc = 1usize << D;
        let mut axes = [[AxisWeights::default(); D]; MAX_CORNERS];
        let mut lo = [usize::MAX; D];
        let mut hi = [0usize; D];
        for (k, x) in corners.iter().enumerate() {
            hats(grid, x, &mut axes[k])?;
            for a in 0..D {
                lo[a] = lo[a].min(axes[k][a].first);
                hi[a] = hi[a].max(axes[k][a].first + 1);
            }
        }
        if (0..D).all(|a| hi[a] - lo[a] < MAP_SPAN) {
            let mut slot = [u8::MAX; MAP_SLOTS];
            for k in 0..nc {
                for j in 0..nc {
                    let (node, n) = hat_node(grid, &axes[k], j);
                    let mut key = 0;
                    for a in (0..D).rev() {
                        key = key * MAP_SPAN + axes[k][a].first + ((j >> a) & 1) - lo[a];
                    }
                    let (w, g) = (wf[k] * n, wg[k] * n);
                    match slot[key] {
                        u8::MAX => {
                            slot[key] = out.len() as u8;
                            out.push(node, w, g);
                        }
                        s => out.add_to(s as usize, w, g),
                    }
                }
            }
        } else {
            // A domain stretched over more than MAP_SPAN nodes along an axis.
            for (k, axes) in axes.iter().enumerate().take(nc) {
                for j in 0..nc {
                    let (node, n) = hat_node(grid, axes, j);
                    out.accumulate(node, wf[k] * n, wg[k] * n);
                }
            }
        }
        Ok(())
    }

    fn fill_box(
        &self,
        _grid: &Grid<D>,
        point: &PointView<'_, D>,
    ) -> Option<(SVector<f64, D>, SVector<f64, D>)> {
        let c = point.corners;
        let lo = SVector::<f64, D>::from_fn(|a, _| c.iter().map(|x| x[a]).fold(f64::INFINITY, f64::min));
        let hi = SVector::<f64, D>::from_fn(|a, _| c.iter().map(|x| x[a]).fold(f64::NEG_INFINITY, f64::max));
        Some((lo, hi))
    }

    fn update_corners(
        &self,
        grid: &Grid<D>,
        du_nodal: &[f64],
        corners: &mut [SVector<f64, D>],
    ) -> Result<(), BasisError> {
        let mut axes = [AxisWeights::default(); D];
        #[cfg(feature = "seeded-bugs")]
        let sign = if crate::seeded::active(crate::seeded::Bug::CornersAgainstGrid) {
            -1.0
        } else {
            1.0
        };
        #[cfg(not(feature = "seeded-bugs"))]
        let sign = 1.0;
        for x in corners.iter_mut() {
            hats(grid, x, &mut axes)?;
            let mut du = SVector::<f64, D>::zeros();
            for j in 0..(1usize << D) {
                let (node, n) = hat_node(grid, &axes, j);
                for a in 0..D {
                    du[a] += n * du_nodal[node * D + a];
                }
            }
            *x += du * sign;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Matrix3;

    /// The support as the search of every listed node builds it (the evaluation the node map
    /// and the Gauss table replaced).
    fn searched<const D: usize>(grid: &Grid<D>, corners: &[SVector<f64, D>]) -> PointSupport<D> {
        let mut out = PointSupport::default();
        let mut wf = [0.0; MAX_CORNERS];
        let mut wg = [SVector::<f64, D>::zeros(); MAX_CORNERS];
        corner_weights(corners, &mut wf, &mut wg).unwrap();
        let mut axes = [AxisWeights::default(); D];
        for (k, x) in corners.iter().enumerate() {
            hats(grid, x, &mut axes).unwrap();
            for j in 0..(1usize << D) {
                let (node, n) = hat_node(grid, &axes, j);
                out.accumulate(node, wf[k] * n, wg[k] * n);
            }
        }
        out
    }

    /// Sheared, rotated and stretched domains (up to three cells long, which takes the search
    /// path) give the searched support bit for bit: same nodes in the same order, same
    /// weights and gradients.
    fn same_as_searched<const D: usize>() {
        let grid = Grid::<D>::try_new([0.0; D], [1.0; D], [12; D]).unwrap();
        let mut state = 0x9e3779b97f4a7c15u64;
        let mut rand = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut long = 0;
        for _ in 0..400 {
            let x = SVector::<f64, D>::from_fn(|_, _| 4.0 + 4.0 * rand());
            let stretch = 0.2 + 4.0 * rand();
            let r = SVector::<f64, D>::from_fn(|_, _| 0.25 * stretch * (0.5 + rand()));
            let mut corners = vec![];
            box_corners(&x, &r, &mut corners);
            // A shear of the box about its centre.
            let shear = 0.4 * (rand() - 0.5);
            for c in corners.iter_mut() {
                let d = *c - x;
                c[0] += shear * d[D - 1];
            }
            if (0..D).any(|a| 2.0 * r[a] > 2.0) {
                long += 1;
            }
            let (f, zero) = (Matrix3::identity(), SVector::<f64, D>::zeros());
            let view = PointView {
                position: &x,
                half_length: &zero,
                position0: &x,
                half_length0: &zero,
                f: &f,
                corners: &corners,
            };
            let mut fast = PointSupport::default();
            Cpdi.evaluate(&grid, &view, &mut fast).unwrap();
            let slow = searched(&grid, &corners);
            assert_eq!(fast.nodes(), slow.nodes());
            for (a, b) in fast.weights().iter().zip(slow.weights()) {
                assert_eq!(a.to_bits(), b.to_bits());
            }
            for (a, b) in fast.gradients().iter().zip(slow.gradients()) {
                for i in 0..D {
                    assert_eq!(a[i].to_bits(), b[i].to_bits());
                }
            }
        }
        assert!(long > 0, "no domain took the search path");
    }

    #[test]
    fn node_map_equals_the_search_2d() {
        same_as_searched::<2>();
    }

    #[test]
    fn node_map_equals_the_search_3d() {
        same_as_searched::<3>();
    }
}
