//! **Stage 3 — tool axes.** Takes a [`Path`] (part frame, mm) — with its
//! [`Tube`] when the surface is known, or alone for paths made elsewhere — and
//! returns [`ToolAxes`]: one [`LocalFrame`] per point (path tangent `t`,
//! surface normal `n`, build direction `b`, tool axis `T`, all unit vectors in
//! the part frame) and a report [SPEC §4; thesis §2.4, eq. 2.30–2.36].
//!
//! The pieces, in the order [`tool_axes`] applies them:
//!
//! 1. [`normals`] — tangent by central difference (eq. 2.34), normal from the
//!    tube (eq. 2.33) or from facets of the path alone (§2.4.3, eq. 2.36), and
//!    `b = t × n` oriented away from the substrate (eq. 2.35);
//! 2. [`rules`] — optional projection of every `b` into a plane (§3.3.1);
//! 3. [`lead_tilt`] — tool axis `T` from a lead angle `theta_n` (feed plane)
//!    and a tilt angle `theta_t` (normal plane), Rodrigues (eq. 2.30–2.32),
//!    constant, per point, or by a rule such as the 50° rule (eq. 3.20–3.21);
//! 4. [`rules`] — smoothing of the lead/tilt angles along each layer with a
//!    bound on their rate (rad/mm), so that `T` moves smoothly relative to the
//!    local frame.
//!
//! Collision of the torch with the part built so far and the substrate, and
//! its avoidance, are in [`collision`] (they need a torch: a separate call).
//!
//! # Conventions
//! * `normal` is the **outward** surface normal (away from the tube's guide);
//!   `build` is `± t × n`, the sign chosen so that `b` points away from the
//!   substrate. The triple `(t, n, b)` is therefore right- or left-handed
//!   depending on the direction the layers are deposited in; the tool axis is
//!   built as a vector formula (`T ∝ b + tan(theta_n) t + tan(theta_t) n`, the
//!   closed form of eq. 2.32) that does not depend on handedness: a positive
//!   lead leans `T` toward the feed direction, a positive tilt toward the
//!   outside of the tube.
//! * Angles in radians, lengths in mm, the part frame throughout.

pub mod collision;
pub mod lead_tilt;
pub mod normals;
pub mod rules;

#[cfg(test)]
mod tests;

pub use collision::{
    avoid_collisions, check_collisions, AvoidanceOptions, AvoidanceReport, CollisionOptions,
    CollisionReport, LayerClearance, Torch, TorchSpec,
};
pub use lead_tilt::{lead_tilt_of, tool_axis, tool_axis_rodrigues};
pub use normals::{mean_normal_difference, mean_normal_difference_per_layer, NormalMethod};
pub use rules::{max_angle_rate, max_rate, smooth_angles, smooth_layer, AxisRule};

use crate::geometry::{Substrate, Tube};
use crate::math::Vector3;
use crate::path::Path;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// Local frame at one path point (part frame, unit vectors).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LocalFrame {
    /// Path tangent `t`, in the deposition direction (central difference along
    /// the layer, eq. 2.34).
    pub tangent: Vector3,
    /// Outward surface normal `n` (analytic eq. 2.33, or numeric from facets
    /// of the path), perpendicular to `t`.
    pub normal: Vector3,
    /// Build direction `b = ± t × n`, oriented away from the substrate (toward
    /// the next layer). After a plane projection ([`ToolAxisOptions::project_build`])
    /// it is the projected direction.
    pub build: Vector3,
    /// Tool axis `T` (from the deposition point toward the torch).
    pub tool: Vector3,
}

/// Local frames of every point of `path`, layer by layer: analytic normals
/// from `tube`, tool axis along the build direction (lead = tilt = 0).
///
/// The first, minimal entry point, kept for callers that need nothing more;
/// [`tool_axes`] is the full stage. A degenerate point (two coincident
/// neighbours) gets its tangent from `∂M/∂v` instead of failing.
pub fn local_frames(path: &Path, tube: &Tube) -> Vec<Vec<LocalFrame>> {
    normals::analytic_frames(path, tube)
}

/// Options of [`tool_axes`]. Plain data; [`ToolAxisOptions::validate`] names
/// the field at fault.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ToolAxisOptions {
    /// Where surface normals come from.
    pub normals: NormalMethod,
    /// Constant lead angle `theta_n` (rad, |.| < π/2): leans `T` in the feed
    /// plane `(t, b)`, positive toward the feed direction.
    pub lead_rad: f64,
    /// Constant tilt angle `theta_t` (rad, |.| < π/2): leans `T` in the normal
    /// plane `(n, b)`, positive toward the outward normal.
    pub tilt_rad: f64,
    /// A rule that sets the angles point by point (on top of the constants).
    pub rule: AxisRule,
    /// Project every build direction into the plane with this normal (part
    /// frame, need not be unit) before computing `T` (thesis §3.3.1: the
    /// torus on a cylinder uses the YZ plane, normal `[1, 0, 0]`).
    pub project_build: Option<[f64; 3]>,
    /// With [`Self::project_build`]: a build direction within this angle of
    /// the plane (rad, in (0, π/2)) is projected fully; beyond it the
    /// projection fades linearly with the angle, to none for a direction along
    /// the plane's normal. The full projection turns fast where `b` passes
    /// near the normal (its projection's direction is ill-conditioned there,
    /// 1 / cos of the angle): the fade bounds that to `π / 2 / (π / 2 - this)`
    /// times the turn of `b` itself. `None`: projected fully everywhere
    /// (thesis §3.3.1).
    pub project_build_full_rad: Option<f64>,
    /// Take the build direction of the first layer along the substrate's
    /// outward normal (made perpendicular to `t`) instead of `t × n` (thesis
    /// §2.4.2, for features added on a non-planar substrate).
    pub first_layer_along_substrate: bool,
    /// Bound on the rate of change of the lead/tilt angles along a layer (rad
    /// per mm of path), enforced by [`smooth_angles`] after the rule; `None`
    /// leaves them as computed. The axis `T` then turns at most at this rate
    /// relative to the local frame (the frame's own turn comes on top; a rule's
    /// cone is not re-imposed — check the report).
    pub max_rate_rad_per_mm: Option<f64>,
    /// Bound on the angular rate of `T` itself along a layer (rad per mm of
    /// path, part frame), enforced last by [`smooth_layer`]: where the build
    /// direction jumps (the cusps of constant-distance layers), the torch turns
    /// over a window split evenly before and after the jump instead of at
    /// once, so that the robot's wrist can follow. `None` leaves `T` as
    /// computed.
    pub max_axis_rate_rad_per_mm: Option<f64>,
}

impl Default for ToolAxisOptions {
    fn default() -> Self {
        Self {
            normals: NormalMethod::Auto,
            lead_rad: 0.0,
            tilt_rad: 0.0,
            rule: AxisRule::None,
            project_build: None,
            project_build_full_rad: None,
            first_layer_along_substrate: false,
            max_rate_rad_per_mm: None,
            max_axis_rate_rad_per_mm: None,
        }
    }
}

impl ToolAxisOptions {
    /// The thesis's set-up for the hemisphere top (eq. 3.20–3.21): tool axis
    /// along `b` except where `b` leans more than 50° from the part's Z, where
    /// it is tilted back to exactly 50°.
    pub fn thesis_50_deg_rule() -> Self {
        Self {
            rule: AxisRule::thesis_50_deg(),
            ..Self::default()
        }
    }

    /// Checks every field.
    ///
    /// # Errors
    /// [`ToolAxisError::InvalidOption`] naming the field.
    pub fn validate(&self) -> Result<(), ToolAxisError> {
        let bad = |field: &'static str, reason: String| {
            Err(ToolAxisError::InvalidOption { field, reason })
        };
        let angle_ok = |a: f64| a.is_finite() && a.abs() < std::f64::consts::FRAC_PI_2 - 1e-9;
        if !angle_ok(self.lead_rad) {
            return bad(
                "lead_rad",
                format!(
                    "must be finite and within (-π/2, π/2), got {}",
                    self.lead_rad
                ),
            );
        }
        if !angle_ok(self.tilt_rad) {
            return bad(
                "tilt_rad",
                format!(
                    "must be finite and within (-π/2, π/2), got {}",
                    self.tilt_rad
                ),
            );
        }
        if let Some(p) = self.project_build {
            let v = Vector3::from(p);
            if !(v.iter().all(|c| c.is_finite()) && v.norm() > 0.0) {
                return bad(
                    "project_build",
                    format!("plane normal must be finite and non-zero, got {p:?}"),
                );
            }
        }
        if let Some(a) = self.project_build_full_rad {
            if !(a > 0.0 && a < std::f64::consts::FRAC_PI_2) {
                return bad(
                    "project_build_full_rad",
                    format!("must be within (0, π/2), got {a}"),
                );
            }
        }
        for (field, rate) in [
            ("max_rate_rad_per_mm", self.max_rate_rad_per_mm),
            ("max_axis_rate_rad_per_mm", self.max_axis_rate_rad_per_mm),
        ] {
            if let Some(r) = rate {
                if !(r.is_finite() && r > 0.0) {
                    return bad(field, format!("must be positive and finite, got {r}"));
                }
            }
        }
        self.rule.validate()
    }
}

/// What [`tool_axes`] did, for reports.
#[derive(Debug, Clone, PartialEq)]
pub struct ToolAxisReport {
    /// The normal method actually used.
    pub normals: NormalMethod,
    /// Points where the rule changed the angles.
    pub rule_active_points: usize,
    /// Points where the rule could not reach its target (e.g. the cone axis is
    /// out of reach by tilt alone); `(layer, point)`, first 100.
    pub rule_unreachable: Vec<(usize, usize)>,
    /// Number of such points.
    pub rule_unreachable_count: usize,
    /// Largest angle between `T` and the part's +Z (rad).
    pub max_angle_from_z_rad: f64,
    /// Largest angular rate of `T` between consecutive points (rad/mm, part
    /// frame): the turn of the local frame plus the change of the angles.
    pub max_rate_rad_per_mm: f64,
    /// Largest rate of change of the lead/tilt pair between consecutive
    /// points (rad/mm), after smoothing.
    pub max_angle_rate_rad_per_mm: f64,
    /// Points whose `T` the smoothing moved.
    pub smoothed_points: usize,
}

/// The tool axes of a path: one frame per point, layer by layer (same shape
/// as `path.layers`), with the lead/tilt angles used and a report.
#[derive(Debug, Clone, PartialEq)]
pub struct ToolAxes {
    /// Local frames (part frame), `frames[layer][point]`.
    pub frames: Vec<Vec<LocalFrame>>,
    /// `(theta_n, theta_t)` (rad) of `T` relative to `b` at each point, after
    /// rules and smoothing.
    pub angles: Vec<Vec<(f64, f64)>>,
    /// What was done.
    pub report: ToolAxisReport,
}

/// Errors of the tool-axis stage; each names the option, layer or point.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ToolAxisError {
    /// An option is invalid.
    #[error("tool-axis option `{field}`: {reason}")]
    InvalidOption {
        /// The option.
        field: &'static str,
        /// What is wrong.
        reason: String,
    },
    /// Analytic normals were asked for without a tube.
    #[error("analytic normals need the tube surface; pass the tube or use numeric normals")]
    NeedsTube,
    /// Numeric normals need at least two slices (a facet below or above).
    #[error("numeric normals need at least two slices; the path has {slices}")]
    TooFewSlices {
        /// Slices in the path.
        slices: usize,
    },
    /// A layer has fewer than 2 points: no tangent.
    #[error("layer {layer}: {points} point(s), a tangent needs at least 2")]
    TooFewPoints {
        /// Layer index in `path.layers`.
        layer: usize,
        /// Its number of points.
        points: usize,
    },
    /// The two neighbours of a point coincide: no tangent.
    #[error("layer {layer}, point {point}: its neighbours coincide, no tangent (eq. 2.34)")]
    DegenerateTangent {
        /// Layer.
        layer: usize,
        /// Point.
        point: usize,
    },
    /// The facets of a point are flat (the nearest point of the next layer
    /// is on the chord): no numeric normal.
    #[error("layer {layer}, point {point}: degenerate facet, no numeric normal (eq. 2.35–2.36)")]
    DegenerateNormal {
        /// Layer.
        layer: usize,
        /// Point.
        point: usize,
    },
    /// `frames` and `path` do not have the same shape.
    #[error("layer {layer}: {frames} frames for {points} points")]
    ShapeMismatch {
        /// Layer.
        layer: usize,
        /// Frames given.
        frames: usize,
        /// Points in the layer.
        points: usize,
    },
    /// A torch specification is invalid.
    #[error("torch `{field}`: {reason}")]
    InvalidTorch {
        /// The field.
        field: &'static str,
        /// What is wrong.
        reason: String,
    },
    /// A collision query is not supported for this pair of shapes.
    #[error("collision query unsupported between the torch and {what}")]
    UnsupportedQuery {
        /// The obstacle.
        what: &'static str,
    },
}

/// **Stage 3 entry point.** Tool axes of every point of `path`.
///
/// `tube` gives analytic normals (required by [`NormalMethod::Analytic`],
/// used by [`NormalMethod::Auto`] when present); `substrate` orients the build
/// directions away from it (plane or cylinder; when absent or a mesh, `b`
/// points toward the next layer). [SPEC §4; thesis eq. 2.30–2.36, 3.20–3.21]
///
/// # Errors
/// [`ToolAxisError`] for invalid options, a missing tube, too few points or
/// slices, or degenerate tangents and facets (naming layer and point).
///
/// # Example
/// ```
/// # use waam_slicer::{io::part_file::read_part_file, path::slice, toolaxis::*};
/// let part = read_part_file(std::path::Path::new("parts/hemisphere.toml")).unwrap();
/// let path = slice(&part.tube, &part.substrate, &part.slice_options()).unwrap();
/// let axes = tool_axes(&path, Some(&part.tube), Some(&part.substrate),
///                      &ToolAxisOptions::thesis_50_deg_rule()).unwrap();
/// assert!(axes.report.max_angle_from_z_rad <= 50f64.to_radians() + 1e-9);
/// ```
pub fn tool_axes(
    path: &Path,
    tube: Option<&Tube>,
    substrate: Option<&Substrate>,
    opts: &ToolAxisOptions,
) -> Result<ToolAxes, ToolAxisError> {
    opts.validate()?;
    for (li, l) in path.layers.iter().enumerate() {
        if l.points.len() < 2 {
            return Err(ToolAxisError::TooFewPoints {
                layer: li,
                points: l.points.len(),
            });
        }
    }
    if let AxisRule::PerPoint { angles } = &opts.rule {
        rules::check_shape(path, angles.iter().map(Vec::len))?;
    }
    let method = match (opts.normals, tube) {
        (NormalMethod::Analytic, None) => return Err(ToolAxisError::NeedsTube),
        (NormalMethod::Auto, Some(_)) | (NormalMethod::Analytic, Some(_)) => NormalMethod::Analytic,
        (NormalMethod::Auto, None) | (NormalMethod::Numeric, _) => NormalMethod::Numeric,
    };
    // 1. t, n, b.
    let mut frames = match (method, tube) {
        (NormalMethod::Analytic, Some(tube)) => normals::analytic_frames_checked(path, tube)?,
        _ => normals::numeric_frames(path)?,
    };
    if let Some(s) = substrate {
        normals::orient_away_from_substrate(path, &mut frames, s, opts.first_layer_along_substrate);
    }
    // 2. Projection of b into a plane.
    if let Some(p) = opts.project_build {
        let full = opts
            .project_build_full_rad
            .unwrap_or(std::f64::consts::FRAC_PI_2);
        rules::project_build(&mut frames, &Vector3::from(p).normalize(), full);
    }
    // 3.–5. Per layer, independently (in parallel, results in layer order):
    // lead / tilt, constant or by rule; smoothing of the angles; bound on
    // the rate of T; the layer's part of the report.
    let per_layer: Vec<(Vec<(f64, f64)>, LayerAxisReport)> = path
        .layers
        .par_iter()
        .zip(frames.par_iter_mut())
        .enumerate()
        .map(|(li, (layer, layer_frames))| layer_axes(layer, li, layer_frames, opts))
        .collect();
    let mut report = ToolAxisReport {
        normals: method,
        rule_active_points: 0,
        rule_unreachable: Vec::new(),
        rule_unreachable_count: 0,
        max_angle_from_z_rad: 0.0,
        max_rate_rad_per_mm: 0.0,
        max_angle_rate_rad_per_mm: 0.0,
        smoothed_points: 0,
    };
    let mut angles = Vec::with_capacity(per_layer.len());
    for (la, r) in per_layer {
        report.rule_active_points += r.rule_active_points;
        report.rule_unreachable_count += r.rule_unreachable.len();
        for &pi in &r.rule_unreachable {
            if report.rule_unreachable.len() < 100 {
                report.rule_unreachable.push((angles.len(), pi));
            }
        }
        report.smoothed_points += r.smoothed_points;
        report.max_rate_rad_per_mm = report.max_rate_rad_per_mm.max(r.max_rate_rad_per_mm);
        report.max_angle_from_z_rad = report.max_angle_from_z_rad.max(r.max_angle_from_z_rad);
        angles.push(la);
    }
    Ok(ToolAxes {
        frames,
        angles,
        report,
    })
}

/// One layer's part of [`ToolAxisReport`].
struct LayerAxisReport {
    rule_active_points: usize,
    /// Points where the rule could not reach its target.
    rule_unreachable: Vec<usize>,
    smoothed_points: usize,
    max_rate_rad_per_mm: f64,
    max_angle_from_z_rad: f64,
}

/// Steps 3–5 of [`tool_axes`] on layer `li`: sets the tool axis of each of
/// its frames and returns its `(theta_n, theta_t)` angles and report.
fn layer_axes(
    layer: &crate::path::Layer,
    li: usize,
    frames: &mut [LocalFrame],
    opts: &ToolAxisOptions,
) -> (Vec<(f64, f64)>, LayerAxisReport) {
    let positions: Vec<_> = layer.points.iter().map(|p| p.position).collect();
    axes_along(&positions, layer.bead_wraps(), li, 0, frames, opts)
}

/// The tool axes `T` (part frame, unit) of one bead of a layer split into
/// beads: points `range` of layer `li` of `path`, whose frames (`b`, `t`,
/// `n`; [`tool_axes`]'s output) are `frames`, set by steps 3–5 of
/// [`tool_axes`] as on an open layer that runs from the bead's first point
/// to its last. The rate bound then spreads no jump of the build direction
/// across the bead's ends: where the layer is split at a corner, each bead
/// keeps its own side's axes up to the corner instead of turning half way
/// round it toward the other bead's.
///
/// # Panics
/// Never; an empty or out-of-range `range` gives the axes of the points it
/// holds within the layer (none for an empty one).
pub fn bead_tool_axes(
    path: &Path,
    li: usize,
    frames: &[LocalFrame],
    range: std::ops::Range<usize>,
    opts: &ToolAxisOptions,
) -> Vec<Vector3> {
    let Some(layer) = path.layers.get(li) else {
        return Vec::new();
    };
    let end = range.end.min(layer.points.len()).min(frames.len());
    let start = range.start.min(end);
    let positions: Vec<_> = layer.points[start..end]
        .iter()
        .map(|p| p.position)
        .collect();
    let mut bead = frames[start..end].to_vec();
    axes_along(&positions, false, li, start, &mut bead, opts);
    bead.iter().map(|f| f.tool).collect()
}

/// Steps 3–5 of [`tool_axes`] on the points `positions` (part frame, mm)
/// of layer `li` from its point `first` on, whose frames are `frames`;
/// `wraps`: the bead runs across the last point to the first.
fn axes_along(
    positions: &[crate::math::Point3],
    wraps: bool,
    li: usize,
    first: usize,
    frames: &mut [LocalFrame],
    opts: &ToolAxisOptions,
) -> (Vec<(f64, f64)>, LayerAxisReport) {
    let mut report = LayerAxisReport {
        rule_active_points: 0,
        rule_unreachable: Vec::new(),
        smoothed_points: 0,
        max_rate_rad_per_mm: 0.0,
        max_angle_from_z_rad: 0.0,
    };
    // 3. Lead / tilt, constant or by rule.
    let mut angles = Vec::with_capacity(frames.len());
    for (pi, f) in frames.iter_mut().enumerate() {
        let out = opts
            .rule
            .apply(f, opts.lead_rad, opts.tilt_rad, li, first + pi);
        if out.active {
            report.rule_active_points += 1;
        }
        if !out.reached {
            report.rule_unreachable.push(first + pi);
        }
        f.tool = tool_axis(f, out.lead_rad, out.tilt_rad);
        angles.push((out.lead_rad, out.tilt_rad));
    }
    // 4. Smoothing of the lead/tilt angles along the layer.
    if let Some(rate) = opts.max_rate_rad_per_mm {
        let moved = smooth_angles(positions, &mut angles, wraps, rate);
        report.smoothed_points += moved;
        if moved > 0 {
            for (f, &(lead, tilt)) in frames.iter_mut().zip(&angles) {
                f.tool = tool_axis(f, lead, tilt);
            }
        }
    }
    // 5. Bound on the rate of T itself.
    let mut axes: Vec<Vector3> = frames.iter().map(|f| f.tool).collect();
    if let Some(rate) = opts.max_axis_rate_rad_per_mm {
        let moved = smooth_layer(positions, &mut axes, wraps, rate);
        report.smoothed_points += moved;
        if moved > 0 {
            for ((f, t), a) in frames.iter_mut().zip(&axes).zip(angles.iter_mut()) {
                f.tool = *t;
                *a = lead_tilt_of(f, t);
            }
        }
    }
    report.max_rate_rad_per_mm = rules::max_rate(positions, &axes, wraps);
    for a in &axes {
        report.max_angle_from_z_rad = report.max_angle_from_z_rad.max(a.z.clamp(-1.0, 1.0).acos());
    }
    (angles, report)
}
