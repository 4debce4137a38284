//! Extreme finite values in every numeric key of every committed study file: each is either
//! an error at load naming a key of the file, or a study whose changed cases solve to a
//! recorded result (converged, failed at a step or rejected with a reason) and whose measures
//! and checks are computed; never a panic.
//!
//! Each mutation changes one number of one study file. An accepted mutation is carried
//! through the study as a user would meet it: the cheapest quick-tier case whose inputs it
//! changed is solved, and the kind's measures and checks are evaluated on the committed full
//! results with that case's record in them (a measure that panicked on a derived quantity,
//! e.g. the column's closed form at `length = 1e308`, is caught here). An abort (e.g. an
//! allocation of tens of GB) would end the test binary: that fails too.

use igimp::study::cantilever::CantileverStudy;
use igimp::study::column::ColumnStudy;
use igimp::study::compaction::CompactionStudy;
use igimp::study::dynamics::DynamicStudy;
use igimp::study::element::ElementStudy;
use igimp::study::engine::{self, StudyKind};
use igimp::study::manufactured::ManufacturedStudy;
use igimp::study::results::CaseRecordOf;
use igimp::study::scene::SceneStudy;
use igimp::study::{StudyError, Tier};
use std::collections::BTreeSet;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::Path;
use toml::Value;

const FLOATS: [f64; 5] = [1e300, -1e300, 1e-300, 0.0, 5e-324];
const INTS: [i64; 4] = [-1, 0, 1 << 53, i64::MAX];

/// A key path of a TOML document: table keys and array indices.
#[derive(Debug, Clone)]
enum Seg {
    Key(String),
    Index(usize),
}

fn shown(path: &[Seg]) -> String {
    let mut s = String::new();
    for seg in path {
        match seg {
            Seg::Key(k) if s.is_empty() => s.push_str(k),
            Seg::Key(k) => s.push_str(&format!(".{k}")),
            Seg::Index(i) => s.push_str(&format!("[{i}]")),
        }
    }
    s
}

/// Every numeric leaf below `v` (but the schema version).
fn numeric_paths(v: &Value, prefix: &mut Vec<Seg>, out: &mut Vec<Vec<Seg>>) {
    match v {
        Value::Table(t) => {
            for (k, x) in t {
                if prefix.is_empty() && k == "schema" {
                    continue;
                }
                prefix.push(Seg::Key(k.clone()));
                numeric_paths(x, prefix, out);
                prefix.pop();
            }
        }
        Value::Array(a) => {
            for (i, x) in a.iter().enumerate() {
                prefix.push(Seg::Index(i));
                numeric_paths(x, prefix, out);
                prefix.pop();
            }
        }
        Value::Integer(_) | Value::Float(_) => out.push(prefix.clone()),
        _ => {}
    }
}

fn at<'a>(v: &'a mut Value, path: &[Seg]) -> &'a mut Value {
    path.iter().fold(v, |v, s| match s {
        Seg::Key(k) => &mut v[k.as_str()],
        Seg::Index(i) => &mut v[*i],
    })
}

/// What the probes of one study file found.
#[derive(Default)]
struct Tally {
    rejected: usize,
    accepted: usize,
    solved: usize,
    failures: Vec<String>,
    /// Seconds spent loading, solving and measuring.
    seconds: [f64; 3],
}

/// The cheapest quick-tier case of `study` whose inputs differ from every case of `base`.
fn cheapest_changed<K: StudyKind>(base: &K, study: &K) -> Option<K::Case> {
    let known: BTreeSet<String> = base
        .cases(Tier::Quick)
        .0
        .iter()
        .chain(&base.cases(Tier::Full).0)
        .map(|c| base.key(c).hash)
        .collect();
    study
        .cases(Tier::Quick)
        .0
        .into_iter()
        .filter(|c| !known.contains(&study.key(c).hash))
        .min_by(|a, b| study.cost(a).total_cmp(&study.cost(b)))
}

/// Probe every numeric key of one study file of kind `K` with every extreme value.
fn probe<K: StudyKind>(name: &str, text: &str, tally: &mut Tally) {
    let base = K::parse(text, name).unwrap_or_else(|e| panic!("{name}: {e}"));
    let committed = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("reports")
        .join(base.name());
    let results = engine::read::<K>(&committed).ok();
    let doc: Value = text.parse().unwrap();
    let mut paths = vec![];
    numeric_paths(&doc, &mut vec![], &mut paths);
    for path in &paths {
        let key = shown(path);
        let original = at(&mut doc.clone(), path).clone();
        let values: Vec<Value> = match original {
            Value::Integer(_) => INTS.iter().map(|&i| Value::Integer(i)).collect(),
            _ => FLOATS.iter().map(|&f| Value::Float(f)).collect(),
        };
        for value in values {
            let mut mutated = doc.clone();
            *at(&mut mutated, path) = value.clone();
            let mutated_text = toml::to_string(&mutated).unwrap();
            let what = format!("{name}: `{key}` = {value}");
            let t = std::time::Instant::now();
            let parsed = catch_unwind(AssertUnwindSafe(|| K::parse(&mutated_text, name)));
            tally.seconds[0] += t.elapsed().as_secs_f64();
            let study = match parsed {
                Err(_) => {
                    tally.failures.push(format!("{what}: panicked at load"));
                    continue;
                }
                Ok(Err(e)) => {
                    tally.rejected += 1;
                    check_error_names_a_key(&e, &mutated, &what, tally);
                    continue;
                }
                Ok(Ok(s)) => s,
            };
            tally.accepted += 1;
            let t = std::time::Instant::now();
            let changed = cheapest_changed(&base, &study);
            tally.seconds[0] += t.elapsed().as_secs_f64();
            let t = std::time::Instant::now();
            let record = match changed {
                None => None,
                Some(case) => {
                    tally.solved += 1;
                    match catch_unwind(AssertUnwindSafe(|| study.solve(&case, None))) {
                        Err(_) => {
                            tally
                                .failures
                                .push(format!("{what}: panicked solving {}", study.key(&case).id));
                            continue;
                        }
                        Ok(Err(e)) => {
                            tally.failures.push(format!("{what}: solve error {e}"));
                            continue;
                        }
                        Ok(Ok(o)) => Some(K::record(&o).clone()),
                    }
                }
            };
            tally.seconds[1] += t.elapsed().as_secs_f64();
            let t = std::time::Instant::now();
            let Some(mut r) = results.clone() else { continue };
            r.study = study;
            r.checks.clear();
            if let Some(record) = record {
                match r.cases.iter().position(|c| c.id() == record.id()) {
                    Some(i) => r.cases[i] = record,
                    None => r.cases.push(record),
                }
            }
            if catch_unwind(AssertUnwindSafe(|| K::measure(&mut r))).is_err() {
                tally.failures.push(format!("{what}: panicked measuring"));
            }
            tally.seconds[2] += t.elapsed().as_secs_f64();
        }
    }
}

/// A load error names a key the mutated file has (its path as written, a section of it, or
/// a whole-file key), with its line when it is a value's error.
fn check_error_names_a_key(e: &StudyError, doc: &Value, what: &str, tally: &mut Tally) {
    match e {
        StudyError::Invalid { key, file, .. } => {
            let head: String = key.split(['.', '[']).next().unwrap_or("").to_string();
            if doc.get(&head).is_none() {
                tally.failures.push(format!(
                    "{what}: error names `{key}`, which the file does not have: {e}"
                ));
            } else if !file.contains(':') {
                tally.failures.push(format!("{what}: error has no line: {e}"));
            }
        }
        StudyError::Parse { .. } => {}
        other => tally
            .failures
            .push(format!("{what}: unexpected error kind: {other}")),
    }
}

/// Newton capped for the probes: at most this many iterations a step and no cut-backs, so
/// that a case an extreme value breaks fails in its first steps instead of halving its load
/// six times (the dynamic cantilever took 12 s a probe before); the whole path, assembly,
/// constitutive update, failure record and measures, runs as in a study.
const PROBE_ITERATIONS: i64 = 8;

fn cap_newton(v: &mut Value) {
    if let Value::Table(t) = v {
        for (k, x) in t.iter_mut() {
            if k == "newton" {
                if let Value::Table(n) = x {
                    let cap = n
                        .get("max_iterations")
                        .and_then(|m| m.as_integer())
                        .map(|m| m.min(PROBE_ITERATIONS));
                    if let Some(m) = cap {
                        n.insert("max_iterations".into(), Value::Integer(m));
                    }
                    n.insert("max_cutbacks".into(), Value::Integer(0));
                }
            } else {
                cap_newton(x);
            }
        }
    } else if let Value::Array(a) = v {
        a.iter_mut().for_each(cap_newton);
    }
}

/// Probe every committed study file of `problem` (the study kind's key).
fn probe_kind(problem: &str) {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("studies");
    let mut files: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    files.sort();
    // A panic inside catch_unwind still prints its message; the tally says which input.
    let hook = std::panic::take_hook();
    std::panic::set_hook(Box::new(|_| {}));
    let mut report = vec![];
    let mut failures = vec![];
    for f in &files {
        let name = f.file_name().unwrap().to_string_lossy().into_owned();
        let mut doc: Value = std::fs::read_to_string(f).unwrap().parse().unwrap();
        if doc.get("problem").and_then(|p| p.as_str()) != Some(problem) {
            continue;
        }
        cap_newton(&mut doc);
        let text = toml::to_string(&doc).unwrap();
        let mut tally = Tally::default();
        match problem {
            "column" => probe::<ColumnStudy>(&name, &text, &mut tally),
            "compaction" => probe::<CompactionStudy>(&name, &text, &mut tally),
            "cantilever" => probe::<CantileverStudy>(&name, &text, &mut tally),
            "manufactured" => probe::<ManufacturedStudy>(&name, &text, &mut tally),
            "dynamics" => probe::<DynamicStudy>(&name, &text, &mut tally),
            "scene" => probe::<SceneStudy>(&name, &text, &mut tally),
            "element" => probe::<ElementStudy>(&name, &text, &mut tally),
            other => panic!("{name}: no probe for problem {other:?}"),
        }
        assert!(tally.rejected > 0 && tally.accepted > 0, "{name}: nothing probed");
        report.push(format!(
            "{name}: {} rejected, {} accepted ({} solved); {:.1} s loading, {:.1} s solving, {:.1} s measuring",
            tally.rejected, tally.accepted, tally.solved, tally.seconds[0], tally.seconds[1], tally.seconds[2]
        ));
        failures.extend(tally.failures);
    }
    std::panic::set_hook(hook);
    eprintln!("{}", report.join("\n"));
    assert!(!report.is_empty(), "no study file of problem {problem:?}");
    assert!(
        failures.is_empty(),
        "{} failures:\n{}",
        failures.len(),
        failures.join("\n")
    );
}

#[test]
fn extreme_values_in_column_studies_are_rejected_or_solved_and_measured() {
    probe_kind("column");
}

#[test]
fn extreme_values_in_compaction_studies_are_rejected_or_solved_and_measured() {
    probe_kind("compaction");
}

#[test]
fn extreme_values_in_cantilever_studies_are_rejected_or_solved_and_measured() {
    probe_kind("cantilever");
}

#[test]
fn extreme_values_in_manufactured_studies_are_rejected_or_solved_and_measured() {
    probe_kind("manufactured");
}

#[test]
fn extreme_values_in_dynamics_studies_are_rejected_or_solved_and_measured() {
    probe_kind("dynamics");
}

#[test]
fn extreme_values_in_scene_studies_are_rejected_or_solved_and_measured() {
    probe_kind("scene");
}

#[test]
fn extreme_values_in_element_studies_are_rejected_or_solved_and_measured() {
    probe_kind("element");
}

/// Every `[material]` and `[materials.<name>]` table of every committed study file: an
/// unknown model, and each parameter left out, are rejected at load by an error naming the
/// table's key (`material.model`, `material.poisson_ratio`) with its line, never a panic.
#[test]
fn every_material_table_rejects_an_unknown_model_and_a_missing_parameter() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("studies");
    let tmp = tempfile::tempdir().unwrap();
    let mut probed = 0;
    for e in std::fs::read_dir(&dir).unwrap() {
        let p = e.unwrap().path();
        if p.extension().is_none_or(|x| x != "toml") {
            continue;
        }
        let name = p.file_name().unwrap().to_string_lossy().into_owned();
        let doc: Value = std::fs::read_to_string(&p).unwrap().parse().unwrap();
        // A scene names its materials only (`[materials.<name>]`).
        let mut tables: Vec<(String, Value)> = doc
            .get("material")
            .map(|m| ("material".to_string(), m.clone()))
            .into_iter()
            .collect();
        if let Some(named) = doc.get("materials").and_then(|m| m.as_table()) {
            tables.extend(named.iter().map(|(k, t)| (format!("materials.{k}"), t.clone())));
        }
        for (path, table) in tables {
            let segs: Vec<Seg> = path.split('.').map(|k| Seg::Key(k.to_string())).collect();
            let mut edits: Vec<(String, Value)> = vec![];
            let mut unknown = table.clone();
            unknown["model"] = Value::String("no-such-model".into());
            edits.push((format!("{path}.model"), unknown));
            for key in table.as_table().unwrap().keys().filter(|k| *k != "model") {
                let mut missing = table.clone();
                missing.as_table_mut().unwrap().remove(key);
                edits.push((format!("{path}.{key}"), missing));
            }
            for (key, edited) in edits {
                let mut mutated = doc.clone();
                *at(&mut mutated, &segs) = edited;
                let file = tmp.path().join(&name);
                std::fs::write(&file, toml::to_string(&mutated).unwrap()).unwrap();
                let e = catch_unwind(AssertUnwindSafe(|| igimp::study::kinds::catalogue_entry(&file)))
                    .unwrap_or_else(|_| panic!("{name}: `{key}` edited: panicked"))
                    .expect_err(&format!("{name}: `{key}` edited: accepted"));
                match &e {
                    StudyError::Invalid { key: k, file, .. } => {
                        assert_eq!(k, &key, "{name}: {e}");
                        assert!(file.contains(':'), "{name}: no line: {e}");
                    }
                    other => panic!("{name}: `{key}`: {other}"),
                }
                probed += 1;
            }
        }
    }
    assert!(probed >= 50, "{probed} material edits probed");
}

/// Every committed study file is probed by one of the tests above.
#[test]
fn every_study_kind_has_a_probe() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("studies");
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.extension().is_some_and(|x| x == "toml") {
            let doc: Value = std::fs::read_to_string(&p).unwrap().parse().unwrap();
            let problem = doc.get("problem").and_then(|v| v.as_str()).unwrap_or("");
            assert!(
                [
                    "column",
                    "compaction",
                    "cantilever",
                    "manufactured",
                    "dynamics",
                    "scene",
                    "element"
                ]
                .contains(&problem),
                "{}: no probe for problem {problem:?}",
                p.display()
            );
        }
    }
}
