//! Total-Lagrangian MPM (de Vaucorbeil, Nguyen & Hutchinson 2020): the weights and their
//! gradients are those of the reference configuration, S_vp(X_p) and ∇₀S_vp(X_p), for the whole
//! analysis; points never cross cells of the reference grid.
//!
//! In this code's updated-Lagrangian step the start-of-step gradient is the pushed-forward
//! ∇ₙS_vp = Fₙ⁻ᵀ ∇₀S_vp. Then ΔF = I + Σ Δu_v ⊗ ∇ₙS_vp gives F_{n+1} = Fₙ + Σ Δu_v ⊗ ∇₀S_vp
//! (F = I + ∇₀u, exactly the total-Lagrangian deformation gradient) and the internal force
//! Σ_p V_p σ_p ∇_{n+1}S_vp = Σ_p V⁰_p P_p ∇₀S_vp (P = Jσ F⁻ᵀ, the first Piola–Kirchhoff
//! stress): the total-Lagrangian equations, with this code's consistent tangent.

use super::{BasisError, BasisFamily, Configuration, PointSupport, PointView};
use crate::mesh::grid::Grid;
use nalgebra::SVector;

/// A basis evaluated in the reference configuration.
#[derive(Debug, Clone, Copy, Default)]
pub struct TotalLagrangian<B>(pub B);

impl<const D: usize, B: BasisFamily<D>> BasisFamily<D> for TotalLagrangian<B> {
    fn support_nodes(&self) -> usize {
        self.0.support_nodes()
    }

    fn configuration(&self) -> Configuration {
        Configuration::Total
    }

    fn evaluate(
        &self,
        grid: &Grid<D>,
        point: &PointView<'_, D>,
        out: &mut PointSupport<D>,
    ) -> Result<(), BasisError> {
        self.0.evaluate(grid, &point.reference(), out)?;
        #[cfg(feature = "seeded-bugs")]
        if crate::seeded::active(crate::seeded::Bug::ReferenceGradients) {
            return Ok(());
        }
        let f = super::padded(&super::block::<D>(point.f));
        let f_inv_t = super::block::<D>(&f.try_inverse().ok_or(BasisError::InvertedDomain)?).transpose();
        for g in out.gradients_mut() {
            *g = f_inv_t * *g;
        }
        Ok(())
    }

    fn fill_box(
        &self,
        grid: &Grid<D>,
        point: &PointView<'_, D>,
    ) -> Option<(SVector<f64, D>, SVector<f64, D>)> {
        self.0.fill_box(grid, &point.reference())
    }
}
