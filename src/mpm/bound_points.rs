//! Displacements bound to material points ([`crate::discretise::point_penalty`]): a footing
//! that moves with the soil under it, where a prescribed grid node would let go of the soil
//! once it has settled below the node's row (reference/README.md item 81).

use super::MpmSolver;
use crate::discretise::point_penalty::{BoundPoints, PointPenalty};
use crate::solver::error::InputError;
use crate::solver::newton::ResidualNorm;
use crate::solver::ramp::Ramp;
use nalgebra::SVector;

impl<const D: usize> MpmSolver<D> {
    /// Bind components of `points` to prescribed displacements (axis, value at full load)
    /// following `ramp`, by a penalty of factor `penalty` (k_p = β E V_p⁰ / h², E the model's
    /// Young's modulus, h the grid spacing; [`DEFAULT_POINT_PENALTY`]). Returns the group's
    /// index for [`Self::bound_reaction`]. Refused with dynamics and with the linearised
    /// residual norm, whose reaction updates do not carry the penalty.
    pub fn bind_points(
        &mut self,
        points: &[usize],
        values: &[(usize, f64)],
        ramp: Ramp,
        penalty: f64,
    ) -> Result<usize, InputError> {
        ramp.validate("ramp")?;
        if !(penalty.is_finite() && penalty > 0.0) {
            return Err(InputError::new("penalty", penalty, "must be finite and > 0"));
        }
        if points.is_empty() {
            return Err(InputError::new(
                "bound points",
                "none",
                "must bind at least one point",
            ));
        }
        if let Some(&p) = points.iter().find(|&&p| p >= self.points.len()) {
            return Err(InputError::new(
                "bound point",
                p,
                format!("must be a point, < {}", self.points.len()),
            ));
        }
        if let Some(&(a, v)) = values.iter().find(|&&(a, v)| a >= D || !v.is_finite()) {
            return Err(InputError::new(
                "bound component",
                format!("(axis {a}, {v})"),
                format!("axis < {D} and a finite value"),
            ));
        }
        if self.settings.dynamics.is_some() {
            return Err(InputError::new(
                "bound points",
                "with dynamics",
                "are for quasi-static analyses only",
            ));
        }
        if self.settings.newton.residual_norm == ResidualNorm::Linearised {
            return Err(InputError::new(
                "newton.residual_norm",
                "linearised",
                "must be total or external with points bound to a displacement",
            ));
        }
        let h = self.grid.spacing().iter().copied().fold(f64::INFINITY, f64::min);
        let e = self.model().young_modulus();
        self.bound.push(BoundPoints {
            stiffness: points
                .iter()
                .map(|&p| penalty * e * self.points.volume0[p] / (h * h))
                .collect(),
            points: points.to_vec(),
            values: values.to_vec(),
            ramp,
            reaction: SVector::zeros(),
        });
        Ok(self.bound.len() - 1)
    }

    /// The force group `group`'s points exerted on their load at the last converged step, per
    /// axis: the counterpart of a prescribed node's reaction (zero along unbound axes).
    pub fn bound_reaction(&self, group: usize) -> SVector<f64, D> {
        self.bound.get(group).map_or(SVector::zeros(), |g| g.reaction)
    }

    /// The penalties of a step to `load_factor` from the committed positions, into `out`.
    pub(super) fn point_penalties(&self, load_factor: f64, out: &mut Vec<PointPenalty>) {
        out.clear();
        for g in &self.bound {
            let r = g.ramp.factor(load_factor);
            for (&p, &k) in g.points.iter().zip(&g.stiffness) {
                let (x, x0) = (&self.points.position[p], &self.points.position0[p]);
                out.extend(g.values.iter().map(|&(a, v)| PointPenalty {
                    point: p,
                    axis: a,
                    stiffness: k,
                    target: x0[a] + v * r - x[a],
                }));
            }
        }
    }

    /// After a commit at `load_factor`: each group's force −Σ k_p e_p, e_p the committed
    /// misfit x_p − X_p − ū(λ).
    pub(super) fn commit_bound_reactions(&mut self, load_factor: f64) {
        let (pos, pos0) = (&self.points.position, &self.points.position0);
        for g in &mut self.bound {
            let r = g.ramp.factor(load_factor);
            let mut f = SVector::<f64, D>::zeros();
            for (&p, &k) in g.points.iter().zip(&g.stiffness) {
                for &(a, v) in &g.values {
                    f[a] -= k * (pos[p][a] - pos0[p][a] - v * r);
                }
            }
            g.reaction = f;
        }
    }

    /// Renumber the bound points after the points were reordered (old `p` is new
    /// `new_index[p]`).
    pub(super) fn renumber_bound(&mut self, new_index: &[usize]) {
        for g in &mut self.bound {
            g.points.iter_mut().for_each(|p| *p = new_index[*p]);
        }
    }
}
