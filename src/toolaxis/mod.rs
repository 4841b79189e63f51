//! **Stage 3 — tool axes.** Takes a [`Path`] and its [`Tube`] (part frame,
//! mm) and returns one [`LocalFrame`] per point: path tangent, surface normal,
//! build direction and tool axis [SPEC §4; thesis eq. 2.30–2.36]. This first
//! version uses the analytic surface normal and a tool axis along the build
//! direction (lead = tilt = 0).

use crate::geometry::Tube;
use crate::math::Vector3;
use crate::path::Path;

/// Local frame at one path point (part frame, unit vectors).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LocalFrame {
    /// Path tangent `t` (central difference along the layer, eq. 2.34).
    pub tangent: Vector3,
    /// Outward surface normal `n` (eq. 2.33).
    pub normal: Vector3,
    /// Build direction `b = t × n`, oriented away from the substrate (toward
    /// increasing guide parameter).
    pub build: Vector3,
    /// Tool axis `T` (here equal to `b`).
    pub tool: Vector3,
}

/// Local frames of every point of `path`, layer by layer.
pub fn local_frames(path: &Path, tube: &Tube) -> Vec<Vec<LocalFrame>> {
    path.layers
        .iter()
        .map(|layer| {
            let n = layer.points.len();
            (0..n)
                .map(|i| {
                    let p = &layer.points[i];
                    let (prev, next) = if layer.closed {
                        ((i + n - 1) % n, (i + 1) % n)
                    } else {
                        (i.saturating_sub(1), (i + 1).min(n - 1))
                    };
                    let sp = tube.surface(p.t, p.v);
                    let normal = sp.normal.into_inner();
                    let chord = layer.points[next].position - layer.points[prev].position;
                    // Tangent in the surface's tangent plane.
                    let tangent = {
                        let c = chord - normal * chord.dot(&normal);
                        if c.norm() > 0.0 {
                            c.normalize()
                        } else {
                            sp.d_dv.normalize()
                        }
                    };
                    let mut build = tangent.cross(&normal);
                    if build.dot(&sp.d_dt) < 0.0 {
                        build = -build;
                    }
                    LocalFrame {
                        tangent,
                        normal,
                        build,
                        tool: build,
                    }
                })
                .collect()
        })
        .collect()
}
