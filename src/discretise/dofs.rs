//! What the assembly works on: the support table (for every integration point the nodes it
//! touches, with weights and gradients) and the equation numbering of the nodal dofs (fixed,
//! tied, active) with the sparsity pattern they imply. Kept apart from [`crate::discretise::assembly`] so
//! that the operators the assembly adds (e.g. [`crate::discretise::ghost`]) can number their dofs without
//! depending on it.

use nalgebra::{SMatrix, SVector};

pub use crate::basis::MAX_POINT_NODES;

/// For every point: the nodes it touches, the weights S and gradients ∂S/∂X̃ on the
/// start-of-step configuration. Stored flat (CSR-like) and refilled every load step.
#[derive(Debug, Clone, Default)]
pub struct SupportTable<const D: usize> {
    offsets: Vec<usize>,
    nodes: Vec<usize>,
    weights: Vec<f64>,
    gradients: Vec<SVector<f64, D>>,
}

impl<const D: usize> SupportTable<D> {
    /// Empty the table for a new step (the storage stays).
    pub fn clear(&mut self) {
        self.offsets.clear();
        self.offsets.push(0);
        self.nodes.clear();
        self.weights.clear();
        self.gradients.clear();
    }
    /// Append one node to the current point.
    #[inline]
    pub fn push_node(&mut self, node: usize, s: f64, grad: SVector<f64, D>) {
        self.nodes.push(node);
        self.weights.push(s);
        self.gradients.push(grad);
    }
    /// Close the current point. Its node count must not exceed [`MAX_POINT_NODES`].
    pub fn finish_point(&mut self) {
        if self.offsets.is_empty() {
            self.offsets.push(0);
        }
        let start = *self.offsets.last().unwrap();
        assert!(
            self.nodes.len() - start <= MAX_POINT_NODES,
            "point support exceeds MAX_POINT_NODES"
        );
        self.offsets.push(self.nodes.len());
    }
    /// Number of points closed by [`Self::finish_point`].
    pub fn num_points(&self) -> usize {
        self.offsets.len().saturating_sub(1)
    }
    /// Every point's nodes, flat, and where each point's start: all the sparsity pattern
    /// reads of the table ([`DofMap::pattern`]).
    pub fn node_lists(&self) -> (&[usize], &[usize]) {
        (&self.offsets, &self.nodes)
    }
    /// Nodes, weights and gradients of point `p`.
    #[inline]
    pub fn point(&self, p: usize) -> (&[usize], &[f64], &[SVector<f64, D>]) {
        let (a, b) = (self.offsets[p], self.offsets[p + 1]);
        (&self.nodes[a..b], &self.weights[a..b], &self.gradients[a..b])
    }
    /// Interpolate a nodal vector field (`D` values per node) to point `p`: Σ S_a u_a.
    pub fn interpolate(&self, p: usize, nodal: &[f64]) -> SVector<f64, D> {
        let (nodes, s, _) = self.point(p);
        let mut u = SVector::<f64, D>::zeros();
        for (&n, &w) in nodes.iter().zip(s) {
            for i in 0..D {
                u[i] += w * nodal[n * D + i];
            }
        }
        u
    }
    /// ∂u/∂X̃ at point `p` from nodal values, eq (32).
    pub fn gradient(&self, p: usize, nodal: &[f64]) -> SMatrix<f64, D, D> {
        let (nodes, _, g) = self.point(p);
        let mut gu = SMatrix::<f64, D, D>::zeros();
        for (&n, ga) in nodes.iter().zip(g) {
            for i in 0..D {
                let ui = nodal[n * D + i];
                for j in 0..D {
                    gu[(i, j)] += ui * ga[j];
                }
            }
        }
        gu
    }
}

/// Equation numbers of the nodal degrees of freedom: `None` for fixed or inactive ones.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct DofMap {
    eq: Vec<Option<usize>>,
    count: usize,
}

impl DofMap {
    /// Active nodes are those touched by a point with a non-zero weight or gradient; a dof is
    /// free if its node is active and `(node, axis)` is not in `fixed`. `ties` lists
    /// `(slave, master)` node pairs whose dofs share the master's equations (u_slave = u_master),
    /// so forces and stiffness at the slave are summed into the master's rows and columns.
    pub fn build<const D: usize>(
        num_nodes: usize,
        table: &SupportTable<D>,
        fixed: &[(usize, usize)],
        ties: &[(usize, usize)],
    ) -> Self {
        let mut active = vec![false; num_nodes];
        for p in 0..table.num_points() {
            let (nodes, s, g) = table.point(p);
            for k in 0..nodes.len() {
                if s[k] != 0.0 || g[k].iter().any(|&x| x != 0.0) {
                    active[nodes[k]] = true;
                }
            }
        }
        let mut eq: Vec<Option<usize>> = vec![None; num_nodes * D];
        let mut is_fixed = vec![false; num_nodes * D];
        for &(n, a) in fixed {
            if n < num_nodes && a < D {
                is_fixed[n * D + a] = true;
            }
        }
        let mut slave = vec![false; num_nodes];
        for &(s, _) in ties {
            slave[s] = true;
        }
        let mut count = 0;
        for n in 0..num_nodes {
            if !active[n] || slave[n] {
                continue;
            }
            for a in 0..D {
                if !is_fixed[n * D + a] {
                    eq[n * D + a] = Some(count);
                    count += 1;
                }
            }
        }
        for &(s, m) in ties {
            assert!(!slave[m], "tie master {m} is itself a slave");
            for a in 0..D {
                eq[s * D + a] = if is_fixed[s * D + a] { None } else { eq[m * D + a] };
            }
        }
        Self { eq, count }
    }
    /// Number of equations.
    pub fn len(&self) -> usize {
        self.count
    }
    /// True if no dof has an equation.
    pub fn is_empty(&self) -> bool {
        self.count == 0
    }
    /// Equation of `dof = node * D + axis`.
    #[inline]
    pub fn eq(&self, dof: usize) -> Option<usize> {
        self.eq[dof]
    }
    /// Number of nodal dofs (`num_nodes * D`).
    pub fn num_dofs(&self) -> usize {
        self.eq.len()
    }
    /// Scatter equation values into a nodal vector (zero at fixed/inactive dofs).
    pub fn expand(&self, u: &[f64], nodal: &mut [f64]) {
        for (dof, e) in self.eq.iter().enumerate() {
            nodal[dof] = e.map_or(0.0, |e| u[e]);
        }
    }
    /// Sum a nodal force vector into equation order (tied dofs add into their master).
    pub fn gather_forces(&self, nodal: &[f64], f: &mut [f64]) {
        f.iter_mut().for_each(|v| *v = 0.0);
        for (dof, e) in self.eq.iter().enumerate() {
            if let Some(e) = *e {
                f[e] += nodal[dof];
            }
        }
    }
    /// Gather a nodal vector into equation order.
    pub fn gather(&self, nodal: &[f64], u: &mut [f64]) {
        for (dof, e) in self.eq.iter().enumerate() {
            if let Some(e) = *e {
                u[e] = nodal[dof];
            }
        }
    }

    /// Sparsity pattern (per column, the rows) coupling every pair of free dofs that share a point.
    ///
    /// Built at the node level: the points touching each node (a node → points index), then
    /// each node's neighbour nodes with a marker array, in parallel over blocks of nodes, and
    /// only then expanded to the D × D dof couplings. A point couples up to 27 nodes in 3D,
    /// i.e. 81 × 81 dof pairs: going through nodes first divides the transient work by D² and
    /// needs no sorting of duplicated lists (reference/README.md item 59).
    pub fn pattern<const D: usize>(&self, table: &SupportTable<D>) -> Vec<Vec<usize>> {
        use rayon::prelude::*;
        let num_nodes = self.eq.len() / D;
        let has_eq = |n: usize| (0..D).any(|a| self.eq[n * D + a].is_some());
        // node → points touching it, CSR.
        let mut start = vec![0usize; num_nodes + 1];
        for p in 0..table.num_points() {
            for &n in table.point(p).0 {
                start[n + 1] += 1;
            }
        }
        for n in 0..num_nodes {
            start[n + 1] += start[n];
        }
        let mut next = start.clone();
        let mut points = vec![0usize; start[num_nodes]];
        for p in 0..table.num_points() {
            for &n in table.point(p).0 {
                points[next[n]] = p;
                next[n] += 1;
            }
        }
        // Neighbour nodes (with equations) of each node, sorted.
        let blocks = (rayon::current_num_threads() * 8).max(1);
        let block = num_nodes.div_ceil(blocks).max(1);
        // Per block: its nodes' sorted neighbour lists, one after another, and where each ends.
        let neighbours: Vec<(Vec<usize>, Vec<usize>)> = (0..num_nodes.div_ceil(block))
            .into_par_iter()
            .map(|b| {
                let mut seen = vec![usize::MAX; num_nodes];
                let (mut flat, mut ends) = (vec![], vec![]);
                for n in b * block..((b + 1) * block).min(num_nodes) {
                    let first = flat.len();
                    if has_eq(n) {
                        for &p in &points[start[n]..start[n + 1]] {
                            for &m in table.point(p).0 {
                                if seen[m] != n && has_eq(m) {
                                    seen[m] = n;
                                    flat.push(m);
                                }
                            }
                        }
                        flat[first..].sort_unstable();
                    }
                    ends.push(flat.len());
                }
                (flat, ends)
            })
            .collect();
        let mut columns: Vec<Vec<usize>> = vec![Vec::new(); self.count];
        let lists = neighbours.iter().flat_map(|(flat, ends)| {
            ends.iter().scan(0, move |first, &end| {
                Some(&flat[std::mem::replace(first, end)..end])
            })
        });
        for (n, list) in lists.enumerate() {
            for a in 0..D {
                let Some(e) = self.eq[n * D + a] else { continue };
                let col = &mut columns[e];
                col.reserve_exact(list.len() * D);
                for &m in list {
                    col.extend((0..D).filter_map(|b| self.eq[m * D + b]));
                }
            }
        }
        columns
    }
}

impl crate::solver::multigrid::DofGeometry {
    /// The position and component of every equation of `dofs` (a tied dof sits at its
    /// master, the first node numbered with the equation).
    pub fn of_equations(nodes: &crate::solver::multigrid::NodeGeometry, dofs: &DofMap) -> Self {
        let d = nodes.dim;
        let mut out = crate::solver::multigrid::DofGeometry {
            dim: d,
            spacing: nodes.spacing,
            positions: vec![[f64::NAN; 3]; dofs.len()],
            components: vec![0; dofs.len()],
        };
        for dof in 0..dofs.num_dofs() {
            if let Some(e) = dofs.eq(dof) {
                if out.positions[e][0].is_nan() {
                    out.positions[e] = nodes.positions[dof / d];
                    out.components[e] = (dof % d) as u8;
                }
            }
        }
        out
    }
}
