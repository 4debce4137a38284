//! Weighting functions S_vp and their gradients behind one contract, [`BasisFamily`]: each
//! family (plain MPM, GIMP split per element (eqs 7–10), CPDI2, quadratic and cubic
//! B-splines, total-Lagrangian MPM) is one file that owns its support, its weights and
//! gradients at a point from the point's state ([`PointView`]: position, domain, F, corners),
//! its domain state update, its reference configuration and the region the ghost penalty
//! counts as its material. Solvers, problems and studies name a family by [`Basis`] and never
//! match on it.
//!
//! The tensor-product families are written one axis at a time ([`AxisKernel`]) and combined
//! by [`TensorProduct`], as the paper does for 2D (§2.2). Evaluation fills caller-owned values
//! and never allocates.

pub mod bspline;
pub mod bspline_gimp;
pub mod cpdi;
pub mod gimp;
pub mod linear;
pub mod method;
mod tensor_product;
pub mod total_lagrangian;

pub use bspline::{BsplineKernel, SplineBoundary, SplineDegree};
pub use bspline_gimp::BsplineGimpKernel;
pub use cpdi::Cpdi;
pub use gimp::{gimp_element_weights, GimpKernel};
pub use linear::LinearKernel;
pub use tensor_product::{Support, TensorProduct};
pub use total_lagrangian::TotalLagrangian;

use crate::material::kinematics::stretch_tensor;
use crate::mesh::grid::Grid;
use nalgebra::{Matrix3, SVector};
use serde::{Deserialize, Serialize};

/// Most nodes a point may touch along one axis: a GIMP domain up to two elements long (a
/// cubic B-spline touches 4).
pub const MAX_AXIS_NODES: usize = 5;

/// Most nodes one integration point may touch: [`MAX_AXIS_NODES`] per axis in 3D.
pub const MAX_POINT_NODES: usize = MAX_AXIS_NODES * MAX_AXIS_NODES * MAX_AXIS_NODES;

/// Weights along one axis: nodes `first .. first + len` with values `w` and derivatives `dw`
/// with respect to the grid coordinate.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct AxisWeights {
    /// Index along this axis of the first grid node the point touches.
    pub first: usize,
    /// How many consecutive nodes the point touches along this axis (at most [`MAX_AXIS_NODES`]).
    pub len: usize,
    /// This axis's factor of S_vp for each touched node; entries from `len` on are unused.
    pub w: [f64; MAX_AXIS_NODES],
    /// Derivative of each `w` along the axis (per unit length); entries from `len` on are unused.
    pub dw: [f64; MAX_AXIS_NODES],
}

/// Why weights could not be evaluated.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum BasisError {
    /// The point (or its domain) is not inside the grid along this axis.
    OutsideGrid {
        /// The axis along which the point or domain leaves the grid.
        axis: usize,
    },
    /// The domain spans more than `MAX_AXIS_NODES - 1` elements.
    DomainTooLarge {
        /// The axis along which the domain is too long.
        axis: usize,
    },
    /// The domain half-length is not positive and finite (a collapsed GIMP domain).
    DegenerateDomain {
        /// The axis along which the half-length collapsed.
        axis: usize,
    },
    /// A corner-tracked domain (CPDI) folded over (its map's Jacobian is not positive), or a
    /// total-Lagrangian point's F is singular.
    InvertedDomain,
    /// The family is not a tensor product of axis kernels (CPDI, TLMPM) and was asked for
    /// one axis's weights.
    NotTensorProduct,
}

impl std::fmt::Display for BasisError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            BasisError::OutsideGrid { axis } => write!(f, "outside the background grid along axis {axis}"),
            BasisError::DomainTooLarge { axis } => {
                write!(
                    f,
                    "domain longer than {} elements along axis {axis}",
                    MAX_AXIS_NODES - 2
                )
            }
            BasisError::DegenerateDomain { axis } => {
                write!(f, "domain length collapsed to <= 0 along axis {axis}")
            }
            BasisError::InvertedDomain => write!(f, "domain inverted (Jacobian of its map <= 0)"),
            BasisError::NotTensorProduct => write!(f, "not a tensor-product basis"),
        }
    }
}

/// One axis of a background grid.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GridAxis {
    /// Which axis (for error messages).
    pub axis: usize,
    /// Coordinate of the axis's first node.
    pub origin: f64,
    /// Element size h.
    pub spacing: f64,
    /// Number of elements along the axis.
    pub cells: usize,
}

impl GridAxis {
    /// Axis `a` of `grid`.
    pub fn of<const D: usize>(grid: &Grid<D>, a: usize) -> Self {
        GridAxis {
            axis: a,
            origin: grid.origin()[a],
            spacing: grid.spacing()[a],
            cells: grid.cells()[a],
        }
    }

    /// The element holding coordinate `x`, clamped to the grid (a point on the outer face
    /// belongs to the last element; a non-finite `x` to an end element).
    #[inline]
    pub fn cell_of(&self, x: f64) -> usize {
        (((x - self.origin) / self.spacing).floor().max(0.0) as usize).min(self.cells - 1)
    }
}

/// How material point domains are updated at the end of a load step (§3.3).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum DomainUpdate {
    /// l_i = l_i0 U_ii with the right stretch tensor U = √(FᵀF), eq (39) (the paper's choice).
    #[default]
    Stretch,
    /// l_i = l_i0 F_ii, eq (37) (cpGIMP); fails under large rotation.
    FDiagonal,
    /// Domains never change (uGIMP).
    Fixed,
}

impl DomainUpdate {
    /// Domain half-lengths of a point with initial half-lengths `r0` after committing `f`
    /// (eqs 37/39).
    pub fn half_length<const D: usize>(self, r0: &SVector<f64, D>, f: &Matrix3<f64>) -> SVector<f64, D> {
        match self {
            DomainUpdate::Stretch => {
                let u = stretch_tensor(f);
                SVector::<f64, D>::from_fn(|a, _| r0[a] * u[(a, a)])
            }
            DomainUpdate::FDiagonal => SVector::<f64, D>::from_fn(|a, _| r0[a] * f[(a, a)]),
            DomainUpdate::Fixed => *r0,
        }
    }
}

/// Which configuration a family's weights live in.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Configuration {
    /// The start of each load step (updated Lagrangian): weights from the current state.
    Updated,
    /// The reference configuration (total Lagrangian): weights of the initial state.
    Total,
}

/// What a family may read of one material point.
#[derive(Debug, Clone, Copy)]
pub struct PointView<'a, const D: usize> {
    /// Position x_p at the start of the step.
    pub position: &'a SVector<f64, D>,
    /// Domain half-lengths l_p / 2 at the start of the step.
    pub half_length: &'a SVector<f64, D>,
    /// Initial position X_p.
    pub position0: &'a SVector<f64, D>,
    /// Initial half-lengths.
    pub half_length0: &'a SVector<f64, D>,
    /// Committed deformation gradient F (3×3; plane strain and 1D fill the unused axes).
    pub f: &'a Matrix3<f64>,
    /// Domain corners (2^D, axis 0 fastest) for families that track them; empty otherwise.
    pub corners: &'a [SVector<f64, D>],
}

impl<'a, const D: usize> PointView<'a, D> {
    /// The same point in its reference configuration (undeformed, at X_p).
    pub fn reference(&self) -> PointView<'a, D> {
        PointView {
            position: self.position0,
            half_length: self.half_length0,
            position0: self.position0,
            half_length0: self.half_length0,
            f: &IDENTITY,
            corners: &[],
        }
    }
}

/// A D×D matrix (D ≤ 3) embedded in the identity 3×3: its determinant and inverse are those
/// of the block.
pub fn padded<const D: usize>(m: &nalgebra::SMatrix<f64, D, D>) -> Matrix3<f64> {
    let mut out = Matrix3::identity();
    for i in 0..D {
        for j in 0..D {
            out[(i, j)] = m[(i, j)];
        }
    }
    out
}

/// The D×D block of a 3×3 matrix.
pub fn block<const D: usize>(m: &Matrix3<f64>) -> nalgebra::SMatrix<f64, D, D> {
    nalgebra::SMatrix::<f64, D, D>::from_fn(|i, j| m[(i, j)])
}

static IDENTITY: Matrix3<f64> = Matrix3::new(1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0);

/// The nodes one point touches, with S_vp and ∂S_vp/∂x: a fixed-capacity list, so that
/// evaluation allocates nothing.
#[derive(Debug, Clone)]
pub struct PointSupport<const D: usize> {
    len: usize,
    nodes: [usize; MAX_POINT_NODES],
    w: [f64; MAX_POINT_NODES],
    g: [SVector<f64, D>; MAX_POINT_NODES],
}

impl<const D: usize> Default for PointSupport<D> {
    fn default() -> Self {
        Self {
            len: 0,
            nodes: [0; MAX_POINT_NODES],
            w: [0.0; MAX_POINT_NODES],
            g: [SVector::<f64, D>::zeros(); MAX_POINT_NODES],
        }
    }
}

impl<const D: usize> PointSupport<D> {
    /// Forget every listed node (the storage stays).
    pub fn clear(&mut self) {
        self.len = 0;
    }
    /// Number of nodes listed.
    pub fn len(&self) -> usize {
        self.len
    }
    /// True if no node is listed.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }
    /// Append a node (the caller guarantees it is not yet listed).
    #[inline]
    pub fn push(&mut self, node: usize, w: f64, g: SVector<f64, D>) {
        assert!(
            self.len < MAX_POINT_NODES,
            "point support exceeds MAX_POINT_NODES"
        );
        self.nodes[self.len] = node;
        self.w[self.len] = w;
        self.g[self.len] = g;
        self.len += 1;
    }
    /// Add to a node's weight and gradient, listing it if new.
    #[inline]
    pub fn accumulate(&mut self, node: usize, w: f64, g: SVector<f64, D>) {
        if let Some(k) = self.nodes[..self.len].iter().position(|&n| n == node) {
            self.w[k] += w;
            self.g[k] += g;
        } else {
            self.push(node, w, g);
        }
    }
    /// Add to the weight and gradient of local node `k` (already listed).
    #[inline]
    pub fn add_to(&mut self, k: usize, w: f64, g: SVector<f64, D>) {
        debug_assert!(k < self.len);
        self.w[k] += w;
        self.g[k] += g;
    }
    /// Local node `k`: (flat grid node, S_vp, ∂S_vp/∂x).
    #[inline]
    pub fn node(&self, k: usize) -> (usize, f64, SVector<f64, D>) {
        (self.nodes[k], self.w[k], self.g[k])
    }
    /// Flat grid indices of the listed nodes.
    pub fn nodes(&self) -> &[usize] {
        &self.nodes[..self.len]
    }
    /// S_vp of each listed node, in the order of [`Self::nodes`].
    pub fn weights(&self) -> &[f64] {
        &self.w[..self.len]
    }
    /// ∂S_vp/∂x of each listed node, in the order of [`Self::nodes`].
    pub fn gradients(&self) -> &[SVector<f64, D>] {
        &self.g[..self.len]
    }
    /// The gradients, for a family that maps them after evaluation (TLMPM's push-forward).
    pub fn gradients_mut(&mut self) -> &mut [SVector<f64, D>] {
        &mut self.g[..self.len]
    }
}

/// One axis of a tensor-product family.
pub trait AxisKernel: Sync + Send {
    /// Nodes a point with a cell-sized domain touches along the axis, in general position.
    fn support_nodes(&self) -> usize;
    /// True if the kernel integrates over the point's domain x ± r (GIMP); false for
    /// point-evaluated kernels, whose `r` is ignored.
    fn has_domain(&self) -> bool {
        false
    }
    /// Half-width, along an axis of grid spacing `spacing`, of the box whose overlap with the
    /// cells counts as a point's material for the ghost penalty's cell fill (`r`: the point's
    /// domain half-length); `None`: all of it in the cell holding the point. The default is the
    /// domain for domain kernels and `None` otherwise.
    fn fill_half_width(&self, spacing: f64, r: f64) -> Option<f64> {
        let _ = spacing;
        self.has_domain().then_some(r)
    }
    /// Weights along one grid axis for a point at `x` whose domain half-length is `r`.
    fn axis_weights(&self, axis: GridAxis, x: f64, r: f64, out: &mut AxisWeights) -> Result<(), BasisError>;
}

/// The contract of a basis family in `D` dimensions.
pub trait BasisFamily<const D: usize>: Sync + Send {
    /// Nodes per axis a point with a cell-sized domain touches, in general position (the
    /// support width: 2 for MPM, 3 for GIMP, CPDI and quadratic splines, 4 for cubic).
    fn support_nodes(&self) -> usize;

    /// The configuration the weights live in.
    fn configuration(&self) -> Configuration {
        Configuration::Updated
    }

    /// True if the family tracks domain corners ([`PointView::corners`]).
    fn needs_corners(&self) -> bool {
        false
    }

    /// S_vp and ∂S_vp/∂x on the start-of-step configuration of one point.
    fn evaluate(
        &self,
        grid: &Grid<D>,
        point: &PointView<'_, D>,
        out: &mut PointSupport<D>,
    ) -> Result<(), BasisError>;

    /// The box (lower, upper corner) whose overlap with each cell of `grid` counts as the
    /// point's material there for the ghost penalty's cell fill; `None`: all of it in the cell
    /// holding the point. Every node the point's weights reach must be a node of a cell the
    /// box overlaps, or the ghost penalty cannot see it (see the B-spline kernel's
    /// [`AxisKernel::fill_half_width`]).
    fn fill_box(
        &self,
        grid: &Grid<D>,
        point: &PointView<'_, D>,
    ) -> Option<(SVector<f64, D>, SVector<f64, D>)>;

    /// Move tracked corners with a converged nodal increment (families that track them).
    fn update_corners(
        &self,
        _grid: &Grid<D>,
        _du_nodal: &[f64],
        _corners: &mut [SVector<f64, D>],
    ) -> Result<(), BasisError> {
        Ok(())
    }
}

/// Declares the basis families once: the [`Basis`] enum, [`Basis::ALL`], and each family's
/// implementation, axis kernel, method name and label follow from one row per family, so that
/// a new in-crate family is its own file and one row here.
macro_rules! basis_families {
    ($(
        $(#[$doc:meta])*
        $variant:ident => $imp:expr, axis $axis:expr, method $method:literal, label $label:literal;
    )*) => {
        /// Which basis family a material point solver uses. The serialised names are the
        /// families' method names apart from GIMP's (`gimp`; the method is `igimp`).
        #[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Serialize, Deserialize, Hash)]
        #[serde(rename_all = "kebab-case")]
        pub enum Basis {
            $($(#[$doc])* $variant,)*
        }

        impl Basis {
            /// Every family, in declaration order.
            pub const ALL: [Basis; [$(stringify!($variant)),*].len()] = [$(Basis::$variant),*];

            /// The family's implementation in `D` dimensions.
            pub fn family<const D: usize>(self) -> &'static dyn BasisFamily<D> {
                match self {
                    $(Basis::$variant => &$imp,)*
                }
            }

            /// [`Self::family`] as a shared value, the form the solver holds (it also holds
            /// families defined outside the crate).
            pub fn shared<const D: usize>(self) -> std::sync::Arc<dyn BasisFamily<D>> {
                match self {
                    $(Basis::$variant => std::sync::Arc::new($imp),)*
                }
            }

            /// The axis kernel of a tensor-product family; `None` for CPDI and TLMPM.
            pub fn axis_kernel(self) -> Option<&'static dyn AxisKernel> {
                match self {
                    $(Basis::$variant => $axis,)*
                }
            }

            /// The name of the method in study files and `results.json`.
            pub fn method_name(self) -> &'static str {
                match self {
                    $(Basis::$variant => $method,)*
                }
            }

            /// The human name.
            pub fn label(self) -> &'static str {
                match self {
                    $(Basis::$variant => $label,)*
                }
            }
        }
    };
}

const MPM: TensorProduct<LinearKernel> = TensorProduct(LinearKernel);
const GIMP: TensorProduct<GimpKernel> = TensorProduct(GimpKernel);
const BSPLINE2: TensorProduct<BsplineKernel> = TensorProduct(BsplineKernel {
    degree: SplineDegree::Quadratic,
    boundary: SplineBoundary::LinearExtrapolation,
});
const BSPLINE3: TensorProduct<BsplineKernel> = TensorProduct(BsplineKernel {
    degree: SplineDegree::Cubic,
    boundary: SplineBoundary::LinearExtrapolation,
});
const BSPLINE2_GIMP: TensorProduct<BsplineGimpKernel> = TensorProduct(BsplineGimpKernel {
    degree: SplineDegree::Quadratic,
});
const BSPLINE3_GIMP: TensorProduct<BsplineGimpKernel> = TensorProduct(BsplineGimpKernel {
    degree: SplineDegree::Cubic,
});
const TLMPM: TotalLagrangian<TensorProduct<LinearKernel>> = TotalLagrangian(TensorProduct(LinearKernel));

basis_families! {
    /// Standard MPM: linear shape functions evaluated at the point, χ_p = δ V_p (eq 5).
    Mpm => MPM, axis Some(&LinearKernel), method "mpm", label "MPM";
    /// GIMP with a top-hat characteristic function (eq 6), split per element (eqs 7–10).
    Gimp => GIMP, axis Some(&GimpKernel), method "igimp", label "iGIMP";
    /// CPDI2: corner-tracked multilinear domains ([`cpdi`]).
    Cpdi => Cpdi, axis None, method "cpdi", label "CPDI2";
    /// Quadratic B-splines, boundary nodes by linear extrapolation ([`bspline`]).
    Bspline2 => BSPLINE2, axis Some(&BSPLINE2.0), method "bspline2", label "quadratic B-spline MPM";
    /// Cubic B-splines, boundary nodes by linear extrapolation ([`bspline`]).
    Bspline3 => BSPLINE3, axis Some(&BSPLINE3.0), method "bspline3", label "cubic B-spline MPM";
    /// Total-Lagrangian MPM: linear hats in the reference configuration ([`total_lagrangian`]).
    Tlmpm => TLMPM, axis None, method "tlmpm", label "TLMPM";
    /// Quadratic B-splines averaged over the point's domain ([`bspline_gimp`]).
    Bspline2Gimp => BSPLINE2_GIMP, axis Some(&BSPLINE2_GIMP.0), method "bspline2-gimp", label "quadratic B-spline GIMP";
    /// Cubic B-splines averaged over the point's domain ([`bspline_gimp`]).
    Bspline3Gimp => BSPLINE3_GIMP, axis Some(&BSPLINE3_GIMP.0), method "bspline3-gimp", label "cubic B-spline GIMP";
}

impl Basis {
    /// True if the family's weights depend on the domain half-lengths, and so on the domain
    /// update rule (the domain-averaged kernels: GIMP and the B-spline GIMPs; CPDI's domains
    /// follow their corners).
    pub fn uses_domain_update(self) -> bool {
        self.axis_kernel().is_some_and(|k| k.has_domain())
    }

    /// Weights along one grid axis for a point at `x` whose domain half-length is `r`
    /// (ignored by point-evaluated kernels); tensor-product families only.
    pub fn axis_weights(
        self,
        grid_axis: GridAxis,
        x: f64,
        r: f64,
        out: &mut AxisWeights,
    ) -> Result<(), BasisError> {
        self.axis_kernel()
            .ok_or(BasisError::NotTensorProduct)?
            .axis_weights(grid_axis, x, r, out)
    }

    /// Per-axis weights of a point at `x` with domain half-lengths `r` on `grid`
    /// (tensor-product families only).
    pub fn evaluate<const D: usize>(
        self,
        grid: &Grid<D>,
        x: &SVector<f64, D>,
        r: &SVector<f64, D>,
        out: &mut Support<D>,
    ) -> Result<(), BasisError> {
        for a in 0..D {
            self.axis_weights(GridAxis::of(grid, a), x[a], r[a], &mut out.axes[a])?;
        }
        Ok(())
    }
}
