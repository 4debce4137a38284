//! Replacing a study's report as a whole: `results.json` and its side files (`points/`,
//! `domains.json`) go from the old run's to the new run's in one step a kill cannot split.
//!
//! Single files are replaced atomically by [`super::store::write_file`], but a report is
//! several: a run killed after removing the old point files and before writing the new
//! `results.json` would leave a results file whose point files are gone. So a run writes its
//! whole report into a staging folder beside the old one, then renames the staging folder to
//! `.incoming` — the commit point: from then on the new report is complete on disk — and
//! moves its entries into place, `results.json` last. Whoever finds an `.incoming` (the next
//! run, or `--render-only`) finishes the moves first ([`recover`]), so a kill at any moment
//! leaves the old report (before the commit point) or the new one (after it), never neither.
//! The moves run under a lock file so that two processes never interleave them.

use super::StudyError;
use crate::study::atomic_file::{host_tag, is_stale_temp};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{Duration, Instant};

/// The committed new report, waiting to be moved into place.
const INCOMING: &str = ".incoming";
/// Prefix of an old side folder moved aside (removed once the new one is in place).
const OUTGOING: &str = ".outgoing-";
const LOCK: &str = ".report.lock";
/// How long a process waits for another's lock before it reports an error. The lock is held
/// for a handful of renames (milliseconds); a minute leaves room for a slow file system.
const LOCK_WAIT: Duration = Duration::from_secs(60);

/// Fault injection for the tests of a kill during replacement: with `IGIMP_FAULT_REPLACE=n`
/// the process exits (status 137, as after SIGKILL) just before its n-th replacement step
/// (0: before the commit point), without unwinding or cleaning up.
fn fault_point(step: &mut u32) {
    if let Some(n) = std::env::var("IGIMP_FAULT_REPLACE")
        .ok()
        .and_then(|v| v.parse::<u32>().ok())
    {
        if *step == n {
            std::process::exit(137);
        }
    }
    *step += 1;
}

fn io(path: &Path, e: impl std::fmt::Display) -> StudyError {
    StudyError::io(path, e)
}

/// The staging folder of a new report of `dir`: write every file of the report into
/// [`Staged::dir`], then [`Staged::commit`].
pub struct Staged {
    dir: PathBuf,
    target: PathBuf,
}

impl Staged {
    /// A fresh staging folder in `dir` (created if missing), named after this process so that
    /// a later run can tell it abandoned ([`is_stale_temp`]).
    pub fn begin(target: &Path) -> Result<Staged, StudyError> {
        static N: AtomicU64 = AtomicU64::new(0);
        std::fs::create_dir_all(target).map_err(|e| io(target, e))?;
        recover(target)?;
        let name = format!(
            ".staging.{}-{}-{}.tmp",
            host_tag(),
            std::process::id(),
            N.fetch_add(1, Ordering::Relaxed)
        );
        let dir = target.join(name);
        if dir.exists() {
            std::fs::remove_dir_all(&dir).map_err(|e| io(&dir, e))?;
        }
        std::fs::create_dir(&dir).map_err(|e| io(&dir, e))?;
        Ok(Staged {
            dir,
            target: target.to_path_buf(),
        })
    }

    /// Where the new report's files go.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// Put the staged report in place of the old one.
    pub fn commit(self) -> Result<(), StudyError> {
        let mut step = 0;
        let _lock = Lock::take(&self.target)?;
        // An earlier commit killed before its moves: finish it first (it is older than ours).
        apply(&self.target, &mut step)?;
        fault_point(&mut step);
        let incoming = self.target.join(INCOMING);
        std::fs::rename(&self.dir, &incoming).map_err(|e| io(&incoming, e))?;
        apply(&self.target, &mut step)
    }
}

impl Drop for Staged {
    /// A staging folder that was not committed (an error while writing the report) is removed.
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.dir);
    }
}

/// Finish a replacement a killed process committed but did not complete, and remove what
/// killed runs left (abandoned staging folders, old side folders moved aside). Cheap when
/// there is nothing to do; every reader of a report calls it first.
pub fn recover(target: &Path) -> Result<(), StudyError> {
    let Ok(entries) = std::fs::read_dir(target) else {
        return Ok(());
    };
    let mut pending = false;
    for e in entries.flatten() {
        let name = e.file_name().to_string_lossy().into_owned();
        if name == INCOMING || name.starts_with(OUTGOING) {
            pending = true;
        } else if name.starts_with(".staging.") && is_stale_temp(&e.path()) {
            let _ = std::fs::remove_dir_all(e.path());
        }
    }
    if pending {
        let _lock = Lock::take(target)?;
        apply(target, &mut 0)?;
    }
    Ok(())
}

/// Move the entries of `<target>/.incoming` into `target` (`results.json` last: it is the
/// file readers open first), then remove the old side folders and `.incoming`. Every step can
/// be repeated after a kill at any point: an entry still in `.incoming` has not been moved,
/// and an old folder moved aside is never moved back.
fn apply(target: &Path, step: &mut u32) -> Result<(), StudyError> {
    let incoming = target.join(INCOMING);
    if incoming.is_dir() {
        let mut names: Vec<String> = std::fs::read_dir(&incoming)
            .map_err(|e| io(&incoming, e))?
            .filter_map(|e| e.ok().map(|e| e.file_name().to_string_lossy().into_owned()))
            .collect();
        names.sort_by_key(|n| (n == "results.json", n.clone()));
        for name in names {
            let (src, dst) = (incoming.join(&name), target.join(&name));
            if src.is_dir() {
                if dst.exists() {
                    let old = target.join(format!("{OUTGOING}{name}"));
                    if old.exists() {
                        std::fs::remove_dir_all(&old).map_err(|e| io(&old, e))?;
                    }
                    fault_point(step);
                    std::fs::rename(&dst, &old).map_err(|e| io(&dst, e))?;
                }
                fault_point(step);
            } else if dst.is_dir() {
                std::fs::remove_dir_all(&dst).map_err(|e| io(&dst, e))?;
            }
            std::fs::rename(&src, &dst).map_err(|e| io(&dst, e))?;
            fault_point(step);
        }
    }
    for e in std::fs::read_dir(target).map_err(|e| io(target, e))?.flatten() {
        if e.file_name().to_string_lossy().starts_with(OUTGOING) {
            std::fs::remove_dir_all(e.path()).map_err(|err| io(&e.path(), err))?;
        }
    }
    if incoming.is_dir() {
        std::fs::remove_dir(&incoming).map_err(|e| io(&incoming, e))?;
    }
    Ok(())
}

/// `<target>/.report.lock`, created exclusively and holding its owner's `host pid`; removed on
/// drop. A lock whose owner is a dead process of this host is taken over.
struct Lock(PathBuf);

impl Lock {
    fn take(target: &Path) -> Result<Lock, StudyError> {
        let path = target.join(LOCK);
        let me = format!("{} {}", host_tag(), std::process::id());
        let start = Instant::now();
        loop {
            match std::fs::OpenOptions::new()
                .write(true)
                .create_new(true)
                .open(&path)
            {
                Ok(mut f) => {
                    use std::io::Write;
                    f.write_all(me.as_bytes()).map_err(|e| io(&path, e))?;
                    return Ok(Lock(path));
                }
                Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => {
                    if lock_abandoned(&path) {
                        let _ = std::fs::remove_file(&path);
                        continue;
                    }
                    if start.elapsed() > LOCK_WAIT {
                        return Err(io(
                            &path,
                            format!(
                                "held by another process for over {} s (remove it if no study is running)",
                                LOCK_WAIT.as_secs()
                            ),
                        ));
                    }
                    std::thread::sleep(Duration::from_millis(20));
                }
                Err(e) => return Err(io(&path, e)),
            }
        }
    }
}

impl Drop for Lock {
    fn drop(&mut self) {
        let _ = std::fs::remove_file(&self.0);
    }
}

/// Whether the lock file's owner (`host pid`) is a dead process of this host.
fn lock_abandoned(path: &Path) -> bool {
    let Ok(text) = std::fs::read_to_string(path) else {
        return false;
    };
    let mut parts = text.split_whitespace();
    let (Some(host), Some(pid)) = (parts.next(), parts.next()) else {
        // Being written this instant (created, not yet filled), or damaged: age decides.
        return std::fs::metadata(path)
            .and_then(|m| m.modified())
            .ok()
            .and_then(|t| t.elapsed().ok())
            .is_some_and(|a| a > crate::study::atomic_file::STALE_TEMP_AGE);
    };
    host == host_tag() && Path::new("/proc/self").exists() && !Path::new("/proc").join(pid).exists()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn report(dir: &Path, tag: &str) {
        std::fs::create_dir_all(dir.join("points")).unwrap();
        std::fs::write(dir.join("points").join(format!("{tag}.csv")), tag).unwrap();
        std::fs::write(dir.join("results.json"), tag).unwrap();
    }

    fn read(dir: &Path) -> (String, Vec<String>) {
        let mut pts: Vec<String> = std::fs::read_dir(dir.join("points"))
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        pts.sort();
        (std::fs::read_to_string(dir.join("results.json")).unwrap(), pts)
    }

    #[test]
    fn commit_replaces_the_whole_report_and_leaves_nothing_behind() {
        let t = tempfile::tempdir().unwrap();
        report(t.path(), "old");
        let s = Staged::begin(t.path()).unwrap();
        report(s.dir(), "new");
        s.commit().unwrap();
        assert_eq!(read(t.path()), ("new".into(), vec!["new.csv".into()]));
        let left: Vec<_> = std::fs::read_dir(t.path())
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .filter(|n| n.starts_with('.'))
            .collect();
        assert!(left.is_empty(), "{left:?}");
    }

    /// A commit interrupted after each of its moves (simulated by doing the moves by hand up
    /// to that point) is finished by `recover`; before the commit point the old report stays.
    #[test]
    fn recover_rolls_an_interrupted_commit_forward() {
        for stage in 0..4 {
            let t = tempfile::tempdir().unwrap();
            report(t.path(), "old");
            let inc = t.path().join(INCOMING);
            report(&inc, "new");
            if stage >= 1 {
                std::fs::rename(t.path().join("points"), t.path().join(".outgoing-points")).unwrap();
            }
            if stage >= 2 {
                std::fs::rename(inc.join("points"), t.path().join("points")).unwrap();
            }
            if stage >= 3 {
                std::fs::rename(inc.join("results.json"), t.path().join("results.json")).unwrap();
            }
            recover(t.path()).unwrap();
            assert_eq!(
                read(t.path()),
                ("new".into(), vec!["new.csv".into()]),
                "stage {stage}"
            );
            assert!(!inc.exists() && !t.path().join(".outgoing-points").exists());
        }
    }

    #[test]
    fn an_uncommitted_staging_folder_changes_nothing() {
        let t = tempfile::tempdir().unwrap();
        report(t.path(), "old");
        {
            let s = Staged::begin(t.path()).unwrap();
            report(s.dir(), "new");
        }
        recover(t.path()).unwrap();
        assert_eq!(read(t.path()), ("old".into(), vec!["old.csv".into()]));
    }
}
