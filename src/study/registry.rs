//! The registry of plane-strain study kinds: which kind a study file or a results folder
//! holds (its `problem` key), and the kind's parse, run, render and index functions. Adding a
//! plane-strain study kind is one `plane_kind!` line (its study, run and module) and one
//! entry in [`KINDS`].

use super::plane::{
    check_counts, invalid, problem_of_results, problem_of_study, IndexEntry, PlaneRunOptions, PlaneStudy,
    RunSummary,
};
use super::{cantilever, compaction, StudyError, Tier};
use std::path::{Path, PathBuf};

/// A plane-strain study kind: its study file, how a tier is solved and written, and the
/// folder it renders.
pub trait PlaneKind: PlaneStudy {
    type Run;
    /// The study's `name` (its output folder under `--out`).
    fn study_name(&self) -> &str;
    fn run(
        &self,
        study_file: &str,
        tier: Tier,
        options: &PlaneRunOptions<'_>,
    ) -> Result<Self::Run, StudyError>;
    /// The study's one-line summary (`study list`).
    fn study_summary(&self) -> &str;
    /// Write results.json and the domain file; returns the folder.
    fn write(out: &Path, run: &Self::Run) -> Result<PathBuf, StudyError>;
    fn summary(run: &Self::Run) -> RunSummary;
}

/// Both kinds follow the same module layout: `run_study_with`, `write_outputs`, and a run
/// with `summary()` and `resumed`.
macro_rules! plane_kind {
    ($study:ty, $run:ty, $module:ident) => {
        impl PlaneKind for $study {
            type Run = $run;
            fn study_name(&self) -> &str {
                &self.name
            }
            fn study_summary(&self) -> &str {
                &self.summary
            }
            fn run(
                &self,
                study_file: &str,
                tier: Tier,
                options: &PlaneRunOptions<'_>,
            ) -> Result<Self::Run, StudyError> {
                $module::run_study_with(self, study_file, tier, options)
            }
            fn write(out: &Path, run: &Self::Run) -> Result<PathBuf, StudyError> {
                $module::write_outputs(out, run)
            }
            fn summary(run: &Self::Run) -> RunSummary {
                run.summary().with_resumed(run.resumed)
            }
        }
    };
}

plane_kind!(compaction::CompactionStudy, compaction::CompactionRun, compaction);
plane_kind!(cantilever::CantileverStudy, cantilever::CantileverRun, cantilever);

/// Parse, solve and write one study file: its folder and summary (none with `render_only`).
type RunFn =
    for<'a, 'b> fn(&Request<'a>, PlaneRunOptions<'b>) -> Result<(PathBuf, Option<RunSummary>), StudyError>;
/// (name, summary) of a study file's text, for `study list`.
type CatalogueFn = fn(&str, &str) -> Result<(String, String), StudyError>;

/// One registered kind: its `problem` key and what `study` does with it.
struct Entry {
    problem: &'static str,
    run: RunFn,
    catalogue: CatalogueFn,
    render: fn(&Path) -> Result<Vec<PathBuf>, StudyError>,
    index: fn(&Path) -> Result<IndexEntry, StudyError>,
}

/// Every plane-strain study kind.
const KINDS: &[Entry] = &[
    Entry {
        problem: "compaction",
        run: run_kind::<compaction::CompactionStudy>,
        catalogue: catalogue_of::<compaction::CompactionStudy>,
        render: crate::render::compaction::render,
        index: crate::render::compaction::index_entry,
    },
    Entry {
        problem: "cantilever",
        run: run_kind::<cantilever::CantileverStudy>,
        catalogue: catalogue_of::<cantilever::CantileverStudy>,
        render: crate::render::cantilever::render,
        index: crate::render::cantilever::index_entry,
    },
];

fn kind(problem: &str) -> Option<&'static Entry> {
    KINDS.iter().find(|k| k.problem == problem)
}

/// Is `problem` a plane-strain study kind?
pub fn is_plane_problem(problem: &str) -> bool {
    kind(problem).is_some()
}

fn catalogue_of<K: PlaneKind>(text: &str, shown: &str) -> Result<(String, String), StudyError> {
    K::parse(text, shown).map(|s| (s.study_name().to_string(), s.study_summary().to_string()))
}

/// What `study` asks of one study file.
struct Request<'a> {
    text: &'a str,
    /// The file as shown in errors.
    shown: &'a str,
    /// The file name recorded in results.json.
    file_name: &'a str,
    tier: Tier,
    out: &'a Path,
    render_only: bool,
}

/// Parse, and unless `render_only` solve and write, a study of kind `K`; its folder and
/// summary.
fn run_kind<K: PlaneKind>(
    r: &Request<'_>,
    options: PlaneRunOptions<'_>,
) -> Result<(PathBuf, Option<RunSummary>), StudyError> {
    let spec = K::parse(r.text, r.shown)?;
    let dir = r.out.join(spec.study_name());
    if r.render_only {
        return Ok((dir, None));
    }
    let options = PlaneRunOptions {
        study_dir: Some(dir.clone()),
        ..options
    };
    let run = spec.run(r.file_name, r.tier, &options)?;
    K::write(r.out, &run)?;
    Ok((dir, Some(K::summary(&run))))
}

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
    let request = Request {
        text,
        shown: &shown,
        file_name: &file_name,
        tier,
        out,
        render_only,
    };
    let Some(k) = kind(problem) else {
        let known: Vec<&str> = KINDS.iter().map(|k| k.problem).collect();
        return Err(invalid(
            &shown,
            "problem",
            format!("{problem:?}"),
            format!("must be column or {}", known.join(", ")),
        ));
    };
    let (dir, summary) = (k.run)(&request, options)?;
    let files = render_dir(&dir)?;
    Ok((dir, summary, files))
}

/// Render the tables and figures of a plane-strain study folder from its results.
pub fn render_dir(dir: &Path) -> Result<Vec<PathBuf>, StudyError> {
    match problem_of_results(dir).as_deref().and_then(kind) {
        Some(k) => (k.render)(dir),
        None => Err(StudyError::io(
            &dir.join("results.json"),
            "not a plane-strain study result",
        )),
    }
}

/// The index entry of a plane-strain study folder; `None` for other studies.
pub fn index_entry(dir: &Path) -> Result<Option<IndexEntry>, StudyError> {
    match problem_of_results(dir).as_deref().and_then(kind) {
        Some(k) => (k.index)(dir).map(Some),
        None => Ok(None),
    }
}

/// The (passed, failed, not evaluated) checks of a plane-strain study folder.
pub fn folder_check_counts(dir: &Path) -> Result<(usize, usize, usize), StudyError> {
    Ok(index_entry(dir)?.map_or((0, 0, 0), |e| check_counts(&e.checks)))
}

/// (name, summary) of a plane-strain study file for `study list`; `None` for other studies.
pub fn catalogue_entry(file: &Path) -> Option<Result<(String, String), StudyError>> {
    let text = std::fs::read_to_string(file).ok()?;
    let k = kind(&problem_of_study(&text)?)?;
    Some((k.catalogue)(&text, &file.display().to_string()))
}
