//! Stage 7, the program's vocabulary: a [`Program`] of [`ProgramPoint`]s
//! (joints in the controller convention, rad; positions in the part frame,
//! mm) each with its [`ArcFlag`], the set-up before each bead
//! ([`BeadSetup`]), the home position, the files an emitter writes
//! ([`EmittedFile`]) and what every emitter and the checker ask of a
//! program's moves ([`joint_move_target`], [`segment_length_mm`], ...).

use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::math::{Point3, UnitVector3, Vector3};
use crate::program::{HomePosition, ProgramError, ProgramOptions};
use crate::robot::positioner::PositionerJoints;
use crate::robot::{CellLayout, Configuration, Joints, Vendor};

/// What a point is for: a bead point with its arc switching meaning, or a
/// transit point with the arc off (rs-opw's `PathFlags`: approach, trace,
/// retract) [SPEC §8].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ArcFlag {
    /// Clearance point before a bead: the bead's first point moved away from
    /// the part along the tool axis by [`ProgramOptions::clearance_mm`],
    /// same orientation; reached by a joint move with the arc off, then left
    /// by a linear move to the bead's first point. Not a bead point.
    Approach,
    /// First point of a bead: reached with the arc off, exact stop, the arc
    /// starts here.
    Start,
    /// Reached with the arc on (blended).
    On,
    /// Last point of a bead: reached with the arc on, exact stop, the arc
    /// stops here.
    End,
    /// Clearance point after a bead: its last point moved away from the part
    /// along the tool axis; reached by a linear move with the arc off. The
    /// arc-off transition to the next layer goes from here to the next
    /// [`ArcFlag::Approach`] by a joint move. Not a bead point.
    Retract,
    /// Via point of an arc-off transit that a single joint move from the
    /// retract point to the next approach point would take through the
    /// deposited wall: reached by a joint move with the arc off, after the
    /// retract point of the bead it leaves (the torch lifted far along the
    /// tool axis, the positioner turning alone with the torch clear, or the
    /// home position; [`build_program_with`](crate::program::build_program_with)).
    /// Its position is the torch tip's, part frame. Not a bead point.
    Transit,
}

impl ArcFlag {
    /// `true` for the points of a bead (start, on, end), `false` for the
    /// approach, retract and transit points.
    pub fn is_bead(&self) -> bool {
        matches!(self, ArcFlag::Start | ArcFlag::On | ArcFlag::End)
    }
}

/// One point of a program.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ProgramPoint {
    /// Layer index.
    pub layer: usize,
    /// The bead within the layer: 0 for its first (or only) bead, one more
    /// at each split at a corner ([`PathPointInput::bead`](crate::robot::trajectory::PathPointInput::bead)).
    #[serde(skip_serializing_if = "is_zero")]
    pub bead: usize,
    /// Point index within the layer (approach and retract points: the index
    /// of the bead point they are offset from).
    pub point: usize,
    /// Deposition point, part frame (mm); for approach and retract points
    /// the torch tip, `clearance` away from the part along the tool axis.
    pub position_mm: Point3,
    /// Tool axis, part frame (unit).
    pub tool_axis: UnitVector3,
    /// Free angle about the tool axis `R_Z` (rad).
    pub r_z: f64,
    /// Robot joints, controller convention (rad).
    pub joints: Joints,
    /// Positioner joints `[q7, q8]` (rad), torch-carried cell only.
    pub positioner: Option<PositionerJoints>,
    /// Travel speed of the deposition point relative to the part on the way
    /// to this point (mm/s); on a bead's first point, the travel speed of
    /// its first segment; on approach and retract points the linear speed
    /// of the moves into and out of the bead (approach point → first point,
    /// last point → retract point), [`ProgramOptions::approach_speed_mm_s`].
    pub speed_mm_s: f64,
    /// Wire feed speed on the way to this point with the arc on (mm/s);
    /// on a bead's first point the wire feed of its first segment (what
    /// the arc starts with); 0 on approach and retract points (arc off).
    pub wire_feed_mm_s: f64,
    /// Arc flag.
    pub arc: ArcFlag,
    /// This bead point is the via (circle) point of a circular move (FANUC
    /// `C`, KUKA `CIRC`, ABB `ArcC`/`MoveC`): the controller passes through
    /// its position on the circle from the previous point to the next one,
    /// which the move ends at and whose speed it carries
    /// ([`moves::thin_beads`](crate::program::moves::thin_beads)). Always an [`ArcFlag::On`] point between two
    /// bead points; `false` for every point of an unthinned program.
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub via: bool,
}

/// `true` for 0 (a layer's first bead is not written).
fn is_zero(k: &usize) -> bool {
    *k == 0
}

impl ProgramPoint {
    /// Whether `other` is a point of the same bead (same layer and bead).
    pub fn same_bead(&self, other: &ProgramPoint) -> bool {
        self.layer == other.layer && self.bead == other.bead
    }

    /// The bead's name in the programs' comments: the layer index, with
    /// `.k` for the `k`-th split bead of a layer split at its corners
    /// (`12`, `12.1`).
    pub fn bead_label(&self) -> String {
        if self.bead == 0 {
            self.layer.to_string()
        } else {
            format!("{}.{}", self.layer, self.bead)
        }
    }
}

/// A buildable program: points in path order, one bead per layer, or
/// more where a layer is split at its corners.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Program {
    /// Program name (controller-safe: letters, digits, `_`, starting with a letter).
    pub name: String,
    /// The cell the program is for.
    pub cell: CellLayout,
    /// The IK branch of every point.
    pub configuration: Configuration,
    /// The points.
    pub points: Vec<ProgramPoint>,
    /// Home position: the first and last motion (`None`: no home moves).
    pub home: Option<HomePosition>,
    /// What happens before each bead, one per bead in order (empty: nothing).
    pub bead_setup: Vec<BeadSetup>,
    /// The planned deposition points of every bead in order (part frame,
    /// mm) with their travel speeds and wire feeds (mm/s), before the beads
    /// were thinned into moves
    /// ([`moves::thin_beads`](crate::program::moves::thin_beads)): what a checker compares the moves with.
    pub planned: Vec<PlannedPoint>,
}

impl Program {
    /// Checks that every number an emitter writes is finite (positions,
    /// tool axes, `R_Z`, joints, positioner joints, speeds > 0, wire feeds
    /// at least 0): a hand-built program must not put `NaN` or `inf` into a controller file.
    ///
    /// # Errors
    /// [`ProgramError::Mismatch`] naming the first bad point and field.
    pub fn check_finite(&self) -> Result<(), ProgramError> {
        for (index, p) in self.points.iter().enumerate() {
            let bad = |field: &str| ProgramError::Mismatch {
                index,
                reason: format!(
                    "layer {}, point {}: `{field}` is not finite",
                    p.layer, p.point
                ),
            };
            if !p.position_mm.iter().all(|v| v.is_finite()) {
                return Err(bad("position_mm"));
            }
            if !p.tool_axis.iter().all(|v| v.is_finite()) {
                return Err(bad("tool_axis"));
            }
            if !p.r_z.is_finite() {
                return Err(bad("r_z"));
            }
            if !p.joints.iter().all(|v| v.is_finite()) {
                return Err(bad("joints"));
            }
            if p.positioner
                .is_some_and(|q| !q.iter().all(|v| v.is_finite()))
            {
                return Err(bad("positioner"));
            }
            if !(p.speed_mm_s.is_finite() && p.speed_mm_s > 0.0) {
                return Err(bad("speed_mm_s (must be finite and > 0)"));
            }
            if !(p.wire_feed_mm_s.is_finite() && p.wire_feed_mm_s >= 0.0) {
                return Err(bad("wire_feed_mm_s (must be finite and >= 0)"));
            }
        }
        Ok(())
    }

    /// The bead points (approach and retract points left out), in order.
    pub fn bead_points(&self) -> impl Iterator<Item = &ProgramPoint> {
        self.points.iter().filter(|p| p.arc.is_bead())
    }

    /// Sets the payload updates of a part-carried program (the robot
    /// carries the part as it grows): before bead 0 and before every
    /// `opts.payload_every_layers`-th bead, the substrate and fixture
    /// (`payload_base_kg` at `payload_base_cog_mm`, flange frame) plus the
    /// metal of the beads before it, bead `k` weighing `bead_mass_kg[k]`
    /// (kg) with its centre at the mean of its points (part frame, taken into
    /// the flange frame by the cell's `flange_from_part`). Nothing in a
    /// torch-carried cell (the positioner carries the part, not the arm) or
    /// with `payload_every_layers = 0`.
    ///
    /// # Errors
    /// [`ProgramError::Mismatch`] when `bead_mass_kg` has not one mass per
    /// bead or a mass is negative or not finite; [`ProgramError::InvalidOptions`]
    /// for bad options.
    pub fn set_payloads(
        &mut self,
        opts: &ProgramOptions,
        bead_mass_kg: &[f64],
    ) -> Result<(), ProgramError> {
        opts.validate()?;
        let beads = self.num_beads();
        if bead_mass_kg.len() != beads {
            return Err(ProgramError::Mismatch {
                index: bead_mass_kg.len().min(beads),
                reason: format!("{} bead masses for {beads} beads", bead_mass_kg.len()),
            });
        }
        if let Some(k) = bead_mass_kg
            .iter()
            .position(|m| !(m.is_finite() && *m >= 0.0))
        {
            return Err(ProgramError::Mismatch {
                index: k,
                reason: format!(
                    "bead {k}: mass {} kg is not finite and >= 0",
                    bead_mass_kg[k]
                ),
            });
        }
        let CellLayout::PartCarried(c) = &self.cell else {
            return Ok(());
        };
        if opts.payload_every_layers == 0 {
            return Ok(());
        }
        if self.bead_setup.len() != beads {
            self.bead_setup = self
                .points
                .iter()
                .filter(|p| p.arc == ArcFlag::Start)
                .map(|p| BeadSetup {
                    layer: p.layer,
                    payload: None,
                    dwell_s: 0.0,
                    wait_input: None,
                })
                .collect();
        }
        // the centre of each bead, flange frame
        let mut centres = Vec::with_capacity(beads);
        let (mut sum, mut n) = (Vector3::zeros(), 0usize);
        for p in self.bead_points() {
            sum += p.position_mm.coords;
            n += 1;
            if p.arc == ArcFlag::End {
                centres.push(c.flange_from_part * Point3::from(sum / n as f64));
                (sum, n) = (Vector3::zeros(), 0);
            }
        }
        let mut mass = opts.payload_base_kg;
        let mut moment = Vector3::from(opts.payload_base_cog_mm) * opts.payload_base_kg;
        let every = opts.payload_every_layers as usize;
        for (k, setup) in self.bead_setup.iter_mut().enumerate() {
            if k % every == 0 {
                let cog_mm = if mass > 0.0 {
                    Point3::from(moment / mass)
                } else {
                    Point3::from(opts.payload_base_cog_mm)
                };
                setup.payload = Some(Payload {
                    mass_kg: mass,
                    cog_mm,
                });
            }
            mass += bead_mass_kg[k];
            if let Some(centre) = centres.get(k) {
                moment += centre.coords * bead_mass_kg[k];
            }
        }
        Ok(())
    }

    /// Number of beads (arc starts).
    pub fn num_beads(&self) -> usize {
        self.points
            .iter()
            .filter(|p| p.arc == ArcFlag::Start)
            .count()
    }
}

/// The travel speed and the wire feed of one path point (mm/s): what the
/// move into the point runs at (SPEC §5: the bead's cross-section is
/// `A = pi d^2/4 * wire_feed / travel_speed`, eq. 1.1). The program builder
/// takes one per trajectory point ([`build_program`](crate::program::build_program)).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PointFeed {
    /// Travel speed of the deposition point over the part on the way to
    /// the point (mm/s, > 0).
    pub travel_speed_mm_s: f64,
    /// Wire feed speed on the way to the point (mm/s, > 0).
    pub wire_feed_mm_s: f64,
}

impl PointFeed {
    /// The same travel speed and wire feed (mm/s) at each of `n` points.
    pub fn constant(travel_speed_mm_s: f64, wire_feed_mm_s: f64, n: usize) -> Vec<PointFeed> {
        vec![
            PointFeed {
                travel_speed_mm_s,
                wire_feed_mm_s,
            };
            n
        ]
    }

    /// `wire_feed / travel_speed`, the ratio that sets the bead's
    /// cross-section (SPEC §5, eq. 1.1; dimensionless).
    pub fn ratio(&self) -> f64 {
        self.wire_feed_mm_s / self.travel_speed_mm_s
    }
}

/// A planned deposition point of a bead, before the beads were thinned
/// into moves: what a checker compares the moves with.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PlannedPoint {
    /// Deposition point, part frame (mm).
    pub position_mm: Point3,
    /// Travel speed and wire feed on the way to it (mm/s); on a bead's
    /// first point those of its first segment.
    pub feed: PointFeed,
}

/// The payload carried on the flange (part-carried cell): substrate,
/// fixture and the metal deposited so far.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Payload {
    /// Mass (kg).
    pub mass_kg: f64,
    /// Centre of gravity, flange frame (mm).
    pub cog_mm: Point3,
}

/// What a program does before a bead, from [`ProgramOptions`]: written
/// before the bead's approach move, in this order: payload, dwell, wait.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct BeadSetup {
    /// Layer of the bead.
    pub layer: usize,
    /// New payload before this bead (`None`: unchanged).
    pub payload: Option<Payload>,
    /// Dwell before this bead (s; 0: none). Always 0 on the first bead.
    pub dwell_s: f64,
    /// Digital input to wait for before this bead (`None`: no wait; always
    /// `None` on the first bead).
    pub wait_input: Option<u32>,
}

/// `true` when point `i` of `program` is reached by a joint move (FANUC
/// `J`, KUKA `PTP`, ABB `MoveAbsJ`): an approach point, a bead's first
/// point without one, or a transit's via point ([`ArcFlag::Transit`]);
/// every other point is reached by a linear move.
pub fn joint_move_target(program: &Program, i: usize) -> bool {
    program.points[i].arc == ArcFlag::Transit
        || opens_bead(
            i.checked_sub(1).map(|k| program.points[k].arc),
            program.points[i].arc,
        )
}

/// `true` when a point with flag `arc`, after one with flag `prev` (`None`
/// for the first point), opens a bead's block of points: an approach point,
/// or a bead's first point without one. Such a point is reached by a joint
/// move ([`joint_move_target`]) and a program is split only before one
/// ([`split::beads`](crate::program::split::beads)).
pub fn opens_bead(prev: Option<ArcFlag>, arc: ArcFlag) -> bool {
    match arc {
        ArcFlag::Approach => true,
        ArcFlag::Start => prev != Some(ArcFlag::Approach),
        _ => false,
    }
}

/// Smallest joint change (rad) counted as motion between two consecutive
/// points.
pub const JOINT_STILL_RAD: f64 = 1e-9;

/// `true` when any of `a` differs from `b` by more than [`JOINT_STILL_RAD`]
/// (joints or positioner joints, rad).
pub fn joints_move(a: &[f64], b: &[f64]) -> bool {
    a.iter()
        .zip(b)
        .any(|(x, y)| (x - y).abs() > JOINT_STILL_RAD)
}

/// Largest positioner motion over a segment still counted as a positioner
/// at rest (deg): above it, a torch-carried cell's segment is
/// [`positioner_moves`] and emitters time it instead of giving a TCP speed.
pub const POSITIONER_STILL_DEG: f64 = 0.01;

/// `true` when the positioner turns by more than [`POSITIONER_STILL_DEG`]
/// on either axis between point `i - 1` and point `i` of `program` (never
/// for `i = 0` or without a positioner). On such a segment the TCP's
/// travel in the robot frame is not the deposition point's travel over the
/// part (the part turns under a nearly still torch), so a TCP speed would
/// not give the planned travel speed.
pub fn positioner_moves(program: &Program, i: usize) -> bool {
    let Some(prev) = move_start(program, i).map(|k| &program.points[k]) else {
        return false;
    };
    match (program.points[i].positioner, prev.positioner) {
        (Some(a), Some(b)) => {
            (a[0] - b[0]).abs().max((a[1] - b[1]).abs()) > POSITIONER_STILL_DEG.to_radians()
        }
        _ => false,
    }
}

/// Length of the move into point `i` of `program`, the deposition point's
/// travel over the part (part frame, mm): the chord from the previous
/// point, or for a circular move the arc from [`move_start`] through the via
/// ([`arc_length`](crate::program::pose::arc_length)); 0 for `i = 0`.
pub fn segment_length_mm(program: &Program, i: usize) -> f64 {
    let Some(k) = move_start(program, i) else {
        return 0.0;
    };
    let end = &program.points[i].position_mm;
    let start = &program.points[k].position_mm;
    if k + 2 == i {
        let via = &program.points[k + 1].position_mm;
        crate::program::compress::arc_length(start, via, end)
    } else {
        (end - start).norm()
    }
}

/// Length of the path the deposition point travels over the part during
/// the move into point `i` of `program` as the controller interpolates it
/// (mm; [`pose::deposited_length_mm`](crate::program::pose::deposited_length_mm)),
/// in the part frame when `in_part` ([`pose::moves_in_part_frame`](crate::program::pose::moves_in_part_frame):
/// then [`segment_length_mm`]) else in the robot base frame; 0 for `i = 0`.
/// The length a timed move's time is the planned speed over.
pub fn deposited_length_mm(program: &Program, i: usize, in_part: bool) -> f64 {
    let Some(k) = move_start(program, i) else {
        return 0.0;
    };
    if in_part {
        return segment_length_mm(program, i);
    }
    fn at(p: &ProgramPoint) -> (&Joints, Option<PositionerJoints>) {
        (&p.joints, p.positioner)
    }
    let points = &program.points;
    crate::program::pose::deposited_length_mm(
        &program.cell,
        at(&points[k]),
        (k + 2 == i).then(|| at(&points[k + 1])),
        at(&points[i]),
        false,
    )
}

/// Where the move into point `i` of `program` starts: the point before it,
/// or the one before the via when point `i` ends a circular move
/// ([`ProgramPoint::via`]); `None` for `i = 0`.
pub fn move_start(program: &Program, i: usize) -> Option<usize> {
    let k = i.checked_sub(1)?;
    match (k.checked_sub(1), program.points[k].via) {
        (Some(before), true) => Some(before),
        _ => Some(k),
    }
}

/// Checks a controller program name: an ASCII letter first, then letters,
/// digits or `_`, at most 32 characters (RAPID identifiers take 32; FANUC
/// TP program names take up to 36 characters on recent controllers, 8 on
/// old ones, where shorter names are the user's choice; KRL names take 24,
/// which [`kuka::kuka_files`](crate::program::kuka::kuka_files) checks on top of this).
///
/// # Errors
/// [`ProgramError::InvalidOptions`] naming `name`.
pub fn check_name(name: &str) -> Result<(), ProgramError> {
    let ok = !name.is_empty()
        && name.len() <= 32
        && name.starts_with(|c: char| c.is_ascii_alphabetic())
        && name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_');
    if ok {
        Ok(())
    } else {
        Err(ProgramError::InvalidOptions {
            field: "name",
            value: name.to_string(),
            reason: "a letter, then letters, digits or `_`, at most 32 characters",
        })
    }
}

/// One emitted file: its name (with extension) and its content.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct EmittedFile {
    /// File name, e.g. `HEMI.ls`.
    pub name: String,
    /// Content.
    pub text: String,
}

/// Writes every file into `dir`, each atomically (temporary file, then rename).
///
/// # Errors
/// [`ProgramError::Io`] naming the file.
pub fn write_files(dir: &Path, files: &[EmittedFile]) -> Result<(), ProgramError> {
    for f in files {
        let path = dir.join(&f.name);
        crate::util::atomic::write_atomic(&path, |w| w.write_all(f.text.as_bytes())).map_err(
            |source| ProgramError::Io {
                path: path.display().to_string(),
                source: source.into(),
            },
        )?;
    }
    Ok(())
}

/// Renders a writer function into a `String`.
pub(crate) fn render(
    f: impl FnOnce(&mut dyn std::io::Write) -> std::io::Result<()>,
) -> Result<String, ProgramError> {
    let mut buf: Vec<u8> = Vec::new();
    f(&mut buf).map_err(|source| ProgramError::Io {
        path: "<memory>".into(),
        source: source.into(),
    })?;
    String::from_utf8(buf).map_err(|e| ProgramError::Io {
        path: "<memory>".into(),
        source: std::io::Error::other(e).into(),
    })
}

/// Checks that `cell`'s robot is a `vendor` arm, the only one whose joints
/// (controller convention, rad) and flange poses the `emitter` (e.g. `KUKA
/// KRL`) may write or read.
///
/// # Errors
/// [`ProgramError::VendorMismatch`] naming both vendors and the robot.
pub fn check_vendor(
    cell: &CellLayout,
    vendor: Vendor,
    emitter: &'static str,
) -> Result<(), ProgramError> {
    let robot = cell.robot();
    if robot.vendor == vendor {
        Ok(())
    } else {
        Err(ProgramError::VendorMismatch {
            emitter,
            emitter_vendor: vendor.display_name(),
            robot: robot.name.clone(),
            robot_vendor: robot.vendor.display_name(),
        })
    }
}
