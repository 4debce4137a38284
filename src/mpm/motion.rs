//! The grid's motion in a dynamic analysis: projected from the points at a step's start,
//! the Newmark predictor, and the points' velocity and acceleration committed at its end.

use super::MpmSolver;
use crate::solver::dynamics::NewmarkStep;
use nalgebra::SVector;

impl<const D: usize> MpmSolver<D> {
    /// Time of the committed state (0 for quasi-static analyses).
    pub fn time(&self) -> f64 {
        self.time
    }

    /// The grid's v₀, a₀ of a dynamic step from the points (mass-weighted, zero at the fixed
    /// dofs) and the step's predictor ã, after the step's supports are built.
    pub(super) fn project_motion(&mut self, n: &NewmarkStep, fixed: &[(usize, usize)]) {
        let dofs = self.grid.num_nodes() * D;
        let m = &mut self.nodal;
        for v in [&mut m.velocity, &mut m.acceleration, &mut m.predictor] {
            v.clear();
            v.resize(dofs, 0.0);
        }
        let mut mass = vec![0.0; self.grid.num_nodes()];
        let table = &self.work.table;
        for p in 0..table.num_points() {
            let (nodes, s, _) = table.point(p);
            let mp = self.points.mass[p];
            for (&node, &w) in nodes.iter().zip(s) {
                mass[node] += w * mp;
                for a in 0..D {
                    m.velocity[node * D + a] += w * mp * self.points.velocity[p][a];
                    m.acceleration[node * D + a] += w * mp * self.points.acceleration[p][a];
                }
            }
        }
        for (node, &mn) in mass.iter().enumerate() {
            if mn > 0.0 {
                for a in 0..D {
                    m.velocity[node * D + a] /= mn;
                    m.acceleration[node * D + a] /= mn;
                }
            }
        }
        for &(node, a) in fixed {
            m.velocity[node * D + a] = 0.0;
            m.acceleration[node * D + a] = 0.0;
        }
        for k in 0..dofs {
            m.predictor[k] = n.predictor(m.velocity[k], m.acceleration[k]);
        }
    }

    /// The points' velocities and accelerations after a converged dynamic step:
    /// v_p += Σ_a S_ap Δt((1 − γ) a₀ + γ a₁)_a, a_p = Σ_a S_ap a₁_a ([`crate::solver::dynamics`]).
    pub(super) fn commit_motion(&mut self, n: &NewmarkStep) {
        let table = &self.work.table;
        let (du, m) = (&self.work.du_nodal, &self.nodal);
        for p in 0..table.num_points() {
            let (nodes, s, _) = table.point(p);
            let (mut dv, mut a1) = (SVector::<f64, D>::zeros(), SVector::<f64, D>::zeros());
            for (&node, &w) in nodes.iter().zip(s) {
                for a in 0..D {
                    let k = node * D + a;
                    let acc = n.acceleration_after(du[k], m.predictor[k]);
                    a1[a] += w * acc;
                    dv[a] += w * n.velocity_change(m.acceleration[k], acc);
                }
            }
            self.points.velocity[p] += dv;
            self.points.acceleration[p] = a1;
        }
    }
}
