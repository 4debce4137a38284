//! The scene report's section on other codes: every case of a study that puts an external
//! code beside igimp, with its Newton iterations, the solve's seconds and the seconds per
//! iteration, the code, and why a case failed.

use super::md_cell;
use crate::study::results::CaseStatus;
use crate::study::scene::SceneResults;
use std::fmt::Write as _;

/// The section, empty for a study without external methods.
pub fn external_markdown(r: &SceneResults) -> String {
    if !r.cases.iter().any(|c| c.method.is_external()) {
        return String::new();
    }
    // One thread: the cases ran one after another, each on one thread (an external code too:
    // its adapter asks for one), so their times compare; otherwise they shared the cores.
    let concurrency = if r.timing.threads == 1 {
        "The cases ran one after another, each on one thread (igimp's and the external codes' alike), so their times compare."
    } else {
        "Cases ran concurrently and shared the cores, so times vary from run to run; `RAYON_NUM_THREADS=1` runs them one at a time on one thread each."
    };
    let mut s = format!(
        "## Beside other codes\n\nEvery case, igimp's and the external codes' (studies/PROTOCOL.md). *Solve s* is the code's own measure of its load steps (igimp: the whole case; an external code: its solve loop, import and set-up excluded); *process s* is the adapter process's wall time. {concurrency} An external code's residuals are in its own norm where the code says so.\n\n| case | method | code | status | Newton | solve s | ms per iteration | process s | note |\n|---|---|---|---|---:|---:|---:|---:|---|\n",
    );
    for c in &r.cases {
        let ext = c.external.as_ref();
        let seconds = match ext {
            Some(e) => e.seconds,
            None => r.timing.cases.get(&c.id).copied(),
        };
        let its = c.solve.newton_iterations;
        let per = seconds.filter(|_| its > 0).map(|t| 1e3 * t / its as f64);
        let note = match (&c.solve.failure, ext.and_then(|e| e.residual_norm.as_deref())) {
            (Some(f), _) if c.solve.status != CaseStatus::Converged => {
                // The reason's lines (an adapter's output tail) on one table row.
                let reason: Vec<&str> = f
                    .reason
                    .lines()
                    .map(str::trim)
                    .filter(|l| !l.is_empty())
                    .collect();
                format!("step {}: {}", f.step, reason.join(" / "))
            }
            (_, Some(norm)) => format!("residuals: {norm}"),
            _ => String::new(),
        };
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} | {its} | {} | {} | {} | {} |",
            c.id,
            c.method,
            ext.map_or("igimp (in process)".to_string(), |e| if e.code.is_empty() {
                "—".into()
            } else {
                md_cell(&e.code)
            }),
            c.solve.status.word(),
            seconds.map_or("—".into(), |t| format!("{t:.3}")),
            per.map_or("—".into(), |t| format!("{t:.2}")),
            ext.and_then(|e| e.process_seconds)
                .map_or("—".into(), |t| format!("{t:.2}")),
            md_cell(&note)
        );
    }
    s.push('\n');
    s
}
