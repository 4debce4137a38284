//! `--resume` and `--merge` never trust a stale case record (issue 45, D4): a hand-edited
//! record, a truncated one and one written by another build are each solved again, and the
//! run says so on stderr with the case id and the reason; `--reuse-other-builds` reuses the
//! records of another build on purpose, never an edited one. Each test drives the `study`
//! binary on three small column cases (a few milliseconds each) into a temporary `--out`.

use igimp::study::column::records::ColumnResults;
use igimp::study::results::read_results;
use igimp::study::store::fnv1a64;
use serde_json::Value;
use std::path::PathBuf;
use std::process::{Command, Output};

// Three small column cases (iGIMP, MPM, quadratic FEM), shared with `usability`.
use crate::usability::TINY;

/// The iGIMP case of `TINY`, whose record the tests tamper with.
const IGIMP: &str = "igimp-w40000-e8-p2-s4";

/// The value D4 planted in a record by hand: far below any solved case's error.
const PLANTED: f64 = 1e-12;

struct Setup {
    _tmp: tempfile::TempDir,
    studies: PathBuf,
    out: PathBuf,
}

impl Setup {
    /// `TINY` solved once into a fresh `--out`.
    fn solved() -> Self {
        let tmp = tempfile::tempdir().unwrap();
        let studies = tmp.path().join("studies");
        std::fs::create_dir_all(&studies).unwrap();
        std::fs::write(studies.join("tiny.toml"), TINY).unwrap();
        let out = tmp.path().join("out");
        let s = Setup {
            _tmp: tmp,
            studies,
            out,
        };
        s.ok(&[]);
        s
    }

    fn run(&self, extra: &[&str]) -> (Output, String) {
        let out = Command::new(env!("CARGO_BIN_EXE_study"))
            .args(["tiny", "--quick", "--studies-dir"])
            .arg(&self.studies)
            .arg("--out")
            .arg(&self.out)
            .args(extra)
            .env("RAYON_NUM_THREADS", "1")
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&out.stderr).into_owned();
        (out, err)
    }

    fn ok(&self, extra: &[&str]) -> String {
        let (out, err) = self.run(extra);
        assert!(out.status.success(), "study tiny {extra:?} failed:\n{err}");
        err
    }

    fn record_file(&self) -> PathBuf {
        self.out.join("tiny/cases").join(format!("{IGIMP}.json"))
    }

    fn record(&self) -> Value {
        serde_json::from_slice(&std::fs::read(self.record_file()).unwrap()).unwrap()
    }

    fn put_record(&self, v: &Value) {
        std::fs::write(self.record_file(), serde_json::to_string(v).unwrap()).unwrap();
    }

    fn results(&self) -> ColumnResults {
        read_results(&self.out.join("tiny")).unwrap()
    }
}

/// The stress error the results give the iGIMP case.
fn stress_error(r: &ColumnResults) -> f64 {
    let c = r.cases.iter().find(|c| c.id == IGIMP).unwrap();
    serde_json::to_value(c).unwrap()["stress_error"].as_f64().unwrap()
}

/// `stress_error` of a stored record set to `value` (the record of a column case is its
/// outcome and its points).
fn plant(record: &mut Value, value: f64) {
    record["record"]["output"][0]["stress_error"] = value.into();
}

/// The case file's text as another build would have written it, with `stress_error` set to
/// `value`: its source digest replaced and its content digest recomputed the way the store
/// computes it (FNV-1a of the file without its `digest` member), so that only the build and
/// the value differ.
fn from_other_build(text: &str, value: f64) -> String {
    let v: Value = serde_json::from_str(text).unwrap();
    let member = format!(",\"digest\":\"{}\"", v["digest"].as_str().unwrap());
    let this = format!("\"source\":\"{}\"", v["build"]["source"].as_str().unwrap());
    assert!(text.contains(&member) && text.contains(&this), "{text}");
    let bare = text
        .replacen(&member, "", 1)
        .replacen(&this, "\"source\":\"0123456789abcdef\"", 1);
    // The outcome comes first in the record, before any point.
    let key = "\"stress_error\":";
    let at = bare.find(key).unwrap() + key.len();
    let end = at + bare[at..].find([',', '}']).unwrap();
    let bare = format!("{}{value:e}{}", &bare[..at], &bare[end..]);
    let digest = format!("{:016x}", fnv1a64(bare.as_bytes()));
    bare.replacen(
        ",\"record\":",
        &format!(",\"digest\":\"{digest}\",\"record\":"),
        1,
    )
}

/// (resumed, total) of the "resumed N of M cases" line.
fn resumed(stderr: &str) -> (usize, usize) {
    let line = stderr
        .lines()
        .find(|l| l.contains(": resumed "))
        .unwrap_or_else(|| panic!("no resume line in:\n{stderr}"));
    let w: Vec<&str> = line.split_whitespace().collect();
    let at = w.iter().position(|w| *w == "resumed").unwrap();
    (w[at + 1].parse().unwrap(), w[at + 3].parse().unwrap())
}

/// The stderr line that names the iGIMP case as not reused, saying `reason`.
fn said(stderr: &str, reason: &str) {
    assert!(
        stderr
            .lines()
            .any(|l| l.contains(IGIMP) && l.contains("not reused") && l.contains(reason)),
        "no line naming {IGIMP} as not reused ({reason}):\n{stderr}"
    );
}

/// D4's hand edit: `stress_error = 1e-12` in the iGIMP record. Before, `--resume` reported
/// it as the case's result (the fitted slope of the issue came from such a record); now the
/// case is solved again and the results equal those of the first run.
#[test]
fn an_edited_record_is_solved_again_and_said() {
    let s = Setup::solved();
    let first = s.results();
    assert!(stress_error(&first) > 1e-4, "{}", stress_error(&first));
    let mut r = s.record();
    plant(&mut r, PLANTED);
    s.put_record(&r);
    let err = s.ok(&["--resume"]);
    said(&err, "edited or corrupt");
    assert_eq!(resumed(&err), (2, 3), "{err}");
    assert_eq!(s.results().without_timing(), first.without_timing());
    // Reusing other builds on purpose does not reuse an edited record either.
    s.put_record(&r);
    let err = s.ok(&["--resume", "--reuse-other-builds"]);
    said(&err, "edited or corrupt");
    assert_eq!(stress_error(&s.results()), stress_error(&first));
}

/// A record cut to half its bytes (a full disk, a copy interrupted) is solved again, and
/// said; before, it was solved again without a word.
#[test]
fn a_truncated_record_is_solved_again_and_said() {
    let s = Setup::solved();
    let first = s.results();
    let bytes = std::fs::read(s.record_file()).unwrap();
    std::fs::write(s.record_file(), &bytes[..bytes.len() / 2]).unwrap();
    let err = s.ok(&["--resume"]);
    said(&err, "truncated or unreadable");
    assert_eq!(resumed(&err), (2, 3), "{err}");
    assert_eq!(s.results().without_timing(), first.without_timing());
}

/// A record of another build (other sources: other solver code) is solved again and said,
/// as is a record written before records carried their build; `--reuse-other-builds` reuses
/// the other build's record on purpose (its planted value then reaches the results, which
/// shows it was read back, not solved). Before, both were reused under the new build.
#[test]
fn a_record_of_another_build_is_solved_again_unless_asked() {
    let s = Setup::solved();
    let first = s.results();
    let text = std::fs::read_to_string(s.record_file()).unwrap();
    let other = from_other_build(&text, PLANTED);
    std::fs::write(s.record_file(), &other).unwrap();
    let err = s.ok(&["--resume"]);
    said(&err, "another build");
    assert_eq!(resumed(&err), (2, 3), "{err}");
    assert_eq!(s.results().without_timing(), first.without_timing());

    std::fs::write(s.record_file(), &other).unwrap();
    let err = s.ok(&["--resume", "--reuse-other-builds"]);
    assert_eq!(resumed(&err), (3, 3), "{err}");
    assert_eq!(stress_error(&s.results()), PLANTED);

    // A record of the layout before builds were recorded: no build, no digest.
    let mut old = s.record();
    plant(&mut old, PLANTED);
    let o = old.as_object_mut().unwrap();
    o.remove("build");
    o.remove("digest");
    s.put_record(&old);
    let err = s.ok(&["--resume"]);
    said(&err, "another build");
    assert_eq!(s.results().without_timing(), first.without_timing());
}

/// `--merge` refuses a shard's record of another build, naming the case and the reason in
/// its error, and takes it with `--reuse-other-builds`; shards of one build merge as before.
#[test]
fn merge_refuses_a_record_of_another_build_unless_asked() {
    let s = Setup::solved();
    let first = s.results();
    std::fs::remove_dir_all(s.out.join("tiny")).unwrap();
    for k in ["0/2", "1/2"] {
        s.ok(&["--shard", k]);
    }
    let text = std::fs::read_to_string(s.record_file()).unwrap();
    let value = stress_error(&first);
    std::fs::write(s.record_file(), from_other_build(&text, value)).unwrap();
    let (out, err) = s.run(&["--merge"]);
    assert!(!out.status.success(), "merged a record of another build:\n{err}");
    assert!(
        err.lines().any(|l| l.contains("not stored by any shard")
            && l.contains(IGIMP)
            && l.contains("another build")),
        "{err}"
    );
    s.ok(&["--merge", "--reuse-other-builds"]);
    assert_eq!(s.results().without_timing(), first.without_timing());
}

/// The flag is named in `--help`.
#[test]
fn help_names_the_reuse_flag() {
    let out = Command::new(env!("CARGO_BIN_EXE_study"))
        .arg("--help")
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("--reuse-other-builds"), "{text}");
}
