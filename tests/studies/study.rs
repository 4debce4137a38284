//! The study runner: the quick tier of `studies/column.toml` meets the rate bands written in the
//! file, its outputs re-render byte for byte, runs are repeatable, bad study files are rejected
//! with the key named, and a diverging case is recorded while the others finish.
//!
//! Everything is written to temporary folders, never to the repository's `reports/`.

use igimp::basis::method::Method;
use igimp::study::column::rates::RateRecord;
use igimp::study::column::records::ColumnResults;
use igimp::study::column::{ColumnStudy, Measure};
use igimp::study::engine::{run_in_memory, write_outputs, Run, StudyKind};
use igimp::study::render::column as report;
use igimp::study::results::CaseStatus;
use igimp::study::{StudyError, Tier};

type StudyRun = Run<ColumnStudy>;

fn run_study(s: &ColumnStudy, file: &str, tier: Tier, _on_done: &dyn Fn(&str)) -> StudyRun {
    run_in_memory(s, file, tier).expect("an in-memory run")
}

fn read_results(dir: &std::path::Path) -> Result<ColumnResults, StudyError> {
    igimp::study::results::read_results(dir)
}
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::OnceLock;

fn column_file() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("studies/column.toml")
}

fn column_text() -> String {
    std::fs::read_to_string(column_file()).expect("studies/column.toml")
}

/// The quick tier of the column study, solved once for all tests of this file.
fn quick() -> &'static StudyRun {
    static RUN: OnceLock<StudyRun> = OnceLock::new();
    RUN.get_or_init(|| {
        let spec = ColumnStudy::load(&column_file()).expect("column study parses");
        run_study(&spec, "column.toml", Tier::Quick, &|_| {})
    })
}

fn is_fem(m: Method) -> bool {
    matches!(m, Method::FEM_LINEAR | Method::FEM_QUADRATIC)
}

fn expected_rate(method: Method, measure: Measure) -> &'static RateRecord {
    quick()
        .results
        .measures
        .rates
        .iter()
        .find(|r| r.method == method && r.measure == measure && r.expected.is_some())
        .unwrap_or_else(|| panic!("no expected {measure:?} rate for {method:?} in the quick tier"))
}

fn assert_in_band(r: &RateRecord) {
    let b = r.expected.as_ref().expect("expectation");
    let slope = r.slope.unwrap_or_else(|| panic!("no fitted slope for {r:?}"));
    assert!(
        (slope - b.rate).abs() <= b.tolerance,
        "{} {} W={} ppc={:?} {}: slope {slope:.3} outside {} ± {} ({})",
        r.sweep,
        r.method.name(),
        r.load,
        r.points_per_cell,
        r.measure.name(),
        b.rate,
        b.tolerance,
        b.source
    );
    assert_eq!(r.pass, Some(true));
}

/// Every non-FEM rate expectation of the quick tier holds, with the bands from the study file.
#[test]
fn igimp_quick_tier_rates_inside_study_bands() {
    let run = quick();
    let checked: Vec<&RateRecord> = run
        .results
        .measures
        .rates
        .iter()
        .filter(|r| r.expected.is_some() && !is_fem(r.method))
        .collect();
    assert!(
        checked
            .iter()
            .any(|r| r.method == Method::IGIMP && r.measure == Measure::StressError)
            && checked
                .iter()
                .any(|r| r.method == Method::IGIMP && r.measure == Measure::FError),
        "the quick tier must check iGIMP stress and F error rates"
    );
    for r in checked {
        assert_in_band(r);
    }
    for c in run
        .results
        .measures
        .comparisons
        .iter()
        .filter(|c| !is_fem(c.lower) && !is_fem(c.higher))
    {
        assert_eq!(c.pass, Some(true), "comparison failed: {c:?}");
    }
    // The iGIMP cases of the quick tier all converge.
    for c in run.results.cases.iter().filter(|c| c.method == Method::IGIMP) {
        assert_eq!(
            c.solve.status,
            CaseStatus::Converged,
            "{}: {:?}",
            c.id,
            c.solve.failure
        );
    }
}

/// Paper §5.1, Figure 11: linear FEM's stress error converges at rate 1 ± 0.1.
#[test]
fn fem_linear_stress_error_rate_is_1() {
    let r = expected_rate(Method::FEM_LINEAR, Measure::StressError);
    assert_eq!(
        r.expected.as_ref().map(|b| (b.rate, b.tolerance)),
        Some((1.0, 0.1))
    );
    assert_in_band(r);
}

/// Paper Table 1: linear FEM's base F error converges at rate 1 ± 0.1.
#[test]
fn fem_linear_f_error_rate_is_1() {
    assert_in_band(expected_rate(Method::FEM_LINEAR, Measure::FError));
}

/// Paper §5.1, Figure 11: quadratic FEM's stress error converges at rate 2 ± 0.2.
#[test]
fn fem_quadratic_stress_error_rate_is_2() {
    let r = expected_rate(Method::FEM_QUADRATIC, Measure::StressError);
    assert_eq!(
        r.expected.as_ref().map(|b| (b.rate, b.tolerance)),
        Some((2.0, 0.2))
    );
    assert_in_band(r);
}

/// Paper §5.1, Figure 11: at equal element count iGIMP's stress error is below linear FEM's.
#[test]
fn igimp_stress_error_below_linear_fem_at_equal_elements() {
    let c = quick()
        .results
        .measures
        .comparisons
        .iter()
        .find(|c| c.lower == Method::IGIMP && c.higher == Method::FEM_LINEAR)
        .expect("comparison igimp < fem-linear in the study file");
    assert!(c.elements_checked.len() >= 3, "{c:?}");
    assert_eq!(c.pass, Some(true), "{c:?}");
}

/// Two runs of the quick tier give identical results apart from wall-clock fields, and the
/// written `results.json` parses back to the same numbers.
#[test]
fn study_runs_are_repeatable_and_results_json_parses() {
    let first = quick();
    let spec = ColumnStudy::load(&column_file()).unwrap();
    let second = run_study(&spec, "column.toml", Tier::Quick, &|_| {});
    assert_eq!(first.results.without_timing(), second.results.without_timing());
    assert_eq!(first.outputs, second.outputs);
    let dir = tempfile::tempdir().unwrap();
    let a = write_outputs(&dir.path().join("a"), first).unwrap();
    let b = write_outputs(&dir.path().join("b"), &second).unwrap();
    let ra = read_results(&a).unwrap();
    let rb = read_results(&b).unwrap();
    assert_eq!(ra.without_timing(), rb.without_timing());
    assert_eq!(ra.cases.len(), first.results.cases.len());
    // The `timing` block (wall seconds, threads, seconds per case) is last.
    let strip = |p: &Path| -> String {
        let text = std::fs::read_to_string(p.join("results.json")).unwrap();
        let end = text.find("\"timing\": {").expect("a timing block");
        assert!(
            !text[..end].contains("seconds"),
            "wall-clock data outside `timing`"
        );
        text[..end].to_string()
    };
    assert_eq!(
        strip(&a),
        strip(&b),
        "results.json differs beyond wall-clock fields"
    );
    for case in &ra.cases {
        if case.solve.status != CaseStatus::Rejected {
            let csv = std::fs::read_to_string(a.join(format!("points/{}.csv", case.id))).unwrap();
            assert!(csv.starts_with("z0,z,volume0,sigma_zz,f_zz\n"));
            assert_eq!(csv.lines().count(), case.points + 1);
        }
    }
}

fn study_bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_study"))
}

fn read_tree(dir: &Path) -> Vec<(PathBuf, Vec<u8>)> {
    let mut out = vec![];
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            } else {
                out.push((p.clone(), std::fs::read(&p).unwrap()));
            }
        }
    }
    out.sort();
    out
}

/// `study column --quick` writes the report, every figure and the index, and `--render-only`
/// redraws them byte for byte from `results.json`.
#[test]
fn study_binary_quick_tier_rerenders_byte_identically() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("reports");
    let status = study_bin()
        .args(["column", "--quick", "--out"])
        .arg(&out)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .status()
        .unwrap();
    assert!(status.success());
    let col = out.join("column");
    for f in [
        "results.json",
        "table1.md",
        "fig8.svg",
        "fig9a.svg",
        "fig9b.svg",
        "fig10.svg",
        "fig11.svg",
    ] {
        assert!(col.join(f).is_file(), "missing {f}");
    }
    let index = std::fs::read_to_string(out.join("index.md")).unwrap();
    assert!(index.contains("column/table1.md") && index.contains("column/fig11.svg"));
    let table = std::fs::read_to_string(col.join("table1.md")).unwrap();
    assert!(table.contains("Table 1") && table.contains("4.091e-4"), "{table}");
    let svg = std::fs::read_to_string(col.join("fig9b.svg")).unwrap();
    assert!(svg.contains("<text") && svg.contains("number of elements") && svg.contains("slope"));

    let before = read_tree(&out);
    // Remove the rendered files so that the re-render must recreate them.
    for f in ["table1.md", "fig8.svg", "fig11.svg"] {
        std::fs::remove_file(col.join(f)).unwrap();
    }
    std::fs::remove_file(out.join("index.md")).unwrap();
    let status = study_bin()
        .args(["column", "--render-only", "--out"])
        .arg(&out)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .status()
        .unwrap();
    assert!(status.success());
    let after = read_tree(&out);
    assert_eq!(before.len(), after.len());
    for ((pa, a), (pb, b)) in before.iter().zip(&after) {
        assert_eq!(pa, pb);
        assert!(a == b, "{} changed on --render-only", pa.display());
    }
}

/// `study --help` explains each study in a line and `study list` lists them.
#[test]
fn study_binary_help_and_list_name_the_column_study() {
    let help = study_bin()
        .arg("--help")
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&help.stdout);
    assert!(help.status.success());
    assert!(
        text.contains("column") && text.contains("--quick") && text.contains("--render-only"),
        "{text}"
    );
    let list = study_bin()
        .arg("list")
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .unwrap();
    // Studies are listed by file name; the column study is one line among them.
    let listed = String::from_utf8_lossy(&list.stdout).into_owned();
    assert!(listed.lines().any(|l| l.starts_with("column ")), "{listed}");
}

fn parse_err(text: &str) -> String {
    match ColumnStudy::parse(text, "bad.toml") {
        Ok(_) => panic!("study file accepted"),
        Err(e) => e.to_string(),
    }
}

/// A misspelt key is an error naming the key and the file.
#[test]
fn study_file_with_misspelt_key_is_rejected_naming_it() {
    let text = column_text().replacen("elements = [50]", "elemnts = [50]", 1);
    let msg = parse_err(&text);
    assert!(msg.contains("bad.toml") && msg.contains("elemnts"), "{msg}");
    let msg = parse_err(&column_text().replacen("tolerance = 1.0e-9", "tolerence = 1.0e-9", 1));
    assert!(msg.contains("tolerence"), "{msg}");
}

/// A negative element count is an error naming the key and the allowed range.
#[test]
fn study_file_with_negative_element_count_names_key_and_range() {
    let text = column_text().replacen("elements = [50]", "elements = [-50]", 1);
    let err = ColumnStudy::parse(&text, "bad.toml").unwrap_err();
    match &err {
        StudyError::Invalid { key, allowed, .. } => {
            assert_eq!(key, "sweeps[0].elements[0]");
            assert!(allowed.contains("1..="), "{allowed}");
        }
        other => panic!("expected a range error, got {other}"),
    }
    let msg = err.to_string();
    assert!(msg.contains("bad.toml") && msg.contains("-50"), "{msg}");
}

/// A missing required key is an error naming it.
#[test]
fn study_file_with_missing_field_names_it() {
    let text: String = column_text()
        .lines()
        .filter(|l| !l.starts_with("load_steps"))
        .map(|l| format!("{l}\n"))
        .collect();
    let msg = parse_err(&text);
    assert!(msg.contains("load_steps"), "{msg}");
    // The binary reports it too, with a failing exit status.
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("broken.toml");
    std::fs::write(&file, &text).unwrap();
    let out = study_bin()
        .arg(&file)
        .arg("--out")
        .arg(dir.path().join("out"))
        .output()
        .unwrap();
    assert!(!out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("broken.toml") && stderr.contains("load_steps"),
        "{stderr}"
    );
}

/// A case forced to diverge (one load step of W = 400,000 with a single Newton iteration) is
/// recorded as failed with its step and residuals, and the other cases still finish.
#[test]
fn diverging_case_is_recorded_and_the_sweep_goes_on() {
    let text = r#"
schema = 1
name = "diverge"
summary = "one case that cannot converge beside two that do"
problem = "column"
report_file = "table.md"
load_steps = 20
[column]
length = 50.0
density = 80.0
[material]
model = "linear-elastic"
young_modulus = 1.0e6
poisson_ratio = 0.0
[newton]
tolerance = 1.0e-9
max_iterations = 30
[[sweeps]]
id = "capped"
title = "one step, one Newton iteration"
methods = ["igimp"]
weights = [400000.0]
elements = [16]
points_per_cell = [2]
load_steps = 1
newton = { tolerance = 1.0e-9, max_iterations = 1 }
[[sweeps]]
id = "fine"
title = "the usual settings"
methods = ["igimp"]
weights = [40000.0]
elements = [16, 32]
points_per_cell = [2]
[[figures]]
id = "conv"
title = "convergence"
kind = "convergence"
sweep = "fine"
weight = 40000.0
measure = "stress_error"
"#;
    let spec = ColumnStudy::parse(text, "diverge.toml").unwrap();
    let run = run_study(&spec, "diverge.toml", Tier::Full, &|_| {});
    let cases = &run.results.cases;
    assert_eq!(cases.len(), 3);
    let failed = &cases[0];
    assert_eq!(failed.solve.status, CaseStatus::Failed, "{failed:?}");
    assert!(failed.id.contains("it1"), "{}", failed.id);
    let f = failed.solve.failure.as_ref().unwrap();
    assert_eq!(f.step, 1);
    assert!(!f.residuals.is_empty(), "{f:?}");
    assert_eq!(failed.stress_error, None);
    for c in &cases[1..] {
        assert_eq!(c.solve.status, CaseStatus::Converged, "{c:?}");
        assert!(c.stress_error.is_some_and(|e| e > 0.0 && e < 0.1));
    }
    // The failure is in results.json and the report, and rendering still works.
    let dir = tempfile::tempdir().unwrap();
    let sdir = write_outputs(dir.path(), &run).unwrap();
    report::render(&sdir).unwrap();
    let table = std::fs::read_to_string(sdir.join("table.md")).unwrap();
    assert!(table.contains("failed") && table.contains(&failed.id), "{table}");
}

/// The plastic column study in its quick tier: every expected rate (σzz, σxx,
/// linear FEM) lies in its band from `studies/column-plastic.toml`, iGIMP stays below linear
/// FEM, the point files carry σxx and the plastic multiplier, and the yield height of the finest iGIMP case is within
/// 0.25 element of the analytical (Kirchhoff-criterion) value — and not the paper's formula.
#[test]
fn plastic_column_quick_tier_meets_its_bands_and_yield_height() {
    let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("studies/column-plastic.toml");
    let spec = ColumnStudy::load(&file).expect("plastic study parses");
    let run = run_study(&spec, "column-plastic.toml", Tier::Quick, &|_| {});
    let expected: Vec<&RateRecord> = run
        .results
        .measures
        .rates
        .iter()
        .filter(|r| r.expected.is_some())
        .collect();
    assert!(expected.iter().any(|r| r.measure == Measure::SigmaXxError));
    for r in expected {
        assert_in_band(r);
    }
    for c in &run.results.measures.comparisons {
        assert_eq!(c.pass, Some(true), "comparison failed: {c:?}");
    }
    let dir = tempfile::tempdir().unwrap();
    let study_dir = write_outputs(dir.path(), &run).unwrap();
    let finest = run
        .results
        .cases
        .iter()
        .filter(|c| c.method == Method::IGIMP && c.load == 400000.0)
        .max_by_key(|c| c.elements)
        .unwrap();
    let csv =
        std::fs::read_to_string(study_dir.join(igimp::study::column::kind::points_file(&finest.id))).unwrap();
    // σxx, then von Mises' internal variable: yielded (> 0) at the base, 0 at the top.
    assert!(csv.starts_with("z0,z,volume0,sigma_zz,f_zz,sigma_xx,plastic_multiplier\n"));
    let rows: Vec<Vec<f64>> = csv
        .lines()
        .skip(1)
        .map(|l| l.split(',').map(|x| x.parse().unwrap()).collect())
        .collect();
    let lowest = rows.iter().min_by(|a, b| a[0].total_cmp(&b[0])).unwrap();
    let highest = rows.iter().max_by(|a, b| a[0].total_cmp(&b[0])).unwrap();
    assert!(lowest[6] > 0.0 && highest[6] == 0.0, "{lowest:?} {highest:?}");
    let zy = finest.yield_height.expect("yield height");
    let h = 50.0 / finest.elements as f64;
    assert!((zy - 46.135795).abs() < 0.25 * h, "yield height {zy}");
    assert!(
        (zy - 46.25).abs() > 5.0 * (zy - 46.135795).abs(),
        "yield height {zy} is not clearly closer to the Kirchhoff criterion than to the paper's formula"
    );
    report::render(&study_dir).unwrap();
    assert!(study_dir.join("fig13.svg").exists() && study_dir.join("table.md").exists());
}
