//! When a step may keep the last step's sparsity pattern and symbolic analysis.

use crate::discretise::dofs::{DofMap, SupportTable};
use crate::discretise::ghost::GhostOperator;
use crate::discretise::patches::VolumePatches;

/// Everything a step's sparsity pattern is a function of: the equation of every nodal dof,
/// every point's nodes and the ghost faces' nodes. A step whose key equals the last one's has
/// the same pattern to the entry, so the pattern and the direct solvers' symbolic analysis are
/// kept (detected, not assumed: a point that moved to another cell changes its nodes).
/// Stored as the last build's copies, node numbers in 4 bytes (at 1e6 3D points of 8 nodes
/// each, 32 MB).
#[derive(Debug, Default)]
pub(crate) struct PatternKey {
    dofs: DofMap,
    offsets: Vec<usize>,
    nodes: Vec<u32>,
    ghost: Vec<u32>,
    /// F-bar's patch of every point (empty: off).
    patches: Vec<usize>,
    /// Set once a key was recorded (an empty table is a key too).
    valid: bool,
}

/// `kept` and `numbers` hold the same numbers, in the same order.
fn same_numbers(kept: &[u32], numbers: impl Iterator<Item = usize>) -> bool {
    let mut count = 0;
    for n in numbers {
        if kept.get(count).is_none_or(|&k| k as usize != n) {
            return false;
        }
        count += 1;
    }
    count == kept.len()
}

impl PatternKey {
    fn ghost_nodes<const D: usize>(ghost: Option<&GhostOperator<D>>) -> impl Iterator<Item = usize> + '_ {
        ghost
            .into_iter()
            .flat_map(|g| g.face_stencils().flatten().copied())
    }

    pub(super) fn matches<const D: usize>(
        &self,
        dofs: &DofMap,
        table: &SupportTable<D>,
        ghost: Option<&GhostOperator<D>>,
        patches: Option<&VolumePatches>,
    ) -> bool {
        let (offsets, nodes) = table.node_lists();
        self.valid
            && self.patches == patches.map_or(&[][..], VolumePatches::assignment)
            && self.dofs == *dofs
            && self.offsets == offsets
            && same_numbers(&self.nodes, nodes.iter().copied())
            && same_numbers(&self.ghost, Self::ghost_nodes(ghost))
    }

    pub(super) fn record<const D: usize>(
        &mut self,
        dofs: &DofMap,
        table: &SupportTable<D>,
        ghost: Option<&GhostOperator<D>>,
        patches: Option<&VolumePatches>,
    ) {
        let (offsets, nodes) = table.node_lists();
        self.patches.clear();
        self.patches
            .extend_from_slice(patches.map_or(&[][..], VolumePatches::assignment));
        let narrow = |n: usize| u32::try_from(n).ok();
        self.dofs.clone_from(dofs);
        self.offsets.clear();
        self.offsets.extend_from_slice(offsets);
        self.nodes.clear();
        self.ghost.clear();
        // A node number of 2^32 or more (never on a grid that fits in memory) leaves the key
        // invalid: the pattern is then rebuilt every step.
        self.valid = nodes.iter().all(|&n| narrow(n).is_some())
            && Self::ghost_nodes(ghost).all(|n| narrow(n).is_some());
        if self.valid {
            self.nodes.extend(nodes.iter().map(|&n| n as u32));
            self.ghost.extend(Self::ghost_nodes(ghost).map(|n| n as u32));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::SVector;

    /// Two points on a line of four nodes, each touching two neighbours.
    fn table(nodes: [[usize; 2]; 2]) -> SupportTable<1> {
        let mut t = SupportTable::default();
        t.clear();
        for pair in nodes {
            for n in pair {
                t.push_node(n, 0.5, SVector::<f64, 1>::new(1.0));
            }
            t.finish_point();
        }
        t
    }

    /// The key keeps a pattern exactly when what the pattern is built from is unchanged: the
    /// same supports and equations match; a point that moved to another node pair, or a dof
    /// newly fixed, does not. And wherever the key matches, the pattern built afresh is the
    /// kept one, entry for entry.
    #[test]
    fn the_pattern_key_matches_exactly_the_unchanged_supports_and_equations() {
        let before = table([[0, 1], [1, 2]]);
        let dofs = DofMap::build(4, &before, &[], &[]);
        let mut key = PatternKey::default();
        assert!(!key.matches(&dofs, &before, None, None), "no key recorded yet");
        key.record(&dofs, &before, None, None);
        let same = table([[0, 1], [1, 2]]);
        let same_dofs = DofMap::build(4, &same, &[], &[]);
        assert!(key.matches(&same_dofs, &same, None, None));
        assert_eq!(dofs.pattern(&before), same_dofs.pattern(&same));
        let moved = table([[0, 1], [2, 3]]);
        let moved_dofs = DofMap::build(4, &moved, &[], &[]);
        assert!(
            !key.matches(&moved_dofs, &moved, None, None),
            "a point changed nodes"
        );
        assert_ne!(dofs.pattern(&before), moved_dofs.pattern(&moved));
        let fixed_dofs = DofMap::build(4, &same, &[(0, 0)], &[]);
        assert!(!key.matches(&fixed_dofs, &same, None, None), "node 0 fixed");
    }
}
