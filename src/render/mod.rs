//! Rendering: tables, figures and index pages from the results files a study wrote, one
//! module per study kind (criterion's split between analysis and report). Nothing here solves.

pub mod cantilever;
pub mod column;
pub mod compaction;

use crate::study::plane::{self, CheckRecord, IndexEntry};
use crate::study::StudyError;
use std::path::{Path, PathBuf};

/// Write a plane-strain study's rendered files into `dir`: the report, its extra tables
/// (file, text) and one SVG per figure that has something to draw (id, svg); the files
/// written, in that order.
pub(crate) fn write_plane_files(
    dir: &Path,
    report: (&str, String),
    tables: impl IntoIterator<Item = (String, String)>,
    figures: impl IntoIterator<Item = Result<Option<(String, String)>, StudyError>>,
) -> Result<Vec<PathBuf>, StudyError> {
    let mut written = vec![];
    plane::write_text(&dir.join(report.0), &report.1, &mut written)?;
    for (file, text) in tables {
        plane::write_text(&dir.join(file), &text, &mut written)?;
    }
    for f in figures {
        if let Some((id, svg)) = f? {
            plane::write_text(&dir.join(format!("{id}.svg")), &svg, &mut written)?;
        }
    }
    Ok(written)
}

/// The reports index entry of a plane-strain study: its report, tables (title, file) and
/// figures (title, id).
pub(crate) fn plane_index_entry(
    header: (String, String, crate::study::Tier),
    checks: Vec<CheckRecord>,
    report_file: &str,
    tables: impl IntoIterator<Item = (String, String)>,
    figures: impl IntoIterator<Item = (String, String)>,
) -> IndexEntry {
    let mut files = vec![("report".to_string(), report_file.to_string())];
    files.extend(tables);
    files.extend(
        figures
            .into_iter()
            .map(|(title, id)| (title, format!("{id}.svg"))),
    );
    let (name, summary, tier) = header;
    IndexEntry {
        name,
        summary,
        tier,
        checks,
        files,
    }
}
