//! **Joint trajectory of a path in a cell.** Takes path points (layer, point,
//! position in the part frame (mm), tool axis, free angle `R_Z` (rad)) and a
//! travel speed (mm/s) and returns, per point, the joints (rad) in the cell's
//! configuration with J6 (and every joint) unwrapped along the path, joint
//! speeds (rad/s), dexterity, `dq/dR_Z`, and a report of every joint-limit,
//! speed, singularity and hose-torsion violation naming layer, point and
//! joint. SPEC §6.2, §6.4, §7.
//!
//! Plain inputs ([`PathPointInput`]) so that this stage does not depend on
//! the path module.

use std::fmt;

use serde::{Deserialize, Serialize};

use crate::math::{Point3, UnitVector3};
use crate::robot::cell::{CellLayout, CellPoint, CellPose, TorchCarriedCell};
use crate::robot::ik::Configuration;
use crate::robot::indices::{dexterity_warm, SvdWarmStart};
use crate::robot::model::Joints;
use crate::robot::positioner::PositionerJoints;
use crate::robot::RobotError;

/// Slack on the torch-carried build tilt bound (rad): rounding of the chain
/// of rotations.
const BUILD_TILT_ROUNDING_RAD: f64 = 1e-9;

/// One path point, as the trajectory stage needs it.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct PathPointInput {
    /// Layer index.
    pub layer: usize,
    /// Point index within the layer.
    pub point: usize,
    /// Deposition point, part frame (mm).
    pub position_mm: Point3,
    /// Tool axis `T` (unit, from the deposition point towards the torch), part frame.
    pub tool_axis: UnitVector3,
    /// Build direction `b` (unit), part frame; the torch-carried cell turns it
    /// vertical. `None`: the tool axis is used.
    pub build_direction: Option<UnitVector3>,
    /// The free angle about the tool axis `R_Z` (rad).
    pub r_z: f64,
    /// Positioner joints `[q7, q8]` (rad) planned for this point
    /// (torch-carried cell); `None`: `b` turned exactly vertical.
    #[serde(default)]
    pub positioner: Option<PositionerJoints>,
    /// The bead within the layer: 0 for its first (or only) bead, one more
    /// at each split at a corner (the points of a layer split in beads
    /// share the split point, one in each bead).
    #[serde(default)]
    pub bead: usize,
    /// Travel speed of the deposition point on the way into this point
    /// from the previous point of its bead (mm/s, along the chord); unused
    /// at a bead's first point.
    pub travel_speed_mm_s: f64,
}

impl PathPointInput {
    /// Whether `other` is a point of the same bead (same layer and bead).
    pub fn same_bead(&self, other: &PathPointInput) -> bool {
        self.layer == other.layer && self.bead == other.bead
    }
}

/// Options of [`joint_trajectory`]. Plain data.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct TrajectoryOptions {
    /// Wrist singularity reported when `|sin J5| < sin(margin)` (rad). Default 5°.
    pub wrist_singularity_margin_rad: f64,
    /// Elbow singularity reported when `|cos gamma| < sin(margin)` (rad). Default 2°.
    pub elbow_singularity_margin_rad: f64,
    /// Shoulder singularity reported when the wrist centre is closer than
    /// this to the J1 axis (mm). Default 50 mm.
    pub shoulder_singularity_margin_mm: f64,
    /// Length dividing the linear rows of the Jacobian for the dexterity (mm);
    /// 1 reproduces the thesis's raw index. Default 1.
    pub dexterity_length_scale_mm: f64,
    /// Compute `dq/dR_Z` per point. Default `true`.
    pub with_derivatives: bool,
    /// Start every layer from the joint representation inside the travel
    /// (unlimited joints in `(-180°, 180°]`) instead of unwrapping from the
    /// previous layer's last point: the arc is off between layers and the
    /// robot may rewind J4/J6 there. Default `true`.
    pub rewind_between_layers: bool,
}

impl Default for TrajectoryOptions {
    fn default() -> Self {
        Self {
            wrist_singularity_margin_rad: 5f64.to_radians(),
            elbow_singularity_margin_rad: 2f64.to_radians(),
            shoulder_singularity_margin_mm: 50.0,
            dexterity_length_scale_mm: 1.0,
            with_derivatives: true,
            rewind_between_layers: true,
        }
    }
}

impl TrajectoryOptions {
    /// Checks every field.
    ///
    /// # Errors
    /// [`RobotError::InvalidOptions`] naming the field.
    pub fn validate(&self) -> Result<(), RobotError> {
        let bad = |field, value, reason| RobotError::InvalidOptions {
            field,
            value,
            reason,
        };
        for (f, v) in [
            (
                "wrist_singularity_margin_rad",
                self.wrist_singularity_margin_rad,
            ),
            (
                "elbow_singularity_margin_rad",
                self.elbow_singularity_margin_rad,
            ),
        ] {
            if !(0.0..std::f64::consts::FRAC_PI_2).contains(&v) {
                return Err(bad(f, v, "must be in [0, π/2)"));
            }
        }
        if !(self.shoulder_singularity_margin_mm >= 0.0
            && self.shoulder_singularity_margin_mm.is_finite())
        {
            return Err(bad(
                "shoulder_singularity_margin_mm",
                self.shoulder_singularity_margin_mm,
                "must be finite and >= 0",
            ));
        }
        if !(self.dexterity_length_scale_mm > 0.0 && self.dexterity_length_scale_mm.is_finite()) {
            return Err(bad(
                "dexterity_length_scale_mm",
                self.dexterity_length_scale_mm,
                "must be finite and > 0",
            ));
        }
        Ok(())
    }
}

/// Which singularity a point is near.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SingularityKind {
    /// J5 near 0.
    Wrist,
    /// Arm stretched or folded.
    Elbow,
    /// Wrist centre near the J1 axis.
    Shoulder,
}

/// What is wrong at a point.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum ViolationKind {
    /// A joint outside its travel.
    JointLimit {
        /// Joint number, 1-based (J1..J6, 7/8 for the positioner).
        joint: usize,
        /// Value (rad).
        value_rad: f64,
        /// Lower bound (rad).
        lower_rad: f64,
        /// Upper bound (rad).
        upper_rad: f64,
    },
    /// A joint faster than its maximum at the programmed travel speed,
    /// between the previous point and this one.
    JointSpeed {
        /// Joint number, 1-based.
        joint: usize,
        /// Speed needed (rad/s).
        speed_rad_s: f64,
        /// Maximum (rad/s).
        max_rad_s: f64,
    },
    /// Near a singularity.
    Singularity {
        /// Which.
        kind: SingularityKind,
        /// The measure (`|sin J5|`, `|cos gamma|` or mm), as in
        /// [`SingularityMeasures`](crate::robot::ik::SingularityMeasures).
        measure: f64,
    },
    /// Torch hose torsion `|q4 + q6|` over its limit (torch-carried cell).
    HoseTorsion {
        /// `|q4 + q6|` (rad).
        torsion_rad: f64,
        /// Limit (rad).
        max_rad: f64,
    },
    /// The build direction `b`, seen in the robot base frame, outside the
    /// torch-carried cell's cone of the vertical (`max_vertical_error_deg`).
    BuildTilt {
        /// Angle of `b` from the vertical (rad).
        tilt_rad: f64,
        /// The cone's half angle (rad).
        max_rad: f64,
    },
    /// No joints for this point.
    NoSolution(RobotError),
}

/// One problem at one point.
#[derive(Debug, Clone, PartialEq)]
pub struct Violation {
    /// Layer index.
    pub layer: usize,
    /// Point index within the layer.
    pub point: usize,
    /// What.
    pub kind: ViolationKind,
}

impl fmt::Display for Violation {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "layer {}, point {}: ", self.layer, self.point)?;
        match &self.kind {
            ViolationKind::JointLimit {
                joint,
                value_rad,
                lower_rad,
                upper_rad,
            } => write!(
                f,
                "J{joint} = {:.3}° outside [{:.1}°, {:.1}°]",
                value_rad.to_degrees(),
                lower_rad.to_degrees(),
                upper_rad.to_degrees()
            ),
            ViolationKind::JointSpeed {
                joint,
                speed_rad_s,
                max_rad_s,
            } => write!(
                f,
                "J{joint} needs {:.2}°/s, maximum {:.1}°/s",
                speed_rad_s.to_degrees(),
                max_rad_s.to_degrees()
            ),
            ViolationKind::Singularity { kind, measure } => {
                write!(f, "near the {kind:?} singularity (measure {measure:.4})")
            }
            ViolationKind::HoseTorsion {
                torsion_rad,
                max_rad,
            } => write!(
                f,
                "hose torsion |J4 + J6| = {:.2}° over {:.1}°",
                torsion_rad.to_degrees(),
                max_rad.to_degrees()
            ),
            ViolationKind::BuildTilt { tilt_rad, max_rad } => write!(
                f,
                "build direction {:.2}° from the vertical, cone {:.1}°",
                tilt_rad.to_degrees(),
                max_rad.to_degrees()
            ),
            ViolationKind::NoSolution(e) => write!(f, "no joint solution: {e}"),
        }
    }
}

/// Every problem of a trajectory, in path order.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct TrajectoryReport {
    /// The problems.
    pub violations: Vec<Violation>,
}

impl TrajectoryReport {
    /// `true` when nothing is wrong: the path is buildable as computed.
    pub fn is_clean(&self) -> bool {
        self.violations.is_empty()
    }

    /// Joint-limit violations of joint `joint` (1-based).
    pub fn limit_violations_of(&self, joint: usize) -> impl Iterator<Item = &Violation> {
        self.violations.iter().filter(
            move |v| matches!(v.kind, ViolationKind::JointLimit { joint: j, .. } if j == joint),
        )
    }
}

impl fmt::Display for TrajectoryReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.violations.is_empty() {
            return writeln!(f, "no violation");
        }
        for v in &self.violations {
            writeln!(f, "{v}")?;
        }
        Ok(())
    }
}

/// Joints and derived quantities at one path point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JointPoint {
    /// Layer index.
    pub layer: usize,
    /// The bead within the layer ([`PathPointInput::bead`]).
    pub bead: usize,
    /// Point index within the layer.
    pub point: usize,
    /// Robot joints (rad), unwrapped along the path; `None` if no solution.
    pub joints: Option<Joints>,
    /// Positioner joints `[q7, q8]` (rad), torch-carried cell only.
    pub positioner: Option<PositionerJoints>,
    /// Joint speeds from the previous point of the layer at the travel speed
    /// (rad/s, signed); zero at the first point of a layer.
    pub joint_speed_rad_s: Joints,
    /// Time from the previous point of the layer (s).
    pub dt_s: f64,
    /// Dexterity `xi_min/xi_max` [eq. 1.8] (options' length scale).
    pub dexterity: f64,
    /// `dq/dR_Z` (rad/rad) if asked for and defined.
    pub dq_drz: Option<Joints>,
}

/// The joint trajectory of a path and its report.
#[derive(Debug, Clone, PartialEq)]
pub struct JointTrajectory {
    /// The configuration used throughout.
    pub configuration: Configuration,
    /// One entry per input point, same order.
    pub points: Vec<JointPoint>,
    /// Every violation found.
    pub report: TrajectoryReport,
}

impl JointTrajectory {
    /// Points of layer `layer`, in order.
    pub fn layer(&self, layer: usize) -> impl Iterator<Item = &JointPoint> {
        self.points.iter().filter(move |p| p.layer == layer)
    }
}

/// Joint trajectory of `points` in `cell`, each point reached at its own
/// travel speed ([`PathPointInput::travel_speed_mm_s`]).
///
/// The cell's configuration is used for every point; each point's joints
/// are unwrapped towards the previous point's (so J6, unlimited, turns
/// continuously within a layer); the first point of a layer takes the
/// representation inside each joint's travel (see
/// [`TrajectoryOptions::rewind_between_layers`]). Joint speeds are `Δq / Δt` with
/// `Δt = |M_m − M_{m−1}| / TS_m` (part frame, consecutive points of a layer).
///
/// # Errors
/// Only for bad input: [`RobotError::InvalidOptions`] (options, travel speed),
/// [`RobotError::BadPathPoint`] (non-finite position or `R_Z`). Points without
/// solution are reported, not errors.
pub fn joint_trajectory(
    cell: &CellLayout,
    points: &[PathPointInput],
    opts: &TrajectoryOptions,
) -> Result<JointTrajectory, RobotError> {
    trajectory(cell, points, opts, true)
}

/// [`joint_trajectory`] without the dexterity (0 at every point) and
/// `dq/dR_Z` (`None`): the same joints, speeds and violations, for a
/// program model, which reads nothing else.
///
/// # Errors
/// As [`joint_trajectory`].
pub(crate) fn joint_trajectory_without_measures(
    cell: &CellLayout,
    points: &[PathPointInput],
    opts: &TrajectoryOptions,
) -> Result<JointTrajectory, RobotError> {
    trajectory(cell, points, opts, false)
}

fn trajectory(
    cell: &CellLayout,
    points: &[PathPointInput],
    opts: &TrajectoryOptions,
    measures: bool,
) -> Result<JointTrajectory, RobotError> {
    check_inputs(points, opts)?;
    let robot = cell.robot();
    let hose_limit = match cell {
        CellLayout::TorchCarried(c) => Some(c.max_hose_torsion_rad),
        CellLayout::PartCarried(_) => None,
    };
    let mut report = TrajectoryReport::default();
    let mut out: Vec<JointPoint> = Vec::with_capacity(points.len());
    let mut prev_q: Option<Joints> = None;
    let mut prev_q8 = 0.0;
    let mut warm = SvdWarmStart::default();

    for (idx, p) in points.iter().enumerate() {
        let cp = CellPoint {
            position_mm: p.position_mm,
            tool_axis: p.tool_axis,
            build_direction: p.build_direction,
            positioner: p.positioner,
            travel_speed_mm_s: p.travel_speed_mm_s,
        };
        let mut violation = |kind| {
            report.violations.push(Violation {
                layer: p.layer,
                point: p.point,
                kind,
            })
        };
        let new_layer = idx == 0 || !points[idx - 1].same_bead(p);
        let near = if new_layer && opts.rewind_between_layers {
            None
        } else {
            prev_q.as_ref()
        };
        let solved = cell.joints(&cp, p.r_z, near, prev_q8);
        let (q, pose) = match solved {
            Ok(x) => x,
            Err(e) => {
                violation(ViolationKind::NoSolution(e));
                out.push(JointPoint {
                    layer: p.layer,
                    bead: p.bead,
                    point: p.point,
                    joints: None,
                    positioner: None,
                    joint_speed_rad_s: [0.0; 6],
                    dt_s: 0.0,
                    dexterity: 0.0,
                    dq_drz: None,
                });
                continue;
            }
        };
        if let Some(qp) = pose.positioner {
            prev_q8 = qp[1];
        }
        // limits
        for (j, v) in robot.limit_violations(&q) {
            let l = robot.limits[j];
            violation(ViolationKind::JointLimit {
                joint: j + 1,
                value_rad: v,
                lower_rad: l.lower_rad,
                upper_rad: l.upper_rad,
            });
        }
        // speeds, within a layer
        let (speed, dt) =
            joint_speeds(cell, points, &out, idx, &q, pose.positioner, &mut violation);
        if let (CellLayout::TorchCarried(c), Some(qp)) = (cell, pose.positioner) {
            positioner_checks(c, &cp, &qp, &mut violation);
        }
        // singularities
        singularity_checks(cell, &q, opts, &mut violation);
        // hose
        if let Some(max) = hose_limit {
            let tor = (q[3] + q[5]).abs();
            if tor > max {
                violation(ViolationKind::HoseTorsion {
                    torsion_rad: tor,
                    max_rad: max,
                });
            }
        }
        let (dex, dq_drz) = if measures {
            point_measures(cell, &pose, &q, opts, &mut warm)
        } else {
            (0.0, None)
        };
        out.push(JointPoint {
            layer: p.layer,
            bead: p.bead,
            point: p.point,
            joints: Some(q),
            positioner: pose.positioner,
            joint_speed_rad_s: speed,
            dt_s: dt,
            dexterity: dex,
            dq_drz,
        });
        prev_q = Some(q);
    }
    Ok(JointTrajectory {
        configuration: cell.configuration(),
        points: out,
        report,
    })
}

/// Refuses a path point whose position, `R_Z`, tool axis or travel speed
/// is not finite (the speed also not positive).
fn check_inputs(points: &[PathPointInput], opts: &TrajectoryOptions) -> Result<(), RobotError> {
    opts.validate()?;
    for p in points {
        if !(p.travel_speed_mm_s > 0.0 && p.travel_speed_mm_s.is_finite()) {
            return Err(RobotError::BadPathPoint {
                layer: p.layer,
                point: p.point,
                reason: "travel_speed_mm_s not finite and > 0",
            });
        }
        if !(p.position_mm.iter().all(|v| v.is_finite()) && p.r_z.is_finite()) {
            return Err(RobotError::BadPathPoint {
                layer: p.layer,
                point: p.point,
                reason: "non-finite position or R_Z",
            });
        }
        if !p.tool_axis.iter().all(|v| v.is_finite()) {
            return Err(RobotError::BadPathPoint {
                layer: p.layer,
                point: p.point,
                reason: "non-finite tool axis",
            });
        }
    }
    Ok(())
}

/// Joint speeds (rad/s) from the previous point of the same layer to point
/// `idx` at joints `q` (positioner joints `positioner`), and the time
/// between them (s) at the point's travel speed; zeros at a layer's first point.
/// Reports every arm and positioner joint over its maximum speed.
#[allow(clippy::too_many_arguments)]
fn joint_speeds(
    cell: &CellLayout,
    points: &[PathPointInput],
    out: &[JointPoint],
    idx: usize,
    q: &Joints,
    positioner: Option<PositionerJoints>,
    violation: &mut dyn FnMut(ViolationKind),
) -> ([f64; 6], f64) {
    let p = &points[idx];
    let robot = cell.robot();
    let mut speed = [0.0; 6];
    let mut dt = 0.0;
    if idx > 0 {
        let pp = &points[idx - 1];
        if pp.same_bead(p) {
            if let (Some(qprev), d) = (out[idx - 1].joints, (p.position_mm - pp.position_mm).norm())
            {
                if d > 0.0 {
                    dt = d / p.travel_speed_mm_s;
                    for j in 0..6 {
                        speed[j] = (q[j] - qprev[j]) / dt;
                        if speed[j].abs() > robot.max_speed_rad_s[j] {
                            violation(ViolationKind::JointSpeed {
                                joint: j + 1,
                                speed_rad_s: speed[j].abs(),
                                max_rad_s: robot.max_speed_rad_s[j],
                            });
                        }
                    }
                    if let (CellLayout::TorchCarried(c), Some(qp), Some(qpp)) =
                        (cell, positioner, out[idx - 1].positioner)
                    {
                        for k in 0..2 {
                            let s = ((qp[k] - qpp[k]) / dt).abs();
                            if s > c.positioner.max_speed_rad_s[k] {
                                violation(ViolationKind::JointSpeed {
                                    joint: 7 + k,
                                    speed_rad_s: s,
                                    max_rad_s: c.positioner.max_speed_rad_s[k],
                                });
                            }
                        }
                    }
                }
            }
        }
    }
    (speed, dt)
}

/// Reports the build direction's tilt from the vertical beyond the cone
/// and the positioner's joint limits at positioner joints `qp` (rad).
fn positioner_checks(
    c: &TorchCarriedCell,
    cp: &CellPoint,
    qp: &PositionerJoints,
    violation: &mut dyn FnMut(ViolationKind),
) {
    let tilt = c.build_tilt(cp, qp);
    // rounding of the chain of rotations: [`BUILD_TILT_ROUNDING_RAD`]
    if tilt > c.max_vertical_error_rad + BUILD_TILT_ROUNDING_RAD {
        violation(ViolationKind::BuildTilt {
            tilt_rad: tilt,
            max_rad: c.max_vertical_error_rad,
        });
    }
    for (k, (l, v)) in c.positioner.limits.iter().zip(*qp).enumerate() {
        if !l.contains(v) {
            violation(ViolationKind::JointLimit {
                joint: 7 + k,
                value_rad: v,
                lower_rad: l.lower_rad,
                upper_rad: l.upper_rad,
            });
        }
    }
}

/// Reports the wrist, elbow and shoulder singularities of joints `q`
/// closer than the options' margins.
fn singularity_checks(
    cell: &CellLayout,
    q: &Joints,
    opts: &TrajectoryOptions,
    violation: &mut dyn FnMut(ViolationKind),
) {
    let robot = cell.robot();
    let sin_wrist = opts.wrist_singularity_margin_rad.sin();
    let sin_elbow = opts.elbow_singularity_margin_rad.sin();
    let sm = robot.singularity_measures(q);
    if sm.wrist_sin_j5 < sin_wrist {
        violation(ViolationKind::Singularity {
            kind: SingularityKind::Wrist,
            measure: sm.wrist_sin_j5,
        });
    }
    if sm.elbow_cos < sin_elbow {
        violation(ViolationKind::Singularity {
            kind: SingularityKind::Elbow,
            measure: sm.elbow_cos,
        });
    }
    if sm.shoulder_distance_mm < opts.shoulder_singularity_margin_mm {
        violation(ViolationKind::Singularity {
            kind: SingularityKind::Shoulder,
            measure: sm.shoulder_distance_mm,
        });
    }
}

/// The dexterity of joints `q` (warm-started along the trajectory) and,
/// with `opts.with_derivatives`, `dq/dR_Z` at `pose`.
fn point_measures(
    cell: &CellLayout,
    pose: &CellPose,
    q: &Joints,
    opts: &TrajectoryOptions,
    warm: &mut SvdWarmStart,
) -> (f64, Option<Joints>) {
    let robot = cell.robot();
    let jac = robot.jacobian(q);
    let dex = dexterity_warm(&jac, opts.dexterity_length_scale_mm, warm);
    let dq_drz = if opts.with_derivatives {
        // the Jacobian above, and its dexterity as a bound for the
        // singularity test (same answers as `cell.dq_drz(&pose, &q)`)
        cell.dq_drz_from(pose, &jac, Some((dex, opts.dexterity_length_scale_mm)))
            .ok()
    } else {
        None
    };
    (dex, dq_drz)
}

/// One bead's joint trajectory as a stage solved it (the optimiser's
/// re-check of a layer in its branch), kept with the cell, the options and
/// the points it was solved from so that a later stage (the program's
/// trajectory) takes it instead of solving the same joints again
/// ([`SolvedBead::reuse`]).
#[derive(Clone, PartialEq)]
pub(crate) struct SolvedBead {
    cell: CellLayout,
    opts: TrajectoryOptions,
    inputs: Vec<PathPointInput>,
    trajectory: JointTrajectory,
}

impl fmt::Debug for SolvedBead {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("SolvedBead")
            .field("points", &self.inputs.len())
            .finish_non_exhaustive()
    }
}

impl SolvedBead {
    /// What [`joint_trajectory`] (or its form without measures) gave for
    /// `inputs` in `cell` with `opts`.
    pub(crate) fn new(
        cell: &CellLayout,
        opts: &TrajectoryOptions,
        inputs: Vec<PathPointInput>,
        trajectory: JointTrajectory,
    ) -> Self {
        Self {
            cell: cell.clone(),
            opts: *opts,
            inputs,
            trajectory,
        }
    }

    /// The trajectory [`joint_trajectory_without_measures`] gives for
    /// `inputs` in `cell` with `opts`, to the bit, where it is this one
    /// renamed ([`ReusedBead::append_to`]): `None` unless `inputs` and the
    /// solved points are each one bead, of the same points bit for bit but
    /// for their layer, bead and point numbers (position, axes, `R_Z`,
    /// positioner joints, travel speed), in an equal cell, with the same
    /// singularity margins. Then every step of the walk is the same (a bead
    /// starts afresh whatever the options' rewinding; the numbers only
    /// label the output, the dexterity and `dq/dR_Z` are left out as that
    /// form leaves them): the same joints, speeds and violations, labelled
    /// with `inputs`' numbers.
    pub(crate) fn reuse(
        &self,
        cell: &CellLayout,
        inputs: &[PathPointInput],
        opts: &TrajectoryOptions,
    ) -> Option<ReusedBead<'_>> {
        let margins = |o: &TrajectoryOptions| {
            [
                o.wrist_singularity_margin_rad.to_bits(),
                o.elbow_singularity_margin_rad.to_bits(),
                o.shoulder_singularity_margin_mm.to_bits(),
            ]
        };
        let one_bead = |ps: &[PathPointInput]| ps.iter().all(|p| p.same_bead(&ps[0]));
        let same = inputs.len() == self.inputs.len()
            && !inputs.is_empty()
            && self.trajectory.points.len() == inputs.len()
            && margins(opts) == margins(&self.opts)
            && opts.validate().is_ok()
            && one_bead(inputs)
            && one_bead(&self.inputs)
            && inputs
                .iter()
                .zip(&self.inputs)
                .all(|(a, b)| same_point(a, b))
            && *cell == self.cell;
        if !same {
            return None;
        }
        // each violation names its point: found in order along the bead
        let mut at = 0;
        let mut violations_at = Vec::with_capacity(self.trajectory.report.violations.len());
        for v in &self.trajectory.report.violations {
            while self.inputs[at].point != v.point || self.inputs[at].layer != v.layer {
                at += 1;
                if at == self.inputs.len() {
                    return None;
                }
            }
            violations_at.push(at);
        }
        Some(ReusedBead {
            solved: self,
            violations_at,
        })
    }
}

/// A [`SolvedBead`] found to be the trajectory of a bead's points
/// ([`SolvedBead::reuse`]).
pub(crate) struct ReusedBead<'a> {
    solved: &'a SolvedBead,
    /// The index in the bead of each violation's point.
    violations_at: Vec<usize>,
}

impl ReusedBead<'_> {
    /// Appends the bead's joint points and violations to `whole`, labelled
    /// with the numbers of `inputs` (the points it was found the
    /// trajectory of), without dexterity nor `dq/dR_Z`.
    pub(crate) fn append_to(&self, inputs: &[PathPointInput], whole: &mut JointTrajectory) {
        let t = &self.solved.trajectory;
        whole
            .points
            .extend(t.points.iter().zip(inputs).map(|(jp, p)| JointPoint {
                layer: p.layer,
                bead: p.bead,
                point: p.point,
                dexterity: 0.0,
                dq_drz: None,
                ..*jp
            }));
        whole
            .report
            .violations
            .extend(
                t.report
                    .violations
                    .iter()
                    .zip(&self.violations_at)
                    .map(|(v, &at)| Violation {
                        layer: inputs[at].layer,
                        point: inputs[at].point,
                        kind: v.kind.clone(),
                    }),
            );
    }
}

/// Whether two path points are the same but for their layer, bead and
/// point numbers, bit for bit.
fn same_point(a: &PathPointInput, b: &PathPointInput) -> bool {
    let bits = |p: &PathPointInput| -> [u64; 14] {
        let d = p.build_direction.map_or([0.0; 3], |b| [b.x, b.y, b.z]);
        let q = p.positioner.unwrap_or([0.0; 2]);
        let v = [
            p.position_mm.x,
            p.position_mm.y,
            p.position_mm.z,
            p.tool_axis.x,
            p.tool_axis.y,
            p.tool_axis.z,
            d[0],
            d[1],
            d[2],
            p.r_z,
            q[0],
            q[1],
            p.travel_speed_mm_s,
        ];
        let flags = u64::from(p.build_direction.is_some()) | u64::from(p.positioner.is_some()) << 1;
        std::array::from_fn(|i| v.get(i).map_or(flags, |x| x.to_bits()))
    };
    bits(a) == bits(b)
}
