//! Plain CSV of every program point [SPEC §8]: layer, point, arc flag,
//! position and tool axis (part frame, mm / unitless), `R_Z` (deg), robot
//! joints (deg, controller convention), positioner joints (deg, empty in
//! the part-carried cell) and travel speed (mm/s). One header line, comma
//! separated, `.` decimal point.

use std::io::Write;

use crate::program::fmt::{Deg, Mm, Unitless};
use crate::program::{ArcFlag, Program};

/// The header line (without newline).
pub const HEADER: &str = "layer,point,arc,x_mm,y_mm,z_mm,tx,ty,tz,r_z_deg,j1_deg,j2_deg,j3_deg,j4_deg,j5_deg,j6_deg,e1_deg,e2_deg,speed_mm_s";

/// Writes the CSV of `program`.
///
/// # Errors
/// I/O errors of `w`.
pub fn write_csv(w: &mut dyn Write, program: &Program) -> std::io::Result<()> {
    writeln!(w, "{HEADER}")?;
    for p in &program.points {
        let arc = match p.arc {
            ArcFlag::Approach => "approach",
            ArcFlag::Start => "start",
            ArcFlag::On => "on",
            ArcFlag::End => "end",
            ArcFlag::Retract => "retract",
            ArcFlag::Transit => "transit",
        };
        write!(
            w,
            "{},{},{arc},{},{},{},{},{},{},{}",
            p.layer,
            p.point,
            Mm(p.position_mm.x),
            Mm(p.position_mm.y),
            Mm(p.position_mm.z),
            Unitless(p.tool_axis.x),
            Unitless(p.tool_axis.y),
            Unitless(p.tool_axis.z),
            Deg(p.r_z.to_degrees())
        )?;
        for q in p.joints {
            write!(w, ",{}", Deg(q.to_degrees()))?;
        }
        match p.positioner {
            Some(e) => write!(w, ",{},{}", Deg(e[0].to_degrees()), Deg(e[1].to_degrees()))?,
            None => write!(w, ",,")?,
        }
        writeln!(w, ",{}", Mm(p.speed_mm_s))?;
    }
    Ok(())
}
