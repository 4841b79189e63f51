//! **Stage 1 — tube geometry.** Describes a tube as a guide curve `Mg(t)`, a
//! frame field along it and a circular profile of radius `A(t)`, and the
//! substrate it is built on; gives surface points `M(t, v)`, derivatives and
//! normals (part frame, mm, rad) and the first layer `tube ∩ substrate`.
//! SPEC §2; thesis eq. 2.1–2.33. Build a [`Tube`] with [`Tube::new`], which
//! validates it once; every later stage takes `&Tube`.

pub mod frame;
pub mod guide;
pub mod plane;
pub mod profile;
pub mod substrate;
pub mod tube;

pub use frame::{Frame, FrameField, FrameMethod};
pub use guide::GuideCurve;
pub use plane::Plane;
pub use profile::{ProfileLaw, ProfilePiece};
pub use substrate::{CurvePoint, MeshSubstrate, Substrate};
pub use tube::{SurfacePoint, Tube, TubeRange};

/// Errors of the geometry stage; each names where it happened.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum GeometryError {
    /// An expression could not be parsed or differentiated.
    #[error("expression `{text}`: {reason}")]
    Expression {
        /// The expression text.
        text: String,
        /// What is wrong.
        reason: String,
    },
    /// A spline's input points are unusable.
    #[error("spline point {index}: {reason}")]
    Spline {
        /// Index of the offending point.
        index: usize,
        /// What is wrong.
        reason: String,
    },
    /// A pipe-run segment is invalid.
    #[error("pipe segment {index}: {reason}")]
    Pipe {
        /// Index of the offending segment.
        index: usize,
        /// What is wrong.
        reason: String,
    },
    /// A named input field is invalid.
    #[error("{field}: {reason}")]
    InvalidField {
        /// The field (dotted path as in the part file).
        field: String,
        /// What is wrong.
        reason: String,
    },
    /// The parameter range is empty or not finite.
    #[error("empty or non-finite parameter range: t_min = {t_min}, t_max = {t_max} (need t_min < t_max, extensions >= 0)")]
    EmptyRange {
        /// Lower bound.
        t_min: f64,
        /// Upper bound.
        t_max: f64,
    },
    /// The guide's derivative vanishes: the curve stops and has no tangent.
    #[error("guide curve has zero derivative at t = {t:.6}: no tangent there")]
    ZeroDerivative {
        /// Where.
        t: f64,
    },
    /// A value is NaN or infinite.
    #[error("{what} is not finite at t = {t:.6}")]
    NonFinite {
        /// Which quantity.
        what: &'static str,
        /// Where.
        t: f64,
    },
    /// The profile radius is zero or negative.
    #[error("profile radius A(t) = {radius} mm is not positive at t = {t:.6}")]
    NonPositiveRadius {
        /// Where.
        t: f64,
        /// The radius there (mm).
        radius: f64,
    },
    /// The profile radius reaches the guide's radius of curvature: the surface folds.
    #[error("tube folds at t = {t:.6}: profile radius {radius:.4} mm >= guide radius of curvature {radius_of_curvature:.4} mm")]
    Folds {
        /// Where.
        t: f64,
        /// Profile radius there (mm).
        radius: f64,
        /// Guide radius of curvature there (mm).
        radius_of_curvature: f64,
    },
    /// Frenet frame requested where the guide is straight.
    #[error("Frenet frame undefined at t = {t:.6}: the guide's curvature is zero there (use the rotation-minimising frame, `method = \"rmf\"`)")]
    FrenetUndefined {
        /// Where.
        t: f64,
    },
    /// The tube does not meet the substrate along an iso-`v` line.
    #[error("substrate misses the tube at v = {v:.6} rad: {reason}")]
    SubstrateMiss {
        /// Profile angle (rad).
        v: f64,
        /// Details.
        reason: String,
    },
    /// An STL mesh could not be used.
    #[error("STL `{file}`: {reason}")]
    Stl {
        /// File name or other source.
        file: String,
        /// What is wrong.
        reason: String,
    },
}
