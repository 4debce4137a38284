//! Prescribed (non-zero) nodal displacements: groups of dofs, each with its total value and a
//! [`Ramp`], turned into the increments of one load step. A solver fixes these dofs (they
//! have no equation) and the step's system starts every Newton evaluation from their
//! increments ([`super::assembly::StepInput::prescribed`]), so the first residual already
//! carries the whole imposed motion and the reactions there are the internal force minus the
//! external one ([`super::assembly::StepWorkspace::reaction`]).

use crate::solver::error::InputError;
use crate::solver::ramp::Ramp;

/// Groups of prescribed dofs (dof = node·D + axis) with their values at full load.
#[derive(Debug, Clone, Default)]
pub struct PrescribedDisplacements {
    groups: Vec<(Vec<(usize, f64)>, Ramp)>,
    /// The load factor of the committed state.
    committed: f64,
}

impl PrescribedDisplacements {
    /// Prescribe `dofs` (dof, value at full load), following `ramp`.
    pub fn add(&mut self, dofs: Vec<(usize, f64)>, ramp: Ramp) {
        self.groups.push((dofs, ramp));
    }

    /// Prescribe `dofs` (node, axis, value at full load) of a `D`-dimensional discretisation
    /// of `num_nodes` nodes after checking them and `ramp`: an error names the first bad one.
    pub fn add_checked<const D: usize>(
        &mut self,
        dofs: &[(usize, usize, f64)],
        num_nodes: usize,
        ramp: Ramp,
    ) -> Result<(), InputError> {
        ramp.validate("ramp")?;
        if let Some(&(n, a, v)) = dofs
            .iter()
            .find(|&&(n, a, v)| n >= num_nodes || a >= D || !v.is_finite())
        {
            return Err(InputError::new(
                "prescribed dof",
                format!("(node {n}, axis {a}, {v})"),
                format!("node < {num_nodes}, axis < {D} and a finite value"),
            ));
        }
        self.add(dofs.iter().map(|&(n, a, v)| (n * D + a, v)).collect(), ramp);
        Ok(())
    }

    /// No dof is prescribed.
    pub fn is_empty(&self) -> bool {
        self.groups.is_empty()
    }

    /// Every prescribed dof (a dof in two groups twice).
    pub fn dofs(&self) -> impl Iterator<Item = usize> + '_ {
        self.groups
            .iter()
            .flat_map(|(d, _)| d.iter().map(|&(dof, _)| dof))
    }

    /// The increments (dof, Δu) from the committed state to `load_factor`, into `out`.
    pub fn increments(&self, load_factor: f64, out: &mut Vec<(usize, f64)>) {
        out.clear();
        for (dofs, ramp) in &self.groups {
            let step = ramp.factor(load_factor) - ramp.factor(self.committed);
            out.extend(dofs.iter().map(|&(dof, v)| (dof, v * step)));
        }
    }

    /// Record that the state at `load_factor` is committed.
    pub fn commit(&mut self, load_factor: f64) {
        self.committed = load_factor;
    }
}
