//! The one study engine. A study kind ([`StudyKind`]) says how its study file is checked, which
//! cases a tier has, how one case is solved and what its measures and checks are; the engine
//! does the rest for every kind alike: rayon across cases (most expensive first, results in
//! the deterministic case order, so the output does not depend on the thread count), the case
//! store (`<out>/<name>/cases/`, every finished case written atomically as soon as it is done),
//! `--resume` by input hash, build and content digest ([`super::store`]), `--vtk`, the progress callbacks, `--shard K/N` and `--merge`, and
//! the [`Envelope`] written as `results.json`.
//!
//! A failed case is recorded in its record (status, step, reason, residuals) and the others go
//! on; only an I/O error of the store stops a run (the first in case order).

use super::checks::CheckRecord;
use super::results::{
    read_results, write_json, CaseRecordOf, CaseStatus, Envelope, Provenance, SweepIndex, Timing,
};
use super::store::{CaseStore, Refusal};
use super::vtk_output::{pvd_path, VtkOptions};
use super::{Distribution, StudyError, Tier};
use crate::basis::method::Method;
use crate::solver::profile::{self, CaseCost};
use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Instant;

/// The store key of a case: its id, the hash of the inputs that define its result
/// ([`super::store::case_hash`]), and whether it writes ParaView files.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct CaseKey {
    pub id: String,
    pub hash: String,
    pub has_vtk: bool,
}

/// The inputs that define a case's result, hashed for `--resume`.
#[derive(Serialize)]
struct CaseDefinition<'a, S> {
    id: &'a str,
    method: Method,
    spec: &'a S,
    /// Domain snapshots taken for the figures (0: none).
    snapshot_every: usize,
}

impl CaseKey {
    /// The key of a case defined by its id, method and problem input `spec` (and the
    /// snapshots its figures take); the material point methods write ParaView files.
    pub fn of_spec<S: Serialize>(id: &str, method: Method, spec: &S, snapshot_every: usize) -> Self {
        CaseKey {
            id: id.to_string(),
            hash: super::store::case_hash(&CaseDefinition {
                id,
                method,
                spec,
                snapshot_every,
            }),
            has_vtk: method.uses_material_points(),
        }
    }
}

/// Where and what a case writes for ParaView (`--vtk`).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct VtkTarget {
    /// The study's output folder (files go to its `vtk/`).
    pub study_dir: PathBuf,
    pub options: VtkOptions,
}

/// One kind of study: a problem's study file and how its cases are planned, solved, measured
/// and checked.
pub trait StudyKind: Serialize + DeserializeOwned + Clone + Sync {
    /// The `problem` key of the kind's study files (and of `study.problem` in its results).
    const PROBLEM: &'static str;
    /// One case to solve.
    type Case: Sync;
    /// What the case store keeps of a solved case: its record and any side data.
    type Output: Send + Serialize + DeserializeOwned;
    /// A case's entry in `results.json`.
    type Record: Clone + CaseRecordOf + Serialize + DeserializeOwned;
    /// The kind's measures besides the checks (flattened into `results.json`).
    type Measures: Clone + Default + Serialize + DeserializeOwned;

    /// Check every value of the parsed file; errors name `file`, the key and the allowed range.
    fn validate(&self, file: &str) -> Result<(), StudyError>;
    /// The study's `name` (its output folder).
    fn name(&self) -> &str;
    /// One line for `study list`.
    fn summary(&self) -> &str;
    /// The cases the study file declares expected to fail.
    fn expected_failures(&self) -> &[super::vocabulary::ExpectedFailure];
    /// Every distinct case of the tier in file order (the order shards split) and the case
    /// ids of each sweep.
    fn cases(&self, tier: Tier) -> (Vec<Self::Case>, SweepIndex);
    fn key(&self, case: &Self::Case) -> CaseKey;
    /// Relative cost, so that the expensive cases start first.
    fn cost(&self, case: &Self::Case) -> f64;
    /// Solve one case; with `vtk`, also write its ParaView files.
    fn solve(&self, case: &Self::Case, vtk: Option<&VtkTarget>) -> Result<Self::Output, StudyError>;
    /// [`Self::solve`] given the study's output folder (`None`: an in-memory run), for a kind
    /// whose cases keep files of their own (an external code's case and result files).
    fn solve_in(
        &self,
        case: &Self::Case,
        vtk: Option<&VtkTarget>,
        _study_dir: Option<&Path>,
    ) -> Result<Self::Output, StudyError> {
        self.solve(case, vtk)
    }
    fn record(output: &Self::Output) -> &Self::Record;
    /// Fill the measures and checks of `results`, whose cases are solved.
    fn measure(results: &mut Results<Self>);
    /// Write the files beside `results.json` (e.g. drawn domains, point files) into `dir`.
    fn write_side_files(&self, dir: &Path, outputs: &[Self::Output]) -> Result<(), StudyError>;

    /// Parse and validate a study file's text; `file` names it in errors.
    fn parse(text: &str, file: &str) -> Result<Self, StudyError> {
        let spec: Self = super::vocabulary::parse_toml(text, file)?;
        spec.validate(file)
            .and_then(|_| spec.check_expected_failures(file))
            .and_then(|_| spec.check_sweeps_distinct(file, text))
            .map_err(|e| super::locate::locate(text, e))?;
        Ok(spec)
    }

    /// No sweep lists a value twice (it would name one case twice, solved once).
    fn check_sweeps_distinct(&self, file: &str, text: &str) -> Result<(), StudyError> {
        let chk = super::vocabulary::Checker { file };
        for tier in [Tier::Full, Tier::Quick] {
            let (_, index) = self.cases(tier);
            for (sweep, ids) in &index {
                let mut seen = std::collections::BTreeSet::new();
                if let Some(twice) = ids.iter().find(|id| !seen.insert(id.as_str())) {
                    // The sweep's index in the file, read only for the error.
                    let position = text.parse::<toml::Table>().ok().and_then(|t| {
                        t.get("sweeps")?
                            .as_array()?
                            .iter()
                            .position(|s| s.get("id").and_then(|v| v.as_str()) == Some(sweep.as_str()))
                    });
                    let key = match position {
                        Some(i) => format!("sweeps[{i}]"),
                        None => format!("sweep {sweep:?}"),
                    };
                    return Err(chk.err(
                        key,
                        format!("{sweep:?}"),
                        format!(
                            "must not list a value twice in the {} tier: case {twice} would be named twice and solved once",
                            tier.name()
                        ),
                    ));
                }
            }
        }
        Ok(())
    }

    /// Each declared expected failure lists case ids and gives its reason. (A pattern that
    /// matches no case of a run is said in the run's summary, not refused: a study file cut to
    /// a few sweeps keeps its declarations.)
    fn check_expected_failures(&self, file: &str) -> Result<(), StudyError> {
        let chk = super::vocabulary::Checker { file };
        for (i, e) in self.expected_failures().iter().enumerate() {
            chk.text(&format!("expected_failures[{i}].reason"), &e.reason)?;
            chk.non_empty(&format!("expected_failures[{i}].cases"), &e.cases)?;
            for (j, p) in e.cases.iter().enumerate() {
                chk.text(&format!("expected_failures[{i}].cases[{j}]"), p)?;
            }
        }
        Ok(())
    }

    /// Read, parse and validate a study file.
    fn load(path: &Path) -> Result<Self, StudyError> {
        let text = std::fs::read_to_string(path).map_err(|e| StudyError::io(path, e))?;
        Self::parse(&text, &path.display().to_string())
    }
}

/// The [`StudyKind`] methods of a study file with `name` and `summary` fields whose
/// inherent `check(&self, file)` validates it.
macro_rules! study_file_fields {
    () => {
        fn validate(&self, file: &str) -> Result<(), $crate::study::StudyError> {
            self.check(file)
        }
        fn name(&self) -> &str {
            &self.name
        }
        fn summary(&self) -> &str {
            &self.summary
        }
        fn expected_failures(&self) -> &[$crate::study::vocabulary::ExpectedFailure] {
            &self.expected_failures
        }
    };
}
pub(crate) use study_file_fields;

/// Every distinct case of `sweeps` (id, cases) in file order, a case shared by two sweeps
/// once, and the case ids of each sweep: what [`StudyKind::cases`] returns.
pub fn distinct_cases<C>(
    sweeps: impl IntoIterator<Item = (String, Vec<C>)>,
    id: impl Fn(&C) -> &str,
) -> (Vec<C>, SweepIndex) {
    let mut seen = std::collections::BTreeSet::new();
    let mut all = vec![];
    let mut index = SweepIndex::new();
    for (sweep, cases) in sweeps {
        index.insert(sweep, cases.iter().map(|c| id(c).to_string()).collect());
        all.extend(cases.into_iter().filter(|c| seen.insert(id(c).to_string())));
    }
    (all, index)
}

/// `results.json` of study kind `K`.
pub type Results<K> = Envelope<K, <K as StudyKind>::Record, <K as StudyKind>::Measures>;

/// A solved study: the results, each case's output (case order), and how many were read back
/// from the case store.
pub struct Run<K: StudyKind> {
    pub results: Results<K>,
    pub outputs: Vec<K::Output>,
    pub resumed: usize,
}

/// What a run asks besides the tier: the case store, `--resume`, `--vtk`, `--shard`/`--merge`
/// and the progress callbacks.
pub struct RunOptions<'a> {
    /// The study's output folder; `None`: no case store and no VTK (an in-memory run).
    pub study_dir: Option<PathBuf>,
    /// Reuse the stored record of a case whose inputs hash equally, written by this build,
    /// whose content matches its digest.
    pub resume: bool,
    /// With `resume` or `--merge`, reuse records of another build too (their inputs and
    /// content digest must still match).
    pub reuse_other_builds: bool,
    /// Write ParaView files of the cases that have them.
    pub vtk: Option<VtkOptions>,
    /// `--shard K/N` or `--merge` (needs `study_dir`).
    pub distribution: Distribution,
    /// Called once with the number of cases, then with each case's id and status when done.
    pub on_start: &'a (dyn Fn(usize) + Sync),
    pub on_done: &'a (dyn Fn(&str, CaseStatus) + Sync),
    /// Called with a case's id and the reason when its stored record is not reused and the
    /// case is solved again (`--merge` lists them in its error instead).
    pub on_refused: &'a (dyn Fn(&str, &Refusal) + Sync),
}

impl Default for RunOptions<'_> {
    fn default() -> Self {
        Self {
            study_dir: None,
            resume: false,
            reuse_other_builds: false,
            vtk: None,
            distribution: Distribution::Whole,
            on_start: &|_| {},
            on_done: &|_, _| {},
            on_refused: &|_, _| {},
        }
    }
}

/// Solve `cases`, most expensive first (by `cost`), as many at once as the rayon pool has
/// threads, and return the results in the order of `cases` with what each cost. Each worker
/// runs its cases on a rayon pool of its own ([`profile::CasePool`]) with as many threads, so
/// that a case's phases and heap peak are accounted to it alone; a case left to finish alone
/// still has every thread for its own parallel loops.
pub fn run_cases<C: Sync, R: Send>(
    cases: &[C],
    cost: impl Fn(&C) -> f64 + Sync,
    solve: impl Fn(&C) -> R + Sync,
) -> Vec<(R, CaseCost)> {
    let mut order: Vec<usize> = (0..cases.len()).collect();
    order.sort_by(|&a, &b| cost(&cases[b]).total_cmp(&cost(&cases[a])).then(a.cmp(&b)));
    let threads = rayon::current_num_threads().max(1);
    let next = AtomicUsize::new(0);
    let solved = std::sync::Mutex::new(Vec::<(usize, R, CaseCost)>::with_capacity(cases.len()));
    std::thread::scope(|scope| {
        for _ in 0..threads.min(order.len()) {
            scope.spawn(|| {
                let pool = profile::CasePool::new(threads);
                loop {
                    let k = next.fetch_add(1, Ordering::Relaxed);
                    let Some(&i) = order.get(k) else { break };
                    let (r, c) = pool.run(|| solve(&cases[i]));
                    solved.lock().unwrap_or_else(|e| e.into_inner()).push((i, r, c));
                }
            });
        }
    });
    let mut solved = solved.into_inner().unwrap_or_else(|e| e.into_inner());
    solved.sort_by_key(|s| s.0);
    solved.into_iter().map(|(_, r, c)| (r, c)).collect()
}

/// A finished case as the store keeps it: its output and the seconds it took, by phase (so
/// that a resumed run reports the original timing).
#[derive(Serialize, Deserialize)]
struct StoredCase<R> {
    output: R,
    seconds: f64,
    /// Absent in cases stored before phases were accounted.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    cost: Option<CaseCost>,
}

/// Each case's output with its seconds and what they were spent on (unless stored before
/// phases were accounted), and how many were read back from the store.
type Solved<K> = (Vec<(<K as StudyKind>::Output, f64, Option<CaseCost>)>, usize);
/// A case's output and, if read back from the store, its original seconds and cost.
type Finished<K> = (<K as StudyKind>::Output, Option<(f64, Option<CaseCost>)>);

/// Solve (or read back) every case this process owns: with `resume` (or `--merge`), a case
/// stored earlier under the same id and input hash by this build (or any, with
/// `reuse_other_builds`), whose content matches its digest (with `--vtk`, whose `.pvd` exists
/// too), is read back instead of solved, and a record refused is reported (`on_refused`);
/// every solved case is stored as soon as it is done. Returns the outputs in case order with
/// their seconds, and how many were resumed. `--merge` solves nothing and lists every case
/// not read back in one error, with the reason of each refused record; `--shard` stores its
/// cases and ends with [`StudyError::ShardDone`].
fn solve_all<K: StudyKind>(
    study: &K,
    cases: &[K::Case],
    options: &RunOptions<'_>,
) -> Result<Solved<K>, StudyError> {
    let store = match &options.study_dir {
        Some(dir) => Some(CaseStore::open(&dir.join("cases"))?),
        None => None,
    };
    let distribution = options.distribution;
    let merge = distribution == Distribution::Merge;
    let resume = options.resume || merge;
    let own: Vec<&K::Case> = cases
        .iter()
        .enumerate()
        .filter(|(i, _)| distribution.owns(*i))
        .map(|(_, c)| c)
        .collect();
    (options.on_start)(own.len());
    let resumed = AtomicUsize::new(0);
    let done = |id: &str, o: &K::Output| (options.on_done)(id, K::record(o).status());
    let outputs = run_cases(
        &own,
        |c| study.cost(c),
        |c| -> Result<Result<Finished<K>, Refusal>, StudyError> {
            let key = study.key(c);
            let (Some(store), Some(dir)) = (&store, &options.study_dir) else {
                let o = study.solve_in(c, None, None)?;
                done(&key.id, &o);
                return Ok(Ok((o, None)));
            };
            // --merge solves nothing, so it does not ask for the VTK files either.
            let vtk_done = match options.vtk {
                Some(_) if key.has_vtk && !merge => pvd_path(dir, &key.id)?.exists(),
                _ => true,
            };
            if resume && vtk_done {
                match store.load::<StoredCase<K::Output>>(&key.id, &key.hash, options.reuse_other_builds) {
                    Ok(s) => {
                        resumed.fetch_add(1, Ordering::Relaxed);
                        done(&key.id, &s.output);
                        return Ok(Ok((s.output, Some((s.seconds, s.cost)))));
                    }
                    Err(why) if merge => return Ok(Err(why)),
                    Err(Refusal::Absent) => {}
                    Err(why) => (options.on_refused)(&key.id, &why),
                }
            }
            if merge {
                return Ok(Err(Refusal::Absent));
            }
            let vtk = options.vtk.filter(|_| key.has_vtk).map(|options| VtkTarget {
                study_dir: dir.clone(),
                options,
            });
            let t = Instant::now();
            let output = study.solve_in(c, vtk.as_ref(), Some(dir))?;
            let seconds = t.elapsed().as_secs_f64();
            // The phases so far; the engine's own measure (store write included) replaces
            // this one for a case solved now.
            let cost = CaseCost {
                seconds,
                ..profile::current()
            };
            let stored = StoredCase {
                output,
                seconds,
                cost: Some(cost),
            };
            store.save(&key.id, &key.hash, &stored)?;
            done(&key.id, &stored.output);
            Ok(Ok((stored.output, None)))
        },
    );
    let mut out = Vec::with_capacity(outputs.len());
    let mut missing = vec![];
    for (c, (r, cost)) in own.iter().zip(outputs) {
        match r? {
            Ok((o, Some((seconds, stored)))) => out.push((o, seconds, stored)),
            Ok((o, None)) => out.push((o, cost.seconds, Some(cost))),
            Err(Refusal::Absent) => missing.push(study.key(c).id),
            Err(why) => missing.push(format!("{} ({why})", study.key(c).id)),
        }
    }
    if let (false, Some(dir)) = (missing.is_empty(), &options.study_dir) {
        return Err(StudyError::MissingCases {
            dir: dir.join("cases").display().to_string(),
            total: cases.len(),
            missing,
            hint: other_cases_hint(&dir.join("cases"), cases.iter().map(|c| study.key(c).id)),
        });
    }
    if let (Distribution::Shard { k, n }, Some(dir)) = (distribution, &options.study_dir) {
        return Err(StudyError::ShardDone {
            k,
            n,
            solved: out.len(),
            total: cases.len(),
            dir: dir.join("cases").display().to_string(),
        });
    }
    Ok((out, resumed.into_inner()))
}

/// A hint for `--merge` when the store holds records of cases this run does not have: the
/// shards were most likely run with the other tier (`--quick`) or another study file.
fn other_cases_hint(store: &Path, ids: impl Iterator<Item = String>) -> String {
    let ids: std::collections::BTreeSet<String> = ids.collect();
    let others: Vec<String> = std::fs::read_dir(store)
        .into_iter()
        .flatten()
        .filter_map(|e| {
            let name = e.ok()?.file_name().to_string_lossy().into_owned();
            name.strip_suffix(".json")
                .filter(|s| !s.starts_with('.'))
                .map(str::to_string)
        })
        .filter(|id| !ids.contains(id))
        .collect();
    match others.first() {
        None => String::new(),
        Some(first) => format!(
            ". The store holds {} records of cases this run does not have (e.g. {first}): were the shards run with another tier (--quick) or study file than this --merge?",
            others.len()
        ),
    }
}

/// Solve every case of the tier with `options`, then measure and check: the run of `study`
/// whose study file is `study_file` (its name, recorded in the results).
pub fn run<K: StudyKind>(
    study: &K,
    study_file: &str,
    tier: Tier,
    options: &RunOptions<'_>,
) -> Result<Run<K>, StudyError> {
    let start = Instant::now();
    // The resident peak is the study's own only if it can be reset (one process may run
    // several studies); otherwise it is not reported.
    let own_peak = profile::reset_peak_resident();
    let (cases, sweep_cases) = study.cases(tier);
    if cases.is_empty() {
        return Err(StudyError::Invalid {
            file: study_file.to_string(),
            key: "sweeps".into(),
            value: format!("{} tier: 0 cases", tier.name()),
            allowed: "must give the tier run at least one case (every sweep is skipped or empty)".into(),
        });
    }
    let (solved, resumed) = solve_all(study, &cases, options)?;
    let mut times = std::collections::BTreeMap::new();
    let mut costs = std::collections::BTreeMap::new();
    let mut records = Vec::with_capacity(solved.len());
    let mut outputs = Vec::with_capacity(solved.len());
    for (o, seconds, cost) in solved {
        let r = K::record(&o).clone();
        times.insert(r.id().to_string(), seconds);
        if let Some(cost) = cost {
            costs.insert(r.id().to_string(), cost);
        }
        records.push(r);
        outputs.push(o);
    }
    let mut results = Envelope {
        provenance: Provenance::new(study_file, tier),
        study: study.clone(),
        sweep_cases,
        cases: records,
        measures: K::Measures::default(),
        checks: Vec::<CheckRecord>::new(),
        timing: Timing {
            wall_seconds: 0.0,
            threads: rayon::current_num_threads(),
            cases: times,
            costs,
            peak_resident_bytes: None,
        },
    };
    K::measure(&mut results);
    results.timing.wall_seconds = start.elapsed().as_secs_f64();
    // A run that read cases back from the store did not hold them: its peak is not theirs.
    results.timing.peak_resident_bytes = profile::peak_resident_bytes().filter(|_| own_peak && resumed == 0);
    Ok(Run {
        results,
        outputs,
        resumed,
    })
}

/// [`run`] in memory: no case store, no VTK, no progress.
pub fn run_in_memory<K: StudyKind>(study: &K, study_file: &str, tier: Tier) -> Result<Run<K>, StudyError> {
    run(study, study_file, tier, &RunOptions::default())
}

/// Write `<out>/<name>/results.json` and the kind's side files, replacing the old ones as a
/// whole ([`super::replace`]: a kill at any moment leaves the old report or the new one);
/// returns the folder.
pub fn write_outputs<K: StudyKind>(out: &Path, run: &Run<K>) -> Result<PathBuf, StudyError> {
    let study = &run.results.study;
    let dir = out.join(study.name());
    let staged = super::replace::Staged::begin(&dir)?;
    study.write_side_files(staged.dir(), &run.outputs)?;
    write_json(&staged.dir().join("results.json"), &run.results, true)?;
    staged.commit()?;
    Ok(dir)
}

/// Read the `results.json` of a kind-`K` study folder.
pub fn read<K: StudyKind>(dir: &Path) -> Result<Results<K>, StudyError> {
    read_results(dir)
}
