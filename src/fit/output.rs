//! The fitted tube as a part file ([`PartSpec`]): a `spline` guide through
//! the fitted points, a `constant` or `piecewise` cubic radius law over the
//! same knots, a flat substrate at the start end, and the slicing, tool-axis
//! and process tables of a template part (or the sample parts' defaults).

use super::outcome::TubeFit;
use super::smooth;
use crate::io::part_file::{
    FrameSpec, GuideSpec, PartSpec, ProcessSpec, ProfilePieceSpec, ProfileSpec, RangeSpec, Scalar,
    SlicingSpec, SubstrateSpec, ToolAxisSpec,
};
use crate::path::Strategy;
use crate::process::ProcessPreset;

fn number(x: f64) -> String {
    // Display of f64 is the shortest text that reads back to the same value,
    // and never uses an exponent.
    if x < 0.0 {
        format!("({x})")
    } else {
        format!("{x}")
    }
}

/// `A(t)` on one knot interval, in Horner form of `(t - k)`.
fn cubic_text(c: [f64; 4], k: f64) -> String {
    let x = format!("(t - {})", number(k));
    format!(
        "{} + {x} * ({} + {x} * ({} + {x} * {}))",
        number(c[0]),
        number(c[1]),
        number(c[2]),
        number(c[3])
    )
}

fn vec3(v: [f64; 3]) -> [Scalar; 3] {
    v.map(Scalar::Number)
}

impl TubeFit {
    /// The radius law as a part file's `[profile]`: `constant` when every
    /// knot value is the same, else `piecewise` cubics (one per knot
    /// interval, C² at the knots).
    pub fn profile_spec(&self) -> ProfileSpec {
        let r = &self.radius_mm;
        if r.iter().all(|&x| x == r[0]) {
            return ProfileSpec::Constant {
                radius: Scalar::Number(r[0]),
            };
        }
        let m = smooth::natural_second_derivatives(&self.knots, r);
        let n = self.knots.len() - 1;
        let pieces = (0..n)
            .map(|i| ProfilePieceSpec {
                until: (i + 1 < n).then(|| Scalar::Number(self.knots[i + 1])),
                radius: cubic_text(smooth::interval_cubic(&self.knots, r, &m, i), self.knots[i]),
            })
            .collect();
        ProfileSpec::Piecewise { pieces }
    }

    /// The fitted tube as a part file named `name`; the `[slicing]`,
    /// `[tool_axis]` and `[process]` tables (and the constants they may
    /// use) come from `template` when given, else constant-distance slicing
    /// at `Delta` = 2 mm with 400 points, the tool axis's turning rate
    /// bounded to 10°/mm, CMT steel (as the bent sample parts).
    pub fn part_spec(&self, name: &str, template: Option<&PartSpec>) -> PartSpec {
        let rep = &self.report;
        let wall = rep
            .wall
            .as_ref()
            .map(|w| format!(", wall {:.3} mm", w.mean_mm))
            .unwrap_or_default();
        let (slicing, tool_axis, process, constants) = match template {
            Some(t) => (
                t.slicing.clone(),
                t.tool_axis.clone(),
                t.process.clone(),
                t.constants.clone(),
            ),
            None => (
                SlicingSpec {
                    strategy: Strategy::Constant,
                    delta_mm: 2.0,
                    points: Some(400),
                    chord_mm: None,
                    max_spacing_mm: None,
                    corner_threshold_deg: None,
                    seams_on_corners: None,
                },
                Some(ToolAxisSpec {
                    max_axis_rate_deg_per_mm: Some(Scalar::Number(10.0)),
                    ..ToolAxisSpec::default()
                }),
                Some(ProcessSpec {
                    preset: ProcessPreset::CmtSteel,
                    ..ProcessSpec::default()
                }),
                Default::default(),
            ),
        };
        PartSpec {
            name: name.to_string(),
            description: format!(
                "tube fitted to a mesh: {:.1} mm long, radius {:.3} to {:.3} mm{wall}; vertices {:.4} mm RMS, {:.4} mm at most from the fitted surface",
                rep.length_mm, rep.radius_min_mm, rep.radius_max_mm, rep.rms_mm, rep.max_mm
            ),
            source: format!("waam fit of {} ({} triangles)", self.file, rep.triangles),
            constants,
            guide: GuideSpec::Spline {
                points: self.guide_points.iter().map(|p| [p.x, p.y, p.z]).collect(),
            },
            frame: FrameSpec::default(),
            profile: self.profile_spec(),
            range: RangeSpec {
                t_min: Scalar::Number(self.t_min),
                t_max: Scalar::Number(self.t_max),
                extend_before: Some(Scalar::Number(self.extend_before_mm)),
                extend_after: None,
            },
            substrate: SubstrateSpec::Plane {
                point: vec3(self.substrate_point.coords.into()),
                normal: vec3(self.substrate_normal.into_inner().into()),
            },
            end_plane: None,
            slicing,
            tool_axis,
            process,
        }
    }
}
