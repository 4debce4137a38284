//! The study harness end to end: study files, the tiers of every study, re-rendering byte
//! for byte, resume, ParaView output and thread-count independence. One test binary.

mod bar_study;
mod cantilever_dynamic_study;
mod cantilever_study;
mod column3d_study;
mod committed_answers;
mod compaction_reference_study;
mod compaction_study;
mod defects;
mod element_study;
mod external;
mod figures;
mod first_contact;
mod footing_newton;
mod manufactured3d_study;
mod manufactured_dynamic_study;
mod manufactured_study;
mod performance;
mod reliability;
mod resume;
mod scene_study;
mod schema_doc;
mod step_record;
mod study;
mod three_d_studies;
mod trimmed;
mod usability;
