//! **Stage 0 — reading and writing files.** Part files, cell files, path CSV,
//! joints CSV, the wall STL, atomic writes.
pub mod atomic;
pub mod cell_file;
pub mod decimal;
pub mod joints_csv;
pub mod part_file;
pub mod path_csv;
pub mod wall_stl;
