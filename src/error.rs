//! The crate-level error: one variant per stage, each wrapping that stage's own
//! error enum (which names the file, field, layer or point at fault).

use crate::geometry::GeometryError;
use crate::io::part_file::PartFileError;

/// Any error of the library.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// Building or evaluating the tube geometry failed.
    #[error(transparent)]
    Geometry(#[from] GeometryError),
    /// A part file could not be read.
    #[error(transparent)]
    PartFile(#[from] PartFileError),
}
