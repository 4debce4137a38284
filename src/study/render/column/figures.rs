//! The column study's figures: stress profiles against the analytical column and log-log
//! convergence plots.

use super::*;
use crate::study::render::plot::{self, ConvergenceSeries, ProfileSeries};

/// Draw one figure of the study (SVG text).
pub fn render_figure(
    results: &ColumnResults,
    study_dir: &Path,
    fig: &FigureSpec,
) -> Result<Option<String>, StudyError> {
    let ids = of_sweep(results, &fig.sweep);
    let file_err = |e: String| StudyError::Io {
        path: study_dir.join(format!("{}.svg", fig.id)).display().to_string(),
        message: e,
    };
    match fig.kind {
        FigureKind::Profile => {
            let mut series_out = vec![];
            for (m, ppc) in sweep_series(results, &fig.sweep, fig.weight) {
                for c in series(&results.cases, ids, m, fig.weight, ppc) {
                    if c.solve.status != CaseStatus::Converged {
                        continue;
                    }
                    let rows = read_points_csv(&study_dir.join(points_file(&c.id)))?;
                    series_out.push(ProfileSeries {
                        label: format!("σzz, {}, {} elements", series_label(m, ppc), c.elements),
                        points: rows.iter().map(|r| (r[3], r[1])).collect(),
                    });
                }
            }
            let exact = analytical_at(results, fig.weight)?;
            let mut curves = vec![ProfileSeries {
                label: "analytical σzz, eqs (42)-(45)".into(),
                points: exact.profile.iter().map(|r| (r[2], r[1])).collect(),
            }];
            let plastic = results.study.plastic();
            if plastic {
                // The lateral stress is recorded in the sixth column of plastic point files.
                for (m, ppc) in sweep_series(results, &fig.sweep, fig.weight) {
                    for c in series(&results.cases, ids, m, fig.weight, ppc) {
                        if c.solve.status != CaseStatus::Converged {
                            continue;
                        }
                        let rows = read_points_csv(&study_dir.join(points_file(&c.id)))?;
                        series_out.push(ProfileSeries {
                            label: format!("σxx, {}, {} elements", series_label(m, ppc), c.elements),
                            points: rows
                                .iter()
                                .filter(|r| r.len() > 5)
                                .map(|r| (r[5], r[1]))
                                .collect(),
                        });
                    }
                }
                curves.push(ProfileSeries {
                    label: "analytical σxx = σyy (derived; eq 54)".into(),
                    points: exact.profile.iter().map(|r| (r[3], r[1])).collect(),
                });
            }
            plot::profile_svg(
                &fig.title,
                if plastic {
                    "Cauchy stress σzz, σxx (Pa)"
                } else {
                    "vertical Cauchy stress σzz (Pa)"
                },
                "current height z (m)",
                &series_out,
                &curves,
            )
            .map(Some)
            .map_err(file_err)
        }
        FigureKind::Convergence => {
            let measure = fig.measure.unwrap_or(Measure::StressError);
            let mut out = vec![];
            for sweep in std::iter::once(&fig.sweep).chain(&fig.overlay) {
                let ids = of_sweep(results, sweep);
                let untreated = results.study.sweep(sweep).is_some_and(|s| s.untreated);
                for (m, ppc) in sweep_series(results, sweep, fig.weight) {
                    let pts: Vec<(f64, f64)> = series(&results.cases, ids, m, fig.weight, ppc)
                        .iter()
                        .filter_map(|c| case_error(c, measure).map(|e| (c.elements as f64, e)))
                        .collect();
                    if pts.is_empty() {
                        continue;
                    }
                    let label = series_label(m, ppc);
                    out.push(ConvergenceSeries {
                        label: if untreated {
                            format!("{label}, untreated")
                        } else {
                            label
                        },
                        points: pts,
                        slope: fitted(results, sweep, m, fig.weight, ppc, measure),
                    });
                }
            }
            // Nothing converged (or every error is zero): a log-log axis has nothing to show.
            if !out
                .iter()
                .any(|s| s.points.iter().any(|p| p.0 > 0.0 && p.1 > 0.0))
            {
                return Ok(None);
            }
            plot::convergence_svg(&fig.title, measure.label(), &out, fig.slope_triangles)
                .map(Some)
                .map_err(file_err)
        }
    }
}
