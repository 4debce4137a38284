//! The compaction's and the cantilever's contributions: every method's end value against the
//! study's reference at each element size, and its GCI extrapolation.

use super::records::{f, method_of, Group, MethodsResults, ReferenceRow, MIN_METHODS_PER_FIGURE};
use crate::study::external::StudyMethod as Method;
use serde_json::Value;

/// A GCI record's (extrapolated value, order, note) for `series` of `sweep`, if any.
fn gci_of(r: &Value, sweep: &str, series: &str, measure: &str) -> (Option<f64>, Option<f64>, String) {
    let rec = r["gci"]
        .as_array()
        .into_iter()
        .flatten()
        .find(|g| g["sweep"] == sweep && g["series"] == series && g["measure"] == measure);
    match rec {
        Some(g) => {
            let asym = g["note"].as_str() == Some("in the asymptotic range");
            (
                f(&g["gci"]["extrapolated"]).filter(|_| asym),
                f(&g["gci"]["order"]),
                g["note"].as_str().unwrap_or("").to_string(),
            )
        }
        None => (None, None, "no GCI".into()),
    }
}

/// The compaction: every sweep with two or more material point methods, Figure 17's measure
/// over the study's reference.
pub(super) fn compaction(name: &str, r: &Value, out: &mut MethodsResults) {
    let Some(reference) = f(&r["reference"]["value"]) else {
        return;
    };
    let what = r["reference"]["description"].as_str().unwrap_or("").to_string();
    let dim = r["study"]["block"]["dimension"].as_i64().unwrap_or(2);
    for sw in r["study"]["sweeps"].as_array().into_iter().flatten() {
        let Some(id) = sw["id"].as_str() else { continue };
        let methods: Vec<Method> = sw["methods"]
            .as_array()
            .into_iter()
            .flatten()
            .filter_map(method_of)
            .filter(|m| !m.is_fem())
            .collect();
        if methods.len() < 2 || !sw["ghost_gammas"].is_null() || !sw["material"].is_null() {
            continue;
        }
        let ids: Vec<&str> = r["sweep_cases"][id]
            .as_array()
            .into_iter()
            .flatten()
            .filter_map(|v| v.as_str())
            .collect();
        let mut group = Group {
            id: format!("{name}-{id}"),
            title: format!("{name}, sweep {id}: max horizontal displacement over the reference against h"),
            x_desc: "element size h".into(),
            y_desc: "u_max / u_ref".into(),
            log_y: false,
            series: vec![],
        };
        for m in methods {
            let cs: Vec<&Value> = r["cases"]
                .as_array()
                .into_iter()
                .flatten()
                .filter(|c| ids.contains(&c["id"].as_str().unwrap_or("")))
                .filter(|c| method_of(&c["method"]) == Some(m.clone()))
                .collect();
            let Some(ppc) = cs.first().and_then(|c| c["points_per_cell"].as_i64()) else {
                continue;
            };
            let ratios: Vec<(f64, f64)> = cs
                .iter()
                .filter(|c| c["points_per_cell"].as_i64() == Some(ppc))
                .filter_map(|c| Some((f(&c["h"])?, f(&c["max_horizontal_displacement"])? / reference)))
                .collect();
            let grid = if dim == 3 {
                format!("{ppc}×{ppc}×{ppc}")
            } else {
                format!("{ppc}×{ppc}")
            };
            let series = format!("{}, {grid} points", m.label());
            let (ext, order, note) = gci_of(r, id, &series, "max horizontal displacement");
            out.references.push(ReferenceRow {
                study: name.to_string(),
                sweep: id.to_string(),
                measure: "max horizontal displacement".into(),
                method: m.clone(),
                reference: what.clone(),
                ratios: ratios.clone(),
                extrapolated_ratio: ext.map(|e| e / reference),
                observed_order: order,
                gci_note: note,
            });
            group.series.push((m, ratios));
        }
        if group.series.len() >= MIN_METHODS_PER_FIGURE {
            out.groups.push(group);
        }
    }
}

/// The cantilever: every refinement's final u/L over its reference method's extrapolation.
pub(super) fn cantilever(name: &str, r: &Value, out: &mut MethodsResults) {
    for refinement in r["study"]["refinement"].as_array().into_iter().flatten() {
        let (Some(id), Some(reference)) = (refinement["id"].as_str(), method_of(&refinement["reference"]))
        else {
            continue;
        };
        let rows: Vec<&Value> = r["refinement"]
            .as_array()
            .into_iter()
            .flatten()
            .filter(|x| x["refinement"] == id)
            .collect();
        let (ext, _, _) = gci_of(r, id, &reference.label(), "final u/L");
        let finest = rows
            .iter()
            .filter(|x| method_of(&x["method"]) == Some(reference.clone()))
            .filter_map(|x| Some((f(&x["element_size"])?, f(&x["u_over_l"])?)))
            .min_by(|a, b| a.0.total_cmp(&b.0));
        let (u_ref, what) = match (ext, finest) {
            (Some(e), _) => (e, format!("{} u/L extrapolated (GCI)", reference.label())),
            (None, Some((h, u))) => (u, format!("finest {} u/L, h = {h}", reference.label())),
            _ => continue,
        };
        let mut group = Group {
            id: format!("{name}-{id}"),
            title: format!("{name}, refinement {id}: final u/L over the reference against h"),
            x_desc: "element size h".into(),
            y_desc: "u/L over the reference".into(),
            log_y: false,
            series: vec![],
        };
        for m in refinement["methods"]
            .as_array()
            .into_iter()
            .flatten()
            .filter_map(method_of)
        {
            let ratios: Vec<(f64, f64)> = rows
                .iter()
                .filter(|x| method_of(&x["method"]) == Some(m.clone()))
                .filter_map(|x| Some((f(&x["element_size"])?, f(&x["u_over_l"])? / u_ref)))
                .collect();
            let (e, order, note) = gci_of(r, id, &m.label(), "final u/L");
            out.references.push(ReferenceRow {
                study: name.to_string(),
                sweep: id.to_string(),
                measure: "final u/L".into(),
                method: m.clone(),
                reference: what.clone(),
                ratios: ratios.clone(),
                extrapolated_ratio: e.map(|e| e / u_ref),
                observed_order: order,
                gci_note: note,
            });
            group.series.push((m, ratios));
        }
        if group.series.len() >= MIN_METHODS_PER_FIGURE {
            out.groups.push(group);
        }
    }
}
