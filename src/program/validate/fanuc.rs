//! FANUC programs validated: the TP programs read by
//! [`parse_ls`](crate::program::readback::parse_ls) and decoded into
//! [`Step`](super::Step)s by [`fanuc_steps`] (which names what a
//! controller needs that the file says wrong: frames, `RTCP`, `COORD`,
//! `ARC : TRUE`, arc instructions), then checked by [`check_steps`].

use crate::math::Point3;
use crate::program::fanuc::{FanucOptions, TpProgram};
use crate::program::readback::fanuc::fanuc_steps;
use crate::robot::{Cell, Configuration, Vendor};

use super::{check_steps, vendor_matches, ValidationReport};

/// Validates `programs` (the first is executed; `CALL`s are followed into
/// the others by name) against `cell`, with the frames and process of
/// `opts`. `planned`: the planned deposition points of the beads (part
/// frame, mm), one per bead motion in execution order, when available.
/// A cell whose robot is not a FANUC arm is refused: the report holds that
/// one problem ([`ProgramError::VendorMismatch`](crate::program::ProgramError::VendorMismatch)'s
/// message, line 1 of the main program).
pub fn validate_fanuc(
    programs: &[TpProgram],
    cell: &Cell,
    opts: &FanucOptions,
    planned: Option<&[Point3]>,
) -> ValidationReport {
    let mut report = ValidationReport::default();
    let file = programs.first().map_or("", |p| p.name.as_str());
    if !vendor_matches(
        cell,
        Vendor::Fanuc,
        crate::program::fanuc::EMITTER,
        file,
        &mut report,
    ) {
        return report;
    }
    let steps = fanuc_steps(programs, cell, opts, &mut report);
    check_steps(&steps, cell, planned, &opts.common, &mut report);
    report
}

/// Parses `F U T, 0, 0, 1` into the branch and the turns of J1, J4, J6.
pub fn parse_config(s: &str) -> Option<(Configuration, [i32; 3])> {
    let mut parts = s.split(',');
    let cfg = Configuration::from_fanuc(parts.next()?)?;
    let mut turns = [0; 3];
    for t in &mut turns {
        *t = parts.next()?.trim().parse().ok()?;
    }
    if parts.next().is_some() {
        return None;
    }
    Some((cfg, turns))
}
