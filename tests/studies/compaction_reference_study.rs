//! The Figure 17 reference study (`studies/compaction-reference.toml`), quick tier: its Q4
//! FEM cases are solved by multigrid CG, and the Richardson reference they give equals the
//! one the direct solver (LDLᵀ) gives on the same three meshes, to the Newton tolerance;
//! every case converges, every load step quadratically, and the CG iteration bound of the study
//! file is evaluated and met.

use igimp::fem::QuadElement;
use igimp::problems::compaction::{solve_fem, CompactionSpec};
use igimp::solver::linear::LinearSolver;
use igimp::solver::newton::check_quadratic;
use igimp::study::checks::richardson;
use igimp::study::compaction::CompactionStudy;
use igimp::study::engine::{run_in_memory, StudyKind};
use igimp::study::results::CaseStatus;
use igimp::study::Tier;
use std::path::Path;

#[test]
fn cg_reference_equals_the_direct_solvers_on_the_same_meshes() {
    let s = CompactionStudy::load(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("studies/compaction-reference.toml"),
    )
    .expect("studies/compaction-reference.toml parses");
    let r = run_in_memory(&s, "compaction-reference.toml", Tier::Quick)
        .unwrap()
        .results;
    for c in &r.cases {
        assert_eq!(c.solve.status, CaseStatus::Converged, "{}", c.id);
        for st in &c.solve.steps {
            check_quadratic(&st.residuals, 1e-3, 1e-11, 1.0, 1.8)
                .unwrap_or_else(|e| panic!("{} step {}: {e}", c.id, st.step));
        }
    }
    let fem: Vec<_> = r.cases.iter().filter(|c| c.method.is_fem()).collect();
    assert!(
        fem.iter().all(|c| c.id.ends_with("-cg")),
        "the FEM cases are solved by CG"
    );
    // The iteration bound of the study file, evaluated on the CG cases (h = 1/2 to 1/8 here).
    let bound = r
        .checks
        .iter()
        .find(|c| c.id == "fem-reference-cg-iterations")
        .expect("the CG iteration check");
    assert_eq!(bound.pass, Some(true), "{bound:?}");
    assert!(bound.measured.unwrap() >= 1.0, "{bound:?}");
    let reference = r.measures.reference.as_ref().expect("a reference");
    // The same meshes by LDLᵀ (the compaction study's solver).
    let mut h: Vec<f64> = fem.iter().map(|c| c.h).collect();
    h.sort_by(|a, b| b.total_cmp(a));
    let direct: Vec<f64> = h
        .iter()
        .map(|&h| {
            let spec = CompactionSpec {
                element_size: h,
                linear_solver: LinearSolver::Ldlt,
                newton: s.newton.settings(),
                ..CompactionSpec::default()
            };
            solve_fem(&spec, QuadElement::Q4)
                .unwrap()
                .max_horizontal_displacement
        })
        .collect();
    // Each mesh: CG's displacement equals LDLᵀ's to the Newton tolerance.
    for (&h, d) in h.iter().zip(&direct) {
        let c = fem.iter().find(|c| c.h == h).unwrap();
        let u = c.max_horizontal_displacement.unwrap();
        assert!((u / d - 1.0).abs() < 1e-8, "h = {h}: CG {u} vs LDLT {d}");
    }
    let (extrapolated, _) = richardson([direct[0], direct[1], direct[2]], 2.0).expect("monotone");
    assert!(
        (reference.value / extrapolated - 1.0).abs() < 1e-8,
        "CG {} vs LDLT {extrapolated}",
        reference.value
    );
}
