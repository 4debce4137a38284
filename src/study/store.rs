//! Crash-safe study outputs: atomic file writes, a stable hash of a case's inputs, and a
//! per-case record store that lets an interrupted sweep resume.
//!
//! Every file a study writes goes through [`write_atomic`] (write a temporary file in the same
//! folder, flush it to disk, rename it over the target), so killing the run at any moment
//! leaves either the old file or the new one, never a truncated one. [`CaseStore`] keeps one
//! JSON file per finished case, `cases/<case-id>.json`, holding the hash of the case's inputs
//! ([`case_hash`]) beside its record; `study --resume` reuses a stored record when the hash
//! of the case to run matches, and solves the case again otherwise.
//!
//! The store is generic over the record type; [`super::engine`] uses it for every kind.

use super::StudyError;
pub use crate::atomic_file::write_atomic;
use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};
use std::path::{Component, Path, PathBuf};

/// [`write_atomic`] with the error as a [`StudyError`] naming the file.
pub fn write_file(path: &Path, bytes: &[u8]) -> Result<(), StudyError> {
    write_atomic(path, bytes).map_err(|e| StudyError::io(path, e))
}

/// 64-bit FNV-1a of `bytes`: stable across platforms, Rust versions and runs (unlike
/// `std::collections::hash_map::DefaultHasher`, whose algorithm is unspecified).
pub fn fnv1a64(bytes: &[u8]) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for &b in bytes {
        h ^= u64::from(b);
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    h
}

/// Hash of a case definition: FNV-1a of its canonical JSON (object keys sorted, floats in
/// serde_json's shortest round-trip form), as 16 hex digits. Two definitions hash equally iff
/// their canonical JSON is equal, up to 64-bit collisions.
pub fn case_hash<T: Serialize>(definition: &T) -> String {
    // `serde_json::Value`'s map is a BTreeMap (no `preserve_order` feature), so converting
    // through it sorts the keys of every object.
    let canonical = serde_json::to_value(definition)
        .and_then(|v| serde_json::to_string(&v))
        .unwrap_or_default();
    format!("{:016x}", fnv1a64(canonical.as_bytes()))
}

/// `dir/name` if `name` is a single plain file-name component (no `..`, `/`, root or drive,
/// not empty, no leading `.`); an error otherwise. Keeps every output inside its folder even if
/// an id were built from unchecked input.
pub fn confined(dir: &Path, name: &str) -> Result<PathBuf, StudyError> {
    let p = Path::new(name);
    let mut parts = p.components();
    let ok = matches!((parts.next(), parts.next()), (Some(Component::Normal(_)), None))
        && !name.starts_with('.')
        && !name.contains(['/', '\\', '\0']);
    if ok {
        Ok(dir.join(name))
    } else {
        Err(StudyError::io(
            &dir.join(name),
            "output name must be a plain file name inside the output folder",
        ))
    }
}

#[derive(Serialize, Deserialize)]
struct Stored<T> {
    id: String,
    hash: String,
    record: T,
}

/// One JSON file per finished case, `<dir>/<case-id>.json`, holding the hash of the case's
/// inputs and its record.
#[derive(Debug, Clone)]
pub struct CaseStore {
    dir: PathBuf,
}

impl CaseStore {
    /// The store in `dir` (created if missing); temporary files abandoned by a killed run
    /// are removed, those of another live writer (a concurrent shard) are not
    /// ([`crate::atomic_file::is_stale_temp`]).
    pub fn open(dir: &Path) -> Result<Self, StudyError> {
        std::fs::create_dir_all(dir).map_err(|e| StudyError::io(dir, e))?;
        crate::atomic_file::remove_stale_temps(dir).map_err(|e| StudyError::io(dir, e))?;
        Ok(Self {
            dir: dir.to_path_buf(),
        })
    }

    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// File of case `id`.
    pub fn path(&self, id: &str) -> Result<PathBuf, StudyError> {
        confined(&self.dir, &format!("{id}.json"))
    }

    /// The stored record of case `id` if it was written for inputs with hash `hash`; `None`
    /// if absent, unreadable, for other inputs, or of another layout.
    pub fn load<T: DeserializeOwned>(&self, id: &str, hash: &str) -> Option<T> {
        let text = std::fs::read_to_string(self.path(id).ok()?).ok()?;
        let stored: Stored<T> = serde_json::from_str(&text).ok()?;
        (stored.id == id && stored.hash == hash).then_some(stored.record)
    }

    /// Store the record of case `id` with its input hash, atomically.
    pub fn save<T: Serialize>(&self, id: &str, hash: &str, record: &T) -> Result<(), StudyError> {
        let path = self.path(id)?;
        let stored = Stored {
            id: id.to_string(),
            hash: hash.to_string(),
            record,
        };
        let json = serde_json::to_string(&stored).map_err(|e| StudyError::io(&path, e))?;
        write_file(&path, json.as_bytes())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// FNV-1a test vectors from the reference implementation (Fowler, Noll, Vo).
    #[test]
    fn fnv1a64_matches_reference_vectors() {
        assert_eq!(fnv1a64(b""), 0xcbf29ce484222325);
        assert_eq!(fnv1a64(b"a"), 0xaf63dc4c8601ec8c);
        assert_eq!(fnv1a64(b"foobar"), 0x85944171f73967e8);
    }

    #[test]
    fn case_hash_ignores_key_order_and_sees_every_value() {
        let a = serde_json::json!({"x": 1.0, "y": [1, 2]});
        let b: serde_json::Value = serde_json::from_str(r#"{"y": [1, 2], "x": 1.0}"#).unwrap();
        assert_eq!(case_hash(&a), case_hash(&b));
        assert_ne!(
            case_hash(&a),
            case_hash(&serde_json::json!({"x": 1.0, "y": [1, 3]}))
        );
    }

    #[test]
    fn confined_rejects_traversal() {
        let d = Path::new("out");
        assert!(confined(d, "case-1.json").is_ok());
        for bad in ["", ".", "..", "../x", "a/b", "/etc/passwd", ".hidden", "a\\b"] {
            assert!(confined(d, bad).is_err(), "{bad:?} accepted");
        }
    }

    #[test]
    fn store_round_trip_and_hash_mismatch() {
        let dir = tempfile::tempdir().unwrap();
        let store = CaseStore::open(dir.path()).unwrap();
        store.save("c1", "00ff", &vec![1.5, 2.5]).unwrap();
        assert_eq!(store.load::<Vec<f64>>("c1", "00ff"), Some(vec![1.5, 2.5]));
        assert_eq!(store.load::<Vec<f64>>("c1", "00fe"), None);
        assert_eq!(store.load::<Vec<f64>>("c2", "00ff"), None);
    }
}
