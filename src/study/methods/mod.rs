//! The cross-method comparison: every method's fitted rates, deviations and GCI
//! extrapolations, gathered from the `results.json` of the studies in one output folder into
//! `<out>/methods/methods.json`, which `crate::study::render::methods` alone draws from.
//!
//! Nothing is solved here. The column-type, manufactured and dynamics studies contribute their
//! fitted rates (the `rates` array; a dynamics study's name the method inside `series` and say
//! whether the grid or the time step was refined) and, for the overlay figures, each rate's errors against its
//! resolution (the cases of its sweep); the compaction and cantilever studies contribute every
//! method's end value against the study's reference at each element size and its GCI
//! extrapolation. A series is one method in one group: the study, the measure and the keys
//! that must agree for two methods to share axes (load, points per cell, field, domain
//! update).

use crate::study::results::Software;
use crate::study::vocabulary::number;
use serde_json::Value;
use std::collections::BTreeMap;

mod records;
mod references;

use records::{case_field, f, method_of};
pub use records::{Group, MethodsResults, RateRow, ReferenceRow, Source, MIN_METHODS_PER_FIGURE};
use references::{cantilever, compaction};

/// Gather every study's results of `studies` (name, parsed `results.json`), in order.
pub fn collect(studies: &[(String, Value)]) -> MethodsResults {
    let mut out = MethodsResults {
        software: Software::this_build(),
        sources: vec![],
        rates: vec![],
        references: vec![],
        groups: vec![],
    };
    for (name, r) in studies {
        out.sources.push(Source {
            study: name.clone(),
            tier: r["tier"].as_str().unwrap_or("?").to_string(),
            software: serde_json::from_value::<Software>(r["software"].clone())
                .map_or("?".into(), |s| s.label()),
        });
        let problem = r["study"]["problem"].as_str().unwrap_or("");
        match problem {
            "compaction" => compaction(name, r, &mut out),
            "cantilever" => cantilever(name, r, &mut out),
            _ if r["rates"].is_array() => rates(name, r, &mut out),
            _ => {}
        }
    }
    out
}

/// Column-type and manufactured studies: their fitted rates and the errors behind them.
fn rates(name: &str, r: &Value, out: &mut MethodsResults) {
    let cases: BTreeMap<&str, &Value> = r["cases"]
        .as_array()
        .into_iter()
        .flatten()
        .filter_map(|c| Some((c["id"].as_str()?, c)))
        .collect();
    let manufactured = r["study"]["problem"].as_str() == Some("manufactured");
    let mut groups: BTreeMap<(String, String), Group> = BTreeMap::new();
    for rate in r["rates"].as_array().into_iter().flatten() {
        // A dynamics study's series (method, mass, points per cell) and refinement.
        let series = &rate["series"];
        let (Some(sweep), Some(method), Some(measure)) = (
            rate["sweep"].as_str(),
            method_of(&rate["method"]).or_else(|| method_of(&series["method"])),
            rate["measure"].as_str(),
        ) else {
            continue;
        };
        let ppc = rate["points_per_cell"]
            .as_i64()
            .or_else(|| series["points_per_cell"].as_i64());
        let mass = series["mass"].as_str();
        let in_time = rate["refinement"].as_str() == Some("time");
        let domain_update = rate["domain_update"].as_str();
        let level_key = if manufactured {
            "cells"
        } else if in_time {
            "steps_per_period"
        } else {
            "elements"
        };
        let levels_field = if manufactured {
            "cells_used"
        } else if rate["levels_used"].is_array() {
            "levels_used"
        } else {
            "elements_used"
        };
        let levels: Vec<f64> = rate[levels_field]
            .as_array()
            .into_iter()
            .flatten()
            .filter_map(f)
            .collect();
        // The sweep's cases of this series, for the overlay.
        let ids: Vec<&str> = r["sweep_cases"][sweep]
            .as_array()
            .into_iter()
            .flatten()
            .filter_map(|v| v.as_str())
            .collect();
        let series_cases: Vec<&Value> = ids
            .iter()
            .filter_map(|id| cases.get(id).copied())
            .filter(|c| method_of(&c["method"]).as_ref() == Some(&method))
            .filter(|c| c["points_per_cell"].as_i64() == ppc || method.is_fem())
            .filter(|c| rate["load"].is_null() || c["load"] == rate["load"])
            .filter(|c| domain_update.is_none() || c["domain_update"].as_str() == domain_update)
            .filter(|c| mass.is_none() || c["mass"].as_str() == mass)
            .collect();
        let field = series_cases
            .first()
            .and_then(|c| c["field"].as_str())
            .map(str::to_string);
        let mut keys = vec![];
        if let Some(fl) = &field {
            keys.push(format!("{fl} field"));
        }
        if let Some(w) = f(&rate["load"]) {
            keys.push(format!("W = {}", number(w)));
        }
        if let (Some(p), false) = (ppc, method.is_fem()) {
            keys.push(format!("{p} points per cell (per axis)"));
        }
        if let Some(d) = domain_update.filter(|d| *d != "stretch") {
            keys.push(format!("{d} domain update"));
        }
        if let Some(m) = mass.filter(|m| *m != "consistent") {
            keys.push(format!("{m} mass"));
        }
        if in_time {
            keys.push("time step refined".to_string());
        }
        let group = keys.join(", ");
        let expected = rate["expected"]
            .is_object()
            .then(|| Some((f(&rate["expected"]["rate"])?, f(&rate["expected"]["tolerance"])?)))
            .flatten();
        out.rates.push(RateRow {
            study: name.to_string(),
            group: group.clone(),
            measure: measure.to_string(),
            sweep: sweep.to_string(),
            method: method.clone(),
            slope: f(&rate["slope"]),
            levels: levels.clone(),
            expected,
            // The dynamics and manufactured studies keep their verdicts among their checks,
            // named by the rate's sweep, method, (mass | domain update and points per cell)
            // and measure.
            pass: rate["pass"].as_bool().or_else(|| {
                let id = match mass {
                    Some(mass) => format!("{sweep}-{}-{mass}-{measure}-rate", method.name()),
                    None => crate::study::manufactured::rate_check_id(
                        sweep,
                        method.own()?,
                        serde_json::from_value(rate["domain_update"].clone()).ok(),
                        ppc.map(|p| p as usize),
                        measure,
                    ),
                };
                r["checks"]
                    .as_array()?
                    .iter()
                    .find(|c| c["id"].as_str() == Some(id.as_str()))?["pass"]
                    .as_bool()
            }),
        });
        // FEM series have no points per cell: they join the material point groups of the
        // same field and load only through their own group, so they are not overlaid.
        if method.is_fem() {
            continue;
        }
        let points: Vec<(f64, f64)> = series_cases
            .iter()
            .filter_map(|c| Some((f(&c[level_key])?, f(&c[case_field(measure)])?)))
            .filter(|&(_, e)| e > 0.0)
            .collect();
        if points.is_empty() {
            continue;
        }
        let g = groups
            .entry((measure.to_string(), group.clone()))
            .or_insert_with(|| Group {
                id: format!("{name}-{measure}-{}", groups_slug(&group)),
                title: format!("{name}: {measure} against {level_key}, {group}"),
                x_desc: level_key.to_string(),
                y_desc: format!("{measure} error"),
                log_y: true,
                series: vec![],
            });
        // One series per method: the first sweep that fits it (the families sweeps repeat
        // nothing, the paper's sweeps come first).
        if !g.series.iter().any(|(m, _)| *m == method) {
            g.series.push((method, points));
        }
    }
    out.groups.extend(
        groups
            .into_values()
            .filter(|g| g.series.len() >= MIN_METHODS_PER_FIGURE),
    );
}

/// A file-name slug of a group's words.
fn groups_slug(words: &str) -> String {
    let mut s: String = words
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() {
                c.to_ascii_lowercase()
            } else {
                '-'
            }
        })
        .collect();
    while s.contains("--") {
        s = s.replace("--", "-");
    }
    s.trim_matches('-').to_string()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::basis::method::Method;
    use serde_json::json;

    /// A dynamics results file: the method inside `series`, time sweeps grouped apart from
    /// space sweeps (their levels are time steps, not elements), the lumped-mass series of the
    /// same method kept apart from the consistent one.
    #[test]
    fn dynamics_rates_are_gathered_by_refinement_and_mass() {
        let mut cases = vec![];
        let mut rates = vec![];
        let mut sweep_cases = serde_json::Map::new();
        for (sw, refinement, mass) in [
            ("space", "space", "consistent"),
            ("time", "time", "consistent"),
            ("time", "time", "lumped"),
        ] {
            for m in ["igimp", "cpdi", "tlmpm"] {
                for (e, n) in [(8, 64), (16, 128)] {
                    let (e, n) = if refinement == "space" { (e, 512) } else { (32, n) };
                    let id = format!("{m}-{mass}-{sw}-e{e}-n{n}");
                    cases.push(
                        json!({"id": id, "method": m, "mass": mass, "elements": e, "steps_per_period": n,
                                      "points_per_cell": 2, "displacement_error": 1.0 / (e * n) as f64}),
                    );
                    sweep_cases
                        .entry(sw.to_string())
                        .or_insert_with(|| json!([]))
                        .as_array_mut()
                        .unwrap()
                        .push(json!(id));
                }
                rates.push(json!({"sweep": sw, "series": {"method": m, "mass": mass, "points_per_cell": 2},
                                  "measure": "displacement", "refinement": refinement, "slope": 2.0,
                                  "levels_used": if refinement == "space" { json!([8, 16]) } else { json!([64, 128]) }}));
            }
        }
        // A dynamics study's verdicts are its checks, named by sweep, method, mass and measure.
        let checks = json!([{"id": "time-cpdi-lumped-displacement-rate", "pass": false},
                            {"id": "space-igimp-consistent-displacement-rate", "pass": true}]);
        let r = json!({"tier": "full", "study": {"problem": "dynamics"}, "cases": cases, "rates": rates,
                       "sweep_cases": sweep_cases, "checks": checks});
        let out = collect(&[("vibrating-bar".into(), r)]);
        assert_eq!(out.rates.len(), 9);
        let verdicts: Vec<(&str, Method, Option<bool>)> = out
            .rates
            .iter()
            .filter(|x| x.pass.is_some())
            .map(|x| (x.sweep.as_str(), x.method.own().unwrap(), x.pass))
            .collect();
        assert_eq!(
            verdicts,
            [
                ("space", Method::IGIMP, Some(true)),
                ("time", Method::CPDI, Some(false))
            ],
            "{verdicts:?}"
        );
        assert!(out.rates.iter().all(|x| x.method.uses_material_points()));
        let titles: Vec<&str> = out.groups.iter().map(|g| g.title.as_str()).collect();
        assert_eq!(out.groups.len(), 3, "{titles:?}");
        let time = out
            .groups
            .iter()
            .find(|g| g.title.contains("lumped mass"))
            .expect("the lumped group");
        assert!(
            time.title.contains("time step refined") && time.x_desc == "steps_per_period",
            "{}",
            time.title
        );
        // Each lumped series holds its own two cases, not the consistent ones.
        assert!(time.series.iter().all(|(_, p)| p.len() == 2), "{:?}", time.series);
    }

    /// A manufactured study's rate finds its verdict in the check named by its sweep, method,
    /// domain update, points per cell and measure; a rate without a check has none.
    #[test]
    fn manufactured_rates_take_their_checks_verdicts() {
        let rates = json!([
            {"sweep": "axis", "method": "igimp", "domain_update": "stretch", "points_per_cell": 2,
             "measure": "displacement", "slope": 2.0, "cells_used": [8, 16]},
            {"sweep": "axis", "method": "igimp", "domain_update": "f-diagonal", "points_per_cell": 2,
             "measure": "displacement", "slope": 1.0, "cells_used": [8, 16]},
            {"sweep": "axis", "method": "fem-q4", "measure": "stress", "slope": 1.0, "cells_used": [8, 16]}
        ]);
        let checks = json!([{"id": "axis-igimp-stretch-p2-displacement-rate", "pass": true},
                            {"id": "axis-fem-q4-stress-rate", "pass": false}]);
        let r = json!({"tier": "full", "study": {"problem": "manufactured"}, "cases": [], "rates": rates,
                       "sweep_cases": {"axis": []}, "checks": checks});
        let out = collect(&[("manufactured".into(), r)]);
        let verdicts: Vec<Option<bool>> = out.rates.iter().map(|x| x.pass).collect();
        assert_eq!(verdicts, [Some(true), None, Some(false)]);
    }

    /// A column-type results file with three methods in one group and one FEM series: one
    /// rate row each, one overlay of the three material point methods, errors from the cases.
    #[test]
    fn rates_are_gathered_per_group_and_overlaid() {
        let case = |m: &str, e: i64, err: f64| {
            json!({"id": format!("{m}-e{e}"), "method": m, "load": 4.0e4, "elements": e,
                   "points_per_cell": 2, "stress_error": err})
        };
        let mut cases = vec![];
        let mut rates = vec![];
        let mut sweep = vec![];
        for (m, p) in [
            ("igimp", 2.0),
            ("cpdi", 2.0),
            ("bspline2", 0.0),
            ("fem-linear", 1.0),
        ] {
            for e in [8, 16] {
                cases.push(case(m, e, 1.0 / (e as f64).powf(p).max(1.0)));
                sweep.push(format!("{m}-e{e}"));
            }
            rates.push(
                json!({"sweep": "s", "method": m, "load": 4.0e4, "points_per_cell": 2,
                              "measure": "stress_error", "slope": p, "elements_used": [8, 16],
                              "expected": {"rate": p, "tolerance": 0.1}, "pass": true}),
            );
        }
        let r = json!({"tier": "quick", "software": {"name": "igimp", "version": "0"},
                       "study": {"problem": "column"}, "cases": cases, "rates": rates,
                       "sweep_cases": {"s": sweep}});
        let out = collect(&[("column".into(), r)]);
        assert_eq!(out.rates.len(), 4);
        assert_eq!(out.rates[0].expected, Some((2.0, 0.1)));
        assert_eq!(out.groups.len(), 1, "{:#?}", out.groups);
        let g = &out.groups[0];
        assert_eq!(g.series.len(), 3);
        assert_eq!(g.series[0].1, vec![(8.0, 1.0 / 64.0), (16.0, 1.0 / 256.0)]);
        assert!(g.series.iter().all(|(m, _)| !m.is_fem()));
    }

    /// A compaction with a reference and a GCI record: ratios per h and the extrapolated ratio
    /// only in the asymptotic range.
    #[test]
    fn compaction_deviations_and_extrapolations_are_gathered() {
        let case = |m: &str, h: f64, u: f64| {
            json!({"id": format!("{m}-h{h}"), "method": m, "h": h, "points_per_cell": 2,
                   "max_horizontal_displacement": u})
        };
        let cases = vec![
            case("igimp", 1.0, 0.99),
            case("igimp", 0.5, 1.0),
            case("mpm", 1.0, 1.1),
        ];
        let r = json!({"tier": "full", "software": {"name": "igimp", "version": "0"},
            "study": {"problem": "compaction", "block": {"dimension": 2},
                      "sweeps": [{"id": "f", "methods": ["igimp", "mpm"]}]},
            "reference": {"value": 2.0, "description": "Q4"},
            "sweep_cases": {"f": ["igimp-h1", "igimp-h0.5", "mpm-h1"]}, "cases": cases,
            "gci": [{"sweep": "f", "series": "iGIMP, 2×2 points", "measure": "max horizontal displacement",
                     "gci": {"extrapolated": 1.01, "order": 2.0}, "note": "in the asymptotic range"},
                    {"sweep": "f", "series": "MPM, 2×2 points", "measure": "max horizontal displacement",
                     "gci": {"extrapolated": 1.5, "order": 0.3}, "note": "oscillatory convergence"}]});
        let out = collect(&[("compaction".into(), r)]);
        assert_eq!(out.references.len(), 2);
        let ig = &out.references[0];
        assert_eq!(ig.ratios, vec![(1.0, 0.495), (0.5, 0.5)]);
        assert_eq!(ig.extrapolated_ratio, Some(0.505));
        assert_eq!(out.references[1].extrapolated_ratio, None);
        assert!(out.groups.is_empty(), "two methods are not overlaid");
    }
}
