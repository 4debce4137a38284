//! A new user's first contact with the harness: each test reproduces one defect found by
//! feeding the release binary hostile or careless input (an extreme value, an inapplicable
//! key, a huge mesh, a run whose every case fails) and checks the clear answer it now gets.

use std::path::{Path, PathBuf};
use std::process::Output;

fn repo_study(name: &str) -> String {
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("studies")
        .join(format!("{name}.toml"));
    std::fs::read_to_string(p).unwrap()
}

/// `text` with the line starting with `key =` (the first) replaced by `key = value`.
fn set(text: &str, key: &str, value: &str) -> String {
    let mut done = false;
    let out: Vec<String> = text
        .lines()
        .map(|l| {
            if !done && l.split('=').next().is_some_and(|k| k.trim() == key) && l.contains('=') {
                done = true;
                format!("{key} = {value}")
            } else {
                l.to_string()
            }
        })
        .collect();
    assert!(done, "no `{key} =` line");
    out.join("\n") + "\n"
}

fn write(dir: &Path, file: &str, text: &str) -> PathBuf {
    std::fs::create_dir_all(dir).unwrap();
    let p = dir.join(file);
    std::fs::write(&p, text).unwrap();
    p
}

fn study(args: &[&str], dir: &Path) -> (Output, String) {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_study"))
        .args(args)
        .current_dir(dir)
        .env("RAYON_NUM_THREADS", "1")
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    (out, err)
}

/// `text` is rejected at load: the error names `key`, says `also`, and gives the line `line`.
fn rejected(text: &str, key: &str, also: &str, line: Option<usize>) -> String {
    let tmp = tempfile::tempdir().unwrap();
    write(tmp.path(), "s.toml", text);
    let (o, err) = study(&["s.toml", "--render-only", "--out", "out"], tmp.path());
    assert!(!o.status.success(), "accepted; stderr:\n{err}");
    assert!(
        err.contains(&format!("`{key}`")),
        "error does not name `{key}`:\n{err}"
    );
    assert!(err.contains(also), "error does not say {also:?}:\n{err}");
    if let Some(n) = line {
        assert!(
            err.contains(&format!("s.toml:{n}:")),
            "error does not give line {n}:\n{err}"
        );
    }
    err
}

fn line_of(text: &str, start: &str) -> usize {
    1 + text.lines().position(|l| l.starts_with(start)).unwrap()
}

/// D1: an extreme length or density solved, then panicked measuring the closed form
/// ("ln F / F = NaN has no solution", exit 101); now rejected at load naming the key and the
/// derived gravity.
#[test]
fn extreme_length_or_density_is_rejected_at_load_naming_the_derived_gravity() {
    let base = repo_study("column");
    let t = set(&base, "length", "1.0e308");
    rejected(&t, "column.length", "gravity", Some(line_of(&t, "length =")));
    let t = set(&base, "density", "1.0e-320");
    rejected(&t, "column.length", "ρ0 = 1e-320", Some(line_of(&t, "length =")));
}

/// D5: a problem input was named as the problem calls it (`half_width`) inside an opaque
/// "sweeps[0] case …" key; now the file's key with its line.
#[test]
fn case_inputs_name_the_files_key_and_line() {
    let t = set(&repo_study("compaction"), "half_width", "-4.0");
    rejected(
        &t,
        "block.half_width",
        "igimp-elastic",
        Some(line_of(&t, "half_width =")),
    );
    let t = set(&repo_study("manufactured"), "young_modulus", "-1.0");
    rejected(
        &t,
        "material.young_modulus",
        "> 0",
        Some(line_of(&t, "young_modulus =")),
    );
    let t = set(&repo_study("vibrating-bar"), "beta", "-1.0");
    rejected(&t, "bar.beta", "(0, 0.5]", Some(line_of(&t, "beta =")));
}

/// D5 and D8: `bar.periods = 1e6` was only refused at run time (as `load_steps`), with exit 0;
/// an amplitude of 0 was accepted (every error 0).
#[test]
fn derived_step_counts_and_a_zero_amplitude_are_rejected_at_load() {
    let t = set(&repo_study("vibrating-bar"), "periods", "1.0e6");
    rejected(&t, "bar.periods", "time steps must be <= 1000000", None);
    let t = set(&repo_study("manufactured"), "axis_aligned", "0.0");
    rejected(&t, "amplitude.axis_aligned", "must not be 0", None);
}

/// D8: a Newton tolerance below round-off made every case fail, with exit 0.
#[test]
fn a_tolerance_below_round_off_is_rejected() {
    let t = set(&repo_study("column"), "tolerance", "1.0e-20");
    rejected(
        &t,
        "newton.tolerance",
        "round-off",
        Some(line_of(&t, "tolerance =")),
    );
}

/// D5: a duplicate cantilever case id got the identifier-format message.
#[test]
fn a_duplicate_case_id_is_called_a_duplicate() {
    let base = repo_study("cantilever");
    let first = base
        .find("[[cases]]\nid = ")
        .expect("a [[cases]] table with its id first");
    let id_line = base[first + 10..].lines().next().unwrap();
    let second = base[first + 10..].find("[[cases]]\nid = ").unwrap() + first + 10;
    let second_line = base[second + 10..].lines().next().unwrap();
    let t = format!(
        "{}{}{}",
        &base[..second + 10],
        id_line,
        &base[second + 10 + second_line.len()..]
    );
    rejected(&t, "cases[1].id", "must be unique", None);
}

/// D8: an inapplicable key (a domain update on a FEM case) was accepted silently.
#[test]
fn a_domain_update_on_a_fem_case_is_rejected() {
    let base = repo_study("cantilever");
    let fem = base.find("method = \"fem-q8\"").expect("a Q8 case");
    let t = format!("{}domain_update = \"stretch\"\n{}", &base[..fem], &base[fem..]);
    let err = rejected(&t, "cases[8].domain_update", "must be absent for fem-q8", None);
    assert!(err.contains("= \"stretch\""), "{err}");
}

/// D8: `elements = [8, 8]` was silently de-duplicated while a duplicate method is rejected.
#[test]
fn a_value_listed_twice_in_a_sweep_is_rejected() {
    let t = repo_study("column").replacen("elements = [50]", "elements = [50, 50]", 1);
    rejected(&t, "sweeps[0]", "must not list a value twice", None);
}

/// A tiny column whose Newton gets one iteration: every case fails at its first step.
fn failing_column(declared: bool) -> String {
    let mut t = String::from(
        "schema = 1\nname = \"tiny\"\nsummary = \"every case fails\"\nproblem = \"column\"\n\
         report_file = \"table1.md\"\nload_steps = 2\n\n[column]\nlength = 50.0\n\
         density = 80.0\n\n[material]\nmodel = \"linear-elastic\"\nyoung_modulus = 1.0e6\n\
         poisson_ratio = 0.0\n\n[newton]\n\
         tolerance = 1.0e-9\nmax_iterations = 1\n\n[[sweeps]]\nid = \"s\"\ntitle = \"t\"\n\
         methods = [\"igimp\"]\nweights = [40000.0]\nelements = [4, 8]\npoints_per_cell = [2]\n",
    );
    if declared {
        t.push_str("\n[[expected_failures]]\ncases = [\"igimp-*\"]\nreason = \"one Newton iteration cannot converge\"\n");
    }
    t
}

/// D7 and item 4: `--check` exited 0 when every case failed, if the study had no checks;
/// now an undeclared failure fails it, a declared one is reported as expected.
#[test]
fn check_fails_on_undeclared_failures_and_reports_declared_ones() {
    let tmp = tempfile::tempdir().unwrap();
    write(tmp.path(), "tiny.toml", &failing_column(false));
    let (o, err) = study(&["tiny.toml", "--check", "--out", "out"], tmp.path());
    assert_eq!(o.status.code(), Some(2), "stderr:\n{err}");
    assert!(err.contains("2 NOT expected"), "{err}");
    write(tmp.path(), "tiny.toml", &failing_column(true));
    let (o, err) = study(&["tiny.toml", "--check", "--out", "out"], tmp.path());
    assert!(o.status.success(), "stderr:\n{err}");
    assert!(
        err.contains("2 expected to fail (one Newton iteration cannot converge)"),
        "{err}"
    );
}

/// A declaration that matches no case of the run is said (stale, or of a sweep not run), and
/// the failures it does not cover fail --check.
#[test]
fn an_expected_failure_matching_no_case_is_said() {
    let tmp = tempfile::tempdir().unwrap();
    let t = failing_column(true).replace("cases = [\"igimp-*\"]", "cases = [\"mpm-*\"]");
    write(tmp.path(), "tiny.toml", &t);
    let (o, err) = study(&["tiny.toml", "--check", "--out", "out"], tmp.path());
    assert_eq!(o.status.code(), Some(2), "stderr:\n{err}");
    assert!(
        err.contains("expected failures that match no case of this run: mpm-*"),
        "{err}"
    );
}

/// D3: the case cap was per sweep: many sweeps (or files) ran 200,006 cases.
#[test]
fn the_case_cap_holds_for_a_whole_run() {
    let tmp = tempfile::tempdir().unwrap();
    let elements: Vec<String> = (10..3010).map(|n| n.to_string()).collect();
    for name in ["a", "b"] {
        let t = failing_column(false)
            .replace("name = \"tiny\"", &format!("name = \"{name}\""))
            .replace("methods = [\"igimp\"]", "methods = [\"igimp\", \"mpm\"]")
            .replace(
                "elements = [4, 8]",
                &format!("elements = [{}]", elements.join(", ")),
            );
        write(tmp.path(), &format!("{name}.toml"), &t);
    }
    let (o, err) = study(&["a.toml", "b.toml", "--render-only", "--out", "out"], tmp.path());
    assert!(!o.status.success(), "accepted:\n{err}");
    assert!(
        err.contains("12000 cases in the full tier (a 6000, b 6000)"),
        "{err}"
    );
    assert!(err.contains("at most 10000 cases"), "{err}");
    // One of them alone is within the cap.
    let (_, err) = study(&["a.toml", "--render-only", "--out", "out"], tmp.path());
    assert!(!err.contains("at most 10000 cases"), "{err}");
}

/// D8: `study list column`, and `study list` of a folder that does not exist, exited 0.
#[test]
fn list_with_names_or_a_missing_folder_fails() {
    let tmp = tempfile::tempdir().unwrap();
    let (o, err) = study(&["list", "column"], tmp.path());
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("`list` takes no study names"), "{err}");
    let (o, err) = study(&["list", "--studies-dir", "/nonexistent-igimp"], tmp.path());
    assert!(!o.status.success(), "{err}");
    assert!(err.contains("/nonexistent-igimp"), "{err}");
}

/// D8: `--render-only --quick` ignored `--quick` and drew the full tier's results.
#[test]
fn render_only_quick_refuses_full_results() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("out").join("tiny");
    std::fs::create_dir_all(&out).unwrap();
    std::fs::write(
        out.join("results.json"),
        "{\"tier\": \"full\", \"study\": {\"problem\": \"column\"}}",
    )
    .unwrap();
    write(tmp.path(), "tiny.toml", &failing_column(true));
    let (o, err) = study(
        &["tiny.toml", "--render-only", "--quick", "--out", "out"],
        tmp.path(),
    );
    assert!(!o.status.success(), "{err}");
    assert!(err.contains("--render-only --quick"), "{err}");
}

/// Item 7: `study all --render-only` stopped at the first study without results.
#[test]
fn render_only_all_lists_the_studies_without_results() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("studies");
    let (o, err) = study(
        &[
            "all",
            "--render-only",
            "--out",
            "out",
            "--studies-dir",
            dir.to_str().unwrap(),
        ],
        tmp.path(),
    );
    assert!(o.status.success(), "{err}");
    assert!(err.contains("not rendered, no results.json"), "{err}");
    assert!(
        err.contains("column-plastic") && err.contains("vibrating-bar"),
        "{err}"
    );
}

/// D9: a run without --vtk left the previous run's `vtk/` beside results it does not show.
#[test]
fn a_run_without_vtk_removes_an_earlier_runs_vtk() {
    let tmp = tempfile::tempdir().unwrap();
    write(tmp.path(), "tiny.toml", &failing_column(true));
    let old = tmp.path().join("out").join("tiny").join("vtk");
    std::fs::create_dir_all(&old).unwrap();
    std::fs::write(old.join("stale.pvd"), "").unwrap();
    let (o, err) = study(&["tiny.toml", "--out", "out"], tmp.path());
    assert!(o.status.success(), "{err}");
    assert!(!old.exists(), "vtk/ kept:\n{err}");
    assert!(err.contains("removed"), "{err}");
}

/// D2: a FEM mesh of 6.4e9 elements aborted the process (a 25.6 GB allocation) and lost the
/// other cases; now it is refused with its estimate before anything is allocated.
#[test]
fn a_mesh_over_the_size_cap_is_refused_with_its_estimate() {
    use igimp::fem::{PlaneMesh, QuadElement};
    let e = PlaneMesh::structured(
        nalgebra::SVector::zeros(),
        nalgebra::SVector::from([4.0, 8.0]),
        [40_000, 80_000],
        QuadElement::Q4,
    )
    .unwrap_err();
    assert!(e.allowed.contains("estimated memory peak"), "{e}");
    assert!(e.allowed.contains("MAX_CASE_BYTES"), "{e}");
}

/// D2 in a study: the case over the cap is recorded as rejected with its estimate, and the
/// other case of the sweep is solved (before, the process aborted and lost every case).
#[test]
fn a_case_over_the_size_cap_is_recorded_and_the_others_run() {
    let text = "schema = 1\nname = \"huge\"\nsummary = \"one case over the size cap\"\n\
        problem = \"compaction\"\nreport_file = \"report.md\"\n\n[block]\nhalf_width = 4.0\n\
        height = 8.0\ngrid_extent = [10.0, 10.0]\nweight = 4.0e5\nload_steps = 2\n\n\
        [material]\nmodel = \"linear-elastic\"\nyoung_modulus = 1.0e5\npoisson_ratio = 0.3\n\n[newton]\ntolerance = 1.0e-9\nmax_iterations = 30\n\n\
        [weak_nodes]\ntolerance = 0.0\ntreatment = \"tie\"\n\n[ghost]\ngamma = 0.0\n\
        source = \"none\"\n\n[[sweeps]]\nid = \"s\"\ntitle = \"t\"\nmethods = [\"fem-q4\"]\n\
        element_sizes = [1.0e-4, 2.0]\npoints_per_cell = [2]\n\n[reference]\nfem_sweep = \"s\"\n\
        igimp_sweep = \"s\"\nsource = \"none\"\n";
    let tmp = tempfile::tempdir().unwrap();
    write(tmp.path(), "huge.toml", text);
    let (o, err) = study(&["huge.toml", "--out", "out"], tmp.path());
    assert!(o.status.success(), "{err}");
    let results: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(tmp.path().join("out/huge/results.json")).unwrap())
            .unwrap();
    let status = |id: &str| {
        let c = results["cases"]
            .as_array()
            .unwrap()
            .iter()
            .find(|c| c["id"] == id)
            .unwrap_or_else(|| panic!("no case {id}"));
        (c["status"].clone(), c["failure"]["reason"].clone())
    };
    let (s, reason) = status("fem-q4-elastic-h0.0001");
    assert_eq!(s, "rejected");
    assert!(
        reason.as_str().unwrap().contains("estimated memory peak"),
        "{reason}"
    );
    assert_eq!(status("fem-q4-elastic-h2").0, "converged");
}

/// D9: a `--merge` of another tier than its shards' listed every case "missing" with no hint.
#[test]
fn a_merge_of_another_tier_says_so() {
    let tmp = tempfile::tempdir().unwrap();
    let text = failing_column(true).replace(
        "points_per_cell = [2]\n",
        "points_per_cell = [2]\nquick = { elements = [16] }\n",
    );
    write(tmp.path(), "tiny.toml", &text);
    let (o, err) = study(
        &["tiny.toml", "--quick", "--shard", "0/1", "--out", "out"],
        tmp.path(),
    );
    assert!(o.status.success(), "{err}");
    let (o, err) = study(&["tiny.toml", "--merge", "--out", "out"], tmp.path());
    assert!(!o.status.success(), "{err}");
    assert!(err.contains("another tier (--quick)"), "{err}");
}

/// D5: a key missing from the top level was reported at line 1, column 1 (often a comment);
/// now the error says where the key belongs.
#[test]
fn a_missing_top_level_key_says_where_it_belongs() {
    let t: String = repo_study("column")
        .lines()
        .filter(|l| !l.starts_with("summary ="))
        .map(|l| format!("{l}\n"))
        .collect();
    let tmp = tempfile::tempdir().unwrap();
    write(tmp.path(), "s.toml", &t);
    let (o, err) = study(&["s.toml", "--render-only", "--out", "out"], tmp.path());
    assert!(!o.status.success(), "{err}");
    assert!(
        err.contains("missing required key `summary` at the top level of the file"),
        "{err}"
    );
    assert!(!err.contains("line 1, column 1"), "{err}");
}

/// The `[material]` section: an unknown model lists the known ones, a missing or an unknown
/// parameter names its key, a sweep naming no `[materials.<name>]` table names its key, and a
/// kind that takes one model only says which, each with the file's line.
#[test]
fn material_errors_name_the_model_or_parameter_key_and_line() {
    let column = repo_study("column");
    let t = set(&column, "model", "\"von-mieses\"");
    rejected(
        &t,
        "material.model",
        "linear-elastic, von-mises",
        Some(line_of(&t, "model =")),
    );
    let t = column.replacen("poisson_ratio = 0.0\n", "", 1);
    rejected(
        &t,
        "material.poisson_ratio",
        "the model linear-elastic needs it",
        Some(line_of(&t, "[material]")),
    );
    let t = column.replacen(
        "model = \"linear-elastic\"",
        "model = \"linear-elastic\"\nyield_stress = 3.0e4",
        1,
    );
    rejected(
        &t,
        "material.yield_stress",
        "is not a parameter of the model linear-elastic",
        Some(line_of(&t, "yield_stress =")),
    );
    let compaction = repo_study("compaction");
    let t = compaction.replacen("material = \"von-mises\"", "material = \"plastic\"", 1);
    rejected(
        &t,
        "sweeps[1].material",
        "it has: von-mises",
        Some(line_of(&t, "material = \"plastic\"")),
    );
    let t = compaction.replacen("yield_stress = 1.2e4", "", 1);
    rejected(
        &t,
        "materials.von-mises.yield_stress",
        "the model von-mises needs it",
        Some(line_of(&t, "[materials.von-mises]")),
    );
    let t = set(
        &repo_study("manufactured"),
        "model",
        "\"von-mises\"\nyield_stress = 1.0",
    );
    rejected(
        &t,
        "material.model",
        "must be \"linear-elastic\"",
        Some(line_of(&t, "model =")),
    );
}
