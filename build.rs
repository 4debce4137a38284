//! Records the git commit the library is built from, and whether the sources differ from it,
//! so that every results.json and report names the code that produced it
//! (`study::results::Software`). Outside a git checkout both are "unknown".

use std::path::Path;
use std::process::Command;

fn git(args: &[&str]) -> Option<String> {
    let out = Command::new("git")
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .ok()?;
    out.status
        .success()
        .then(|| String::from_utf8_lossy(&out.stdout).trim().to_string())
}

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    // What a result depends on at build time (study files are read at run time and recorded
    // whole in results.json); a regenerated report must not make its own build dirty.
    const SOURCES: [&str; 4] = ["src", "Cargo.toml", "Cargo.lock", "build.rs"];
    for s in SOURCES {
        println!("cargo:rerun-if-changed={s}");
    }
    let commit = git(&["rev-parse", "HEAD"]);
    if let (Some(dir), Some(common)) = (
        git(&["rev-parse", "--absolute-git-dir"]),
        git(&["rev-parse", "--git-common-dir"]),
    ) {
        let common = Path::new(env!("CARGO_MANIFEST_DIR")).join(common);
        for p in [
            Path::new(&dir).join("HEAD"),
            Path::new(&dir).join("index"),
            common.join("refs"),
            common.join("packed-refs"),
        ] {
            if p.exists() {
                println!("cargo:rerun-if-changed={}", p.display());
            }
        }
    }
    let dirty = commit.as_ref().and_then(|_| {
        let mut args = vec!["status", "--porcelain", "--untracked-files=normal", "--"];
        args.extend(SOURCES);
        git(&args).map(|s| !s.is_empty())
    });
    println!(
        "cargo:rustc-env=IGIMP_GIT_COMMIT={}",
        commit.unwrap_or_else(|| "unknown".into())
    );
    println!(
        "cargo:rustc-env=IGIMP_GIT_DIRTY={}",
        dirty.map_or("unknown", |d| if d { "true" } else { "false" })
    );
}
