//! The vendor-neutral words of a robot program: how a position is written
//! and how the controller moves to it. Every vendor's emitter, reader and
//! decoder uses these; none defines its own.

use serde::{Deserialize, Serialize};

/// How positions are written: joint values, or a Cartesian pose with the
/// controller's configuration data (FANUC `CONFIG`, KUKA Status/Turn, ABB
/// `confdata`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum PositionMode {
    /// `J1..J6` in degrees (the thesis's articular mode: the branch is ours).
    #[default]
    Joint,
    /// `X Y Z W P R` with configuration string and turn numbers.
    Cartesian,
}

/// How the controller moves to a position: a joint move (FANUC `J`, KUKA
/// `PTP`, ABB `MoveAbsJ`/`MoveJ`), a linear one (FANUC `L`, KUKA `LIN`,
/// ABB `MoveL`/`ArcL`) or a circular one (FANUC `C`, KUKA `CIRC`, ABB
/// `MoveC`/`ArcC`), whose via position comes first as a [`MoveKind::Via`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MoveKind {
    /// Joint interpolation.
    Joint,
    /// Linear interpolation of the tool point, orientation interpolated.
    Linear,
    /// The via (auxiliary, circle) point of a circular move: not a move of
    /// its own; the controller passes through this position on its way to
    /// the next one, which is the [`MoveKind::Circular`] end.
    Via,
    /// Circular interpolation of the tool point from the previous position
    /// through the via to this one, orientation interpolated from start to
    /// end ([`interpolate`](crate::program::compress::interpolate)).
    Circular,
}
