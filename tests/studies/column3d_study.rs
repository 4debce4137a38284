//! The 3D column (`studies/column-3d.toml`: the §5.1 column as a 1 × 1 × n prism with lateral
//! rollers) reproduces the 1D column: for every case the two studies share (same method,
//! weight, elements, points per cell along the column; every basis family), eq (46), the base
//! F error, the top displacement and the base F agree within 1e-6 relative (measured
//! 2026-12-01: at most 4e-13 for iGIMP and FEM; 2026-12-03: 6e-11 for the other families), and
//! its Table 1 checks pass.

use igimp::study::column::ColumnStudy;
use igimp::study::engine::{run_in_memory, StudyKind};
use igimp::study::results::CaseStatus;
use igimp::study::Tier;
use std::path::Path;

fn quick(file: &str) -> igimp::study::column::records::ColumnResults {
    let s = ColumnStudy::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("studies").join(file)).unwrap();
    run_in_memory(&s, file, Tier::Quick).unwrap().results
}

#[test]
fn column_3d_equals_the_1d_column() {
    let (d3, d1) = (quick("column-3d.toml"), quick("column.toml"));
    assert_eq!(d3.study.dimension, 3);
    let mut compared = 0;
    let mut worst: f64 = 0.0;
    for c in &d3.cases {
        assert_eq!(c.solve.status, CaseStatus::Converged, "{}", c.id);
        // Hex8 and Hex20 on the prism are the 1D linear and quadratic elements.
        let id_1d =
            c.id.replace("fem-hex8", "fem-linear")
                .replace("fem-hex20", "fem-quadratic");
        let Some(o) = d1.case(&id_1d) else { continue };
        for (a, b) in [
            (c.stress_error, o.stress_error),
            (c.f_error, o.f_error),
            (c.top_displacement, o.top_displacement),
            (c.base_f, o.base_f),
        ] {
            let (a, b) = (a.unwrap(), b.unwrap());
            worst = worst.max((a / b - 1.0).abs());
        }
        compared += 1;
    }
    assert!(compared >= 6, "only {compared} shared cases");
    // Every basis family, not only iGIMP, reduces to its 1D column on the prism (the families
    // sweep runs the 1D column's quick sizes; measured 2026-12-03: at most 6e-11 relative).
    for family in ["cpdi", "bspline2", "bspline3", "tlmpm"] {
        let shared = d3
            .cases
            .iter()
            .filter(|c| c.id.starts_with(&format!("{family}-")) && d1.case(&c.id).is_some())
            .count();
        assert!(shared >= 4, "{family}: {shared} cases shared with the 1D column");
    }
    assert!(
        worst <= 1e-6,
        "3D against 1D: largest relative difference {worst:e}"
    );
    for c in &d3.checks {
        assert_eq!(c.pass, Some(true), "{}: {}", c.id, c.description);
    }
    // Newton converges quadratically in 3D, as in 1D.
    for c in &d3.cases {
        for s in &c.solve.steps {
            igimp::solver::newton::check_quadratic(&s.residuals, 1e-3, 1e-11, 1.0, 1.8)
                .unwrap_or_else(|e| panic!("{} step {}: {e}", c.id, s.step));
        }
    }
}

/// A dimension other than 1 or 3, and FEM in 3D, are input errors naming the field.
#[test]
fn column_dimension_is_validated() {
    use igimp::basis::method::Method;
    use igimp::problems::column::{solve_column, ColumnSpec};
    let e = ColumnSpec {
        dimension: 2,
        ..ColumnSpec::default()
    }
    .validate()
    .unwrap_err();
    assert_eq!(e.field, "dimension");
    let e = solve_column(
        &ColumnSpec {
            dimension: 3,
            ..ColumnSpec::default()
        },
        Method::FEM_LINEAR,
    )
    .unwrap_err();
    assert_eq!(e.field, "dimension");
    // Every family (derived, so that a new one needs no edit here), then the elements.
    let expected: Vec<&str> = Method::MATERIAL_POINT
        .iter()
        .map(|m| m.name())
        .chain(["fem-hex8", "fem-hex20"])
        .collect();
    assert!(e.allowed.contains(&expected.join(", ")), "{e}");
    // The 3D elements are not 1D methods.
    let e = solve_column(&ColumnSpec::default(), Method::FEM_HEX8).unwrap_err();
    assert_eq!(e.field, "dimension");
}
