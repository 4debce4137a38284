//! Rendering: tables, figures and index pages from the results files a study wrote, one
//! module per study kind (criterion's split between analysis and report). Nothing here solves.

pub mod cantilever;
pub mod column;
pub mod compaction;
