//! Crash-safe study outputs: atomic file writes, a stable hash of a case's inputs, and a
//! per-case record store that lets an interrupted sweep resume.
//!
//! Every file a study writes goes through [`write_atomic`] (write a temporary file in the same
//! folder, flush it to disk, rename it over the target), so killing the run at any moment
//! leaves either the old file or the new one, never a truncated one. [`CaseStore`] keeps one
//! JSON file per finished case, `cases/<case-id>.json`, holding beside its record the hash of
//! the case's inputs ([`case_hash`]), the identity of the build that wrote it ([`BuildId`])
//! and a digest of the file's own content. `study --resume` reuses a stored record only when
//! all three match (the build's by choice, `--reuse-other-builds`) and otherwise solves the
//! case again, saying why ([`Refusal`]).
//!
//! The content digest is FNV-1a of the file's bytes without its `,"digest":"…"` member
//! ([`content_digest`]): any byte changed after the store wrote the file refuses it. It
//! catches accidents (a truncated or corrupted file) and hand edits, not an adversary, who
//! can recompute it. It is taken of the bytes as written rather than of a canonical form
//! ([`case_hash`]'s, through a `serde_json::Value` tree) because such a tree of a large record
//! holds several times the record's text at once, on top of the solved case.
//!
//! The store is generic over the record type; [`super::engine`] uses it for every kind.

use super::StudyError;
pub use crate::study::atomic_file::write_atomic;
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
    fnv1a64_from(0xcbf2_9ce4_8422_2325, bytes)
}

/// [`fnv1a64`] of `bytes` continued from the state `h`.
fn fnv1a64_from(mut h: u64, bytes: &[u8]) -> u64 {
    for &b in bytes {
        h ^= u64::from(b);
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    h
}

/// The `digest` member as the store writes it, between `build` and `record`.
fn digest_member(digest: &str) -> String {
    format!(",\"digest\":\"{digest}\"")
}

/// Content digest of a case file's `text`: [`fnv1a64`] of the text without the first
/// `,"digest":"<digest>"` (none if `digest` is `None`), as 16 hex digits; `None` if the text
/// does not hold that member.
pub fn content_digest(text: &[u8], digest: Option<&str>) -> Option<String> {
    let (before, after) = match digest {
        None => (text, &text[text.len()..]),
        Some(d) => {
            let member = digest_member(d);
            let at = text.windows(member.len()).position(|w| w == member.as_bytes())?;
            (&text[..at], &text[at + member.len()..])
        }
    };
    let h = fnv1a64_from(fnv1a64(before), after);
    Some(format!("{h:016x}"))
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

/// The build a record was written by. Records are compared by `source` alone, the digest of
/// the sources, features and target the binary was built from (build.rs): it tells two dirty
/// trees apart, which commit and dirty flag cannot, and survives a commit that changes no
/// source. `commit` and `dirty` are for people reading a refusal.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct BuildId {
    pub source: String,
    pub commit: String,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub dirty: Option<bool>,
}

impl BuildId {
    /// This binary's build.
    pub fn this_build() -> Self {
        // The same build.rs values as `results::Software::this_build`, read here so that the
        // store stays below the results module (tests/verification/layering.rs).
        BuildId {
            source: env!("IGIMP_SOURCE_DIGEST").to_string(),
            commit: env!("IGIMP_GIT_COMMIT").to_string(),
            dirty: env!("IGIMP_GIT_DIRTY").parse().ok(),
        }
    }
}

impl std::fmt::Display for BuildId {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let c = &self.commit;
        write!(f, "sources {}, commit {}", self.source, &c[..c.len().min(12)])?;
        if self.dirty == Some(true) {
            write!(f, " with uncommitted changes")?;
        }
        Ok(())
    }
}

/// Why a stored record is not reused.
#[derive(Debug, Clone, PartialEq)]
pub enum Refusal {
    /// No record of the case (nothing to say: the case was never finished).
    Absent,
    /// Not valid JSON of the store's layout, or not readable at all.
    Unreadable(String),
    /// Content that does not match its digest, or a file holding another case.
    Edited(String),
    /// Written for other inputs (the study file changed).
    OtherInputs,
    /// Written by another build; `None`: by one that recorded no build and no digest (before
    /// records carried them), which cannot be checked and is never reused.
    OtherBuild(Option<BuildId>),
}

impl std::fmt::Display for Refusal {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Refusal::Absent => write!(f, "not stored"),
            Refusal::Unreadable(e) => write!(f, "truncated or unreadable ({e})"),
            Refusal::Edited(e) => write!(f, "edited or corrupt ({e})"),
            Refusal::OtherInputs => write!(f, "written for other inputs (the case's definition changed)"),
            Refusal::OtherBuild(Some(b)) => write!(
                f,
                "written by another build ({b}; this build: {}); --reuse-other-builds reuses it",
                BuildId::this_build()
            ),
            Refusal::OtherBuild(None) => write!(
                f,
                "written by another build, one that recorded neither its identity nor a content \
                 digest, so it cannot be checked (not reused even with --reuse-other-builds)"
            ),
        }
    }
}

/// A case file, written in this field order (the digest member sits before `record`).
#[derive(Serialize, Deserialize)]
struct Stored<T> {
    id: String,
    hash: String,
    /// Absent in records written before builds were recorded.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    build: Option<BuildId>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    digest: Option<String>,
    record: T,
}

/// A case file's members but its record (which is skipped, not held).
#[derive(Deserialize)]
struct Header {
    id: String,
    hash: String,
    #[serde(default)]
    build: Option<BuildId>,
    #[serde(default)]
    digest: Option<String>,
}

/// One JSON file per finished case, `<dir>/<case-id>.json`, holding the hash of the case's
/// inputs, the build that wrote it, its content digest and its record.
#[derive(Debug, Clone)]
pub struct CaseStore {
    dir: PathBuf,
}

impl CaseStore {
    /// The store in `dir` (created if missing); temporary files abandoned by a killed run
    /// are removed, those of another live writer (a concurrent shard) are not
    /// ([`crate::study::atomic_file::is_stale_temp`]).
    pub fn open(dir: &Path) -> Result<Self, StudyError> {
        std::fs::create_dir_all(dir).map_err(|e| StudyError::io(dir, e))?;
        crate::study::atomic_file::remove_stale_temps(dir).map_err(|e| StudyError::io(dir, e))?;
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

    /// The stored record of case `id` if its content matches its digest, it was written for
    /// inputs with hash `hash`, and by this build (or any build, with `other_builds`: the
    /// digest must match all the same); otherwise why not.
    pub fn load<T: DeserializeOwned>(&self, id: &str, hash: &str, other_builds: bool) -> Result<T, Refusal> {
        let path = self.path(id).map_err(|e| Refusal::Unreadable(e.to_string()))?;
        let bytes = match std::fs::read(&path) {
            Ok(b) => b,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Err(Refusal::Absent),
            Err(e) => return Err(Refusal::Unreadable(e.to_string())),
        };
        let header: Header =
            serde_json::from_slice(&bytes).map_err(|e| Refusal::Unreadable(e.to_string()))?;
        if header.digest.is_none() && header.build.is_none() {
            return Err(Refusal::OtherBuild(None));
        }
        let digest = header.digest.as_deref();
        if digest.is_none() || content_digest(&bytes, digest).as_deref() != digest {
            return Err(Refusal::Edited("its content does not match its digest".into()));
        }
        if header.id != id {
            return Err(Refusal::Edited(format!("it holds case {:?}", header.id)));
        }
        if header.hash != hash {
            return Err(Refusal::OtherInputs);
        }
        let this_build = header
            .build
            .as_ref()
            .is_some_and(|b| b.source == BuildId::this_build().source);
        if !this_build && !other_builds {
            return Err(Refusal::OtherBuild(header.build));
        }
        let stored: Stored<T> =
            serde_json::from_slice(&bytes).map_err(|e| Refusal::Unreadable(e.to_string()))?;
        Ok(stored.record)
    }

    /// Store the record of case `id` with its input hash, this build and the content digest,
    /// atomically.
    pub fn save<T: Serialize>(&self, id: &str, hash: &str, record: &T) -> Result<(), StudyError> {
        let path = self.path(id)?;
        let stored = Stored {
            id: id.to_string(),
            hash: hash.to_string(),
            build: Some(BuildId::this_build()),
            digest: None,
            record,
        };
        let mut text = serde_json::to_string(&stored).map_err(|e| StudyError::io(&path, e))?;
        let digest = content_digest(text.as_bytes(), None).unwrap_or_default();
        // The member goes where serde puts a field declared between `build` and `record`; in
        // JSON text `,"record":` cannot occur inside a string, so its first place is the key.
        let at = text.find(",\"record\":").unwrap_or(text.len());
        text.insert_str(at, &digest_member(&digest));
        write_file(&path, text.as_bytes())
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
        assert_eq!(store.load::<Vec<f64>>("c1", "00ff", false), Ok(vec![1.5, 2.5]));
        assert_eq!(
            store.load::<Vec<f64>>("c1", "00fe", false),
            Err(Refusal::OtherInputs)
        );
        assert_eq!(store.load::<Vec<f64>>("c2", "00ff", false), Err(Refusal::Absent));
    }

    /// `c1` stored, its file's text changed by `edit`, written back and loaded.
    fn load_edited(edit: impl Fn(String) -> String, other_builds: bool) -> Result<Vec<f64>, Refusal> {
        let dir = tempfile::tempdir().unwrap();
        let store = CaseStore::open(dir.path()).unwrap();
        store.save("c1", "00ff", &vec![1.5, 2.5]).unwrap();
        let path = store.path("c1").unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        std::fs::write(&path, edit(text)).unwrap();
        store.load::<Vec<f64>>("c1", "00ff", other_builds)
    }

    /// `text` with `from` (which must occur) replaced by `to` and the digest recomputed as
    /// the store computes it.
    fn resealed(text: &str, from: &str, to: &str) -> String {
        assert!(text.contains(from), "{from} not in {text}");
        let old: serde_json::Value = serde_json::from_str(text).unwrap();
        let member = format!(",\"digest\":\"{}\"", old["digest"].as_str().unwrap());
        let bare = text.replacen(&member, "", 1).replacen(from, to, 1);
        let digest = format!("{:016x}", fnv1a64(bare.as_bytes()));
        bare.replacen(
            ",\"record\":",
            &format!(",\"digest\":\"{digest}\",\"record\":"),
            1,
        )
    }

    /// The file as another build writes it: another source digest, the digest recomputed.
    fn other_build(text: String) -> String {
        let this = format!("\"source\":\"{}\"", BuildId::this_build().source);
        resealed(&text, &this, "\"source\":\"0123456789abcdef\"")
    }

    #[test]
    fn an_edited_record_is_refused_even_from_another_build() {
        assert_eq!(load_edited(|t| t, false), Ok(vec![1.5, 2.5]));
        // Resealing alone reproduces the file (the test's digest is the store's).
        assert_eq!(
            load_edited(|t| resealed(&t, "c1", "c1"), false),
            Ok(vec![1.5, 2.5])
        );
        let edit = |t: String| t.replacen("2.5]", "1e-12]", 1);
        assert!(matches!(load_edited(edit, false), Err(Refusal::Edited(_))));
        assert!(matches!(load_edited(edit, true), Err(Refusal::Edited(_))));
        // Any byte: the digest is of the file as written.
        let spaced = |t: String| t.replacen(",", ", ", 1);
        assert!(matches!(load_edited(spaced, false), Err(Refusal::Edited(_))));
        let moved = |t: String| resealed(&t, "\"id\":\"c1\"", "\"id\":\"c0\"");
        assert!(matches!(load_edited(moved, false), Err(Refusal::Edited(e)) if e.contains("c0")));
        // The digest removed, the build kept.
        let bare = |t: String| {
            let v: serde_json::Value = serde_json::from_str(&t).unwrap();
            t.replacen(&digest_member(v["digest"].as_str().unwrap()), "", 1)
        };
        assert!(matches!(load_edited(bare, true), Err(Refusal::Edited(_))));
    }

    #[test]
    fn a_record_of_another_build_is_reused_only_on_request() {
        match load_edited(other_build, false) {
            Err(Refusal::OtherBuild(Some(b))) => assert_eq!(b.source, "0123456789abcdef"),
            r => panic!("{r:?}"),
        }
        assert_eq!(load_edited(other_build, true), Ok(vec![1.5, 2.5]));
        // The layout before builds were recorded: never reused, it cannot be checked.
        let old = |t: String| {
            let mut v: serde_json::Value = serde_json::from_str(&t).unwrap();
            let o = v.as_object_mut().unwrap();
            o.remove("build");
            o.remove("digest");
            serde_json::to_string(&v).unwrap()
        };
        assert_eq!(load_edited(old, false), Err(Refusal::OtherBuild(None)));
        assert_eq!(load_edited(old, true), Err(Refusal::OtherBuild(None)));
    }

    #[test]
    fn a_truncated_record_is_unreadable() {
        let dir = tempfile::tempdir().unwrap();
        let store = CaseStore::open(dir.path()).unwrap();
        store.save("c1", "00ff", &vec![1.5, 2.5]).unwrap();
        let path = store.path("c1").unwrap();
        let bytes = std::fs::read(&path).unwrap();
        for cut in [1, 3, bytes.len() / 2] {
            std::fs::write(&path, &bytes[..bytes.len() - cut]).unwrap();
            let r = store.load::<Vec<f64>>("c1", "00ff", false);
            assert!(matches!(&r, Err(Refusal::Unreadable(_))), "cut {cut}: {r:?}");
        }
        std::fs::write(&path, b"").unwrap();
        let r = store.load::<Vec<f64>>("c1", "00ff", false);
        assert!(matches!(&r, Err(Refusal::Unreadable(_))), "empty: {r:?}");
    }

    /// This build's identity is the 16 hex digits build.rs writes.
    #[test]
    fn this_build_has_a_source_digest() {
        let b = BuildId::this_build();
        assert_eq!(b.source.len(), 16);
        assert!(b.source.bytes().all(|c| c.is_ascii_hexdigit()), "{}", b.source);
    }
}
