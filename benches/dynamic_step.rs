//! The cost of one implicit dynamic time step against one quasi-static Newton iteration of the
//! same size: the dynamic manufactured axis-aligned field (src/problems/manufactured_dynamic.rs)
//! and its static counterpart (src/problems/manufactured.rs), iGIMP, 2 points per cell per
//! axis, multigrid-preconditioned CG, one process per size:
//!
//! `cargo bench --bench dynamic_step -- 1e5 1e6` (target point counts; `DYNAMIC_DIMENSION=3`
//! for the unit cube). Each line gives the dynamic step (weights, projection of the grid's
//! motion, its Newton iterations, commit) and the static step's time per Newton iteration,
//! both measured on the second step (the first builds the multigrid hierarchy), and their
//! ratio.
// The scaling benches' driver (one process per size) and memory reader; their iteration timer is
// not used here.
#[allow(dead_code)]
mod scaling;

use igimp::basis::method::Method;
use igimp::problems::manufactured::{self, ManufacturedSpec};
use igimp::problems::manufactured_dynamic::{self, DynamicManufacturedSpec};
use igimp::solver::linear::LinearSolver;
use igimp::solver::load_stepping::LoadStepping;
use std::time::Instant;

/// (seconds of the second step, its Newton iterations) of `solver`.
fn second_step<S: LoadStepping>(mut solver: S) -> (f64, usize) {
    solver.step().expect("first step");
    let t = Instant::now();
    let report = solver.step().expect("second step");
    (t.elapsed().as_secs_f64(), report.newton.iterations())
}

fn run<const D: usize>(target: f64) {
    // (2 cells)^D points per cell: cells = (target / 2^D)^(1/D).
    let cells = (target / (1 << D) as f64).powf(1.0 / D as f64).round().max(2.0) as usize;
    let dynamic = DynamicManufacturedSpec {
        cells,
        steps_per_period: 64,
        dimension: D,
        ..Default::default()
    };
    let mut solver = manufactured_dynamic::mpm_solver::<D>(&dynamic, Method::IGIMP).expect("dynamic solver");
    solver.settings.linear_solver = LinearSolver::Iterative;
    let points = solver.points.len();
    let (step, iterations) = second_step(solver);
    let stat = ManufacturedSpec {
        cells,
        dimension: D,
        ..Default::default()
    };
    let (static_step, static_iterations) = if D == 2 {
        let mut s = manufactured::mpm_solver(&stat, Method::IGIMP).expect("static solver");
        s.settings.linear_solver = LinearSolver::Iterative;
        second_step(s)
    } else {
        let mut s =
            igimp::problems::manufactured3d::mpm_solver_3d(&stat, Method::IGIMP).expect("static solver");
        s.settings.linear_solver = LinearSolver::Iterative;
        second_step(s)
    };
    let per_iteration = static_step / static_iterations as f64;
    println!(
        "{D}D {points:>9} points ({cells} cells per side): dynamic step {step:.3} s ({iterations} Newton iterations) | static {static_step:.3} s for {static_iterations} iterations, {per_iteration:.3} s per iteration | step / static iteration {:.2} | peak memory {:.0} MiB",
        step / per_iteration,
        scaling::peak_memory_mib()
    );
}

fn main() {
    let sizes = [1e4, 1e5];
    match std::env::var("DYNAMIC_DIMENSION").as_deref() {
        Ok("3") => scaling::drive(&sizes, run::<3>),
        _ => scaling::drive(&sizes, run::<2>),
    }
}
