//! The vibrating-bar study (`studies/vibrating-bar.toml`), quick tier: every check passes (the
//! trapezoidal rule second order in Δt for the material point families and Line2, each family
//! second order in h, the period within 0.5 %, the energy bounded), the outputs re-render byte
//! for byte, and the time-rate band fails for a damped Newmark (γ = 0.6: first order).

use igimp::study::dynamics::DynamicStudy;
use igimp::study::engine::{run_in_memory, write_outputs, Run, StudyKind};
use igimp::study::render::dynamics::render;
use igimp::study::Tier;
use std::path::Path;
use std::sync::OnceLock;

fn study() -> DynamicStudy {
    DynamicStudy::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("studies/vibrating-bar.toml"))
        .expect("studies/vibrating-bar.toml parses")
}

fn quick() -> &'static Run<DynamicStudy> {
    static RUN: OnceLock<Run<DynamicStudy>> = OnceLock::new();
    RUN.get_or_init(|| run_in_memory(&study(), "vibrating-bar.toml", Tier::Quick).expect("an in-memory run"))
}

/// The quick tier's 14 checks are all evaluated and pass.
#[test]
fn every_bar_check_passes() {
    let r = &quick().results;
    assert_eq!(
        r.checks.len(),
        14,
        "{:?}",
        r.checks.iter().map(|c| &c.id).collect::<Vec<_>>()
    );
    for c in &r.checks {
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

/// A dynamics study's quick run written and rendered twice: nothing left undrawn, and `files`
/// the same bytes both times.
pub fn assert_rerenders_byte_identically(run: &Run<DynamicStudy>, files: &[&str]) {
    let tmp = tempfile::tempdir().unwrap();
    let dir = write_outputs(tmp.path(), run).unwrap();
    let first = render(&dir).unwrap();
    assert!(first.not_drawn.is_empty(), "{:?}", first.not_drawn);
    let read = |f: &str| std::fs::read(dir.join(f)).unwrap();
    let before: Vec<Vec<u8>> = files.iter().map(|f| read(f)).collect();
    render(&dir).unwrap();
    for (f, b) in files.iter().zip(before) {
        assert_eq!(read(f), b, "{f} changed on re-render");
    }
}

/// Rendering twice from the written results gives the same bytes, and the history figure is
/// drawn from `histories.json`.
#[test]
fn bar_outputs_rerender_byte_identically() {
    assert_rerenders_byte_identically(
        quick(),
        &[
            "report.md",
            "history.svg",
            "time-displacement.svg",
            "space-displacement.svg",
        ],
    );
}

/// γ = 0.6 damps the response and makes Newmark first order in Δt: the iGIMP time-rate band
/// 2.0 ± 0.2 must fail (the check can fail).
#[test]
fn damped_newmark_fails_the_time_rate_band() {
    let mut s = study();
    let b = s.bar.as_mut().expect("the bar study has [bar]");
    b.gamma = 0.6;
    b.beta = 0.3025; // (γ + 1/2)² / 4: unconditionally stable with γ = 0.6
    s.sweeps.retain(|x| x.id == "time");
    s.expect_rate.retain(|x| x.sweep == "time");
    s.expect_at_most.clear();
    s.figures.clear();
    let run = run_in_memory(&s, "vibrating-bar.toml", Tier::Quick).unwrap();
    let c = run
        .results
        .checks
        .iter()
        .find(|c| c.id == "time-igimp-consistent-displacement-rate")
        .expect("the iGIMP time-rate check");
    assert_eq!(
        c.pass,
        Some(false),
        "{}: measured {:?}",
        c.description,
        c.measured
    );
}

/// The large-amplitude bar (`studies/vibrating-bar-large.toml`), quick tier: its five checks
/// (iGIMP, CPDI2 and Line2 second order in h against the Line3 reference, iGIMP and Line3
/// second order in Δt) are evaluated and pass, and every case was measured against its
/// reference.
#[test]
fn every_large_amplitude_bar_check_passes() {
    let s =
        DynamicStudy::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("studies/vibrating-bar-large.toml"))
            .expect("studies/vibrating-bar-large.toml parses");
    let r = run_in_memory(&s, "vibrating-bar-large.toml", Tier::Quick)
        .expect("an in-memory run")
        .results;
    assert_eq!(
        r.checks.len(),
        5,
        "{:?}",
        r.checks.iter().map(|c| &c.id).collect::<Vec<_>>()
    );
    crate::manufactured_dynamic_study::assert_all_pass(&r.checks);
    for c in &r.cases {
        assert!(
            c.displacement_error.is_some() && c.reference_failure.is_none(),
            "{}",
            c.id
        );
        assert!(c.id.contains("-vs-fem-quadratic-e256-"), "{}", c.id);
    }
}
