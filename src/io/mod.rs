//! **Stage 0 — reading and writing files.** Part files, cell files, atomic writes.
pub mod cell_file;
pub mod part_file;
