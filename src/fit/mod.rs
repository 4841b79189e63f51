//! **Stage 0a — a tube from a mesh.** Takes a triangle mesh of a thin-walled
//! tube ([`TubeMesh`], read from a binary or ASCII STL; mesh frame = part
//! frame, mm): its mid-surface, or the inner and outer skins of its wall, and
//! gives a [`TubeFit`]: a cubic-spline guide `Mg(t)` (`t` = chord length, mm),
//! a smooth radius law `A(t)` (mm) from end to end, the wall thickness when
//! two skins are given, the start end's plane as a flat substrate (or, with
//! [`FitOptions::substrate`], a substrate mesh the start end must stand
//! on), the distance of every mesh vertex to the fitted surface, and a
//! [`FitReport`] (distances of the mesh to the fitted surface, per-station
//! radius errors). [`TubeFit::part_spec`] writes it as a part file that the
//! later stages take unchanged; the front door is
//! [`Part::from_mesh`](crate::Part::from_mesh).
//!
//! A mesh in another unit ([`FitOptions::units`]: cm, m, in) is converted
//! to mm first, and repaired ([`repair`]: duplicated seam vertices welded,
//! zero-area triangles dropped, separate pieces under 1 % of the area left
//! out and named in the report); winding and normals are never read.
//!
//! The pieces (STYLE §10): the problem of one section — a least-squares
//! circle in the plane normal to the guide ([`section`]); the smoothing fit of
//! the guide and radius law by a natural cubic spline ([`smooth`]); the options
//! ([`FitOptions`]); the driver ([`fit_tube`]): the mesh's open ends and
//! faces ([`topology`]), a first guide through the centroids of the level
//! sets of the geodesic distance from the start end, then sections normal to
//! the current guide, a circle per section, a smooth refit, until the guide
//! stops moving. Where the vertices' sections fail (a coarse export whose
//! rings lie askew to the stations), the refits take points along a bend's
//! edges too, or else start from plane cuts of the skin (`cut`: a first
//! guide marched through them, sections cut from the triangles), and end on
//! the vertices. A mesh that is not one tube (a branch, a closed blob, a
//! section far from a circle, a residual over [`FitOptions::max_rms_mm`]) is
//! refused with a [`FitError`] naming the file, the station and what was found.

mod coarse;
mod cut;
mod driver;
pub mod ends;
pub mod features;
mod first_guide;
mod laws;
mod mesh;
mod options;
mod outcome;
mod output;
pub mod repair;
mod report;
mod samples;
pub mod section;
pub mod smooth;
pub mod topology;

pub use driver::fit_tube;
pub use mesh::{TubeMesh, MAX_MESH_BYTES};
pub use options::{FitOptions, StartEnd, Units};
pub use outcome::{
    EndKind, EndReport, FeatureKind, FeatureReport, FitReport, LeftOut, RepairReport,
    StationReport, TubeFit, WallReport,
};

/// Errors of the fit stage; each names the mesh file, and the station
/// (index along the guide from the start end, and its `t` in mm) when there
/// is one.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum FitError {
    /// The STL cannot be read, or holds no usable triangle.
    #[error("{file}: {reason}")]
    Stl {
        /// The mesh file.
        file: String,
        /// What is wrong.
        reason: String,
    },
    /// The STL file cannot be opened or read (an I/O failure: missing,
    /// permissions, disk), as opposed to [`FitError::Stl`], a file read
    /// whose content is wrong.
    #[error("{file}: {reason}")]
    StlIo {
        /// The mesh file.
        file: String,
        /// What failed (`cannot open: ...`, `cannot read: ...`).
        reason: String,
    },
    /// An option has an unusable value.
    #[error("{file}: fit option `{field}`: {reason}")]
    InvalidOption {
        /// The mesh file.
        file: String,
        /// The option's field name.
        field: String,
        /// What is wrong.
        reason: String,
    },
    /// The mesh is a closed surface with no open end and no flat end face:
    /// a blob, not a tube.
    #[error("{file}: not a tube: {found}")]
    ClosedSurface {
        /// The mesh file.
        file: String,
        /// What was found (vertices, faces).
        found: String,
    },
    /// The tube branches: it has more than two open ends, or a level set of
    /// the distance from the start end falls apart in several rings.
    #[error("{file}: not one tube: a branch at station {station} ({t_mm:.1} mm from the start end, near ({x:.1}, {y:.1}, {z:.1}) mm): {found}")]
    Branch {
        /// The mesh file.
        file: String,
        /// Index of the station (level set) where the tube splits.
        station: usize,
        /// Distance (mm, along the surface) from the start end.
        t_mm: f64,
        /// Where (mesh frame, mm): x.
        x: f64,
        /// y (mm).
        y: f64,
        /// z (mm).
        z: f64,
        /// What was found.
        found: String,
    },
    /// The mesh's surfaces do not make one tube (several separate surfaces,
    /// one open end only, skins that are not nested, too short).
    #[error("{file}: not a tube: {found}")]
    NotATube {
        /// The mesh file.
        file: String,
        /// What was found.
        found: String,
    },
    /// A section normal to the fitted guide is not near a circle.
    #[error(
        "{file}: station {station} (t = {t_mm:.2} mm): the section is not near a circle: {found}"
    )]
    SectionNotCircle {
        /// The mesh file.
        file: String,
        /// Index of the station from the start end.
        station: usize,
        /// Guide parameter of the station (mm).
        t_mm: f64,
        /// What was found (RMS, radius, angular gap).
        found: String,
    },
    /// The mesh's vertices are too far from the fitted tube.
    #[error("{file}: not a tube within max_rms_mm = {max_rms_mm} mm: the vertices are {rms_mm:.3} mm RMS from the fitted tube; worst at station {station} (t = {t_mm:.2} mm, {station_rms_mm:.3} mm RMS)")]
    Residual {
        /// The mesh file.
        file: String,
        /// RMS distance of the vertices to the fitted surface (mm).
        rms_mm: f64,
        /// The bound (mm).
        max_rms_mm: f64,
        /// The station of largest RMS.
        station: usize,
        /// Its guide parameter (mm).
        t_mm: f64,
        /// Its RMS (mm).
        station_rms_mm: f64,
    },
    /// The tube's start end is further from the substrate mesh than
    /// [`FitOptions::substrate_tolerance_mm`].
    #[error("{file}: the start end is {distance_mm:.3} mm from the substrate {substrate} (its rim's largest distance; at most {tolerance_mm} mm allowed, substrate_tolerance_mm): the tube does not stand on it")]
    SubstrateFar {
        /// The mesh file.
        file: String,
        /// The substrate's STL file.
        substrate: String,
        /// Largest distance of the start end's rim to the substrate (mm).
        distance_mm: f64,
        /// The bound (mm).
        tolerance_mm: f64,
    },
    /// The fit failed on a mesh whose size suggests another unit than
    /// [`FitOptions::units`]: the failure, with the likely unit.
    #[error("{source}\n  note: {hint}")]
    Units {
        /// The warning naming the likely unit.
        hint: String,
        /// Why the fit failed.
        source: Box<FitError>,
    },
    /// An end of the tube is none of those the fit knows: open,
    /// flat-capped, ring-capped (two skins), each cut square or obliquely
    /// ([`ends`]).
    #[error("{file}: the tube's {end} (station {station}, t = {t_mm:.2} mm) is not an open, flat-capped, ring-capped or obliquely cut end: {found}")]
    UnknownEnd {
        /// The mesh file.
        file: String,
        /// Which end: `start` (on the substrate) or `end`.
        end: String,
        /// The end's station (0 for the start).
        station: usize,
        /// Its guide parameter (mm from the start end).
        t_mm: f64,
        /// What was found.
        found: String,
    },
    /// A feature that is not tube (a collar, a flange, a block, a tab) on
    /// the mesh ([`features`]); [`FitOptions::trim`] fits the longest
    /// tubular stretch instead.
    #[error("{file}: not a tube: a {kind} at stations {station} to {last_station} ({t_mm:.2} to {t_end_mm:.2} mm from the start end along the guide): {size}")]
    Feature {
        /// The mesh file.
        file: String,
        /// What it looks like: collar, flange, block, tab.
        kind: &'static str,
        /// Its first station.
        station: usize,
        /// Its last station.
        last_station: usize,
        /// Where it begins (mm from the start end along the guide).
        t_mm: f64,
        /// Where it ends (mm from the start end along the guide).
        t_end_mm: f64,
        /// Its size (mm), where it is, how many others were found, and
        /// whether `trim` can cut it out.
        size: String,
    },
    /// The fit could not be computed (too few points at a station, a
    /// singular system, no convergence to a usable guide).
    #[error("{file}: station {station}: cannot fit: {reason}")]
    Degenerate {
        /// The mesh file.
        file: String,
        /// The station (0 when none applies).
        station: usize,
        /// What failed.
        reason: String,
    },
}
