//! Verification studies as data: a study file (`studies/<name>.toml`) names its problem (the
//! study kind), the sweeps, the solver settings, the expectations with their bands and
//! sources, and the figures to draw.
//!
//! Pipeline (compute → JSON → render): [`engine::run`] solves every case of any
//! [`engine::StudyKind`] (rayon, results in a fixed order, the case store, `--resume`,
//! `--vtk`, `--shard`/`--merge`) and [`engine::write_outputs`] writes the [`results::Envelope`]
//! as `results.json`; [`crate::study::render`] reads only the results files. The kinds: [`column`](mod@column)
//! (§5.1), [`compaction`] (§5.2), [`cantilever`] (§5.3), [`manufactured`] and the
//! [`dynamics`] (the vibrating bar and the dynamic manufactured fields); [`crate::study::kinds`]
//! registers them.
//!
//! Counts in the files are parsed as signed integers so that a negative value is reported by
//! validation with its key and allowed range instead of as a type error.

pub mod atomic_file;
pub mod cantilever;
pub mod checks;
pub mod column;
pub mod compaction;
pub mod dynamics;
pub mod element;
pub mod engine;
pub mod external;
pub mod kinds;
pub mod locate;
pub mod manufactured;
pub mod material;
pub mod methods;
pub mod render;
pub mod replace;
pub mod results;
pub mod scene;
pub mod store;
pub mod vocabulary;
pub mod vtk;
pub mod vtk_output;

use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};
use thiserror::Error;

/// Most cases one run of `study` solves, all its study files together: 10,000 one-step cases
/// already hold 720 MB resident and write a 240 MB results.json (reference/README.md item 58);
/// every committed study together has under 1,000 in its full tier.
pub const MAX_CASES_PER_RUN: usize = 10_000;

/// Version of the study-file layout (the `schema` key).
pub const SCHEMA_VERSION: i64 = 1;

/// A study file could not be read, parsed or validated.
#[derive(Debug, Error)]
pub enum StudyError {
    /// TOML syntax, a misspelt (unknown) key, a missing key or a wrong type: the message from
    /// the parser names the key and the line.
    #[error("{file}: {message}")]
    Parse { file: String, message: String },
    /// A value outside its allowed range.
    #[error("{file}: invalid `{key}` = {value}: {allowed}")]
    Invalid {
        file: String,
        key: String,
        value: String,
        allowed: String,
    },
    /// A problem input made invalid by a study file's values, named as the problem calls it
    /// (`half_width`); [`locate::locate`] turns it into [`StudyError::Invalid`] naming the
    /// file's key (`block.half_width`) and its line.
    #[error("{0}")]
    CaseInput(Box<CaseInput>),
    /// A study folder without `results.json` (nothing to render).
    #[error("{path}: No such file or directory (os error 2): solve the study first")]
    NoResults { study: String, path: String },
    #[error("{path}: {message}")]
    Io { path: String, message: String },
    /// `--shard`: this shard's cases are solved and stored; nothing else is written.
    #[error("shard {k}/{n}: solved and stored {solved} of {total} cases in {dir}; run with --merge once every shard is done")]
    ShardDone {
        k: usize,
        n: usize,
        solved: usize,
        total: usize,
        dir: String,
    },
    /// `--merge` with cases no shard has stored (for these inputs, by this build).
    #[error("{dir}: --merge: {} of {total} cases not stored by any shard (or refused, with the reason): {}{hint}", missing.len(), missing.join(", "))]
    MissingCases {
        dir: String,
        total: usize,
        missing: Vec<String>,
        /// Why they may be missing (e.g. the store holds another tier's cases), or empty.
        hint: String,
    },
}

/// See [`StudyError::CaseInput`].
#[derive(Debug, Error)]
#[error("{file}: invalid `{field}` = {value}: {allowed} (in case {case}, `{scope}`)")]
pub struct CaseInput {
    pub file: String,
    /// The section whose case it is, e.g. `sweeps[0]` or `sweeps[0].quick`.
    pub scope: String,
    pub case: String,
    pub field: String,
    pub value: String,
    pub allowed: String,
}

/// How a run shares its cases between processes (`study --shard K/N`, `study --merge`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Distribution {
    /// Solve (or resume) every case and write the results.
    #[default]
    Whole,
    /// Solve only the cases whose index in the deterministic case order is ≡ k (mod n), store
    /// them in the case store and write nothing else ([`StudyError::ShardDone`]).
    Shard { k: usize, n: usize },
    /// Solve nothing: read every case from the store (the shards'), then fit, check and write
    /// the results as an unsharded run would ([`StudyError::MissingCases`] if one is absent).
    Merge,
}

impl Distribution {
    /// Does this process solve case `index`?
    pub fn owns(&self, index: usize) -> bool {
        match *self {
            Distribution::Shard { k, n } => index % n == k,
            _ => true,
        }
    }

    /// Parse `K/N` with 0 ≤ K < N.
    pub fn parse_shard(text: &str) -> Result<Self, String> {
        let (k, n) = text
            .split_once('/')
            .ok_or_else(|| format!("{text:?}: expected K/N, e.g. 0/4"))?;
        let k: usize = k
            .trim()
            .parse()
            .map_err(|_| format!("{text:?}: K must be an integer"))?;
        let n: usize = n
            .trim()
            .parse()
            .map_err(|_| format!("{text:?}: N must be an integer"))?;
        if n == 0 || k >= n {
            return Err(format!(
                "{text:?}: need 0 <= K < N (K is the 0-based shard index)"
            ));
        }
        Ok(Distribution::Shard { k, n })
    }
}

impl StudyError {
    pub(crate) fn io(path: &Path, err: impl std::fmt::Display) -> Self {
        StudyError::Io {
            path: path.display().to_string(),
            message: err.to_string(),
        }
    }
}

/// Which quick/full tier of a study to run.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Tier {
    /// Every sweep as written.
    Full,
    /// Each sweep with its `quick` overrides (the CI tier).
    Quick,
}

impl Tier {
    pub fn name(self) -> &'static str {
        match self {
            Tier::Full => "full",
            Tier::Quick => "quick",
        }
    }
}

/// The study files (`*.toml`) in a folder, sorted by name.
pub fn study_files(dir: &Path) -> Result<Vec<PathBuf>, StudyError> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(dir)
        .map_err(|e| StudyError::io(dir, e))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    files.sort();
    Ok(files)
}
