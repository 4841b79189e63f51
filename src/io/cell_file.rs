//! **Cell files (TOML).** Reads a robot (a named preset, possibly with
//! overrides, or a full definition) and optionally one cell (part carried or
//! torch carried) from a file in `parts/cells/`. Degrees and FANUC
//! `[X, Y, Z, W, P, R]` (mm, deg) at this edge; radians inside. Unknown keys
//! are errors. SPEC §6.
//!
//! ```toml
//! name = "ROBOWAM part carried"
//! source = "Chalvin (2020), §3.3 eq. 3.18"
//!
//! [robot]
//! preset = "arcmate120ic_nominal"
//! lower_deg = [-170, -100, -185, -200, -135, -inf]
//! upper_deg = [170, 160, 273, 200, 135, inf]
//!
//! [part_carried]
//! deposition_point_mm = [1045.747, -630.155, 653.167]
//! configuration = "F U T"
//! ```

use std::path::Path;

use serde::Deserialize;

use crate::math::{Isometry3, Point3};
use crate::program::{ProgramOptions, ProgramSettings};
use crate::robot::orientation::FanucPose;
use crate::robot::{
    ArmGeometry, CellLayout, Configuration, JointConvention, JointLimit, PartCarriedCell,
    Positioner, RobotError, RobotModel, RobotPreset, TorchCarriedCell, Vendor,
};

/// Part size the cell-file reader allows for when it checks that the arm
/// reaches the work (mm): a cell is refused only if no path point within
/// 1 m of the part frame origin could be reached
/// ([`CellLayout::check_reach`]). A cell file names no part; a plan checks again
/// with its path's own extent.
pub const CELL_FILE_PART_RADIUS_MM: f64 = 1000.0;

/// Errors reading a cell file; each names the file and the key at fault.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum CellFileError {
    /// The file could not be read.
    #[error("{path}: cannot read: {source}")]
    Io {
        /// The file.
        path: String,
        /// The I/O error.
        source: std::io::Error,
    },
    /// The file is not valid TOML or does not match the schema (unknown or
    /// misspelt key, wrong type); the message gives line and column.
    #[error("{path}: {message}")]
    Syntax {
        /// The file.
        path: String,
        /// The parser's message.
        message: String,
    },
    /// A key is missing or its value is out of its domain.
    #[error("{path}: `{key}`: {reason}")]
    Invalid {
        /// The file.
        path: String,
        /// The key, dotted (`robot.geometry`, `part_carried.configuration`).
        key: String,
        /// What is wrong.
        reason: String,
    },
    /// The robot or cell built from the file is invalid.
    #[error("{path}: {source}")]
    Robot {
        /// The file.
        path: String,
        /// What the robot stage rejected.
        source: RobotError,
    },
}

/// What a cell file holds.
#[derive(Debug, Clone, PartialEq)]
pub struct CellFile {
    /// Name of the file's content.
    pub name: String,
    /// Where the numbers come from.
    pub source: String,
    /// The robot (also inside `cell` when there is one).
    pub robot: RobotModel,
    /// The cell, if the file describes one.
    pub cell: Option<CellLayout>,
    /// The `[placement]` table: bounds for `waam place`, if given.
    pub placement: Option<PlacementSpec>,
    /// The `[program]` table (home, dwell, interpass wait, payload, transit,
    /// coordination, and `[program.fanuc]`, `[program.kuka]`,
    /// `[program.abb]`): defaults where absent.
    pub program: ProgramSettings,
    /// The `[[keep_out]]` tables: boxes the arm, the positioner and the
    /// part must keep out of (robot base frame, mm; [`crate::program::cell_check`]).
    pub keep_out: Vec<crate::program::cell_check::KeepOut>,
}

/// The `[placement]` table of a cell file: the bounds of the placement
/// search (robot base frame; mm and degrees). Each key is optional.
///
/// ```toml
/// [placement]
/// min_mm = [600, -900, 300]     # deposition point (part carried) or positioner origin (torch carried)
/// max_mm = [1300, 300, 1200]
/// rotation_deg = [-180, 180]    # part mount about the flange axis / positioner about the vertical
/// fixed = ["z"]                 # variables kept at the file's value: x, y, z, rotation
/// keep_out_min_mm = [-300, -300, -1000]   # a box the point may not enter
/// keep_out_max_mm = [300, 300, 500]
/// # searched only when a range is given (else kept at the file's value):
/// tilt_x_deg = [-30, 30]        # fixture tilt of the part about X, Y: of its mount on the
/// tilt_y_deg = [-30, 30]        #   flange (part carried) or on the table (torch carried)
/// offset_mm = [0, 100]          # part carried: the part's mount along the flange axis
/// torch_rotation_deg = [-90, 90]  # torch carried: the torch in its clamp, about the flange axis
/// fixture_rotation_deg = [-180, 180]  # torch carried: the part on the table about its normal
/// # the part's offset in its mount's plane: on the table (torch carried, table frame x, y;
/// # searched by default: the part origin within ±150 mm of the turn axis) or on the flange
/// # (part carried, flange frame x, y; kept unless given); [0, 0] keeps it
/// offset_x_mm = [-150, 150]
/// offset_y_mm = [-150, 150]
/// ```
///
/// The mount ranges (tilts, offsets, rotations of the fixture or torch) are
/// relative to the file's own mount (`flange_from_part_xyzwpr`,
/// `table_from_part_xyzwpr`, `tool_xyzwpr`), composed as
/// [`PlacementValues::apply`](crate::place::PlacementValues::apply) says.
#[derive(Debug, Clone, PartialEq, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlacementSpec {
    /// Lower corner of the box searched (mm).
    pub min_mm: Option<[f64; 3]>,
    /// Upper corner of the box searched (mm).
    pub max_mm: Option<[f64; 3]>,
    /// Range of the rotation (deg).
    pub rotation_deg: Option<[f64; 2]>,
    /// Variables kept at the file's value: `x`, `y`, `z`, `rotation`.
    #[serde(default)]
    pub fixed: Vec<String>,
    /// Lower corner of the keep-out box (mm).
    pub keep_out_min_mm: Option<[f64; 3]>,
    /// Upper corner of the keep-out box (mm).
    pub keep_out_max_mm: Option<[f64; 3]>,
    /// Range of the fixture's tilt of the part about X (deg): about the
    /// flange X axis (part carried) or the table X axis (torch carried),
    /// within ±90°. Absent: kept at the file's mount.
    pub tilt_x_deg: Option<[f64; 2]>,
    /// As `tilt_x_deg`, about Y (deg).
    pub tilt_y_deg: Option<[f64; 2]>,
    /// Part carried: range of the part mount's offset along the flange axis
    /// (mm), within ±1000 mm. Absent: kept.
    pub offset_mm: Option<[f64; 2]>,
    /// Torch carried: range of the torch's rotation in its clamp about the
    /// flange axis (deg), at most a turn wide. Absent: kept.
    pub torch_rotation_deg: Option<[f64; 2]>,
    /// Range of the part's offset along x in its mount's plane (mm), within
    /// ±1000 mm of the file's mount: table frame x (torch carried), flange
    /// frame x (part carried). Absent: torch carried, the part origin within
    /// ±[`TABLE_OFFSET_MM`](crate::place::TABLE_OFFSET_MM) of the turn axis
    /// (and the file's mount); part carried, kept.
    pub offset_x_mm: Option<[f64; 2]>,
    /// As `offset_x_mm`, along the table (flange) frame y (mm).
    pub offset_y_mm: Option<[f64; 2]>,
    /// Torch carried: range of the part's rotation on the table about the
    /// table normal (deg), at most a turn wide. Absent: kept (with an
    /// endless turn it only matters against the turn stroke).
    pub fixture_rotation_deg: Option<[f64; 2]>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct FileDoc {
    name: String,
    #[serde(default)]
    source: String,
    robot: RobotSection,
    part_carried: Option<PartCarriedSection>,
    torch_carried: Option<TorchCarriedSection>,
    placement: Option<PlacementSpec>,
    program: Option<toml::Table>,
    #[serde(default)]
    keep_out: Vec<crate::program::cell_check::KeepOut>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct ConventionSection {
    sign: [f64; 6],
    offset_deg: [f64; 6],
    j2_j3_coupled: bool,
    /// Rows of `wrist_from_flange`.
    wrist_from_flange_rows: [[f64; 3]; 3],
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RobotSection {
    preset: Option<RobotPreset>,
    name: Option<String>,
    source: Option<String>,
    vendor: Option<Vendor>,
    geometry: Option<ArmGeometry>,
    convention: Option<ConventionSection>,
    lower_deg: Option<[f64; 6]>,
    upper_deg: Option<[f64; 6]>,
    max_speed_deg_s: Option<[f64; 6]>,
    encoder_sigma_deg: Option<[f64; 6]>,
    twist_deviation_deg: Option<[f64; 6]>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct PartCarriedSection {
    deposition_point_mm: [f64; 3],
    configuration: String,
    /// `flange_from_part` as FANUC `[X, Y, Z, W, P, R]` (mm, deg); identity if absent.
    flange_from_part_xyzwpr: Option<[f64; 6]>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct PositionerSection {
    name: String,
    tilt_to_table_mm: f64,
    lower_deg: Option<[f64; 2]>,
    upper_deg: Option<[f64; 2]>,
    max_speed_deg_s: Option<[f64; 2]>,
    turn_stroke_deg: Option<[f64; 2]>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct TorchCarriedSection {
    configuration: String,
    positioner_pose_xyzwpr: [f64; 6],
    tool_xyzwpr: [f64; 6],
    table_from_part_xyzwpr: Option<[f64; 6]>,
    max_hose_torsion_deg: f64,
    #[serde(default = "default_vertical_error_deg")]
    max_vertical_error_deg: f64,
    positioner: PositionerSection,
}

fn default_vertical_error_deg() -> f64 {
    1.0
}

/// Reads and validates a cell file.
///
/// # Errors
/// [`CellFileError`] naming the file and the key.
pub fn read_cell_file(path: impl AsRef<Path>) -> Result<CellFile, CellFileError> {
    let path = path.as_ref();
    let shown = path.display().to_string();
    let text = std::fs::read_to_string(path).map_err(|source| CellFileError::Io {
        path: shown.clone(),
        source,
    })?;
    parse_cell_file(&text, &shown)
}

fn limits_from(lower: &[f64], upper: &[f64]) -> Vec<JointLimit> {
    lower
        .iter()
        .zip(upper)
        .map(|(l, u)| JointLimit::from_degrees(*l, *u))
        .collect()
}

/// Parses and validates the text of a cell file; `origin` names it in errors.
///
/// # Errors
/// [`CellFileError`] naming `origin` and the key.
pub fn parse_cell_file(text: &str, origin: &str) -> Result<CellFile, CellFileError> {
    let doc: FileDoc = toml::from_str(text).map_err(|e| CellFileError::Syntax {
        path: origin.to_string(),
        message: e.to_string(),
    })?;
    let invalid = |key: &str, reason: &str| CellFileError::Invalid {
        path: origin.to_string(),
        key: key.to_string(),
        reason: reason.to_string(),
    };
    let robot_err = |source| CellFileError::Robot {
        path: origin.to_string(),
        source,
    };
    let r = doc.robot;
    let mut robot = match r.preset {
        Some(p) => RobotModel::preset(p),
        None => {
            let vendor = r
                .vendor
                .ok_or_else(|| invalid("robot.vendor", "required when no preset is given"))?;
            let geometry = r
                .geometry
                .ok_or_else(|| invalid("robot.geometry", "required when no preset is given"))?;
            for (key, present) in [
                ("robot.lower_deg", r.lower_deg.is_some()),
                ("robot.upper_deg", r.upper_deg.is_some()),
                ("robot.max_speed_deg_s", r.max_speed_deg_s.is_some()),
            ] {
                if !present {
                    return Err(invalid(key, "required when no preset is given"));
                }
            }
            RobotModel {
                name: r.name.clone().unwrap_or_else(|| doc.name.clone()),
                source: String::new(),
                vendor,
                geometry,
                convention: JointConvention::of(vendor),
                limits: [JointLimit::UNLIMITED; 6],
                max_speed_rad_s: [1.0; 6],
                max_acceleration_rad_s2: None,
                encoder_sigma_rad: None,
                twist_deviation_rad: [0.0; 6],
            }
        }
    };
    if let Some(n) = r.name {
        robot.name = n;
    }
    if let Some(s) = r.source {
        robot.source = s;
    }
    if r.preset.is_some() && (r.vendor.is_some() || r.geometry.is_some()) {
        return Err(invalid(
            "robot.preset",
            "give either a preset or `vendor` + `geometry`, not both",
        ));
    }
    if let Some(c) = r.convention {
        let m = crate::math::Matrix3::from_row_slice(&c.wrist_from_flange_rows.concat());
        robot.convention = JointConvention {
            sign: c.sign,
            offset_rad: c.offset_deg.map(f64::to_radians),
            j2_j3_coupled: c.j2_j3_coupled,
            wrist_from_flange: m,
        };
    }
    match (r.lower_deg, r.upper_deg) {
        (Some(l), Some(u)) => {
            let v = limits_from(&l, &u);
            robot.limits = [v[0], v[1], v[2], v[3], v[4], v[5]];
        }
        (None, None) => {}
        _ => {
            return Err(invalid(
                "robot.lower_deg",
                "give both lower_deg and upper_deg",
            ))
        }
    }
    if let Some(s) = r.max_speed_deg_s {
        robot.max_speed_rad_s = s.map(f64::to_radians);
    }
    if let Some(s) = r.encoder_sigma_deg {
        robot.encoder_sigma_rad = Some(s.map(f64::to_radians));
    }
    if let Some(s) = r.twist_deviation_deg {
        robot.twist_deviation_rad = s.map(f64::to_radians);
    }
    robot.validate().map_err(robot_err)?;

    let parse_cfg = |key: &str, s: &str| {
        Configuration::from_fanuc(s)
            .ok_or_else(|| invalid(key, "expected FANUC letters N|F, U|D, T|B, e.g. \"N U T\""))
    };
    let cell = match (doc.part_carried, doc.torch_carried) {
        (Some(_), Some(_)) => {
            return Err(invalid(
                "torch_carried",
                "a file describes one cell: part_carried or torch_carried",
            ))
        }
        (Some(pc), None) => {
            let configuration = parse_cfg("part_carried.configuration", &pc.configuration)?;
            let c = PartCarriedCell {
                name: doc.name.clone(),
                robot: robot.clone(),
                deposition_point_mm: Point3::from(pc.deposition_point_mm),
                configuration,
                flange_from_part: pc
                    .flange_from_part_xyzwpr
                    .map(|v| FanucPose::from_xyzwpr_deg(v).to_isometry())
                    .unwrap_or_else(Isometry3::identity),
            };
            Some(CellLayout::PartCarried(c))
        }
        (None, Some(tc)) => {
            let configuration = parse_cfg("torch_carried.configuration", &tc.configuration)?;
            let ps = tc.positioner;
            let limits = match (ps.lower_deg, ps.upper_deg) {
                (Some(l), Some(u)) => {
                    let v = limits_from(&l, &u);
                    [v[0], v[1]]
                }
                (None, None) => [JointLimit::UNLIMITED; 2],
                _ => {
                    return Err(invalid(
                        "torch_carried.positioner.lower_deg",
                        "give both lower_deg and upper_deg",
                    ))
                }
            };
            let turn_stroke = match ps.turn_stroke_deg {
                None => None,
                Some(_) if limits[1].lower_rad.is_finite() || limits[1].upper_rad.is_finite() => {
                    return Err(invalid(
                        "torch_carried.positioner.turn_stroke_deg",
                        "give a stroke only for an endless turn (lower_deg/upper_deg -inf/inf): a finite travel is the stroke",
                    ))
                }
                Some([lo, hi]) if !(lo.is_finite() && hi.is_finite() && hi - lo >= 360.0) => {
                    return Err(invalid(
                        "torch_carried.positioner.turn_stroke_deg",
                        "must be finite and at least 360 degrees wide, so that every angle of the endless turn has a value in it",
                    ))
                }
                Some([lo, hi]) => Some(JointLimit {
                    lower_rad: lo.to_radians(),
                    upper_rad: hi.to_radians(),
                }),
            };
            let positioner = Positioner {
                turn_stroke,
                name: ps.name,
                tilt_to_table_mm: ps.tilt_to_table_mm,
                limits,
                max_speed_rad_s: ps
                    .max_speed_deg_s
                    .map(|s| s.map(f64::to_radians))
                    .unwrap_or([f64::INFINITY; 2]),
            };
            let c = TorchCarriedCell {
                name: doc.name.clone(),
                robot: robot.clone(),
                positioner,
                base_from_positioner: FanucPose::from_xyzwpr_deg(tc.positioner_pose_xyzwpr)
                    .to_isometry(),
                flange_from_tcp: FanucPose::from_xyzwpr_deg(tc.tool_xyzwpr).to_isometry(),
                table_from_part: tc
                    .table_from_part_xyzwpr
                    .map(|v| FanucPose::from_xyzwpr_deg(v).to_isometry())
                    .unwrap_or_else(Isometry3::identity),
                configuration,
                max_hose_torsion_rad: tc.max_hose_torsion_deg.to_radians(),
                max_vertical_error_rad: tc.max_vertical_error_deg.to_radians(),
            };
            Some(CellLayout::TorchCarried(c))
        }
        (None, None) => None,
    };
    if let Some(c) = &cell {
        c.validate().map_err(robot_err)?;
        c.check_reach(CELL_FILE_PART_RADIUS_MM).map_err(robot_err)?;
    }
    if let Some(p) = &doc.placement {
        for f in &p.fixed {
            if !["x", "y", "z", "rotation"].contains(&f.as_str()) {
                return Err(invalid(
                    "placement.fixed",
                    &format!("`{f}`: expected x, y, z or rotation"),
                ));
            }
        }
        if p.min_mm.is_some() != p.max_mm.is_some() {
            return Err(invalid("placement.min_mm", "give both min_mm and max_mm"));
        }
        if p.keep_out_min_mm.is_some() != p.keep_out_max_mm.is_some() {
            return Err(invalid(
                "placement.keep_out_min_mm",
                "give both keep_out_min_mm and keep_out_max_mm",
            ));
        }
        let part_carried = matches!(cell, Some(CellLayout::PartCarried(_)));
        let ranges = [
            ("placement.tilt_x_deg", p.tilt_x_deg, 90.0, None),
            ("placement.tilt_y_deg", p.tilt_y_deg, 90.0, None),
            ("placement.offset_mm", p.offset_mm, 1000.0, Some(true)),
            (
                "placement.torch_rotation_deg",
                p.torch_rotation_deg,
                360.0,
                Some(false),
            ),
            ("placement.offset_x_mm", p.offset_x_mm, 1000.0, None),
            ("placement.offset_y_mm", p.offset_y_mm, 1000.0, None),
            (
                "placement.fixture_rotation_deg",
                p.fixture_rotation_deg,
                360.0,
                Some(false),
            ),
        ];
        for (field, range, limit, only_part_carried) in ranges {
            let Some([lo, hi]) = range else { continue };
            if only_part_carried.is_some_and(|pc| pc != part_carried) {
                let kind = if part_carried { "part" } else { "torch" };
                return Err(invalid(
                    field,
                    &format!("not a variable of a {kind}-carried cell"),
                ));
            }
            let ok = lo.is_finite() && hi.is_finite() && lo <= hi;
            let within = if field.ends_with("rotation_deg") {
                hi - lo <= limit
            } else {
                lo >= -limit && hi <= limit
            };
            if !(ok && within) {
                return Err(invalid(
                    field,
                    &format!("[{lo}, {hi}] must be finite, ordered and within {limit}"),
                ));
            }
        }
    }
    let program = match doc.program {
        Some(t) => program_settings(origin, t, cell.as_ref())?,
        None => ProgramSettings::default(),
    };
    for (i, k) in doc.keep_out.iter().enumerate() {
        k.validate()
            .map_err(|reason| invalid(&format!("keep_out[{i}]"), &reason))?;
    }
    Ok(CellFile {
        name: doc.name,
        source: doc.source,
        robot,
        cell,
        placement: doc.placement,
        program,
        keep_out: doc.keep_out,
    })
}

/// The `[program]` table: its vendor sub-tables (`[program.<key>]`, each
/// registered vendor's, [`crate::program::registry`]) are each vendor's
/// emitter options, the rest the vendor-independent
/// [`ProgramOptions`]; unknown keys are errors, and the home position must
/// lie inside the cell's joint travel.
fn program_settings(
    path: &str,
    mut table: toml::Table,
    cell: Option<&CellLayout>,
) -> Result<ProgramSettings, CellFileError> {
    let mut settings = ProgramSettings::take_vendor_tables(&mut table).map_err(
        |(key, e): (&str, toml::de::Error)| CellFileError::Syntax {
            path: path.to_string(),
            message: format!("[program.{key}]: {}", e.message()),
        },
    )?;
    let common: ProgramOptions =
        toml::Value::Table(table)
            .try_into()
            .map_err(|e: toml::de::Error| CellFileError::Syntax {
                path: path.to_string(),
                message: format!("[program]: {}", e.message()),
            })?;
    let invalid = |e: crate::program::ProgramError| {
        let (key, reason) = match &e {
            crate::program::ProgramError::InvalidOptions {
                field,
                value,
                reason,
            } => (field.to_string(), format!("{value}: {reason}")),
            other => (String::new(), other.to_string()),
        };
        CellFileError::Invalid {
            path: path.to_string(),
            key,
            reason,
        }
    };
    let prefixed = |vendor: &str, e: crate::program::ProgramError| {
        let mut err = invalid(e);
        if let CellFileError::Invalid { key, .. } = &mut err {
            *key = format!("program.{vendor}.{key}");
        }
        err
    };
    common.validate().map_err(|e| {
        let mut err = invalid(e);
        if let CellFileError::Invalid { key, .. } = &mut err {
            *key = format!("program.{key}");
        }
        err
    })?;
    settings
        .check_vendor_options()
        .map_err(|(key, e)| prefixed(key, e))?;
    if let Some((c, h)) = cell.and_then(|c| Some((c, common.home(c)?))) {
        let limits = &c.robot().limits;
        if let Some(j) = (0..6).find(|&j| !limits[j].contains(h.joints[j])) {
            return Err(CellFileError::Invalid {
                path: path.to_string(),
                key: "program.home_deg".into(),
                reason: format!(
                    "J{} = {:.3}° is outside its travel [{:.1}°, {:.1}°]",
                    j + 1,
                    h.joints[j].to_degrees(),
                    limits[j].lower_rad.to_degrees(),
                    limits[j].upper_rad.to_degrees()
                ),
            });
        }
    }
    settings.common = common;
    Ok(settings)
}

/// A placed cell file's text: `text` (the cell file as read, `file` naming
/// it) with the placement's values written into its `[part_carried]` or
/// `[torch_carried]` table (FANUC `[X, Y, Z, W, P, R]`, mm and deg, 6
/// decimals), the bounds searched as its `[placement]` table (relative to
/// the mount written, so that placing again from the file searches the same
/// box), and a header comment giving the margins achieved. The original's
/// comments, key order and layout are kept (toml_edit); a header from an
/// earlier placement is replaced.
///
/// # Errors
/// [`CellFileError::Syntax`] naming `file` when `text` is not TOML or lacks
/// the table of the placed cell's kind.
pub fn placed_cell_file(
    text: &str,
    file: &str,
    p: &crate::place::Placement,
    bounds: &crate::place::PlacementBounds,
) -> Result<String, CellFileError> {
    use toml_edit::{DocumentMut, Item, Table};
    let syntax = |message: String| CellFileError::Syntax {
        path: file.to_string(),
        message,
    };
    let mut doc: DocumentMut = text
        .parse()
        .map_err(|e: toml_edit::TomlError| syntax(e.to_string()))?;
    let table = |doc: &DocumentMut, name: &str| -> Result<Table, CellFileError> {
        match doc.get(name).and_then(Item::as_table) {
            Some(t) => Ok(t.clone()),
            None => Err(syntax(format!("no [{name}] table"))),
        }
    };
    let v = &p.values;
    match &p.cell {
        CellLayout::PartCarried(c) => {
            let mut t = table(&doc, "part_carried")?;
            t["deposition_point_mm"] = toml_floats(c.deposition_point_mm.coords.as_slice());
            let mount_moved = [
                v.rotation,
                v.tilt_x,
                v.tilt_y,
                v.offset_mm,
                v.offset_x_mm,
                v.offset_y_mm,
            ]
            .iter()
            .any(|x| *x != 0.0);
            if mount_moved || t.contains_key("flange_from_part_xyzwpr") {
                let pose = FanucPose::from_isometry(&c.flange_from_part).to_xyzwpr_deg();
                t["flange_from_part_xyzwpr"] = toml_floats(&pose);
            }
            doc["part_carried"] = Item::Table(t);
        }
        CellLayout::TorchCarried(c) => {
            let mut t = table(&doc, "torch_carried")?;
            let pose = FanucPose::from_isometry(&c.base_from_positioner).to_xyzwpr_deg();
            t["positioner_pose_xyzwpr"] = toml_floats(&pose);
            let mount_moved = [
                v.tilt_x,
                v.tilt_y,
                v.offset_x_mm,
                v.offset_y_mm,
                v.fixture_rotation,
            ]
            .iter()
            .any(|x| *x != 0.0);
            if mount_moved || t.contains_key("table_from_part_xyzwpr") {
                let pose = FanucPose::from_isometry(&c.table_from_part).to_xyzwpr_deg();
                t["table_from_part_xyzwpr"] = toml_floats(&pose);
            }
            if v.torch_rotation != 0.0 {
                let pose = FanucPose::from_isometry(&c.flange_from_tcp).to_xyzwpr_deg();
                t["tool_xyzwpr"] = toml_floats(&pose);
            }
            doc["torch_carried"] = Item::Table(t);
        }
    }
    // An existing [placement] table keeps its place and comments; its keys
    // are replaced.
    let mut spec = doc
        .get("placement")
        .and_then(Item::as_table)
        .cloned()
        .unwrap_or_default();
    spec.clear();
    placement_table(&mut spec, p, bounds);
    doc["placement"] = Item::Table(spec);
    let body = doc.to_string();
    // A file placed before starts with our header: not repeated.
    let body = strip_placed_header(&body);
    let m = &p.margins;
    let b = &p.margins_before;
    Ok(format!(
        "# Placed by waam place from {} ({}).\n\
         # Worst-layer margins after: {:.2} deg from a joint stop, speed headroom {:.1} %, dexterity {:.4}, {:.1} mm inside the arm's reach, {} infeasible layer(s).\n\
         # Before (on the search's subsample of layers and points): {:.2} deg, {:.1} %, {:.4}, {:.1} mm, {} infeasible layer(s).\n\
         # Candidates {}, feasible on the subsample {:.0} %, certified on the full path {}, {:.1} s.\n{body}",
        file,
        if p.feasible { "feasible" } else { "NOT feasible" },
        m.joint_limit_deg,
        100.0 * m.speed_headroom,
        m.dexterity,
        m.reach_mm,
        m.infeasible_layers,
        b.joint_limit_deg,
        100.0 * b.speed_headroom,
        b.dexterity,
        b.reach_mm,
        b.infeasible_layers,
        p.candidates,
        100.0 * p.feasible_fraction,
        p.certified,
        p.time_s,
    ))
}

/// Fills the `[placement]` table `spec` with the bounds searched, around
/// the placement found: the box of the deposition point (positioner) as
/// searched; the rotation, fixture (tilts, offsets, rotation on the table)
/// and torch-mount ranges relative to the mount written (exact for the
/// offsets alone or one free tilt axis; with several, placing again
/// searches a slightly different box about the found mount; a
/// torch-carried cell's offset on the table is written even when fixed,
/// since its default is searched); the fixed variables; the keep-out box.
fn placement_table(
    spec: &mut toml_edit::Table,
    p: &crate::place::Placement,
    bounds: &crate::place::PlacementBounds,
) {
    use std::f64::consts::PI;
    let v = &bounds.variables;
    let found = &p.values;
    spec["min_mm"] = toml_floats(&[v[0].lower, v[1].lower, v[2].lower]);
    spec["max_mm"] = toml_floats(&[v[0].upper, v[1].upper, v[2].upper]);
    let (lo, hi) = (v[3].lower - found.rotation, v[3].upper - found.rotation);
    let span = (hi - lo).min(2.0 * PI);
    spec["rotation_deg"] = toml_floats(&[lo.to_degrees(), (lo + span).to_degrees()]);
    let mount = match p.cell {
        CellLayout::PartCarried(_) => ("offset_mm", found.offset_mm, false),
        CellLayout::TorchCarried(_) => ("torch_rotation_deg", found.torch_rotation, true),
    };
    let extra = [
        (&v[4], ("tilt_x_deg", found.tilt_x, true)),
        (&v[5], ("tilt_y_deg", found.tilt_y, true)),
        (&v[6], mount),
        (&v[7], ("offset_x_mm", found.offset_x_mm, false)),
        (&v[8], ("offset_y_mm", found.offset_y_mm, false)),
        (
            &v[9],
            ("fixture_rotation_deg", found.fixture_rotation, true),
        ),
    ];
    // A torch-carried cell searches the offset on its table by default: kept
    // fixed, it is written `[0, 0]` so that placing again keeps it.
    let torch = matches!(p.cell, CellLayout::TorchCarried(_));
    for (var, (key, x, degrees)) in extra {
        if var.is_free() || (torch && key.starts_with("offset_")) {
            let (lo, hi) = (var.lower - x, var.upper - x);
            let r = if degrees {
                [lo.to_degrees(), hi.to_degrees()]
            } else {
                [lo, hi]
            };
            spec[key] = toml_floats(&r);
        }
    }
    let fixed: toml_edit::Array = ["x", "y", "z", "rotation"]
        .iter()
        .zip(v)
        .filter(|(_, var)| var.lower == var.upper)
        .map(|(n, _)| *n)
        .collect();
    if !fixed.is_empty() {
        spec["fixed"] = toml_edit::value(fixed);
    }
    if let Some((lo, hi)) = bounds.keep_out {
        spec["keep_out_min_mm"] = toml_floats(&lo);
        spec["keep_out_max_mm"] = toml_floats(&hi);
    }
}

/// A TOML array of `xs` rounded to 6 decimals (no `-0`).
fn toml_floats(xs: &[f64]) -> toml_edit::Item {
    let round6 = |x: f64| {
        let r = (x * 1e6).round() / 1e6;
        if r == 0.0 {
            0.0
        } else {
            r
        }
    };
    let mut a: toml_edit::Array = xs.iter().map(|x| round6(*x)).collect();
    a.fmt();
    toml_edit::value(a)
}

/// The first lines of the comment [`placed_cell_file`] puts at the top.
const PLACED_HEADER: [&str; 4] = [
    "# Placed by waam place ",
    "# Worst-layer margins after: ",
    "# Before (on the search's subsample",
    "# Candidates ",
];

/// `text` without the header [`placed_cell_file`] puts first (a cell file
/// placed again keeps one header, the new one, and the original's own
/// comments).
fn strip_placed_header(text: &str) -> &str {
    let mut rest = text;
    while PLACED_HEADER.iter().any(|h| rest.starts_with(h)) {
        rest = rest.split_once('\n').map_or("", |(_, r)| r);
    }
    rest
}
