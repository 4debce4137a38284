//! The compaction's measures and checks: the Figure 17 reference (Richardson-extrapolated
//! FEM, else the finest FEM mesh, else the finest iGIMP case) and the study file's
//! expectations (deviation, convergence, weak-node and ghost spreads).

use super::records::{CompactionRecord, CompactionResults, ReferenceRecord};
use crate::basis::method::Method;
use crate::study::checks::{check_at_most, relative_spread, richardson, CheckRecord, GciRecord};
use crate::study::results::CaseStatus;
use crate::study::vocabulary::{number, points_grid};
use std::collections::BTreeSet;

pub(super) fn figure17_reference(results: &CompactionResults) -> Option<ReferenceRecord> {
    let mut fem: Vec<&CompactionRecord> = results
        .sweep(&results.study.reference.fem_sweep)
        .into_iter()
        .filter(|c| c.method.is_fem() && c.max_horizontal_displacement.is_some())
        .collect();
    fem.sort_by(|a, b| b.h.total_cmp(&a.h));
    if let Some(finest) = fem.last() {
        let n = fem.len();
        let u = |c: &CompactionRecord| c.max_horizontal_displacement.unwrap_or(f64::NAN);
        if n >= 3 {
            let (a, b, c) = (fem[n - 3], fem[n - 2], fem[n - 1]);
            let r = a.h / b.h;
            if ((b.h / c.h) - r).abs() < 1e-9 * r {
                if let Some((limit, p)) = richardson([u(a), u(b), u(c)], r) {
                    return Some(ReferenceRecord {
                        value: limit,
                        method: finest.method,
                        cases: vec![a.id.clone(), b.id.clone(), c.id.clone()],
                        observed_order: Some(p),
                        description: format!(
                            "{} extrapolated from h = {}, {}, {} (observed order {p:.2})",
                            finest.method.label(),
                            a.h,
                            b.h,
                            c.h
                        ),
                    });
                }
            }
        }
        return Some(ReferenceRecord {
            value: u(finest),
            method: finest.method,
            cases: vec![finest.id.clone()],
            observed_order: None,
            description: format!("finest {} mesh, h = {}", finest.method.label(), finest.h),
        });
    }
    let finest = results
        .sweep(&results.study.reference.igimp_sweep)
        .into_iter()
        .filter(|c| c.method == Method::IGIMP && c.max_horizontal_displacement.is_some())
        .min_by(|a, b| {
            a.h.total_cmp(&b.h)
                .then(b.points_per_cell.cmp(&a.points_per_cell))
        })?;
    Some(ReferenceRecord {
        value: finest.max_horizontal_displacement?,
        method: Method::IGIMP,
        cases: vec![finest.id.clone()],
        observed_order: None,
        description: format!(
            "finest iGIMP case (h = {}, {} points per cell): the study has no converged FEM reference sweep",
            finest.h,
            points_grid(
                finest.points_per_cell.unwrap_or(0),
                results.study.block.dimension as usize
            )
        ),
    })
}

/// The methods an expectation checks (iGIMP when it names none), the suffix of its check id
/// (empty for iGIMP alone, so that the paper's checks keep their names) and their labels.
fn checked_methods(methods: &[Method]) -> (Vec<Method>, String, String) {
    if methods.is_empty() || methods == [Method::IGIMP] {
        return (vec![Method::IGIMP], String::new(), "iGIMP".to_string());
    }
    (
        methods.to_vec(),
        methods.iter().map(|m| format!("-{}", m.name())).collect(),
        methods.iter().map(|m| m.label()).collect::<Vec<_>>().join(", "),
    )
}

pub(super) fn compute_checks(results: &CompactionResults) -> Vec<CheckRecord> {
    let mut out = vec![];
    let reference = results.measures.reference.as_ref().map(|r| r.value);
    let of = |sweep: &str, methods: &[Method]| -> Vec<&CompactionRecord> {
        results
            .sweep(sweep)
            .into_iter()
            .filter(|c| methods.contains(&c.method) && c.max_horizontal_displacement.is_some())
            .collect()
    };
    let igimp = |sweep: &str| of(sweep, &[Method::IGIMP]);
    let deviation = |c: &CompactionRecord| -> Option<f64> {
        Some((c.max_horizontal_displacement? / reference? - 1.0).abs())
    };
    let against = results
        .measures
        .reference
        .as_ref()
        .map_or("no reference".into(), |r| r.description.clone());
    for e in &results.study.expect_deviation {
        let (methods, named, label) = checked_methods(&e.methods);
        let methods = &methods[..];
        let devs: Vec<f64> = of(&e.sweep, methods)
            .into_iter()
            .filter(|c| c.h <= e.max_element_size)
            .filter_map(deviation)
            .collect();
        let expected = results
            .sweep(&e.sweep)
            .into_iter()
            .filter(|c| methods.contains(&c.method) && c.h <= e.max_element_size)
            .count();
        let measured = (!devs.is_empty()).then(|| devs.iter().copied().fold(0.0, f64::max));
        // A case that did not complete fails the check (its deviation is unknown).
        let measured = measured.map(|m| if devs.len() < expected { f64::INFINITY } else { m });
        out.push(check_at_most(
            &format!(
                "{}{named}-within-{}pc-h{}",
                e.sweep,
                100.0 * e.tolerance,
                e.max_element_size
            ),
            format!(
                "largest abs(u/u_ref − 1) over the {} completed {label} cases with h ≤ {}{} (u_ref: {against})",
                devs.len(),
                e.max_element_size,
                if devs.len() < expected {
                    format!("; {} not completed: fails", expected - devs.len())
                } else {
                    String::new()
                }
            ),
            measured,
            e.tolerance,
            &e.source,
        ));
    }
    for e in &results.study.expect_extrapolation {
        let records: Vec<GciRecord> = series_gci(results, &e.sweep)
            .into_iter()
            .filter(|(m, _)| *m == e.method)
            .map(|(_, g)| g)
            .collect();
        // Worst over the method's points-per-cell series; a series without a GCI in the
        // asymptotic range cannot be compared and fails.
        let measured = records
            .iter()
            .map(|g| match (&g.gci, reference) {
                (Some(x), Some(r)) if x.in_asymptotic_range() => (x.extrapolated / r - 1.0).abs(),
                _ => f64::INFINITY,
            })
            .reduce(f64::max);
        out.push(check_at_most(
            &format!("{}-{}-extrapolated-within-{}pc", e.sweep, e.method.name(), 100.0 * e.tolerance),
            format!(
                "abs(u_ext/u_ref − 1) of the GCI extrapolation of the {} series ({}; a series outside the asymptotic range fails; u_ref: {against})",
                e.method.label(),
                records
                    .iter()
                    .map(|g| format!("{}: {}", g.series, g.note))
                    .collect::<Vec<_>>()
                    .join("; ")
            ),
            measured,
            e.tolerance,
            &e.source,
        ));
    }
    for e in &results.study.expect_convergence {
        let (methods, named, label) = checked_methods(&e.methods);
        let cases = of(&e.sweep, &methods);
        let keys: BTreeSet<(Method, usize)> = cases
            .iter()
            .filter_map(|c| Some((c.method, c.points_per_cell?)))
            .collect();
        let mut worst: Option<f64> = None;
        let mut series = 0;
        for (m, p) in keys {
            let mut s: Vec<&CompactionRecord> = cases
                .iter()
                .copied()
                .filter(|c| c.method == m && c.points_per_cell == Some(p) && results.is_default(c))
                .collect();
            s.sort_by(|a, b| b.h.total_cmp(&a.h));
            let d: Vec<f64> = s.iter().filter_map(|c| deviation(c)).collect();
            if d.len() >= 2 {
                series += 1;
                for w in d.windows(2) {
                    let growth = w[1] - w[0];
                    worst = Some(worst.map_or(growth, |x: f64| x.max(growth)));
                }
            }
        }
        let over = if named.is_empty() {
            String::new()
        } else {
            format!(" ({label})")
        };
        out.push(check_at_most(
            &format!("{}{named}-converges", e.sweep),
            format!(
                "largest growth of abs(u/u_ref − 1) from one element size to the next smaller, over {series} points-per-cell series{over} (u_ref: {against})"
            ),
            worst,
            e.slack,
            &e.source,
        ));
    }
    for e in &results.study.expect_weak_node_spread {
        let cases: Vec<&CompactionRecord> = igimp(&e.sweep)
            .into_iter()
            .filter(|c| c.weak_node_tolerance > 0.0)
            .collect();
        let hs: BTreeSet<u64> = cases.iter().map(|c| c.h.to_bits()).collect();
        let mut worst: Option<f64> = None;
        for h in hs {
            let u: Vec<f64> = cases
                .iter()
                .filter(|c| c.h.to_bits() == h)
                .filter_map(|c| c.max_horizontal_displacement)
                .collect();
            if let Some(spread) = relative_spread(&u) {
                worst = Some(worst.map_or(spread, |w: f64| w.max(spread)));
            }
        }
        out.push(check_at_most(
            &format!("{}-weak-node-spread", e.sweep),
            "largest (max − min)/min of the displacement over the non-zero weak-node tolerances at one element size".into(),
            worst,
            e.tolerance,
            &e.source,
        ));
    }
    for e in &results.study.expect_ghost_spread {
        let (methods, named, label) = checked_methods(&e.methods);
        let cases: Vec<&CompactionRecord> = results
            .sweep(&e.sweep)
            .into_iter()
            .filter(|c| methods.contains(&c.method))
            .filter(|c| c.ghost_gamma > 0.0 && c.h <= e.max_element_size)
            .collect();
        let keys: BTreeSet<(Method, u64, Option<usize>)> = cases
            .iter()
            .map(|c| (c.method, c.h.to_bits(), c.points_per_cell))
            .collect();
        let mut worst: Option<f64> = None;
        let mut gammas: BTreeSet<u64> = BTreeSet::new();
        let mut incomplete = 0;
        for k in keys {
            let group: Vec<&&CompactionRecord> = cases
                .iter()
                .filter(|c| (c.method, c.h.to_bits(), c.points_per_cell) == k)
                .collect();
            gammas.extend(group.iter().map(|c| c.ghost_gamma.to_bits()));
            let u: Vec<f64> = group
                .iter()
                .filter_map(|c| c.max_horizontal_displacement)
                .collect();
            incomplete += group.len() - u.len();
            if let Some(spread) = relative_spread(&u) {
                worst = Some(worst.map_or(spread, |w: f64| w.max(spread)));
            }
        }
        let (g_lo, g_hi) = gammas
            .iter()
            .map(|&b| f64::from_bits(b))
            .fold((f64::MAX, f64::MIN), |(a, b), x| (a.min(x), b.max(x)));
        out.push(check_at_most(
            &format!("{}{named}-ghost-spread", e.sweep),
            format!(
                "largest (max − min)/min of the displacement over ghost γ in [{}, {}] at one element size ≤ {}{} ({incomplete} case(s) not completed count as a failure)",
                number(g_lo),
                number(g_hi),
                e.max_element_size,
                if named.is_empty() {
                    String::new()
                } else {
                    format!(", per method ({label})")
                }
            ),
            if incomplete > 0 { Some(f64::INFINITY) } else { worst },
            e.tolerance,
            &e.source,
        ));
    }
    for e in &results.study.expect_linear_iterations {
        // Σ CG iterations / Newton solves of each converged case that used CG.
        let worst = results
            .sweep(&e.sweep)
            .into_iter()
            .filter(|c| c.solve.status == CaseStatus::Converged)
            .filter_map(|c| {
                let cg: usize = c.solve.steps.iter().map(|s| s.linear_iterations).sum();
                (cg > 0 && c.solve.newton_iterations > 0)
                    .then(|| cg as f64 / c.solve.newton_iterations as f64)
            })
            .reduce(f64::max);
        out.push(check_at_most(
            &format!("{}-cg-iterations", e.sweep),
            "largest mean number of CG iterations per Newton solve of a case solved by CG".into(),
            worst,
            e.max_per_solve,
            &e.source,
        ));
    }
    out
}

/// The GCI of Figure 17's measure for every series (method, points per cell, the study's
/// default treatment) of every sweep with three or more element sizes.
pub(super) fn gci_records(results: &CompactionResults) -> Vec<GciRecord> {
    results
        .study
        .sweeps
        .iter()
        .flat_map(|sw| series_gci(results, &sw.id))
        .map(|(_, g)| g)
        .collect()
}

/// The GCI of every series of one sweep, with its method; none with fewer than three
/// element sizes in the sweep.
fn series_gci(results: &CompactionResults, sweep: &str) -> Vec<(Method, GciRecord)> {
    let mut out = vec![];
    let cases = results.sweep(sweep);
    let hs: BTreeSet<u64> = cases.iter().map(|c| c.h.to_bits()).collect();
    if hs.len() < 3 {
        return out;
    }
    let mut series: Vec<(Method, Option<usize>)> = vec![];
    for c in cases.iter().filter(|c| results.is_default(c)) {
        if !series.contains(&(c.method, c.points_per_cell)) {
            series.push((c.method, c.points_per_cell));
        }
    }
    for (m, ppc) in series {
        let levels: Vec<(f64, f64)> = cases
            .iter()
            .filter(|c| c.method == m && c.points_per_cell == ppc && results.is_default(c))
            .filter_map(|c| Some((c.h, c.max_horizontal_displacement?)))
            .collect();
        let label = match ppc {
            Some(p) => format!(
                "{}, {} points",
                m.label(),
                points_grid(p, results.study.block.dimension as usize)
            ),
            None => m.label().to_string(),
        };
        out.push((
            m,
            GciRecord::of(sweep, label, "max horizontal displacement", levels),
        ));
    }
    out
}
