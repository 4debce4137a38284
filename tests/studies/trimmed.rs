//! Study files cut to a few of their sweeps, for tests whose subject is the harness (resume,
//! timing fields, determinism) rather than the study's numbers: every sweep not kept is
//! dropped with each table that names it (`sweep = ...` or `refinement = ...`), so the cut
//! file loads and runs like the original on fewer cases.

use std::path::{Path, PathBuf};

/// `studies/<name>.toml` without the sweeps and refinements whose ids are in `drop`, written
/// into `dir` (returned, for `--studies-dir`).
pub fn write(dir: &Path, name: &str, drop: &[&str]) -> PathBuf {
    let from = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("studies")
        .join(format!("{name}.toml"));
    let mut doc: toml::Table = std::fs::read_to_string(&from).unwrap().parse().unwrap();
    let dropped = |t: &toml::Value| {
        ["id", "sweep", "refinement"].iter().any(|k| {
            t.get(k)
                .and_then(|v| v.as_str())
                .is_some_and(|v| drop.contains(&v))
        })
    };
    let mut removed = 0;
    for (key, value) in doc.iter_mut() {
        if let toml::Value::Array(items) = value {
            let before = items.len();
            items.retain(|t| !(t.is_table() && dropped(t)));
            removed += before - items.len();
            assert!(
                key != "sweeps" || !items.is_empty(),
                "{name}: every sweep dropped"
            );
        }
    }
    assert!(removed >= drop.len(), "{name}: some of {drop:?} not found");
    std::fs::create_dir_all(dir).unwrap();
    std::fs::write(dir.join(format!("{name}.toml")), toml::to_string(&doc).unwrap()).unwrap();
    dir.to_path_buf()
}

/// A rerun (of a cut study) against the first run: it ran at least `min_cases` cases, and
/// each case's record and output equal those of the first run's case with the same id.
pub fn assert_rerun_equal<C, O>(
    again: (&[C], &[O]),
    first: (&[C], &[O]),
    min_cases: usize,
    id: impl Fn(&C) -> &str,
) where
    C: PartialEq + std::fmt::Debug,
    O: PartialEq + std::fmt::Debug,
{
    assert!(again.0.len() >= min_cases, "{} cases", again.0.len());
    for (case, output) in again.0.iter().zip(again.1) {
        let at = first
            .0
            .iter()
            .position(|c| id(c) == id(case))
            .unwrap_or_else(|| panic!("{} not in the first run", id(case)));
        assert_eq!(case, &first.0[at], "{}", id(case));
        assert_eq!(output, &first.1[at], "{}", id(case));
    }
}
