//! **Files, at the edges of the pipeline.** Reads part files and cell files
//! into the stages' own types (tube, substrate, slicing and process settings;
//! robot, cell layout, program options), and writes the path and joints CSV
//! and the wall STL. It sits above the stages it reads into (it imports
//! them; none of them imports it); atomic writes and decimal text are the
//! leaf [`util`](crate::util), re-exported here at their former paths.
pub mod cell_file;
pub mod joints_csv;
pub mod part_file;
pub mod path_csv;
pub mod wall_stl;

// Kept at their former paths for callers (moved to the leaf `util`).
pub use crate::util::{atomic, decimal};
