//! `joints.csv`: one row per planned point, header
//! `layer,point,x,y,z,tx,ty,tz,rz_deg,j1,j2,j3,j4,j5,j6` (+ `e1,e2` with a
//! positioner) `,travel_speed_mm_s,bead_height_mm,bead,wire_feed_mm_s`. Position (mm) and tool
//! axis in the part frame, `R_Z` and joints in degrees, joints in the
//! robot's controller convention (FANUC J2/J3 for FANUC arms); a point
//! without a joint solution has empty joint cells. The last two columns are
//! the travel speed the program runs on the way to the point (mm/s) and the
//! bead height the plan asks for there (mm: the point's local distance to
//! the layer below, `Delta` on the first layer); every plan writes them, a
//! replanned one ([`crate::replan`]) with its corrected values. The `bead`
//! column numbers the beads of a layer: 0 for its first (or only) one, one
//! more at each split at a corner, whose point is written once in each of
//! the two beads ([`crate::optimise::split`]). The last column is the wire
//! feed speed the program runs on the way to the point (mm/s): the
//! process's, but where the plan slowed the torch down
//! ([`crate::optimise::slow`]), where it follows the speed so that the bead's
//! cross-section stays. Also reads such a file back (files without the wire
//! feed column, without it and the `bead` column, or without those and the
//! process columns, too).

use std::io::Write;

use crate::optimise::{LayerPoints, Plan};
use crate::util::decimal::{push_fixed, push_u64};

/// The header line without the positioner columns.
pub const HEADER: &str = "layer,point,x,y,z,tx,ty,tz,rz_deg,j1,j2,j3,j4,j5,j6";

/// The process columns, last on every line (after `e1,e2` when present).
pub const PROCESS_COLUMNS: &str = "travel_speed_mm_s,bead_height_mm";

/// The bead column, after the process columns.
pub const BEAD_COLUMN: &str = "bead";

/// The wire feed column, last on every line written (after the bead column).
pub const WIRE_FEED_COLUMN: &str = "wire_feed_mm_s";

/// Writes `plan`'s points (made from `layers`); `positioner` adds `e1,e2`;
/// `process[i][m]` is `[travel speed (mm/s), bead height (mm), wire feed
/// (mm/s)]` of point `m` of `layers[i]` (a missing entry writes empty cells).
/// Numbers with 6 decimals by the fixed-point formatter of
/// [`decimal`](crate::util::decimal) (within half a unit of the last digit of
/// the standard formatting), one row at a time into a reused buffer.
///
/// # Errors
/// I/O errors of `w`.
pub fn write_joints_csv(
    w: &mut dyn Write,
    layers: &[LayerPoints],
    plan: &Plan,
    positioner: bool,
    process: &[Vec<[f64; 3]>],
) -> std::io::Result<()> {
    write!(w, "{HEADER}")?;
    write!(w, "{}", if positioner { ",e1,e2" } else { "" })?;
    writeln!(w, ",{PROCESS_COLUMNS},{BEAD_COLUMN},{WIRE_FEED_COLUMN}")?;
    let mut row: Vec<u8> = Vec::with_capacity(256);
    for (i, (lp, l)) in layers.iter().zip(&plan.layers).enumerate() {
        for (m, (cp, pp)) in lp.points.iter().zip(&l.points).enumerate() {
            row.clear();
            let p = cp.position_mm;
            let t = cp.tool_axis;
            push_row(
                &mut row,
                &Row {
                    layer: lp.layer,
                    point: lp.first_point + m,
                    position_mm: [p.x, p.y, p.z],
                    tool_axis: [t.x, t.y, t.z],
                    rz_rad: pp.r_z,
                    joints_rad: pp.joints,
                    positioner_rad: if positioner {
                        Some(pp.positioner)
                    } else {
                        None
                    },
                    process: process.get(i).and_then(|l| l.get(m)).copied(),
                    bead: lp.bead,
                },
            );
            w.write_all(&row)?;
        }
    }
    Ok(())
}

/// The values of one row as planned (angles in rad).
struct Row {
    layer: usize,
    point: usize,
    position_mm: [f64; 3],
    tool_axis: [f64; 3],
    rz_rad: f64,
    joints_rad: Option<[f64; 6]>,
    /// `None`: no positioner columns; `Some(None)`: empty ones.
    positioner_rad: Option<Option<[f64; 2]>>,
    /// Travel speed (mm/s), bead height (mm) and wire feed (mm/s); `None`:
    /// empty cells.
    process: Option<[f64; 3]>,
    /// The bead within the layer.
    bead: usize,
}

/// Appends `r` as a line of `joints.csv` (degrees, 6 decimals).
fn push_row(out: &mut Vec<u8>, r: &Row) {
    push_u64(out, r.layer as u64);
    out.push(b',');
    push_u64(out, r.point as u64);
    for x in r.position_mm.iter().chain(&r.tool_axis) {
        out.push(b',');
        push_fixed(out, *x, 6);
    }
    out.push(b',');
    push_fixed(out, r.rz_rad.to_degrees(), 6);
    match r.joints_rad {
        Some(q) => {
            for v in q {
                out.push(b',');
                push_fixed(out, v.to_degrees(), 6);
            }
        }
        None => out.extend_from_slice(b",,,,,,"),
    }
    match r.positioner_rad {
        Some(Some(e)) => {
            for v in e {
                out.push(b',');
                push_fixed(out, v.to_degrees(), 6);
            }
        }
        Some(None) => out.extend_from_slice(b",,"),
        None => {}
    }
    let process = r.process.filter(|v| v.iter().all(|x| x.is_finite()));
    match process {
        Some(v) => {
            for x in &v[..2] {
                out.push(b',');
                push_fixed(out, *x, 6);
            }
        }
        None => out.extend_from_slice(b",,"),
    }
    out.push(b',');
    push_u64(out, r.bead as u64);
    out.push(b',');
    if let Some(v) = process {
        push_fixed(out, v[2], 6);
    }
    out.push(b'\n');
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
    /// Travel speed on the way to the point (mm/s); `None` when the cell is
    /// empty or the file has no process columns.
    pub travel_speed_mm_s: Option<f64>,
    /// Bead height asked for at the point (mm); `None` as above.
    pub bead_height_mm: Option<f64>,
    /// Wire feed speed on the way to the point (mm/s); `None` when the cell
    /// is empty or the file has no wire feed column.
    pub wire_feed_mm_s: Option<f64>,
    /// The bead within the layer (0 for its first, one more at each split
    /// at a corner; 0 when the file has no `bead` column).
    pub bead: usize,
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
    let (header, with_wire) = match lines.next() {
        Some((_, h)) => match h.strip_suffix(&format!(",{WIRE_FEED_COLUMN}")) {
            Some(rest) => (Some(rest), true),
            None => (Some(h), false),
        },
        None => (None, false),
    };
    let (header, with_bead) = match header {
        Some(h) => match h.strip_suffix(&format!(",{BEAD_COLUMN}")) {
            Some(rest) => (Some(rest), true),
            None => (Some(h), false),
        },
        None => (None, false),
    };
    let (header, with_process) = match header {
        Some(h) => match h.strip_suffix(&format!(",{PROCESS_COLUMNS}")) {
            Some(rest) => (rest, true),
            None => (h, false),
        },
        None => ("", false),
    };
    let positioner = match header {
        h if h == HEADER => false,
        h if h.strip_suffix(",e1,e2") == Some(HEADER) => true,
        _ => {
            return Err(err(
                1,
                format!("expected the header `{HEADER}` (with `,e1,e2` for a positioner), then `,{PROCESS_COLUMNS},{BEAD_COLUMN},{WIRE_FEED_COLUMN}`"),
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
        .chain(if with_process {
            PROCESS_COLUMNS.split(',').collect::<Vec<_>>()
        } else {
            Vec::new()
        })
        .chain(with_bead.then_some(BEAD_COLUMN))
        .chain(with_wire.then_some(WIRE_FEED_COLUMN))
        .collect();
    let process_at = 15 + if positioner { 2 } else { 0 };
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
            bead: if with_bead {
                index(names.len() - 1 - usize::from(with_wire))?
            } else {
                0
            },
            wire_feed_mm_s: if with_wire {
                num(names.len() - 1)?
            } else {
                None
            },
            travel_speed_mm_s: if with_process { num(process_at)? } else { None },
            bead_height_mm: if with_process {
                num(process_at + 1)?
            } else {
                None
            },
        });
    }
    Ok(rows)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The row as the first version wrote it, with the standard float
    /// formatting (`{:.6}` of the values in mm and degrees).
    fn standard(r: &Row) -> String {
        let mut s = format!("{},{}", r.layer, r.point);
        for x in r.position_mm.iter().chain(&r.tool_axis) {
            s += &format!(",{x:.6}");
        }
        s += &format!(",{:.6}", r.rz_rad.to_degrees());
        match r.joints_rad {
            Some(q) => q
                .iter()
                .for_each(|v| s += &format!(",{:.6}", v.to_degrees())),
            None => s += ",,,,,,",
        }
        match r.positioner_rad {
            Some(Some(e)) => e
                .iter()
                .for_each(|v| s += &format!(",{:.6}", v.to_degrees())),
            Some(None) => s += ",,",
            None => {}
        }
        match r.process {
            Some(v) => v[..2].iter().for_each(|x| s += &format!(",{x:.6}")),
            None => s += ",,",
        }
        s += &format!(",{}", r.bead);
        match r.process {
            Some(v) => s += &format!(",{:.6}", v[2]),
            None => s += ",",
        }
        s
    }

    #[test]
    fn rows_match_the_standard_formatting_within_half_a_last_digit() {
        // a deterministic spread of positions (m-sized parts), unit axes and
        // angles of both signs, with and without joints and positioner
        let mut x = 0.271_828_314_f64;
        let mut next = |scale: f64| {
            x = (x * 9.7 + 0.377).fract();
            (2.0 * x - 1.0) * scale
        };
        let mut differing = 0;
        for i in 0..20_000 {
            let r = Row {
                layer: i / 100,
                point: i % 100,
                position_mm: [next(2000.0), next(2000.0), next(1500.0)],
                tool_axis: [next(1.0), next(1.0), next(1.0)],
                rz_rad: next(7.0),
                joints_rad: (i % 7 != 3).then(|| std::array::from_fn(|_| next(6.5))),
                positioner_rad: match i % 3 {
                    0 => None,
                    1 => Some(None),
                    _ => Some(Some([next(3.2), next(6.4)])),
                },
                process: (i % 5 != 2)
                    .then(|| [next(20.0).abs(), next(3.0).abs(), next(90.0).abs()]),
                bead: i % 3,
            };
            let mut ours = Vec::new();
            push_row(&mut ours, &r);
            let ours = String::from_utf8(ours).unwrap();
            assert!(ours.ends_with('\n'));
            let ours = ours.trim_end();
            let std = standard(&r);
            if ours == std {
                continue;
            }
            differing += 1;
            let (a, b): (Vec<&str>, Vec<&str>) =
                (ours.split(',').collect(), std.split(',').collect());
            assert_eq!(a.len(), b.len(), "{ours}\n{std}");
            for (p, q) in a.iter().zip(&b) {
                if p == q {
                    continue;
                }
                let (p, q): (f64, f64) = (p.parse().unwrap(), q.parse().unwrap());
                // half a unit of the 6th decimal each way, plus the rounding
                // of the scaled value (one part in 2^52 of it)
                assert!(
                    (p - q).abs() <= 1e-6 * 1.000_001 + q.abs() * 2.3e-16,
                    "{ours}\n{std}"
                );
            }
        }
        // the two formatters differ only on rare ties (not everywhere)
        assert!(differing < 200, "{differing} rows differ");
    }

    #[test]
    fn empty_cells_and_read_back() {
        let rows = [
            Row {
                layer: 2,
                point: 7,
                position_mm: [1045.747, -630.155, 0.5],
                tool_axis: [0.0, -0.0, 1.0],
                rz_rad: -std::f64::consts::FRAC_PI_2,
                joints_rad: None,
                positioner_rad: Some(None),
                process: None,
                bead: 0,
            },
            Row {
                layer: 2,
                point: 8,
                position_mm: [1.0, 2.0, 3.0],
                tool_axis: [0.6, 0.0, 0.8],
                rz_rad: 0.25,
                joints_rad: Some([0.1, -0.2, 0.3, -0.4, 0.5, -3.0]),
                positioner_rad: Some(Some([-0.5, 1.5])),
                process: Some([8.5, 1.75, 61.25]),
                bead: 1,
            },
        ];
        let mut text =
            format!("{HEADER},e1,e2,{PROCESS_COLUMNS},{BEAD_COLUMN},{WIRE_FEED_COLUMN}\n")
                .into_bytes();
        for r in &rows {
            push_row(&mut text, r);
        }
        let text = String::from_utf8(text).unwrap();
        assert!(
            text.contains("\n2,7,1045.747000,-630.155000,0.500000,0.000000,0.000000,1.000000,-90.000000,,,,,,,,,,,0,\n"),
            "{text}"
        );
        let back = read_joints_csv(&text, "joints.csv").unwrap();
        assert_eq!(back.len(), 2);
        assert_eq!(back[0].joints_deg, None);
        assert_eq!(back[0].positioner_deg, None);
        let j = back[1].joints_deg.unwrap();
        assert!((j[5] + 3f64.to_degrees()).abs() < 1e-6, "{j:?}");
        assert!((back[1].positioner_deg.unwrap()[1] - 1.5f64.to_degrees()).abs() < 1e-6);
        assert_eq!(back[0].travel_speed_mm_s, None);
        assert_eq!(back[1].travel_speed_mm_s, Some(8.5));
        assert_eq!(back[1].bead_height_mm, Some(1.75));
        assert_eq!((back[0].bead, back[1].bead), (0, 1));
        assert_eq!(back[0].wire_feed_mm_s, None);
        assert_eq!(back[1].wire_feed_mm_s, Some(61.25));
        // files written before the wire feed column, before the bead column,
        // and before the process columns, still read
        let without = |columns: usize| -> String {
            text.lines()
                .map(|l| {
                    let cells: Vec<&str> = l.split(',').collect();
                    cells[..cells.len() - columns].join(",") + "\n"
                })
                .collect()
        };
        let back = read_joints_csv(&without(1), "joints.csv").unwrap();
        assert_eq!(back[1].bead_height_mm, Some(1.75));
        assert_eq!(back[1].bead, 1);
        assert_eq!(back[1].wire_feed_mm_s, None);
        let back = read_joints_csv(&without(2), "joints.csv").unwrap();
        assert_eq!(back[1].bead_height_mm, Some(1.75));
        assert_eq!(back[1].bead, 0);
        let old = without(4);
        let back = read_joints_csv(&old, "joints.csv").unwrap();
        assert_eq!(back[1].bead_height_mm, None);
        assert!((back[1].positioner_deg.unwrap()[1] - 1.5f64.to_degrees()).abs() < 1e-6);
    }
}
