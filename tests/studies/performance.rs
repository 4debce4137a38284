//! The performance figures of `results.json` (reference/README.md item 35): every step's unknowns and
//! nnz(K) match the problem's size, counted here from the mesh and its supports without the
//! solver's dof map or pattern, and every case's cost block (seconds by phase, heap peak) is
//! present and consistent. The compaction's quick tier, run by the `study` binary (whose
//! allocator counts the heap).

use igimp::basis::method::Method;
use igimp::study::compaction::CompactionResults;
use igimp::study::results::{read_results, CaseStatus};
use std::process::Command;

/// Unknowns and non-zeros of the Q4 compaction at h: an `nx × ny` node-grid block with
/// u_x = 0 on x = 0 and u_y = 0 on y = 0; two dofs couple when their nodes share an element
/// (|Δi|, |Δj| ≤ 1), and the tangent is stored in full.
fn q4_compaction_size(half_width: f64, height: f64, h: f64) -> (usize, usize) {
    let nx = (half_width / h).round() as i64;
    let ny = (height / h).round() as i64;
    let free = |i: i64, j: i64| -> usize { usize::from(i != 0) + usize::from(j != 0) };
    let mut unknowns = 0;
    let mut nnz = 0;
    for i in 0..=nx {
        for j in 0..=ny {
            unknowns += free(i, j);
            for di in -1..=1 {
                for dj in -1..=1 {
                    let (a, b) = (i + di, j + dj);
                    if (0..=nx).contains(&a) && (0..=ny).contains(&b) {
                        nnz += free(i, j) * free(a, b);
                    }
                }
            }
        }
    }
    (unknowns, nnz)
}

#[test]
fn performance_fields_match_the_problem_size_and_add_up() {
    let tmp = tempfile::tempdir().unwrap();
    // Every method the compaction runs (fig17: iGIMP, Q4; plastic: Q8; families: every
    // basis), without the sweeps that only repeat them with other penalties.
    let studies = crate::trimmed::write(
        &tmp.path().join("studies"),
        "compaction",
        &["plastic-ghost", "ghost", "weak-nodes", "families-ghost"],
    );
    let o = Command::new(env!("CARGO_BIN_EXE_study"))
        .args(["compaction", "--quick", "--studies-dir"])
        .arg(&studies)
        .arg("--out")
        .arg(tmp.path())
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let r: CompactionResults = read_results(&tmp.path().join("compaction")).unwrap();
    let (w, ht) = (r.study.block.half_width, r.study.block.height);
    let mut q4 = 0;
    for c in r.cases.iter().filter(|c| c.solve.status == CaseStatus::Converged) {
        assert!(!c.solve.steps.is_empty(), "{}", c.id);
        for s in &c.solve.steps {
            match c.method {
                Method::FEM_Q4 => {
                    let (n, nnz) = q4_compaction_size(w, ht, c.h);
                    assert_eq!((s.unknowns, s.nonzeros), (n, nnz), "{} step {}", c.id, s.step);
                }
                Method::FEM_Q8 => {
                    // Corner and mid-side nodes (no centre node); a corner node couples with
                    // the 21 nodes of its four elements.
                    let (nx, ny) = ((w / c.h).round() as usize, (ht / c.h).round() as usize);
                    let nodes = (2 * nx + 1) * (ny + 1) + (nx + 1) * ny;
                    let n = 2 * nodes - (2 * ny + 1) - (2 * nx + 1);
                    assert_eq!(s.unknowns, n, "{} step {}", c.id, s.step);
                    assert!(s.nonzeros > s.unknowns && s.nonzeros <= 42 * n, "{}", c.id);
                }
                m => {
                    assert!(m.uses_material_points(), "{}", c.id);
                    let Method::MaterialPoint(basis) = m else {
                        unreachable!()
                    };
                    let k = basis.family::<2>().support_nodes();
                    // A point's support has k nodes per axis (3 for GIMP, 4 for the cubic
                    // spline), so two nodes share a point only within k − 1 nodes of each
                    // other: an equation couples with at most 2 (2k − 1)² equations; every
                    // diagonal is stored.
                    let nodes = ((w / c.h).round() as usize + 3) * ((ht / c.h).round() as usize + 3);
                    assert!(
                        s.unknowns > 0 && s.unknowns <= 2 * nodes,
                        "{} {}",
                        c.id,
                        s.unknowns
                    );
                    assert!(
                        s.nonzeros >= s.unknowns && s.nonzeros <= 2 * (2 * k - 1).pow(2) * s.unknowns,
                        "{}: nnz {} for {} unknowns",
                        c.id,
                        s.nonzeros,
                        s.unknowns
                    );
                }
            }
            // Direct solves by LU here: no LDLᵀ factor to count, no CG iterations.
            assert_eq!(s.linear_iterations, 0, "{}", c.id);
        }
        q4 += usize::from(c.method == Method::FEM_Q4);
    }
    assert!(q4 >= 3, "the quick tier has Q4 cases ({q4})");

    let t = &r.timing;
    assert_eq!(t.costs.len(), r.cases.len(), "a cost block for every case");
    for c in &r.cases {
        let k = &t.costs[&c.id];
        let phases = [k.weights, k.constitutive, k.assembly, k.setup, k.solve];
        assert!(phases.iter().all(|&p| p >= 0.0), "{}: {k:?}", c.id);
        // The phases run one after another on the case's own thread: they fit in its wall
        // time (the case's own clock starts before and stops after them).
        let sum: f64 = phases.iter().sum();
        assert!(
            sum <= k.seconds,
            "{}: phases {sum} s > wall {} s",
            c.id,
            k.seconds
        );
        assert_eq!(k.seconds, t.cases[&c.id], "{}", c.id);
        if c.solve.status == CaseStatus::Converged {
            assert!(
                k.constitutive > 0.0 && k.assembly > 0.0 && k.setup > 0.0,
                "{}: {k:?}",
                c.id
            );
            // The tangent alone takes 16 bytes a non-zero (value and row index).
            let nnz = c.solve.steps.iter().map(|s| s.nonzeros).max().unwrap() as u64;
            let heap = k.heap_peak_bytes.expect("the study binary counts the heap");
            assert!(heap >= 16 * nnz, "{}: heap peak {heap} B for nnz {nnz}", c.id);
            assert!(heap < 1 << 32, "{}: heap peak {heap} B for a quick case", c.id);
        }
    }
    assert!(t.peak_resident_bytes.is_some_and(|b| b > 0));
    let report = std::fs::read_to_string(tmp.path().join("compaction/report.md")).unwrap();
    assert!(report.contains("## Linear systems") && report.contains("## Cost"));
}
