//! Every quick tier's answers against the committed reports (issue 47). A quick tier's cases
//! are full-tier cases (the same ids from the same inputs), so `reports/<study>/results.json`
//! holds the answers the previous commit gave them. A change that moves an answer by more
//! than [`RELATIVE`], or a load step's Newton iterations by more than one, fails here until
//! the reports are regenerated, and the regeneration shows the move in review
//! (reference/README.md item 64).

use serde_json::Value;
use std::path::Path;

/// An answer may move by this much relative to itself, or absolutely below 1: the errors and
/// drifts of exact methods are round-off, and a reordered sum moves them by their own size
/// (the trapezoidal rule's 2.0e-10 energy drift moved to 1.5e-10 when LDLᵀ replaced LU).
const RELATIVE: f64 = 1e-9;
/// Keys that are the solver's diagnostics, not answers: the Newton residuals (their last
/// entry is round-off; their count is checked per step instead), the total of those counts,
/// the sizes of the factorisation chosen, and wall-clock times.
const DIAGNOSTICS: &[&str] = &[
    "residuals",
    "newton_iterations",
    "nonzeros",
    "factor_nonzeros",
    "timing",
    // An external code's case: its own and its process's wall seconds.
    "seconds",
    "process_seconds",
    "phases",
];
/// Words of a failure's reason carry numbers of the failing state; its step is compared.
const TEXT_EXEMPT: &[&str] = &["reason"];
/// Cases whose answers round-off moves beyond [`RELATIVE`]: the cantilever's demonstrations
/// of ill-conditioning (weak nodes left untreated, MPM's cell crossing, the Jacobian domain
/// update that collapses a domain). When LDLᵀ replaced LU their tip displacements moved by
/// up to 7e-7 and a step's Newton count by up to 8 (reference/README.md item 64). Only their
/// status and failing step are compared.
const ROUND_OFF_SENSITIVE: &[(&str, &str)] = &[
    ("cantilever", "stretch-untreated"),
    ("cantilever", "f-diagonal-untreated"),
    ("cantilever", "f-diagonal-jacobian"),
    ("cantilever", "families-mpm-h0.5"),
    ("cantilever", "families-mpm-h0.25"),
];

/// The case records of a results file by id (the checks are the tier's own: a quick tier
/// fits its rates over fewer cases).
fn cases(results: &Value) -> Vec<(String, &Value)> {
    let records = results.get("cases").and_then(Value::as_array);
    records
        .into_iter()
        .flatten()
        .filter_map(|case| Some((case.get("id")?.as_str()?.to_string(), case)))
        .collect()
}

fn compare(a: &Value, b: &Value, path: &str, out: &mut Vec<String>) {
    match (a, b) {
        (Value::Object(x), Value::Object(y)) => {
            for (k, va) in x {
                if k == "steps" {
                    newton_counts(va, y.get(k), path, out);
                }
                if DIAGNOSTICS.contains(&k.as_str()) || TEXT_EXEMPT.contains(&k.as_str()) {
                    continue;
                }
                match y.get(k) {
                    Some(vb) => compare(va, vb, &format!("{path}/{k}"), out),
                    None => out.push(format!("{path}/{k}: missing")),
                }
            }
        }
        (Value::Array(x), Value::Array(y)) if x.len() == y.len() => {
            for (i, (va, vb)) in x.iter().zip(y).enumerate() {
                compare(va, vb, &format!("{path}[{i}]"), out);
            }
        }
        (Value::Number(x), Value::Number(y)) => {
            let (x, y) = (x.as_f64().unwrap(), y.as_f64().unwrap());
            if (x - y).abs() > RELATIVE * x.abs().max(y.abs()).max(1.0) {
                out.push(format!("{path}: {x:e} committed, {y:e} now"));
            }
        }
        _ if a == b => {}
        _ => out.push(format!("{path}: {a} committed, {b} now")),
    }
}

/// Each load step's Newton iterations within one of the committed count.
fn newton_counts(a: &Value, b: Option<&Value>, path: &str, out: &mut Vec<String>) {
    let count = |s: &Value| {
        s.get("residuals")
            .and_then(Value::as_array)
            .map(|r| r.len() as i64)
    };
    let (Some(x), Some(y)) = (a.as_array(), b.and_then(Value::as_array)) else {
        return;
    };
    for (i, (sa, sb)) in x.iter().zip(y).enumerate() {
        if let (Some(na), Some(nb)) = (count(sa), count(sb)) {
            if (na - nb).abs() > 1 {
                out.push(format!(
                    "{path}/steps[{i}]: {} Newton iterations committed, {} now",
                    na - 1,
                    nb - 1
                ));
            }
        }
    }
}

/// The quick tier of every study (`study all --quick`), case by case against the committed
/// full tier: every answer within [`RELATIVE`], every step's Newton count within one.
#[test]
fn quick_tier_answers_match_the_committed_reports() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let tmp = tempfile::tempdir().unwrap();
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_study"))
        .args(["all", "--quick", "--out"])
        .arg(tmp.path())
        .current_dir(root)
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let (mut compared, mut moved) = (0usize, Vec::new());
    let mut studies: Vec<_> = std::fs::read_dir(root.join("reports"))
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .filter(|n| root.join("reports").join(n).join("results.json").is_file())
        .collect();
    studies.sort();
    for name in &studies {
        let read =
            |p: &Path| -> Value { serde_json::from_str(&std::fs::read_to_string(p).unwrap()).unwrap() };
        let committed = read(&root.join("reports").join(name).join("results.json"));
        let quick = tmp.path().join(name).join("results.json");
        assert!(
            quick.is_file(),
            "`study all --quick` wrote no {name}/results.json"
        );
        let quick = read(&quick);
        let committed: std::collections::HashMap<_, _> = cases(&committed).into_iter().collect();
        for (key, case) in cases(&quick) {
            // An external code that could not be installed here (no registry): its cases are
            // skipped with a message, except in CI, which installs it.
            if case["failure"]["reason"]
                .as_str()
                .is_some_and(|r| r.contains("the set-up of adapter"))
            {
                let ci = std::env::var("CI").is_ok_and(|v| v == "true" || v == "1");
                assert!(
                    !ci,
                    "{name}: {key}: an external code could not be set up in CI: {}",
                    case["failure"]["reason"]
                );
                eprintln!("SKIPPED {name}: {key}: {}", case["failure"]["reason"]);
                continue;
            }
            if let Some(c) = committed.get(&key) {
                compared += 1;
                let path = format!("{name}: {key}");
                if ROUND_OFF_SENSITIVE.contains(&(name.as_str(), key.as_str())) {
                    for k in ["status", "failure/step"] {
                        let (a, b) = (c.pointer(&format!("/{k}")), case.pointer(&format!("/{k}")));
                        if a != b {
                            moved.push(format!("{path}/{k}: {a:?} committed, {b:?} now"));
                        }
                    }
                } else {
                    compare(c, case, &path, &mut moved);
                }
            }
        }
    }
    // Most quick cases are full-tier cases: a renamed case or a lost report would show here.
    assert!(
        compared >= 300,
        "only {compared} quick-tier cases found in the committed reports"
    );
    // One line per case: how many of its answers moved, and the first.
    let mut by_case: Vec<(String, usize, String)> = Vec::new();
    for m in &moved {
        let case = m.split('/').next().unwrap_or(m).to_string();
        match by_case.last_mut() {
            Some((c, n, _)) if *c == case => *n += 1,
            _ => by_case.push((case, 1, m.clone())),
        }
    }
    assert!(
        moved.is_empty(),
        "{} answers of {} cases moved from the committed reports (regenerate them if the \
         move is intended, and say why):\n{}",
        moved.len(),
        by_case.len(),
        by_case
            .iter()
            .map(|(_, n, first)| format!("{n:5} moved, first {first}"))
            .collect::<Vec<_>>()
            .join("\n")
    );
}
