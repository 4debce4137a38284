//! The registry of study kinds: which kind a study file or a results folder holds (its
//! `problem` key) and the kind's solve, render and index functions. It sits above
//! [`crate::study`] and [`crate::study::render`], which do not know it. Adding a kind is its problem
//! (`src/problems/<x>.rs`), its study kind (`src/study/<x>/`), its render file
//! (`src/study/render/<x>.rs`) and one line in [`KINDS`].

use crate::study::cantilever::CantileverStudy;
use crate::study::column::ColumnStudy;
use crate::study::compaction::CompactionStudy;
use crate::study::dynamics::DynamicStudy;
use crate::study::element::ElementStudy;
use crate::study::engine::{self, RunOptions, StudyKind};
use crate::study::manufactured::ManufacturedStudy;
use crate::study::render::{self, IndexEntry, Rendered};
use crate::study::results::{problem_of_results, problem_of_study, RunSummary};
use crate::study::scene::SceneStudy;
use crate::study::{StudyError, Tier};
use std::path::{Path, PathBuf};

/// Every study kind.
pub const KINDS: &[Kind] = &[
    Kind::of::<ColumnStudy>(render::column::render, render::column::index_entry),
    Kind::of::<CompactionStudy>(render::compaction::render, render::compaction::index_entry),
    Kind::of::<CantileverStudy>(render::cantilever::render, render::cantilever::index_entry),
    Kind::of::<ManufacturedStudy>(render::manufactured::render, render::manufactured::index_entry),
    Kind::of::<DynamicStudy>(render::dynamics::render, render::dynamics::index_entry),
    Kind::of::<SceneStudy>(render::scene::render, render::scene::index_entry),
    Kind::of::<ElementStudy>(render::element::render, render::element::index_entry),
];

/// What `study` asks of one study file.
pub struct Request<'a> {
    pub text: &'a str,
    /// The file as shown in errors.
    pub shown: &'a str,
    /// The file name recorded in results.json.
    pub file_name: &'a str,
    pub tier: Tier,
    pub out: &'a Path,
    pub render_only: bool,
}

/// Parse, solve (unless `render_only`) and write a study file: its folder and summary.
type RunFn =
    for<'a, 'b> fn(&Request<'a>, RunOptions<'b>) -> Result<(PathBuf, Option<RunSummary>), StudyError>;

/// (name, summary) of a study file's text (and the file as shown), for `study list`, and its
/// number of cases in the full and the quick tier.
type CatalogueFn = fn(&str, &str) -> Result<Entry, StudyError>;

/// A valid study file's name, summary and cases per tier.
struct Entry {
    name: String,
    summary: String,
    full: usize,
    quick: usize,
}

/// One registered kind: its `problem` key and what `study` does with it.
pub struct Kind {
    pub problem: &'static str,
    run: RunFn,
    catalogue: CatalogueFn,
    render: fn(&Path) -> Result<Rendered, StudyError>,
    index: fn(&Path) -> Result<IndexEntry, StudyError>,
}

impl Kind {
    const fn of<K: StudyKind>(
        render: fn(&Path) -> Result<Rendered, StudyError>,
        index: fn(&Path) -> Result<IndexEntry, StudyError>,
    ) -> Kind {
        Kind {
            problem: K::PROBLEM,
            run: run_kind::<K>,
            catalogue: catalogue_of::<K>,
            render,
            index,
        }
    }
}

fn catalogue_of<K: StudyKind>(text: &str, shown: &str) -> Result<Entry, StudyError> {
    K::parse(text, shown).map(|s| Entry {
        name: s.name().to_string(),
        summary: s.summary().to_string(),
        full: s.cases(Tier::Full).0.len(),
        quick: s.cases(Tier::Quick).0.len(),
    })
}

fn run_kind<K: StudyKind>(
    r: &Request<'_>,
    options: RunOptions<'_>,
) -> Result<(PathBuf, Option<RunSummary>), StudyError> {
    let study = K::parse(r.text, r.shown)?;
    let dir = r.out.join(study.name());
    if r.render_only {
        // --render-only draws what results.json holds; asked for the quick tier, it must hold it.
        let held = crate::study::results::read_json::<serde_json::Value>(&dir.join("results.json"))
            .ok()
            .and_then(|v| v.get("tier")?.as_str().map(str::to_string));
        if r.tier == Tier::Quick && held.as_deref().is_some_and(|t| t != "quick") {
            return Err(StudyError::Invalid {
                file: dir.join("results.json").display().to_string(),
                key: "tier".into(),
                value: format!("{:?}", held.unwrap_or_default()),
                allowed: "must be \"quick\" for --render-only --quick: --render-only redraws what results.json holds (drop --quick, or run the quick tier first)".into(),
            });
        }
        return Ok((dir, None));
    }
    let options = RunOptions {
        study_dir: Some(dir.clone()),
        ..options
    };
    let vtk = options.vtk.is_some();
    let run = engine::run(&study, r.file_name, r.tier, &options)?;
    engine::write_outputs(r.out, &run)?;
    // ParaView files belong to the run that wrote them: a run without --vtk removes an older
    // run's, which would otherwise sit beside results they do not show.
    let old_vtk = dir.join("vtk");
    if !vtk && old_vtk.is_dir() {
        std::fs::remove_dir_all(&old_vtk).map_err(|e| StudyError::io(&old_vtk, e))?;
        eprintln!(
            "{}: removed {} of an earlier run (this run wrote no ParaView files; add --vtk for them)",
            study.name(),
            old_vtk.display()
        );
    }
    Ok((dir, Some(run.results.summary(run.resumed))))
}

/// Problem keys of results written before a kind was renamed, and the kind's key now: the
/// dynamics kind was "bar" while the vibrating bar was its only problem, so that such a
/// results folder still renders (a study file must name the kind's key).
const RENAMED: &[(&str, &str)] = &[("bar", "dynamics")];

/// The kind of `problem`, or an error naming the study file's `problem` key and the kinds.
pub fn kind(problem: &str, shown: &str) -> Result<&'static Kind, StudyError> {
    let problem = RENAMED
        .iter()
        .find(|(old, _)| *old == problem)
        .map_or(problem, |(_, new)| new);
    KINDS.iter().find(|k| k.problem == problem).ok_or_else(|| {
        let known: Vec<&str> = KINDS.iter().map(|k| k.problem).collect();
        StudyError::Invalid {
            file: shown.to_string(),
            key: "problem".into(),
            value: format!("{problem:?}"),
            allowed: format!("must be one of {}", known.join(", ")),
        }
    })
}

/// Solve (unless `render_only`) and render the study in `file`, with the case store,
/// `--resume`, `--vtk`, `--shard`/`--merge` and progress of `options` (its `study_dir` is set
/// here: `<out>/<name>`). Returns the study's output folder, its summary (none with
/// `render_only`) and the rendered files.
pub fn run_file(
    file: &Path,
    tier: Tier,
    out: &Path,
    render_only: bool,
    options: RunOptions<'_>,
) -> Result<(PathBuf, Option<RunSummary>, Rendered), StudyError> {
    let text = std::fs::read_to_string(file).map_err(|e| StudyError::io(file, e))?;
    let shown = file.display().to_string();
    let k = kind_of_study(&text, &shown)?;
    let file_name = file.file_name().map_or_else(
        || file.display().to_string(),
        |f| f.to_string_lossy().into_owned(),
    );
    let request = Request {
        text: &text,
        shown: &shown,
        file_name: &file_name,
        tier,
        out,
        render_only,
    };
    let (dir, summary) = (k.run)(&request, options)?;
    let files = render_dir(&dir)?;
    Ok((dir, summary, files))
}

/// The kind of a study file's text: a TOML syntax error as the parser reports it, else its
/// `problem` key's kind.
fn kind_of_study(text: &str, shown: &str) -> Result<&'static Kind, StudyError> {
    let problem = problem_of_study(text).unwrap_or_default();
    kind(&problem, shown).map_err(|e| {
        match crate::study::vocabulary::parse_toml::<toml::Value>(text, shown) {
            Err(parse) => parse,
            Ok(_) => e,
        }
    })
}

fn kind_of_results(dir: &Path) -> Result<&'static Kind, StudyError> {
    // A replacement a killed run committed is finished before anything is read.
    crate::study::replace::recover(dir)?;
    let shown = dir.join("results.json").display().to_string();
    kind(&problem_of_results(dir)?, &shown)
}

/// Render the tables and figures of a study folder from its results (and say which figures
/// had nothing to draw).
pub fn render_dir(dir: &Path) -> Result<Rendered, StudyError> {
    (kind_of_results(dir)?.render)(dir)
}

/// The index entry of a study folder.
pub fn index_entry(dir: &Path) -> Result<IndexEntry, StudyError> {
    (kind_of_results(dir)?.index)(dir)
}

/// Write `<out>/index.md` linking the reports and figures of every study folder in `out`
/// that holds a `results.json`.
pub fn render_index(out: &Path) -> Result<PathBuf, StudyError> {
    let dirs = study_dirs(out)?;
    let entries = dirs
        .iter()
        .map(|d| index_entry(d))
        .collect::<Result<Vec<_>, _>>()?;
    let mut page = render::index_page(&entries);
    if out.join(METHODS_DIR).join(render::methods::REPORT).is_file() {
        page.push_str(&format!(
            "## methods\n\nEvery method side by side, gathered from the studies above: [report]({METHODS_DIR}/{}).\n\n",
            render::methods::REPORT
        ));
    }
    let p = out.join("index.md");
    crate::study::store::write_file(&p, page.as_bytes())?;
    Ok(p)
}

/// The folder of `out` the cross-method report is written to.
pub const METHODS_DIR: &str = "methods";

/// The study folders of `out` (those holding a `results.json`), sorted.
fn study_dirs(out: &Path) -> Result<Vec<PathBuf>, StudyError> {
    let mut dirs: Vec<PathBuf> = std::fs::read_dir(out)
        .map_err(|e| StudyError::io(out, e))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.join("results.json").is_file())
        .collect();
    dirs.sort();
    Ok(dirs)
}

/// Gather every study of `out` into `<out>/methods/methods.json` and render the cross-method
/// report from it ([`crate::study::methods`]); nothing (`None`) when no study in `out` has
/// rates or reference comparisons.
pub fn render_methods(out: &Path) -> Result<Option<Rendered>, StudyError> {
    let mut studies = vec![];
    for d in study_dirs(out)? {
        let v: serde_json::Value = crate::study::results::read_json(&d.join("results.json"))?;
        let name = d
            .file_name()
            .map_or_else(String::new, |n| n.to_string_lossy().into_owned());
        studies.push((name, v));
    }
    let gathered = crate::study::methods::collect(&studies);
    if gathered.rates.is_empty() && gathered.references.is_empty() {
        return Ok(None);
    }
    let dir = out.join(METHODS_DIR);
    std::fs::create_dir_all(&dir).map_err(|e| StudyError::io(&dir, e))?;
    let text = serde_json::to_string_pretty(&gathered).map_err(|e| StudyError::Io {
        path: dir.join(render::methods::RESULTS).display().to_string(),
        message: e.to_string(),
    })?;
    crate::study::store::write_file(&dir.join(render::methods::RESULTS), text.as_bytes())?;
    render::methods::render(&dir).map(Some)
}

/// (name, summary) of a study file for `study list`.
pub fn catalogue_entry(file: &Path) -> Result<(String, String), StudyError> {
    entry(file).map(|e| (e.name, e.summary))
}

fn entry(file: &Path) -> Result<Entry, StudyError> {
    let text = std::fs::read_to_string(file).map_err(|e| StudyError::io(file, e))?;
    let shown = file.display().to_string();
    let k = kind_of_study(&text, &shown)?;
    (k.catalogue)(&text, &shown)
}

/// Parse and validate every study file of a run, and reject two files with one `name` (they
/// would write the same output folder): every error, or `Ok` if all are valid.
pub fn validate_files(files: &[PathBuf], tier: Tier) -> Result<(), Vec<StudyError>> {
    let mut errors = vec![];
    let mut names: std::collections::BTreeMap<String, String> = Default::default();
    let mut counts = vec![];
    for f in files {
        match entry(f) {
            Ok(e) => {
                let shown = f.display().to_string();
                counts.push((e.name.clone(), if tier == Tier::Quick { e.quick } else { e.full }));
                if let Some(first) = names.get(&e.name) {
                    if *first != shown {
                        errors.push(StudyError::Invalid {
                            file: shown,
                            key: "name".into(),
                            value: format!("{:?}", e.name),
                            allowed: format!(
                                "already the name of {first}: each study needs its own name (its output folder)"
                            ),
                        });
                    }
                } else {
                    names.insert(e.name, shown);
                }
            }
            Err(e) => errors.push(e),
        }
    }
    let total: usize = counts.iter().map(|c| c.1).sum();
    if errors.is_empty() && total > crate::study::MAX_CASES_PER_RUN {
        let each: Vec<String> = counts.iter().map(|(n, c)| format!("{n} {c}")).collect();
        errors.push(StudyError::Invalid {
            file: files.iter().map(|f| f.display().to_string()).collect::<Vec<_>>().join(", "),
            key: "sweeps".into(),
            value: format!("{total} cases in the {} tier ({})", tier.name(), each.join(", ")),
            allowed: format!(
                "one run must solve at most {} cases (igimp::study::MAX_CASES_PER_RUN): split the sweeps, or run the study files one by one",
                crate::study::MAX_CASES_PER_RUN
            ),
        });
    }
    if errors.is_empty() {
        Ok(())
    } else {
        Err(errors)
    }
}
