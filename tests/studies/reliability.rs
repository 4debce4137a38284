//! The study harness under concurrent writers and kills: two live shards sharing one case
//! store never lose each other's files, a kill while a report is replaced leaves the old or
//! the new report (never neither), and what the binary says when things go wrong.

use igimp::study::atomic_file::host_tag;
use igimp::study::column::records::ColumnResults;
use igimp::study::results::read_results;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

fn study_bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_study"))
}

/// 84 column cases of a few milliseconds each: a shard of them writes `cases/` for a good
/// part of a second, long enough for the other shard to open the store meanwhile.
const MANY: &str = r#"
schema = 1
name = "many"
summary = "many small column cases"
problem = "column"
report_file = "table.md"
load_steps = 8
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
methods = ["igimp", "mpm", "fem-linear"]
weights = [10000.0, 20000.0, 40000.0]
elements = [8, 16, 24, 32]
points_per_cell = [1, 2, 3]
"#;

fn studies_with(dir: &Path, name: &str, text: &str) -> PathBuf {
    let studies = dir.join("studies");
    std::fs::create_dir_all(&studies).unwrap();
    std::fs::write(studies.join(format!("{name}.toml")), text).unwrap();
    studies
}

fn command(studies: &Path, name: &str, out: &Path, extra: &[&str]) -> Command {
    let mut c = study_bin();
    c.arg(name)
        .arg("--studies-dir")
        .arg(studies)
        .arg("--out")
        .arg(out)
        .args(extra)
        .env("RAYON_NUM_THREADS", "1");
    c
}

fn ok(out: Output, what: &str) -> String {
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(out.status.success(), "{what} failed ({:?}):\n{err}", out.status);
    err
}

fn json_files(d: &Path) -> usize {
    std::fs::read_dir(d).map_or(0, |r| {
        r.filter_map(|e| e.ok())
            .filter(|e| e.path().extension().is_some_and(|x| x == "json"))
            .count()
    })
}

/// Shard 1 is started while shard 0 is writing its cases (its first case file is on disk),
/// so that shard 1 opens the store - and cleans up after killed runs - while shard 0 has
/// temporaries in flight; in other rounds both start together. No shard may fail, and the
/// merge must equal an unsharded run. (Before the store told live writers from dead ones,
/// the opening shard deleted the other's temporaries and that shard exited 1 on its rename.)
#[test]
fn live_shards_sharing_a_store_lose_nothing() {
    let tmp = tempfile::tempdir().unwrap();
    let studies = studies_with(tmp.path(), "many", MANY);
    let rounds = 12;
    for round in 0..rounds {
        let out = tmp.path().join(format!("r{round}"));
        let cases = out.join("many/cases");
        let first = command(&studies, "many", &out, &["--shard", "0/2"])
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        if round % 2 == 0 {
            let start = Instant::now();
            while json_files(&cases) == 0 && start.elapsed() < Duration::from_secs(60) {
                std::thread::sleep(Duration::from_micros(200));
            }
        }
        let second = command(&studies, "many", &out, &["--shard", "1/2"])
            .output()
            .unwrap();
        ok(second, &format!("round {round}: shard 1/2"));
        ok(
            first.wait_with_output().unwrap(),
            &format!("round {round}: shard 0/2"),
        );
        assert_eq!(json_files(&cases), 84, "round {round}: cases stored");
    }
    let last = tmp.path().join(format!("r{}", rounds - 1));
    ok(
        command(&studies, "many", &last, &["--merge"]).output().unwrap(),
        "merge",
    );
    let whole = tmp.path().join("whole");
    ok(
        command(&studies, "many", &whole, &[]).output().unwrap(),
        "whole run",
    );
    let a: ColumnResults = read_results(&last.join("many")).unwrap();
    let b: ColumnResults = read_results(&whole.join("many")).unwrap();
    assert_eq!(a.without_timing(), b.without_timing());
}

/// A temporary file of a live writer in `cases/` survives a run opening the store; one of a
/// dead writer of this host is removed.
#[test]
fn opening_the_store_spares_a_live_writers_temporaries() {
    let tmp = tempfile::tempdir().unwrap();
    let studies = studies_with(
        tmp.path(),
        "many",
        &MANY.replace("elements = [8, 16, 24, 32]", "elements = [8]"),
    );
    let cases = tmp.path().join("out/many/cases");
    std::fs::create_dir_all(&cases).unwrap();
    // This test process is alive for the whole run: its temporary must stay.
    let live = cases.join(format!(".x.json.{}-{}-0.tmp", host_tag(), std::process::id()));
    // pid_max is at most 2^22 on Linux, so this writer is dead.
    let dead = cases.join(format!(".y.json.{}-{}-0.tmp", host_tag(), (1u32 << 22) + 5));
    std::fs::write(&live, "in flight").unwrap();
    std::fs::write(&dead, "abandoned").unwrap();
    ok(
        command(&studies, "many", &tmp.path().join("out"), &[])
            .output()
            .unwrap(),
        "run",
    );
    assert!(live.exists(), "a live writer's temporary was deleted");
    if Path::new("/proc/self").exists() {
        assert!(!dead.exists(), "an abandoned temporary was kept");
    }
}

/// The points of every case listed in a column `results.json` exist: the report renders.
fn consistent(dir: &Path) -> ColumnResults {
    let r: ColumnResults = read_results(dir).unwrap();
    for c in &r.cases {
        assert!(
            dir.join("points").join(format!("{}.csv", c.id)).is_file(),
            "{}: no point file",
            c.id
        );
    }
    let csvs = std::fs::read_dir(dir.join("points")).unwrap().count();
    assert_eq!(csvs, r.cases.len(), "stale point files beside results.json");
    r
}

/// A re-run killed at every step of replacing the report (fault injection,
/// `IGIMP_FAULT_REPLACE=n`: the process exits as if killed just before its n-th step), then
/// `--render-only`: the folder renders, and holds the old report (killed before the commit
/// point) or the new one (after it) with exactly its own point files.
#[test]
fn a_kill_while_replacing_a_report_leaves_the_old_or_the_new() {
    let tmp = tempfile::tempdir().unwrap();
    let old_text = MANY.replace("elements = [8, 16, 24, 32]", "elements = [8, 16]");
    let new_text = MANY.replace("elements = [8, 16, 24, 32]", "elements = [24]");
    let mut seen_old = false;
    let mut seen_new = false;
    for step in 0..8 {
        let out = tmp.path().join(format!("k{step}"));
        let studies = studies_with(&out, "many", &old_text);
        ok(command(&studies, "many", &out, &[]).output().unwrap(), "old run");
        let dir = out.join("many");
        let old = consistent(&dir);
        std::fs::write(studies.join("many.toml"), &new_text).unwrap();
        let killed = command(&studies, "many", &out, &[])
            .env("IGIMP_FAULT_REPLACE", step.to_string())
            .output()
            .unwrap();
        let finished = killed.status.success();
        if !finished {
            assert_eq!(
                killed.status.code(),
                Some(137),
                "step {step}: not the injected fault"
            );
        }
        ok(
            command(&studies, "many", &out, &["--render-only"])
                .output()
                .unwrap(),
            "render-only",
        );
        let now = consistent(&dir);
        assert!(dir.join("table.md").is_file());
        let ids = |r: &ColumnResults| r.cases.iter().map(|c| c.id.clone()).collect::<Vec<_>>();
        let is_old = ids(&now) == ids(&old);
        seen_old |= is_old;
        seen_new |= !is_old;
        if finished {
            assert!(!is_old, "step {step}: a finished run left the old report");
            break;
        }
        let dots: Vec<String> = std::fs::read_dir(&dir)
            .unwrap()
            .filter_map(|e| e.ok().map(|e| e.file_name().to_string_lossy().into_owned()))
            .filter(|n| n.starts_with(".incoming") || n.starts_with(".outgoing"))
            .collect();
        assert!(dots.is_empty(), "step {step}: left behind {dots:?}");
    }
    assert!(
        seen_old && seen_new,
        "the faults did not cover both sides of the commit point"
    );
}
