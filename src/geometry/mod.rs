//! **Stage 1 — tube geometry.** (work in progress)

/// Errors of the geometry stage.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum GeometryError {
    /// Placeholder.
    #[error("invalid geometry")]
    Invalid,
}
