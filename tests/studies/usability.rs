//! The `study` binary as a researcher uses it: ParaView output read back by an independent
//! reader (Python meshio), a sweep killed part-way and resumed, and results that do not
//! depend on the number of threads.

use igimp::study::column::kind::read_points_csv;
use igimp::study::column::records::ColumnResults as StudyResults;
use igimp::study::results::read_results;
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

fn study_bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_study"))
}

/// A column study with three small cases (iGIMP, MPM, quadratic FEM); `resume` tampers with
/// their records.
pub(crate) const TINY: &str = r#"
schema = 1
name = "tiny"
summary = "three small column cases"
problem = "column"
report_file = "table.md"
load_steps = 4
[column]
length = 50.0
density = 80.0
[material]
model = "von-mises"
young_modulus = 1.0e6
poisson_ratio = 0.0
yield_stress = 20000.0
[newton]
tolerance = 1.0e-9
max_iterations = 30
[[sweeps]]
id = "a"
title = "small cases"
methods = ["igimp", "mpm", "fem-quadratic"]
weights = [40000.0]
elements = [8]
points_per_cell = [2]
"#;

/// Six iGIMP cases of 0.1-0.6 s each on one thread: long enough to kill the run between cases.
const SLOW: &str = r#"
schema = 1
name = "slow"
summary = "resume test"
problem = "column"
report_file = "table.md"
load_steps = 20
[column]
length = 50.0
density = 80.0
[material]
model = "linear-elastic"
young_modulus = 1.0e6
poisson_ratio = 0.0
[newton]
tolerance = 1.0e-9
max_iterations = 30
[[sweeps]]
id = "big"
title = "big cases"
methods = ["igimp"]
weights = [40000.0]
elements = [1024, 2048]
points_per_cell = [2, 3, 4]
"#;

fn write_study(dir: &Path, name: &str, text: &str) -> PathBuf {
    let studies = dir.join("studies");
    std::fs::create_dir_all(&studies).unwrap();
    std::fs::write(studies.join(format!("{name}.toml")), text).unwrap();
    studies
}

fn run(dir: &Path, name: &str, out: &str, threads: usize, extra: &[&str]) -> String {
    run_with(&dir.join("studies"), name, &dir.join(out), threads, extra)
}

/// Run study `name` of the folder `studies` into `out`; its stderr.
fn run_with(studies: &Path, name: &str, out: &Path, threads: usize, extra: &[&str]) -> String {
    let output = study_bin()
        .arg(name)
        .arg("--studies-dir")
        .arg(studies)
        .arg("--out")
        .arg(out)
        .args(extra)
        .env("RAYON_NUM_THREADS", threads.to_string())
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&output.stderr).into_owned();
    assert!(output.status.success(), "study {name} failed:\n{stderr}");
    stderr
}

fn results(dir: &Path, out: &str, name: &str) -> StudyResults {
    read_results(&dir.join(out).join(name)).unwrap()
}

/// Is `python3 -c "import meshio"` available? In CI (`CI=true`) its absence is a failure.
fn meshio_available() -> bool {
    let ok = Command::new("python3")
        .args(["-c", "import meshio"])
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status()
        .is_ok_and(|s| s.success());
    if !ok {
        let ci = std::env::var("CI").is_ok_and(|v| v == "true" || v == "1");
        assert!(!ci, "python3 with meshio is required in CI (.ci/run installs it)");
        eprintln!("SKIPPED: python3 with the meshio package is not available (pip install meshio)");
    }
    ok
}

/// Read VTU files with meshio: for each file its points, cell blocks and point arrays.
fn meshio_read(files: &[PathBuf]) -> Value {
    const SCRIPT: &str = r#"
import json, sys, meshio
out = {}
for path in sys.argv[1:]:
    m = meshio.read(path)
    out[path] = {
        "points": m.points.tolist(),
        "cells": [[c.type, c.data.tolist()] for c in m.cells],
        "data": {k: v.tolist() for k, v in m.point_data.items()},
    }
print(json.dumps(out))
"#;
    let output = Command::new("python3")
        .arg("-c")
        .arg(SCRIPT)
        .args(files)
        .output()
        .unwrap();
    assert!(
        output.status.success(),
        "meshio failed: {}",
        String::from_utf8_lossy(&output.stderr)
    );
    serde_json::from_slice(&output.stdout).unwrap()
}

fn column(v: &Value, name: &str, component: usize) -> Vec<f64> {
    v["data"][name]
        .as_array()
        .unwrap_or_else(|| panic!("no array {name}"))
        .iter()
        .map(|row| row[component].as_f64().unwrap())
        .collect()
}

/// `--vtk` files of the final state, read by meshio, hold exactly the point values of the
/// point CSVs and reproduce results.json's top displacement; the grid/mesh has one cell per
/// element.
#[test]
fn vtk_output_read_by_meshio_matches_results_json_and_point_files() {
    if !meshio_available() {
        return;
    }
    let tmp = tempfile::tempdir().unwrap();
    write_study(tmp.path(), "tiny", TINY);
    run(tmp.path(), "tiny", "out", 2, &["--vtk-every", "2"]);
    let sdir = tmp.path().join("out/tiny");
    let res: StudyResults = read_results(&sdir).unwrap();
    assert_eq!(res.cases.len(), 3);
    for case in &res.cases {
        let pvd = std::fs::read_to_string(sdir.join(format!("vtk/{}.pvd", case.id))).unwrap();
        // Steps 0, 2 and 4, each with points and grid.
        assert_eq!(pvd.matches("<DataSet").count(), 6, "{pvd}");
        let pts_file = sdir.join(format!("vtk/{}/points_00004.vtu", case.id));
        let grid_file = sdir.join(format!("vtk/{}/grid_00004.vtu", case.id));
        let all = meshio_read(&[pts_file.clone(), grid_file.clone()]);
        let pts = &all[pts_file.to_str().unwrap()];
        let grid = &all[grid_file.to_str().unwrap()];
        let csv = read_points_csv(&sdir.join(format!("points/{}.csv", case.id))).unwrap();
        assert_eq!(csv.len(), case.points);
        let x: Vec<f64> = pts["points"]
            .as_array()
            .unwrap()
            .iter()
            .map(|p| p[0].as_f64().unwrap())
            .collect();
        let z0 = column(pts, "position0", 0);
        let v0 = column(pts, "volume0", 0);
        let s_zz = column(pts, "cauchy_stress", 0);
        let s_xx = column(pts, "cauchy_stress", 4);
        let f_zz = column(pts, "deformation_gradient", 0);
        let u = column(pts, "displacement", 0);
        let tau = column(pts, "kirchhoff_stress", 0);
        let lam = column(pts, "plastic_multiplier", 0);
        assert_eq!(x.len(), csv.len());
        // CSV columns: z0, z, volume0, sigma_zz, f_zz, sigma_xx, then the material's internal
        // variable plastic_multiplier, as the VTK array of that name (shortest round-trip text
        // in both files, so equality is exact).
        for (p, row) in csv.iter().enumerate() {
            assert_eq!(
                [z0[p], x[p], v0[p], s_zz[p], f_zz[p], s_xx[p], lam[p]],
                row[..7],
                "{} point {p}",
                case.id
            );
            assert_eq!(u[p], x[p] - z0[p]);
            // τ = σ J with J = F_zz in uniaxial strain.
            assert!((tau[p] - s_zz[p] * f_zz[p]).abs() <= 1e-9 * tau[p].abs());
        }
        assert!(
            lam.iter().any(|&l| l > 0.0),
            "{}: the plastic column yields",
            case.id
        );
        let top = z0
            .iter()
            .enumerate()
            .max_by(|a, b| a.1.total_cmp(b.1))
            .map(|(p, _)| u[p])
            .unwrap();
        let cells = grid["cells"].as_array().unwrap();
        let grid_u = column(grid, "displacement", 0);
        if case.method.name().starts_with("fem") {
            assert_eq!(cells[0][0], "line3");
            assert_eq!(cells[0][1].as_array().unwrap().len(), 8);
            // FEM: results.json's top displacement is that of the top node.
            assert_eq!(Some(*grid_u.last().unwrap()), case.top_displacement);
        } else {
            assert_eq!(cells[0][0], "line");
            assert_eq!(cells[0][1].as_array().unwrap().len(), 8);
            assert_eq!(Some(top), case.top_displacement);
            let extent = column(pts, "domain_extent", 0);
            let total: f64 = extent.iter().sum();
            assert!(
                (total - (50.0 + top)).abs() < 1e-2 * 50.0,
                "domains cover the column"
            );
            assert!(grid_u.iter().any(|&v| v < 0.0), "grid displacement is written");
        }
    }
}

/// The column as a 3D prism (`dimension = 3`) writes ParaView files as the 1D column does:
/// iGIMP its points and its 1 × 1 × n background grid of hexahedra, Hex8 and Hex20 their Gauss
/// points and their mesh (VTK hexahedra and quadratic hexahedra in our node order), at every
/// step; the top displacement read back equals the solver's.
#[test]
fn column_3d_writes_points_and_hexahedral_grids_read_by_meshio() {
    use igimp::basis::method::Method;
    use igimp::problems::column::{solve_column_observed, ColumnSpec};
    use igimp::study::vtk_output::{ColumnVtkWriter, VtkOptions};
    let tmp = tempfile::tempdir().unwrap();
    let spec = ColumnSpec {
        dimension: 3,
        elements: 4,
        load_steps: 2,
        ..ColumnSpec::default()
    };
    for (method, cell, nodes) in [
        (Method::IGIMP, "hexahedron", 8),
        (Method::FEM_HEX8, "hexahedron", 8),
        (Method::FEM_HEX20, "hexahedron20", 20),
    ] {
        let id = method.name();
        let mut w = ColumnVtkWriter::new(tmp.path(), id, spec.load_steps, VtkOptions { every: 1 }).unwrap();
        let outcome =
            solve_column_observed(&spec, method, &mut |step, state| w.observe(step, state)).unwrap();
        assert!(outcome.failure.is_none(), "{id}");
        let pvd = std::fs::read_to_string(w.finish().unwrap()).unwrap();
        // Steps 0, 1 and 2, each with points and grid.
        assert_eq!(pvd.matches("<DataSet").count(), 6, "{pvd}");
        if !meshio_available() {
            return;
        }
        let pts_file = tmp.path().join(format!("vtk/{id}/points_00002.vtu"));
        let grid_file = tmp.path().join(format!("vtk/{id}/grid_00002.vtu"));
        let all = meshio_read(&[pts_file.clone(), grid_file.clone()]);
        let (pts, grid) = (
            &all[pts_file.to_str().unwrap()],
            &all[grid_file.to_str().unwrap()],
        );
        let cells = grid["cells"].as_array().unwrap();
        assert_eq!(cells[0][0], cell, "{id}");
        let conn = cells[0][1].as_array().unwrap();
        assert_eq!(conn.len(), spec.elements, "{id}: one cell per element");
        assert!(conn.iter().all(|c| c.as_array().unwrap().len() == nodes));
        let n_points = pts["points"].as_array().unwrap().len();
        assert_eq!(n_points, outcome.points.len(), "{id}");
        let (z0, uz) = (column(pts, "position0", 2), column(pts, "displacement", 2));
        let grid_uz = column(grid, "displacement", 2);
        let top = if method == Method::IGIMP {
            let p = (0..n_points).max_by(|&a, &b| z0[a].total_cmp(&z0[b])).unwrap();
            uz[p]
        } else {
            // Every top node of the prism moves alike (uniaxial strain).
            grid_uz.iter().copied().fold(f64::INFINITY, f64::min)
        };
        assert!(
            (top - outcome.top_displacement).abs() <= 1e-12 * outcome.top_displacement.abs(),
            "{id}: {top} vs {}",
            outcome.top_displacement
        );
        assert!(
            grid_uz.iter().any(|&v| v < 0.0),
            "{id}: grid displacement is written"
        );
    }
}

fn resumed_count(stderr: &str) -> (usize, usize) {
    let line = stderr
        .lines()
        .find(|l| l.contains("resumed"))
        .unwrap_or_else(|| panic!("no resume line in:\n{stderr}"));
    let words: Vec<&str> = line.split_whitespace().collect();
    let at = words.iter().position(|w| *w == "resumed").unwrap();
    (words[at + 1].parse().unwrap(), words[at + 3].parse().unwrap())
}

/// Spawn `cmd`, wait until a first case file appears in `cases`, and kill it.
fn kill_after_first_case(mut cmd: Command, cases: &Path) {
    let mut child = cmd.stderr(Stdio::null()).spawn().unwrap();
    let start = Instant::now();
    let finished = |d: &Path| {
        std::fs::read_dir(d).map_or(0, |r| {
            r.filter_map(|e| e.ok())
                .filter(|e| e.path().extension().is_some_and(|x| x == "json"))
                .count()
        })
    };
    while finished(cases) == 0 {
        assert!(start.elapsed() < Duration::from_secs(120), "no case finished");
        assert!(
            child.try_wait().unwrap().is_none(),
            "run ended before a case was seen"
        );
        std::thread::sleep(Duration::from_millis(2));
    }
    child.kill().unwrap();
    child.wait().unwrap();
}

/// A run killed after its first finished case, rerun with `--resume`, reuses the finished
/// cases, solves the rest and ends with the results.json of an uninterrupted run (wall times
/// aside). Killed on one thread, uninterrupted on two: also a thread-count check.
#[test]
fn killed_sweep_resumes_to_the_uninterrupted_results() {
    let tmp = tempfile::tempdir().unwrap();
    write_study(tmp.path(), "slow", SLOW);
    let cases = tmp.path().join("killed/slow/cases");
    let mut cmd = study_bin();
    cmd.args(["slow", "--studies-dir"])
        .arg(tmp.path().join("studies"))
        .arg("--out")
        .arg(tmp.path().join("killed"))
        .env("RAYON_NUM_THREADS", "1");
    kill_after_first_case(cmd, &cases);
    assert!(
        !tmp.path().join("killed/slow/results.json").exists(),
        "the run finished before it was killed; the cases are too small for this machine"
    );
    let stderr = run(tmp.path(), "slow", "killed", 2, &["--resume"]);
    let (resumed, total) = resumed_count(&stderr);
    assert_eq!(total, 6);
    assert!((1..total).contains(&resumed), "resumed {resumed} of {total}");

    run(tmp.path(), "slow", "clean", 2, &[]);
    let a = results(tmp.path(), "killed", "slow");
    let b = results(tmp.path(), "clean", "slow");
    assert_eq!(a.without_timing(), b.without_timing());
    for c in &a.cases {
        let p = format!("slow/points/{}.csv", c.id);
        let pa = std::fs::read(tmp.path().join("killed").join(&p)).unwrap();
        let pb = std::fs::read(tmp.path().join("clean").join(&p)).unwrap();
        assert_eq!(pa, pb, "{p}");
    }
    // A second --resume solves nothing.
    let stderr = run(tmp.path(), "slow", "killed", 2, &["--resume"]);
    assert_eq!(resumed_count(&stderr), (6, 6));
    // A changed input is solved again: only the cases whose definition changed.
    write_study(
        tmp.path(),
        "slow",
        &SLOW.replace("tolerance = 1.0e-9", "tolerance = 1.0e-10"),
    );
    let stderr = run(tmp.path(), "slow", "killed", 2, &["--resume"]);
    assert_eq!(resumed_count(&stderr), (0, 6));
}

/// The quick tier of both column studies gives identical results.json numbers and point
/// files on one and on two threads; only the `timing` block and `wall_seconds` differ.
#[test]
fn results_identical_on_one_and_two_threads() {
    let tmp = tempfile::tempdir().unwrap();
    let studies = Path::new(env!("CARGO_MANIFEST_DIR")).join("studies");
    for (threads, out) in [(1, "t1"), (2, "t2")] {
        let o = study_bin()
            .args(["column", "column-plastic", "--quick", "--studies-dir"])
            .arg(&studies)
            .arg("--out")
            .arg(tmp.path().join(out))
            .env("RAYON_NUM_THREADS", threads.to_string())
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    }
    for name in ["column", "column-plastic"] {
        let a = results(tmp.path(), "t1", name);
        let b = results(tmp.path(), "t2", name);
        assert_eq!(a.timing.threads, 1);
        assert_eq!(b.timing.threads, 2);
        assert_eq!(a.without_timing(), b.without_timing(), "{name}");
        // Byte-level: the JSON text differs only in wall-clock fields.
        let strip = |out: &str| -> Value {
            let text = std::fs::read_to_string(tmp.path().join(out).join(name).join("results.json")).unwrap();
            let mut v: Value = serde_json::from_str(&text).unwrap();
            v["timing"] = Value::Null;
            for c in v["cases"].as_array_mut().unwrap() {
                c["wall_seconds"] = Value::Null;
            }
            v
        };
        assert_eq!(strip("t1"), strip("t2"), "{name}");
        for c in &a.cases {
            let p = format!("{name}/points/{}.csv", c.id);
            assert_eq!(
                std::fs::read(tmp.path().join("t1").join(&p)).unwrap(),
                std::fs::read(tmp.path().join("t2").join(&p)).unwrap(),
                "{p}"
            );
        }
    }
}

/// The 2D studies honour `--resume` and `--vtk` as the column does: the compaction run is
/// killed after its first finished case and resumed, the cantilever loses half its stored
/// cases and is resumed; both end with the results.json of an uninterrupted run (timing
/// aside), and meshio reads the domains of the final frame back equal to domains.json. The
/// study files without their basis-family sweeps (`trimmed`): the harness under test is the
/// same for every method, and the families would triple the runs.
#[test]
fn plane_studies_resume_and_write_vtk() {
    use igimp::study::{cantilever, compaction};
    let tmp = tempfile::tempdir().unwrap();
    let studies = tmp.path().join("studies");
    crate::trimmed::write(&studies, "compaction", &["families", "families-ghost"]);
    crate::trimmed::write(&studies, "cantilever", &["families"]);
    let quick = |name: &str, out: &str, extra: &[&str]| {
        let mut args = vec!["--quick"];
        args.extend_from_slice(extra);
        run_with(&studies, name, &tmp.path().join(out), 2, &args)
    };
    let cases = tmp.path().join("killed/compaction/cases");
    let mut cmd = study_bin();
    cmd.args(["compaction", "--quick", "--vtk", "--studies-dir"])
        .arg(&studies)
        .arg("--out")
        .arg(tmp.path().join("killed"))
        .env("RAYON_NUM_THREADS", "1");
    kill_after_first_case(cmd, &cases);
    assert!(!tmp.path().join("killed/compaction/results.json").exists());
    let stderr = quick("compaction", "killed", &["--resume", "--vtk"]);
    let (resumed, total) = resumed_count(&stderr);
    assert!((1..total).contains(&resumed), "resumed {resumed} of {total}");
    quick("compaction", "clean", &[]);
    let a = read_results::<compaction::CompactionResults>(&tmp.path().join("killed/compaction")).unwrap();
    let b = read_results::<compaction::CompactionResults>(&tmp.path().join("clean/compaction")).unwrap();
    assert_eq!(a.without_timing(), b.without_timing());

    quick("cantilever", "killed", &["--vtk"]);
    let stored = tmp.path().join("killed/cantilever/cases");
    let mut files: Vec<PathBuf> = std::fs::read_dir(&stored)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    files.sort();
    for f in files.iter().step_by(2) {
        std::fs::remove_file(f).unwrap();
    }
    std::fs::remove_file(tmp.path().join("killed/cantilever/results.json")).unwrap();
    let stderr = quick("cantilever", "killed", &["--resume", "--vtk"]);
    let (resumed, total) = resumed_count(&stderr);
    assert_eq!(resumed, total - files.len().div_ceil(2), "{stderr}");
    quick("cantilever", "clean", &[]);
    let a = read_results::<cantilever::CantileverResults>(&tmp.path().join("killed/cantilever")).unwrap();
    let b = read_results::<cantilever::CantileverResults>(&tmp.path().join("clean/cantilever")).unwrap();
    assert_eq!(a.without_timing(), b.without_timing());

    // ParaView files: one .pvd per iGIMP case; the final frame of Figure 15's case holds the
    // domains of domains.json.
    let vtk = tmp.path().join("killed/compaction/vtk");
    for c in a
        .cases
        .iter()
        .filter(|c| c.method == igimp::basis::method::Method::IGIMP)
    {
        assert!(
            tmp.path()
                .join(format!("killed/cantilever/vtk/{}.pvd", c.id))
                .is_file(),
            "{}",
            c.id
        );
    }
    if !meshio_available() {
        return;
    }
    let id = "igimp-elastic-h1-p2";
    let last = vtk.join(id).join("domains_00020.vtu");
    assert!(
        vtk.join(id).join("grid.vtu").is_file(),
        "the background grid is written"
    );
    let domains: Value =
        serde_json::from_slice(&std::fs::read(tmp.path().join("killed/compaction/domains.json")).unwrap())
            .unwrap();
    let doms = domains[id].as_array().unwrap();
    const SCRIPT: &str = r#"
import json, sys, meshio
m = meshio.read(sys.argv[1])
print(json.dumps({"type": m.cells[0].type, "n": len(m.cells[0].data),
                  "centre": m.cell_data["centre"][0].tolist(),
                  "sigma_yy": m.cell_data["sigma_yy"][0].reshape(-1).tolist()}))
"#;
    let out = Command::new("python3")
        .arg("-c")
        .arg(SCRIPT)
        .arg(&last)
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let m: Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(m["type"], "quad");
    assert_eq!(m["n"].as_u64().unwrap() as usize, doms.len());
    for (p, d) in doms.iter().enumerate() {
        for a in 0..2 {
            let (v, r) = (m["centre"][p][a].as_f64().unwrap(), d["x"][a].as_f64().unwrap());
            assert!((v - r).abs() <= 1e-12 * r.abs().max(1.0), "point {p}: {v} vs {r}");
        }
        let (v, r) = (
            m["sigma_yy"][p].as_f64().unwrap(),
            d["sigma_yy"].as_f64().unwrap(),
        );
        assert!((v - r).abs() <= 1e-12 * r.abs().max(1.0), "point {p}: {v} vs {r}");
    }
}

/// `--shard K/N` then `--merge` gives the results.json of an unsharded run (timing aside) for
/// a column and a plane-strain study (the compaction's quick tier cut to Figure 17 at h = 1,
/// 1/2 with 2x2 points and its FEM reference sweep: the subject is the store and the merge,
/// not the numbers; the whole quick tier ran twice here, 74 s of the suite); shards write no
/// results.json; `--merge` with a shard
/// missing fails naming the cases no shard stored.
#[test]
fn sharded_runs_merge_to_the_unsharded_results() {
    use igimp::study::compaction;
    let tmp = tempfile::tempdir().unwrap();
    write_study(tmp.path(), "tiny", TINY);
    let studies = tmp.path().join("studies");
    let repo = crate::trimmed::write(
        &tmp.path().join("cut"),
        "compaction",
        &[
            "plastic",
            "plastic-ghost",
            "ghost",
            "weak-nodes",
            "families",
            "families-ghost",
        ],
    );
    // Figure 17's sweep (the reference names it) at h = 1 and 1/2 with 2x2 points only.
    let cut = repo.join("compaction.toml");
    let mut doc: toml::Table = std::fs::read_to_string(&cut).unwrap().parse().unwrap();
    let sweeps = doc["sweeps"].as_array_mut().unwrap();
    let fig17 = sweeps
        .iter_mut()
        .find(|t| t["id"].as_str() == Some("fig17"))
        .unwrap();
    fig17["quick"] = toml::toml! { element_sizes = [1.0, 0.5] points_per_cell = [2] }.into();
    std::fs::write(&cut, toml::to_string(&doc).unwrap()).unwrap();
    let n = 3;
    for k in 0..n {
        let shard = format!("{k}/{n}");
        let stderr = run_with(
            &studies,
            "tiny",
            &tmp.path().join("sharded"),
            1,
            &["--shard", &shard],
        );
        assert!(stderr.contains(&format!("shard {k}/{n}")), "{stderr}");
        if k == 0 {
            // Merging before every shard has run names what is missing.
            let out = study_bin()
                .args(["tiny", "--merge", "--studies-dir"])
                .arg(&studies)
                .arg("--out")
                .arg(tmp.path().join("sharded"))
                .output()
                .unwrap();
            let err = String::from_utf8_lossy(&out.stderr);
            assert!(
                !out.status.success() && err.contains("not stored by any shard"),
                "{err}"
            );
        }
        run_with(
            &repo,
            "compaction",
            &tmp.path().join("sharded"),
            1,
            &["--quick", "--shard", &shard],
        );
    }
    assert!(!tmp.path().join("sharded/tiny/results.json").exists());
    assert!(!tmp.path().join("sharded/compaction/results.json").exists());
    run_with(&studies, "tiny", &tmp.path().join("sharded"), 2, &["--merge"]);
    run_with(
        &repo,
        "compaction",
        &tmp.path().join("sharded"),
        2,
        &["--quick", "--merge"],
    );
    run(tmp.path(), "tiny", "whole", 2, &[]);
    run_with(&repo, "compaction", &tmp.path().join("whole"), 2, &["--quick"]);
    assert_eq!(
        results(tmp.path(), "sharded", "tiny").without_timing(),
        results(tmp.path(), "whole", "tiny").without_timing()
    );
    let a = read_results::<compaction::CompactionResults>(&tmp.path().join("sharded/compaction")).unwrap();
    let b = read_results::<compaction::CompactionResults>(&tmp.path().join("whole/compaction")).unwrap();
    assert_eq!(a.without_timing(), b.without_timing());
}

/// 3D domains go to ParaView as hexahedra (VTK order): meshio reads one `hexahedron` per
/// point whose 8 corners are centre ± half-lengths, with the cell data in point order.
#[test]
fn vtk_3d_domains_are_hexahedra_read_by_meshio() {
    use igimp::study::vtk_output::{write_domain_frames, DomainBox, DomainFrame};
    let tmp = tempfile::tempdir().unwrap();
    let domains = vec![
        DomainBox {
            centre: [0.25, 0.25, 0.25],
            half: [0.25, 0.25, 0.25],
        },
        DomainBox {
            centre: [1.0, 2.0, 3.0],
            half: [0.1, 0.2, 0.3],
        },
    ];
    let frame = DomainFrame {
        time: 1.0,
        step: 3,
        dimension: 3,
        domains: domains.clone(),
        scalars: vec![("sigma_zz".into(), vec![-1.0, -2.0])],
    };
    let grid = igimp::mesh::grid::Grid::<3>::try_new([0.0; 3], [0.5, 1.0, 0.25], [2, 1, 3]).unwrap();
    let grid = igimp::study::vtk::background_grid(&grid, &[]);
    let pvd = write_domain_frames(tmp.path(), "case", &[frame], Some(&grid)).unwrap();
    // The background grid is part 1 of the time step.
    let text = std::fs::read_to_string(&pvd).unwrap();
    assert!(text.contains(r#"part="1" file="case/grid.vtu""#), "{text}");
    if !meshio_available() {
        return;
    }
    let grid_file = tmp.path().join("vtk/case/grid.vtu");
    let g = &meshio_read(std::slice::from_ref(&grid_file))[grid_file.to_str().unwrap()];
    assert_eq!(g["cells"][0][0], "hexahedron");
    assert_eq!(g["cells"][0][1].as_array().unwrap().len(), 6);
    let top = g["points"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| {
            [
                p[0].as_f64().unwrap(),
                p[1].as_f64().unwrap(),
                p[2].as_f64().unwrap(),
            ]
        })
        .fold([0.0f64; 3], |m, p| std::array::from_fn(|a| m[a].max(p[a])));
    assert_eq!(
        top,
        [1.0, 1.0, 0.75],
        "the grid spans 2 x 1 x 3 cells of 0.5 x 1 x 0.25"
    );
    const SCRIPT: &str = r#"
import json, sys, meshio
m = meshio.read(sys.argv[1])
c = m.cells[0]
print(json.dumps({"type": c.type, "corners": [[m.points[i].tolist() for i in cell] for cell in c.data],
                  "sigma_zz": m.cell_data["sigma_zz"][0].reshape(-1).tolist()}))
"#;
    let out = Command::new("python3")
        .arg("-c")
        .arg(SCRIPT)
        .arg(tmp.path().join("vtk/case/domains_00003.vtu"))
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let m: Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(m["type"], "hexahedron");
    let corners = m["corners"].as_array().unwrap();
    assert_eq!(corners.len(), 2);
    for (d, cell) in domains.iter().zip(corners) {
        let cell = cell.as_array().unwrap();
        assert_eq!(cell.len(), 8);
        for (k, x) in cell.iter().enumerate() {
            // VTK hexahedron order: bottom face (z−) counter-clockwise, then the top face.
            let sign = [
                [-1, -1, -1],
                [1, -1, -1],
                [1, 1, -1],
                [-1, 1, -1],
                [-1, -1, 1],
                [1, -1, 1],
                [1, 1, 1],
                [-1, 1, 1],
            ][k];
            for a in 0..3 {
                let expect = d.centre[a] + sign[a] as f64 * d.half[a];
                assert!(
                    (x[a].as_f64().unwrap() - expect).abs() < 1e-12,
                    "corner {k} axis {a}"
                );
            }
        }
    }
    assert_eq!(m["sigma_zz"], serde_json::json!([-1.0, -2.0]));
}
