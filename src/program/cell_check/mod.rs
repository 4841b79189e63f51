//! **The whole cell checked for collisions** along a program's motions.
//! Takes a [`Program`](crate::program::Program) (its approach, retract, transit and home moves), the
//! planned joints of every bead point (a [`JointTrajectory`](crate::robot::trajectory::JointTrajectory): what the
//! thinned moves stay within `path_tolerance_mm` of), the layers (part
//! frame, mm: the part's wall so far) and the cell's [`CellScene`] (robot
//! base frame, mm); returns a [`CellClearance`] (the closest approach per
//! layer and which pair) or refuses the program
//! ([`ProgramError::Collision`] naming the layer, the point or the move,
//! the two bodies and the depth).
//!
//! **Bodies** (robot base frame):
//! * the arm's links as capsules between its joint frame origins
//!   ([`arm_chain`](crate::robot::chain::arm_chain): the kinematic
//!   lengths of the preset): the J1 column (base origin → J2 height), the
//!   upper arm (J2 axis → J3 axis), the forearm (J3 offset point → the
//!   wrist unit) and the wrist (two capsules: the wrist unit behind the
//!   wrist centre → the wrist centre → the flange), with the radii and wrist-unit length of
//!   [`LinkRadii::for_robot`];
//! * the cell file's `[[keep_out]]` boxes (fixtures, fences, a second
//!   machine: axis-aligned, base frame);
//! * torch-carried cell: the positioner's table (a disc of
//!   [`TABLE_RADIUS_MM`] × [`TABLE_THICKNESS_MM`] under the table frame's
//!   origin) and its tilt body (a capsule along the tilt axis through the
//!   tilt centre C7, [`TILT_BODY_RADIUS_MM`]), both moving with the
//!   positioner's joints;
//! * the part: the layers deposited so far (the layer being deposited
//!   included) as the union of the convex hulls of bands of
//!   [`LAYERS_PER_BAND`] consecutive layers (each band also holding the
//!   previous band's last layer, so that the wall between them is inside a
//!   hull), on the flange (part-carried) or on the table (torch-carried).
//!
//! **Pairs** checked: link vs link two or more apart (column–forearm,
//! column–wrist, upper arm–wrist); every link vs every keep-out box, the
//! table and the tilt body; the part vs the column, upper arm and forearm
//! (part-carried: the part is on the flange, the wrist holds it) or vs the
//! upper arm, forearm and wrist (torch-carried); the part vs every keep-out
//! box. Not checked (see the crate README): the torch against the arm and
//! the table (the torch against the wall is [`super::transit`]'s check),
//! the positioner's base below the tilt body, the substrate beyond the
//! hull of the layers.
//!
//! **Drawn as checked**: the report's 3-D view ([`crate::report`]) draws
//! the arm's capsules, the table, the tilt body and the keep-out boxes from
//! this module's body outlines (the same capsules, poses and radii), and
//! highlights each layer's [`LayerCellClearance::closest_pair`].
//!
//! **Motions**: every bead point's planned joints; the linear moves into
//! and out of each bead, the arc-off joint moves between beads and the
//! home moves, interpolated linearly in joint space (exact for the joint
//! moves, FANUC `J`, KUKA `PTP`, ABB `MoveAbsJ`; within a fraction of a
//! millimetre for the short linear moves). Samples are taken **by swept
//! distance**: a bound on how far any point of the arm, the part or the
//! table can move between two samples (the sum of each axis's change times
//! the largest distance from that axis to a body it moves) is kept below
//! [`SAMPLE_STEP_MM`], so a contact between samples is missed by at most
//! half of that.
//!
//! **Culling**: each pair is first bounded below by the distance between
//! the bodies' bounding spheres and by its last exact distance less how far
//! each of the two bodies has moved since (each body's displacement from
//! sample to sample: its capsule's ends, or its centre and its turn times
//! its radius, summed like an odometer), and skipped when that bound
//! already exceeds the clearance and comes within [`REPORT_TOLERANCE_MM`]
//! of the layer's closest approach so far; parry's exact distance (GJK)
//! runs only on the pairs left. A body whose bound with a sphere holding
//! all the part's hulls (they share one pose) already passes that test is
//! culled with every hull at once: each hull's own bound is no lower, so
//! the pairs culled are the same. An arm link and a hull are also bounded
//! about the axis the part turns about (`PartAxis`: J6 part-carried, the
//! table's turn torch-carried): the distance between the boxes of the two
//! bodies in (distance from the axis, height along it), which does not
//! change as the part turns — the nozzle spinning a full turn a layer
//! under the fixed torch leaves its culling to this bound. The part's hulls are built from at most
//! [`HULL_POINTS_PER_LAYER`] points a layer, its distances lowered by the
//! largest chord deviation of a dropped point (conservative). So
//! `closest_approach_mm` is a distance measured at a sample, at most
//! [`REPORT_TOLERANCE_MM`] above the smallest over the samples.
use parry3d_f64::query;
use parry3d_f64::shape::{Capsule, ConvexPolyhedron, Cuboid, Cylinder, Shape, SupportMap};
use serde::{Deserialize, Serialize};

mod walk;
pub use walk::check_cell;

use crate::math::{Isometry3, Point3, Translation3, UnitQuaternion, Vector3};
use crate::optimise::LayerPoints;
use crate::program::ProgramError;
use crate::robot::chain::arm_chain_and_flange;
use crate::robot::{CellLayout, Joints, RobotModel};
use crate::toolaxis::collision::support::ClusteredHull;

/// Default `[program] collision_clearance_mm` (mm).
pub const DEFAULT_CLEARANCE_MM: f64 = 10.0;

/// Largest swept distance between two samples of a motion (mm).
pub const SAMPLE_STEP_MM: f64 = 5.0;

/// How far above the smallest distance over the samples a layer's reported
/// closest approach may be (mm): the culling's tolerance.
pub const REPORT_TOLERANCE_MM: f64 = 1.0;

/// Radius of the positioner's table (mm): not given by the thesis nor the
/// cell files; 250 mm, the size of a 500 mm face plate, is assumed.
pub const TABLE_RADIUS_MM: f64 = 250.0;
/// Thickness of the positioner's table below its face (mm), assumed.
pub const TABLE_THICKNESS_MM: f64 = 40.0;
/// Radius of the positioner's tilt body about its tilt axis (mm), assumed.
pub const TILT_BODY_RADIUS_MM: f64 = 80.0;

/// An axis-aligned box the arm, the part and the positioner must keep out
/// of: a cell file's `[[keep_out]]` table. Robot base frame (mm).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct KeepOut {
    /// Its name, as refusals name it (`fence`, `fixture`).
    pub name: String,
    /// Lower corner, robot base frame (mm).
    pub min_mm: [f64; 3],
    /// Upper corner, robot base frame (mm), above `min_mm` on every axis.
    pub max_mm: [f64; 3],
}

impl KeepOut {
    /// Checks the corners.
    ///
    /// # Errors
    /// A message naming the field when a corner is not finite or `max_mm`
    /// is not above `min_mm` on every axis.
    pub fn validate(&self) -> Result<(), String> {
        if !self
            .min_mm
            .iter()
            .chain(&self.max_mm)
            .all(|v| v.is_finite())
        {
            return Err(format!("keep_out `{}`: corners must be finite", self.name));
        }
        if (0..3).any(|i| self.max_mm[i] <= self.min_mm[i]) {
            return Err(format!(
                "keep_out `{}`: max_mm {:?} must be above min_mm {:?} on every axis",
                self.name, self.max_mm, self.min_mm
            ));
        }
        Ok(())
    }
}

/// Radii of the arm's link capsules (mm).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct LinkRadii {
    /// J1 column, base origin → J2 height (mm).
    pub column_mm: f64,
    /// Upper arm, J2 → J3 (mm).
    pub upper_arm_mm: f64,
    /// Forearm, J3 offset point → the wrist unit (mm).
    pub forearm_mm: f64,
    /// Wrist unit, from [`LinkRadii::wrist_unit_mm`] before the wrist
    /// centre on the forearm's axis through the wrist centre to the flange (mm).
    pub wrist_mm: f64,
    /// Length of the wrist unit (the J5 housing and the slimmer end of the
    /// J4 tube) behind the wrist centre, along the forearm (mm). The wrist
    /// is adjacent to the flange: it is not checked against the part the
    /// flange holds (part-carried) — the cell's J5 travel stands for that
    /// contact, as the thesis's ±135° does (table A.1 note 1: "to avoid
    /// substrate/robot collisions").
    pub wrist_unit_mm: f64,
}

impl LinkRadii {
    /// The radii for `robot` (mm). Half the widths of the links on the
    /// vendors' outline drawings, rounded down to 10 mm — **estimates**,
    /// read off the published dimension drawings of arms of this class
    /// (FANUC ArcMate 120iC / M-20iA, KUKA KR 16-2, ABB IRB 2600: upper
    /// arm about 200 mm wide, forearm about 160 mm at its J3 housing, the
    /// J4 tube and wrist unit about 120 mm wide over the last 250 mm behind
    /// the J5 axis),
    /// not measured; a cell whose arm is bulkier should say so with
    /// `[[keep_out]]` margins. The J1 column is the base housing above
    /// the floor (about 300 mm across).
    /// The three preset arms share one estimate, so `robot` does not choose
    /// among them yet.
    pub fn for_robot(_robot: &RobotModel) -> Self {
        Self {
            column_mm: 150.0,
            upper_arm_mm: 100.0,
            forearm_mm: 80.0,
            wrist_mm: 60.0,
            wrist_unit_mm: 250.0,
        }
    }
}

/// The static and moving obstacles of a cell, besides the arm (robot base
/// frame, mm).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct CellScene {
    /// Keep-out boxes (fixtures, fences).
    pub keep_out: Vec<KeepOut>,
    /// Clearance every pair must keep (mm, ≥ 0).
    pub clearance_mm: f64,
    /// Check the motions between beads (arc-off transits, home moves) as
    /// well as the beads with their approach and retract. `false` where
    /// the program's layers are a subsample of the build (a placement's
    /// screening): its transits join layers far apart, motions the build
    /// never makes.
    pub transits: bool,
}

/// The closest approach of one layer's motions.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LayerCellClearance {
    /// Layer index.
    pub layer: usize,
    /// Smallest distance between two bodies of a checked pair along the
    /// layer's motions (mm; negative: penetration depth). `inf` when no
    /// pair was measured (every one culled far away).
    pub closest_approach_mm: f64,
    /// The two bodies at that approach.
    pub closest_pair: Option<(String, String)>,
}

/// What [`check_cell`] measured.
#[derive(Debug, Clone, PartialEq, Default, Serialize)]
pub struct CellClearance {
    /// One entry per layer, in program order.
    pub layers: Vec<LayerCellClearance>,
    /// Samples (arm poses) checked.
    pub samples: usize,
    /// Pair distances computed exactly (the rest were culled).
    pub exact_queries: usize,
    /// Pairs culled by their bounding spheres.
    pub culled: usize,
}

/// A collision found by the whole-cell check, as the plan's summary
/// (`summary.json`'s `collision`) and the report write it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CollisionSummary {
    /// The layer the motion belongs to.
    pub layer: usize,
    /// The point (bead point, or the point a move goes to); `None` for a
    /// home move.
    pub point: Option<usize>,
    /// The motion: `bead`, `approach`, `retract`, `arc-off transit`, `home
    /// move`.
    pub motion: &'static str,
    /// The two bodies (arm links, `part`, the positioner's table or tilt
    /// body, a keep-out box by its name).
    pub bodies: [String; 2],
    /// Their distance (mm; negative: penetration).
    pub distance_mm: f64,
    /// The penetration depth (mm, ≥ 0).
    pub depth_mm: f64,
    /// The clearance asked for (mm).
    pub clearance_mm: f64,
}

impl CollisionSummary {
    /// The collision `e` names, if it is one
    /// ([`ProgramError::Collision`]).
    pub fn of(e: &ProgramError) -> Option<Self> {
        let ProgramError::Collision {
            layer,
            point,
            motion,
            body_a,
            body_b,
            distance_mm,
            clearance_mm,
        } = e
        else {
            return None;
        };
        Some(Self {
            layer: *layer,
            point: *point,
            motion,
            bodies: [body_a.clone(), body_b.clone()],
            distance_mm: *distance_mm,
            depth_mm: (-distance_mm).max(0.0),
            clearance_mm: *clearance_mm,
        })
    }
}

/// A body of the scene at one sample: its name, shape, pose (base frame)
/// and bounding sphere (centre, radius; base frame, mm).
struct Body<'a> {
    name: &'a str,
    shape: &'a dyn Shape,
    pose: Isometry3,
    centre: Point3,
    radius: f64,
    margin: f64,
    /// A capsule's segment ends (base frame), for its displacement.
    ends: Option<(Point3, Point3)>,
    /// A hull's vertices in clusters: its support function, faster than
    /// the shape's own and with the same answers.
    support: Option<&'a ClusteredHull>,
    /// An arm link's capsule, for a distance query on concrete types.
    capsule: Option<&'a Capsule>,
    /// A hull's extent about the part's turn axis ([`Local::axial`]).
    axial: Option<(f64, f64, f64)>,
}

/// What the culling remembers between samples: each body's last place and
/// odometer (mm), each pair's last exact distance and the two odometers then
/// (by the pair's index in the sample's list of pairs, the same list at
/// every sample with the same bodies).
///
/// The part's hulls share one pose: their odometers are brought up to date
/// only when a pair of them needs one (a remembered distance to bound, an
/// exact distance to remember), by the same sums in the same order as at
/// every sample, from the part's poses kept since the memory last forgot.
#[derive(Default)]
struct Memory {
    /// Which layer's hull the bodies are for (the part changes with it).
    layer: Option<usize>,
    /// How many bodies the sample has, the part's hulls included.
    count: usize,
    /// The bodies before the part's hulls: their places and odometers.
    places: Vec<(Point3, Point3, UnitQuaternion)>,
    odometer: Vec<f64>,
    pairs: Vec<Option<(f64, f64, f64)>>,
    /// The part's pose at each sample since the memory last forgot.
    part_poses: Vec<Isometry3>,
    /// The part's turn from the sample before to each (rad), once computed.
    part_turns: Vec<Option<f64>>,
    /// Per hull of the part: its odometer and the sample (into
    /// `part_poses`) it is up to date with.
    hull_odometer: Vec<(f64, usize)>,
    /// The sample's pairs before the part's hulls' (indices into its
    /// bodies): a buffer kept from sample to sample, rebuilt at each.
    pair_list: Vec<(usize, usize)>,
    /// Per body before the part's hulls, whether the hulls' common sphere
    /// culls its pairs with every hull (false for a body no hull pairs
    /// with; a buffer, as `pair_list`).
    far_from_part: Vec<bool>,
    /// Per body before the part's hulls, its capsule's extent about the
    /// part's turn axis and its radius where needed (a link the hulls pair
    /// with, not culled by their common sphere; a buffer, as `pair_list`).
    seg_axial: Vec<Option<(f64, f64, f64, f64)>>,
}

/// The part's hulls at one sample: the index of the first in the sample's
/// bodies (they follow every other body) and their local shapes.
#[derive(Clone, Copy)]
struct HullBodies<'h, 'c> {
    first: usize,
    hulls: &'h [&'c Local],
}

impl Memory {
    /// Moves each body's odometer on by its displacement since the last
    /// sample; forgets everything when the bodies are others. `bodies` are
    /// those before the part's hulls; `part` the hulls' pose and how many
    /// there are (their odometers move on when needed,
    /// [`Memory::odometer_of`]).
    fn advance(&mut self, layer: usize, bodies: &[Body], part: Option<(Isometry3, usize)>) {
        let hulls = part.map_or(0, |(_, n)| n);
        let count = bodies.len() + hulls;
        if self.layer != Some(layer) || self.count != count {
            self.layer = Some(layer);
            self.count = count;
            self.places = bodies.iter().map(place_of).collect();
            self.odometer = vec![0.0; bodies.len()];
            self.pairs.clear();
            self.part_poses.clear();
            self.part_turns.clear();
            self.part_poses.extend(part.map(|(pose, _)| pose));
            self.part_turns.extend(part.map(|_| Some(0.0)));
            self.hull_odometer = vec![(0.0, 0); hulls];
            return;
        }
        // bodies with the same turn share its angle
        let mut turn: Option<([u64; 4], [u64; 4], f64)> = None;
        for (i, b) in bodies.iter().enumerate() {
            let now = place_of(b);
            let was = self.places[i];
            let moved = match b.ends {
                Some(_) => (now.0 - was.0).norm().max((now.1 - was.1).norm()),
                None => {
                    let key = (bits(&was.2), bits(&now.2));
                    let angle = match turn {
                        Some((w, n, a)) if (w, n) == key => a,
                        _ => {
                            let a = was.2.angle_to(&now.2);
                            turn = Some((key.0, key.1, a));
                            a
                        }
                    };
                    (now.0 - was.0).norm() + b.radius * angle
                }
            };
            self.odometer[i] += moved;
            self.places[i] = now;
        }
        if let Some((pose, _)) = part {
            self.part_poses.push(pose);
            self.part_turns.push(None);
        }
    }

    /// Body `i`'s odometer at this sample (mm); a hull's brought up to
    /// date: at each sample since it last was, its centre's displacement
    /// plus its radius times the part's turn, as [`Memory::advance`] adds
    /// them for the other bodies.
    fn odometer_of(&mut self, i: usize, part: HullBodies) -> f64 {
        let Some(h) = i.checked_sub(part.first) else {
            return self.odometer[i];
        };
        let hull = part.hulls[h];
        let (mut odometer, since) = self.hull_odometer[h];
        let now_at = self.part_poses.len().saturating_sub(1);
        if since < now_at {
            let mut was = self.part_poses[since] * hull.centre;
            for s in since + 1..=now_at {
                let now = self.part_poses[s] * hull.centre;
                let angle = match self.part_turns[s] {
                    Some(a) => a,
                    None => {
                        let a = self.part_poses[s - 1]
                            .rotation
                            .angle_to(&self.part_poses[s].rotation);
                        self.part_turns[s] = Some(a);
                        a
                    }
                };
                odometer += (now - was).norm() + hull.radius * angle;
                was = now;
            }
            self.hull_odometer[h] = (odometer, now_at);
        }
        odometer
    }

    /// Pair `k` (bodies `i`, `j`): its last exact distance less how far its
    /// bodies moved since.
    fn lower_bound(&mut self, k: usize, i: usize, j: usize, part: HullBodies) -> f64 {
        let Some((d, oi, oj)) = self.pairs.get(k).copied().flatten() else {
            return f64::NEG_INFINITY;
        };
        let (ni, nj) = (self.odometer_of(i, part), self.odometer_of(j, part));
        d - (ni - oi) - (nj - oj)
    }

    fn remember(&mut self, k: usize, i: usize, j: usize, d: f64, part: HullBodies) {
        let (oi, oj) = (self.odometer_of(i, part), self.odometer_of(j, part));
        if self.pairs.len() <= k {
            self.pairs.resize(k + 1, None);
        }
        self.pairs[k] = Some((d, oi, oj));
    }
}

/// A rotation's components, bit for bit.
fn bits(q: &UnitQuaternion) -> [u64; 4] {
    std::array::from_fn(|i| q.coords[i].to_bits())
}

/// A body's place: a capsule's ends, else its centre (twice) and rotation.
fn place_of(b: &Body) -> (Point3, Point3, UnitQuaternion) {
    match b.ends {
        Some((a, e)) => (a, e, UnitQuaternion::identity()),
        None => (b.centre, b.centre, b.pose.rotation),
    }
}

const COLUMN: &str = "J1 column";
const UPPER_ARM: &str = "upper arm";
const FOREARM: &str = "forearm";
const WRIST: &str = "wrist";
const TABLE: &str = "positioner table";
const TILT: &str = "positioner tilt body";
const PART: &str = "part";

/// The arm's four link capsules at `q` (base frame): the forearm stops
/// [`LinkRadii::wrist_unit_mm`] before the wrist centre, where the wrist
/// unit (J5 housing) begins, which is the wrist capsule up to the flange.
fn links(robot: &RobotModel, r: &LinkRadii, q: &Joints) -> [(&'static str, Capsule); 5] {
    links_and_flange(robot, r, q).0
}

/// [`links`] and the flange's pose at `q` (`base_from_flange`, base frame,
/// mm; [`RobotModel::flange_pose`]'s to the bit) from one forward
/// kinematics.
fn links_and_flange(
    robot: &RobotModel,
    r: &LinkRadii,
    q: &Joints,
) -> ([(&'static str, Capsule); 5], Isometry3) {
    let (c, base_from_flange) = arm_chain_and_flange(robot, q);
    let along = c[5] - c[4];
    let len = along.norm();
    let cut = if len > 0.0 {
        c[5] - along * (r.wrist_unit_mm.min(len) / len)
    } else {
        c[5]
    };
    (
        [
            (COLUMN, Capsule::new(c[0], c[1], r.column_mm)),
            (UPPER_ARM, Capsule::new(c[2], c[3], r.upper_arm_mm)),
            (FOREARM, Capsule::new(c[4], cut, r.forearm_mm)),
            (WRIST, Capsule::new(cut, c[5], r.wrist_mm)),
            (WRIST, Capsule::new(c[5], c[6], r.wrist_mm)),
        ],
        base_from_flange,
    )
}

/// The positioner's table as the check models it: a cylinder of
/// [`TABLE_RADIUS_MM`] × [`TABLE_THICKNESS_MM`] (parry's axis is its local
/// Y; [`positioner_poses`] turns it onto the table's Z).
fn table_cylinder() -> Cylinder {
    Cylinder::new(0.5 * TABLE_THICKNESS_MM, TABLE_RADIUS_MM)
}

/// The positioner's tilt body as the check models it: a capsule of
/// [`TILT_BODY_RADIUS_MM`] along the tilt axis (the positioner frame's Y),
/// ±[`TABLE_RADIUS_MM`] about the tilt centre C7 (positioner frame).
fn tilt_capsule() -> Capsule {
    Capsule::new(
        Point3::new(0.0, -TABLE_RADIUS_MM, 0.0),
        Point3::new(0.0, TABLE_RADIUS_MM, 0.0),
        TILT_BODY_RADIUS_MM,
    )
}

/// Poses (robot base frame) of the table's cylinder ([`table_cylinder`])
/// and of the tilt body ([`tilt_capsule`]) at positioner joints `qp` (rad):
/// the table's cylinder below the table frame's origin, its axis on the
/// table's Z; the tilt body on the positioner frame (it is round about the
/// tilt axis, so `q7` does not move it).
fn positioner_poses(c: &crate::robot::TorchCarriedCell, qp: &[f64; 2]) -> (Isometry3, Isometry3) {
    let base_from_table = c.base_from_positioner * c.positioner.positioner_from_table(qp);
    let table_pose = base_from_table
        * Isometry3::translation(0.0, 0.0, -0.5 * TABLE_THICKNESS_MM)
        * Isometry3::rotation(Vector3::x() * std::f64::consts::FRAC_PI_2);
    (table_pose, c.base_from_positioner)
}

/// What kind of solid a [`BodyOutline`] is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub(crate) enum OutlineKind {
    /// A capsule: the segment `a`–`b` swept by a ball of `radius_mm`.
    Capsule,
    /// A cylinder (flat ends) of `radius_mm` about the axis `a`–`b`.
    Cylinder,
    /// An axis-aligned box, lower corner `a`, upper corner `b`.
    Box,
}

/// One body of the whole-cell check as the check models it, for drawing
/// (the report's 3-D view): robot base frame, mm.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct BodyOutline {
    /// The body's name, as [`LayerCellClearance::closest_pair`] and
    /// [`ProgramError::Collision`] name it.
    pub name: String,
    /// Its solid.
    pub kind: OutlineKind,
    /// First segment end (capsule, cylinder) or lower corner (box), base frame (mm).
    pub a: Point3,
    /// Second segment end or upper corner, base frame (mm).
    pub b: Point3,
    /// Radius (mm; 0 for a box).
    pub radius_mm: f64,
}

/// The arm's link capsules at controller joints `q` (rad), as [`check_cell`]
/// checks them (robot base frame, mm): the J1 column, upper arm, forearm
/// and the wrist's two capsules, with [`LinkRadii::for_robot`].
pub(crate) fn arm_outlines(robot: &RobotModel, q: &Joints) -> Vec<BodyOutline> {
    links(robot, &LinkRadii::for_robot(robot), q)
        .iter()
        .map(|(name, c)| BodyOutline {
            name: (*name).to_string(),
            kind: OutlineKind::Capsule,
            a: c.segment.a,
            b: c.segment.b,
            radius_mm: c.radius,
        })
        .collect()
}

/// The positioner's table (a cylinder, moving with `qp`, rad) and its tilt
/// body (a capsule, fixed) as [`check_cell`] checks them (robot base
/// frame, mm).
pub(crate) fn positioner_outlines(
    c: &crate::robot::TorchCarriedCell,
    qp: &[f64; 2],
) -> [BodyOutline; 2] {
    let (table_pose, tilt_pose) = positioner_poses(c, qp);
    let table = table_cylinder();
    let tilt = tilt_capsule();
    // the cylinder's local axis is Y
    let h = table.half_height;
    [
        BodyOutline {
            name: TABLE.to_string(),
            kind: OutlineKind::Cylinder,
            a: table_pose * Point3::new(0.0, -h, 0.0),
            b: table_pose * Point3::new(0.0, h, 0.0),
            radius_mm: table.radius,
        },
        BodyOutline {
            name: TILT.to_string(),
            kind: OutlineKind::Capsule,
            a: tilt_pose * tilt.segment.a,
            b: tilt_pose * tilt.segment.b,
            radius_mm: tilt.radius,
        },
    ]
}

/// The cell's keep-out boxes as [`check_cell`] checks them (robot base
/// frame, mm).
pub(crate) fn keep_out_outlines(keep_out: &[KeepOut]) -> Vec<BodyOutline> {
    keep_out
        .iter()
        .map(|k| BodyOutline {
            name: k.name.clone(),
            kind: OutlineKind::Box,
            a: Point3::from(k.min_mm),
            b: Point3::from(k.max_mm),
            radius_mm: 0.0,
        })
        .collect()
}

/// The name [`check_cell`] gives the part's hulls.
pub(crate) const PART_NAME: &str = PART;

fn capsule_body<'a>(name: &'a str, c: &'a Capsule) -> Body<'a> {
    let centre = Point3::from((c.segment.a.coords + c.segment.b.coords) * 0.5);
    Body {
        name,
        shape: c,
        pose: Isometry3::identity(),
        centre,
        radius: 0.5 * (c.segment.b - c.segment.a).norm() + c.radius,
        margin: 0.0,
        ends: Some((c.segment.a, c.segment.b)),
        support: None,
        capsule: Some(c),
        axial: None,
    }
}

/// A convex shape in its local frame with its bounding sphere there.
struct Local {
    shape: Box<dyn Shape>,
    centre: Point3,
    radius: f64,
    /// Lowered from every distance to it (mm): the part's thinning.
    margin: f64,
    /// A hull's clustered vertices ([`ClusteredHull`]).
    support: Option<ClusteredHull>,
    /// A hull's extent about the part's turn axis ([`PartAxis`]): the
    /// largest distance of a vertex from the axis and the smallest and
    /// largest height along it (mm).
    axial: Option<(f64, f64, f64)>,
}

impl Local {
    fn at(&self, name: &'static str, pose: Isometry3) -> Body<'_> {
        Body {
            name,
            shape: self.shape.as_ref(),
            pose,
            centre: pose * self.centre,
            radius: self.radius,
            margin: self.margin,
            ends: None,
            support: self.support.as_ref(),
            capsule: None,
            axial: self.axial,
        }
    }
}

/// The hull of `points` (part frame) with its bounding sphere; `None` for
/// a degenerate set (fewer than four points off a plane).
fn hull(points: &[Point3]) -> Option<Local> {
    let h = ConvexPolyhedron::from_convex_hull(points)?;
    let support = Some(ClusteredHull::new(&h));
    let n = h.points().len().max(1) as f64;
    let centre = Point3::from(h.points().iter().map(|p| p.coords).sum::<Vector3>() / n);
    let radius = h
        .points()
        .iter()
        .map(|p| (p - centre).norm())
        .fold(0.0, f64::max);
    Some(Local {
        shape: Box::new(h),
        centre,
        radius,
        margin: 0.0,
        support,
        axial: None,
    })
}

/// Most points of a layer that enter the part's hull; a longer layer keeps
/// every `k`-th point (and its last), and the hull's distances are lowered
/// by the largest distance of a dropped point from the chord between its
/// kept neighbours, so that the check stays conservative.
pub const HULL_POINTS_PER_LAYER: usize = 24;

/// A layer's points thinned to at most [`HULL_POINTS_PER_LAYER`], and the
/// largest distance of a dropped point from its kept neighbours' chord (mm).
fn thin_layer(points: &[Point3]) -> (Vec<Point3>, f64) {
    let n = points.len();
    if n <= HULL_POINTS_PER_LAYER {
        return (points.to_vec(), 0.0);
    }
    let k = n.div_ceil(HULL_POINTS_PER_LAYER);
    let mut kept: Vec<usize> = (0..n).step_by(k).collect();
    if kept.last() != Some(&(n - 1)) {
        kept.push(n - 1);
    }
    let mut margin: f64 = 0.0;
    for w in kept.windows(2) {
        let (a, b) = (points[w[0]], points[w[1]]);
        let ab = b - a;
        let len2 = ab.norm_squared();
        for p in &points[w[0] + 1..w[1]] {
            let t = if len2 > 0.0 {
                ((p - a).dot(&ab) / len2).clamp(0.0, 1.0)
            } else {
                0.0
            };
            margin = margin.max((p - (a + ab * t)).norm());
        }
    }
    (kept.into_iter().map(|i| points[i]).collect(), margin)
}

/// Layers per band of the part's model: the wall so far is the union of
/// the convex hulls of bands of this many consecutive layers (tight on bent
/// tubes, where one hull of the whole wall would fill the bend).
pub const LAYERS_PER_BAND: usize = 4;

/// The hull of `pts` (part frame), or of a thin slab over them when they are
/// flat (a first layer): lifted by 0.01 mm.
fn hull_or_slab(pts: &[Point3], margin: f64) -> Option<Local> {
    let mut h = hull(pts);
    if h.is_none() {
        let lifted: Vec<Point3> = pts
            .iter()
            .map(|p| p + Vector3::z() * 0.01)
            .chain(pts.iter().copied())
            .collect();
        h = hull(&lifted);
    }
    if let Some(local) = &mut h {
        local.margin = margin;
    }
    h
}

/// The part's model per layer (part frame): the complete bands of
/// [`LAYERS_PER_BAND`] layers before it, each one convex hull, and the hull
/// of its own band up to and including it; each from the layers' points
/// thinned by [`thin_layer`], with the margin (mm) its distances are
/// lowered by, and its extent about `axis` ([`PartAxis::extent`]).
///
/// A band's hull is the hull of its last layer's own band: each hull is
/// built once, and the layers' hulls are built in parallel.
struct WallBands {
    /// Per layer, the hull of its band up to and including it.
    own: Vec<Option<Local>>,
    /// The layers whose hull closes a band, in order.
    closing: Vec<usize>,
    /// Per layer, how many bands are complete before it.
    before: Vec<usize>,
}

impl WallBands {
    fn new(layers: &[LayerPoints], axis: &PartAxis) -> Self {
        use rayon::prelude::*;
        let mut inputs: Vec<(Vec<Point3>, f64)> = Vec::with_capacity(layers.len());
        let mut ends_band: Vec<bool> = Vec::with_capacity(layers.len());
        let mut pts: Vec<Point3> = Vec::new();
        let mut margin: f64 = 0.0;
        for (k, l) in layers.iter().enumerate() {
            let raw: Vec<Point3> = l.points.iter().map(|p| p.position_mm).collect();
            let (thin, m) = thin_layer(&raw);
            margin = margin.max(m);
            pts.extend(thin.iter().copied());
            inputs.push((pts.clone(), margin));
            let closes = (k + 1) % LAYERS_PER_BAND == 0;
            ends_band.push(closes);
            if closes {
                // the next band starts from this layer, so that the wall
                // between two bands' layers is inside a hull
                pts = thin;
                margin = m;
            }
        }
        let own: Vec<Option<Local>> = inputs
            .par_iter()
            .map(|(pts, margin)| {
                let mut h = hull_or_slab(pts, *margin)?;
                h.axial = h
                    .shape
                    .as_shape::<ConvexPolyhedron>()
                    .and_then(|c| axis.extent(c.points()));
                Some(h)
            })
            .collect();
        let mut closing = Vec::new();
        let mut before = Vec::with_capacity(layers.len());
        for (k, h) in own.iter().enumerate() {
            before.push(closing.len());
            if ends_band[k] && h.is_some() {
                closing.push(k);
            }
        }
        Self {
            own,
            closing,
            before,
        }
    }

    /// The hulls of the layer at index `k` (into the layers): the complete
    /// bands before it, then its own band (none for an index out of range).
    fn hulls_of(&self, k: usize) -> Vec<&Local> {
        let Some(&before) = self.before.get(k) else {
            return Vec::new();
        };
        self.closing[..before]
            .iter()
            .filter_map(|&c| self.own[c].as_ref())
            .chain(self.own[k].as_ref())
            .collect()
    }
}

/// The part's model a layer's motions are checked against: its hulls
/// (part frame, one pose) and a sphere holding their bounding spheres.
pub(super) struct PartModel<'c> {
    hulls: Vec<&'c Local>,
    /// `None` for fewer than two hulls (nothing to gain).
    sphere: Option<HullsSphere>,
}

impl<'c> PartModel<'c> {
    /// The model of `hulls` with their common sphere.
    fn new(hulls: Vec<&'c Local>) -> Self {
        let sphere = (hulls.len() >= 2).then(|| {
            let n = hulls.len() as f64;
            let centre = Point3::from(hulls.iter().map(|h| h.centre.coords).sum::<Vector3>() / n);
            let radius = hulls
                .iter()
                .map(|h| (h.centre - centre).norm() + h.radius)
                .fold(0.0, f64::max);
            let margin = hulls.iter().map(|h| h.margin).fold(0.0, f64::max);
            HullsSphere {
                centre,
                radius,
                margin,
            }
        });
        Self { hulls, sphere }
    }
}

/// A sphere holding the bounding spheres of a layer's hulls (part frame,
/// mm) and the largest of their margins (mm).
#[derive(Clone, Copy)]
struct HullsSphere {
    centre: Point3,
    radius: f64,
    margin: f64,
}

/// What [`HullsSphere::lower_bound`] leaves below every hull's own sphere
/// bound (mm): far above the rounding of either (some 1e-12 mm at
/// metres), so that a pair culled by the common sphere is one its own
/// bound culls as well.
const HULLS_SPHERE_SLACK_MM: f64 = 1e-6;

impl HullsSphere {
    /// A lower bound of the sphere bound of `a` with each of the hulls
    /// placed at a pose (`|centre_a - centre_h| - r_a - r_h - margin_h`):
    /// each hull's sphere lies in this one. `centre`: this sphere's centre
    /// at that pose (base frame).
    fn lower_bound(&self, a: &Body, centre: &Point3) -> f64 {
        (a.centre - centre).norm()
            - a.radius
            - self.radius
            - a.margin
            - self.margin
            - HULLS_SPHERE_SLACK_MM
    }
}

/// The refusal or the closest approach of one pair.
struct Closest {
    distance_mm: f64,
    pair: Option<(String, String)>,
}

/// One sample of a motion: joints, positioner joints, and where it is.
#[derive(Clone, Copy)]
struct Sample<'a> {
    q: &'a Joints,
    qp: Option<[f64; 2]>,
}

/// The checker: the scene's fixed shapes and the per-layer hulls.
struct Checker<'a> {
    cell: &'a CellLayout,
    radii: LinkRadii,
    keep_out: Vec<Local>,
    keep_out_names: Vec<&'a str>,
    table: Local,
    tilt: Local,
    /// The part's hulls per layer.
    wall: WallBands,
    clearance: f64,
    /// Per axis (the arm's six, the positioner's two), the largest distance
    /// from the axis to a point of a body it moves (mm).
    lever: [f64; 8],
    /// The axis the part turns about (part frame).
    axis: PartAxis,
}

/// The axis the part turns about while it is built, part frame: the
/// flange's Z (J6) where the arm carries it, the table's Z (the turn)
/// where the positioner does. Distances from it and heights along it are
/// the same wherever the part has turned about it.
#[derive(Clone, Copy)]
struct PartAxis {
    origin: Point3,
    dir: Vector3,
}

impl PartAxis {
    fn of(cell: &CellLayout) -> Self {
        let part_from_axis = match cell {
            CellLayout::PartCarried(c) => c.flange_from_part.inverse(),
            CellLayout::TorchCarried(c) => c.table_from_part.inverse(),
        };
        Self {
            origin: part_from_axis * Point3::origin(),
            dir: part_from_axis * Vector3::z(),
        }
    }

    /// Height along the axis and the radial part of `p` (part frame).
    fn split(&self, p: &Point3) -> (f64, Vector3) {
        let v = p - self.origin;
        let h = v.dot(&self.dir);
        (h, v - self.dir * h)
    }

    /// A hull's extent: largest distance of a vertex from the axis, lowest
    /// and highest height (mm).
    fn extent(&self, points: &[Point3]) -> Option<(f64, f64, f64)> {
        let mut out: Option<(f64, f64, f64)> = None;
        for p in points {
            let (h, r) = self.split(p);
            let r = r.norm();
            out = Some(match out {
                None => (r, h, h),
                Some((rm, lo, hi)) => (rm.max(r), lo.min(h), hi.max(h)),
            });
        }
        out
    }

    /// A segment's smallest distance from the axis and its lowest and
    /// highest height (mm; its ends in the part frame).
    fn segment(&self, a: &Point3, b: &Point3) -> (f64, f64, f64) {
        let (ha, ra) = self.split(a);
        let (hb, rb) = self.split(b);
        let d = rb - ra;
        let l2 = d.norm_squared();
        let t = if l2 > 0.0 {
            (-ra.dot(&d) / l2).clamp(0.0, 1.0)
        } else {
            0.0
        };
        ((ra + d * t).norm(), ha.min(hb), ha.max(hb))
    }
}

/// What the axial bound leaves below the distance it bounds (mm): far
/// above its rounding.
const AXIAL_SLACK_MM: f64 = 1e-6;

/// A lower bound of the distance between a capsule (its segment's
/// [`PartAxis::segment`] and radius) and a hull (its
/// [`PartAxis::extent`] and margin): the map of a point to its distance
/// from the axis and its height moves no point apart, so the distance is
/// at least that of the two sets' boxes in those two coordinates.
fn axial_bound(seg: (f64, f64, f64), radius: f64, hull: (f64, f64, f64), margin: f64) -> f64 {
    let dr = (seg.0 - hull.0).max(0.0);
    let dh = (seg.1 - hull.2).max(hull.1 - seg.2).max(0.0);
    (dr * dr + dh * dh).sqrt() - radius - margin - AXIAL_SLACK_MM
}

/// Where a sample is, for a refusal.
#[derive(Clone)]
struct Place {
    layer: usize,
    point: Option<usize>,
    motion: &'static str,
}

impl<'a> Checker<'a> {
    fn new(cell: &'a CellLayout, scene: &'a CellScene, layers: &[LayerPoints]) -> Self {
        let keep_out = scene
            .keep_out
            .iter()
            .map(|k| {
                let half = Vector3::from(std::array::from_fn::<f64, 3, _>(|i| {
                    0.5 * (k.max_mm[i] - k.min_mm[i]).max(0.0)
                }));
                let centre = Point3::from(std::array::from_fn::<f64, 3, _>(|i| {
                    0.5 * (k.max_mm[i] + k.min_mm[i])
                }));
                // the cuboid is centred on its local origin: the pose puts
                // it at `centre`; the sphere is kept in the local frame
                Local {
                    shape: Box::new(Cuboid::new(half)),
                    centre: Point3::from(centre.coords),
                    radius: half.norm(),
                    margin: 0.0,
                    support: None,
                    axial: None,
                }
            })
            .collect();
        let g = &cell.robot().geometry;
        // how far from each axis a point of a body it moves can be: the
        // links beyond it plus what the flange carries (the part, or the
        // torch), or for the positioner the table and the part on it
        let part_extent = layers
            .iter()
            .flat_map(|l| &l.points)
            .map(|p| p.position_mm.coords.norm())
            .fold(0.0, f64::max);
        let carried = match cell {
            CellLayout::PartCarried(c) => {
                c.flange_from_part.translation.vector.norm() + part_extent
            }
            CellLayout::TorchCarried(c) => c.flange_from_tcp.translation.vector.norm(),
        };
        let wrist = g.wrist_to_flange_mm.abs() + carried;
        let fore = g.elbow_offset_mm.abs() + g.forearm_mm.abs() + wrist;
        let upper = g.upper_arm_mm.abs() + fore;
        let reach = g.shoulder_offset_mm.abs() + g.lateral_offset_mm.abs() + upper;
        let (tilt_arm, turn_arm) = match cell {
            CellLayout::TorchCarried(c) => {
                let table_to_part = c.table_from_part.translation.vector.norm() + part_extent;
                let turn = TABLE_RADIUS_MM.max(table_to_part) + TABLE_THICKNESS_MM;
                (
                    c.positioner.tilt_to_table_mm.abs() + turn + TILT_BODY_RADIUS_MM,
                    turn,
                )
            }
            CellLayout::PartCarried(_) => (0.0, 0.0),
        };
        let lever = [reach, upper, fore, wrist, wrist, wrist, tilt_arm, turn_arm];
        // the table: a cylinder (parry's axis is Y) turned onto Z, below
        // the table frame's origin
        let half_t = 0.5 * TABLE_THICKNESS_MM;
        let table = Local {
            shape: Box::new(table_cylinder()),
            centre: Point3::origin(),
            radius: (TABLE_RADIUS_MM.powi(2) + half_t.powi(2)).sqrt(),
            margin: 0.0,
            support: None,
            axial: None,
        };
        let tilt = Local {
            shape: Box::new(tilt_capsule()),
            centre: Point3::origin(),
            radius: TABLE_RADIUS_MM + TILT_BODY_RADIUS_MM,
            margin: 0.0,
            support: None,
            axial: None,
        };
        let axis = PartAxis::of(cell);
        let wall = WallBands::new(layers, &axis);
        Self {
            cell,
            radii: LinkRadii::for_robot(cell.robot()),
            keep_out,
            keep_out_names: scene.keep_out.iter().map(|k| k.name.as_str()).collect(),
            table,
            tilt,
            wall,
            clearance: scene.clearance_mm,
            lever,
            axis,
        }
    }

    /// Largest distance any point of the arm (or the part) moves between
    /// two samples (mm, a bound).
    fn swept_mm(&self, a: &Sample, b: &Sample) -> f64 {
        let arm: f64 = (0..6)
            .map(|j| (a.q[j] - b.q[j]).abs() * self.lever[j])
            .sum();
        let pos = match (a.qp, b.qp) {
            (Some(x), Some(y)) => {
                (x[0] - y[0]).abs() * self.lever[6] + (x[1] - y[1]).abs() * self.lever[7]
            }
            _ => 0.0,
        };
        arm + pos
    }

    /// Checks one sample; updates `best`; the first pair closer than the
    /// clearance is returned.
    ///
    /// The pairs, in order: link with link, each link with each keep-out
    /// box, each link with the table and the tilt body, then per hull of
    /// the part its links and the keep-out boxes. A hull's body is placed
    /// only where a pair of it is not culled by the hulls' common sphere.
    fn check(
        &self,
        s: &Sample,
        (layer, part): (usize, &PartModel),
        best: &mut Closest,
        memory: &mut Memory,
        stats: &mut CellClearance,
    ) -> Option<(String, String, f64)> {
        stats.samples += 1;
        let robot = self.cell.robot();
        let (capsules, base_from_flange) = links_and_flange(robot, &self.radii, s.q);
        let mut all: Vec<Body> = Vec::with_capacity(capsules.len() + self.keep_out.len() + 2);
        all.extend(capsules.iter().map(|(n, c)| capsule_body(n, c)));
        let first_other = all.len();
        for (k, name) in self.keep_out.iter().zip(&self.keep_out_names) {
            all.push(Body {
                name,
                shape: k.shape.as_ref(),
                pose: Isometry3::from_parts(
                    Translation3::from(k.centre.coords),
                    UnitQuaternion::identity(),
                ),
                centre: k.centre,
                radius: k.radius,
                margin: 0.0,
                ends: None,
                support: None,
                capsule: None,
                axial: None,
            });
        }
        // indices into `all` (the list kept from sample to sample)
        let mut pairs = std::mem::take(&mut memory.pair_list);
        pairs.clear();
        let (column, upper, fore, wrist, flange) = (0, 1, 2, 3, 4);
        pairs.extend([
            (column, fore),
            (column, wrist),
            (column, flange),
            (upper, wrist),
            (upper, flange),
        ]);
        for o in first_other..all.len() {
            for l in 0..5 {
                pairs.push((l, o));
            }
        }
        let keep_outs = first_other..all.len();
        // the part's pose and the links its hulls pair with
        let (part_pose, part_links): (Option<Isometry3>, &[usize]) = match self.cell {
            CellLayout::TorchCarried(c) => match s.qp {
                Some(qp) => {
                    let (table_pose, tilt_pose) = positioner_poses(c, &qp);
                    let t = all.len();
                    all.push(self.table.at(TABLE, table_pose));
                    all.push(self.tilt.at(TILT, tilt_pose));
                    for l in 0..5 {
                        pairs.push((l, t));
                        pairs.push((l, t + 1));
                    }
                    (Some(c.base_from_part(&qp)), &[upper, fore, wrist, flange])
                }
                None => (None, &[]),
            },
            CellLayout::PartCarried(c) => (
                Some(base_from_flange * c.flange_from_part),
                &[column, upper, fore],
            ),
        };
        let hull_count = part_pose.map_or(0, |_| part.hulls.len());
        memory.advance(layer, &all, part_pose.map(|p| (p, hull_count)));
        // the part's hulls come last: a body whose pairs with every hull
        // are culled by the hulls' common sphere is not bounded hull by hull
        let hulls = HullBodies {
            first: all.len(),
            hulls: &part.hulls[..hull_count],
        };
        // the bodies the hulls pair with: only theirs are bounded against
        // the hulls' common sphere and about the part's axis
        let partners = |o: usize| part_links.contains(&o) || keep_outs.contains(&o);
        let mut far_from_part = std::mem::take(&mut memory.far_from_part);
        far_from_part.clear();
        match (part_pose, part.sphere) {
            (Some(pose), Some(sphere)) => {
                let centre = pose * sphere.centre;
                far_from_part.extend(all.iter().enumerate().map(|(o, a)| {
                    if !partners(o) {
                        return false;
                    }
                    let bound = sphere.lower_bound(a, &centre);
                    bound > self.clearance && bound >= best.distance_mm - REPORT_TOLERANCE_MM
                }));
            }
            _ => far_from_part.resize(all.len(), false),
        }
        // each link the hulls pair with about the part's axis (part
        // frame), where a pair of it with a hull is left to bound (not
        // culled by the common sphere)
        let mut seg_axial = std::mem::take(&mut memory.seg_axial);
        seg_axial.clear();
        if let Some(pose) = part_pose {
            let part_from_base = pose.inverse();
            seg_axial.extend(
                all.iter()
                    .zip(&far_from_part)
                    .enumerate()
                    .map(|(o, (b, &far))| {
                        if far || !part_links.contains(&o) {
                            return None;
                        }
                        let ((a, e), c) = (b.ends?, b.capsule?);
                        let (r, lo, hi) = self
                            .axis
                            .segment(&(part_from_base * a), &(part_from_base * e));
                        Some((r, lo, hi, c.radius))
                    }),
            );
        }
        let mut pass = Pass {
            best,
            memory,
            stats,
            hulls,
            hit: None,
        };
        for (k, &(i, j)) in pairs.iter().enumerate() {
            let seg = seg_axial.get(i).copied().flatten();
            self.pair(&mut pass, k, (i, &all[i]), (j, &all[j]), seg);
        }
        if let Some(pose) = part_pose {
            // per hull: its links, then the keep-out boxes
            let partners: usize = part_links.len() + keep_outs.len();
            let far = part_links
                .iter()
                .copied()
                .chain(keep_outs.clone())
                .filter(|&o| far_from_part[o])
                .count();
            if far == partners {
                pass.stats.culled += partners * hull_count;
            } else {
                for (h, local) in hulls.hulls.iter().enumerate() {
                    let p = hulls.first + h;
                    let mut body: Option<Body> = None;
                    let partner_of = part_links.iter().copied().chain(keep_outs.clone());
                    for (m, o) in partner_of.enumerate() {
                        if far_from_part[o] {
                            pass.stats.culled += 1;
                            continue;
                        }
                        let hull = body.get_or_insert_with(|| local.at(PART, pose));
                        let k = pairs.len() + h * partners + m;
                        if m < part_links.len() {
                            let seg = seg_axial.get(o).copied().flatten();
                            self.pair(&mut pass, k, (o, &all[o]), (p, hull), seg);
                        } else {
                            self.pair(&mut pass, k, (p, hull), (o, &all[o]), None);
                        }
                    }
                }
            }
        }
        let hit = pass.hit;
        memory.pair_list = pairs;
        memory.far_from_part = far_from_part;
        memory.seg_axial = seg_axial;
        hit
    }

    /// One pair of a sample (`k`: its index in the sample's pairs; `i`, `j`:
    /// the bodies' indices in the sample; `seg`: the first body's extent
    /// about the part's axis, where it is to bound the pair): bounded from
    /// below, culled when the bound clears the clearance and cannot lower
    /// the closest approach, else measured.
    fn pair(
        &self,
        pass: &mut Pass,
        k: usize,
        (i, a): (usize, &Body),
        (j, b): (usize, &Body),
        seg: Option<(f64, f64, f64, f64)>,
    ) {
        let margin = a.margin + b.margin;
        let mut bound = ((a.centre - b.centre).norm() - a.radius - b.radius - margin)
            .max(pass.memory.lower_bound(k, i, j, pass.hulls));
        if let (Some(seg), Some(h)) = (seg, b.axial) {
            bound = bound.max(axial_bound((seg.0, seg.1, seg.2), seg.3, h, b.margin));
        }
        if bound > self.clearance && bound >= pass.best.distance_mm - REPORT_TOLERANCE_MM {
            pass.stats.culled += 1;
            return;
        }
        pass.stats.exact_queries += 1;
        let Ok(mut d) = exact_distance(a, b) else {
            return;
        };
        if d <= 0.0 {
            // penetrating: the depth from the contact query
            if let Ok(Some(c)) = query::contact(&a.pose, a.shape, &b.pose, b.shape, 0.0) {
                d = c.dist.min(0.0);
            }
        }
        d -= margin;
        pass.memory.remember(k, i, j, d, pass.hulls);
        if d < pass.best.distance_mm {
            pass.best.distance_mm = d;
            pass.best.pair = Some((a.name.to_string(), b.name.to_string()));
        }
        if d < self.clearance && pass.hit.as_ref().is_none_or(|h| d < h.2) {
            pass.hit = Some((a.name.to_string(), b.name.to_string(), d));
        }
    }
}

/// What one sample's pairs share: the closest approach so far, the
/// culling's memory, the counts, the part's hulls and the closest pair
/// under the clearance.
struct Pass<'s, 'h, 'c> {
    best: &'s mut Closest,
    memory: &'s mut Memory,
    stats: &'s mut CellClearance,
    hulls: HullBodies<'h, 'c>,
    hit: Option<(String, String, f64)>,
}

/// The refusal of a sample at `place` where the pair `hit` (its two bodies
/// and their distance, mm) comes closer than `clearance` (mm).
fn refusal(place: &Place, hit: (String, String, f64), clearance: f64) -> ProgramError {
    ProgramError::Collision {
        layer: place.layer,
        point: place.point,
        motion: place.motion,
        body_a: hit.0,
        body_b: hit.1,
        distance_mm: hit.2,
        clearance_mm: clearance,
    }
}

/// The distance between two bodies (mm), as parry's `query::distance`
/// answers it: for a hull, its support function is the clustered one
/// ([`ClusteredHull`]: the same vertices), called the way parry's
/// dispatcher calls it for two support-mapped shapes (no pair of the check
/// holds a ball, two cuboids, two segments or a half-space).
fn exact_distance(a: &Body, b: &Body) -> Result<f64, query::Unsupported> {
    if a.support.is_none() && b.support.is_none() {
        return query::distance(&a.pose, a.shape, &b.pose, b.shape);
    }
    if let (Some(c), Some(h)) = (a.capsule, b.support) {
        // an arm link against a part hull, the check's common query: the
        // same function on the concrete types (the same operations)
        let pos12 = a.pose.inv_mul(&b.pose);
        return Ok(query::details::distance_support_map_support_map(
            &pos12, c, h,
        ));
    }
    let s1: &dyn SupportMap = match a.support {
        Some(h) => h,
        None => a.shape.as_support_map().ok_or(query::Unsupported)?,
    };
    let s2: &dyn SupportMap = match b.support {
        Some(h) => h,
        None => b.shape.as_support_map().ok_or(query::Unsupported)?,
    };
    let pos12 = a.pose.inv_mul(&b.pose);
    Ok(query::details::distance_support_map_support_map(
        &pos12, s1, s2,
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The part's hulls' odometers, brought up to date only when needed
    /// ([`Memory::odometer_of`]), are to the bit the running sums that
    /// [`Memory::advance`] keeps for every other body (a hull's centre's
    /// displacement plus its radius times the turn, at every sample): read
    /// at random samples, with samples skipped, after the memory forgets.
    #[test]
    fn a_hulls_odometer_brought_up_to_date_late_is_its_running_sum() {
        let mut next = crate::util::uniform(0x5851_f42d_4c95_7f2d, -1.0, 1.0);
        let ring = |z: f64, r: f64| -> Vec<Point3> {
            (0..12)
                .map(|i| {
                    let a = i as f64 * std::f64::consts::TAU / 12.0;
                    Point3::new(r * a.cos() + 3.0, r * a.sin() - 7.0, z)
                })
                .collect()
        };
        let hulls: Vec<Local> = (0..3)
            .map(|k| {
                let mut pts = ring(10.0 * k as f64, 40.0 + k as f64);
                pts.extend(ring(10.0 * k as f64 + 12.5, 41.0 + k as f64));
                hull(&pts).expect("a hull")
            })
            .collect();
        let refs: Vec<&Local> = hulls.iter().collect();
        let part = HullBodies {
            first: 0,
            hulls: &refs,
        };
        let mut memory = Memory::default();
        let mut pose = Isometry3::identity();
        // the running sums, as `advance` adds them for a body it places
        let mut sums = [0.0; 3];
        let mut was: Vec<Point3> = Vec::new();
        let mut was_rotation = UnitQuaternion::identity();
        let mut read = 0;
        for s in 0..400 {
            // a layer change at 250: the memory forgets
            let layer = usize::from(s >= 250);
            let step = Isometry3::from_parts(
                Translation3::new(next(), next(), next()),
                UnitQuaternion::from_euler_angles(0.05 * next(), 0.05 * next(), 0.05 * next()),
            );
            pose = step * pose;
            memory.advance(layer, &[], Some((pose, refs.len())));
            let now: Vec<Point3> = refs.iter().map(|h| pose * h.centre).collect();
            if s == 0 || s == 250 {
                sums = [0.0; 3];
            } else {
                let angle = was_rotation.angle_to(&pose.rotation);
                for (h, hull) in refs.iter().enumerate() {
                    sums[h] += (now[h] - was[h]).norm() + hull.radius * angle;
                }
            }
            was = now;
            was_rotation = pose.rotation;
            for (h, sum) in sums.iter().enumerate() {
                if next() > 0.6 {
                    assert_eq!(
                        memory.odometer_of(h, part).to_bits(),
                        sum.to_bits(),
                        "hull {h} at sample {s}"
                    );
                    read += 1;
                }
            }
        }
        assert!(read > 100, "{read} reads");
        assert!(sums.iter().all(|&o| o > 10.0), "{sums:?}");
    }
}
