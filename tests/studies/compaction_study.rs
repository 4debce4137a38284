//! The compaction study (`studies/compaction.toml`, paper §5.2), quick tier: its outputs parse
//! and re-render byte for byte with `study --render-only`, two runs give the same numbers,
//! Figure 17's claim holds against the Q4 FEM reference, and failing cases are recorded.
//!
//! Everything is written to temporary folders, never to the repository's `reports/`.

use igimp::study::compaction::{CompactionResults, CompactionStudy};
use igimp::study::engine::{run_in_memory, write_outputs, Run, StudyKind};
use igimp::study::render::compaction::render;
use igimp::study::results::CaseStatus;
use igimp::study::Tier;

type CompactionRun = Run<CompactionStudy>;

fn run_study(s: &CompactionStudy, file: &str, tier: Tier) -> CompactionRun {
    run_in_memory(s, file, tier).expect("an in-memory run")
}

fn read_results(dir: &Path) -> Result<CompactionResults, igimp::study::StudyError> {
    igimp::study::results::read_results(dir)
}
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::OnceLock;

fn study() -> CompactionStudy {
    CompactionStudy::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("studies/compaction.toml"))
        .expect("studies/compaction.toml parses")
}

/// The quick tier, solved once for all tests of this file.
fn quick() -> &'static CompactionRun {
    static RUN: OnceLock<CompactionRun> = OnceLock::new();
    RUN.get_or_init(|| run_study(&study(), "compaction.toml", Tier::Quick))
}

fn read_tree(dir: &Path) -> BTreeMap<PathBuf, Vec<u8>> {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.is_file())
        .map(|p| (p.clone(), std::fs::read(&p).unwrap()))
        .collect()
}

/// results.json parses back; the report, Tables 2–3 and Figures 15–18 are written; deleting
/// them and running `study compaction --render-only` recreates them byte for byte.
#[test]
fn compaction_quick_outputs_rerender_byte_identically() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("reports");
    let dir = write_outputs(&out, quick()).unwrap();
    render(&dir).unwrap();
    let parsed = read_results(&dir).unwrap();
    assert_eq!(parsed.cases.len(), quick().results.cases.len());
    // serde_json may move a float by one ulp on the way back, so compare what the checks say.
    let verdicts = |c: &[igimp::study::checks::CheckRecord]| -> Vec<(String, Option<bool>)> {
        c.iter().map(|c| (c.id.clone(), c.pass)).collect()
    };
    assert_eq!(verdicts(&parsed.checks), verdicts(&quick().results.checks));
    for f in [
        "results.json",
        "domains.json",
        "report.md",
        "table2.md",
        "table3.md",
        "fig15.svg",
        "fig16.svg",
        "fig17.svg",
        "fig18.svg",
    ] {
        assert!(dir.join(f).is_file(), "missing {f}");
    }
    let table2 = std::fs::read_to_string(dir.join("table2.md")).unwrap();
    assert!(
        table2.contains("1.357e-3") && table2.contains("step 16 code"),
        "{table2}"
    );
    let before = read_tree(&dir);
    for (p, _) in before
        .iter()
        .filter(|(p, _)| !p.ends_with("results.json") && !p.ends_with("domains.json"))
    {
        std::fs::remove_file(p).unwrap();
    }
    let status = Command::new(env!("CARGO_BIN_EXE_study"))
        .args(["compaction", "--render-only", "--out"])
        .arg(&out)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .status()
        .unwrap();
    assert!(status.success());
    assert!(before == read_tree(&dir), "re-rendered files differ");
    let index = std::fs::read_to_string(out.join("index.md")).unwrap();
    assert!(
        index.contains("compaction/fig17.svg") && index.contains("compaction/table3.md"),
        "{index}"
    );
}

/// A second run agrees with the quick tier's in every case record and output (wall-clock
/// times are kept apart from them): the second run is the study cut to Figure 17, its
/// reference, the failing plastic case and every basis family with each penalty
/// (`trimmed`), so each kind of case and every basis is run twice.
#[test]
fn compaction_quick_tier_is_deterministic() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = crate::trimmed::write(
        tmp.path(),
        "compaction",
        &["plastic", "ghost", "weak-nodes", "families"],
    );
    let cut = CompactionStudy::load(&dir.join("compaction.toml")).unwrap();
    let again = run_study(&cut, "compaction.toml", Tier::Quick);
    let first = quick();
    crate::trimmed::assert_rerun_equal(
        (&again.results.cases, &again.outputs),
        (&first.results.cases, &first.outputs),
        10,
        |c| c.id.as_str(),
    );
}

/// Figure 17 (paper §5.2): for h ≤ 1/2 every points-per-cell setting that completes lies within
/// 1 % of the converged reference, within 2 % at h = 1, and the distance to the reference does
/// not grow as h decreases (0.1 % slack). The reference is the Q4 FEM extrapolated over its
/// three finest quick-tier meshes (h = 1/4, 1/8, 1/16).
#[test]
fn compaction_figure17_within_one_percent_of_fem_reference() {
    let r = &quick().results;
    let reference = r.measures.reference.as_ref().expect("a reference");
    assert_eq!(reference.method.name(), "fem-q4", "{reference:?}");
    let completed: Vec<_> = r
        .sweep("fig17")
        .into_iter()
        .filter(|c| c.method.name() == "igimp" && c.solve.status == CaseStatus::Converged)
        .collect();
    assert!(completed.len() >= 6);
    for c in &completed {
        let dev = (c.max_horizontal_displacement.unwrap() / reference.value - 1.0).abs();
        let band = if c.h <= 0.5 { 0.01 } else { 0.02 };
        assert!(
            dev <= band,
            "{}: {dev:.4} > {band} (reference {reference:?})",
            c.id
        );
    }
    for p in [2, 3] {
        let mut s: Vec<_> = completed
            .iter()
            .filter(|c| c.points_per_cell == Some(p))
            .collect();
        s.sort_by(|a, b| b.h.total_cmp(&a.h));
        let d: Vec<f64> = s
            .iter()
            .map(|c| (c.max_horizontal_displacement.unwrap() / reference.value - 1.0).abs())
            .collect();
        assert!(
            d.len() >= 3 && d.windows(2).all(|w| w[1] <= w[0] + 1e-3),
            "{p}x{p}: {d:?}"
        );
    }
    for c in &r.checks {
        assert_eq!(c.pass, Some(true), "{c:?}");
    }
}

/// Cases that cannot complete are recorded, not fatal: the plastic block at h = 1/4 with the
/// ghost penalty too weak for it (γ = 0.03 on every face; a point's domain would grow beyond
/// 3 elements at step 15) fails with its load step, the reason and the residuals of the
/// failing step. Every Figure 17 case converges with the default ghost term, one point per
/// cell included, and so does every plastic case with the plastic default (γ = 0.1).
#[test]
fn compaction_failures_are_recorded_with_step_and_residuals() {
    let r = &quick().results;
    {
        let id = "igimp-vm12000-h0.25-p2-g0.03";
        let c = r.case(id).unwrap_or_else(|| panic!("case {id}"));
        assert_eq!(c.solve.status, CaseStatus::Failed, "{id}");
        let f = c.solve.failure.as_ref().unwrap();
        assert!(
            f.step >= 1 && f.step <= 20 && !f.reason.is_empty() && !f.residuals.is_empty(),
            "{id}: {f:?}"
        );
        assert_eq!(c.solve.steps.len(), f.step - 1, "{id}");
    }
    for c in r.sweep("fig17") {
        assert_eq!(
            c.solve.status,
            CaseStatus::Converged,
            "{}: {:?}",
            c.id,
            c.solve.failure
        );
    }
    assert!(r.case("igimp-elastic-h1-p1").is_some());
    for c in r.sweep("plastic") {
        assert_eq!(
            c.solve.status,
            CaseStatus::Converged,
            "{}: {:?}",
            c.id,
            c.solve.failure
        );
        assert!(c.max_horizontal_displacement.unwrap() > 5.0, "{}", c.id);
    }
}

/// Every basis family on Figure 17's measure (sweeps `families` and `families-ghost`): every
/// case converges, and the study's family checks hold (each family within its band of the
/// extrapolated Q4 at h ≤ 1/2, errors falling with h, the GCI extrapolations within 0.25 %
/// of the reference, the ghost spread within 0.1 %; bands and the measurements they come
/// from in studies/compaction.toml). MPM's cell-crossing drift is reported, not checked.
#[test]
fn compaction_every_family_converges_to_the_q4_reference() {
    let r = &quick().results;
    for sweep in ["families", "families-ghost"] {
        let cases = r.sweep(sweep);
        assert!(cases.len() >= 12, "{sweep}: {} cases", cases.len());
        for c in cases {
            assert_eq!(
                c.solve.status,
                CaseStatus::Converged,
                "{}: {:?}",
                c.id,
                c.solve.failure
            );
        }
    }
    let checks: Vec<_> = r.checks.iter().filter(|c| c.id.starts_with("families")).collect();
    assert_eq!(checks.len(), 10, "{checks:#?}");
    for c in checks {
        assert_eq!(c.pass, Some(true), "{c:#?}");
    }
}

/// A sweep that forces a factorisation names it in its case ids, so that it does not merge
/// with the same cases by the default solver (before, `linear_solver = "lu"` gave the
/// default's ids and one of the two sweeps was silently solved by the other's solver); `auto`
/// is the default and names nothing; an unknown solver is refused naming the key.
#[test]
fn a_sweep_that_forces_a_solver_names_it_in_its_ids() {
    let text = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("studies/compaction.toml"))
        .unwrap();
    let fig17 = "[[sweeps]]\nid = \"fig17\"\n";
    let with = |value: &str| {
        let copy = format!("[[sweeps]]\nid = \"fig17-{value}\"\nlinear_solver = \"{value}\"\n");
        let start = text.find(fig17).unwrap();
        let end = start + text[start..].find("\n\n").unwrap();
        let sweep = text[start..end].replacen(fig17, &copy, 1);
        format!("{}\n{sweep}\n", text.trim_end())
    };
    for (value, suffix) in [
        ("lu", "-lu"),
        ("ldlt", "-ldlt"),
        ("llt", "-llt"),
        ("cg", "-cg"),
        ("auto", ""),
    ] {
        let s = CompactionStudy::parse(&with(value), "compaction.toml").unwrap();
        let (_, index) = s.cases(Tier::Quick);
        let plain = &index["fig17"];
        let forced = &index[&format!("fig17-{value}")];
        assert_eq!(plain.len(), forced.len());
        for (a, b) in plain.iter().zip(forced) {
            let h = a.find("-p").unwrap_or(a.len());
            let expected = if a.starts_with("fem") {
                format!("{a}{suffix}")
            } else {
                format!("{}{suffix}{}", &a[..h], &a[h..])
            };
            assert_eq!(b, &expected, "{value}");
        }
    }
    let err = CompactionStudy::parse(&with("gauss"), "compaction.toml")
        .unwrap_err()
        .to_string();
    assert!(err.contains("linear_solver") && err.contains("gauss"), "{err}");
}
