//! One test per defect a hostile user found in the harness: each input below was accepted
//! (or misreported) before, and is now an error at load naming its key, or a warning, or a
//! readable message. Study files are the committed ones with one value changed, checked with
//! `--render-only` (validation runs before anything is solved or rendered).

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn study_bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_study"))
}

fn repo_study(name: &str) -> String {
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("studies")
        .join(format!("{name}.toml"));
    std::fs::read_to_string(p).unwrap()
}

/// `text` with `from` (which must occur) replaced by `to`.
fn with(text: &str, from: &str, to: &str) -> String {
    assert!(text.contains(from), "{from:?} not in the study file");
    text.replacen(from, to, 1)
}

fn write(dir: &Path, file: &str, text: &str) -> PathBuf {
    std::fs::create_dir_all(dir).unwrap();
    let p = dir.join(file);
    std::fs::write(&p, text).unwrap();
    p
}

fn run(args: &[&std::ffi::OsStr]) -> (Output, String) {
    let out = study_bin()
        .args(args)
        .env("RAYON_NUM_THREADS", "1")
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    (out, err)
}

/// The study file `text` is rejected at load with an error naming `key` (and `also`).
fn rejected(text: &str, key: &str, also: &str) {
    let tmp = tempfile::tempdir().unwrap();
    let f = write(tmp.path(), "s.toml", text);
    let out = tmp.path().join("out");
    let (o, err) = run(&[
        f.as_os_str(),
        "--render-only".as_ref(),
        "--out".as_ref(),
        out.as_os_str(),
    ]);
    assert!(!o.status.success(), "accepted; stderr:\n{err}");
    assert!(
        err.contains(&format!("`{key}`")),
        "error does not name `{key}`:\n{err}"
    );
    assert!(err.contains(also), "error does not say {also:?}:\n{err}");
    assert!(err.len() < 2000, "message too long:\n{err}");
}

#[test]
fn column_max_cutbacks_beyond_the_limit_is_rejected_at_load() {
    let t = with(
        &repo_study("column"),
        "[newton]\n",
        "[newton]\nmax_cutbacks = 100\n",
    );
    rejected(&t, "newton.max_cutbacks", "0..=20");
}

#[test]
fn weak_node_tolerances_outside_zero_one_are_rejected_at_load() {
    for study in ["compaction", "cantilever"] {
        for bad in ["-0.5", "1.0"] {
            let t = with(
                &repo_study(study),
                "[weak_nodes]\ntolerance = 0.0",
                &format!("[weak_nodes]\ntolerance = {bad}"),
            );
            rejected(&t, "weak_nodes.tolerance", "[0, 1)");
        }
    }
}

#[test]
fn a_third_grid_extent_is_an_error_not_dropped() {
    let t = with(
        &repo_study("compaction"),
        "grid_extent = [10.0, 10.0]",
        "grid_extent = [10.0, 10.0, 10.0]",
    );
    let tmp = tempfile::tempdir().unwrap();
    let f = write(tmp.path(), "s.toml", &t);
    let out = tmp.path().join("out");
    let (o, err) = run(&[
        f.as_os_str(),
        "--render-only".as_ref(),
        "--out".as_ref(),
        out.as_os_str(),
    ]);
    assert!(
        !o.status.success() && err.contains("grid_extent") && err.contains("2 values"),
        "{err}"
    );
}

#[test]
fn a_cantilever_load_must_be_positive() {
    for bad in ["0.0", "-1.0e5"] {
        let t = with(
            &repo_study("cantilever"),
            "load = 1.0e5 ",
            &format!("load = {bad} "),
        );
        rejected(&t, "load", "> 0");
    }
}

#[test]
fn an_agreement_check_of_a_case_against_itself_is_rejected() {
    let t = with(
        &repo_study("cantilever"),
        "case = \"stretch\"\nreference = \"q8\"",
        "case = \"stretch\"\nreference = \"stretch\"",
    );
    rejected(&t, "expect_agreement[0].reference", "another case");
}

#[test]
fn fit_points_beyond_the_levels_a_tier_runs_are_rejected() {
    // column.toml's first fitted sweep runs 8 element counts, 4 in the quick tier.
    let t = with(&repo_study("column"), "fit_points = 4", "fit_points = 5");
    rejected(&t, "sweeps[1].fit_points", "quick tier");
    let t = with(&repo_study("manufactured"), "fit_points = 3", "fit_points = 7");
    rejected(&t, "sweeps[0].fit_points", "cell counts");
}

#[test]
fn a_domains_figure_of_a_case_without_snapshots_is_rejected() {
    let t = with(
        &repo_study("cantilever"),
        "kind = \"domains\"\ncases = [\"stretch\"]",
        "kind = \"domains\"\ncases = [\"q8\"]",
    );
    rejected(&t, "figures[0].cases", "snapshot_every");
}

#[test]
fn the_cantilever_depth_message_names_element_size() {
    // Two points per cell through one element: the points straddle the axis, the grid does not.
    let t = with(
        &repo_study("cantilever"),
        "element_size = 0.5 ",
        "element_size = 1.0 ",
    );
    let t = with(&t, "points_per_cell = 3 ", "points_per_cell = 2 ");
    rejected(&t, "element_size", "even number of elements");
}

#[test]
fn render_only_with_vtk_is_a_usage_error() {
    let tmp = tempfile::tempdir().unwrap();
    for flag in ["--vtk", "--vtk-every=2"] {
        let (o, err) = run(&[
            "column".as_ref(),
            "--render-only".as_ref(),
            flag.as_ref(),
            "--out".as_ref(),
            tmp.path().as_os_str(),
        ]);
        assert_eq!(o.status.code(), Some(2), "{flag}: {err}");
        assert!(err.contains("cannot be used with"), "{err}");
    }
}

/// A bad file anywhere in the list stops the run before any study is solved, and two files
/// of one `name` are rejected (they would share an output folder).
#[test]
fn every_file_is_validated_before_any_is_solved() {
    let tmp = tempfile::tempdir().unwrap();
    let studies = tmp.path().join("studies");
    let good = repo_study("column");
    write(
        &studies,
        "a.toml",
        &with(&good, "name = \"column\"", "name = \"first\""),
    );
    write(
        &studies,
        "c.toml",
        &with(&good, "young_modulus = 1.0e6", "young_modulus = -1.0"),
    );
    let out = tmp.path().join("out");
    let (o, err) = run(&[
        "all".as_ref(),
        "--quick".as_ref(),
        "--studies-dir".as_ref(),
        studies.as_os_str(),
        "--out".as_ref(),
        out.as_os_str(),
    ]);
    assert!(
        !o.status.success() && err.contains("material.young_modulus"),
        "{err}"
    );
    assert!(
        !out.join("first").exists(),
        "the valid first study was solved: {err}"
    );

    std::fs::remove_file(studies.join("c.toml")).unwrap();
    write(
        &studies,
        "b.toml",
        &with(&good, "name = \"column\"", "name = \"first\""),
    );
    let (o, err) = run(&[
        "all".as_ref(),
        "--quick".as_ref(),
        "--studies-dir".as_ref(),
        studies.as_os_str(),
        "--out".as_ref(),
        out.as_os_str(),
    ]);
    assert!(
        !o.status.success() && err.contains("`name`") && err.contains("a.toml"),
        "{err}"
    );
    assert!(!out.join("first").exists(), "{err}");
}

/// Extreme but valid magnitudes give readable ids and messages (shortest round-trip form),
/// never a 301-digit file name.
#[test]
fn extreme_numbers_read_in_shortest_form() {
    let tmp = tempfile::tempdir().unwrap();
    let small = r#"
schema = 1
name = "x"
summary = "extreme magnitudes"
problem = "column"
report_file = "table.md"
load_steps = 2
[column]
length = 50.0
density = 80.0
[material]
model = "linear-elastic"
young_modulus = 1.0e300
poisson_ratio = 0.0
[newton]
tolerance = 1.0e-9
max_iterations = 30
[[sweeps]]
id = "a"
title = "one case"
methods = ["igimp"]
weights = [1.0e300]
elements = [4]
points_per_cell = [2]
"#;
    let f = write(tmp.path(), "x.toml", small);
    let out = tmp.path().join("out");
    let (o, err) = run(&[f.as_os_str(), "--out".as_ref(), out.as_os_str()]);
    assert!(o.status.success(), "{err}");
    assert!(out.join("x/points/igimp-w1e300-e4-p2-s2.csv").is_file(), "{err}");
    let too_heavy = with(small, "weights = [1.0e300]", "weights = [1.0e305]");
    rejected(&too_heavy, "sweeps[0].weights[0]", "1e303");
}

/// A model with E = 1e-300 has the manufactured field's answer (errors independent of E, as
/// the body force scales with E): before, its squared forces underflowed to a zero norm and
/// the case "converged" at zero displacement with 100 % error.
#[test]
fn tiny_and_huge_moduli_give_the_same_manufactured_errors() {
    let tmp = tempfile::tempdir().unwrap();
    let mut errors = vec![];
    for e in ["1.0", "1.0e-300", "1.0e300"] {
        let text = format!(
            r#"
schema = 1
name = "m"
summary = "modulus scale"
problem = "manufactured"
report_file = "report.md"
load_steps = 4
[material]
model = "linear-elastic"
young_modulus = {e}
poisson_ratio = 0.3
[amplitude]
axis_aligned = 0.1
vortex = 0.6
[newton]
tolerance = 1.0e-10
max_iterations = 30
[[sweeps]]
id = "v"
title = "vortex"
field = "vortex"
methods = ["igimp", "fem-q4"]
domain_updates = ["stretch"]
cells = [4]
points_per_cell = [2]
"#
        );
        let f = write(tmp.path(), "m.toml", &text);
        let out = tmp.path().join(format!("out{e}"));
        let (o, err) = run(&[f.as_os_str(), "--out".as_ref(), out.as_os_str()]);
        assert!(o.status.success(), "{err}");
        let v: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(out.join("m/results.json")).unwrap()).unwrap();
        let errs: Vec<f64> = v["cases"]
            .as_array()
            .unwrap()
            .iter()
            .map(|c| {
                assert_eq!(c["status"], "converged", "E = {e}: {c}");
                c["displacement_error"].as_f64().unwrap()
            })
            .collect();
        errors.push(errs);
    }
    for (e, errs) in errors.iter().enumerate().skip(1) {
        for (a, b) in errs.iter().zip(&errors[0]) {
            assert!(
                (a - b).abs() <= 1e-9 * b,
                "modulus {e}: error {a} against {b} at E = 1"
            );
        }
    }
}

/// A tiny column run: its output folder, its stderr.
fn tiny_run(tmp: &Path, text: &str, extra: &[&str]) -> (PathBuf, Output, String) {
    let f = write(tmp, "t.toml", text);
    let out = tmp.join("out");
    let mut args: Vec<&std::ffi::OsStr> = vec![f.as_os_str(), "--out".as_ref(), out.as_os_str()];
    args.extend(extra.iter().map(|s| std::ffi::OsStr::new(*s)));
    let (o, err) = run(&args);
    (out, o, err)
}

const TINY: &str = r#"
schema = 1
name = "t"
summary = "tiny"
problem = "column"
report_file = "table.md"
load_steps = 2
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
id = "a"
title = "small cases"
methods = ["igimp", "fem-linear"]
weights = [40000.0]
elements = [4, 8]
points_per_cell = [2]
[[figures]]
id = "conv"
title = "Convergence"
kind = "convergence"
sweep = "a"
weight = 40000.0
measure = "stress_error"
"#;

/// A convergence figure whose every case failed is a warning (stderr and the report), not a
/// failed study: the run exits 0, writes its summary and index, and links no missing figure.
#[test]
fn a_figure_without_data_is_a_warning_not_a_failed_study() {
    let tmp = tempfile::tempdir().unwrap();
    // One Newton iteration cannot reach 1e-9 on the column: every case fails.
    let failing = with(
        TINY,
        "max_iterations = 30",
        "max_iterations = 1\nmax_cutbacks = 0",
    );
    let (out, o, err) = tiny_run(tmp.path(), &failing, &[]);
    assert!(o.status.success(), "{err}");
    assert!(err.contains("warning: figure `conv` not drawn"), "{err}");
    let report = std::fs::read_to_string(out.join("t/table.md")).unwrap();
    assert!(
        report.contains("**Not drawn:**") && !report.contains("conv.svg"),
        "{report}"
    );
    let index = std::fs::read_to_string(out.join("index.md")).unwrap();
    assert!(!index.contains("conv.svg"), "{index}");
    assert!(!out.join("t/conv.svg").exists());
    // A quick tier that skips the only sweep is an empty run: an error naming it, not a
    // silent exit 0 (first contact, D8).
    let skipped = with(TINY, "[[figures]]", "[sweeps.quick]\nskip = true\n[[figures]]");
    let (_, o, err) = tiny_run(tmp.path(), &skipped, &["--quick"]);
    assert!(!o.status.success(), "{err}");
    assert!(err.contains("quick tier: 0 cases"), "{err}");
}

/// With stderr not a terminal (a Slurm log), every finished case is a line with the elapsed
/// time and an estimate of the rest; no "0/0" frame.
#[test]
fn progress_is_plain_lines_off_a_terminal() {
    let tmp = tempfile::tempdir().unwrap();
    let (_, o, err) = tiny_run(tmp.path(), TINY, &[]);
    assert!(o.status.success(), "{err}");
    assert!(err.contains("t: 4 cases to solve or resume"), "{err}");
    let lines: Vec<&str> = err.lines().filter(|l| l.contains("/4 cases, ")).collect();
    assert_eq!(lines.len(), 4, "{err}");
    assert!(
        lines.iter().all(|l| l.contains("elapsed") && l.contains("ETA")),
        "{err}"
    );
    assert!(lines[3].starts_with("t: 4/4 cases"), "{err}");
    assert!(!err.contains("0/0"), "{err}");
}

/// Every results.json names the commit the binary was built from, and the report says it.
#[test]
fn results_record_the_commit() {
    let tmp = tempfile::tempdir().unwrap();
    let (out, o, err) = tiny_run(tmp.path(), TINY, &[]);
    assert!(o.status.success(), "{err}");
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("t/results.json")).unwrap()).unwrap();
    let commit = v["software"]["commit"].as_str().unwrap();
    let in_git = Path::new(env!("CARGO_MANIFEST_DIR")).join(".git").exists();
    if in_git {
        assert!(
            commit.len() == 40 && commit.chars().all(|c| c.is_ascii_hexdigit()),
            "{commit}"
        );
        assert!(v["software"]["dirty"].is_boolean(), "{v}");
    }
    let report = std::fs::read_to_string(out.join("t/table.md")).unwrap();
    assert!(
        report.contains(&format!("commit {}", &commit[..commit.len().min(12)])),
        "{report}"
    );
}

/// `--render-only` on a truncated results.json shows the JSON error, not "missing".
#[test]
fn a_truncated_results_file_shows_its_parse_error() {
    let tmp = tempfile::tempdir().unwrap();
    let (out, o, err) = tiny_run(tmp.path(), TINY, &[]);
    assert!(o.status.success(), "{err}");
    let p = out.join("t/results.json");
    let text = std::fs::read_to_string(&p).unwrap();
    std::fs::write(&p, &text[..text.len() / 2]).unwrap();
    let (_, o, err) = tiny_run(tmp.path(), TINY, &["--render-only"]);
    assert!(!o.status.success());
    assert!(err.contains("not valid JSON") && err.contains("line"), "{err}");
    assert!(!err.contains("missing or unreadable"), "{err}");
}
