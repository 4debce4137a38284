//! The column study's Markdown report: Table 1 beside the paper's values, the cases, the
//! fitted rates with their bands and the comparisons.

use super::*;

/// The Markdown report of one study.
pub fn report_markdown(results: &ColumnResults, not_drawn: &[crate::study::render::NotDrawn]) -> String {
    let spec = &results.study;
    let mut s = String::new();
    let _ = writeln!(
        s,
        "# {}: {}\n",
        crate::study::render::md_text(&spec.name),
        crate::study::render::md_text(&spec.summary)
    );
    let _ = writeln!(s, "{}\n", results.provenance.line());
    let (pass, fail, none) = results.check_counts();
    let _ = writeln!(
        s,
        "Checks: {pass} passed, {fail} failed, {none} not evaluated. Cases: {} converged, {} failed, {} rejected.\n",
        results.cases.iter().filter(|c| c.solve.status == CaseStatus::Converged).count(),
        results.cases.iter().filter(|c| c.solve.status == CaseStatus::Failed).count(),
        results.cases.iter().filter(|c| c.solve.status == CaseStatus::Rejected).count(),
    );

    for p in &spec.paper {
        let ppc = p.points_per_cell.map(|n| n as usize);
        let Some(exact) = results.analytical_at(p.weight) else {
            let _ = writeln!(
                s,
                "## {}: no analytical record for W = {} in results.json (solve again)\n",
                p.table, p.weight
            );
            continue;
        };
        let f0 = exact.base_f;
        let _ = writeln!(
            s,
            "## {}: {}, W = {}{}\n",
            p.table,
            Method::label(p.method),
            weight_label(p.weight),
            ppc.map_or(String::new(), |n| format!(", {n} points per cell"))
        );
        let _ = writeln!(
            s,
            "Analytical: top displacement u(L0) = {:.6}, base F(0) = {:.8} (the paper prints {}). \
             F error is eq (47); the paper's values match |F − {}| / {} with its rounded F(0), \
             so both are shown.\n",
            exact.top_displacement, f0, p.analytical_base_f, p.analytical_base_f, p.analytical_base_f
        );
        let ids = of_sweep(results, &p.sweep);
        let cases: Vec<Option<&ColumnRecord>> = p
            .elements
            .iter()
            .map(|&n| {
                series(&results.cases, ids, p.method, p.weight, ppc)
                    .into_iter()
                    .find(|c| c.elements == n as usize && c.solve.status == CaseStatus::Converged)
            })
            .collect();
        let _ = write!(s, "| number of elements |");
        for n in &p.elements {
            let _ = write!(s, " {n} |");
        }
        let _ = write!(s, "\n|---|");
        for _ in &p.elements {
            let _ = write!(s, "---:|");
        }
        s.push('\n');
        let mut row = |name: &str, f: &dyn Fn(usize, Option<&ColumnRecord>) -> String| {
            let _ = write!(s, "| {name} |");
            for (i, c) in cases.iter().enumerate() {
                let _ = write!(s, " {} |", f(i, *c));
            }
            s.push('\n');
        };
        let opt = |x: Option<f64>, f: &dyn Fn(f64) -> String| x.map_or("—".to_string(), f);
        row("top displacement (m), this code", &|_, c| {
            opt(c.and_then(|c| c.top_displacement), &|v| format!("{v:.6}"))
        });
        row("top displacement (m), paper", &|i, _| {
            format!("{:.4}", p.top_displacement[i])
        });
        row("difference", &|i, c| {
            opt(c.and_then(|c| c.top_displacement), &|v| {
                format!("{:+.1e}", v - p.top_displacement[i])
            })
        });
        row("base F, this code", &|_, c| {
            opt(c.and_then(|c| c.base_f), &|v| format!("{v:.6}"))
        });
        row("base F, paper", &|i, _| format!("{:.5}", p.base_f[i]));
        row("difference", &|i, c| {
            opt(c.and_then(|c| c.base_f), &|v| format!("{:+.1e}", v - p.base_f[i]))
        });
        row("F error vs exact F(0), this code", &|_, c| {
            opt(c.and_then(|c| c.f_error), &|v| format!("{v:.3e}"))
        });
        row(
            &format!("F error vs F(0) = {}, this code", p.analytical_base_f),
            &|_, c| {
                opt(c.and_then(|c| c.base_f), &|v| {
                    format!("{:.3e}", (v - p.analytical_base_f).abs() / p.analytical_base_f)
                })
            },
        );
        row("F error, paper", &|i, _| format!("{:.3e}", p.f_error[i]));
        row("relative difference (rounded F(0) convention)", &|i, c| {
            opt(c.and_then(|c| c.base_f), &|v| {
                let e = (v - p.analytical_base_f).abs() / p.analytical_base_f;
                format!("{:+.1}%", 100.0 * (e - p.f_error[i]) / p.f_error[i])
            })
        });
        s.push('\n');
    }

    if spec.plastic() {
        let _ = writeln!(s, "## Yield height\n");
        let _ = writeln!(
            s,
            "Yield starts where the Kirchhoff stress reaches ρy (τzz = −ρy for ν = 0), i.e. at Z_y = L0 − ρy e^(ρy/E) / (ρ0 g); \
             the paper's L0 − ρy/(ρ0 g) equates the Cauchy stress with ρy (reference/README.md, item 6). \
             The computed value is the finest converged iGIMP case's `yield_height`.\n"
        );
        let _ = writeln!(
            s,
            "| W | Z_y, Kirchhoff criterion (this code) | Z_y, paper's formula | finest iGIMP | elements |"
        );
        let _ = writeln!(s, "|---:|---:|---:|---:|---:|");
        let mut loads: Vec<f64> = results.cases.iter().map(|c| c.load).collect();
        loads.sort_by(f64::total_cmp);
        loads.dedup();
        for load in loads {
            let a = results.analytical_at(load);
            let exact = a.and_then(|a| a.yield_height);
            let paper = a.and_then(|a| a.paper_yield_height).unwrap_or(f64::NAN);
            let finest = results
                .cases
                .iter()
                .filter(|c| c.load == load && c.method == Method::IGIMP && c.yield_height.is_some())
                .max_by_key(|c| c.elements);
            let _ = writeln!(
                s,
                "| {} | {} | {paper:.4} | {} | {} |",
                weight_label(load),
                exact.map_or("—".into(), |z| format!("{z:.4}")),
                finest
                    .and_then(|c| c.yield_height)
                    .map_or("—".into(), |z| format!("{z:.4}")),
                finest.map_or("—".into(), |c| c.elements.to_string()),
            );
        }
        s.push('\n');
    }
    let _ = writeln!(s, "## Convergence\n");
    let _ = writeln!(
        s,
        "Error per refinement with the log2 rate log2(e_coarse/e_fine)/log2(n_fine/n_coarse); the \
         fitted slope is the least-squares slope of log(error) against log(h) over the finest \
         element counts listed in the rates table.\n"
    );
    for sweep in &spec.sweeps {
        let Some(plan) = spec.plan(sweep, results.provenance.tier) else {
            continue;
        };
        if plan.elements.len() < 2 {
            continue;
        }
        let ids = of_sweep(results, &sweep.id);
        let _ = writeln!(
            s,
            "### Sweep `{}`: {}\n",
            sweep.id,
            crate::study::render::md_text(&sweep.title)
        );
        for &load in &plan.weights {
            for (m, ppc) in sweep_series(results, &sweep.id, load) {
                let cs = series(&results.cases, ids, m, load, ppc);
                let plastic = spec.plastic();
                let slopes: Vec<String> = Measure::all(plastic)
                    .iter()
                    .map(|&m_| {
                        format!(
                            "{} {}",
                            m_.name(),
                            rate(fitted(results, &sweep.id, m, load, ppc, m_))
                        )
                    })
                    .collect();
                let _ = writeln!(
                    s,
                    "**{}, W = {}** (fitted slope: {})\n",
                    series_label(m, ppc),
                    weight_label(load),
                    slopes.join(", "),
                );
                let extra_head = if plastic {
                    " σxx error | rate | yield height | Zy error |"
                } else {
                    ""
                };
                let extra_rule = if plastic { "---:|---:|---:|---:|" } else { "" };
                let _ = writeln!(
                    s,
                    "| elements | stress error | rate | F error | rate |{extra_head} top u | base F | Newton its/step | status |"
                );
                let _ = writeln!(s, "|---:|---:|---:|---:|---:|{extra_rule}---:|---:|---:|---|");
                let n: Vec<usize> = cs.iter().map(|c| c.elements).collect();
                let es: Vec<Option<f64>> = cs.iter().map(|c| case_error(c, Measure::StressError)).collect();
                let ef: Vec<Option<f64>> = cs.iter().map(|c| case_error(c, Measure::FError)).collect();
                let ex: Vec<Option<f64>> = cs.iter().map(|c| case_error(c, Measure::SigmaXxError)).collect();
                let (rs, rf, rx) = (
                    pairwise_rates(&n, &es),
                    pairwise_rates(&n, &ef),
                    pairwise_rates(&n, &ex),
                );
                for (i, c) in cs.iter().enumerate() {
                    let its = if c.solve.steps.is_empty() {
                        "—".to_string()
                    } else {
                        format!(
                            "{:.2}",
                            c.solve.newton_iterations as f64 / c.solve.steps.len() as f64
                        )
                    };
                    let extra = if plastic {
                        format!(
                            " {} | {} | {} | {} |",
                            e3(ex[i]),
                            rate(rx[i]),
                            c.yield_height.map_or("—".into(), |v| format!("{v:.4}")),
                            e3(case_error(c, Measure::YieldHeightError))
                        )
                    } else {
                        String::new()
                    };
                    let _ = writeln!(
                        s,
                        "| {} | {} | {} | {} | {} |{extra} {} | {} | {} | {} |",
                        c.elements,
                        e3(es[i]),
                        rate(rs[i]),
                        e3(ef[i]),
                        rate(rf[i]),
                        c.top_displacement.map_or("—".into(), |v| format!("{v:.6}")),
                        c.base_f.map_or("—".into(), |v| format!("{v:.6}")),
                        its,
                        status_word(c)
                    );
                }
                s.push('\n');
            }
        }
    }

    let expected: Vec<_> = results
        .measures
        .rates
        .iter()
        .filter(|r| r.expected.is_some())
        .collect();
    if !expected.is_empty() {
        let _ = writeln!(s, "## Expected rates\n");
        let _ = writeln!(
            s,
            "| sweep | series | W | measure | fitted slope | elements fitted | expected | result | source |"
        );
        let _ = writeln!(s, "|---|---|---:|---|---:|---|---|---|---|");
        for r in expected {
            let b = r.expected.as_ref().expect("filtered");
            let _ = writeln!(
                s,
                "| {} | {} | {} | {} | {} | {} | {} ± {} | {} | {} |",
                r.sweep,
                series_label(r.method, r.points_per_cell),
                weight_label(r.load),
                r.measure.name(),
                rate(r.slope),
                if r.elements_used.is_empty() {
                    "—".to_string()
                } else {
                    format!(
                        "{}–{}",
                        r.elements_used[0],
                        r.elements_used[r.elements_used.len() - 1]
                    )
                },
                b.rate,
                b.tolerance,
                pass_word(r.pass),
                b.source
            );
        }
        s.push('\n');
    }
    if !results.measures.comparisons.is_empty() {
        let _ = writeln!(s, "## Error comparisons\n");
        let _ = writeln!(
            s,
            "| sweep | W | measure | expected | elements checked | largest ratio | result | source |"
        );
        let _ = writeln!(s, "|---|---:|---|---|---|---:|---|---|");
        for c in &results.measures.comparisons {
            let worst = c
                .ratios
                .iter()
                .copied()
                .fold(None, |a: Option<f64>, r| Some(a.map_or(r, |a| a.max(r))));
            let _ = writeln!(
                s,
                "| {} | {} | {} | {} below {} | {} | {} | {} | {} |",
                c.sweep,
                weight_label(c.load),
                c.measure.name(),
                Method::label(c.lower),
                Method::label(c.higher),
                if c.elements_checked.is_empty() {
                    "—".to_string()
                } else {
                    format!("{:?}", c.elements_checked)
                },
                worst.map_or("—".into(), |w| format!("{w:.3}")),
                pass_word(c.pass),
                c.source
            );
        }
        s.push('\n');
    }
    let bad: Vec<&ColumnRecord> = results
        .cases
        .iter()
        .filter(|c| c.solve.status != CaseStatus::Converged)
        .collect();
    if !bad.is_empty() {
        let _ = writeln!(s, "## Cases that did not converge\n");
        let _ = writeln!(s, "| case | status | step | reason |");
        let _ = writeln!(s, "|---|---|---:|---|");
        for c in bad {
            let f = c.solve.failure.as_ref();
            let _ = writeln!(
                s,
                "| {} | {} | {} | {} |",
                c.id,
                status_word(c),
                f.map_or(0, |f| f.step),
                f.map_or(String::new(), |f| f.reason.replace('|', "/"))
            );
        }
        s.push('\n');
    }
    s.push_str(&crate::study::render::figures_markdown(
        spec.figures.iter().map(|f| (f.title.as_str(), f.id.as_str())),
        not_drawn,
    ));
    s.push_str(&crate::study::render::performance_markdown(
        &results.cases,
        &results.timing,
    ));
    s
}
