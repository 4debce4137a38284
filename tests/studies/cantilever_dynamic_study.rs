//! The dynamic cantilever study (`studies/cantilever-dynamic.toml`), quick tier: every check is
//! evaluated and passes, the outputs re-render byte for byte, and a cantilever file whose
//! sweep has no reference, or a reference whose time step does not contain the cases', is
//! refused with the key named.

use igimp::study::dynamics::DynamicStudy;
use igimp::study::engine::{run_in_memory, Run, StudyKind};
use igimp::study::Tier;
use std::path::Path;
use std::sync::OnceLock;

fn path() -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("studies/cantilever-dynamic.toml")
}

fn quick() -> &'static Run<DynamicStudy> {
    static RUN: OnceLock<Run<DynamicStudy>> = OnceLock::new();
    RUN.get_or_init(|| {
        let s = DynamicStudy::load(&path()).expect("studies/cantilever-dynamic.toml parses");
        run_in_memory(&s, "cantilever-dynamic.toml", Tier::Quick).expect("an in-memory run")
    })
}

/// The quick tier's six checks (iGIMP's space rate against Q8, iGIMP's and Q8's time rates,
/// iGIMP's tip and period bounds, Q8's energy bound) are evaluated and pass, and every case
/// is measured against its reference.
#[test]
fn every_dynamic_cantilever_check_passes() {
    let r = &quick().results;
    assert_eq!(
        r.checks.len(),
        6,
        "{:?}",
        r.checks.iter().map(|c| &c.id).collect::<Vec<_>>()
    );
    crate::manufactured_dynamic_study::assert_all_pass(&r.checks);
    for c in &r.cases {
        assert!(c.tip_error.is_some() && c.energy_drift.is_some(), "{}", c.id);
        assert!(c.reference_failure.is_none(), "{}", c.id);
    }
}

#[test]
fn dynamic_cantilever_outputs_rerender_byte_identically() {
    crate::bar_study::assert_rerenders_byte_identically(
        quick(),
        &["report.md", "space-tip.svg", "time-tip.svg", "history.svg"],
    );
}

/// A sweep without its reference, a reference whose steps are not a multiple of a case's, and
/// a file with two problem sections are refused, naming the key.
#[test]
fn a_cantilever_sweep_names_a_usable_reference() {
    let text = std::fs::read_to_string(path()).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let refused = |text: String, key: &str| {
        let p = dir.path().join("c.toml");
        std::fs::write(&p, text).unwrap();
        let e = match DynamicStudy::load(&p) {
            Ok(_) => panic!("{key}: accepted"),
            Err(e) => e.to_string(),
        };
        assert!(e.contains(key), "{key}: {e}");
    };
    refused(
        text.replacen(
            "reference = { method = \"fem-q8\", elements = 16, steps_per_period = 64 }\n",
            "",
            1,
        ),
        "sweeps[0].reference",
    );
    refused(
        text.replacen(
            "reference = { elements = 2, steps_per_period = 1024 }",
            "reference = { elements = 2, steps_per_period = 1000 }",
            1,
        ),
        "sweeps[1].reference.steps_per_period",
    );
    let bar = "[bar]\nlength = 1.0\ndensity = 1.0\nvelocity = 1.0e-3\nperiods = 3.0\n\n";
    refused(
        text.replacen("[cantilever]", &format!("{bar}[cantilever]"), 1),
        "exactly one of [bar], [manufactured] and [cantilever]",
    );
}
