//! **The fit stage's output types**: the fitted tube ([`TubeFit`]) and its
//! report ([`FitReport`]: per station, per end, the wall), plus the two
//! values the driver hands to the report builder (an open end's ring, a
//! station's sections). Mesh frame = part frame, mm.

use super::section::{CircleFit, Frame};
use super::{smooth, Units};
use crate::geometry::guide::CubicSpline;
use crate::math::{Point3, UnitVector3};
use serde::Serialize;

/// A fitted tube (part frame = mesh frame, mm): the guide as the points of a
/// natural cubic spline (`t` = chord length from the start end, mm), the
/// radius law and the wall thickness as natural cubic splines over the same
/// knots, the substrate plane at the start end, and the fit report.
#[derive(Debug, Clone)]
pub struct TubeFit {
    /// The mesh file.
    pub file: String,
    /// Points of the spline guide, from the start end (mm).
    pub guide_points: Vec<Point3>,
    /// Guide parameter of each point: cumulative chord length (mm).
    pub knots: Vec<f64>,
    /// Guide parameter of the start end (mm): the first and last guide
    /// points lie one knot interval past the ends, so that the spline's
    /// natural end condition (no curvature) falls outside the tube.
    pub t_min: f64,
    /// Guide parameter of the other end (mm).
    pub t_max: f64,
    /// Radius of the (mid-surface) profile at each knot (mm).
    pub radius_mm: Vec<f64>,
    /// Wall thickness at each knot (mm), when two skins were given.
    pub thickness_mm: Option<Vec<f64>>,
    /// A point of the substrate plane: the guide's point at `t_min` (mm).
    pub substrate_point: Point3,
    /// The substrate's normal, toward the part: the start end's plane.
    pub substrate_normal: UnitVector3,
    /// Parameter range needed below `t = 0` for the substrate to cut the
    /// tube when the start end is not normal to the guide (mm).
    pub extend_before_mm: f64,
    /// Distance (mm) of each vertex of the mesh (same order as
    /// [`TubeMesh::vertices`](super::TubeMesh::vertices)) to the fitted surface, as in the report's
    /// RMS and largest distance; `None` for a vertex left out of the fit
    /// (a flat cap, a stray piece).
    pub vertex_distance_mm: Vec<Option<f64>>,
    /// What the fit found and how well it fits.
    pub report: FitReport,
}

impl TubeFit {
    /// Length of the tube's parameter range `t_max - t_min` (mm).
    pub fn length(&self) -> f64 {
        self.t_max - self.t_min
    }

    /// The guide curve.
    pub fn guide(&self) -> CubicSpline {
        CubicSpline::new(&self.guide_points).expect("validated when fitted")
    }

    /// The radius law `A(t)` (mm).
    pub fn radius(&self, t: f64) -> f64 {
        let m = smooth::natural_second_derivatives(&self.knots, &self.radius_mm);
        smooth::eval(&self.knots, &self.radius_mm, &m, t)
    }

    /// The wall thickness law (mm), when two skins were fitted.
    pub fn wall_thickness(&self, t: f64) -> Option<f64> {
        self.thickness_mm.as_ref().map(|e| {
            let m = smooth::natural_second_derivatives(&self.knots, e);
            smooth::eval(&self.knots, e, &m, t)
        })
    }
}

/// An open end of the tube (mesh frame, mm).
#[derive(Debug, Clone)]
pub(super) struct EndRing {
    pub centre: Point3,
    pub normal: UnitVector3,
    pub radius: f64,
    pub capped: bool,
    /// What [`classify`](super::ends::classify) found, once the guide is fitted.
    pub shape: Option<(EndShape, usize, f64)>,
    /// The loop index of this end in each skin.
    pub loops: Vec<usize>,
}

/// One station's sections (one per skin) and the combined centre and radius.
#[derive(Debug, Clone)]
pub(super) struct Station {
    pub t: f64,
    pub fits: Vec<Option<CircleFit>>,
    pub centre: Option<Point3>,
    pub radius: Option<f64>,
    pub thickness: Option<f64>,
    pub points: usize,
    /// Whether its rings took its neighbours' points (a coarse mesh): its
    /// radius then leans on the radius law's slope across them.
    pub widened: bool,
    /// Whether its centre is the bridge between two rings of vertices of a
    /// coarse export ([`bridge_between_rings`](super::coarse::bridge_between_rings)):
    /// it holds no section of its own, and its borrowed one is not checked.
    pub bridged: bool,
    /// Whether its section is a plane cut of the facets, taken for want of
    /// vertices ([`fill_from_cuts`](super::coarse::fill_from_cuts)).
    pub cut: bool,
    /// Where along the guide its points lie on average, from the station
    /// (mm), and its radius there less its radius at the station (mm): its
    /// circles' mean `dt` and the slope across it ([`Station::radius_read`]).
    pub read_shift: (f64, f64),
}

impl Station {
    /// Its radius (mm) at the guide parameter where its points lie on
    /// average (mm), when it holds one: the radius its points read with no
    /// slope. A ring of a coarse export a few mm off its station is read at
    /// the ring's own place; a smoothed slope across a kink of the profile
    /// (a reducer's cone meeting its pipe) carried it 3 mm off.
    pub(super) fn radius_read(&self) -> Option<(f64, f64)> {
        let (dt, dr) = self.read_shift;
        self.radius.map(|r| (self.t + dt, r + dr))
    }

    /// The station at `frame` from its circle per skin (`fits`) over `points`
    /// samples: its centre (the circles' mean) and radius and, with two skins,
    /// its wall thickness, when every skin has a circle and the ring is `full`.
    pub(super) fn from_fits(
        frame: &Frame,
        fits: Vec<Option<CircleFit>>,
        points: usize,
        full: bool,
    ) -> Station {
        let (ti, c, _, e1, e2) = frame;
        let all: Option<Vec<CircleFit>> = if full {
            fits.iter().copied().collect()
        } else {
            None
        };
        let (centre, radius, thickness, read_shift) = match all {
            Some(f) => {
                let m = f.len() as f64;
                let dt = f.iter().map(|f| f.mean_dt).sum::<f64>() / m;
                let dr = f.iter().map(|f| f.slope * f.mean_dt).sum::<f64>() / m;
                let cx = f.iter().map(|f| f.centre[0]).sum::<f64>() / m;
                let cy = f.iter().map(|f| f.centre[1]).sum::<f64>() / m;
                let r = f.iter().map(|f| f.radius).sum::<f64>() / m;
                let e = (f.len() == 2).then(|| (f[0].radius - f[1].radius).abs());
                (Some(c + e1 * cx + e2 * cy), Some(r), e, (dt, dr))
            }
            None => (None, None, None, (0.0, 0.0)),
        };
        Station {
            t: *ti,
            fits,
            centre,
            radius,
            thickness,
            points,
            widened: false,
            bridged: false,
            cut: false,
            read_shift,
        }
    }
}

/// One open end of the tube as found in the mesh (mesh frame, mm).
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct EndReport {
    /// Centre of its circle (mm).
    pub centre_mm: [f64; 3],
    /// Normal of its plane (unit; either sense).
    pub normal: [f64; 3],
    /// Radius of its circle (mm; the mid-surface's for two skins).
    pub radius_mm: f64,
    /// Whether a flat cap closes it (a disc on one skin, a ring joining two).
    pub capped: bool,
    /// How it is closed: open, flat-capped (one skin), ring-capped (two skins).
    pub kind: EndKind,
    /// Whether it is cut obliquely: its plane tilted from the tube's normal
    /// plane by more than [`OBLIQUE_TILT_DEG`](super::ends::OBLIQUE_TILT_DEG).
    pub oblique: bool,
    /// The tilt of its plane from the tube's normal plane there (degrees):
    /// the angle between the plane's normal and the rim's own axis, the
    /// direction (searched within 17 degrees of the guide's tangent) along
    /// which the rim looks most like a circle.
    pub tilt_deg: f64,
    /// Its station: 0 for the start, the last for the end.
    pub station: usize,
    /// Its guide parameter (mm from the start end).
    pub t_mm: f64,
}

/// One station along the fitted guide.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct StationReport {
    /// Index from the start end.
    pub index: usize,
    /// Guide parameter (mm from the start end along the chords).
    pub t_mm: f64,
    /// Mesh vertices in its section.
    pub points: usize,
    /// Centre of its least-squares circle (mesh frame, mm), when fitted.
    pub centre_mm: Option<[f64; 3]>,
    /// Radius of its least-squares circle (mm; mid-surface for two skins).
    pub section_radius_mm: Option<f64>,
    /// The fitted radius law there (mm).
    pub law_radius_mm: f64,
    /// Law minus section radius (mm).
    pub radius_error_mm: Option<f64>,
    /// RMS of the section's points to its own circle (mm; the worse skin).
    pub section_rms_mm: Option<f64>,
    /// RMS distance of its vertices to the fitted tube surface (mm).
    pub vertex_rms_mm: f64,
    /// Wall thickness of its two circles (mm), for two skins.
    pub wall_thickness_mm: Option<f64>,
    /// The fitted thickness law there (mm), for two skins.
    pub law_thickness_mm: Option<f64>,
}

/// Wall thickness along the tube (two skins given), from the fitted law (mm).
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct WallReport {
    /// Mean over the stations (mm).
    pub mean_mm: f64,
    /// Smallest (mm).
    pub min_mm: f64,
    /// Largest (mm).
    pub max_mm: f64,
}

/// What the fit found and how well the fitted tube matches the mesh.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct FitReport {
    /// The mesh file.
    pub file: String,
    /// Triangles in the mesh.
    pub triangles: usize,
    /// Vertices of the skins (the points fitted).
    pub vertices: usize,
    /// 1: the mid-surface; 2: the inner and outer skins of the wall.
    pub skins: usize,
    /// Flat faces (end caps) left out of the fit.
    pub caps: usize,
    /// Triangles of small stray pieces left out of the fit.
    pub ignored_triangles: usize,
    /// The start end (on the substrate).
    pub start: EndReport,
    /// The other end.
    pub end: EndReport,
    /// Refits of the guide.
    pub iterations: usize,
    /// Whether the guide stopped moving within the tolerance.
    pub converged: bool,
    /// Largest move of a guide point in the last refit (mm).
    pub last_move_mm: f64,
    /// Length of the guide's parameter range (mm).
    pub length_mm: f64,
    /// Points of the spline guide.
    pub guide_points: usize,
    /// Smallest radius of the law (mm).
    pub radius_min_mm: f64,
    /// Largest radius of the law (mm).
    pub radius_max_mm: f64,
    /// RMS distance of the skins' vertices to the fitted surface (mm).
    pub rms_mm: f64,
    /// Largest distance of a vertex to the fitted surface (mm).
    pub max_mm: f64,
    /// Where that vertex is (mesh frame, mm).
    pub max_at_mm: [f64; 3],
    /// Largest distance of a sample of the fitted surface to the mesh (mm;
    /// parry3d), when measured.
    pub surface_to_mesh_max_mm: Option<f64>,
    /// Largest distance (mm) of the start end's rim (its fitted circle) to
    /// the substrate mesh, when one was given
    /// ([`FitOptions::substrate`](super::FitOptions::substrate)).
    pub substrate_distance_mm: Option<f64>,
    /// Wall thickness, for two skins.
    pub wall: Option<WallReport>,
    /// The stations.
    pub stations: Vec<StationReport>,
    /// What was repaired before the fit.
    pub repair: RepairReport,
    /// The unit of the mesh file's coordinates; every length of this report
    /// is in mm.
    pub units: Units,
    /// What the fit noticed but did not refuse (a size suggesting another
    /// unit; a varying radius held by rings of vertices far apart).
    pub warnings: Vec<String>,
    /// Features that are not tube, left out of a trimmed fit
    /// ([`FitOptions::trim`](super::FitOptions::trim)).
    pub features: Vec<FeatureReport>,
}

/// A separate piece of the mesh left out of the fit (mesh frame, mm).
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct LeftOut {
    /// Its triangles.
    pub triangles: usize,
    /// Its area (mm²).
    pub area_mm2: f64,
    /// Its share of the mesh's area (0 to 1).
    pub area_fraction: f64,
    /// Its area-weighted centroid (mm).
    pub centroid_mm: [f64; 3],
}

/// What the fit repaired in the mesh before fitting it.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct RepairReport {
    /// Vertices welded into another within the weld tolerance (duplicated
    /// seam vertices).
    pub welded_vertices: usize,
    /// The weld tolerance (mm): a millionth of the bounding box's diagonal.
    pub weld_tolerance_mm: f64,
    /// Triangles dropped for a zero area or a repeated vertex.
    pub degenerate_triangles: usize,
    /// Separate pieces holding under 1 % of the area, left out.
    pub left_out: Vec<LeftOut>,
}

/// How an end of the tube is closed, as found in the mesh.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum EndKind {
    /// Open: the surface's rim (one skin, or both skins of a wall left open).
    #[default]
    Open,
    /// Closed by a flat face (a disc) on a single skin: a solid end or a
    /// plate.
    FlatCapped,
    /// The two skins of a wall joined by a flat ring.
    RingCapped,
    /// Not an end of the mesh: the fit was trimmed there, by the guide's
    /// normal plane, next to a feature that is not tube
    /// ([`FitOptions::trim`](super::FitOptions::trim)).
    Trimmed,
}

impl EndKind {
    /// The kind's name as written in `fit.json` and printed.
    pub fn name(self) -> &'static str {
        match self {
            EndKind::Open => "open",
            EndKind::FlatCapped => "flat-capped",
            EndKind::RingCapped => "ring-capped",
            EndKind::Trimmed => "trimmed",
        }
    }
}

/// What [`classify`](super::ends::classify) finds of one end.
#[derive(Debug, Clone, Copy)]
pub(super) struct EndShape {
    pub kind: EndKind,
    /// Angle between the end's plane and the guide's normal plane there (rad).
    pub tilt: f64,
    /// Radius of the rim seen along the guide (mm; the mean of the skins).
    pub radius: f64,
}

/// Which end, for the messages: `start` or `end`.
pub(super) fn which(first: bool) -> &'static str {
    if first {
        "start"
    } else {
        "end"
    }
}

/// What a feature that is not tube looks like.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum FeatureKind {
    /// A round sleeve all around the tube, at least as long as it is high.
    Collar,
    /// A round disc all around the tube, higher than it is long.
    Flange,
    /// An outline all around the tube that is not round (a square block).
    Block,
    /// A separate piece beside the tube (a printing tab).
    Tab,
    /// A piece on one side of the tube, joined to its wall (a lug, a fin,
    /// a boss): its outline covers under three quarters of the directions
    /// around the guide, and the wall beside it stays the tube's circle.
    Lug,
}

impl FeatureKind {
    /// The kind's name as printed.
    pub fn name(self) -> &'static str {
        match self {
            FeatureKind::Collar => "collar",
            FeatureKind::Flange => "flange",
            FeatureKind::Block => "block",
            FeatureKind::Tab => "tab",
            FeatureKind::Lug => "lug",
        }
    }
}

/// A feature that is not tube (mesh frame, mm; stations and `t` of the
/// guide fitted before trimming).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FeatureReport {
    /// What it looks like.
    pub kind: FeatureKind,
    /// Its first station along the guide.
    pub first_station: usize,
    /// Its last station.
    pub last_station: usize,
    /// Where it begins: its nearest point to the start end, as the
    /// distance along the guide from the start end (mm).
    pub t_from_mm: f64,
    /// Where it ends: its farthest point from the start end along the
    /// guide (mm from the start end).
    pub t_to_mm: f64,
    /// Its length along the guide (mm): `t_to_mm - t_from_mm`.
    pub length_mm: f64,
    /// How far it reaches out from the tube's wall (mm): its outline's
    /// largest distance from the guide minus the tube's radius.
    pub height_mm: f64,
    /// Its outline's narrowest and widest size across the guide (mm): twice
    /// its smallest and largest distance from the guide over the directions
    /// it covers.
    pub across_mm: [f64; 2],
    /// The share of the directions around the guide its outline covers
    /// (deg: 360 all around; under 270 for a lug; 0 for a separate piece).
    pub around_deg: f64,
    /// The guide's point at its middle (mm).
    pub centre_mm: [f64; 3],
    /// For a separate piece: its triangles (0 otherwise).
    pub triangles: usize,
    /// For a separate piece: its bounding box's sides (mm; zeros otherwise).
    pub box_mm: [f64; 3],
}

impl FeatureReport {
    /// Its size in words (mm).
    pub fn size(&self) -> String {
        if self.triangles > 0 {
            return format!(
                "a separate piece of {} triangles, {:.1} x {:.1} x {:.1} mm",
                self.triangles, self.box_mm[0], self.box_mm[1], self.box_mm[2]
            );
        }
        if self.kind == FeatureKind::Lug {
            return format!(
                "{:.1} mm long, reaching {:.1} mm out from the tube's wall on one side, over {:.0} degrees around",
                self.length_mm, self.height_mm, self.around_deg
            );
        }
        let across = if (self.across_mm[1] - self.across_mm[0]) < 0.05 * self.across_mm[1] {
            format!("{:.1} mm across", self.across_mm[1])
        } else {
            format!(
                "{:.1} to {:.1} mm across",
                self.across_mm[0], self.across_mm[1]
            )
        };
        format!(
            "{:.1} mm long, reaching {:.1} mm out from the tube's wall, {across}",
            self.length_mm, self.height_mm
        )
    }
}
