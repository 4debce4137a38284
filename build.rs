//! Records the git commit the library is built from, and whether the sources differ from it,
//! so that every results.json and report names the code that produced it
//! (`study::results::Software`). Outside a git checkout both are "unknown".
//!
//! Also a digest of the sources themselves (`IGIMP_SOURCE_DIGEST`), the build identity a
//! stored case record must match to be resumed (`study::store::BuildId`): unlike the commit
//! it tells two dirty trees apart, and it stays the same across a commit that touches only
//! documentation, tests or study files (these are inputs hashed per case at run time).

use std::path::{Path, PathBuf};
use std::process::Command;

/// 64-bit FNV-1a continued from `h` (the function of `study::store::fnv1a64`; a build script
/// cannot call the crate it builds).
fn fnv1a64(mut h: u64, bytes: &[u8]) -> u64 {
    for &b in bytes {
        h ^= u64::from(b);
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    h
}

/// Every file under `path` (or `path` itself), skipping names that start with `.`: editor
/// swap and backup files are not compiled and must not change the identity while open.
fn files(path: &Path, out: &mut Vec<PathBuf>) {
    if path.is_dir() {
        let entries = std::fs::read_dir(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        for entry in entries {
            let p = entry.unwrap_or_else(|e| panic!("{}: {e}", path.display())).path();
            if !p
                .file_name()
                .is_some_and(|n| n.to_string_lossy().starts_with('.'))
            {
                files(&p, out);
            }
        }
    } else if path.is_file() {
        out.push(path.to_path_buf());
    }
}

/// FNV-1a of `sources` (relative to `root`) in sorted path order, each as its path with `/`
/// separators, its length and its bytes, then of the enabled features and the target: the
/// same sources built alike give the same digest on any machine and in any checkout folder.
fn source_digest(root: &Path, sources: &[&str]) -> String {
    let mut all = vec![];
    for s in sources {
        files(&root.join(s), &mut all);
    }
    let mut named: Vec<(String, PathBuf)> = all
        .into_iter()
        .map(|p| {
            let rel = p.strip_prefix(root).unwrap_or(&p);
            let name: Vec<String> = rel
                .components()
                .map(|c| c.as_os_str().to_string_lossy().into_owned())
                .collect();
            (name.join("/"), p)
        })
        .collect();
    named.sort();
    let mut h = 0xcbf2_9ce4_8422_2325;
    for (name, path) in &named {
        let bytes = std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        h = fnv1a64(h, name.as_bytes());
        h = fnv1a64(h, &[0]);
        h = fnv1a64(h, &(bytes.len() as u64).to_le_bytes());
        h = fnv1a64(h, &bytes);
    }
    // Features select code (`seeded-bugs`); the target selects code and the platform's libm.
    let mut features: Vec<String> = std::env::vars()
        .filter_map(|(k, _)| k.strip_prefix("CARGO_FEATURE_").map(str::to_string))
        .collect();
    features.sort();
    let build = format!(
        "features={};target={}",
        features.join(","),
        std::env::var("TARGET").unwrap_or_default()
    );
    h = fnv1a64(h, build.as_bytes());
    format!("{h:016x}")
}

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
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    println!(
        "cargo:rustc-env=IGIMP_SOURCE_DIGEST={}",
        source_digest(root, &SOURCES)
    );
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
