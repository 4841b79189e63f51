//! **Stage 0 — reading and writing files.** Part files, cell files, atomic writes.
pub mod part_file;
