//! The placement variables: their bounds and keep-out box, the typed
//! values of a placement, and the cell they give.
//!
//! The search itself moves in a point of [`VARIABLES`] coordinates (the
//! order of the module doc's table, mm and rad); [`PlacementValues`] names
//! them for everything outside the search.

use std::f64::consts::PI;

use crate::math::{Isometry3, Point3, Translation3, UnitQuaternion, UnitVector3, Vector3};
use crate::optimise::OptimiseError;
use crate::robot::CellLayout;

/// Number of placement variables (see the module doc's table).
pub const VARIABLES: usize = 10;

/// Default half-width (mm) of the square, centred on the table's turn axis,
/// within which the search moves the part frame's origin on a
/// torch-carried cell's table when the cell file gives no
/// `offset_x_mm`/`offset_y_mm` range (table frame x and y). The table is
/// assumed Ø500 mm ([`TABLE_RADIUS_MM`](crate::program::cell_check::TABLE_RADIUS_MM)
/// = 250 mm): 150 mm leaves 100 mm of face plate around a part origin at
/// the square's edge, and its corners (212 mm out) stay on the plate.
pub const TABLE_OFFSET_MM: f64 = 150.0;

/// A point of the search space: the [`VARIABLES`] coordinates in the
/// order of the module doc's table (mm for positions and offsets, rad
/// for rotations and tilts).
pub(crate) type Coords = [f64; VARIABLES];

/// Tolerance (rad) on the angular range checks of [`PlacementBounds::validate`].
const ANGLE_SLACK_RAD: f64 = 1e-9;

/// One placement variable: its name, its bounds and the cell's current value
/// (mm for positions and offsets, rad for rotations and tilts).
#[derive(Debug, Clone, PartialEq)]
pub struct PlacementVariable {
    /// Name, e.g. `deposition_point_mm.x`, `flange_rotation`, `positioner.x`,
    /// `fixture.tilt_x`, `fixture.offset`, `torch_rotation`,
    /// `fixture.offset_x`, `fixture.rotation`.
    pub name: &'static str,
    /// `true` for an angle (rad), `false` for a length (mm).
    pub angle: bool,
    /// Lower bound (mm or rad).
    pub lower: f64,
    /// Upper bound (mm or rad); equal to `lower` for a fixed variable.
    pub upper: f64,
    /// The value in the cell as given (mm or rad).
    pub current: f64,
}

impl PlacementVariable {
    /// `true` when the bounds leave the variable free.
    pub fn is_free(&self) -> bool {
        self.upper > self.lower
    }
}

/// Bounds of the search and a keep-out box (robot base frame, mm): a
/// deposition point or positioner origin inside the box is refused (the
/// robot's base, a wall, the wire feeder).
#[derive(Debug, Clone, PartialEq)]
pub struct PlacementBounds {
    /// The [`VARIABLES`] variables, in the order of the module doc's table.
    pub variables: [PlacementVariable; VARIABLES],
    /// Keep-out box `(min, max)`, robot base frame (mm).
    pub keep_out: Option<([f64; 3], [f64; 3])>,
}

impl PlacementBounds {
    /// Default bounds around `cell`'s placement: ±`half_box_mm` on each
    /// coordinate of the deposition point (positioner), the full turn on the
    /// rotation, the fixture tilts, the torch mount and the part-carried
    /// mount fixed as given, and the robot's base keep-out: a vertical
    /// cylinder's bounding box of half-width 250 mm about the base axis
    /// below the shoulder.
    ///
    /// Torch carried, the part's offset on the table is searched: the part
    /// frame's origin within ±[`TABLE_OFFSET_MM`] of the turn axis in table
    /// x and y, the range widened to hold the file's own mount (so that the
    /// cell as given is a candidate); the part's rotation on the table stays
    /// as given (with an endless turn it only matters against a turn
    /// stroke).
    pub fn around(cell: &CellLayout, half_box_mm: f64) -> Self {
        let names_pc = [
            "deposition_point_mm.x",
            "deposition_point_mm.y",
            "deposition_point_mm.z",
            "flange_rotation",
            "fixture.tilt_x",
            "fixture.tilt_y",
            "fixture.offset",
            "fixture.offset_x",
            "fixture.offset_y",
            "fixture.rotation",
        ];
        let names_tc = [
            "positioner.x",
            "positioner.y",
            "positioner.z",
            "positioner.rotation",
            "fixture.tilt_x",
            "fixture.tilt_y",
            "torch_rotation",
            "fixture.offset_x",
            "fixture.offset_y",
            "fixture.rotation",
        ];
        // Part origin in the mount's plane (table frame, mm), when its
        // offset is searched by default (torch carried).
        let (p, names, on_table): (Point3, [&'static str; VARIABLES], Option<Vector3>) = match cell
        {
            CellLayout::PartCarried(c) => (c.deposition_point_mm, names_pc, None),
            CellLayout::TorchCarried(c) => (
                Point3::from(c.base_from_positioner.translation.vector),
                names_tc,
                Some(c.table_from_part.translation.vector),
            ),
        };
        let fixed = |name, angle| PlacementVariable {
            name,
            angle,
            lower: 0.0,
            upper: 0.0,
            current: 0.0,
        };
        // The offset moving the part origin, now at `o` on the table, within
        // ±TABLE_OFFSET_MM of the turn axis, widened to hold 0 (the mount
        // as given).
        let table_offset = |name, o: Option<f64>| match o {
            Some(o) => PlacementVariable {
                lower: (-TABLE_OFFSET_MM - o).min(0.0),
                upper: (TABLE_OFFSET_MM - o).max(0.0),
                ..fixed(name, false)
            },
            None => fixed(name, false),
        };
        let position = |k: usize| PlacementVariable {
            name: names[k],
            angle: false,
            lower: p[k] - half_box_mm,
            upper: p[k] + half_box_mm,
            current: p[k],
        };
        let variables = [
            position(0),
            position(1),
            position(2),
            PlacementVariable {
                lower: -PI,
                upper: PI,
                ..fixed(names[3], true)
            },
            fixed(names[4], true),
            fixed(names[5], true),
            fixed(names[6], matches!(cell, CellLayout::TorchCarried(_))),
            table_offset(names[7], on_table.map(|o| o.x)),
            table_offset(names[8], on_table.map(|o| o.y)),
            fixed(names[9], true),
        ];
        Self {
            variables,
            keep_out: Some(([-250.0, -250.0, -1e4], [250.0, 250.0, 400.0])),
        }
    }

    /// Checks every bound.
    ///
    /// # Errors
    /// [`OptimiseError::InvalidPlacement`] naming the variable.
    pub fn validate(&self) -> Result<(), OptimiseError> {
        let invalid = |field: &str, reason: String| OptimiseError::InvalidPlacement {
            field: field.to_string(),
            reason,
        };
        for v in &self.variables {
            if !(v.lower.is_finite() && v.upper.is_finite() && v.lower <= v.upper) {
                return Err(invalid(
                    v.name,
                    format!(
                        "the range [{}, {}] must be finite and ordered",
                        v.lower, v.upper
                    ),
                ));
            }
            if v.angle && (v.upper - v.lower) > 2.0 * PI + ANGLE_SLACK_RAD {
                return Err(invalid(v.name, "a rotation range wider than a turn".into()));
            }
            if v.name.contains("tilt")
                && (v.lower < -PI / 2.0 - ANGLE_SLACK_RAD || v.upper > PI / 2.0 + ANGLE_SLACK_RAD)
            {
                return Err(invalid(v.name, "a fixture tilt beyond ±90°".into()));
            }
        }
        if let Some((lo, hi)) = self.keep_out {
            if !(0..3).all(|k| lo[k] <= hi[k] && lo[k].is_finite() && hi[k].is_finite()) {
                return Err(invalid(
                    "keep_out",
                    format!("min {lo:?} must be below max {hi:?}, finite"),
                ));
            }
        }
        Ok(())
    }

    /// The cell's current values, clamped into the bounds: the search's
    /// first candidate.
    pub(crate) fn current(&self) -> Coords {
        self.variables
            .each_ref()
            .map(|v| v.current.clamp(v.lower, v.upper))
    }

    /// `x` clamped into the bounds.
    pub(crate) fn clamp(&self, x: &mut Coords) {
        for (v, b) in x.iter_mut().zip(&self.variables) {
            *v = v.clamp(b.lower, b.upper);
        }
    }

    /// `true` when `x`'s deposition point (positioner origin) lies in the
    /// keep-out box.
    pub(crate) fn inside_keep_out(&self, x: &Coords) -> bool {
        self.keep_out
            .is_some_and(|(lo, hi)| (0..3).all(|k| x[k] >= lo[k] && x[k] <= hi[k]))
    }
}

/// The values of a placement, named (robot base frame; mm, rad). Each is
/// the variable of the module doc's table for the cell's kind; the one the
/// kind has not is 0.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct PlacementValues {
    /// Part carried: the deposition point `D_R`; torch carried: the
    /// positioner's origin (robot base frame, mm).
    pub position_mm: Point3,
    /// Part carried: the part mount about the flange axis; torch carried:
    /// the positioner about the vertical (rad).
    pub rotation: f64,
    /// The fixture's tilt of the part about X: on the flange (part carried)
    /// or on the table (torch carried) (rad).
    pub tilt_x: f64,
    /// As [`PlacementValues::tilt_x`], about Y (rad).
    pub tilt_y: f64,
    /// Part carried: the part mount's offset along the flange axis (mm);
    /// 0 torch carried.
    pub offset_mm: f64,
    /// Torch carried: the torch's rotation in its clamp about the flange
    /// axis (rad); 0 part carried.
    pub torch_rotation: f64,
    /// The part's offset along x in its mount's plane (mm): table frame x
    /// (torch carried), flange frame x (part carried). See
    /// [`PlacementValues::apply`] for the order of composition.
    pub offset_x_mm: f64,
    /// As [`PlacementValues::offset_x_mm`], along table (flange) frame y (mm).
    pub offset_y_mm: f64,
    /// Torch carried: the part's rotation on the table about the table
    /// normal (the turn axis) through the table centre (rad); 0 part
    /// carried (there the mount's rotation about the flange axis is
    /// [`PlacementValues::rotation`]).
    pub fixture_rotation: f64,
}

impl PlacementValues {
    /// The values of the search's point `x` in a cell of `cell`'s kind.
    pub(crate) fn from_coords(cell: &CellLayout, x: &Coords) -> Self {
        let torch = matches!(cell, CellLayout::TorchCarried(_));
        Self {
            position_mm: Point3::new(x[0], x[1], x[2]),
            rotation: x[3],
            tilt_x: x[4],
            tilt_y: x[5],
            offset_mm: if torch { 0.0 } else { x[6] },
            torch_rotation: if torch { x[6] } else { 0.0 },
            offset_x_mm: x[7],
            offset_y_mm: x[8],
            fixture_rotation: if torch { x[9] } else { 0.0 },
        }
    }

    /// The values in the order of the module doc's table for a cell of
    /// `cell`'s kind (mm, rad), as [`PlacementBounds::variables`] lists
    /// them.
    pub fn in_table_order(&self, cell: &CellLayout) -> [f64; VARIABLES] {
        let mount = match cell {
            CellLayout::PartCarried(_) => self.offset_mm,
            CellLayout::TorchCarried(_) => self.torch_rotation,
        };
        let p = &self.position_mm;
        [
            p.x,
            p.y,
            p.z,
            self.rotation,
            self.tilt_x,
            self.tilt_y,
            mount,
            self.offset_x_mm,
            self.offset_y_mm,
            self.fixture_rotation,
        ]
    }

    /// The cell with this placement: the deposition point (positioner
    /// origin) set; the rotation, tilts, offsets and torch rotation composed
    /// onto the cell's own mounts, on the left (in the flange or table
    /// frame, about its origin):
    ///
    /// * part carried: `flange_from_part = T(offset_x, offset_y, offset) ·
    ///   Rz(rotation) · Rx(tilt_x) · Ry(tilt_y) · flange_from_part₀`
    ///   (flange frame, mm);
    /// * torch carried: `table_from_part = T(offset_x, offset_y, 0) ·
    ///   Rz(fixture_rotation) · Rx(tilt_x) · Ry(tilt_y) · table_from_part₀`
    ///   (table frame: origin at the table centre C8 on the turn axis, z the
    ///   table normal; mm). The offset moves the part in the table plane
    ///   after it is tilted and turned about the table centre.
    pub fn apply(&self, cell: &CellLayout) -> CellLayout {
        let rot = |axis: &UnitVector3, a: f64| UnitQuaternion::from_axis_angle(axis, a);
        let tilt = rot(&Vector3::x_axis(), self.tilt_x) * rot(&Vector3::y_axis(), self.tilt_y);
        let p = self.position_mm;
        let mut out = cell.clone();
        match &mut out {
            CellLayout::PartCarried(c) => {
                c.deposition_point_mm = p;
                let mount = Isometry3::from_parts(
                    Translation3::new(self.offset_x_mm, self.offset_y_mm, self.offset_mm),
                    rot(&Vector3::z_axis(), self.rotation) * tilt,
                );
                c.flange_from_part = mount * c.flange_from_part;
            }
            CellLayout::TorchCarried(c) => {
                c.base_from_positioner = Isometry3::from_parts(
                    Translation3::new(p.x, p.y, p.z),
                    rot(&Vector3::z_axis(), self.rotation) * c.base_from_positioner.rotation,
                );
                c.table_from_part = Isometry3::from_parts(
                    Translation3::new(self.offset_x_mm, self.offset_y_mm, 0.0),
                    rot(&Vector3::z_axis(), self.fixture_rotation) * tilt,
                ) * c.table_from_part;
                c.flange_from_tcp = Isometry3::from_parts(
                    Translation3::identity(),
                    rot(&Vector3::z_axis(), self.torch_rotation),
                ) * c.flange_from_tcp;
            }
        }
        out
    }
}

/// The cell with the search's point `x`.
pub(crate) fn placed_cell(cell: &CellLayout, x: &Coords) -> CellLayout {
    PlacementValues::from_coords(cell, x).apply(cell)
}
