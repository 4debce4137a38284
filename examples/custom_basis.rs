//! A basis family defined outside the crate, against the public contract
//! ([`igimp::basis::AxisKernel`] → [`igimp::basis::TensorProduct`] → `BasisFamily`), run on the
//! §5.1 column through the public solver API (`MpmSolver::with_family`).
//!
//! The family: a *smoothed hat*, the grid's linear hat convolved with a box of fixed
//! half-width a = h/4 whatever the point's domain (GIMP with a constant smoothing length, one of
//! the implementation choices Steffen et al. 2008 examine). Its gradient is continuous: the
//! hat's jump at a node is spread over a width h/2, so points cross cells without MPM's jumps.
//!
//! `cargo run --release --example custom_basis` prints the stress error (eq 46) per element
//! count and the fitted rate; `tests/verification/families.rs` runs the same function.
use igimp::basis::Basis;
use igimp::basis::{AxisKernel, AxisWeights, BasisError, GimpKernel, GridAxis, TensorProduct};
use igimp::problems::column::ColumnSpec;
use igimp::solver::load_stepping::LoadStepping;
use std::sync::Arc;

/// The linear hat convolved with a box of half-width `fraction` × h.
#[derive(Debug, Clone, Copy)]
pub struct SmoothedHat {
    pub fraction: f64,
}

impl AxisKernel for SmoothedHat {
    fn support_nodes(&self) -> usize {
        3
    }
    fn axis_weights(&self, axis: GridAxis, x: f64, _r: f64, out: &mut AxisWeights) -> Result<(), BasisError> {
        // (1/2a) ∫_{x−a}^{x+a} N_v is GIMP's weight of a domain of half-length a.
        GimpKernel.axis_weights(axis, x, self.fraction * axis.spacing, out)
    }
}

/// (elements, stress error) of the column (W = 40,000, 2 points per cell) with the smoothed
/// hat at each of `elements`, and the fitted log-log slope over them.
pub fn column_errors(elements: &[usize]) -> (Vec<(usize, f64)>, f64) {
    let family = Arc::new(TensorProduct(SmoothedHat { fraction: 0.25 }));
    let mut out = vec![];
    for &n in elements {
        let spec = ColumnSpec {
            elements: n,
            weight: 40_000.0,
            ..ColumnSpec::default()
        };
        let mut solver = spec
            .mpm_solver(Basis::Mpm)
            .expect("a valid column")
            .with_family(family.clone());
        if let Err(failure) = solver.run() {
            panic!("{n} elements: {failure}");
        }
        let exact = spec.analytical();
        let p = &solver.points;
        let sigma_exact: Vec<f64> = p.position0.iter().map(|x| exact.stress(x[0])).collect();
        let sigma: Vec<f64> = p.state.iter().map(|s| s.cauchy()[(0, 0)]).collect();
        let e =
            igimp::problems::norms::stress_error(&sigma_exact, &sigma, &p.volume0, spec.weight, spec.length);
        out.push((n, e));
    }
    let (h, e): (Vec<f64>, Vec<f64>) = out.iter().map(|&(n, e)| (1.0 / n as f64, e)).unzip();
    let slope = igimp::problems::norms::fitted_rate(&h, &e).expect("two or more positive errors");
    (out, slope)
}

#[allow(dead_code)]
fn main() {
    let (errors, slope) = column_errors(&[16, 32, 64, 128]);
    for (n, e) in &errors {
        println!("{n:5} elements: stress error {e:.4e}");
    }
    println!("fitted stress-error rate {slope:.2} (MPM on the same column: about 0, cell crossing)");
}
