//! The dynamic manufactured studies (`studies/manufactured-dynamic.toml`, `-3d.toml`), quick tier: every
//! check passes, the outputs re-render byte for byte, and a study file that gives both problem
//! sections, or a manufactured sweep without its field, is refused with the key named.

use igimp::study::dynamics::DynamicStudy;
use igimp::study::engine::{run_in_memory, Run, StudyKind};
use igimp::study::Tier;
use std::path::Path;
use std::sync::OnceLock;

fn path() -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("studies/manufactured-dynamic.toml")
}

fn study() -> DynamicStudy {
    DynamicStudy::load(&path()).expect("studies/manufactured-dynamic.toml parses")
}

/// Every check evaluated and passed.
pub fn assert_all_pass(checks: &[igimp::study::checks::CheckRecord]) {
    for c in checks {
        assert_eq!(
            c.pass,
            Some(true),
            "{}: {} (measured {:?})",
            c.id,
            c.description,
            c.measured
        );
    }
}

fn quick() -> &'static Run<DynamicStudy> {
    static RUN: OnceLock<Run<DynamicStudy>> = OnceLock::new();
    RUN.get_or_init(|| {
        run_in_memory(&study(), "manufactured-dynamic.toml", Tier::Quick).expect("an in-memory run")
    })
}

/// Every quick-tier check is evaluated and passes, and no time step was cut back (a cut step
/// would change Δt inside a convergence series).
#[test]
fn every_dynamic_manufactured_check_passes() {
    let r = &quick().results;
    assert!(
        r.checks.len() >= 4,
        "{:?}",
        r.checks.iter().map(|c| &c.id).collect::<Vec<_>>()
    );
    assert_all_pass(&r.checks);
    for c in &r.cases {
        assert_eq!(c.steps_cut_back, 0, "{}", c.id);
        assert!(
            c.stress_error.is_some() && c.displacement_error.is_some(),
            "{}",
            c.id
        );
    }
}

/// Rendering twice from the written results gives the same bytes.
#[test]
fn dynamic_manufactured_outputs_rerender_byte_identically() {
    crate::bar_study::assert_rerenders_byte_identically(
        quick(),
        &[
            "report.md",
            "axis-space-displacement.svg",
            "axis-time-displacement.svg",
        ],
    );
}

/// A file with both `[bar]` and `[manufactured]`, and a manufactured sweep without `field`,
/// are refused naming the key.
#[test]
fn a_dynamics_file_defines_one_problem_and_every_field() {
    let text = std::fs::read_to_string(path()).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let refused = |text: String, key: &str| {
        let p = dir.path().join("m.toml");
        std::fs::write(&p, text).unwrap();
        let e = match DynamicStudy::load(&p) {
            Ok(_) => panic!("{key}: accepted"),
            Err(e) => e.to_string(),
        };
        assert!(e.contains(key), "{e}");
    };
    let bar = "[bar]\nlength = 1.0\ndensity = 1.0\nvelocity = 1.0e-3\nperiods = 3.0\n\n";
    refused(
        text.replacen("[manufactured]", &format!("{bar}[manufactured]"), 1),
        "manufactured",
    );
    refused(
        text.replacen("field = \"axis-aligned\"\n", "", 1),
        "sweeps[0].field",
    );
}

/// The 3D study's quick tier: its checks (iGIMP and Hex8 displacement second order, Hex8
/// stress first order on the unit cube) are evaluated and pass.
#[test]
fn every_dynamic_manufactured_3d_check_passes() {
    let s = DynamicStudy::load(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("studies/manufactured-dynamic-3d.toml"),
    )
    .expect("studies/manufactured-dynamic-3d.toml parses");
    let r = run_in_memory(&s, "manufactured-dynamic-3d.toml", Tier::Quick)
        .expect("an in-memory run")
        .results;
    assert_eq!(
        r.checks.len(),
        3,
        "{:?}",
        r.checks.iter().map(|c| &c.id).collect::<Vec<_>>()
    );
    assert_all_pass(&r.checks);
}
