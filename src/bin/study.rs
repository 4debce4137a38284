//! `study`: run the paper's verification studies and render their tables and figures.
//!
//! `cargo run --release --bin study -- column` solves every case of `studies/column.toml`,
//! writes `reports/column/results.json` and the point files, then renders the tables, the
//! SVG figures and `reports/index.md` from those files.

use clap::{CommandFactory, FromArgMatches, Parser};
use igimp::study::checks::{check_counts, CheckRecord};
use igimp::study::engine::RunOptions;
use igimp::study::kinds;
use igimp::study::results::{read_json, CaseStatus, Failures};
use igimp::study::store::Refusal;
use igimp::study::vtk_output::VtkOptions;
use igimp::study::{study_files, Distribution, StudyError, Tier};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

/// Counts each case's heap bytes for the `timing.costs` of `results.json`.
#[global_allocator]
static ALLOCATOR: igimp::solver::profile::CountingAllocator = igimp::solver::profile::CountingAllocator;

#[derive(Debug, Parser)]
#[command(
    name = "study",
    version,
    about = "Run the iGIMP paper's verification studies: solve every case, write results.json, \
             render tables and SVG figures",
    long_about = None
)]
struct Cli {
    /// Study names (files `<studies>/<name>.toml`), paths to study files, `all`, or `list`.
    #[arg(required_unless_present = "solve_case", value_name = "STUDY")]
    studies: Vec<String>,
    /// Folder of the adapters that run other codes' cases (`ext:<adapter>` methods;
    /// studies/PROTOCOL.md). Default: `$IGIMP_ADAPTERS`, else `examples/adapters`.
    #[arg(long, value_name = "DIR")]
    adapters: Option<PathBuf>,
    /// Solve one case file of the case protocol in process and write its result file, as
    /// igimp's adapter (`examples/adapters/igimp/`) does; nothing else runs.
    #[arg(long, num_args = 2, value_names = ["CASE_JSON", "RESULT_JSON"], conflicts_with = "studies")]
    solve_case: Option<Vec<PathBuf>>,
    /// Run the quick tier (each sweep's `quick` overrides; what the tests and CI run).
    #[arg(long)]
    quick: bool,
    /// Output folder; each study writes `<out>/<name>/`, and `<out>/index.md` links them.
    #[arg(long, value_name = "DIR", default_value = "reports")]
    out: PathBuf,
    /// Redraw tables and figures from an existing `<out>/<name>/results.json` without solving.
    #[arg(long)]
    render_only: bool,
    /// Folder of the study files.
    #[arg(long, value_name = "DIR")]
    studies_dir: Option<PathBuf>,
    /// Exit with status 2 if an expected rate or comparison fails or could not be evaluated,
    /// or a case failed (or was rejected) that its study file does not declare in
    /// `[[expected_failures]]`.
    #[arg(long)]
    check: bool,
    /// Reuse the cases an earlier (e.g. interrupted) run finished with the same inputs
    /// (`<out>/<name>/cases/`, keyed by a hash of each case's definition) and the same build;
    /// solve the rest. A record edited, truncated, of other inputs or of another build is
    /// solved again, and a line on stderr says which and why.
    #[arg(long)]
    resume: bool,
    /// With --resume or --merge, also reuse records written by another build (other
    /// sources: other solver code may give other answers). Their inputs must match and
    /// their content must match its digest all the same.
    #[arg(long)]
    reuse_other_builds: bool,
    /// Write ParaView files `<out>/<name>/vtk/<case>.pvd` of the initial and the final state:
    /// column and column-3d, the material/Gauss points and the grid/mesh of every case;
    /// compaction, cantilever and manufactured (2D and 3D), the material point domains
    /// (quadrilaterals in 2D, hexahedra in 3D) of the iGIMP and MPM cases with their
    /// background grid (FEM cases write none).
    #[arg(long, conflicts_with = "render_only")]
    vtk: bool,
    /// With --vtk, also write every N-th load step (implies --vtk; column and cantilever;
    /// the compaction writes its initial and final states only, manufactured its final one).
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..), conflicts_with = "render_only")]
    vtk_every: Option<u32>,
    /// Solve only shard K of N (0 <= K < N): the cases whose index in the deterministic case
    /// order is K mod N, stored in `<out>/<name>/cases/`; nothing is rendered. Run every
    /// shard (e.g. as a Slurm job array, examples/slurm/), then `--merge`.
    #[arg(long, value_name = "K/N", value_parser = parse_shard, conflicts_with_all = ["merge", "render_only"])]
    shard: Option<Distribution>,
    /// Read every case from the case store the shards wrote (an error lists any missing one),
    /// then fit, check, write results.json and render as an unsharded run would.
    #[arg(long, conflicts_with = "render_only")]
    merge: bool,
}

fn parse_shard(text: &str) -> Result<Distribution, String> {
    Distribution::parse_shard(text)
}

impl Cli {
    fn distribution(&self) -> Distribution {
        match (self.shard, self.merge) {
            (Some(d), _) => d,
            (None, true) => Distribution::Merge,
            (None, false) => Distribution::Whole,
        }
    }
}

/// `studies/` in the working directory, else the one in the source tree.
fn default_studies_dir() -> PathBuf {
    let local = PathBuf::from("studies");
    if local.is_dir() {
        local
    } else {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("studies")
    }
}

/// (name, summary) of every valid study file in `dir`, and the errors of invalid ones.
fn catalogue(dir: &Path) -> Vec<Result<(String, String), StudyError>> {
    match study_files(dir) {
        Ok(files) => files.iter().map(|f| kinds::catalogue_entry(f)).collect(),
        Err(e) => vec![Err(e)],
    }
}

fn studies_help(dir: &Path) -> String {
    let mut s = format!("Studies (from {}):\n", dir.display());
    for entry in catalogue(dir) {
        match entry {
            Ok((name, summary)) => s.push_str(&format!("  {name:<12} {summary}\n")),
            Err(e) => s.push_str(&format!("  (invalid) {e}\n")),
        }
    }
    s.push_str(
        "\nExamples:\n  study column            full column study into reports/column/\n  \
         study column --quick    the CI tier\n  study all --render-only redraw every report from results.json\n  \
         study column --resume   finish an interrupted run, reusing its finished cases\n  \
         study column --quick --vtk  ParaView files into reports/column/vtk/\n  \
         study list              list the studies",
    );
    s
}

fn resolve(dir: &Path, name: &str) -> PathBuf {
    let p = Path::new(name);
    if name.ends_with(".toml") || p.components().count() > 1 {
        p.to_path_buf()
    } else {
        dir.join(format!("{name}.toml"))
    }
}

/// Progress of one study's cases on stderr: a bar on a terminal; elsewhere (a Slurm log, a
/// pipe) one plain line per finished case with the elapsed time and an estimate of the rest.
/// A case that did not converge is printed as a line of its own in both, and counted in the
/// bar's message.
struct Progress {
    label: String,
    bar: ProgressBar,
    terminal: bool,
    start: Instant,
    state: std::sync::Mutex<(usize, usize, usize)>,
}

impl Progress {
    fn new(label: String) -> Self {
        let terminal = std::io::stderr().is_terminal();
        // Hidden until the number of cases is known, so no "0/0" frame is drawn.
        let bar = ProgressBar::hidden();
        if let Ok(style) =
            ProgressStyle::with_template("{prefix:>8} [{bar:40}] {pos}/{len} cases {elapsed} {msg}")
        {
            bar.set_style(style.progress_chars("=> "));
        }
        bar.set_prefix(label.clone());
        Progress {
            label,
            bar,
            terminal,
            start: Instant::now(),
            state: std::sync::Mutex::new((0, 0, 0)),
        }
    }

    fn on_start(&self, n: usize) {
        self.state.lock().unwrap_or_else(|e| e.into_inner()).0 = n;
        self.bar.set_length(n as u64);
        if self.terminal {
            self.bar.set_draw_target(ProgressDrawTarget::stderr());
        } else {
            eprintln!("{}: {n} cases to solve or resume", self.label);
        }
    }

    /// A stored record not reused: one line, whatever the output.
    fn on_refused(&self, id: &str, why: &Refusal) {
        let line = format!("{}: case {id} not reused, solving it again: {why}", self.label);
        if self.terminal {
            self.bar.println(line);
        } else {
            eprintln!("{line}");
        }
    }

    fn on_done(&self, id: &str, status: CaseStatus) {
        let mut s = self.state.lock().unwrap_or_else(|e| e.into_inner());
        s.1 += 1;
        // A collapse is the result a strength reduction runs for, not a failure.
        s.2 += usize::from(!status.solved());
        let (n, done, failed) = *s;
        let elapsed = self.start.elapsed().as_secs_f64();
        if self.terminal {
            if !status.solved() {
                self.bar
                    .println(format!("{}: case {id} {}", self.label, status.word()));
                self.bar.set_message(format!("({failed} not converged)"));
            }
            self.bar.inc(1);
        } else {
            // The cases left cost about what the finished ones did on average; crude, but the
            // engine starts the most expensive first, so it errs long.
            let eta = elapsed / done as f64 * n.saturating_sub(done) as f64;
            eprintln!(
                "{}: {done}/{n} cases, {id} {}, elapsed {}, ETA {}",
                self.label,
                status.word(),
                clock(elapsed),
                clock(eta)
            );
        }
    }
}

/// Seconds as `1h02m03s`, `2m03s` or `3.4s`.
fn clock(seconds: f64) -> String {
    let s = seconds.max(0.0);
    let whole = s.round() as u64;
    match whole {
        0..=59 => format!("{s:.1}s"),
        60..=3599 => format!("{}m{:02}s", whole / 60, whole % 60),
        _ => format!("{}h{:02}m{:02}s", whole / 3600, whole / 60 % 60, whole % 60),
    }
}

/// Solve (unless `--render-only`) and render one study file; `Ok(false)` if a check failed
/// or could not be evaluated.
fn run_one(file: &Path, cli: &Cli) -> Result<bool, StudyError> {
    let tier = if cli.quick { Tier::Quick } else { Tier::Full };
    let start = Instant::now();
    let label = file.file_stem().map_or_else(
        || file.display().to_string(),
        |s| s.to_string_lossy().into_owned(),
    );
    let progress = Progress::new(label.clone());
    let on_start = |n: usize| progress.on_start(n);
    let on_done = |id: &str, status: CaseStatus| progress.on_done(id, status);
    let on_refused = |id: &str, why: &Refusal| progress.on_refused(id, why);
    let options = RunOptions {
        study_dir: None,
        resume: cli.resume,
        reuse_other_builds: cli.reuse_other_builds,
        vtk: (cli.vtk || cli.vtk_every.is_some()).then(|| VtkOptions {
            every: cli.vtk_every.map_or(0, |n| n as usize),
        }),
        distribution: cli.distribution(),
        on_start: &on_start,
        on_done: &on_done,
        on_refused: &on_refused,
    };
    let ran = kinds::run_file(file, tier, &cli.out, cli.render_only, options);
    progress.bar.finish_and_clear();
    if let Err(e @ StudyError::ShardDone { .. }) = &ran {
        eprintln!("{label}: {e}");
        return Ok(true);
    }
    let (dir, summary, rendered) = ran?;
    let files = rendered.files;
    for w in &rendered.not_drawn {
        eprintln!("{label}: warning: {w}");
    }
    let name = dir
        .file_name()
        .map_or(label, |n| n.to_string_lossy().into_owned());
    if let Some(r) = summary.as_ref().filter(|_| cli.resume) {
        eprintln!(
            "{name}: resumed {} of {} cases from {}",
            r.resumed,
            r.cases,
            dir.join("cases").display()
        );
    }
    match summary {
        Some(r) => eprintln!(
            "{name}: {} cases ({} failed, {} rejected) solved and {} files rendered into {} in {:.2} s on {} threads",
            r.cases,
            r.failed,
            r.rejected,
            files.len(),
            dir.display(),
            start.elapsed().as_secs_f64(),
            rayon::current_num_threads()
        ),
        None => eprintln!("{name}: rendered {} files into {}", files.len(), dir.display()),
    }
    let results = read_json::<serde_json::Value>(&dir.join("results.json")).ok();
    let checks: Vec<CheckRecord> = results
        .as_ref()
        .and_then(|v| serde_json::from_value(v.get("checks")?.clone()).ok())
        .unwrap_or_default();
    let failures = results.as_ref().map(Failures::of).unwrap_or_default();
    if let Some(line) = failures.line() {
        eprintln!("{name}: cases: {line}");
    }
    let (pass, fail, none) = check_counts(&checks);
    eprintln!("{name}: checks: {pass} passed, {fail} failed, {none} not evaluated");
    for c in checks.iter().filter(|c| c.pass != Some(true)) {
        eprintln!(
            "  check {}: {}: measured {}, limit {}",
            if c.pass.is_none() { "not evaluated" } else { "FAIL" },
            c.id,
            c.measured.map_or("—".to_string(), |m| format!("{m:.4e}")),
            c.limit
        );
    }
    Ok(fail == 0 && none == 0 && failures.unexpected.is_empty())
}

fn main() -> ExitCode {
    // The studies folder may be given on the command line; peek at it for the help text.
    let args: Vec<String> = std::env::args().collect();
    let dir_arg = args
        .iter()
        .position(|a| a == "--studies-dir")
        .and_then(|i| args.get(i + 1))
        .map(PathBuf::from)
        .or_else(|| {
            args.iter()
                .find_map(|a| a.strip_prefix("--studies-dir=").map(PathBuf::from))
        });
    let help_dir = dir_arg.unwrap_or_else(default_studies_dir);
    let cmd = Cli::command().after_help(studies_help(&help_dir));
    let cli = match cmd
        .try_get_matches_from(&args)
        .and_then(|m| Cli::from_arg_matches(&m))
    {
        Ok(c) => c,
        Err(e) => e.exit(),
    };
    let dir = cli.studies_dir.clone().unwrap_or_else(default_studies_dir);
    if let Some(a) = &cli.adapters {
        igimp::study::external::adapter::set_adapters_dir(a.clone());
    }
    if let Some(files) = &cli.solve_case {
        return match igimp::study::external::igimp_case::solve_case_file(&files[0], &files[1]) {
            Ok(()) => ExitCode::SUCCESS,
            Err(e) => {
                eprintln!("error: {e}");
                ExitCode::FAILURE
            }
        };
    }

    if cli.studies.iter().any(|s| s == "list") {
        if cli.studies.len() > 1 {
            eprintln!(
                "error: `list` takes no study names (got {}); run `study list` alone, or name the studies to run",
                cli.studies.join(" ")
            );
            return ExitCode::from(2);
        }
        let mut ok = true;
        for entry in catalogue(&dir) {
            match entry {
                Ok((name, summary)) => println!("{name:<12} {summary}"),
                Err(e) => {
                    ok = false;
                    eprintln!("error: {e}");
                }
            }
        }
        return if ok { ExitCode::SUCCESS } else { ExitCode::FAILURE };
    }
    let files: Vec<PathBuf> = if cli.studies.iter().any(|s| s == "all") {
        match study_files(&dir) {
            Ok(f) => f,
            Err(e) => {
                eprintln!("error: {e}");
                return ExitCode::FAILURE;
            }
        }
    } else {
        // A file named twice (by name and by path, say) is solved once.
        let mut seen = std::collections::BTreeSet::new();
        let mut files = vec![];
        for f in cli.studies.iter().map(|s| resolve(&dir, s)) {
            let canonical = std::fs::canonicalize(&f).unwrap_or_else(|_| f.clone());
            if seen.insert(canonical) {
                files.push(f);
            } else {
                eprintln!("note: {} is named more than once; it runs once", f.display());
            }
        }
        files
    };
    let all = cli.studies.iter().any(|s| s == "all");
    // Every file is checked before any is solved: a bad third file must not be found after
    // the first two have run for an hour, and two files of one `name` would overwrite each
    // other's output folder.
    let tier = if cli.quick { Tier::Quick } else { Tier::Full };
    if let Err(errors) = kinds::validate_files(&files, tier) {
        for e in &errors {
            eprintln!("error: {e}");
        }
        eprintln!(
            "error: {} of {} study files invalid; nothing was solved",
            errors.len(),
            files.len()
        );
        return ExitCode::FAILURE;
    }
    let mut all_ok = true;
    let mut without_results = vec![];
    for f in &files {
        match run_one(f, &cli) {
            Ok(ok) => all_ok &= ok,
            // `study all --render-only` renders the studies that have results and lists the
            // others; a study named on its own is an error without them.
            Err(StudyError::NoResults { study, .. }) if all && cli.render_only => without_results.push(study),
            Err(e) => {
                eprintln!("error: {e}");
                return ExitCode::FAILURE;
            }
        }
    }
    if !without_results.is_empty() {
        eprintln!(
            "not rendered, no results.json in {} (solve them first): {}",
            cli.out.display(),
            without_results.join(", ")
        );
    }
    if let Err(e) = std::fs::create_dir_all(&cli.out)
        .map_err(|e| StudyError::Io {
            path: cli.out.display().to_string(),
            message: e.to_string(),
        })
        .and_then(|_| kinds::render_methods(&cli.out))
        .and_then(|_| kinds::render_index(&cli.out))
    {
        eprintln!("error: {e}");
        return ExitCode::FAILURE;
    }
    if cli.check && !all_ok {
        eprintln!(
            "error: some expected rates or comparisons failed or were not evaluated, or a case failed that its study does not expect (--check)"
        );
        return ExitCode::from(2);
    }
    ExitCode::SUCCESS
}
