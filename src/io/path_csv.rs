//! `path.csv`: one row per path point, header
//! `layer,point,t,v,x,y,z,delta,nx,ny,nz,bx,by,bz,tx,ty,tz` (part frame, mm;
//! `delta` empty on the first layer; `n` surface normal, `b` build direction,
//! `t` tool axis). Also reads such a file back (for distance maps of paths
//! made elsewhere).

use crate::math::Point3;
use crate::path::{Layer, PathPoint};
use crate::toolaxis::LocalFrame;
use crate::util::decimal::{push_fixed, push_u64};
use std::io::Write;

/// The header line.
pub const HEADER: &str = "layer,point,t,v,x,y,z,delta,nx,ny,nz,bx,by,bz,tx,ty,tz";

/// Rows formatted per piece of a layer (one task of the parallel formatting).
const PIECE_ROWS: usize = 1024;
/// Pieces formatted at once before they are written (bounds the memory held:
/// 16 × 1024 rows of at most ~200 bytes, about 3 MB).
const PIECES_PER_BATCH: usize = 16;

/// Writes the rows of `layers` with their local frames.
///
/// The rows are formatted in parallel, in pieces of a thousand rows
/// (a bounded batch at a time), and written in order: the bytes do not
/// depend on the number of threads.
///
/// # Errors
/// I/O errors of `w`.
pub fn write_path_csv(
    w: &mut dyn Write,
    layers: &[Layer],
    frames: &[Vec<LocalFrame>],
) -> std::io::Result<()> {
    use rayon::prelude::*;
    writeln!(w, "{HEADER}")?;
    // (layer, first point, end point) of each piece, in file order.
    let pieces = layers
        .iter()
        .zip(frames)
        .enumerate()
        .flat_map(|(li, (l, f))| {
            let n = l.points.len().min(f.len());
            (0..n)
                .step_by(PIECE_ROWS)
                .map(move |a| (li, a, (a + PIECE_ROWS).min(n)))
        });
    let mut batch: Vec<(usize, usize, usize)> = Vec::with_capacity(PIECES_PER_BATCH);
    let mut buffers: Vec<Vec<u8>> = vec![Vec::new(); PIECES_PER_BATCH];
    let mut pieces = pieces.peekable();
    while pieces.peek().is_some() {
        batch.clear();
        batch.extend(pieces.by_ref().take(PIECES_PER_BATCH));
        buffers
            .par_iter_mut()
            .zip(batch.par_iter())
            .for_each(|(buf, &(li, a, b))| {
                buf.clear();
                buf.reserve(200 * (b - a));
                push_rows(buf, li, a..b, &layers[li], &frames[li]);
            });
        for buf in &buffers[..batch.len()] {
            w.write_all(buf)?;
        }
    }
    Ok(())
}

/// Appends the rows of points `range` of layer `li` to `out`, numbers by
/// the fast fixed-point formatter (`decimal`): the standard float
/// formatting was most of the time of writing a million-point path.
fn push_rows(
    out: &mut Vec<u8>,
    li: usize,
    range: std::ops::Range<usize>,
    layer: &Layer,
    frames: &[LocalFrame],
) {
    for pi in range {
        let (p, f) = (&layer.points[pi], &frames[pi]);
        push_u64(out, li as u64);
        out.push(b',');
        push_u64(out, pi as u64);
        for (x, d) in [
            (p.t, 12),
            (p.v, 12),
            (p.position.x, 6),
            (p.position.y, 6),
            (p.position.z, 6),
        ] {
            out.push(b',');
            push_fixed(out, x, d);
        }
        out.push(b',');
        if let Some(delta) = p.delta {
            push_fixed(out, delta, 9);
        }
        for v in [f.normal, f.build, f.tool] {
            for x in v.iter() {
                out.push(b',');
                push_fixed(out, *x, 9);
            }
        }
        out.push(b'\n');
    }
}

/// Error reading a path CSV, naming the line.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{file}, line {line}: {reason}")]
pub struct PathCsvError {
    /// The file.
    pub file: String,
    /// 1-based line number.
    pub line: usize,
    /// What is wrong.
    pub reason: String,
}

/// Reads layers from CSV text with at least the columns `layer`, `x`, `y`,
/// `z` (any order; `t`, `v` used when present). Rows of one layer must be
/// consecutive. A layer is taken as closed when its last point is no further
/// from its first than 1.5 × its longest segment.
///
/// # Errors
/// [`PathCsvError`] naming the line: missing column, unparsable or
/// non-finite number, a layer number going back.
pub fn read_path_csv(text: &str, file: &str) -> Result<Vec<Layer>, PathCsvError> {
    let err = |line: usize, reason: String| PathCsvError {
        file: file.to_string(),
        line,
        reason,
    };
    let mut lines = text.lines().enumerate();
    let (_, header) = lines.next().ok_or_else(|| err(1, "empty file".into()))?;
    let cols: Vec<&str> = header.split(',').map(str::trim).collect();
    let find = |name: &str| cols.iter().position(|c| *c == name);
    let (Some(cl), Some(cx), Some(cy), Some(cz)) = (find("layer"), find("x"), find("y"), find("z"))
    else {
        return Err(err(
            1,
            format!("header must name layer, x, y, z; got `{header}`"),
        ));
    };
    let (ct, cv) = (find("t"), find("v"));
    let mut layers: Vec<(usize, Vec<PathPoint>)> = Vec::new();
    for (i, line) in lines {
        let n = i + 1;
        if line.trim().is_empty() {
            continue;
        }
        let f: Vec<&str> = line.split(',').collect();
        let num = |c: usize, name: &str| -> Result<f64, PathCsvError> {
            let s = f
                .get(c)
                .ok_or_else(|| err(n, format!("missing column `{name}`")))?
                .trim();
            let x: f64 = s
                .parse()
                .map_err(|_| err(n, format!("`{name}` = `{s}` is not a number")))?;
            if x.is_finite() {
                Ok(x)
            } else {
                Err(err(n, format!("`{name}` is not finite")))
            }
        };
        let layer = num(cl, "layer")?;
        if layer < 0.0 || layer.fract() != 0.0 {
            return Err(err(
                n,
                format!("layer `{layer}` is not a non-negative integer"),
            ));
        }
        let layer = layer as usize;
        let p = PathPoint {
            t: ct.map(|c| num(c, "t")).transpose()?.unwrap_or(f64::NAN),
            v: cv.map(|c| num(c, "v")).transpose()?.unwrap_or(f64::NAN),
            position: Point3::new(num(cx, "x")?, num(cy, "y")?, num(cz, "z")?),
            delta: None,
        };
        match layers.last_mut() {
            Some((l, pts)) if *l == layer => pts.push(p),
            Some((l, _)) if *l > layer => {
                return Err(err(n, format!("layer {layer} after layer {l}")))
            }
            _ => layers.push((layer, vec![p])),
        }
    }
    Ok(layers
        .into_iter()
        .enumerate()
        .map(|(slice, (_, points))| {
            let longest = points
                .windows(2)
                .map(|w| (w[1].position - w[0].position).norm())
                .fold(0.0, f64::max);
            let gap = match (points.first(), points.last()) {
                (Some(a), Some(b)) => (a.position - b.position).norm(),
                _ => 0.0,
            };
            let closed = points.len() > 2 && gap <= 1.5 * longest;
            Layer {
                slice,
                points,
                closed,
            }
        })
        .collect())
}
