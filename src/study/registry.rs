//! The registry of plane-strain study kinds: which kind a study file or a results folder
//! holds (its `problem` key), and the kind's parse, run, render and index functions. Adding a
//! plane-strain study kind is one arm in each function here.

use super::plane::{
    check_counts, invalid, problem_of_results, problem_of_study, IndexEntry, PlaneRunOptions, PlaneStudy,
    RunSummary,
};
use super::{cantilever, compaction, StudyError, Tier};
use std::path::{Path, PathBuf};

/// Solve (unless `render_only`) and render the plane-strain study in `file`, whose text and
/// problem are given, with the case store, `--resume`, `--vtk` and progress of `options`
/// (its `study_dir` is set here: `<out>/<name>`). Returns the study's output folder, its
/// summary and the rendered files.
pub fn run_file(
    file: &Path,
    text: &str,
    problem: &str,
    tier: Tier,
    out: &Path,
    render_only: bool,
    options: PlaneRunOptions<'_>,
) -> Result<(PathBuf, Option<RunSummary>, Vec<PathBuf>), StudyError> {
    let file_name = file.file_name().map_or_else(
        || file.display().to_string(),
        |f| f.to_string_lossy().into_owned(),
    );
    let shown = file.display().to_string();
    let (dir, summary) = match problem {
        "compaction" => {
            let spec = compaction::CompactionStudy::parse(text, &shown)?;
            let dir = out.join(&spec.name);
            let summary = if render_only {
                None
            } else {
                let options = PlaneRunOptions {
                    study_dir: Some(dir.clone()),
                    ..options
                };
                let run = compaction::run_study_with(&spec, &file_name, tier, &options)?;
                compaction::write_outputs(out, &run)?;
                Some(run.summary().with_resumed(run.resumed))
            };
            (dir, summary)
        }
        "cantilever" => {
            let spec = cantilever::CantileverStudy::parse(text, &shown)?;
            let dir = out.join(&spec.name);
            let summary = if render_only {
                None
            } else {
                let options = PlaneRunOptions {
                    study_dir: Some(dir.clone()),
                    ..options
                };
                let run = cantilever::run_study_with(&spec, &file_name, tier, &options)?;
                cantilever::write_outputs(out, &run)?;
                Some(run.summary().with_resumed(run.resumed))
            };
            (dir, summary)
        }
        other => {
            return Err(invalid(
                &shown,
                "problem",
                format!("{other:?}"),
                "must be column, compaction or cantilever",
            ))
        }
    };
    let files = render_dir(&dir)?;
    Ok((dir, summary, files))
}

/// Render the tables and figures of a plane-strain study folder from its results.
pub fn render_dir(dir: &Path) -> Result<Vec<PathBuf>, StudyError> {
    match problem_of_results(dir).as_deref() {
        Some("compaction") => compaction::render(dir),
        Some("cantilever") => cantilever::render(dir),
        _ => Err(StudyError::io(
            &dir.join("results.json"),
            "not a plane-strain study result",
        )),
    }
}

/// The index entry of a plane-strain study folder; `None` for other studies.
pub fn index_entry(dir: &Path) -> Result<Option<IndexEntry>, StudyError> {
    match problem_of_results(dir).as_deref() {
        Some("compaction") => compaction::index_entry(dir).map(Some),
        Some("cantilever") => cantilever::index_entry(dir).map(Some),
        _ => Ok(None),
    }
}

/// The (passed, failed, not evaluated) checks of a plane-strain study folder.
pub fn folder_check_counts(dir: &Path) -> Result<(usize, usize, usize), StudyError> {
    Ok(index_entry(dir)?.map_or((0, 0, 0), |e| check_counts(&e.checks)))
}

/// (name, summary) of a plane-strain study file for `study list`; `None` for other studies.
pub fn catalogue_entry(file: &Path) -> Option<Result<(String, String), StudyError>> {
    let text = std::fs::read_to_string(file).ok()?;
    let shown = file.display().to_string();
    match problem_of_study(&text)?.as_str() {
        "compaction" => Some(compaction::CompactionStudy::parse(&text, &shown).map(|s| (s.name, s.summary))),
        "cantilever" => Some(cantilever::CantileverStudy::parse(&text, &shown).map(|s| (s.name, s.summary))),
        _ => None,
    }
}
