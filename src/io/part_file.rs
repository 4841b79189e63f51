//! Part files (TOML). (work in progress)

/// Errors reading a part file.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum PartFileError {
    /// Placeholder.
    #[error("bad part file")]
    Invalid,
}
