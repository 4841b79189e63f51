//! Stage 7, the controller's model of a move, shared by the thinner
//! ([`compress`](crate::program::compress), [`moves`](crate::program::moves))
//! and the checker ([`validate`](crate::program::validate)): the pose a
//! controller interpolates ([`ControllerPose`]: tool centre point (mm) and
//! orientation in the frame the move is programmed in, extra axes in rad),
//! in which frame ([`moves_in_part_frame`]), how it interpolates a linear
//! or circular move ([`interpolate`], [`arc_length`]) and the arm's pose
//! for a controller pose and back ([`controller_pose_at`], [`flange_of`]),
//! and the stroke the controller gives the positioner's turn
//! ([`turn_stroke`], [`turn_modulo`]).
//! A leaf: it imports no other module of the program stage but the
//! options and the frames.

use std::f64::consts::TAU;

use nalgebra::{Point3, UnitQuaternion, Vector3};

use crate::math::Isometry3;
use crate::program::frames::fixed_torch_at;
use crate::program::ProgramOptions;
use crate::robot::CellLayout;

/// Three points whose chord angle has a sine below this are collinear.
const COLLINEAR_SIN: f64 = 1e-9;

/// One programmed (or interpolated) controller pose.
#[derive(Clone, Debug, PartialEq)]
pub struct ControllerPose {
    /// Torch (TCP) position in the robot base frame, mm.
    pub p: Point3<f64>,
    /// Torch orientation in the robot base frame.
    pub q: UnitQuaternion<f64>,
    /// Extra axis values (e.g. positioner joints, rad); may be empty, but all
    /// poses of one bead have the same length.
    pub ext: Vec<f64>,
}

impl ControllerPose {
    /// Builds a pose from a position (mm), an orientation and extra axes.
    pub fn new(p: Point3<f64>, q: UnitQuaternion<f64>, ext: Vec<f64>) -> Self {
        Self { p, q, ext }
    }
}

/// Identity-like map for cells where the part does not move: the deposition
/// point is the TCP position `pose.p` (mm) and the torch axis is the tool Z
/// axis `pose.q * Z`, both in the base frame, which is then the part frame.
pub fn tool_z_map(pose: &ControllerPose) -> (Point3<f64>, Vector3<f64>) {
    (pose.p, pose.q * Vector3::z())
}

/// Controller model: the pose at fraction `s` (clamped to [0, 1]) of the move
/// from `a` to `b`, circular through `via.p` when `via` is given and the
/// three positions are not collinear, else linear. Position: straight line,
/// or circle arc from `a.p` through `via.p` to `b.p` with `s` the arc-length
/// fraction (mm, base frame). Orientation: `slerp(a.q, b.q, s)` along the
/// shortest rotation (the via's orientation is not used). Extra axes: linear
/// in `s` (pairs beyond the shorter `ext` are dropped).
pub fn interpolate(
    a: &ControllerPose,
    via: Option<&ControllerPose>,
    b: &ControllerPose,
    s: f64,
) -> ControllerPose {
    let path = MovePath::new(a, via.map(|v| &v.p), b);
    let mut out = a.clone();
    path.pose_into(s.clamp(0.0, 1.0), &mut out);
    out
}

/// Length (mm) of the controller's path from `a` through `via` to `b`: the
/// circle arc through the three points, or the two chords `a → via → b`
/// where they are (nearly) collinear or `via` is not between them on the
/// circle. The same circle as [`interpolate`].
pub fn arc_length(a: &Point3<f64>, via: &Point3<f64>, b: &Point3<f64>) -> f64 {
    match Arc3::through(a, via, b) {
        Some(arc) => arc.radius * arc.sweep,
        None => (via - a).norm() + (b - via).norm(),
    }
}

/// Circle arc from `a` through a via to `b` (controller frame, mm).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Arc3 {
    pub(crate) center: Point3<f64>,
    /// Unit vector from the centre to the start point.
    pub(crate) u: Vector3<f64>,
    /// Unit vector in the arc plane, 90° ahead of `u` in the travel direction.
    pub(crate) w: Vector3<f64>,
    pub(crate) radius: f64,
    /// Swept angle from start to end, rad, in (0, 2π).
    pub(crate) sweep: f64,
}

impl Arc3 {
    /// The arc through three points, or `None` if they are (nearly) collinear.
    pub(crate) fn through(a: &Point3<f64>, via: &Point3<f64>, b: &Point3<f64>) -> Option<Self> {
        let (av, ab) = (via - a, b - a);
        let normal = av.cross(&ab);
        let normal_sq = normal.norm_squared();
        let scale = av.norm_squared() * ab.norm_squared();
        if !(scale > 0.0 && normal_sq > COLLINEAR_SIN * COLLINEAR_SIN * scale) {
            return None;
        }
        let offset = (av.norm_squared() * ab - ab.norm_squared() * av).cross(&normal);
        let center = a + offset / (2.0 * normal_sq);
        let radius = (a - center).norm();
        let u = (a - center) / radius;
        let w = (normal / normal_sq.sqrt()).cross(&u);
        let angle_of = |p: &Point3<f64>| {
            let d = p - center;
            d.dot(&w).atan2(d.dot(&u)).rem_euclid(TAU)
        };
        let (via_angle, sweep) = (angle_of(via), angle_of(b));
        let ordered = via_angle > 0.0 && via_angle < sweep;
        (radius.is_finite() && ordered).then_some(Self {
            center,
            u,
            w,
            radius,
            sweep,
        })
    }

    pub(crate) fn point_at(&self, s: f64) -> Point3<f64> {
        let (sin, cos) = (s * self.sweep).sin_cos();
        self.center + (self.u * cos + self.w * sin) * self.radius
    }
}

/// The controller's interpolated path of one move.
pub(crate) struct MovePath<'a> {
    a: &'a ControllerPose,
    b: &'a ControllerPose,
    arc: Option<Arc3>,
    /// Scaled axis of the shortest rotation from `a.q` to `b.q` (body frame).
    rotation: Vector3<f64>,
}

impl<'a> MovePath<'a> {
    pub(crate) fn new(
        a: &'a ControllerPose,
        via: Option<&Point3<f64>>,
        b: &'a ControllerPose,
    ) -> Self {
        Self {
            a,
            b,
            arc: via.and_then(|v| Arc3::through(&a.p, v, &b.p)),
            rotation: (a.q.inverse() * b.q).scaled_axis(),
        }
    }

    /// Writes the pose at fraction `s` into `out`, reusing its buffers.
    pub(crate) fn pose_into(&self, s: f64, out: &mut ControllerPose) {
        out.p = match &self.arc {
            Some(arc) => arc.point_at(s),
            None => self.a.p + (self.b.p - self.a.p) * s,
        };
        out.q = self.a.q * UnitQuaternion::from_scaled_axis(self.rotation * s);
        out.ext.clear();
        let pairs = self.a.ext.iter().zip(&self.b.ext);
        out.ext.extend(pairs.map(|(x, y)| x + s * (y - x)));
    }
}

/// The controller's pose (module doc) of the arm at joints `q` (rad) and the positioner
/// at `qp` (rad).
pub fn controller_pose_at(
    cell: &CellLayout,
    q: &crate::robot::Joints,
    qp: Option<[f64; 2]>,
    in_part: bool,
) -> ControllerPose {
    let flange = cell.robot().flange_pose(q);
    let (tcp, ext): (Isometry3, Vec<f64>) = match cell {
        CellLayout::PartCarried(c) if in_part => {
            let base_from_part = flange * c.flange_from_part;
            let torch = fixed_torch_at(&c.deposition_point_mm);
            (base_from_part.inverse() * torch, Vec::new())
        }
        // the held tool (the flange) in the base frame
        CellLayout::PartCarried(_) => (flange, Vec::new()),
        CellLayout::TorchCarried(c) => {
            let tcp = flange * c.flange_from_tcp;
            let qp = qp.unwrap_or([0.0; 2]);
            let tcp = if in_part {
                c.base_from_part(&qp).inverse() * tcp
            } else {
                tcp
            };
            (tcp, qp.to_vec())
        }
    };
    ControllerPose::new(tcp.translation.vector.into(), tcp.rotation, ext)
}

/// The flange pose (robot base frame) that puts the controller's tool at
/// `pose` ([`controller_pose_at`]'s inverse), with the positioner at
/// `pose.ext`.
pub fn flange_of(cell: &CellLayout, pose: &ControllerPose, in_part: bool) -> Isometry3 {
    let controller = Isometry3::from_parts(pose.p.coords.into(), pose.q);
    match cell {
        CellLayout::PartCarried(c) if in_part => {
            // controller = (flange · F_fp)⁻¹ · torch
            fixed_torch_at(&c.deposition_point_mm)
                * controller.inverse()
                * c.flange_from_part.inverse()
        }
        CellLayout::PartCarried(_) => controller,
        CellLayout::TorchCarried(c) => {
            let tcp = if in_part {
                c.base_from_part(&[pose.ext[0], pose.ext[1]]) * controller
            } else {
                controller
            };
            tcp * c.flange_from_tcp.inverse()
        }
    }
}

/// Samples of a move's interpolation over which
/// [`deposited_length_mm`] measures the deposited path: a 45° turn of the
/// part is then measured within 3e-5 of its arc (the polyline of `n`
/// chords falls short of an arc of angle `a` by about `(a/n)^2/24`).
pub const DEPOSITED_SAMPLES: usize = 32;

/// Length (mm) of the path the deposition point travels over the part
/// while the controller runs the move from the arm's joints `a.0` (rad) and
/// positioner `a.1` (rad) to `b`, circular through `via` when given: the
/// controller interpolates its tool in the part frame (`in_part`; the path
/// is then the chord, or the arc through the via, over the part) or in the
/// robot base frame, where the part turns under a straight flange path (a
/// part-carried cell without remote TCP, a torch-carried cell without
/// coordination) and the deposited path bows away from the chord: a pure
/// turn of the part by `theta` about the axis of a circle of radius `r`
/// deposits its arc `r theta`, not the chord `2 r sin(theta/2)`. Measured as
/// the polyline through [`DEPOSITED_SAMPLES`] + 1 poses of [`interpolate`].
pub fn deposited_length_mm(
    cell: &CellLayout,
    a: (&crate::robot::Joints, Option<[f64; 2]>),
    via: Option<(&crate::robot::Joints, Option<[f64; 2]>)>,
    b: (&crate::robot::Joints, Option<[f64; 2]>),
    in_part: bool,
) -> f64 {
    let pose = |(q, qp): (&crate::robot::Joints, Option<[f64; 2]>)| {
        controller_pose_at(cell, q, qp, in_part)
    };
    let (pa, pb) = (pose(a), pose(b));
    let via = via.map(|v| pose(v).p);
    if in_part {
        // the controller's tool is the deposition point over the part
        return match via {
            Some(v) => arc_length(&pa.p, &v, &pb.p),
            None => (pb.p - pa.p).norm(),
        };
    }
    let path = MovePath::new(&pa, via.as_ref(), &pb);
    let mut at = pa.clone();
    let mut prev: Option<Point3<f64>> = None;
    let mut length = 0.0;
    for n in 0..=DEPOSITED_SAMPLES {
        path.pose_into(n as f64 / DEPOSITED_SAMPLES as f64, &mut at);
        let flange = flange_of(cell, &at, false);
        let d: Point3<f64> = match cell {
            CellLayout::PartCarried(c) => {
                (flange * c.flange_from_part).inverse() * c.deposition_point_mm
            }
            CellLayout::TorchCarried(c) => {
                let tcp = flange * c.flange_from_tcp;
                let qp = [
                    at.ext.first().copied().unwrap_or(0.0),
                    at.ext.get(1).copied().unwrap_or(0.0),
                ];
                c.base_from_part(&qp).inverse() * Point3::from(tcp.translation.vector)
            }
        };
        if let Some(p) = prev {
            length += (d - p).norm();
        }
        prev = Some(d);
    }
    length
}

/// `true` when `cell`'s linear moves are interpolated in the part frame
/// (the part is the moving frame: a fixed tool about which the part-carried
/// robot moves, or coordinated motion with the positioner); `false` when
/// in the robot base frame.
pub fn moves_in_part_frame(cell: &CellLayout, opts: &ProgramOptions) -> bool {
    match cell {
        CellLayout::TorchCarried(_) => opts.coordinated,
        CellLayout::PartCarried(_) => {
            opts.remote_tcp || cell.robot().vendor.moves_about_fixed_tool()
        }
    }
}

/// The stroke of `cell`'s positioner turn on its robot's controller
/// ([`TorchCarriedCell::turn_stroke`](crate::robot::cell::TorchCarriedCell::turn_stroke));
/// `None` without a positioner.
pub fn turn_stroke(cell: &CellLayout) -> Option<crate::robot::JointLimit> {
    match cell {
        CellLayout::TorchCarried(c) => Some(c.turn_stroke()),
        CellLayout::PartCarried(_) => None,
    }
}

/// `true` when `cell`'s robot controller turns endless axes modulo 360°
/// ([`Vendor::turns_endless_axes_modulo`](crate::robot::Vendor::turns_endless_axes_modulo)) and its positioner's turn is
/// endless without a stated stroke: the turn is then written modulo 360°.
pub fn turn_modulo(cell: &CellLayout) -> bool {
    match cell {
        CellLayout::TorchCarried(c) => {
            c.robot.vendor.turns_endless_axes_modulo()
                && c.positioner.turn_stroke(true) == crate::robot::JointLimit::UNLIMITED
        }
        CellLayout::PartCarried(_) => false,
    }
}
