//! The 3D manufactured-solution study (`studies/manufactured-3d.toml`), quick tier: every
//! expected rate (Hex8 and Hex20 at their textbook orders, iGIMP at its measured slopes) is
//! evaluated and inside its band, every case converges, the 3D point files reproduce the
//! recorded displacement errors from the exact motion alone, and the outputs re-render byte for
//! byte.

use igimp::problems::manufactured3d::Exact3;
use igimp::study::engine::{run_in_memory, write_outputs, Run, StudyKind};
use igimp::study::manufactured::ManufacturedStudy;
use igimp::study::render::manufactured::render;
use igimp::study::results::CaseStatus;
use igimp::study::Tier;
use std::path::Path;
use std::sync::OnceLock;

fn quick() -> &'static Run<ManufacturedStudy> {
    static RUN: OnceLock<Run<ManufacturedStudy>> = OnceLock::new();
    RUN.get_or_init(|| {
        let s = ManufacturedStudy::load(
            &Path::new(env!("CARGO_MANIFEST_DIR")).join("studies/manufactured-3d.toml"),
        )
        .expect("studies/manufactured-3d.toml parses");
        assert_eq!(s.dimension, 3);
        run_in_memory(&s, "manufactured-3d.toml", Tier::Quick).expect("an in-memory run")
    })
}

#[test]
fn every_expected_3d_rate_is_inside_its_band() {
    let r = &quick().results;
    let expected = r
        .study
        .expect_rate
        .iter()
        .filter(|x| x.tier.is_none_or(|t| t == Tier::Quick))
        .count();
    assert!(expected >= 8, "{expected} quick-tier expectations");
    assert_eq!(r.checks.len(), expected);
    for c in &r.checks {
        assert_eq!(
            c.pass,
            Some(true),
            "{}: {} (measured {:?}, limit {})",
            c.id,
            c.description,
            c.measured,
            c.limit
        );
    }
    for c in &r.cases {
        assert_eq!(c.solve.status, CaseStatus::Converged, "{}", c.id);
    }
}

/// The displacement error recomputed from a 3D point file (X, x, v0) and the exact motion
/// alone equals the recorded one, for a material point and a Gauss point case.
#[test]
fn point_files_3d_reproduce_the_recorded_errors() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = write_outputs(tmp.path(), quick()).unwrap();
    let study = &quick().results.study;
    for (id, sweep) in [
        ("axis-aligned-igimp-stretch-n8-p2", "axis-aligned"),
        ("axis-aligned-fem-hex20-n4", "axis-aligned-hex20"),
    ] {
        let rec = quick().results.case(id).expect(id);
        let sw = study.sweeps.iter().find(|s| s.id == sweep).unwrap();
        let (cases, _) = study.cases(Tier::Quick);
        let case = cases.iter().find(|c| c.id == id).unwrap();
        assert_eq!(case.spec.field, sw.field);
        let exact = Exact3::of(&case.spec);
        let text = std::fs::read_to_string(dir.join(format!("points/{id}.csv"))).unwrap();
        let mut lines = text.lines();
        assert!(lines.next().unwrap().starts_with("X,Y,Z,x,y,z,volume0"));
        let (mut num, mut den, mut n) = (0.0, 0.0, 0);
        for line in lines {
            let v: Vec<f64> = line.split(',').map(|x| x.parse().unwrap()).collect();
            assert_eq!(v.len(), 13);
            let xe = exact.position([v[0], v[1], v[2]]);
            for a in 0..3 {
                num += v[6] * (v[3 + a] - xe[a]).powi(2);
                den += v[6] * (xe[a] - v[a]).powi(2);
            }
            n += 1;
        }
        assert_eq!(n, rec.points, "{id}");
        let e = (num / den).sqrt();
        let recorded = rec.displacement_error.unwrap();
        assert!((e / recorded - 1.0).abs() < 1e-12, "{id}: {e} vs {recorded}");
    }
}

/// The report and figures are written, and rendering again recreates them byte for byte.
#[test]
fn manufactured_3d_outputs_rerender_byte_identically() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = write_outputs(tmp.path(), quick()).unwrap();
    let first = render(&dir).unwrap().files;
    assert_eq!(first.len(), 5, "{first:?}");
    let report = std::fs::read_to_string(&first[0]).unwrap();
    assert!(
        report.contains("unit cube") && report.contains("2×2×2 points"),
        "{report}"
    );
    let bytes: Vec<Vec<u8>> = first.iter().map(|p| std::fs::read(p).unwrap()).collect();
    for p in &first {
        std::fs::remove_file(p).unwrap();
    }
    let again = render(&dir).unwrap().files;
    assert_eq!(again, first);
    for (p, b) in again.iter().zip(bytes) {
        assert_eq!(std::fs::read(p).unwrap(), b, "{}", p.display());
    }
}

/// A 3D study file with a value the cube does not take is rejected with the key named: a
/// dimension other than 2 or 3, a plane element, a domain figure (2D only).
#[test]
fn bad_3d_inputs_name_their_key() {
    use igimp::study::StudyError;
    let text =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("studies/manufactured-3d.toml"))
            .unwrap();
    let domains = r#"
[[figures]]
id = "d"
title = "domains"
kind = "domains"
sweep = "vortex"
cells = 4
points_per_cell = 2
"#;
    // The appended figure's index: after every figure of the file.
    let appended = format!("figures[{}].kind", text.matches("[[figures]]").count());
    for (edited, key, says) in [
        (
            text.replace("dimension = 3", "dimension = 4"),
            "dimension",
            "must be 2 or 3",
        ),
        (
            text.replace(r#"methods = ["fem-hex20"]"#, r#"methods = ["fem-q8"]"#),
            "sweeps[1].methods[0]",
            "fem-hex8",
        ),
        (format!("{text}{domains}"), &appended, "dimension = 2"),
    ] {
        match ManufacturedStudy::parse(&edited, "m3.toml") {
            Err(StudyError::Invalid { key: k, allowed, .. }) => {
                assert_eq!(k, key);
                assert!(allowed.contains(says), "{key}: {allowed}");
            }
            other => panic!("{key}: {other:?}"),
        }
    }
}
