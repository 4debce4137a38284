//! Every example runs, as `cargo run --release --example <name>` would, and prints what its
//! doc says (`cargo test` builds the examples beside the test binaries; `custom_basis` is also
//! compiled into this binary and checked by `families`).

use std::path::PathBuf;
use std::process::Command;

/// `target/<profile>/examples/<name>`, beside this test binary's `deps/`.
fn example(name: &str) -> PathBuf {
    let exe = std::env::current_exe().unwrap();
    let profile = exe.parent().and_then(|d| d.parent()).unwrap();
    profile.join("examples").join(name)
}

/// Run example `name` with `args`: it exits 0 and its output contains every one of `says`.
fn runs(name: &str, args: &[&str], says: &[&str]) {
    let path = example(name);
    assert!(
        path.exists(),
        "{} not built: the whole `cargo test` builds the examples (or `cargo build --release --examples`)",
        path.display()
    );
    let out = Command::new(&path)
        .args(args)
        .env("RAYON_NUM_THREADS", "1")
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout).into_owned() + &String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{name} {args:?} failed:\n{text}");
    for s in says {
        assert!(text.contains(s), "{name} {args:?} does not say {s:?}:\n{text}");
    }
}

#[test]
fn the_column_example_converges_at_every_size() {
    runs("column", &[], &["elements 256", "failure None"]);
}

#[test]
fn the_cantilever_example_reaches_the_last_step() {
    runs("cantilever", &[], &["final step 50", "failure: None"]);
}

#[test]
fn the_compaction_example_prints_every_steps_residuals() {
    runs("compaction", &[], &["step 20:"]);
}

#[test]
fn the_stabilisation_probe_runs_both_problems_and_explains_its_usage() {
    runs("stabilisation", &["compaction", "1", "2", "ghost:0.1"], &[]);
    runs("stabilisation", &["cantilever", "ghost:0.01"], &[]);
    let out = Command::new(example("stabilisation")).output().unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("usage: stabilisation"));
}
