//! **Stage 6a — the positioner's laws: outcomes as data.** A layer's laws
//! ([`PositionerLaw`]: `[q7, q8]` per point in rad, the largest tilt of `b`
//! from the vertical, the rate bound in rad/s, the grids' proof), the start
//! they came from ([`PositionerSeed`]) and the constraint that binds them
//! ([`PositionerBinding`]).

use serde::{Deserialize, Serialize};

use crate::robot::positioner::PositionerJoints;

/// Which positioner constraint binds a law.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum PositionerBinding {
    /// `b` leaves the cone of the vertical (rad over the cone).
    Cone {
        /// Point index within the layer.
        point: usize,
        /// Angle of `b` from the vertical (rad).
        tilt_rad: f64,
        /// The cone's half angle (rad).
        max_rad: f64,
    },
    /// An axis outside its travel.
    Travel {
        /// 7 (tilt) or 8 (turn).
        joint: usize,
        /// Point index within the layer.
        point: usize,
        /// Value (rad).
        value_rad: f64,
    },
    /// The endless turn leaves the window of the controller's stroke the
    /// bead was shifted into ([`TorchCarriedCell::turn_stroke`](crate::robot::cell::TorchCarriedCell::turn_stroke), less the
    /// plan's margin, moved by whole turns): the bead turns the table
    /// through more than the program can hold.
    Stroke {
        /// Point index within the layer.
        point: usize,
        /// Value (rad).
        value_rad: f64,
        /// The window's lower bound (rad).
        lower_rad: f64,
        /// The window's upper bound (rad).
        upper_rad: f64,
    },
    /// An axis faster than its maximum at the programmed travel speed.
    Speed {
        /// 7 (tilt) or 8 (turn).
        joint: usize,
        /// Point index within the layer (the step from the point before).
        point: usize,
        /// Speed needed (rad/s).
        speed_rad_s: f64,
        /// Maximum (rad/s).
        max_rad_s: f64,
    },
}

impl std::fmt::Display for PositionerBinding {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match *self {
            Self::Cone {
                point,
                tilt_rad,
                max_rad,
            } => write!(
                f,
                "build direction {:.2}° from the vertical at point {point} (cone {:.1}°)",
                tilt_rad.to_degrees(),
                max_rad.to_degrees()
            ),
            Self::Travel {
                joint,
                point,
                value_rad,
            } => write!(
                f,
                "positioner J{joint} = {:.2}° outside its travel at point {point}",
                value_rad.to_degrees()
            ),
            Self::Stroke {
                point,
                value_rad,
                lower_rad,
                upper_rad,
            } => write!(
                f,
                "positioner J8 = {:.1}° at point {point} outside the turn's stroke [{:.1}°, {:.1}°] (shifted by whole turns): the bead turns the table through more than the program holds",
                value_rad.to_degrees(),
                lower_rad.to_degrees(),
                upper_rad.to_degrees()
            ),
            Self::Speed {
                joint,
                point,
                speed_rad_s,
                max_rad_s,
            } => write!(
                f,
                "positioner J{joint} needs {:.1}°/s at point {point}, maximum {:.1}°/s",
                speed_rad_s.to_degrees(),
                max_rad_s.to_degrees()
            ),
        }
    }
}

/// Which start the kept law came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum PositionerSeed {
    /// Held at the pose that turns the layer's mean `b` vertical.
    Hold,
    /// Every point's `b` exactly vertical (the thesis), fitted by the law.
    Follow,
    /// The pose held while `b` stays well inside the cone, moved just
    /// enough where it would leave it, fitted by the law.
    Lazy,
    /// Every point's `b` exactly vertical, not fitted: with
    /// [`PositionerMode::Vertical`](super::PositionerMode::Vertical), or where no smooth law keeps the cone
    /// (a corner of `b`) and the positioner's speeds allow it.
    Vertical,
    /// The law the arm could not follow, solved again under the arm's
    /// linearised constraints ([`ArmRow`](super::ArmRow), [`positioner_law_for_arm`](super::positioner_law_for_arm)).
    Arm,
    /// A path of positioner poses over a grid of 0.25–2° cells that keeps
    /// `b` inside the cone at every point of the layer within the axes'
    /// speeds (the reachable poses propagated point to point, followed back
    /// with the least motion and relaxed), fitted by the law, or kept as it
    /// is where no fit keeps the constraints: where no other start's law
    /// keeps the cone (a layer whose `b` passes the pole and swings far off
    /// it, or turns a corner off the pole, where the smooth starts fall into
    /// a local minimum).
    Grid,
}

/// The positioner's laws of one layer and how they were found.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PositionerLaw {
    /// `[q7, q8]` per point of the layer (rad).
    pub joints: Vec<PositionerJoints>,
    /// Largest angle of `b` (robot base frame) from the vertical (rad).
    pub max_tilt_rad: f64,
    /// The point where it is reached.
    pub max_tilt_point: usize,
    /// The seed kept.
    pub seed: PositionerSeed,
    /// `true` when cone, travel and speeds hold at every point.
    pub feasible: bool,
    /// The most violated constraint when not feasible.
    pub binding: Option<PositionerBinding>,
    /// SQP iterations (both seeds, all rounds).
    pub iterations: usize,
    /// Points the law was solved on.
    pub samples: usize,
    /// The objective of the module doc at the law kept (rad², eq. 4.3
    /// form; 0 in [`PositionerMode::Vertical`](super::PositionerMode::Vertical)).
    pub objective: f64,
    /// A bound from the geometry alone: the positioner must turn the part
    /// at least this fast (rad/s) somewhere on the layer to keep `b` within
    /// the cone ([`required_rotation_rate`](super::required_rotation_rate)); `inf` at a corner of `b`.
    pub required_rate_rad_s: f64,
    /// The fastest the positioner can turn the part, `v7 + v8` (rad/s; `inf`
    /// when a speed is unknown).
    pub available_rate_rad_s: f64,
    /// `true` when the geometry proves the layer cannot be built in this
    /// cell whatever the arm and the positioner do: the rate bound
    /// (`required > available`), or no positioner path reaches
    /// [`PositionerLaw::unreachable_point`].
    pub proven_infeasible: bool,
    /// Where a layer the laws could not keep in the cone was also searched
    /// on a grid of positioner poses ([`unreachable_point`](super::unreachable_point)): the first point
    /// that no positioner motion within its travel and speeds reaches with
    /// `b` inside the cone. `None`: not searched, or reached.
    pub unreachable_point: Option<usize>,
    /// The stretch of the layer `(i, j)` (point indices) where the bound is reached.
    pub required_between: (usize, usize),
    /// The other starts' laws that also hold cone, travel and speeds, best
    /// objective first: the positioner sees the arm only through a proxy,
    /// so where the arm cannot follow the kept law (hose torsion, a joint's
    /// speed) the layer is planned again on these. Not serialised.
    #[serde(skip)]
    pub alternatives: Vec<PositionerLaw>,
}
