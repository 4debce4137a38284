//! The support reactions as the paper's group updates them: linearised from the last tangent.

use crate::discretise::dofs::DofMap;
use crate::discretise::ghost::GhostOperator;

/// The fixed rows of the tangent at the last assembly and the state they were formed at, for
/// the reactions as the paper's group updates them (AMPLE: f_rct += K_f δu − f^ob_f). After
/// an update to u the out-of-balance left at the fixed dofs telescopes to
/// f^ob_f(u) = −[f_int,f(u) − f_int,f(u_t) − K_f(u_t)(u − u_t)], u_t the tangent's state,
/// and f_ext,f + f_rct = f_int,f(u) + f^ob_f(u) (reference/README.md, item 18).
#[derive(Debug, Default)]
pub struct LinearisedReactions {
    /// (nodal dof, equation, value) entries of K_f (material part; the ghost part is added
    /// from the operator, it is linear).
    rows: Vec<(usize, usize, f64)>,
    /// u and f_int at the fixed dofs when the tangent was formed; empty before the first.
    u_t: Vec<f64>,
    fixed_t: Vec<f64>,
    /// The last evaluation's u and out-of-balance at the fixed dofs (nodal dof order).
    u_last: Vec<f64>,
    oob: Vec<f64>,
    scratch_nodal: Vec<f64>,
    scratch_eq: Vec<f64>,
}

impl LinearisedReactions {
    pub(super) fn clear(&mut self) {
        self.rows.clear();
        self.u_t.clear();
        self.fixed_t.clear();
        self.oob.clear();
    }

    /// A tangent is formed at the last evaluation: its state becomes the linearisation point
    /// and its fixed rows are collected afresh ([`Self::rows_mut`]).
    pub(super) fn start_tangent(&mut self, fixed_forces: &[f64]) {
        self.rows.clear();
        self.u_t.clone_from(&self.u_last);
        self.fixed_t.clear();
        self.fixed_t.extend_from_slice(fixed_forces);
    }

    /// The (nodal dof, equation, value) entries of K_f, filled by the tangent's assembly.
    pub(super) fn rows_mut(&mut self) -> &mut Vec<(usize, usize, f64)> {
        &mut self.rows
    }

    /// ‖f^ob_f‖² of the last evaluation.
    pub(super) fn out_of_balance_sq(&self) -> f64 {
        self.oob.iter().map(|x| x * x).sum()
    }

    /// ‖f_ext,f + f_rct‖² = ‖f_int,f + f^ob_f‖² at the fixed dofs (plain ‖f_int,f‖² before the
    /// first tangent).
    pub(super) fn reactions_sq(&self, fixed_forces: &[f64]) -> f64 {
        if self.oob.is_empty() {
            return fixed_forces.iter().map(|x| x * x).sum();
        }
        fixed_forces
            .iter()
            .zip(&self.oob)
            .map(|(f, o)| (f + o).powi(2))
            .sum()
    }

    /// The out-of-balance left at the fixed dofs by the linearised update at `u`, given the
    /// internal force there (`fixed_forces`, nodal dof order); zero before the first tangent
    /// (exact reactions).
    pub(super) fn update<const D: usize>(
        &mut self,
        u: &[f64],
        fixed_forces: &[f64],
        dofs: &DofMap,
        ghost: Option<&GhostOperator<D>>,
    ) {
        self.u_last.clear();
        self.u_last.extend_from_slice(u);
        self.oob.clear();
        if self.u_t.len() != u.len() {
            return;
        }
        // −[f_int,f(u) − f_int,f(u_t) − K_f (u − u_t)]
        self.oob
            .extend(fixed_forces.iter().zip(&self.fixed_t).map(|(f, t)| t - f));
        for &(dof, col, k) in &self.rows {
            self.oob[dof] += k * (u[col] - self.u_t[col]);
        }
        if let Some(g) = ghost {
            // u − u_t, expanded to the nodes; scratch_eq then takes the (unused) free rows.
            self.scratch_eq.clear();
            self.scratch_eq
                .extend(u.iter().zip(&self.u_t).map(|(a, b)| a - b));
            self.scratch_nodal.clear();
            self.scratch_nodal.resize(dofs.num_dofs(), 0.0);
            dofs.expand(&self.scratch_eq, &mut self.scratch_nodal);
            self.scratch_eq.fill(0.0);
            g.add_residual(
                dofs,
                &self.scratch_nodal,
                &mut self.scratch_eq,
                Some(&mut self.oob),
            );
        }
    }
}
