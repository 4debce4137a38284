//! Ghost stabilisation of the background grid: the cure for nearly empty cells.
//!
//! A node whose elements hold only a sliver of material gets a tiny share of the stiffness
//! (eq 27 sums over the points that reach it), so the tangent is nearly singular and Newton
//! either stalls or moves the node wildly (det ΔF ≤ 0). As in CutFEM (Burman 2010) and the
//! implicit octree GIMP of Bird, Coombs, Augarde et al. (2026), the step's energy gets a
//! penalty on the jump of the normal derivative of the displacement increment across the
//! interior faces F of the active grid (nodes in 1D, edges in 2D, faces in 3D):
//!
//! ```text
//! G(Δu) = ½ Σ_F γ E h_F ∫_F ⟦∂Δu/∂n⟧ · ⟦∂Δu/∂n⟧ ds
//! ```
//!
//! with E the elastic Young's modulus of the model and h_F the element size normal to F, so
//! that γ is dimensionless and the term scales like an element's stiffness (E h^(D−2)). The
//! grid is reset every load step, so the penalty acts on the increment Δu of the step on its
//! start-of-step configuration and never accumulates: it adds `K_g Δu` to the internal force
//! and the constant `K_g` to the tangent (exactly consistent, Newton stays quadratic).
//!
//! **Why E and not the tangent's modulus.** A modulus taken from the current tangent would make
//! G depend on the stress state, and its consistent linearisation would need the derivative of
//! that modulus. The term's only job is to bound the smallest eigenvalue of the cut-cell
//! stiffness from below at the scale of a full element, for which the elastic modulus (an upper
//! bound of the plastic tangent's) is the right scale; it stays quadratic and symmetric.
//!
//! **Why ghost penalty rather than aggregation.** Aggregation (Badia et al. 2018) needs a
//! root cell for every cut cell and constrains the ill-posed dofs to an extension from it,
//! i.e. it changes the discrete space where material moves across cells each step; the
//! penalty keeps the space and is one assembly term on a regular grid, identical in 1D, 2D and
//! 3D, and its effect on the answer is measured by γ (the studies sweep it over two decades).
//!
//! For linear (Q1) elements ∂Δu/∂n is linear along the face and the jump across the face
//! between cells K⁻ and K⁺ (normal axis a) is, per component, Σ_o j(o_a) T_o(s) Δu_o: the
//! second difference j = (1, −2, 1)/h_a of the three node layers along a times the bilinear
//! tangential shape function T_o. The face matrix is therefore the same for every face of one
//! axis: `γ E h_a · j ⊗ j · M_t`, with M_t the tangential Q1 face mass matrix (1 in 1D).
//!
//! Faces: [`GhostFaces::Cut`] penalises the faces between two active cells of which at least
//! one is partially filled (the CutFEM face band: fill below [`GhostSettings::cut_fill`], or,
//! when [`GhostSettings::cut_share`] is set, a node of the cell with a material share below
//! it); [`GhostFaces::All`] every face between two
//! active cells, which also controls the odd–even (1D) and hourglass (2D) modes of one point
//! per cell.

use crate::discretise::dofs::DofMap;
use crate::mesh::grid::Grid;
use crate::solver::error::InputError;
use crate::solver::sparse::SparseMatrix;
use serde::{Deserialize, Serialize};

/// Default of [`GhostSettings::cut_fill`]: a cell is cut (partially filled) when its material
/// volume is above zero and below this fraction of its volume. GIMP domains of a deformed body
/// do not tile the grid (the U update keeps them axis-aligned under rotation), so a fraction
/// near 1 marks nearly every cell of a bent beam as cut, and every penalised face between
/// well-filled cells adds bias without curing anything: the near-null modes live in cells
/// filled a few per cent. The default is the fraction that keeps both measured spreads over γ
/// small (reference/README.md item 59; compaction: Figure 17's displacement over
/// γ ∈ [0.1, 10] at h ≤ 1/2; cantilever, h = 0.5: u/L over γ ∈ [1e-3, 1e-1]):
///
/// | cut_fill | 0.5 | 0.25 | 0.1 | 0.05 |
/// |---|---:|---:|---:|---:|
/// | compaction spread | 0.097 % | 0.038 % | 0.027 % | 0.48 % |
/// | cantilever spread | 0.47 % | 0.41 % | 0.34 % | 0.15 % |
///
/// Below 0.1 the compaction's slivers of 5–10 % go untreated and γ = 0.1 no longer holds them;
/// 0.1 is the default, the cantilever study uses 0.05 (its smallest spread).
pub const DEFAULT_CUT_FILL: f64 = 0.1;

fn default_cut_fill() -> f64 {
    DEFAULT_CUT_FILL
}

/// Which interior faces of the active grid carry the ghost penalty.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum GhostFaces {
    /// Faces between two active cells at least one of which is partially filled
    /// (material volume below [`GhostSettings::cut_fill`] of the cell's).
    #[default]
    Cut,
    /// Every face between two active cells.
    All,
}

/// Ghost penalty settings.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GhostSettings {
    /// Dimensionless penalty factor γ; 0 switches the term off.
    pub gamma: f64,
    /// Which faces are penalised.
    #[serde(default)]
    pub faces: GhostFaces,
    /// With `cut` faces: the fill fraction below which a cell counts as cut, in (0, 1]
    /// (default [`DEFAULT_CUT_FILL`]).
    #[serde(default = "default_cut_fill")]
    pub cut_fill: f64,
    /// With `cut` faces: a cell also counts as cut when one of its nodes has a material share
    /// ψ_v = Σ_p S_vp V_p / h^D ([`node_share`]) below this, in [0, 1); 0 (the default) is off.
    ///
    /// The fill of a cell measures its material, not what its far nodes see: a cut reaching
    /// a node only through an edge or a corner, or only through one cell just above
    /// `cut_fill`, leaves that node a share far below the cell's fill, and the tangent a
    /// near-null mode there. ½ cut_fill² is the share a flat cut filling cut_fill of a cell
    /// leaves the nodes on its far side (∫ N_v over a layer of depth cut_fill·h at the end of
    /// the hat, times the full tangential hat), the natural companion of `cut_fill`.
    ///
    /// Opt-in (default 0): it cures the 3D cantilever's near-null mode at h = 0.25, where cells
    /// filled just above `cut_fill` leave their far nodes tiny shares, but in 2D it moves the
    /// cantilever's u/L by up to 0.34 % and widens its γ spread beyond the study's band, so
    /// only the study that needs it sets it (reference/README.md item 59 has the
    /// measurements).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub cut_share: f64,
}

fn is_zero(x: &f64) -> bool {
    *x == 0.0
}

impl Default for GhostSettings {
    /// Off.
    fn default() -> Self {
        Self {
            gamma: 0.0,
            faces: GhostFaces::Cut,
            cut_fill: DEFAULT_CUT_FILL,
            cut_share: 0.0,
        }
    }
}

impl GhostSettings {
    /// Largest accepted γ: far above any useful value (the studies use 1e-3 … 1e-1), small
    /// enough that the penalty cannot swamp the material stiffness by round-off.
    pub const MAX_GAMMA: f64 = 1e3;

    /// True if the penalty is applied (γ > 0).
    pub fn is_on(&self) -> bool {
        self.gamma > 0.0
    }

    /// Check γ, `cut_fill` and `cut_share` against their ranges.
    pub fn validate(&self) -> Result<(), InputError> {
        if !(self.gamma.is_finite() && (0.0..=Self::MAX_GAMMA).contains(&self.gamma)) {
            return Err(InputError::new(
                "ghost.gamma",
                self.gamma,
                format!("must lie in [0, {}] (0 = off)", Self::MAX_GAMMA),
            ));
        }
        if !(self.cut_fill > 0.0 && self.cut_fill <= 1.0) {
            return Err(InputError::new(
                "ghost.cut_fill",
                self.cut_fill,
                "must lie in (0, 1] (the fill fraction below which a cell is cut)",
            ));
        }
        if !(self.cut_share >= 0.0 && self.cut_share < 1.0) {
            return Err(InputError::new(
                "ghost.cut_share",
                self.cut_share,
                "must lie in [0, 1) (the node share below which a node's cells are cut; 0 = off)",
            ));
        }
        Ok(())
    }
}

/// Material share of every node of `grid` over the cell volume: ψ_v = Σ_p S_vp V_p / h^D,
/// from the step's weights (`supports`, in point order) and the points' volumes.
pub fn node_share<const D: usize>(
    grid: &Grid<D>,
    supports: &crate::discretise::dofs::SupportTable<D>,
    volumes: impl Iterator<Item = f64>,
    share: &mut Vec<f64>,
) {
    let cell_volume: f64 = grid.spacing().iter().product();
    share.clear();
    share.resize(grid.num_nodes(), 0.0);
    for (p, v) in volumes.enumerate().take(supports.num_points()) {
        let (nodes, s, _) = supports.point(p);
        for (&n, &w) in nodes.iter().zip(s) {
            share[n] += w * v / cell_volume;
        }
    }
}

/// Nodes of one face's stencil: 3 node layers along the normal times 2 per tangential axis.
const fn face_nodes(d: usize) -> usize {
    3 * (1 << (d - 1))
}

/// Most nodes of a face stencil (3D: 12).
const MAX_FACE_NODES: usize = 12;

/// The assembled ghost operator of one load step: the penalised faces and, per normal axis,
/// the face matrix shared by all of them.
#[derive(Debug, Clone, Default)]
pub struct GhostOperator<const D: usize> {
    /// Per normal axis: `face_nodes(D)²` entries, row-major in stencil order.
    face_matrix: Vec<Vec<f64>>,
    /// Penalised faces: (normal axis, stencil nodes).
    faces: Vec<(usize, [usize; MAX_FACE_NODES])>,
    /// Cell fill fractions of the step (reused storage).
    fill: Vec<f64>,
    /// Material share of every node, Σ_p S_vp V_p over the cell volume (reused storage;
    /// empty: not used). See [`Self::build`].
    share: Vec<f64>,
    /// Cells counted as cut at the last [`Self::build`] (reused storage).
    cut: Vec<bool>,
    /// Nodes some point reaches, for [`Self::retain_reached`] (reused storage).
    reached: Vec<bool>,
    /// Faces [`Self::retain_reached`] dropped at the last build.
    dropped: usize,
}

impl<const D: usize> GhostOperator<D> {
    /// Number of penalised faces.
    pub fn num_faces(&self) -> usize {
        self.faces.len()
    }
    /// The penalised faces' stencil nodes, face by face: all [`Self::add_pattern`] reads of
    /// the operator.
    pub fn face_stencils(&self) -> impl Iterator<Item = &[usize]> + '_ {
        let m = face_nodes(D);
        self.faces.iter().map(move |(_, nodes)| &nodes[..m])
    }
    /// Faces between active cells that [`Self::retain_reached`] dropped at the last build.
    pub fn num_dropped_faces(&self) -> usize {
        self.dropped
    }

    /// Drop the faces whose stencil holds a node no point reaches (no non-zero weight or
    /// gradient in `supports`, the [`DofMap`]'s test of an active node).
    ///
    /// Such a node has no equation, so the face would penalise the jump of a field whose value
    /// there is pinned to zero: a constraint, not a stabilisation. The fill of a cell says
    /// where material is, not which nodes its points reach, and the two differ where a
    /// family's fill box covers cells its weights skip: CPDI's corner bounding box (a rotated
    /// domain's box covers cells no corner lies in, and CPDI2 reaches only the nodes of the
    /// corners' cells). Kept, such faces lock CPDI2 (the 2D cantilever's u/L far from Q8's,
    /// reference/README.md item 59). GIMP, MPM and the B-splines (with their fill boxes) reach
    /// every node of every cell their fill boxes overlap, so nothing is dropped for them.
    pub fn retain_reached(&mut self, supports: &crate::discretise::dofs::SupportTable<D>) {
        self.dropped = 0;
        if self.faces.is_empty() {
            return;
        }
        let num_nodes = self
            .faces
            .iter()
            .flat_map(|(_, n)| n[..face_nodes(D)].iter())
            .max()
            .map_or(0, |&n| n + 1);
        self.reached.clear();
        self.reached.resize(num_nodes, false);
        for p in 0..supports.num_points() {
            let (nodes, s, g) = supports.point(p);
            for k in 0..nodes.len() {
                if nodes[k] < num_nodes && (s[k] != 0.0 || g[k].iter().any(|&x| x != 0.0)) {
                    self.reached[nodes[k]] = true;
                }
            }
        }
        let before = self.faces.len();
        let reached = &self.reached;
        self.faces
            .retain(|(_, n)| n[..face_nodes(D)].iter().all(|&v| reached[v]));
        self.dropped = before - self.faces.len();
    }
    /// Cell fill fractions of the last [`Self::build`].
    pub fn fill(&self) -> &[f64] {
        &self.fill
    }
    /// Mutable fill storage, for [`crate::mpm::cell_fill::cell_fill`].
    pub fn fill_mut(&mut self) -> &mut Vec<f64> {
        &mut self.fill
    }
    /// Node material shares of the last [`Self::build`] (empty if none were given).
    pub fn share(&self) -> &[f64] {
        &self.share
    }
    /// Mutable node share storage, for [`node_share`].
    pub fn share_mut(&mut self) -> &mut Vec<f64> {
        &mut self.share
    }

    /// Select the faces from the fill fractions in [`Self::fill_mut`] and form the face
    /// matrices for γ E.
    pub fn build(&mut self, grid: &Grid<D>, settings: &GhostSettings, young_modulus: f64) {
        self.faces.clear();
        self.face_matrix.clear();
        if !settings.is_on() {
            return;
        }
        let h = grid.spacing();
        let cells = grid.cells();
        let m = face_nodes(D);
        let scale = settings.gamma * young_modulus;
        for a in 0..D {
            // K_oo' = γ E h_a j(o_a) j(o'_a) Π_{b≠a} M_b(o_b, o'_b).
            let j = [1.0 / h[a], -2.0 / h[a], 1.0 / h[a]];
            let mut k = vec![0.0; m * m];
            for r in 0..m {
                let or = stencil_offsets::<D>(a, r);
                for s in 0..m {
                    let os = stencil_offsets::<D>(a, s);
                    let mut v = scale * h[a] * j[or[a]] * j[os[a]];
                    for b in (0..D).filter(|&b| b != a) {
                        v *= h[b] / 6.0 * if or[b] == os[b] { 2.0 } else { 1.0 };
                    }
                    k[r * m + s] = v;
                }
            }
            self.face_matrix.push(k);
        }
        let num_cells = grid.num_cells();
        let cell_coords = |mut flat: usize| {
            let mut idx = [0usize; D];
            for (b, i) in idx.iter_mut().enumerate() {
                *i = flat % cells[b];
                flat /= cells[b];
            }
            idx
        };
        let mut stride = [1usize; D];
        for b in 1..D {
            stride[b] = stride[b - 1] * cells[b - 1];
        }
        // Cut cells: filled below cut_fill, or (cut_share > 0) holding a node whose material
        // share is below cut_share.
        let weak = settings.cut_share;
        let use_share = weak > 0.0 && self.share.len() == grid.num_nodes();
        self.cut.clear();
        self.cut.extend((0..num_cells).map(|cell| {
            let phi = self.fill[cell];
            if phi <= 0.0 {
                return false;
            }
            if phi < settings.cut_fill {
                return true;
            }
            if !use_share {
                return false;
            }
            let idx = cell_coords(cell);
            (0..1usize << D).any(|corner| {
                let mut n = [0usize; D];
                for b in 0..D {
                    n[b] = idx[b] + ((corner >> b) & 1);
                }
                self.share[grid.node_index(n)] < weak
            })
        }));
        for cell in 0..num_cells {
            let phi = self.fill[cell];
            if phi <= 0.0 {
                continue;
            }
            let idx = cell_coords(cell);
            for a in 0..D {
                if idx[a] + 1 >= cells[a] {
                    continue;
                }
                let phi_n = self.fill[cell + stride[a]];
                if phi_n <= 0.0 {
                    continue;
                }
                if settings.faces == GhostFaces::Cut && !self.cut[cell] && !self.cut[cell + stride[a]] {
                    continue;
                }
                let mut nodes = [0usize; MAX_FACE_NODES];
                for (r, node) in nodes.iter_mut().enumerate().take(m) {
                    let off = stencil_offsets::<D>(a, r);
                    let mut n = [0usize; D];
                    for b in 0..D {
                        n[b] = idx[b] + off[b];
                    }
                    *node = grid.node_index(n);
                }
                self.faces.push((a, nodes));
            }
        }
    }

    /// Equations of the face stencil's dofs (None where fixed or inactive).
    #[inline]
    fn stencil_eqs(dofs: &DofMap, nodes: &[usize], out: &mut [Option<usize>; MAX_FACE_NODES * 3]) {
        for (r, &n) in nodes.iter().enumerate() {
            for i in 0..D {
                out[r * D + i] = dofs.eq(n * D + i);
            }
        }
    }

    /// Columns of the tangent's sparsity pattern the faces need (appended to `columns`).
    pub fn add_pattern(&self, dofs: &DofMap, columns: &mut [Vec<usize>]) {
        let m = face_nodes(D);
        let mut eqs = [None; MAX_FACE_NODES * 3];
        for (_, nodes) in &self.faces {
            Self::stencil_eqs(dofs, &nodes[..m], &mut eqs);
            for c in eqs[..m * D].iter().flatten() {
                columns[*c].extend(eqs[..m * D].iter().flatten());
            }
        }
    }

    /// `f_int += K_g Δu` at the equations, and at the fixed dofs into `reactions` (indexed by
    /// nodal dof) when given.
    pub fn add_residual(
        &self,
        dofs: &DofMap,
        du_nodal: &[f64],
        f_int: &mut [f64],
        mut reactions: Option<&mut [f64]>,
    ) {
        let m = face_nodes(D);
        for (a, nodes) in &self.faces {
            let k = &self.face_matrix[*a];
            for r in 0..m {
                for i in 0..D {
                    let dof = nodes[r] * D + i;
                    let mut s = 0.0;
                    for c in 0..m {
                        s += k[r * m + c] * du_nodal[nodes[c] * D + i];
                    }
                    match dofs.eq(dof) {
                        Some(e) => f_int[e] += s,
                        None => {
                            if let Some(rx) = reactions.as_deref_mut() {
                                rx[dof] += s;
                            }
                        }
                    }
                }
            }
        }
    }

    /// `K += K_g` (each displacement component on its own).
    pub fn add_tangent(&self, dofs: &DofMap, matrix: &mut SparseMatrix) {
        let m = face_nodes(D);
        let mut eqs = [None; MAX_FACE_NODES * 3];
        for (a, nodes) in &self.faces {
            let k = &self.face_matrix[*a];
            Self::stencil_eqs(dofs, &nodes[..m], &mut eqs);
            for r in 0..m {
                for c in 0..m {
                    for i in 0..D {
                        if let (Some(row), Some(col)) = (eqs[r * D + i], eqs[c * D + i]) {
                            matrix.add(row, col, k[r * m + c]);
                        }
                    }
                }
            }
        }
    }
}

/// Per-axis node offsets of stencil node `r` of a face normal to axis `a`: 0..3 along `a`, 0..2
/// along the others, axis 0 fastest.
#[inline]
fn stencil_offsets<const D: usize>(a: usize, mut r: usize) -> [usize; D] {
    let mut off = [0usize; D];
    for (b, o) in off.iter_mut().enumerate() {
        let n = if b == a { 3 } else { 2 };
        *o = r % n;
        r /= n;
    }
    off
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A cell filled above cut_fill counts as cut when one of its nodes has a share below
    /// cut_share (and only then).
    #[test]
    fn weak_node_share_marks_its_cells_cut() {
        // 3 x 1 cells: full, 6 % (above cut_fill 0.05) in its lower left corner, empty; the
        // node (2, 1) at the 6 % cell's far corner gets a share of 1e-3.
        let grid = Grid::<2>::try_new([0.0, 0.0], [1.0, 1.0], [3, 1]).unwrap();
        let settings = GhostSettings {
            gamma: 1.0,
            faces: GhostFaces::Cut,
            cut_fill: 0.05,
            cut_share: 0.0,
        };
        let mut g = GhostOperator::<2>::default();
        g.fill_mut().extend([1.0, 0.06, 0.0]);
        g.share_mut()
            .extend([0.25, 0.3, 0.02, 0.0, 0.25, 0.27, 1e-3, 0.0]);
        g.build(&grid, &settings, 1.0);
        assert_eq!(g.num_faces(), 0);
        g.build(
            &grid,
            &GhostSettings {
                cut_share: 1.25e-3,
                ..settings
            },
            1.0,
        );
        assert_eq!(g.num_faces(), 1);
    }

    /// The face matrix annihilates every linear field (its jump vanishes), and is positive on
    /// a kinked one.
    #[test]
    fn face_matrix_kernel_is_linear_fields() {
        let grid = Grid::<2>::try_new([0.0, 0.0], [0.5, 0.25], [2, 2]).unwrap();
        let mut g = GhostOperator::<2>::default();
        g.fill_mut().extend([1.0, 0.5, 1.0, 0.5]);
        g.build(
            &grid,
            &GhostSettings {
                gamma: 1.0,
                faces: GhostFaces::All,
                ..Default::default()
            },
            2.0,
        );
        assert_eq!(g.num_faces(), 4);
        let m = face_nodes(2);
        for a in 0..2 {
            let k = &g.face_matrix[a];
            // u = 1 + 2x − 3y + 0.7xy: bilinear, so its normal derivative is continuous.
            let u: Vec<f64> = (0..m)
                .map(|r| {
                    let off = stencil_offsets::<2>(a, r);
                    let (x, y) = (off[0] as f64 * 0.5, off[1] as f64 * 0.25);
                    1.0 + 2.0 * x - 3.0 * y + 0.7 * x * y
                })
                .collect();
            for r in 0..m {
                let s: f64 = (0..m).map(|c| k[r * m + c] * u[c]).sum();
                assert!(s.abs() < 1e-12, "axis {a}: smooth field gives {s}");
            }
            let kink: Vec<f64> = (0..m)
                .map(|r| (stencil_offsets::<2>(a, r)[a] == 1) as u8 as f64)
                .collect();
            let e: f64 = (0..m)
                .map(|r| (0..m).map(|c| kink[r] * k[r * m + c] * kink[c]).sum::<f64>())
                .sum();
            assert!(e > 0.0);
        }
    }

    /// A face whose stencil holds a node no point reaches is dropped; the others stay.
    #[test]
    fn faces_reaching_an_unreached_node_are_dropped() {
        // 3 x 1 cells, all active and every face penalised (2 faces, normal to x); one point
        // reaches the six nodes of cells 0 and 1 only, so the face between cells 1 and 2
        // (stencil: the nodes of cells 1 and 2, i.e. x = 1, 2, 3) holds the unreached
        // nodes at x = 3 and is dropped.
        let grid = Grid::<2>::try_new([0.0, 0.0], [1.0, 1.0], [3, 1]).unwrap();
        let mut g = GhostOperator::<2>::default();
        g.fill_mut().extend([1.0, 1.0, 1.0]);
        let all = GhostSettings {
            gamma: 1.0,
            faces: GhostFaces::All,
            ..Default::default()
        };
        g.build(&grid, &all, 1.0);
        assert_eq!(g.num_faces(), 2);
        let mut table = crate::discretise::dofs::SupportTable::<2>::default();
        for i in 0..3 {
            for j in 0..2 {
                table.push_node(grid.node_index([i, j]), 1.0 / 6.0, nalgebra::SVector::zeros());
            }
        }
        table.finish_point();
        g.retain_reached(&table);
        assert_eq!((g.num_faces(), g.num_dropped_faces()), (1, 1));
        let kept = g.faces[0].1;
        assert!(kept[..face_nodes(2)]
            .iter()
            .all(|&n| grid.node_position(n)[0] < 2.5));
    }
}
