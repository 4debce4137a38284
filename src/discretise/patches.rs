//! Volume patches of the F-bar treatment: the groups of integration points whose volume
//! change is averaged (reference/README.md item 69). A material point belongs to the grid cell
//! that holds it at the start of the step (Coombs et al. 2018's cell patch for implicit MPM);
//! a Gauss point to its element (de Souza Neto et al. 1996).
//!
//! The averaged volume change couples every node a patch's points touch with every other,
//! so the sparsity pattern gains the couplings of each patch's union of nodes
//! ([`VolumePatches::add_pattern`]).

use crate::discretise::dofs::{DofMap, SupportTable};

/// Each point's patch and, per patch, its points (CSR).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct VolumePatches {
    of_point: Vec<usize>,
    start: Vec<usize>,
    points: Vec<usize>,
}

impl VolumePatches {
    /// Group points by `of_point[p]`, the patch of point `p` (any numbers: the patches are
    /// numbered 0.. in the order of their values).
    pub fn set(&mut self, of_point: impl IntoIterator<Item = usize>) {
        self.of_point.clear();
        self.of_point.extend(of_point);
        // Renumber densely by value, keeping the points of a patch in point order.
        let mut keys: Vec<usize> = self.of_point.clone();
        keys.sort_unstable();
        keys.dedup();
        for c in self.of_point.iter_mut() {
            *c = keys.binary_search(c).expect("present");
        }
        let n = keys.len();
        self.start.clear();
        self.start.resize(n + 1, 0);
        for &c in &self.of_point {
            self.start[c + 1] += 1;
        }
        for c in 0..n {
            self.start[c + 1] += self.start[c];
        }
        let mut next = self.start.clone();
        self.points.clear();
        self.points.resize(self.of_point.len(), 0);
        for (p, &c) in self.of_point.iter().enumerate() {
            self.points[next[c]] = p;
            next[c] += 1;
        }
    }

    /// Number of patches.
    pub fn count(&self) -> usize {
        self.start.len().saturating_sub(1)
    }

    /// Number of points grouped.
    pub fn num_points(&self) -> usize {
        self.of_point.len()
    }

    /// The patch of point `p`.
    #[inline]
    pub fn of(&self, p: usize) -> usize {
        self.of_point[p]
    }

    /// The points of patch `c`, ascending.
    #[inline]
    pub fn points(&self, c: usize) -> &[usize] {
        &self.points[self.start[c]..self.start[c + 1]]
    }

    /// Whether patch `c` has two or more points: a patch of one point averages nothing and
    /// is left plain (no scale, no tangent terms, no couplings).
    #[inline]
    pub fn is_shared(&self, c: usize) -> bool {
        self.points(c).len() >= 2
    }

    /// Every point's patch, for the pattern's key.
    pub fn assignment(&self) -> &[usize] {
        &self.of_point
    }

    /// The nodes the points of patch `c` touch, ascending, into `out`.
    pub fn nodes<const D: usize>(&self, table: &SupportTable<D>, c: usize, out: &mut Vec<usize>) {
        out.clear();
        for &p in self.points(c) {
            out.extend_from_slice(table.point(p).0);
        }
        out.sort_unstable();
        out.dedup();
    }

    /// Couple, in `columns` (rows per column, as [`DofMap::pattern`] gives them), every pair
    /// of free dofs of each patch's nodes.
    pub fn add_pattern<const D: usize>(
        &self,
        dofs: &DofMap,
        table: &SupportTable<D>,
        columns: &mut [Vec<usize>],
    ) {
        let (mut nodes, mut eqs) = (Vec::new(), Vec::new());
        for c in 0..self.count() {
            if !self.is_shared(c) {
                continue; // one point: its own support, already coupled
            }
            self.nodes(table, c, &mut nodes);
            eqs.clear();
            eqs.extend(
                nodes
                    .iter()
                    .flat_map(|&n| (0..D).filter_map(move |a| dofs.eq(n * D + a))),
            );
            for &col in &eqs {
                columns[col].extend_from_slice(&eqs);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn points_are_grouped_by_patch_in_point_order() {
        let mut p = VolumePatches::default();
        p.set([7, 3, 7, 9, 3]);
        assert_eq!(p.count(), 3);
        assert_eq!(p.points(0), &[1, 4]);
        assert_eq!(p.points(1), &[0, 2]);
        assert_eq!(p.points(2), &[3]);
        assert_eq!(p.of(3), 2);
    }
}
