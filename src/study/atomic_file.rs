//! Atomic file writes: every output file (results, case records, VTK) is written to a
//! temporary file in the same folder, synced and renamed over the target, so that a run
//! killed at any moment leaves the old file or the new one, never a truncated one.
//!
//! Temporary files name their writer (`.<name>.<host>-<pid>-<n>.tmp`), so that a process
//! cleaning up after a killed run removes only temporaries whose writer is gone
//! ([`is_stale_temp`]): two shards of one study started a moment apart share `cases/`, and
//! one must never delete the other's file between its write and its rename.

use std::io::Write;
use std::path::Path;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{Duration, SystemTime};

/// Age after which a temporary file of a writer this process cannot see (another host of a
/// shared file system, or no `/proc`) counts as abandoned. A temporary lives from its
/// creation to its rename: one write and one `fsync` of a case record or a VTK file, under a
/// second for the largest record the studies write; an hour leaves three orders of magnitude
/// for a slow network file system (reference/README.md item 59).
pub const STALE_TEMP_AGE: Duration = Duration::from_secs(3600);

/// This machine's host name as it appears in temporary file names: `[A-Za-z0-9_]` only (a
/// `-` or `.` would make the name ambiguous to parse), `host` if unknown.
pub fn host_tag() -> &'static str {
    static TAG: std::sync::OnceLock<String> = std::sync::OnceLock::new();
    TAG.get_or_init(|| {
        let raw = std::fs::read_to_string("/proc/sys/kernel/hostname")
            .ok()
            .or_else(|| std::env::var("HOSTNAME").ok())
            .unwrap_or_default();
        let tag: String = raw
            .trim()
            .chars()
            .map(|c| if c.is_ascii_alphanumeric() { c } else { '_' })
            .collect();
        if tag.is_empty() {
            "host".to_string()
        } else {
            tag
        }
    })
}

/// The writer of a temporary file name `.<name>.<host>-<pid>-<n>.tmp`: (host, pid); `None`
/// if the name is not of that form (e.g. written by an older version, `.<name>.<pid>-<n>.tmp`).
pub fn temp_owner(file_name: &str) -> Option<(&str, u32)> {
    let stem = file_name.strip_prefix('.')?.strip_suffix(".tmp")?;
    let tail = stem.rsplit('.').next()?;
    let mut parts = tail.rsplitn(3, '-');
    let (_n, pid, host) = (parts.next()?, parts.next()?, parts.next()?);
    (!host.is_empty()).then_some(())?;
    Some((host, pid.parse().ok()?))
}

/// Whether process `pid` of this host is alive; `None` where that cannot be told (no `/proc`).
fn process_alive(pid: u32) -> Option<bool> {
    let proc = Path::new("/proc");
    proc.join("self")
        .exists()
        .then(|| proc.join(pid.to_string()).exists())
}

/// Whether the temporary file `path` was abandoned by its writer and may be removed: its
/// writer is a process of this host that has exited, or the file is older than
/// [`STALE_TEMP_AGE`] (a writer this process cannot check). A live writer's file is never
/// stale, however old (a pid reused by a live process keeps its file until the age limit).
pub fn is_stale_temp(path: &Path) -> bool {
    let Some(name) = path.file_name().map(|n| n.to_string_lossy().into_owned()) else {
        return false;
    };
    if !(name.starts_with('.') && name.ends_with(".tmp")) {
        return false;
    }
    if let Some((host, pid)) = temp_owner(&name) {
        if host == host_tag() {
            match process_alive(pid) {
                Some(true) => return false,
                Some(false) => return true,
                None => {}
            }
        }
    }
    let age = std::fs::symlink_metadata(path)
        .and_then(|m| m.modified())
        .ok()
        .and_then(|t| SystemTime::now().duration_since(t).ok());
    age.is_some_and(|a| a > STALE_TEMP_AGE)
}

/// Remove the abandoned temporary files ([`is_stale_temp`]) directly in `dir`; returns how
/// many were removed. Another live process's temporaries are left alone.
pub fn remove_stale_temps(dir: &Path) -> std::io::Result<usize> {
    let mut removed = 0;
    for entry in std::fs::read_dir(dir)? {
        let p = entry?.path();
        if is_stale_temp(&p) && std::fs::remove_file(&p).is_ok() {
            removed += 1;
        }
    }
    Ok(removed)
}

/// The temporary name of this process's `n`-th write of `name`.
fn temp_name(name: &str, n: u64) -> String {
    format!(".{name}.{}-{}-{n}.tmp", host_tag(), std::process::id())
}

/// Write `bytes` to `path` atomically: a temporary file `.<name>.<host>-<pid>-<n>.tmp` in the
/// same folder is written and synced, then renamed over `path` (a rename within one file
/// system is atomic on POSIX and replaces the target on Windows).
pub fn write_atomic(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    static COUNTER: AtomicU64 = AtomicU64::new(0);
    let name = path
        .file_name()
        .ok_or_else(|| std::io::Error::other("path has no file name"))?
        .to_string_lossy();
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    let tmp = path.with_file_name(temp_name(&name, n));
    let result = (|| {
        let mut f = std::fs::File::create(&tmp)?;
        f.write_all(bytes)?;
        f.sync_all()?;
        std::fs::rename(&tmp, path)
    })();
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn temp_names_parse_back_to_their_writer() {
        let n = temp_name("case-1.2e3.json", 7);
        assert_eq!(temp_owner(&n), Some((host_tag(), std::process::id())));
        assert_eq!(temp_owner(".a.json.123-4.tmp"), None, "old layout has no host");
        assert_eq!(temp_owner("a.json.h-1-2.tmp"), None);
        assert_eq!(temp_owner(".a.json.h-x-2.tmp"), None);
    }

    /// A live writer's temporary stays, however it is named; a dead writer's of this host
    /// goes; a foreign host's stays until it is older than the age limit.
    #[test]
    fn only_abandoned_temporaries_are_stale() {
        let dir = tempfile::tempdir().unwrap();
        let own = dir.path().join(temp_name("x.json", 0));
        std::fs::write(&own, b"").unwrap();
        assert!(!is_stale_temp(&own));
        let checkable = process_alive(std::process::id()) == Some(true);
        if checkable {
            // pid_max is at most 2^22 on Linux: this pid cannot exist.
            let dead = dir
                .path()
                .join(format!(".x.json.{}-{}-0.tmp", host_tag(), (1u32 << 22) + 1));
            std::fs::write(&dead, b"").unwrap();
            assert!(is_stale_temp(&dead));
        }
        let foreign = dir.path().join(".x.json.otherhost_zz-1-0.tmp");
        std::fs::write(&foreign, b"").unwrap();
        assert!(!is_stale_temp(&foreign), "fresh and not checkable: kept");
        let old = SystemTime::now() - STALE_TEMP_AGE - Duration::from_secs(60);
        std::fs::File::options()
            .write(true)
            .open(&foreign)
            .unwrap()
            .set_modified(old)
            .unwrap();
        assert!(is_stale_temp(&foreign), "older than the age limit: stale");
        assert!(!is_stale_temp(&dir.path().join("x.json")));
        assert_eq!(
            remove_stale_temps(dir.path()).unwrap(),
            1 + usize::from(checkable)
        );
        assert!(own.exists());
    }
}
