//! The compressor's error: why a bead could not be compressed (by
//! [`compress`](super::compress)) or a move not measured (by
//! [`move_deviation`](super::move_deviation)). Part of the program stage's
//! bead compression; the [parent module](super) describes the model.

use std::fmt;

/// Why a bead could not be compressed or a move not measured.
#[derive(Clone, Debug, PartialEq)]
pub enum CompressError {
    /// An option is out of range; `field` is its name in [`CompressOptions`](super::CompressOptions).
    InvalidOption {
        /// Field name.
        field: &'static str,
        /// What is wrong.
        reason: &'static str,
    },
    /// The bead has no poses.
    EmptyBead,
    /// Pose `index` has a non-finite value or a non-unit quaternion.
    InvalidPose {
        /// Index into the input poses.
        index: usize,
        /// What is wrong.
        reason: &'static str,
    },
    /// Pose `index` has `found` extra axes where pose 0 has `expected`.
    ExtLengthMismatch {
        /// Index into the input poses.
        index: usize,
        /// Extra axis count of the first pose.
        expected: usize,
        /// Extra axis count of this pose.
        found: usize,
    },
    /// The must-keep slice is neither empty nor as long as the poses.
    KeepLengthMismatch {
        /// Number of poses.
        expected: usize,
        /// Length of the must-keep slice.
        found: usize,
    },
    /// The map returned a non-finite point or a zero / non-finite axis, for
    /// pose `index` or for an interpolated pose of a move starting at `index`.
    InvalidMapOutput {
        /// Index into the input poses.
        index: usize,
    },
    /// A move given to [`move_deviation`](super::move_deviation) has out-of-range indices.
    InvalidMove {
        /// What is wrong.
        reason: &'static str,
    },
}

impl fmt::Display for CompressError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::InvalidOption { field, reason } => write!(f, "option `{field}` {reason}"),
            Self::EmptyBead => write!(f, "the bead has no poses"),
            Self::InvalidPose { index, reason } => write!(f, "pose {index}: {reason}"),
            Self::ExtLengthMismatch {
                index,
                expected,
                found,
            } => write!(
                f,
                "pose {index} has {found} extra axes, expected {expected}"
            ),
            Self::KeepLengthMismatch { expected, found } => {
                write!(
                    f,
                    "must-keep slice has {found} entries, expected 0 or {expected}"
                )
            }
            Self::InvalidMapOutput { index } => {
                write!(
                    f,
                    "map returned a non-finite point or invalid axis near pose {index}"
                )
            }
            Self::InvalidMove { reason } => write!(f, "invalid move: {reason}"),
        }
    }
}

impl std::error::Error for CompressError {}
