//! **Stage 0 — reading and writing files.** Part files, cell files, atomic writes.
pub mod atomic;
pub mod part_file;
pub mod path_csv;
