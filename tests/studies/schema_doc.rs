//! The study-file schema of `studies/README.md` held to the parser, so that the page cannot
//! drift from it: every whole study file shown in a `toml` block of that page or of the
//! top-level README is accepted by the `study` binary's parser and validator (and its quick
//! tier runs with every check passing), and every key path a committed `studies/*.toml` uses
//! is documented in the schema table of its kind (a new key without a row fails), and every
//! model of the material registry is in the Materials table with its parameters and units.

use std::path::{Path, PathBuf};
use std::process::Command;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn read(rel: &str) -> String {
    std::fs::read_to_string(root().join(rel)).unwrap_or_else(|e| panic!("{rel}: {e}"))
}

/// The ```toml blocks of `md` that are whole study files (they set `schema` and `problem`),
/// each with the line its fence opens at.
fn study_blocks(md: &str) -> Vec<(usize, String)> {
    let mut blocks = vec![];
    let mut open: Option<(usize, String)> = None;
    for (i, line) in md.lines().enumerate() {
        match open.take() {
            None if line.trim_start().starts_with("```toml") => open = Some((i + 1, String::new())),
            None => {}
            Some(block) if line.trim_start().starts_with("```") => blocks.push(block),
            Some((at, mut text)) => {
                text.push_str(line);
                text.push('\n');
                open = Some((at, text));
            }
        }
    }
    assert!(open.is_none(), "a ```toml block is not closed");
    let whole = |t: &str| {
        let starts = |k: &str| t.lines().any(|l| l.starts_with(&format!("{k} =")));
        starts("schema") && starts("problem")
    };
    blocks.into_iter().filter(|(_, t)| whole(t)).collect()
}

fn study(args: &[&std::ffi::OsStr]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_study"))
        .args(args)
        .env("RAYON_NUM_THREADS", "1")
        .output()
        .unwrap()
}

/// Each whole study file of the documents, written to `dir` as `<name>.toml`: (document and
/// line, name).
fn write_examples(dir: &Path) -> Vec<(String, String)> {
    let mut written = vec![];
    for doc in ["studies/README.md", "README.md"] {
        for (line, text) in study_blocks(&read(doc)) {
            let value: toml::Value =
                toml::from_str(&text).unwrap_or_else(|e| panic!("{doc}:{line}: not TOML: {e}"));
            let name = value
                .get("name")
                .and_then(|n| n.as_str())
                .unwrap_or_else(|| panic!("{doc}:{line}: no `name`"))
                .to_string();
            let file = dir.join(format!("{name}.toml"));
            assert!(!file.exists(), "{doc}:{line}: a second example named {name:?}");
            std::fs::write(&file, text).unwrap();
            written.push((format!("{doc}:{line}"), name));
        }
    }
    written
}

#[test]
fn every_study_file_shown_in_the_readmes_is_accepted_by_the_parser() {
    let tmp = tempfile::tempdir().unwrap();
    let written = write_examples(tmp.path());
    // The schema page has at least one example of its own, and the README its column study.
    for doc in ["studies/README.md", "README.md"] {
        assert!(
            written.iter().any(|(at, _)| at.starts_with(&format!("{doc}:"))),
            "no whole study file in a ```toml block of {doc}"
        );
    }
    // `study list` parses and validates every file of the folder, printing `(invalid)` and
    // the error for a rejected one.
    let out = study(&["list".as_ref(), "--studies-dir".as_ref(), tmp.path().as_os_str()]);
    let listed = String::from_utf8_lossy(&out.stdout).into_owned();
    assert!(out.status.success(), "study list failed:\n{listed}");
    let invalid = listed.lines().filter(|l| l.starts_with("(invalid)")).count();
    assert!(invalid == 0, "rejected examples:\n{listed}");
    for (at, name) in &written {
        assert!(
            listed
                .lines()
                .any(|l| l.split_whitespace().next() == Some(name.as_str())),
            "{at}: {name} not listed:\n{listed}"
        );
    }
}

#[test]
fn the_examples_quick_tiers_run_with_every_check_passing() {
    let tmp = tempfile::tempdir().unwrap();
    let written = write_examples(tmp.path());
    let out_dir = tmp.path().join("out");
    for (at, name) in &written {
        let out = study(&[
            name.as_ref(),
            "--quick".as_ref(),
            "--check".as_ref(),
            "--studies-dir".as_ref(),
            tmp.path().as_os_str(),
            "--out".as_ref(),
            out_dir.as_os_str(),
        ]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(
            out.status.success(),
            "{at}: {name} --quick --check failed:\n{err}"
        );
        assert!(err.contains("0 failed, 0 not evaluated"), "{at}: {name}:\n{err}");
    }
}

/// Every leaf key path of a TOML table: `a.b`, arrays of tables as `sweeps[].x`.
fn key_paths(table: &toml::Table, prefix: &str, out: &mut Vec<String>) {
    for (key, value) in table {
        let path = format!("{prefix}{key}");
        match value {
            toml::Value::Table(t) if t.is_empty() => out.push(path),
            toml::Value::Table(t) => key_paths(t, &format!("{path}."), out),
            toml::Value::Array(items) if !items.is_empty() && items.iter().all(|v| v.is_table()) => {
                for item in items.iter().filter_map(|v| v.as_table()) {
                    key_paths(item, &format!("{path}[]."), out);
                }
            }
            _ => out.push(path),
        }
    }
}

/// The text of the `## ` section of `md` whose heading is `heading`, up to the next one.
fn section<'a>(md: &'a str, heading: &str) -> &'a str {
    let start = md
        .find(&format!("\n{heading}\n"))
        .unwrap_or_else(|| panic!("studies/README.md has no section {heading:?}"));
    let body = &md[start + heading.len() + 2..];
    body.find("\n## ").map_or(body, |end| &body[..end])
}

#[test]
fn every_key_of_the_committed_study_files_is_documented_for_its_kind() {
    let md = read("studies/README.md");
    let common = section(&md, "## Keys of every kind");
    let mut files: Vec<PathBuf> = std::fs::read_dir(root().join("studies"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    files.sort();
    assert!(files.len() >= 15, "only {} study files found", files.len());
    let mut missing = vec![];
    for f in &files {
        let table: toml::Table = toml::from_str(&std::fs::read_to_string(f).unwrap()).unwrap();
        let problem = table["problem"].as_str().unwrap();
        let kind = section(&md, &format!("## `problem = \"{problem}\"`"));
        let mut paths = vec![];
        key_paths(&table, "", &mut paths);
        // A named material's key is documented once, as `materials.<name>.<key>`.
        for p in &mut paths {
            if let Some((_, key)) = p.strip_prefix("materials.").and_then(|r| r.split_once('.')) {
                *p = format!("materials.<name>.{key}");
            }
        }
        paths.sort();
        paths.dedup();
        for p in paths {
            let cell = format!("`{p}`");
            if !kind.contains(&cell) && !common.contains(&cell) {
                let file = f.file_name().unwrap().to_string_lossy().into_owned();
                missing.push(format!("{file}: `{p}` (problem = {problem:?})"));
            }
        }
    }
    assert!(
        missing.is_empty(),
        "keys used by committed study files but not in the schema table of their kind in \
         studies/README.md:\n{}",
        missing.join("\n")
    );
}

/// The Materials table lists every built-in model of the registry with each of its parameters
/// and units, and nothing else, so that the page cannot drift from the code.
#[test]
fn the_materials_table_is_the_registry() {
    let md = read("studies/README.md");
    let table = section(&md, "## Materials");
    let rows: Vec<Vec<String>> = table
        .lines()
        .filter(|l| l.starts_with("| `"))
        .map(|l| {
            l.trim_matches('|')
                .split('|')
                .map(|c| c.trim().to_string())
                .collect()
        })
        .collect();
    let mut expected = vec![];
    for entry in igimp::material::constitutive::registry::BUILT_IN {
        for p in entry.parameters {
            expected.push((
                format!("`{}`", entry.name),
                format!("`{}`", p.name),
                p.unit.to_string(),
            ));
        }
    }
    let documented: Vec<(String, String, String)> = rows
        .iter()
        .map(|r| (r[0].clone(), r[1].clone(), r[2].clone()))
        .collect();
    assert_eq!(
        documented, expected,
        "studies/README.md's Materials table against the registry"
    );
}
