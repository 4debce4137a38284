//! What the scaling benches share: one Newton iteration of a material point solver, timed
//! part by part (weights, ghost faces, residual with the constitutive update, tangent
//! assembly, factorisation + solve), the process's peak memory, and a driver that runs one
//! child process per size so that each peak-memory figure is that size's alone.
use igimp::discretise::assembly::{DofMap, LoadStepSystem};
use igimp::discretise::ghost::{GhostFaces, GhostSettings};
use igimp::mpm::MpmSolver;
use igimp::solver::linear::{LinearSolver, SparseSystem};
use igimp::solver::newton::NonlinearSystem;
use std::time::Instant;

/// The process's resident peak in MiB (NaN where /proc is unavailable), from the library's
/// reader.
pub fn peak_memory_mib() -> f64 {
    igimp::solver::profile::peak_resident_bytes().map_or(f64::NAN, |b| b as f64 / (1024.0 * 1024.0))
}

/// `SCALING_GHOST=<gamma>[:all]`: the ghost penalty (cut faces, or every face); default off.
pub fn ghost_from_env() -> GhostSettings {
    let mut g = GhostSettings::default();
    if let Ok(v) = std::env::var("SCALING_GHOST") {
        let mut parts = v.split(':');
        g.gamma = parts
            .next()
            .and_then(|s| s.parse().ok())
            .expect("SCALING_GHOST=<gamma>[:all]");
        if parts.next() == Some("all") {
            g.faces = GhostFaces::All;
        }
    }
    g
}

/// `SCALING_SOLVER=lu|llt|ldlt|cg` (default LDLᵀ; cg: multigrid-preconditioned CG to the
/// relative residual 1e-8, a mid-Newton forcing term).
pub fn solver_from_env() -> LinearSolver {
    match std::env::var("SCALING_SOLVER").as_deref() {
        Ok("lu") => LinearSolver::Lu,
        Ok("llt") => LinearSolver::Llt,
        Ok("cg") => LinearSolver::Iterative,
        _ => LinearSolver::Ldlt,
    }
}

/// `SCALING_REPEAT=<k>`: time the constitutive pass, the assembly and the solve k times and
/// report each one's fastest, their sum, and the fastest of the k whole iterations (default 1).
fn repeats() -> usize {
    std::env::var("SCALING_REPEAT")
        .ok()
        .map_or(1, |v| v.parse().expect("SCALING_REPEAT=<k>, a whole number ≥ 1"))
        .max(1)
}

/// Time one Newton iteration of `solver_mpm` (built in `setup` seconds) and print one line.
/// `SCALING_SHIFT=<s>` translates every point by s·h along every axis first, so that the
/// block's boundary cells are partially filled (it starts cell-aligned: no cut faces), and
/// `SCALING_ORDER=cells` renumbers the points cell by cell.
pub fn time_iteration<const D: usize>(
    mut solver_mpm: MpmSolver<D>,
    ghost_on: bool,
    solver: LinearSolver,
    h: f64,
    setup: f64,
) {
    if let Some(shift) = std::env::var("SCALING_SHIFT")
        .ok()
        .and_then(|s| s.parse::<f64>().ok())
    {
        for x in solver_mpm.points.position.iter_mut() {
            x.add_scalar_mut(shift * h);
        }
    }
    // `SCALING_ORDER=cells`: the points renumbered cell by cell, so that a cell's points are
    // assembled as one run (MpmSolver::sort_points_by_cell); default: the lattice's row by
    // row numbering, which the studies use.
    if std::env::var("SCALING_ORDER").as_deref() == Ok("cells") {
        solver_mpm.sort_points_by_cell();
    }
    let t = Instant::now();
    solver_mpm.build_supports().unwrap();
    let weights = t.elapsed().as_secs_f64();
    let t = Instant::now();
    solver_mpm.build_ghost();
    let ghost_build = t.elapsed().as_secs_f64();
    let ghost = ghost_on.then_some(solver_mpm.ghost());
    // Borrowed, not cloned: a solver's step holds one support table (a clone here added
    // 0.33 GB to the 3D 1e6-point peak that no solver run has).
    let table = solver_mpm.supports();
    let t = Instant::now();
    let dofs = DofMap::build(solver_mpm.grid.num_nodes(), table, &solver_mpm.fixed, &[]);
    let mut matrix = SparseSystem::default();
    // The solver first: it chooses the layout the pattern is built in.
    matrix.set_solver(solver);
    let mut columns = dofs.pattern(table);
    if let Some(g) = ghost {
        g.add_pattern(&dofs, &mut columns);
    }
    matrix.set_pattern(columns);
    if solver == LinearSolver::Iterative {
        let nodes = igimp::solver::multigrid::NodeGeometry::of_grid(&solver_mpm.grid);
        matrix.set_geometry(igimp::solver::multigrid::DofGeometry::of_equations(&nodes, &dofs));
        matrix.set_tolerance(1e-8);
    }
    let pattern = t.elapsed().as_secs_f64();
    let f_ext = vec![1.0; dofs.len()];
    let (mut trials, mut du) = (Vec::new(), Vec::new());
    let mut sys = LoadStepSystem {
        model: solver_mpm.model(),
        states: &solver_mpm.points.state,
        table,
        dofs: &dofs,
        f_ext: &f_ext,
        matrix: &mut matrix,
        trials: &mut trials,
        du_nodal: &mut du,
        ghost,
        fixed_forces: &mut Vec::new(),
        prescribed: &[],
        linearised: None,
        inertia: None,
        dynamic_reference: None,
        f_bar: None,
        point_penalties: &[],
    };
    let u = vec![-1e-4; dofs.len()];
    let mut r = vec![0.0; dofs.len()];
    sys.evaluate(&u, &mut r).unwrap(); // first pass allocates the trial array
    let t = Instant::now();
    sys.evaluate(&u, &mut r).unwrap();
    let mut constitutive = t.elapsed().as_secs_f64();
    let t = Instant::now();
    sys.assemble_tangent();
    let mut tangent = t.elapsed().as_secs_f64();
    let t = Instant::now();
    sys.matrix.solve_in_place(&mut r).unwrap(); // symbolic + numeric
    let first_solve = t.elapsed().as_secs_f64();
    let mut r2 = vec![1.0; dofs.len()];
    let before = sys.matrix.stats();
    let t = Instant::now();
    sys.matrix.solve_in_place(&mut r2).unwrap(); // numeric only (symbolic cached)
    let mut solve = t.elapsed().as_secs_f64();
    let after = sys.matrix.stats();
    // A whole Newton iteration (residual with the constitutive update, tangent, solve) timed
    // as one, beside the sum of its parts' fastest: the first repeat's parts are measured
    // apart above, so its whole is their sum.
    let mut whole = constitutive + tangent + solve;
    // The shared machine's timings wander by tens of per cent from run to run; the repeats
    // report each part's fastest (the same work each time: the trial states, tangent and
    // right-hand side are recomputed from the same increment).
    for _ in 1..repeats() {
        let start = Instant::now();
        sys.evaluate(&u, &mut r).unwrap();
        constitutive = constitutive.min(start.elapsed().as_secs_f64());
        let t = Instant::now();
        sys.assemble_tangent();
        tangent = tangent.min(t.elapsed().as_secs_f64());
        r2.iter_mut().for_each(|v| *v = 1.0);
        let t = Instant::now();
        sys.matrix.solve_in_place(&mut r2).unwrap();
        solve = solve.min(t.elapsed().as_secs_f64());
        whole = whole.min(start.elapsed().as_secs_f64());
    }
    if solver == LinearSolver::Iterative {
        println!(
            "  CG: {} iterations, multigrid set-up {:.3} s, iterations {:.3} s, {} fallbacks",
            after.iterations - before.iterations,
            after.setup_seconds - before.setup_seconds,
            after.solve_seconds - before.solve_seconds,
            sys.matrix.fallbacks()
        );
    }
    println!(
        "{D}D {:>9} points, h = 1/{:<3} {:>8} dofs, nnz {:>10}, {:?}, ghost {} faces: setup {setup:.3} s | per iteration (fastest of {}): weights {weights:.3} s, \
         ghost faces+fill {ghost_build:.3} s, constitutive+residual {constitutive:.3} s, tangent assembly {tangent:.3} s, factorisation+solve {solve:.3} s \
         (first, with symbolic: {first_solve:.3} s); iteration {:.3} s (the three parts' fastest summed), fastest whole {whole:.3} s | pattern {pattern:.3} s | peak memory {:.0} MiB",
        solver_mpm.points.len(),
        (1.0 / h).round(),
        dofs.len(),
        sys.matrix.nnz(),
        solver,
        ghost.map_or(0, |g| g.num_faces()),
        repeats(),
        constitutive + tangent + solve,
        peak_memory_mib()
    );
}

/// Run `run(size)` for the sizes on the command line (default `defaults`), each in a child
/// process of its own.
pub fn drive(defaults: &[f64], run: impl Fn(f64)) {
    let args: Vec<String> = std::env::args()
        .skip(1)
        .filter(|a| !a.starts_with("--"))
        .collect();
    let sizes: Vec<f64> = if args.is_empty() {
        defaults.to_vec()
    } else {
        args.iter().filter_map(|a| a.parse().ok()).collect()
    };
    if sizes.len() == 1 {
        run(sizes[0]);
        return;
    }
    let exe = std::env::current_exe().expect("bench executable");
    for s in sizes {
        let status = std::process::Command::new(&exe)
            .arg(format!("{s}"))
            .status()
            .expect("spawn");
        if !status.success() {
            // A size the machine cannot hold (e.g. killed for memory) is reported, and the
            // larger ones are not tried.
            println!("size {s}: the child process failed ({status}); larger sizes skipped");
            break;
        }
    }
}
