//! External and inertia forces of the points on the nodes (eqs 40, 43).

use crate::discretise::dofs::SupportTable;
use crate::solver::dynamics::{Inertia, MassMatrix};
use nalgebra::SVector;

/// Nodal external force of body forces carried by points: f_a = Σ_p S_ap b_p (eq 40).
pub fn map_point_forces<const D: usize>(
    table: &SupportTable<D>,
    forces: &[SVector<f64, D>],
    nodal: &mut [f64],
) {
    for (p, f) in forces.iter().enumerate() {
        let (nodes, s, _) = table.point(p);
        for (&n, &w) in nodes.iter().zip(s) {
            for i in 0..D {
                nodal[n * D + i] += w * f[i];
            }
        }
    }
}

/// M a for a nodal field a (per nodal dof), handing each contribution (nodal dof, force) to
/// `sink`: consistent, Σ_p m_p S_ap (Σ_b S_bp a_b); lumped, (Σ_p m_p S_ap) a_a.
pub(super) fn mass_times<const D: usize>(
    table: &SupportTable<D>,
    inertia: &Inertia<'_>,
    a: impl Fn(usize) -> f64,
    mut sink: impl FnMut(usize, f64),
) {
    for p in 0..table.num_points() {
        let (nodes, s, _) = table.point(p);
        let m = inertia.point_masses[p];
        let mut ap = [0.0; 3];
        if inertia.mass == MassMatrix::Consistent {
            for (&n, &w) in nodes.iter().zip(s) {
                for (i, v) in ap.iter_mut().enumerate().take(D) {
                    *v += w * a(n * D + i);
                }
            }
        }
        for (&n, &w) in nodes.iter().zip(s) {
            for (i, &v) in ap.iter().enumerate().take(D) {
                let dof = n * D + i;
                sink(
                    dof,
                    m * w
                        * match inertia.mass {
                            MassMatrix::Consistent => v,
                            MassMatrix::Lumped => a(dof),
                        },
                );
            }
        }
    }
}
