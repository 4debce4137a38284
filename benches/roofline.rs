//! The roofline of the tangent assembly: the machine's memory bandwidth (a STREAM triad) and
//! peak FMA rate, and the assembly's achieved flop/s and bytes/s against them.
//!
//! `cargo bench --bench roofline -- [2d|3d] [points]` (default: both, 1e5 points each;
//! `ROOFLINE_ORDER=cells` numbers the points cell by cell, `MpmSolver::sort_points_by_cell`). Prints
//! the triad bandwidth (best of 10 over three 256 MiB arrays, 24 bytes per element as STREAM
//! counts them), the FMA peak of the hardware (AVX2 + FMA, 4 lanes, 10 independent chains per
//! thread, when the CPU has them) and of the build's own target (two-lane SSE2 multiply + add:
//! the crate is compiled for baseline x86-64, so that is the ceiling its kernels can reach),
//! then for the filled manufactured square or cube (iGIMP, 2 points per cell per axis, after
//! one evaluation at a small increment) the tangent assembly's time (best of 3), its flops and
//! bytes counted from the kernel's loops, and the roofline bound max(flops / peak, bytes /
//! bandwidth) with the measured time's ratio to it; then the block kernel's alone: the
//! assembly's time less that of the points' constitutive tangents (timed alone) against the
//! bound of the kernel's own flops and the same bytes.
//!
//! Counts, per point with m support nodes in D dimensions (src/discretise/assembly.rs,
//! `assemble_tangent`): spatial gradients 2 m D² flops; per column (b, k) of the local block
//! the D × D product C = a G_b V (2 D³ + D² flops) and the column m D × D dot products
//! (2 m D² flops); the point's spatial tangent a_ijkl (src/material/kinematics.rs,
//! `spatial_tangent_eigen`, the elastic model's constant D^alg): the divided differences of
//! ln (6 × 3 + 3 × 2 flops, the logarithms not counted), σ = τ / J (9), and per active (k, l)
//! the eigenbasis strain rate (9 × 7), its rotation Q Ĥ Qᵀ (2 × 54), D^alg : de (162) and the
//! D² entries (2 D²). Bytes: per run of consecutive points with the same nodes (summed in a
//! cache-resident block before it is added), each entry's value read and written in the
//! sparse matrix (16 (mD)²); per point, the fields of its trial state the kernel reads (ΔF⁻¹,
//! V, τ, the eigenvalues and eigenvectors of b^e, J: 8 (D² + 23) bytes) and its support (m
//! node numbers and m D gradients: 8 m (1 + D)). Index scans, the equation lookups, the
//! summing of a run's blocks and the transposes are not counted: the bound is a lower one.
use igimp::basis::method::Method;
use igimp::mpm::MpmSolver;
use igimp::problems::manufactured::{self, ManufacturedSpec};
use igimp::solver::load_stepping::LoadStepping;
use igimp::solver::newton::NonlinearSystem;
use rayon::prelude::*;
use std::hint::black_box;
use std::time::Instant;

/// Bytes per second of a = b + s c over 2^25-element arrays, best of 10.
fn triad_bandwidth() -> f64 {
    let n = 1usize << 25;
    let chunk = 1 << 16;
    let (mut a, b, c) = (vec![0.0f64; n], vec![1.0f64; n], vec![2.0f64; n]);
    let s = 3.0;
    let mut best = f64::INFINITY;
    for _ in 0..10 {
        let t = Instant::now();
        a.par_chunks_mut(chunk)
            .zip(b.par_chunks(chunk))
            .zip(c.par_chunks(chunk))
            .for_each(|((a, b), c)| {
                for i in 0..a.len() {
                    a[i] = b[i] + s * c[i];
                }
            });
        best = best.min(t.elapsed().as_secs_f64());
        black_box(&a);
    }
    24.0 * n as f64 / best
}

/// Flops of `iters` rounds of 10 independent 4-lane FMA chains (AVX2 + FMA).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
unsafe fn fma_chains(iters: u64) -> f64 {
    use std::arch::x86_64::*;
    let mut acc = [_mm256_set1_pd(1.0); 10];
    let (x, y) = (_mm256_set1_pd(0.999_999), _mm256_set1_pd(1e-7));
    for _ in 0..iters {
        for a in acc.iter_mut() {
            *a = _mm256_fmadd_pd(*a, x, y);
        }
    }
    let mut out = [0.0; 4];
    let mut sum = _mm256_setzero_pd();
    for a in acc {
        sum = _mm256_add_pd(sum, a);
    }
    _mm256_storeu_pd(out.as_mut_ptr(), sum);
    black_box(out);
    (iters * 10 * 4 * 2) as f64
}

/// Flops of `iters` rounds of 12 independent multiply-add chains as the build compiles them
/// (baseline x86-64: SSE2, two lanes, no fused multiply-add).
fn mul_add_chains(iters: u64) -> f64 {
    let mut acc = [1.0f64; 12];
    let (x, y) = (black_box(0.999_999), black_box(1e-7));
    for _ in 0..iters {
        for a in acc.iter_mut() {
            *a = *a * x + y;
        }
    }
    black_box(acc);
    (iters * 12 * 2) as f64
}

/// Flop/s of `kernel` run on every thread at once, best of 5.
fn peak(kernel: impl Fn(u64) -> f64 + Sync) -> f64 {
    let threads = rayon::current_num_threads();
    let iters = 50_000_000;
    let mut best: f64 = 0.0;
    for _ in 0..5 {
        let t = Instant::now();
        let flops: f64 = (0..threads).into_par_iter().map(|_| kernel(iters)).sum();
        best = best.max(flops / t.elapsed().as_secs_f64());
    }
    best
}

/// What one assembly measured: its time (best of 3), the time of its points' constitutive
/// tangents alone (best of 3), the counted flops of the block kernel and of the constitutive
/// tangents, and the counted bytes.
struct Assembly {
    time: f64,
    constitutive: f64,
    flops: f64,
    constitutive_flops: f64,
    bytes: f64,
}

/// [`Assembly`] of the solver's first step at a small increment.
fn assembly<const D: usize>(mut solver: MpmSolver<D>) -> Assembly {
    // `ROOFLINE_ORDER=cells`: the points renumbered cell by cell, so that a cell's points
    // are added as one run (the byte count follows the runs); default: the row-by-row
    // lattice of the studies.
    if std::env::var("ROOFLINE_ORDER").as_deref() == Ok("cells") {
        solver.sort_points_by_cell();
    }
    let load = 1.0 / solver.load_steps() as f64;
    solver
        .with_step_system(load, |sys| {
            let n = sys.num_unknowns();
            let u: Vec<f64> = (0..n)
                .map(|i| 1e-4 * ((i * 7919 % 101) as f64 / 50.0 - 1.0))
                .collect();
            let mut r = vec![0.0; n];
            sys.evaluate(&u, &mut r).expect("an evaluation");
            let mut best = f64::INFINITY;
            for _ in 0..3 {
                let t = Instant::now();
                sys.assemble_tangent();
                best = best.min(t.elapsed().as_secs_f64());
            }
            let mut constitutive = f64::INFINITY;
            for _ in 0..3 {
                let t = Instant::now();
                let sum: f64 = (0..sys.states.len())
                    .into_par_iter()
                    .map(|p| {
                        let trial = sys.trials[p].as_ref().expect("evaluated");
                        trial.spatial_tangent(sys.model, &sys.states[p])[(0, 0)]
                    })
                    .sum();
                black_box(sum);
                constitutive = constitutive.min(t.elapsed().as_secs_f64());
            }
            let (d, table) = (D as f64, sys.table);
            let (mut flops, mut bytes) = (0.0, 0.0);
            let mut previous: Option<&[usize]> = None;
            for p in 0..table.num_points() {
                let nodes = table.point(p).0;
                let m = nodes.len() as f64;
                let md2 = (m * d) * (m * d);
                flops += 2.0 * m * d * d + m * d * (2.0 * d * d * d + d * d + 2.0 * m * d * d);
                if previous != Some(nodes) {
                    bytes += 16.0 * md2;
                }
                bytes += 8.0 * (d * d + 23.0) + 8.0 * m * (1.0 + d);
                previous = Some(nodes);
            }
            let per_point = 24.0 + 9.0 + d * d * (9.0 * 7.0 + 2.0 * 54.0 + 162.0 + 2.0 * d * d);
            Assembly {
                time: best,
                constitutive,
                flops,
                constitutive_flops: per_point * table.num_points() as f64,
                bytes,
            }
        })
        .expect("the first step's system")
}

/// (cells per side, points, [`Assembly`]) of the filled manufactured square (`d` = 2) or cube
/// (3) with about `points` points, 2 per cell per axis.
fn filled_field_assembly(d: usize, points: f64) -> (usize, usize, Assembly) {
    let cells = (points / (1 << d) as f64).powf(1.0 / d as f64).round().max(2.0) as usize;
    let spec = ManufacturedSpec {
        cells,
        dimension: d,
        ..Default::default()
    };
    let a = if d == 2 {
        assembly(manufactured::mpm_solver(&spec, Method::IGIMP).expect("plane solver"))
    } else {
        assembly(igimp::problems::manufactured3d::mpm_solver_3d(&spec, Method::IGIMP).expect("cube solver"))
    };
    (cells, cells.pow(d as u32) * (1 << d), a)
}

fn report(label: &str, a: &Assembly, peak: f64, bandwidth: f64) {
    let Assembly {
        time,
        constitutive,
        flops,
        constitutive_flops,
        bytes,
    } = *a;
    let all = flops + constitutive_flops;
    let bound = (all / peak).max(bytes / bandwidth);
    let kernel_bound = (flops / peak).max(bytes / bandwidth);
    println!(
        "{label}: assembly {time:.3} s, of which constitutive tangents {constitutive:.3} s | {:.2} Gflop, {:.2} of them constitutive ({:.2} Gflop/s, {:.0} % of the build's peak) | {:.2} GB ({:.2} GB/s, {:.0} % of the triad) | roofline bound {bound:.3} s ({}) | measured / bound {:.2}; the block kernel alone (time and flops of the constitutive tangents left out) {:.2}",
        all / 1e9,
        constitutive_flops / 1e9,
        all / time / 1e9,
        100.0 * all / time / peak,
        bytes / 1e9,
        bytes / time / 1e9,
        100.0 * bytes / time / bandwidth,
        if all / peak > bytes / bandwidth { "compute" } else { "memory" },
        time / bound,
        (time - constitutive) / kernel_bound
    );
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).filter(|a| !a.starts_with('-')).collect();
    let dims: Vec<usize> = match args.first().map(String::as_str) {
        Some("2d") => vec![2],
        Some("3d") => vec![3],
        _ => vec![2, 3],
    };
    let points: f64 = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(1e5);
    // `ROOFLINE_ASSEMBLY_ONLY=1`: the assembly alone, for a profiler (`perf record`); the
    // machine's figures are then not measured and the ratios not printed.
    let assembly_only = std::env::var("ROOFLINE_ASSEMBLY_ONLY").is_ok_and(|v| v == "1");
    if assembly_only {
        for d in dims {
            let (cells, _, a) = filled_field_assembly(d, points);
            println!(
                "{d}D, {cells} cells per side: assembly {:.3} s, constitutive {:.3} s",
                a.time, a.constitutive
            );
        }
        return;
    }
    let bandwidth = triad_bandwidth();
    #[cfg(target_arch = "x86_64")]
    let hardware = (is_x86_feature_detected!("avx2") && is_x86_feature_detected!("fma"))
        .then(|| peak(|i| unsafe { fma_chains(i) }));
    #[cfg(not(target_arch = "x86_64"))]
    let hardware: Option<f64> = None;
    let build = peak(mul_add_chains);
    println!(
        "{} threads | triad {:.2} GB/s | FMA peak {} | the build's multiply-add peak {:.2} Gflop/s",
        rayon::current_num_threads(),
        bandwidth / 1e9,
        hardware.map_or("— (no AVX2 + FMA)".to_string(), |p| format!(
            "{:.2} Gflop/s (AVX2 + FMA)",
            p / 1e9
        )),
        build / 1e9
    );
    for d in dims {
        let (cells, n, counts) = filled_field_assembly(d, points);
        report(
            &format!("{d}D, {n} points ({cells} cells per side)"),
            &counts,
            build,
            bandwidth,
        );
        if let Some(h) = hardware {
            let all = counts.flops + counts.constitutive_flops;
            println!(
                "    against the hardware FMA peak: {:.1} %, measured / bound {:.2}",
                100.0 * all / counts.time / h,
                counts.time / (all / h).max(counts.bytes / bandwidth)
            );
        }
    }
}
