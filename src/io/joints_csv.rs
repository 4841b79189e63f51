//! `joints.csv`: one row per planned point, header
//! `layer,point,x,y,z,tx,ty,tz,rz_deg,j1,j2,j3,j4,j5,j6` (+ `e1,e2` with a
//! positioner). Position (mm) and tool axis in the part frame, `R_Z` and
//! joints in degrees, joints in the robot's controller convention (FANUC
//! J2/J3 for FANUC arms); a point without a joint solution has empty joint
//! cells. Also reads such a file back.

use std::io::Write;

use crate::optimise::{LayerPoints, Plan};

/// The header line without the positioner columns.
pub const HEADER: &str = "layer,point,x,y,z,tx,ty,tz,rz_deg,j1,j2,j3,j4,j5,j6";

/// Writes `plan`'s points (made from `layers`); `positioner` adds `e1,e2`.
///
/// # Errors
/// I/O errors of `w`.
pub fn write_joints_csv(
    w: &mut dyn Write,
    layers: &[LayerPoints],
    plan: &Plan,
    positioner: bool,
) -> std::io::Result<()> {
    write!(w, "{HEADER}")?;
    writeln!(w, "{}", if positioner { ",e1,e2" } else { "" })?;
    for (lp, l) in layers.iter().zip(&plan.layers) {
        for (m, (cp, pp)) in lp.points.iter().zip(&l.points).enumerate() {
            let p = cp.position_mm;
            let t = cp.tool_axis;
            write!(
                w,
                "{},{m},{:.6},{:.6},{:.6},{:.6},{:.6},{:.6},{:.6}",
                lp.layer,
                p.x,
                p.y,
                p.z,
                t.x,
                t.y,
                t.z,
                pp.r_z.to_degrees()
            )?;
            match pp.joints {
                Some(q) => {
                    for v in q {
                        write!(w, ",{:.6}", v.to_degrees())?;
                    }
                }
                None => write!(w, ",,,,,,")?,
            }
            if positioner {
                match pp.positioner {
                    Some(e) => write!(w, ",{:.6},{:.6}", e[0].to_degrees(), e[1].to_degrees())?,
                    None => write!(w, ",,")?,
                }
            }
            writeln!(w)?;
        }
    }
    Ok(())
}

/// One row of `joints.csv` (units as written: mm, degrees).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JointsRow {
    /// Layer index.
    pub layer: usize,
    /// Point index within the layer.
    pub point: usize,
    /// Position, part frame (mm).
    pub position_mm: [f64; 3],
    /// Tool axis, part frame (unit).
    pub tool_axis: [f64; 3],
    /// `R_Z` (deg).
    pub rz_deg: f64,
    /// Robot joints (deg, controller convention); `None` without solution.
    pub joints_deg: Option<[f64; 6]>,
    /// Positioner joints `e1, e2` (deg); `None` without positioner or solution.
    pub positioner_deg: Option<[f64; 2]>,
}

/// Error reading `joints.csv`, naming the file, line and column.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{file}, line {line}: {reason}")]
pub struct JointsCsvError {
    /// The file.
    pub file: String,
    /// 1-based line number.
    pub line: usize,
    /// What is wrong (names the column).
    pub reason: String,
}

/// Reads the text of a `joints.csv`; `file` names it in errors.
///
/// # Errors
/// [`JointsCsvError`] for a wrong header, a wrong column count, a value that
/// is not a finite number, or a row with some joint cells empty and not others.
pub fn read_joints_csv(text: &str, file: &str) -> Result<Vec<JointsRow>, JointsCsvError> {
    let err = |line: usize, reason: String| JointsCsvError {
        file: file.to_string(),
        line,
        reason,
    };
    let mut lines = text.lines().enumerate();
    let positioner = match lines.next() {
        Some((_, h)) if h == HEADER => false,
        Some((_, h)) if h.strip_suffix(",e1,e2") == Some(HEADER) => true,
        _ => {
            return Err(err(
                1,
                format!("expected the header `{HEADER}` (with `,e1,e2` for a positioner)"),
            ))
        }
    };
    let names: Vec<&str> = HEADER
        .split(',')
        .chain(
            if positioner {
                &["e1", "e2"][..]
            } else {
                &[][..]
            }
            .iter()
            .copied(),
        )
        .collect();
    let mut rows = Vec::new();
    for (i, line) in lines {
        let n = i + 1;
        if line.is_empty() {
            continue;
        }
        let cells: Vec<&str> = line.split(',').collect();
        if cells.len() != names.len() {
            return Err(err(
                n,
                format!("{} columns, expected {}", cells.len(), names.len()),
            ));
        }
        let num = |k: usize| -> Result<Option<f64>, JointsCsvError> {
            if cells[k].is_empty() {
                return Ok(None);
            }
            match cells[k].parse::<f64>() {
                Ok(v) if v.is_finite() => Ok(Some(v)),
                _ => Err(err(
                    n,
                    format!("`{}`: `{}` is not a finite number", names[k], cells[k]),
                )),
            }
        };
        let need = |k: usize| -> Result<f64, JointsCsvError> {
            num(k)?.ok_or_else(|| err(n, format!("`{}` is empty", names[k])))
        };
        let index = |k: usize| -> Result<usize, JointsCsvError> {
            cells[k]
                .parse::<usize>()
                .map_err(|_| err(n, format!("`{}`: `{}` is not an index", names[k], cells[k])))
        };
        let group = |range: std::ops::Range<usize>| -> Result<Option<Vec<f64>>, JointsCsvError> {
            let vals: Vec<Option<f64>> = range.clone().map(num).collect::<Result<_, _>>()?;
            if vals.iter().all(Option::is_none) {
                Ok(None)
            } else if vals.iter().all(Option::is_some) {
                Ok(Some(vals.into_iter().flatten().collect()))
            } else {
                Err(err(
                    n,
                    format!(
                        "columns `{}`..`{}`: some empty, some not",
                        names[range.start],
                        names[range.end - 1]
                    ),
                ))
            }
        };
        let joints_deg = group(9..15)?.map(|v| [v[0], v[1], v[2], v[3], v[4], v[5]]);
        let positioner_deg = if positioner {
            group(15..17)?.map(|v| [v[0], v[1]])
        } else {
            None
        };
        rows.push(JointsRow {
            layer: index(0)?,
            point: index(1)?,
            position_mm: [need(2)?, need(3)?, need(4)?],
            tool_axis: [need(5)?, need(6)?, need(7)?],
            rz_deg: need(8)?,
            joints_deg,
            positioner_deg,
        });
    }
    Ok(rows)
}
