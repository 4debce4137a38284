//! Standard MPM: the grid's linear hats evaluated at the point, χ_p = δ V_p (eq 5).

use super::{AxisKernel, AxisWeights, BasisError, GridAxis};

/// The linear hat kernel along one axis; also CPDI's kernel at the domain corners.
#[derive(Debug, Clone, Copy, Default)]
pub struct LinearKernel;

impl AxisKernel for LinearKernel {
    fn support_nodes(&self) -> usize {
        2
    }

    fn axis_weights(
        &self,
        grid_axis: GridAxis,
        x: f64,
        _r: f64,
        out: &mut AxisWeights,
    ) -> Result<(), BasisError> {
        let GridAxis {
            axis,
            origin,
            spacing: h,
            cells,
        } = grid_axis;
        *out = AxisWeights::default();
        let upper = origin + h * cells as f64;
        // A point on the grid's outer face (within round-off) belongs to the last element.
        if !(x >= origin - 1e-12 * h && x <= upper + 1e-12 * h) {
            return Err(BasisError::OutsideGrid { axis });
        }
        let e = grid_axis.cell_of(x);
        let xi = 2.0 * (x - origin - (e as f64 + 0.5) * h) / h;
        out.first = e;
        out.len = 2;
        out.w[0] = 0.5 * (1.0 - xi);
        out.w[1] = 0.5 * (1.0 + xi);
        out.dw[0] = -1.0 / h;
        out.dw[1] = 1.0 / h;
        Ok(())
    }
}
