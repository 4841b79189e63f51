//! The build's **cycle time**: how long a controller takes to run a
//! [`Program`], per move, per layer and for the build (s). Takes the
//! program (its moves as the emitters write them: home moves, arc-off
//! joint moves, the linear moves into and out of each bead, the bead's
//! blended linear and circular moves, the set-up before each bead) and
//! [`CycleOptions`] (the joint-move speed the emitter writes, the path
//! acceleration); returns a [`CycleTime`].
//!
//! The model, move by move:
//!
//! * **Joint moves** (home, the arc-off transit from one bead's retract
//!   point to the next bead's approach point, or to its first point without
//!   approach points): synchronised point-to-point motion from rest to rest.
//!   Each axis (the arm's six, the positioner's two) runs a trapezoidal
//!   profile with its maximum speed times [`CycleOptions::joint_speed_fraction`]
//!   (FANUC `J … 10%`, KUKA `BAS (#VEL_PTP, 10)`) and its maximum
//!   acceleration ([`RobotModel::max_acceleration`](crate::robot::RobotModel::max_acceleration);
//!   the positioner's: its maximum speed over
//!   [`ASSUMED_RAMP_S`]); the move takes
//!   the longest axis's time ([`trapezoid_time`]). Where the emitter gives
//!   joint moves a TCP speed (ABB `MoveAbsJ` with `speeddata`), the move
//!   also takes at least the flange's path length, sampled along the joint
//!   line, run as a trapezoid at that speed.
//! * **Linear moves into and out of a bead** (approach point → first
//!   point, last point → retract point; exact stop at both ends): the
//!   longer of a trapezoid on the path length (part frame, the torch's
//!   travel over the part) at the programmed speed with
//!   [`CycleOptions::path_acceleration_mm_s2`], and each axis's trapezoid.
//! * **A bead** (first point to last, the arc on): the moves are blended
//!   (FANUC `CNT`, KUKA `C_DIS`, ABB zones) and the arc switching points
//!   are exact stops, so the bead is one path from rest to rest whose speed
//!   follows each move's programmed speed, limited on each move so that no
//!   axis exceeds its maximum speed (the move's largest joint change over
//!   that joint's maximum speed), and changing between moves at
//!   [`CycleOptions::path_acceleration_mm_s2`]: the classic forward and
//!   backward pass of a velocity planner ([`profile_time`]). A circular
//!   move's length is its arc's through the via. Joint accelerations inside
//!   a bead are not modelled (the path acceleration stands for them).
//! * **Set-up**: the interlayer dwell ([`BeadSetup::dwell_s`]) counts in
//!   full; a wait for the interpass input has no known duration and counts
//!   as 0 s, its number given in [`CycleTime::waits`]; payload updates
//!   take no time.
//!
//! A layer's time ([`LayerCycle::total_s`]) is the joint move into its
//! first point (from home, or from the previous bead's last point), the
//! dwell and wait before it, its approach, its bead and its retract; the
//! build's ([`CycleTime::total_s`]) is the sum over the layers plus the
//! return home. Controller overheads (arc ignition and crater fill times,
//! look-ahead, the controllers' own jerk limits) are not included.

use serde::Serialize;

use crate::math::Point3;
use crate::program::compress::arc_length;
use crate::program::{ArcFlag, BeadSetup, Program, ProgramPoint};
use crate::robot::model::ASSUMED_RAMP_S;
use crate::robot::CellLayout;

#[cfg(test)]
mod tests;

/// Path acceleration of the torch over the part assumed where none is given
/// (mm/s²): 2000 mm/s² (0.2 g). The vendors' default Cartesian
/// accelerations are controller settings, not data-sheet figures; at WAAM
/// travel speeds (5–20 mm/s) the ramps take a few milliseconds whatever
/// the value, so the cycle time hardly depends on it.
pub const ASSUMED_PATH_ACCELERATION_MM_S2: f64 = 2000.0;

/// Samples of a joint move's flange path when its TCP speed bounds it
/// (ABB `MoveAbsJ`).
const TCP_PATH_SAMPLES: usize = 16;

/// Options of [`cycle_time`]. Plain data.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct CycleOptions {
    /// Fraction of each axis's maximum speed a joint move runs at (0–1]:
    /// FANUC `approach_percent`, KUKA `ptp_percent` over 100; 1 for ABB
    /// (whose `MoveAbsJ` is bounded by [`CycleOptions::joint_move_tcp_speed_mm_s`]).
    pub joint_speed_fraction: f64,
    /// TCP speed bounding a joint move (mm/s), ABB `MoveAbsJ`'s `speeddata`
    /// `v_tcp`; `None`: none.
    pub joint_move_tcp_speed_mm_s: Option<f64>,
    /// Acceleration of the torch along its path over the part (mm/s², > 0),
    /// for the linear and circular moves.
    pub path_acceleration_mm_s2: f64,
    /// Whether the controller interpolates a bead's moves in the part frame,
    /// `[part-carried cell, torch-carried cell]`: then the deposited path is
    /// the chord or arc between the positions; else it runs in the robot
    /// base frame, the part turns under the tool and the deposited path, the
    /// one a move's speed or time is planned over, bows away from the chord
    /// ([`deposited_length_mm`](crate::program::pose::deposited_length_mm);
    /// FANUC without remote TCP, torch-carried cells without coordination).
    /// Default `[true, true]`.
    pub beads_in_part_frame: [bool; 2],
}

impl Default for CycleOptions {
    fn default() -> Self {
        Self {
            joint_speed_fraction: 0.1,
            joint_move_tcp_speed_mm_s: None,
            path_acceleration_mm_s2: ASSUMED_PATH_ACCELERATION_MM_S2,
            beads_in_part_frame: [true, true],
        }
    }
}

/// One layer's share of the cycle time (s).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize)]
pub struct LayerCycle {
    /// Layer (bead) index, as in [`ProgramPoint::layer`].
    pub layer: usize,
    /// The joint move into the layer's first point, from home or from the
    /// previous bead's last point (s).
    pub transit_s: f64,
    /// Dwell before the bead (s).
    pub dwell_s: f64,
    /// The linear move from the approach point to the bead's first point (s).
    pub approach_s: f64,
    /// The bead, arc on, from its first point to its last (s).
    pub bead_s: f64,
    /// The linear move from the bead's last point to the retract point (s).
    pub retract_s: f64,
    /// Sum of the above (s).
    pub total_s: f64,
}

/// The cycle time of a program ([`cycle_time`]).
#[derive(Debug, Clone, PartialEq, Default, Serialize)]
pub struct CycleTime {
    /// The whole build: every layer plus the return home (s).
    pub total_s: f64,
    /// Time with the arc on, summed over the beads (s).
    pub arc_on_s: f64,
    /// One entry per bead, in program order.
    pub layers: Vec<LayerCycle>,
    /// The joint move from the last point back home (s; 0 without home).
    pub home_return_s: f64,
    /// Waits for the interpass input, counted as 0 s each (their duration
    /// depends on the wall's cooling).
    pub waits: usize,
}

/// Time (s) of a rest-to-rest trapezoidal profile over the distance `d`
/// (mm or rad, ≥ 0) with the cruise speed `v` (> 0, per s) and the
/// acceleration `a` (> 0, per s²): `d/v + v/a` when `d >= v²/a` (the
/// speed is reached), else `2·sqrt(d/a)` (a triangle). An infinite `v`
/// or `a` drops its term; 0 for `d <= 0`.
pub fn trapezoid_time(d: f64, v: f64, a: f64) -> f64 {
    if d.is_nan() || d <= 0.0 {
        return 0.0;
    }
    match (v.is_finite(), a.is_finite()) {
        (false, false) => 0.0,
        (true, false) => d / v,
        (false, true) => 2.0 * (d / a).sqrt(),
        (true, true) => {
            if d >= v * v / a {
                d / v + v / a
            } else {
                2.0 * (d / a).sqrt()
            }
        }
    }
}

/// One piece of a blended path: its length (mm) and the highest speed it
/// may run at (mm/s, > 0; the programmed speed, lowered by the axes' speeds).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Segment {
    /// Length along the path (mm, ≥ 0).
    pub length_mm: f64,
    /// Highest speed on it (mm/s, > 0).
    pub speed_mm_s: f64,
    /// Least time it takes whatever its speed (s, ≥ 0): the axes' speed
    /// limits on a piece of zero length.
    pub min_time_s: f64,
}

/// Time (s) of one piece run from the speed `w_a` to `w_b` (mm/s) with the
/// cruise speed `v` and acceleration `a` over `l` mm: accelerate to the
/// peak `min(v, sqrt((2·a·l + w_a² + w_b²)/2))`, cruise, decelerate.
fn piece_time(l: f64, w_a: f64, w_b: f64, v: f64, a: f64) -> f64 {
    if l.is_nan() || l <= 0.0 {
        return 0.0;
    }
    if !a.is_finite() {
        return l / v;
    }
    let peak = v.min(((2.0 * a * l + w_a * w_a + w_b * w_b) / 2.0).sqrt());
    let peak = peak.max(w_a).max(w_b);
    let d_up = ((peak * peak - w_a * w_a) / (2.0 * a)).max(0.0);
    let d_down = ((peak * peak - w_b * w_b) / (2.0 * a)).max(0.0);
    let cruise = (l - d_up - d_down).max(0.0);
    (peak - w_a) / a + (peak - w_b) / a + if peak > 0.0 { cruise / peak } else { 0.0 }
}

/// Time (s) of a blended path from rest to rest through `segments`, the
/// speed changing at `a` (mm/s², > 0): the speed at each junction is the
/// lower of the two pieces' speeds, then lowered by a forward pass (what
/// the path can reach from the start) and a backward pass (what it can
/// stop from before the end); each piece then accelerates to its peak, cruises and decelerates.
/// One piece of length `L` at speed `v` gives [`trapezoid_time`]`(L, v, a)`.
pub fn profile_time(segments: &[Segment], a: f64) -> f64 {
    let n = segments.len();
    if n == 0 {
        return 0.0;
    }
    // w[k]: speed at the start of piece k (w[n]: at the end)
    let mut w = vec![0.0; n + 1];
    for k in 1..n {
        w[k] = segments[k - 1].speed_mm_s.min(segments[k].speed_mm_s);
    }
    if a.is_finite() {
        for k in 1..=n {
            let reach = (w[k - 1] * w[k - 1] + 2.0 * a * segments[k - 1].length_mm).sqrt();
            w[k] = w[k].min(reach);
        }
        w[n] = 0.0;
        for k in (0..n).rev() {
            let reach = (w[k + 1] * w[k + 1] + 2.0 * a * segments[k].length_mm).sqrt();
            w[k] = w[k].min(reach);
        }
    }
    segments
        .iter()
        .enumerate()
        .map(|(k, s)| piece_time(s.length_mm, w[k], w[k + 1], s.speed_mm_s, a).max(s.min_time_s))
        .sum()
}

/// The axes' limits of a cell: maximum speeds (rad/s) and accelerations
/// (rad/s²), the arm's six then the positioner's two (absent: none).
struct Axes {
    speed: Vec<f64>,
    accel: Vec<f64>,
}

impl Axes {
    fn of(cell: &CellLayout) -> Self {
        let robot = cell.robot();
        let mut speed = robot.max_speed_rad_s.to_vec();
        let mut accel = robot.max_acceleration().to_vec();
        if let CellLayout::TorchCarried(c) = cell {
            for v in c.positioner.max_speed_rad_s {
                speed.push(v);
                accel.push(v / ASSUMED_RAMP_S);
            }
        }
        Self { speed, accel }
    }

    /// Each axis's change between two points (rad), positioner included.
    fn changes(a: &[f64; 6], pa: Option<[f64; 2]>, b: &[f64; 6], pb: Option<[f64; 2]>) -> [f64; 8] {
        let mut d = [0.0; 8];
        for j in 0..6 {
            d[j] = (b[j] - a[j]).abs();
        }
        if let (Some(x), Some(y)) = (pa, pb) {
            d[6] = (y[0] - x[0]).abs();
            d[7] = (y[1] - x[1]).abs();
        }
        d
    }

    /// The longest axis's trapezoid time (s) for the changes `d` (rad) at
    /// `fraction` of the maximum speeds.
    fn move_time(&self, d: &[f64; 8], fraction: f64) -> f64 {
        self.speed
            .iter()
            .zip(&self.accel)
            .zip(d)
            .map(|((v, a), d)| trapezoid_time(*d, fraction * v, *a))
            .fold(0.0, f64::max)
    }

    /// The least time (s) for the changes `d` (rad) with no axis above its
    /// maximum speed (no ramps: inside a blended path).
    fn speed_time(&self, d: &[f64; 8]) -> f64 {
        self.speed
            .iter()
            .zip(d)
            .map(|(v, d)| if v.is_finite() { d / v } else { 0.0 })
            .fold(0.0, f64::max)
    }
}

/// A point's joints and positioner joints.
type Pose<'a> = (&'a [f64; 6], Option<[f64; 2]>);

/// The cycle time of `program` (module doc for the model).
///
/// Not finite inputs give a finite result: a program is checked finite
/// when it is built ([`Program::check_finite`]), and a non-positive speed
/// or option falls back on the defaults of [`CycleOptions`].
pub fn cycle_time(program: &Program, opts: &CycleOptions) -> CycleTime {
    let cell = &program.cell;
    let axes = Axes::of(cell);
    let defaults = CycleOptions::default();
    let in_part = match cell {
        crate::robot::CellLayout::PartCarried(_) => opts.beads_in_part_frame[0],
        crate::robot::CellLayout::TorchCarried(_) => opts.beads_in_part_frame[1],
    };
    let deposited = (!in_part).then_some(cell);
    let fraction = if opts.joint_speed_fraction > 0.0 && opts.joint_speed_fraction <= 1.0 {
        opts.joint_speed_fraction
    } else {
        defaults.joint_speed_fraction
    };
    let accel = if opts.path_acceleration_mm_s2 > 0.0 && !opts.path_acceleration_mm_s2.is_nan() {
        opts.path_acceleration_mm_s2
    } else {
        defaults.path_acceleration_mm_s2
    };
    let tcp_speed = opts
        .joint_move_tcp_speed_mm_s
        .filter(|v| v.is_finite() && *v > 0.0);

    let joint_move = |from: Pose, to: Pose| -> f64 {
        let d = Axes::changes(from.0, from.1, to.0, to.1);
        let mut t = axes.move_time(&d, fraction);
        if let Some(v) = tcp_speed {
            let robot = cell.robot();
            let mut length = 0.0;
            let mut prev = robot.flange_pose(from.0).translation.vector;
            for i in 1..=TCP_PATH_SAMPLES {
                let s = i as f64 / TCP_PATH_SAMPLES as f64;
                let q: [f64; 6] = std::array::from_fn(|j| from.0[j] + s * (to.0[j] - from.0[j]));
                let p = robot.flange_pose(&q).translation.vector;
                length += (p - prev).norm();
                prev = p;
            }
            t = t.max(trapezoid_time(length, v, accel));
        }
        t
    };
    let linear_move = |a: &ProgramPoint, b: &ProgramPoint, speed: f64| -> f64 {
        let d = Axes::changes(&a.joints, a.positioner, &b.joints, b.positioner);
        let length = (b.position_mm - a.position_mm).norm();
        let path = if speed > 0.0 && speed.is_finite() {
            trapezoid_time(length, speed, accel)
        } else {
            0.0
        };
        path.max(axes.move_time(&d, 1.0))
    };

    let points = &program.points;
    let mut out = CycleTime::default();
    let mut prev: Option<Pose> = program.home.as_ref().map(|h| (&h.joints, h.positioner));
    let mut bead = 0usize;
    // the joint moves through a transit's via points (after a bead's
    // retract point), counted in the next transit
    let mut via_legs_s = 0.0;
    let mut i = 0;
    while i < points.len() {
        let layer = points[i].layer;
        // one block a bead (a layer split at its corners has several)
        let end = (i..points.len())
            .find(|&k| !points[k].same_bead(&points[i]))
            .unwrap_or(points.len());
        let block = &points[i..end];
        let mut lc = LayerCycle {
            layer,
            ..LayerCycle::default()
        };
        if let Some(from) = prev {
            lc.transit_s = via_legs_s + joint_move(from, (&block[0].joints, block[0].positioner));
        }
        via_legs_s = block
            .windows(2)
            .filter(|w| w[1].arc == ArcFlag::Transit)
            .map(|w| {
                joint_move(
                    (&w[0].joints, w[0].positioner),
                    (&w[1].joints, w[1].positioner),
                )
            })
            .sum();
        if let Some(s) = program.bead_setup.get(bead) {
            let BeadSetup {
                dwell_s,
                wait_input,
                ..
            } = *s;
            if dwell_s.is_finite() && dwell_s > 0.0 {
                lc.dwell_s = dwell_s;
            }
            out.waits += usize::from(wait_input.is_some());
        }
        let start = block.iter().position(|p| p.arc == ArcFlag::Start);
        let finish = block.iter().rposition(|p| p.arc == ArcFlag::End);
        if let (Some(s), Some(e)) = (start, finish) {
            if s > 0 {
                lc.approach_s = linear_move(&block[s - 1], &block[s], block[s - 1].speed_mm_s);
            }
            lc.bead_s = bead_time(&axes, &block[s..=e], accel, deposited);
            if e + 1 < block.len() {
                lc.retract_s = linear_move(&block[e], &block[e + 1], block[e + 1].speed_mm_s);
            }
        }
        lc.total_s = lc.transit_s + lc.dwell_s + lc.approach_s + lc.bead_s + lc.retract_s;
        out.arc_on_s += lc.bead_s;
        out.total_s += lc.total_s;
        out.layers.push(lc);
        let last = &block[block.len() - 1];
        prev = Some((&last.joints, last.positioner));
        bead += 1;
        i = end;
    }
    if let (Some(h), Some(from)) = (&program.home, prev) {
        out.home_return_s = via_legs_s + joint_move(from, (&h.joints, h.positioner));
        out.total_s += out.home_return_s;
    }
    out
}

/// The blended moves of one bead (its first point to its last) as
/// [`Segment`]s, and their [`profile_time`] (s); with `deposited` (the cell,
/// interpolating in the robot base frame) each move's length is the path it
/// deposits, not the chord.
fn bead_time(
    axes: &Axes,
    bead: &[ProgramPoint],
    accel: f64,
    deposited: Option<&crate::robot::CellLayout>,
) -> f64 {
    let over_part = |a: &ProgramPoint, via: Option<&ProgramPoint>, b: &ProgramPoint| {
        deposited.map(|cell| {
            crate::program::pose::deposited_length_mm(
                cell,
                (&a.joints, a.positioner),
                via.map(|v| (&v.joints, v.positioner)),
                (&b.joints, b.positioner),
                false,
            )
        })
    };
    let mut segments = Vec::with_capacity(bead.len());
    let mut k = 1;
    while k < bead.len() {
        let a = &bead[k - 1];
        let (b, length, d) = if bead[k].via && k + 1 < bead.len() {
            let (via, b) = (&bead[k], &bead[k + 1]);
            let d1 = Axes::changes(&a.joints, a.positioner, &via.joints, via.positioner);
            let d2 = Axes::changes(&via.joints, via.positioner, &b.joints, b.positioner);
            let d: [f64; 8] = std::array::from_fn(|j| d1[j] + d2[j]);
            k += 2;
            (
                b,
                over_part(a, Some(via), b).unwrap_or_else(|| {
                    arc_length(&a.position_mm, &via.position_mm, &b.position_mm)
                }),
                d,
            )
        } else {
            let b = &bead[k];
            k += 1;
            (
                b,
                over_part(a, None, b).unwrap_or_else(|| distance(&a.position_mm, &b.position_mm)),
                Axes::changes(&a.joints, a.positioner, &b.joints, b.positioner),
            )
        };
        let min_time = axes.speed_time(&d);
        let mut speed = if b.speed_mm_s.is_finite() && b.speed_mm_s > 0.0 {
            b.speed_mm_s
        } else {
            f64::INFINITY
        };
        if min_time > 0.0 && length > 0.0 {
            speed = speed.min(length / min_time);
        }
        if !speed.is_finite() {
            // no speed and no joint bound: a piece of no length
            speed = 1.0;
        }
        segments.push(Segment {
            length_mm: if length.is_finite() { length } else { 0.0 },
            speed_mm_s: speed,
            min_time_s: min_time,
        });
    }
    profile_time(&segments, accel)
}

fn distance(a: &Point3, b: &Point3) -> f64 {
    (b - a).norm()
}
