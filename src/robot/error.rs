//! The error enum of the robot stage (SPEC §6).

/// Errors of the robot stage: invalid models and cells, poses the arm cannot
/// take (unreachable, singular), calibration data that cannot be fitted.
///
/// A numerical outcome along a trajectory (a joint over its limit, too fast,
/// near a singularity) is not an error: it is listed in the trajectory's
/// [`TrajectoryReport`](crate::robot::trajectory::TrajectoryReport).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum RobotError {
    /// A field of a robot model, positioner or cell is out of its domain.
    #[error("{what}: field `{field}` = {value} is invalid ({reason})")]
    InvalidParameter {
        /// The object being built (robot name, "part-carried cell", ...).
        what: String,
        /// The field at fault, as named in the cell file.
        field: &'static str,
        /// The offending value (file units).
        value: f64,
        /// Why it is rejected.
        reason: &'static str,
    },
    /// The wrist centre is out of reach of the arm for this configuration.
    #[error(
        "pose out of reach: wrist centre at ({wrist_x_mm:.3}, {wrist_y_mm:.3}, {wrist_z_mm:.3}) mm \
         (base frame) is {distance_mm:.3} mm from the J2 axis; the arm spans \
         {min_reach_mm:.3}..{max_reach_mm:.3} mm"
    )]
    Unreachable {
        /// Wrist centre, base frame (mm).
        wrist_x_mm: f64,
        /// Wrist centre, base frame (mm).
        wrist_y_mm: f64,
        /// Wrist centre, base frame (mm).
        wrist_z_mm: f64,
        /// Distance from the shoulder (J2 axis) to the wrist centre in the arm plane (mm).
        distance_mm: f64,
        /// Smallest reachable distance (arm folded) (mm).
        min_reach_mm: f64,
        /// Largest reachable distance (arm stretched) (mm).
        max_reach_mm: f64,
    },
    /// A cell puts its work out of the arm's reach: the point named by
    /// the field (the part-carried deposition point, or the torch-carried
    /// positioner's tilt centre) is too far from (or too near to) the
    /// shoulder for any pose of the arm, whatever the path. See
    /// [`CellLayout::check_reach`](crate::robot::CellLayout::check_reach).
    #[error("{0}")]
    OutOfReach(Box<OutOfReach>),
    /// The wrist centre lies on the J1 axis: J1 is undetermined.
    #[error(
        "shoulder singularity: the wrist centre is {distance_mm:.3e} mm from the J1 axis, J1 is undetermined"
    )]
    ShoulderSingularity {
        /// Distance from the wrist centre to the J1 axis, minus the lateral offset (mm).
        distance_mm: f64,
    },
    /// J5 is zero: J4 and J6 turn about the same axis and only their sum is determined.
    #[error(
        "wrist singularity: |sin J5| = {sin_j5:.3e}, J4 and J6 are undetermined (only J4 ± J6 is)"
    )]
    WristSingularity {
        /// |sin J5| at the pose.
        sin_j5: f64,
    },
    /// A pose or joint vector contains NaN or infinite values.
    #[error("non-finite input: {what}")]
    NonFinite {
        /// Which input.
        what: &'static str,
    },
    /// The positioner cannot turn this build direction vertical.
    #[error(
        "positioner: build direction ({bx:.4}, {by:.4}, {bz:.4}) (part frame) cannot be turned vertical"
    )]
    PositionerUnreachable {
        /// Build direction, part frame.
        bx: f64,
        /// Build direction, part frame.
        by: f64,
        /// Build direction, part frame.
        bz: f64,
    },
    /// Calibration input is inconsistent or too small.
    #[error("calibration: {reason} ({count} measurements)")]
    Calibration {
        /// What is wrong.
        reason: &'static str,
        /// Number of measurements supplied.
        count: usize,
    },
    /// A trajectory input point is malformed.
    #[error("trajectory input, layer {layer}, point {point}: {reason}")]
    BadPathPoint {
        /// Layer index.
        layer: usize,
        /// Point index within the layer.
        point: usize,
        /// What is wrong.
        reason: &'static str,
    },
    /// The `R_Z` parameterisation of the part-carried cell [eq. 3.6–3.7] is
    /// degenerate: the tool axis rotated by `R_Z` is horizontal along Y, so
    /// `R_X = ±90°` and the part orientation does not depend smoothly on `R_Z`.
    #[error(
        "degenerate R_Z parameterisation: tool axis ({tx:.4}, {ty:.4}, {tz:.4}) (part frame) at R_Z = {r_z:.4} rad gives R_X = ±90°"
    )]
    DegenerateToolAxis {
        /// Tool axis, part frame.
        tx: f64,
        /// Tool axis, part frame.
        ty: f64,
        /// Tool axis, part frame.
        tz: f64,
        /// The free angle (rad).
        r_z: f64,
    },
    /// The Jacobian cannot be inverted (the arm is at a singularity).
    #[error("singular Jacobian (manipulability {manipulability:.3e} mm³), dq/dR_Z undefined")]
    SingularJacobian {
        /// `sqrt(det(J Jᵀ))` at the pose (mm³).
        manipulability: f64,
    },
    /// Trajectory options out of their domain.
    #[error("trajectory options: `{field}` = {value} is invalid ({reason})")]
    InvalidOptions {
        /// The field at fault.
        field: &'static str,
        /// The offending value.
        value: f64,
        /// Why it is rejected.
        reason: &'static str,
    },
}

/// What [`RobotError::OutOfReach`] reports: the field, the point, its
/// distance from the shoulder circle and the arm's reach.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error(
    "{what}: `{field}` = ({}, {}, {}) mm (base frame) is out of the arm's reach: \
     {} mm from the shoulder (J2 axis) circle, where the arm with its mounts and \
     the part reaches {}..{} mm (upper arm and forearm {}..{} mm, plus {} mm of \
     wrist, mounts and part)",
    Mm(point_mm[0]), Mm(point_mm[1]), Mm(point_mm[2]), Mm(*distance_mm), Mm(*min_reach_mm),
    Mm(*max_reach_mm), Mm(*arm_min_mm), Mm(*arm_max_mm), Mm(*max_reach_mm - *arm_max_mm)
)]
pub struct OutOfReach {
    /// The cell's name.
    pub what: String,
    /// The cell-file field at fault (`deposition_point_mm`, `positioner_pose_xyzwpr`).
    pub field: &'static str,
    /// The point, base frame (mm).
    pub point_mm: [f64; 3],
    /// Distance from the point to the shoulder circle (mm): the nearest
    /// when the point is too far, the farthest when it is too near.
    pub distance_mm: f64,
    /// Smallest distance the cell can work at (mm): the folded arm less the allowance.
    pub min_reach_mm: f64,
    /// Largest distance the cell can work at (mm): the stretched arm plus the allowance.
    pub max_reach_mm: f64,
    /// Shoulder → wrist centre distance, arm folded (mm).
    pub arm_min_mm: f64,
    /// Shoulder → wrist centre distance, arm stretched (mm).
    pub arm_max_mm: f64,
}

/// A length in mm for messages: one decimal, or three significant digits
/// in exponent form beyond 10 km (a typo such as `1e308` stays readable).
struct Mm(f64);

impl std::fmt::Display for Mm {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        if self.0.is_finite() && self.0.abs() < 1e7 {
            write!(f, "{:.1}", self.0)
        } else {
            write!(f, "{:.3e}", self.0)
        }
    }
}
