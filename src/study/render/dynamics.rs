//! Rendering of a dynamics study: the report (every case's errors, and the bar's period and
//! energy, fitted rates with their bands, checks), the log-log convergence figures and the
//! bar's free-end history against the analytical one, from `results.json` and
//! `histories.json` only.

use super::{checks_markdown, failures_markdown, IndexEntry};
use crate::study::checks::check_counts;
use crate::study::dynamics::kind::History;
use crate::study::dynamics::records::DynamicResults;
use crate::study::dynamics::{DynamicMeasure, FigureKind, FigureSpec, Refinement};
use crate::study::render::plot::{convergence_svg_along, profile_svg, ConvergenceSeries, ProfileSeries};
use crate::study::results::{read_json, read_results};
use crate::study::StudyError;
use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::Path;

fn e3(x: Option<f64>) -> String {
    x.map_or("—".into(), |v| format!("{v:.3e}"))
}

fn r2(x: Option<f64>) -> String {
    x.map_or("—".into(), |v| format!("{v:.2}"))
}

pub fn report_markdown(results: &DynamicResults, not_drawn: &[super::NotDrawn]) -> String {
    let study = &results.study;
    let (pass, fail, none) = check_counts(&results.checks);
    let mut s = format!(
        "# {}: {}\n\n{}\n\nChecks: {pass} passed, {fail} failed, {none} not evaluated.\n\n",
        super::md_text(&study.name),
        super::md_text(&study.summary),
        results.provenance.line()
    );
    let (e, nu) = (
        study.material.parameter("young_modulus"),
        study.material.parameter("poisson_ratio"),
    );
    if let Some(b) = &study.bar {
        // The uniaxial-strain modulus λ + 2μ: E at ν = 0.
        let modulus = e * (1.0 - nu) / ((1.0 + nu) * (1.0 - 2.0 * nu));
        let _ = writeln!(
            s,
            "A fixed–free bar, L = {}, E = {}, ρ = {}, ν = {} (Hencky), set moving in its first mode v(X, 0) = v₀ sin(πX/2L) with v₀ = {} (strain amplitude v₀/c = {:.1e}); Newmark β = {}, γ = {} over {} periods of T = 4L/c = {}. Errors: displacement ‖u_h − u‖/‖u‖ over the points at the end against u = (v₀/ω) sin(πX/2L) sin(ωt); period from the free end's downward zero crossings; energy max |E(t) − E(0)|/E(0), E = kinetic + strain. Rates are slopes of log(measure) against log(h) (space sweeps) or log(Δt) (time sweeps).{}\n",
            b.length,
            e,
            b.density,
            nu,
            b.velocity,
            b.velocity / (modulus / b.density).sqrt(),
            b.beta,
            b.gamma,
            b.periods,
            results.measures.exact_period,
            if study.sweeps.iter().any(|s| s.reference.is_some()) {
                " Sweeps with a reference analysis (named in the case id after `vs`) are measured against it instead of the closed form: displacement ‖u_h − u_ref‖/‖U sin(πX/2L)‖ at the end, u_ref read at each X_p from the reference's shape functions and U its largest free-end displacement; period against the reference's measured period."
            } else {
                ""
            }
        );
    }
    if let Some(m) = &study.manufactured {
        let _ = writeln!(
            s,
            "The unit {} (Hencky, E = {}, ν = {}, ρ₀ = {}) moved by a manufactured field with amplitude a(t) = A sin ωt, ω = πc, c = √(E/ρ₀) (Wallstedt & Guilkey 2008): axis-aligned x = X + a(t)(sin πX, sin πY{}) (A = {}), vortex x = c + R(a(t)(1 − 4r²)³)(X − c){} (θ₀ = {}); rollers on every edge, the body force b₀ = ρ₀ẍ − Div P at the points, the exact velocity and acceleration at t = 0. Newmark β = {}, γ = {} over {} periods of T = 2/c = {}. Errors at the end against the field: displacement ‖x_p − x(X_p)‖/‖u(X_p)‖ and stress Σ‖σ_p − σ(X_p)‖ v_p0/(σ_max |Ω₀|), the form of eq (46). Rates are slopes of log(error) against log(h) (space sweeps) or log(Δt) (time sweeps).\n",
            if m.dimension == 3 { "cube" } else { "square, plane strain" },
            e,
            nu,
            m.density,
            if m.dimension == 3 { ", sin πZ" } else { "" },
            m.amplitude.axis_aligned,
            if m.dimension == 3 { " about z" } else { "" },
            m.amplitude.vortex,
            m.beta,
            m.gamma,
            m.periods,
            results.measures.exact_period
        );
    }
    if let Some(c) = &study.cantilever {
        let _ = writeln!(
            s,
            "The paper's cantilever (§5.3; L = {}, depth {}, E = {}, ν = {}, plane strain, ρ = {}) at rest, its end load P = {} applied suddenly at t = 0⁺ and held; {} over {} T₁, T₁ = {:.4} the Euler–Bernoulli first-mode period (β₁L = 1.8751, EI = Ed³/12(1 − ν²)), starting from a₀ = 0. Measures against each sweep's reference analysis (named in the case id after `vs`): tip max_n |v(t_n) − v_ref(t_n)| / max|v_ref| over the case's steps, v the mean deflection of the two loaded points (material points) or of the tip node (L, d/2) (Q8); period from the downward crossings of half the peak deflection, against the reference's; energy max_t |K + U − W| / max_t W, W = P·(−v) the work of the dead load. Rates are slopes of log(measure) against log(h) (space sweeps) or log(Δt) (time sweeps).\n",
            c.length,
            c.depth,
            e,
            nu,
            c.density,
            c.load,
            match c.rho_infinity {
                Some(r) => format!("generalised-α (Chung & Hulbert 1993) with ρ∞ = {r}"),
                None => format!("Newmark β = {}, γ = {}", c.beta, c.gamma),
            },
            c.periods,
            results.measures.exact_period
        );
    }
    for sw in &study.sweeps {
        if !results.sweep_cases.contains_key(&sw.id) {
            continue;
        }
        if study.cantilever.is_some() {
            let _ = writeln!(
                s,
                "## {}\n\n{}\n\n| case | elements through the depth | steps per T₁ | tip | peak deflection | period | period error | energy | Newton iterations (most per step) | steps at round-off floor | steps cut back |\n|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
                super::md_text(&sw.id),
                super::md_text(&sw.title)
            );
        } else if study.bar.is_some() {
            let _ = writeln!(
                s,
                "## {}\n\n{}\n\n| case | elements | steps per period | displacement | period | period error | energy | Newton iterations (most per step) | steps at round-off floor | steps cut back |\n|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
                super::md_text(&sw.id),
                super::md_text(&sw.title)
            );
        } else {
            let _ = writeln!(
                s,
                "## {}\n\n{}\n\n| case | cells per side | steps per period | displacement | stress | Newton iterations (most per step) | steps at round-off floor | steps cut back |\n|---|---:|---:|---:|---:|---:|---:|---:|",
                super::md_text(&sw.id),
                super::md_text(&sw.title)
            );
        }
        for ser in results.sweep_series(&sw.id) {
            for c in results.series_cases(&sw.id, &ser) {
                let newton = format!("{} ({})", c.solve.newton_iterations, c.max_newton_iterations);
                if study.cantilever.is_some() {
                    let _ = writeln!(
                        s,
                        "| {} | {} | {} | {} | {} | {} | {} | {} | {newton} | {} | {} |",
                        c.id,
                        c.elements,
                        c.steps_per_period,
                        e3(c.tip_error),
                        c.peak_deflection.map_or("—".into(), |v| format!("{v:.5}")),
                        c.measured_period.map_or("—".into(), |t| format!("{t:.5}")),
                        e3(c.period_error),
                        e3(c.energy_drift),
                        c.steps_at_floor,
                        c.steps_cut_back
                    );
                    if let Some(why) = &c.reference_failure {
                        let _ = writeln!(
                            s,
                            "| ↳ no reference measures: {} | | | | | | | | | | |",
                            why.replace('|', "\\|")
                        );
                    }
                } else if study.bar.is_some() {
                    let _ = writeln!(
                        s,
                        "| {} | {} | {} | {} | {} | {} | {} | {newton} | {} | {} |",
                        c.id,
                        c.elements,
                        c.steps_per_period,
                        e3(c.displacement_error),
                        c.measured_period.map_or("—".into(), |t| format!("{t:.6}")),
                        e3(c.period_error),
                        e3(c.energy_drift),
                        c.steps_at_floor,
                        c.steps_cut_back
                    );
                } else {
                    let _ = writeln!(
                        s,
                        "| {} | {} | {} | {} | {} | {newton} | {} | {} |",
                        c.id,
                        c.elements,
                        c.steps_per_period,
                        e3(c.displacement_error),
                        e3(c.stress_error),
                        c.steps_at_floor,
                        c.steps_cut_back
                    );
                }
            }
        }
        s.push('\n');
    }
    s.push_str("## Fitted rates\n\n| sweep | series | measure | against | levels | slope | band | source |\n|---|---|---|---|---|---:|---|---|\n");
    for r in &results.measures.rates {
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} | {:?} | {} | {} | {} |",
            r.sweep,
            r.series.label(),
            r.measure.name(),
            if r.refinement == Refinement::Time {
                "Δt"
            } else {
                "h"
            },
            r.levels_used,
            r2(r.slope),
            r.expected
                .as_ref()
                .map_or("—".into(), |e| format!("{} ± {}", e.rate, e.tolerance)),
            r.expected
                .as_ref()
                .map_or(String::new(), |e| e.source.replace('|', "\\|"))
        );
    }
    s.push('\n');
    s.push_str(&checks_markdown(&results.checks));
    s.push_str(&super::performance_markdown(&results.cases, &results.timing));
    s.push_str(&failures_markdown(
        results
            .cases
            .iter()
            .map(|c| (c.id.as_str(), c.solve.status, c.solve.failure.as_ref())),
    ));
    s.push_str(&super::figures_markdown(
        super::figures_in_tier(&study.figures, &study.sweeps, results.provenance.tier)
            .map(|f| (f.title.as_str(), f.id.as_str())),
        not_drawn,
    ));
    s
}

fn render_figure(
    results: &DynamicResults,
    histories: &BTreeMap<String, History>,
    dir: &Path,
    f: &FigureSpec,
) -> Result<Option<String>, StudyError> {
    let err = |e: String| StudyError::io(&dir.join(format!("{}.svg", f.id)), e);
    let Some(sw) = results.study.sweep(&f.sweep) else {
        return Ok(None);
    };
    match f.kind {
        FigureKind::Convergence => {
            let m = f.measure.unwrap_or(DynamicMeasure::Displacement);
            let refinement = sw.refinement();
            let series: Vec<ConvergenceSeries> = results
                .sweep_series(&f.sweep)
                .into_iter()
                .filter_map(|ser| {
                    let points: Vec<(f64, f64)> = results
                        .series_cases(&f.sweep, &ser)
                        .into_iter()
                        .filter_map(|c| {
                            let n = match refinement {
                                Refinement::Space => c.elements,
                                Refinement::Time => c.steps_per_period,
                            };
                            Some((n as f64, c.measure(m)?)).filter(|p| p.1 > 0.0)
                        })
                        .collect();
                    let slope = results
                        .measures
                        .rates
                        .iter()
                        .find(|r| r.sweep == f.sweep && r.series == ser && r.measure == m)
                        .and_then(|r| r.slope);
                    (points.len() >= 2).then(|| ConvergenceSeries {
                        label: ser.label(),
                        points,
                        slope,
                    })
                })
                .collect();
            if series.is_empty() {
                return Ok(None);
            }
            let x = match refinement {
                Refinement::Space => "elements (h = L/n)",
                Refinement::Time => "time steps per period (Δt = T/n)",
            };
            convergence_svg_along(&f.title, x, m.label(), &series, m != DynamicMeasure::Energy)
                .map(Some)
                .map_err(err)
        }
        FigureKind::History if results.study.cantilever.is_some() => {
            let length = results.study.cantilever.as_ref().map_or(1.0, |c| c.length);
            // Seconds and per cent of L: the axes label whole numbers.
            let series = history_series(
                results,
                histories,
                &f.sweep,
                |c| {
                    format!(
                        "{} ({} el. through the depth, {}/T₁)",
                        c.method.label(),
                        c.elements,
                        c.steps_per_period
                    )
                },
                |p| (p[0], 100.0 * p[1] / length),
            );
            if series.is_empty() {
                return Ok(None);
            }
            profile_svg(&f.title, "t (s)", "tip deflection 100 v / L (%)", &series, &[])
                .map(Some)
                .map_err(err)
        }
        FigureKind::History => {
            let Some(b) = &results.study.bar else {
                return Ok(None);
            };
            let t_period = results.measures.exact_period;
            let amplitude = b.velocity / (2.0 * std::f64::consts::PI / t_period);
            let series = history_series(
                results,
                histories,
                &f.sweep,
                |c| {
                    format!(
                        "{} ({} mass, {} el., {}/T)",
                        c.method.label(),
                        c.mass.name(),
                        c.elements,
                        c.steps_per_period
                    )
                },
                |p| (p[0] / t_period, p[1] / amplitude),
            );
            if series.is_empty() {
                return Ok(None);
            }
            let samples = 400;
            let exact = ProfileSeries {
                label: "analytical".into(),
                points: (0..=samples)
                    .map(|i| {
                        let t = b.periods * i as f64 / samples as f64;
                        (t, (2.0 * std::f64::consts::PI * t).sin())
                    })
                    .collect(),
            };
            profile_svg(&f.title, "t / T", "u(L, t) / (v₀/ω)", &series, &[exact])
                .map(Some)
                .map_err(err)
        }
    }
}

/// One series per case of `sweep` with a stored history (t, u), labelled by `label` and its
/// samples scaled by `point`.
fn history_series(
    results: &DynamicResults,
    histories: &BTreeMap<String, History>,
    sweep: &str,
    label: impl Fn(&crate::study::dynamics::records::DynamicRecord) -> String,
    point: impl Fn(&[f64; 2]) -> (f64, f64),
) -> Vec<ProfileSeries> {
    results
        .sweep(sweep)
        .into_iter()
        .filter_map(|c| {
            let h = histories.get(&c.id)?;
            Some(ProfileSeries {
                label: label(c),
                points: h.iter().map(&point).collect(),
            })
        })
        .collect()
}

/// Render the report and figures from `dir`'s `results.json` and `histories.json`.
pub fn render(dir: &Path) -> Result<super::Rendered, StudyError> {
    let results: DynamicResults = read_results(dir)?;
    let histories: BTreeMap<String, History> = read_json(&dir.join("histories.json"))?;
    let mut files = super::Files::new(dir);
    for f in super::figures_in_tier(
        &results.study.figures,
        &results.study.sweeps,
        results.provenance.tier,
    ) {
        files.figure(
            &f.id,
            render_figure(&results, &histories, dir, f)?,
            "no data (no converged case among those it shows)",
        )?;
    }
    let report = report_markdown(&results, &files.not_drawn);
    files.report(&results.study.report_file, &report)?;
    Ok(files.done())
}

pub fn index_entry(dir: &Path) -> Result<IndexEntry, StudyError> {
    let r: DynamicResults = read_results(dir)?;
    Ok(super::plane_index_entry(
        (&r.study.name, &r.study.summary, r.provenance.tier),
        ("the free-end histories", "histories.json"),
        &r.checks,
        &r.study.report_file,
        std::iter::empty(),
        super::drawn(
            dir,
            r.study.figures.iter().map(|f| (f.title.clone(), f.id.clone())),
        ),
    ))
}
