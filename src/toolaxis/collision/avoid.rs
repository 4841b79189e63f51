//! Collision avoidance: the tool axis tilted within a cone about its
//! nominal direction, smoothly along each layer, until the clearance is
//! reached (part frame, mm, rad).

use super::clearance::{check_shape, layer_clearances, substrate_shape, summarise, Obstacles};
use super::torch::Torch;
use super::{CollisionOptions, CollisionReport, LayerClearance};
use crate::geometry::Substrate;
use crate::math::{tol, Isometry3, Point3, Vector3};
use crate::path::Path;
use crate::toolaxis::rules::{angle, smooth_angles};
use crate::toolaxis::{LocalFrame, ToolAxisError};
use parry3d_f64::shape::Shape;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// Options of [`avoid_collisions`]. Plain data.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct AvoidanceOptions {
    /// Largest deviation of the tool axis from its nominal direction (rad,
    /// in (0, π/2)): the user's cone.
    pub cone_half_angle_rad: f64,
    /// Angular step of the search rings (rad, > 0).
    pub step_rad: f64,
    /// Directions per search ring (>= 4).
    pub azimuths: usize,
    /// Clearance to reach (mm, >= 0).
    pub margin_mm: f64,
    /// Bound on the rate of change of the corrections along a layer (rad per
    /// mm of path, > 0): a correction fades in and out over neighbouring
    /// points at this rate.
    pub max_rate_rad_per_mm: f64,
    /// Search rounds (>= 1): a round re-searches the points a blended
    /// correction did not clear.
    pub rounds: usize,
}

impl Default for AvoidanceOptions {
    fn default() -> Self {
        Self {
            cone_half_angle_rad: 60f64.to_radians(),
            step_rad: 2.5f64.to_radians(),
            azimuths: 16,
            margin_mm: 1.0,
            max_rate_rad_per_mm: 0.05,
            rounds: 3,
        }
    }
}

impl AvoidanceOptions {
    /// Checks every field.
    ///
    /// # Errors
    /// [`ToolAxisError::InvalidOption`] naming the field.
    pub fn validate(&self) -> Result<(), ToolAxisError> {
        let bad = |field: &'static str, reason: String| {
            Err(ToolAxisError::InvalidOption { field, reason })
        };
        if !(self.cone_half_angle_rad > 0.0
            && self.cone_half_angle_rad < std::f64::consts::FRAC_PI_2)
        {
            return bad(
                "cone_half_angle_rad",
                format!("must be in (0, π/2), got {}", self.cone_half_angle_rad),
            );
        }
        if !(self.step_rad > 0.0 && self.step_rad.is_finite()) {
            return bad(
                "step_rad",
                format!("must be positive, got {}", self.step_rad),
            );
        }
        if self.azimuths < 4 {
            return bad("azimuths", format!("must be >= 4, got {}", self.azimuths));
        }
        if !(self.margin_mm >= 0.0 && self.margin_mm.is_finite()) {
            return bad("margin_mm", format!("must be >= 0, got {}", self.margin_mm));
        }
        if !(self.max_rate_rad_per_mm > 0.0 && self.max_rate_rad_per_mm.is_finite()) {
            return bad(
                "max_rate_rad_per_mm",
                format!("must be positive, got {}", self.max_rate_rad_per_mm),
            );
        }
        if self.rounds == 0 {
            return bad("rounds", "must be >= 1".into());
        }
        Ok(())
    }
}

/// What [`avoid_collisions`] did.
#[derive(Debug, Clone, PartialEq)]
pub struct AvoidanceReport {
    /// Clearances with the input axes.
    pub before: CollisionReport,
    /// Clearances with the corrected axes.
    pub after: CollisionReport,
    /// Points whose axis was changed.
    pub corrected_points: usize,
    /// Largest change of an axis (rad).
    pub max_correction_rad: f64,
    /// Points for which no direction in the cone reached the margin,
    /// `(layer, point)`, first 100.
    pub unresolved: Vec<(usize, usize)>,
}

/// Unit basis `(e1, e2)` perpendicular to `tool`, `e1` along the tangent.
fn cone_basis(f: &LocalFrame, tool: &Vector3) -> (Vector3, Vector3) {
    let e1 = f.tangent - tool * f.tangent.dot(tool);
    let e1 = if e1.norm() > tol::ANGLE_RAD {
        e1.normalize()
    } else {
        crate::math::any_perpendicular(tool)
    };
    (e1, tool.cross(&e1))
}

/// `tool` tilted by the correction `c = angle · (cos φ, sin φ)` in the cone
/// basis of the frame.
fn corrected(f: &LocalFrame, tool: &Vector3, c: &[f64; 2]) -> Vector3 {
    let m = c[0].hypot(c[1]);
    if m == 0.0 {
        return *tool;
    }
    let (e1, e2) = cone_basis(f, tool);
    let dir = (e1 * c[0] + e2 * c[1]) / m;
    (tool * m.cos() + dir * m.sin()).normalize()
}

/// Tilts the tool axes, within a cone around each nominal axis, to clear the
/// torch from the part built so far and the substrate, smoothly along each
/// layer. For each point that misses the margin, rings of directions
/// (`azimuths` per ring, `step_rad` apart) are searched for the smallest ring
/// with a direction reaching the margin (bounded, cheap queries), taking the
/// bisector of its widest free arc — starting from the previous
/// point's ring, going down while rings clear and up otherwise (clearance is
/// assumed to grow with the tilt; the result is re-checked) — and that
/// direction kept; the corrections (angle and direction in the
/// local `(t, T × t)` basis) are then spread along the layer as an upper
/// envelope falling off at `max_rate_rad_per_mm`, re-searched where that
/// did not clear, and the correction field finally smoothed to that rate. Returns the
/// new frames (only `tool` changes) and a report; points left unresolved are
/// reported, not errors. The smoothing acts on the corrections, expressed
/// in each point's local basis, so the rate bound applies to the change of
/// the correction, on top of the nominal axes' own variation. Layers in
/// parallel.
///
/// # Errors
/// [`ToolAxisError`] for bad options, a shape mismatch, or an unsupported
/// query.
pub fn avoid_collisions(
    path: &Path,
    frames: &[Vec<LocalFrame>],
    substrate: Option<&Substrate>,
    torch: &Torch,
    copts: &CollisionOptions,
    aopts: &AvoidanceOptions,
) -> Result<(Vec<Vec<LocalFrame>>, AvoidanceReport), ToolAxisError> {
    copts.validate()?;
    aopts.validate()?;
    check_shape(path, frames)?;
    let sub = substrate
        .filter(|_| copts.check_substrate)
        .and_then(|s| substrate_shape(path, s));
    let outs = (0..path.layers.len())
        .into_par_iter()
        .map(|li| avoid_in_layer(path, &frames[li], li, sub.as_ref(), torch, copts, aopts))
        .collect::<Result<Vec<_>, ToolAxisError>>()?;
    let mut new_frames = Vec::with_capacity(outs.len());
    let mut before = Vec::with_capacity(outs.len());
    let mut after = Vec::with_capacity(outs.len());
    let mut corrected_points = 0;
    let mut max_correction_rad: f64 = 0.0;
    let mut unresolved = Vec::new();
    for (li, o) in outs.into_iter().enumerate() {
        corrected_points += o.corrected;
        max_correction_rad = max_correction_rad.max(o.max_corr);
        for p in o.unresolved {
            if unresolved.len() < 100 {
                unresolved.push((li, p));
            }
        }
        new_frames.push(o.frames);
        before.push(o.before);
        after.push(o.after);
    }
    let checked = sub.is_some();
    Ok((
        new_frames,
        AvoidanceReport {
            before: CollisionReport::from_layers(before, checked),
            after: CollisionReport::from_layers(after, checked),
            corrected_points,
            max_correction_rad,
            unresolved,
        },
    ))
}

/// One layer's frames after the avoidance, and what it did.
struct LayerOut {
    frames: Vec<LocalFrame>,
    before: LayerClearance,
    after: LayerClearance,
    /// Points whose tool axis moved.
    corrected: usize,
    /// Largest correction (rad).
    max_corr: f64,
    /// Points left short of the clearance.
    unresolved: Vec<usize>,
}

/// Layer `li`'s tool axes (frames `fr`) tilted clear of the part built
/// below it and the substrate `sub`, in rounds: the points short of the
/// margin searched for their smallest clearing tilt, the tilts blended
/// along the layer at the rate bound, then smoothed.
fn avoid_in_layer(
    path: &Path,
    fr: &[LocalFrame],
    li: usize,
    sub: Option<&(Isometry3, Box<dyn Shape>)>,
    torch: &Torch,
    copts: &CollisionOptions,
    aopts: &AvoidanceOptions,
) -> Result<LayerOut, ToolAxisError> {
    let layer = &path.layers[li];
    let obstacles = Obstacles::new(path, layer.slice, sub, copts.bead_radius_mm);
    let nominal: Vec<Vector3> = fr.iter().map(|f| f.tool).collect();
    let c0 = layer_clearances(&obstacles, torch, path, li, &nominal)?;
    let before = summarise(li, &c0);
    let n = fr.len();
    let positions: Vec<Point3> = layer.points.iter().map(|p| p.position).collect();
    let along = ArcLength::of(&positions, layer.closed);
    // Required corrections per point, and the blended field.
    let mut need: Vec<[f64; 2]> = vec![[0.0, 0.0]; n];
    let mut unresolved = vec![false; n];
    let mut current = c0.clone();
    let mut axes = nominal.clone();
    let mut blended: Vec<[f64; 2]> = vec![[0.0, 0.0]; n];
    for _round in 0..aopts.rounds {
        let todo: Vec<usize> = (0..n)
            .filter(|&i| current[i] < aopts.margin_mm && !unresolved[i])
            .collect();
        if todo.is_empty() {
            break;
        }
        let mut hint = 1;
        for &i in &todo {
            let cone = Cone {
                obstacles: &obstacles,
                torch,
                frame: &fr[i],
                nominal: &nominal[i],
                position: &positions[i],
                aopts,
            };
            let start = blended[i][0].hypot(blended[i][1]);
            let (tilt, missed) = cone.clearing_tilt(start, &mut hint)?;
            if missed {
                unresolved[i] = true;
            }
            if let Some(c) = tilt {
                need[i] = c;
            }
        }
        upper_envelope(&need, &mut blended, &along, aopts.max_rate_rad_per_mm);
        for i in 0..n {
            axes[i] = corrected(&fr[i], &nominal[i], &blended[i]);
        }
        current = layer_clearances(&obstacles, torch, path, li, &axes)?;
    }
    // Smooth the correction field (local coordinates) to the rate.
    let mut pairs: Vec<(f64, f64)> = blended.iter().map(|c| (c[0], c[1])).collect();
    if smooth_angles(
        &positions,
        &mut pairs,
        layer.bead_wraps(),
        aopts.max_rate_rad_per_mm,
    ) > 0
    {
        for (b, p) in blended.iter_mut().zip(&pairs) {
            *b = [p.0, p.1];
        }
        for i in 0..n {
            axes[i] = corrected(&fr[i], &nominal[i], &blended[i]);
        }
    }
    let c1 = layer_clearances(&obstacles, torch, path, li, &axes)?;
    let after = summarise(li, &c1);
    let mut out_frames = fr.to_vec();
    let mut corrected_count = 0;
    let mut max_corr: f64 = 0.0;
    for (f, a) in out_frames.iter_mut().zip(&axes) {
        let d = angle(&f.tool, a);
        if d > tol::AXIS_MOVED_RAD {
            corrected_count += 1;
        }
        max_corr = max_corr.max(d);
        f.tool = *a;
    }
    Ok(LayerOut {
        frames: out_frames,
        before,
        after,
        corrected: corrected_count,
        max_corr,
        unresolved: (0..n).filter(|&i| unresolved[i] || c1[i] <= 0.0).collect(),
    })
}

/// Arc length along a layer (mm): per point from the first, and the
/// layer's whole length (closing segment included when closed).
struct ArcLength {
    s: Vec<f64>,
    total: f64,
    closed: bool,
}

impl ArcLength {
    fn of(positions: &[Point3], closed: bool) -> Self {
        let n = positions.len();
        let mut s = vec![0.0; n];
        for i in 1..n {
            s[i] = s[i - 1] + (positions[i] - positions[i - 1]).norm();
        }
        let total = s[n - 1]
            + if closed {
                (positions[0] - positions[n - 1]).norm()
            } else {
                0.0
            };
        Self { s, total, closed }
    }

    /// Distance along the layer between points `i` and `j` (mm; the
    /// shorter way round a closed layer).
    fn dist(&self, i: usize, j: usize) -> f64 {
        let d = (self.s[i] - self.s[j]).abs();
        if self.closed {
            d.min(self.total - d)
        } else {
            d
        }
    }
}

/// The upper envelope of the needed corrections at `rate` (rad/mm):
/// `|c_i| = max_j (|c_j| - rate d_ij)`, in the direction of the argmax.
fn upper_envelope(need: &[[f64; 2]], blended: &mut [[f64; 2]], along: &ArcLength, rate: f64) {
    let sources: Vec<usize> = (0..need.len())
        .filter(|&j| need[j][0] != 0.0 || need[j][1] != 0.0)
        .collect();
    for (i, bl) in blended.iter_mut().enumerate() {
        let mut best = (0.0, [0.0, 0.0]);
        for &j in &sources {
            let m = need[j][0].hypot(need[j][1]);
            let v = m - rate * along.dist(i, j);
            if v > best.0 {
                best = (v, [need[j][0] / m * v, need[j][1] / m * v]);
            }
        }
        *bl = best.1;
    }
}

/// The search cone of one point: its frame, nominal axis and position, the
/// obstacles and the torch.
struct Cone<'a> {
    obstacles: &'a Obstacles<'a>,
    torch: &'a Torch,
    frame: &'a LocalFrame,
    nominal: &'a Vector3,
    position: &'a Point3,
    aopts: &'a AvoidanceOptions,
}

impl Cone<'_> {
    /// The correction of ring `r` at azimuth `k` (`angle · (cos φ, sin φ)`).
    fn dir_of(&self, r: usize, k: usize) -> [f64; 2] {
        let theta = r as f64 * self.aopts.step_rad;
        let phi = std::f64::consts::TAU * k as f64 / self.aopts.azimuths as f64;
        [theta * phi.cos(), theta * phi.sin()]
    }

    /// Ring `r`: the direction in the middle of its longest run of clear
    /// azimuths (the bisector of the free arc), if any.
    fn ring(&self, r: usize) -> Result<Option<[f64; 2]>, ToolAxisError> {
        let aopts = self.aopts;
        let m = aopts.azimuths;
        let mut clear = Vec::with_capacity(m);
        for k in 0..m {
            let dir = corrected(self.frame, self.nominal, &self.dir_of(r, k));
            clear.push(self.obstacles.is_clear(
                self.torch,
                self.position,
                &dir,
                aopts.margin_mm,
            )?);
        }
        if clear.iter().all(|&c| c) {
            // No obstacle in reach: keep the tilt along t.
            return Ok(Some(self.dir_of(r, 0)));
        }
        // Longest circular run of clear azimuths.
        let start = clear.iter().position(|&c| !c).expect("one blocked");
        let (mut best, mut run) = (None::<(usize, usize)>, None::<(usize, usize)>);
        for step in 1..=m {
            let k = (start + step) % m;
            if clear[k] {
                run = Some(run.map_or((k, 1), |(s0, len)| (s0, len + 1)));
                let cur = run.expect("just set");
                if best.is_none_or(|b| cur.1 > b.1) {
                    best = Some(cur);
                }
            } else {
                run = None;
            }
        }
        Ok(best.map(|(s0, len)| {
            // Middle of the run (half-step for even lengths).
            let mid = s0 as f64 + 0.5 * (len as f64 - 1.0);
            let theta = r as f64 * aopts.step_rad;
            let phi = std::f64::consts::TAU * mid / m as f64;
            [theta * phi.cos(), theta * phi.sin()]
        }))
    }

    /// The smallest clearing tilt beyond the current one (`start`, rad),
    /// searched from the previous point's ring `hint` (neighbours need
    /// similar tilts; updated): down while rings clear, else up until one
    /// does. Returns the tilt (or, when no ring clears, the clearest
    /// direction of the widest ring) and whether the point stays short of
    /// the margin.
    fn clearing_tilt(
        &self,
        start: f64,
        hint: &mut usize,
    ) -> Result<(Option<[f64; 2]>, bool), ToolAxisError> {
        let aopts = self.aopts;
        let rings = (aopts.cone_half_angle_rad / aopts.step_rad).floor() as usize;
        let first = ((start / aopts.step_rad).floor() as usize + 1).max(1);
        if first > rings {
            return Ok((None, true));
        }
        let mut found: Option<[f64; 2]> = None;
        let mut r = (*hint).clamp(first, rings);
        if let Some(c) = self.ring(r)? {
            found = Some(c);
            while r > first {
                match self.ring(r - 1)? {
                    Some(c) => {
                        r -= 1;
                        found = Some(c);
                    }
                    None => break,
                }
            }
        } else {
            while r < rings {
                r += 1;
                if let Some(c) = self.ring(r)? {
                    found = Some(c);
                    break;
                }
            }
        }
        *hint = r;
        if found.is_some() {
            return Ok((found, false));
        }
        // Best effort: the clearest direction of the widest ring.
        let mut best: Option<([f64; 2], f64)> = None;
        for k in 0..aopts.azimuths {
            let c = self.dir_of(rings, k);
            let dir = corrected(self.frame, self.nominal, &c);
            let cl = self.obstacles.clearance(self.torch, self.position, &dir)?;
            if best.is_none_or(|b| cl > b.1) {
                best = Some((c, cl));
            }
        }
        Ok((best.map(|(c, _)| c), true))
    }
}
