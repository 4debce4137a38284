//! Material points: position, influence domain, volume, mass and the committed
//! deformation/constitutive state, stored as structure-of-arrays.

use crate::basis::GridAxis;
use crate::material::kinematics::PointState;
use crate::mesh::grid::Grid;
use crate::solver::error::{require_count, require_positive, InputError};
use nalgebra::SVector;

/// A set of material points in `D` dimensions.
#[derive(Debug, Clone, Default)]
pub struct MaterialPoints<const D: usize> {
    /// Current position x_p.
    pub position: Vec<SVector<f64, D>>,
    /// Initial position X_p.
    pub position0: Vec<SVector<f64, D>>,
    /// Initial domain half-lengths l_p0 / 2.
    pub half_length0: Vec<SVector<f64, D>>,
    /// Current domain half-lengths l_p / 2, updated at the end of each step (eqs 37, 39).
    pub half_length: Vec<SVector<f64, D>>,
    /// Initial volume v_p0.
    pub volume0: Vec<f64>,
    /// Mass ρ0 v_p0.
    pub mass: Vec<f64>,
    /// Committed F, current volume and constitutive state.
    pub state: Vec<PointState>,
    /// Velocity v_p and acceleration a_p (dynamic analyses, [`crate::solver::dynamics`]; zero at
    /// rest, and untouched by quasi-static ones).
    pub velocity: Vec<SVector<f64, D>>,
    /// Acceleration a_p (dynamic analyses; zero at rest).
    pub acceleration: Vec<SVector<f64, D>>,
    /// Domain corners, 2^D per point (axis 0 fastest), for the families that track them
    /// (CPDI); empty otherwise ([`Self::track_corners`]).
    pub corners: Vec<SVector<f64, D>>,
}

impl<const D: usize> MaterialPoints<D> {
    /// Give every point that holds no internal variables `model`'s initial ones
    /// ([`crate::material::constitutive::MaterialState::initialise`]).
    pub fn initialise_material(&mut self, model: &dyn crate::material::constitutive::ConstitutiveModel) {
        for s in &mut self.state {
            s.material.initialise(model);
        }
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.position.len()
    }
    /// True if there are no points.
    pub fn is_empty(&self) -> bool {
        self.position.is_empty()
    }

    /// Add one point with domain half-lengths `half` and density `density`.
    pub fn push(&mut self, x: SVector<f64, D>, half: SVector<f64, D>, density: f64) {
        let vol: f64 = half.iter().map(|h| 2.0 * h).product();
        self.push_with_volume(x, half, vol, density);
    }

    /// Add one point with domain half-lengths `half`, its own volume `vol` (a point whose
    /// lattice cell a body's boundary cuts carries the volume of the part inside, which its
    /// box domain need not equal) and density `density`.
    pub fn push_with_volume(&mut self, x: SVector<f64, D>, half: SVector<f64, D>, vol: f64, density: f64) {
        self.position.push(x);
        self.position0.push(x);
        self.half_length0.push(half);
        self.half_length.push(half);
        self.volume0.push(vol);
        self.mass.push(density * vol);
        self.state.push(PointState::undeformed(vol));
        self.velocity.push(SVector::zeros());
        self.acceleration.push(SVector::zeros());
    }

    /// Fill the box `[lower, upper]` with a regular lattice whose spacing is the grid spacing
    /// divided by `per_cell[a]` along axis `a`, every point's domain covering its lattice cell
    /// (no gaps or overlaps, paper §4). The box must be inside the grid and its sides must be
    /// whole multiples of that spacing.
    pub fn fill_box(
        grid: &Grid<D>,
        lower: [f64; D],
        upper: [f64; D],
        per_cell: [usize; D],
        density: f64,
    ) -> Result<Self, InputError> {
        require_positive("material.density", density)?;
        let mut counts = [0usize; D];
        let mut step = [0.0; D];
        for a in 0..D {
            require_count(&format!("points_per_cell[{a}]"), per_cell[a], 1)?;
            if per_cell[a] > 64 {
                return Err(InputError::new(
                    format!("points_per_cell[{a}]"),
                    per_cell[a],
                    "must be <= 64",
                ));
            }
            let len = upper[a] - lower[a];
            if !(len.is_finite() && len > 0.0) {
                return Err(InputError::new(
                    format!("material.upper[{a}]"),
                    upper[a],
                    format!("must be finite and > material.lower[{a}] = {}", lower[a]),
                ));
            }
            if lower[a] < grid.origin()[a] - 1e-12 || upper[a] > grid.upper(a) + 1e-12 {
                return Err(InputError::new(
                    format!("material box along axis {a}"),
                    format!("[{}, {}]", lower[a], upper[a]),
                    format!(
                        "must lie inside the grid [{}, {}]",
                        grid.origin()[a],
                        grid.upper(a)
                    ),
                ));
            }
            step[a] = grid.spacing()[a] / per_cell[a] as f64;
            let n = len / step[a];
            if (n - n.round()).abs() > 1e-8 * n.max(1.0) || n.round() < 1.0 {
                return Err(InputError::new(
                    format!("material box along axis {a}"),
                    format!("[{}, {}]", lower[a], upper[a]),
                    format!(
                        "length must be a whole multiple of spacing/points_per_cell = {}",
                        step[a]
                    ),
                ));
            }
            counts[a] = n.round() as usize;
        }
        let total: usize = counts.iter().product();
        // Supports reach up to two cells either side (GIMP domains, B-splines).
        crate::mesh::budget::CaseSize {
            dimension: D,
            nodes: grid.num_nodes() as f64,
            points: counts.iter().map(|&n| n as f64).product(),
            coupled_nodes: crate::mesh::budget::stencil(D, 2),
        }
        .check("points_per_cell", format!("{per_cell:?}"))?;
        if total > 20_000_000 {
            return Err(InputError::new(
                "number of material points",
                total,
                "must be <= 20000000",
            ));
        }
        let mut pts = Self::default();
        let half = SVector::<f64, D>::from_fn(|a, _| 0.5 * step[a]);
        for flat in 0..total {
            let mut rest = flat;
            let mut x = SVector::<f64, D>::zeros();
            for a in 0..D {
                let i = rest % counts[a];
                rest /= counts[a];
                x[a] = lower[a] + (i as f64 + 0.5) * step[a];
            }
            pts.push(x, half, density);
        }
        Ok(pts)
    }

    /// Renumber the points cell by cell: ordered by the grid cell holding their position
    /// (axis 0 fastest), the order within a cell kept. Points of one cell then share their
    /// nodes and follow one another, so the assembly adds their blocks as one run (a
    /// [`Self::fill_box`] lattice is numbered row by row, which in 3D at 2 × 2 × 2 points per
    /// cell makes runs of 2 points instead of 8). The set of points is unchanged, but sums over
    /// points are taken in another order, so results change at round-off: an opt-in for
    /// large runs, which no committed study uses. Returns the permutation: new point `k` is
    /// old point `order[k]`.
    pub fn sort_by_cell(&mut self, grid: &Grid<D>) -> Vec<usize> {
        let axes: [GridAxis; D] = std::array::from_fn(|a| GridAxis::of(grid, a));
        let cell = |x: &SVector<f64, D>| {
            (0..D)
                .rev()
                .fold(0usize, |flat, a| flat * axes[a].cells + axes[a].cell_of(x[a]))
        };
        let keys: Vec<usize> = self.position.iter().map(cell).collect();
        let mut order: Vec<usize> = (0..self.len()).collect();
        order.sort_by_key(|&p| keys[p]);
        fn permute<T: Clone>(v: &mut Vec<T>, order: &[usize], per: usize) {
            if v.is_empty() {
                return;
            }
            *v = order
                .iter()
                .flat_map(|&p| v[p * per..(p + 1) * per].iter().cloned())
                .collect();
        }
        // Destructured, so that a field added later cannot be left unpermuted.
        let MaterialPoints {
            position,
            position0,
            half_length0,
            half_length,
            volume0,
            mass,
            state,
            velocity,
            acceleration,
            corners,
        } = self;
        permute(position, &order, 1);
        permute(position0, &order, 1);
        permute(half_length0, &order, 1);
        permute(half_length, &order, 1);
        permute(volume0, &order, 1);
        permute(mass, &order, 1);
        permute(state, &order, 1);
        permute(velocity, &order, 1);
        permute(acceleration, &order, 1);
        permute(corners, &order, 1 << D);
        order
    }

    /// Start tracking domain corners: each point's box x ± r (idempotent).
    pub fn track_corners(&mut self) {
        if self.corners.len() == self.len() << D {
            return;
        }
        self.corners.clear();
        for p in 0..self.len() {
            crate::basis::cpdi::box_corners(&self.position[p], &self.half_length[p], &mut self.corners);
        }
    }

    /// The corners of point `p` (empty unless tracked).
    pub fn corners_of(&self, p: usize) -> &[SVector<f64, D>] {
        let n = 1 << D;
        self.corners.get(p * n..(p + 1) * n).unwrap_or(&[])
    }

    /// What a basis family may read of point `p` ([`crate::basis::PointView`]).
    pub fn view(&self, p: usize) -> crate::basis::PointView<'_, D> {
        crate::basis::PointView {
            position: &self.position[p],
            half_length: &self.half_length[p],
            position0: &self.position0[p],
            half_length0: &self.half_length0[p],
            f: &self.state[p].f,
            corners: self.corners_of(p),
        }
    }

    /// Displacement of point `p` since the start of the analysis.
    pub fn displacement(&self, p: usize) -> SVector<f64, D> {
        self.position[p] - self.position0[p]
    }
}
