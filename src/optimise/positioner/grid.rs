//! **Stage 6a — the positioner's laws: the pose grids.** Grids of
//! positioner poses (tilt × turn, cells of 0.25–2°) propagated point to
//! point along a layer within the axes' speeds: the proof that no positioner
//! motion keeps `b` within the cone ([`unreachable_point`]), and a path
//! that does, relaxed, as a start for the law where the smooth starts fail.

use crate::math::{Matrix3, Vector3};
use crate::robot::positioner::{Positioner, PositionerJoints};

use super::problem::LawProblem;
use super::rate::required_rotation_rate;

/// The first point of a layer that no motion of the positioner reaches
/// with its build direction inside the cone, searched on a grid of poses of
/// `cell_rad` (rad) — a proof: `None` when some path may exist.
///
/// Reachable sets are propagated along the layer: the poses at point `m`
/// are those within `v_k·(t_m − t_a)` (each axis) of a pose reachable at an
/// anchor point `a ≤ m` that keep `b_m` within the cone. On the grid both
/// tests are relaxed so that no real path is lost: the angle of `b` from the
/// vertical moves by at most `|Δq7| + |Δq8|` when the axes move (a rotation
/// moves a direction by at most its angle, and the table's pose is two
/// rotations), so a cell is kept when its centre is within `cone + cell/2 +
/// cell/2` of the vertical; cells join when their centres are up to
/// `v·(t_m − t_a) + cell` apart per axis. The anchor moves on once the
/// slower bounded axis could have moved four cells, so that the cell of
/// slack added per anchor stays a quarter of the motion. The tilt
/// is searched within its travel, the turn modulo a whole turn (a superset
/// of any travel). An empty set at point `m` is then a proof for the layer,
/// up to nothing but rounding. `r0`: `base_from_positioner`'s rotation; `b`
/// in the table frame; `dt` the step times (s).
pub fn unreachable_point(
    positioner: &Positioner,
    r0: &Matrix3,
    b: &[Vector3],
    dt: &[f64],
    cone_rad: f64,
    cell_rad: f64,
) -> Option<usize> {
    let l7 = positioner.limits[0];
    let grid = PoseGrid::new(r0, l7.lower_rad, l7.upper_rad, cell_rad);
    let (n7, n8, h7, h8) = (grid.n7, grid.n8, grid.h7, grid.h8);
    let min_cos = (cone_rad + 0.5 * (h7 + h8)).min(std::f64::consts::PI).cos();
    // the set reachable at the anchor point, dilated by the motion since
    // (one cell of slack per anchor, re-anchored every 4 cells of motion of
    // the slower bounded axis, so that the slack stays a quarter at most)
    let mut anchor = vec![true; n7 * n8];
    let mut t_anchor = 0.0;
    let mut t = 0.0;
    let mut reach = vec![true; n7 * n8];
    // the anchor's reached tilt rows, first and last
    let mut band: (usize, usize) = (0, n7 - 1);
    let mut scratch = Dilation::new(&grid);
    let (v7, v8) = (positioner.max_speed_rad_s[0], positioner.max_speed_rad_s[1]);
    for (m, bm) in b.iter().enumerate() {
        if m > 0 {
            t += dt[m];
            let span = t - t_anchor;
            let cells = |v: f64, h: f64| -> usize {
                if v.is_finite() {
                    ((v * span + h) / h).floor() as usize
                } else {
                    usize::MAX
                }
            };
            scratch.dilate(
                &grid,
                &anchor,
                band,
                cells(v7, h7),
                cells(v8, h8),
                &mut reach,
            );
        }
        let Some(rows) = grid.keep_within(&mut reach, bm, min_cos) else {
            return Some(m);
        };
        let moved = |v: f64, h: f64| !v.is_finite() || v * (t - t_anchor) >= 4.0 * h;
        if m == 0 || (moved(v7, h7) && moved(v8, h8)) {
            anchor.copy_from_slice(&reach);
            band = rows;
            t_anchor = t;
        }
    }
    None
}

/// A grid of positioner poses: tilt rows of `h7` over the tilt's travel
/// (a whole turn where it is unlimited), turn columns of `h8` over a whole
/// turn (periodic: a superset of any travel), each cell stood for by its
/// centre. Cell `(i, j)` is index `i·n8 + j`.
struct PoseGrid {
    n7: usize,
    n8: usize,
    /// Tilt of row 0's lower edge (rad).
    lo7: f64,
    h7: f64,
    h8: f64,
    /// Per row, the world's up turned back by the row's tilt ([`tilted_back`]).
    tilted: Vec<Vector3>,
    /// Per column, the sine and cosine of its turn.
    turns: Vec<(f64, f64)>,
}

impl PoseGrid {
    /// Cells of at most `cell_rad` over the tilt travel `lo..hi` (rad);
    /// `r0`: `base_from_positioner`'s rotation.
    fn new(r0: &Matrix3, lo: f64, hi: f64, cell_rad: f64) -> Self {
        use std::f64::consts::{PI, TAU};
        let (lo7, hi7) = if lo.is_finite() && hi.is_finite() && hi > lo {
            (lo, hi)
        } else {
            (-PI, PI)
        };
        let n7 = (((hi7 - lo7) / cell_rad).ceil() as usize).max(1);
        let h7 = (hi7 - lo7) / n7 as f64;
        let n8 = ((TAU / cell_rad).ceil() as usize).max(1);
        let h8 = TAU / n8 as f64;
        // up in the positioner frame, turned back by each tilt: b_w·z = (Ry(−q7)·up)·(Rz(q8)·b)
        let up = r0.transpose() * Vector3::z();
        PoseGrid {
            n7,
            n8,
            lo7,
            h7,
            h8,
            tilted: (0..n7)
                .map(|i| {
                    let (s, c) = (lo7 + (i as f64 + 0.5) * h7).sin_cos();
                    tilted_back(&up, s, c)
                })
                .collect(),
            turns: (0..n8).map(|j| ((j as f64 + 0.5) * h8).sin_cos()).collect(),
        }
    }

    /// The joints at cell `(i, j)`'s centre (rad).
    fn pose(&self, i: usize, j: usize) -> PositionerJoints {
        [
            self.lo7 + (i as f64 + 0.5) * self.h7,
            (j as f64 + 0.5) * self.h8,
        ]
    }

    /// `b`'s cosine with the vertical at cell `(i, j)` (`b` table frame).
    fn up_cos(&self, b: &Vector3, i: usize, j: usize) -> f64 {
        let (s, c) = self.turns[j];
        self.tilted[i].dot(&turned(b, s, c))
    }

    /// Clears the cells of `set` where `b` is further than `min_cos` from
    /// the vertical; the first and last rows left, `None` when none is.
    fn keep_within(&self, set: &mut [bool], b: &Vector3, min_cos: f64) -> Option<(usize, usize)> {
        let n8 = self.n8;
        let mut rows = None;
        for (i, tilted) in self.tilted.iter().enumerate() {
            let row = &mut set[i * n8..(i + 1) * n8];
            if !row.contains(&true) {
                continue;
            }
            let mut any = false;
            for (cell, (s, c)) in row.iter_mut().zip(&self.turns) {
                if *cell {
                    *cell = tilted.dot(&turned(b, *s, *c)) >= min_cos;
                    any |= *cell;
                }
            }
            if any {
                rows = Some(rows.map_or((i, i), |(lo, _): (usize, usize)| (lo, i)));
            }
        }
        rows
    }
}

/// Scratch of [`Dilation::dilate`].
struct Dilation {
    /// The source dilated along the turn.
    next: Vec<bool>,
    /// Prefix counts along a row.
    count: Vec<usize>,
    /// Set cells per column within the tilt's window.
    columns: Vec<u32>,
}

impl Dilation {
    fn new(grid: &PoseGrid) -> Self {
        Dilation {
            next: vec![false; grid.n7 * grid.n8],
            count: Vec::with_capacity(3 * grid.n8 + 1),
            columns: Vec::with_capacity(grid.n8),
        }
    }

    /// `out` ← the cells within `d7` rows and `d8` columns (the turn
    /// periodic) of a set cell of `src`, whose set cells lie in the rows
    /// `band` (first, last): the turn's window by prefix counts along each
    /// row, then the tilt's by running counts per column, row after row.
    fn dilate(
        &mut self,
        grid: &PoseGrid,
        src: &[bool],
        band: (usize, usize),
        d7: usize,
        d8: usize,
        out: &mut [bool],
    ) {
        let (n7, n8) = (grid.n7, grid.n8);
        let (next, count, columns) = (&mut self.next, &mut self.count, &mut self.columns);
        let (lo, hi) = band;
        let (out_lo, out_hi) = (lo.saturating_sub(d7), hi.saturating_add(d7).min(n7 - 1));
        out[..out_lo * n8].fill(false);
        out[(out_hi + 1) * n8..].fill(false);
        for i in lo..=hi {
            let row = &src[i * n8..(i + 1) * n8];
            let dilated = &mut next[i * n8..(i + 1) * n8];
            if !row.contains(&true) || d8 >= n8 / 2 {
                let any = row.contains(&true);
                dilated.fill(any);
                continue;
            }
            count.clear();
            count.push(0);
            for k in 0..3 * n8 {
                let c = count[k] + usize::from(row[k % n8]);
                count.push(c);
            }
            for (j, cell) in dilated.iter_mut().enumerate() {
                // cells j − d8 ..= j + d8, shifted by one turn
                let (a, z) = (j + n8 - d8, j + n8 + d8 + 1);
                *cell = count[z] > count[a];
            }
        }
        // rows max(i − d7, lo) ..= min(i + d7, hi) counted per column: never
        // empty, as out_lo ..= out_hi is the band widened by d7
        columns.clear();
        columns.resize(n8, 0);
        let (mut entered, mut left) = (lo, lo);
        for i in out_lo..=out_hi {
            let last = i.saturating_add(d7).min(hi);
            while entered <= last {
                let row = &next[entered * n8..(entered + 1) * n8];
                for (c, x) in columns.iter_mut().zip(row) {
                    *c += u32::from(*x);
                }
                entered += 1;
            }
            let first = i.saturating_sub(d7).max(lo);
            while left < first {
                let row = &next[left * n8..(left + 1) * n8];
                for (c, x) in columns.iter_mut().zip(row) {
                    *c -= u32::from(*x);
                }
                left += 1;
            }
            for (o, c) in out[i * n8..(i + 1) * n8].iter_mut().zip(columns.iter()) {
                *o = *c > 0;
            }
        }
    }
}

/// The world's up in the table frame's tilt-turned coordinates of the
/// pose grids: `up` (the vertical in the positioner frame) turned back by a
/// tilt whose sine and cosine are `s`, `c` (`Ry(−q7)·up`). With [`turned`],
/// `b` is within the cone at `(q7, q8)` where their dot product is at least
/// the cone's cosine.
fn tilted_back(up: &Vector3, s: f64, c: f64) -> Vector3 {
    Vector3::new(c * up.x - s * up.z, up.y, s * up.x + c * up.z)
}

/// `b` (table frame) turned by a turn whose sine and cosine are `s`, `c`
/// (`Rz(q8)·b`).
fn turned(b: &Vector3, s: f64, c: f64) -> Vector3 {
    Vector3::new(c * b.x - s * b.y, s * b.x + c * b.y, b.z)
}

/// Cells of motion the slower axis makes in one of a layer's short steps
/// (its tenth shortest percentile) on [`grid_path`]'s grid: the rounding of
/// each step's motion to whole cells is then a small share of it.
const GRID_PATH_STEP_CELLS: f64 = 8.0;

/// Bounds of [`grid_path`]'s cell (deg).
const GRID_PATH_CELL_DEG: (f64, f64) = (0.25, 2.0);

/// Most cells [`grid_path`] keeps in memory, over all points (one bit
/// each, 50 MB): the cell grows past [`GRID_PATH_CELL_DEG`]'s lower bound
/// to stay under it.
const GRID_PATH_MAX_CELLS: f64 = 4e8;

/// Shares of the cone [`grid_path`] tries to keep `b` within, in order
/// (unitless): first the whole cone (where no path keeps it, none is
/// looked for further), then with room for the law's fit, the largest
/// room first.
const GRID_PATH_CONE_SHARES: [f64; 3] = [1.0, 0.8, 0.9];

/// A path of positioner joints (rad, one per point of the layer, on the
/// centres of a grid of poses) that keeps `b` within the cone at every
/// point and moves each axis within its speed between them, found by
/// propagating the poses reachable from point to point and following them
/// back from the last point, each step the least range-weighted move (the
/// path holds still where it can), then relaxed ([`relax`]). The grid's
/// cell is set by the layer's short steps ([`GRID_PATH_STEP_CELLS`]); each
/// axis moves at each step the whole cells its speed allows (an inner
/// approximation: the path between cell centres keeps every speed). The
/// cone is tried whole, then with room ([`GRID_PATH_CONE_SHARES`]). `None`
/// where the grid holds no path. A start for the law
/// ([`PositionerSeed::Grid`](super::PositionerSeed::Grid)), fitted and solved; where no fit keeps the
/// constraints, the path itself is a law (it keeps them at every point).
pub(super) fn grid_path(pb: &LawProblem) -> Option<Vec<PositionerJoints>> {
    let n = pb.b.len();
    if n == 0 {
        return None;
    }
    let (v7, v8) = (pb.max_speed[0], pb.max_speed[1]);
    let mut steps: Vec<f64> = pb.dt.iter().skip(1).copied().filter(|d| *d > 0.0).collect();
    steps.sort_by(f64::total_cmp);
    let short = steps.get(steps.len() / 10).copied().unwrap_or(0.0);
    let slow = v7.min(v8) * short;
    let (min_cell, max_cell) = (
        GRID_PATH_CELL_DEG.0.to_radians(),
        GRID_PATH_CELL_DEG.1.to_radians(),
    );
    let mut cell = if slow.is_finite() && slow > 0.0 {
        (slow / GRID_PATH_STEP_CELLS).clamp(min_cell, max_cell)
    } else {
        max_cell
    };
    let tilt_range = if pb.lower[0].is_finite() && pb.upper[0].is_finite() {
        (pb.upper[0] - pb.lower[0]).max(0.0)
    } else {
        std::f64::consts::TAU
    };
    if !(tilt_range > 0.0) {
        return None;
    }
    // the cells of every point within memory
    let area = tilt_range * std::f64::consts::TAU * n as f64;
    cell = cell.max((area / GRID_PATH_MAX_CELLS).sqrt());
    let grid = PoseGrid::new(&pb.r0, pb.lower[0], pb.upper[0], cell);
    // each axis's whole cells of motion within its speed at each step
    let moves: Vec<(usize, usize)> = pb
        .dt
        .iter()
        .map(|dt| {
            let step = |v: f64, h: f64, cap: usize| -> usize {
                if v.is_finite() {
                    ((v * dt / h).floor() as usize).min(cap)
                } else {
                    cap
                }
            };
            (step(v7, grid.h7, grid.n7), step(v8, grid.h8, grid.n8))
        })
        .collect();
    let reach = |share: f64| -> Option<Vec<Packed>> {
        let min_cos = (share * pb.cone).cos();
        let mut sets: Vec<Packed> = Vec::with_capacity(n);
        let mut set = vec![true; grid.n7 * grid.n8];
        let mut prev = vec![false; grid.n7 * grid.n8];
        let mut band = (0, grid.n7 - 1);
        let mut scratch = Dilation::new(&grid);
        for (m, b) in pb.b.iter().enumerate() {
            if m > 0 {
                std::mem::swap(&mut set, &mut prev);
                let (d7, d8) = moves[m];
                scratch.dilate(&grid, &prev, band, d7, d8, &mut set);
            }
            band = grid.keep_within(&mut set, b, min_cos)?;
            sets.push(Packed::of(&set, band, grid.n8));
        }
        Some(sets)
    };
    let mut sets = reach(GRID_PATH_CONE_SHARES[0])?;
    let mut share = GRID_PATH_CONE_SHARES[0];
    for s in &GRID_PATH_CONE_SHARES[1..] {
        if let Some(r) = reach(*s) {
            (sets, share) = (r, *s);
            break;
        }
    }
    // back from the last point: its cell nearest the vertical, then at each
    // point the reachable cell the least weighted move away
    let n8 = grid.n8;
    let weight = |g: f64| {
        if g > 0.0 {
            g
        } else {
            1.0 / std::f64::consts::TAU
        }
    };
    let (w7, w8) = (weight(pb.gamma[0]) * grid.h7, weight(pb.gamma[1]) * grid.h8);
    let last = (0..grid.n7 * n8)
        .filter(|&k| sets[n - 1].has(k))
        .max_by(|&a, &b| {
            let up = |k: usize| grid.up_cos(&pb.b[n - 1], k / n8, k % n8);
            up(a).total_cmp(&up(b))
        })?;
    let mut cells = vec![(last / n8, last % n8); n];
    for m in (1..n).rev() {
        let (i, j) = cells[m];
        let (d7, d8) = moves[m];
        let d8 = d8.min(n8 / 2);
        let mut best = (f64::INFINITY, (i, j));
        for ii in i.saturating_sub(d7)..=(i + d7).min(grid.n7 - 1) {
            for dj in -(d8 as isize)..=d8 as isize {
                let jj = (j as isize + dj).rem_euclid(n8 as isize) as usize;
                if sets[m - 1].has(ii * n8 + jj) {
                    let cost = w7 * ii.abs_diff(i) as f64 + w8 * dj.unsigned_abs() as f64;
                    if cost < best.0 {
                        best = (cost, (ii, jj));
                    }
                }
            }
        }
        // the sets are the reachable ones: a predecessor always exists
        cells[m - 1] = best.1;
    }
    // the turn unwrapped along the path
    let mut joints: Vec<PositionerJoints> = Vec::with_capacity(n);
    for &(i, j) in &cells {
        let mut q = grid.pose(i, j);
        if let Some(prev) = joints.last() {
            q[1] += ((prev[1] - q[1]) / std::f64::consts::TAU).round() * std::f64::consts::TAU;
        }
        joints.push(q);
    }
    relax(pb, &mut joints, share * pb.cone);
    Some(joints)
}

/// A set of a [`PoseGrid`]'s cells, one bit each, over the rows it holds.
struct Packed {
    /// First cell of the first row held.
    from: usize,
    /// One past the last row's last cell.
    to: usize,
    bits: Vec<u64>,
}

impl Packed {
    /// The cells of `set` in rows `band` (first, last) of `n8` cells.
    fn of(set: &[bool], band: (usize, usize), n8: usize) -> Self {
        let (from, to) = (band.0 * n8, (band.1 + 1) * n8);
        let mut bits = vec![0u64; (to - from).div_ceil(64)];
        for (k, _) in set[from..to].iter().enumerate().filter(|(_, x)| **x) {
            bits[k / 64] |= 1 << (k % 64);
        }
        Packed { from, to, bits }
    }

    /// Whether cell `k` is in the set.
    fn has(&self, k: usize) -> bool {
        k >= self.from && k < self.to && {
            let k = k - self.from;
            self.bits[k / 64] & (1 << (k % 64)) != 0
        }
    }
}

/// Whether the rate bound ([`required_rotation_rate`]) or the coarsest
/// two grids of [`GRID_CELLS_DEG`] prove that no positioner path keeps the
/// layer's `b` within the cone: then [`grid_path`], whose grid is finer
/// and whose approximation is inner, finds none either, and is not run.
pub(super) fn cheaply_proven(pb: &LawProblem) -> bool {
    let available = pb.max_speed[0] + pb.max_speed[1];
    required_rotation_rate(&pb.b, &pb.dt, pb.cone).0 > available
        || pb.unreachable_on(&GRID_CELLS_DEG[..2]).is_some()
}

/// Sweeps of [`relax`].
const RELAX_SWEEPS: usize = 200;

/// Smooths a path of positioner joints (rad per point) that keeps `b`
/// within `cone_rad` and each axis within its travel and speed, keeping
/// all three: each sweep moves every point towards the middle of its
/// neighbours (the whole way, else half, else a quarter) where the move
/// keeps them. A lazy grid path holds still, then moves at full speed; the
/// relaxed one spreads its motion.
fn relax(pb: &LawProblem, q: &mut [PositionerJoints], cone_rad: f64) {
    let n = q.len();
    if n < 3 {
        return;
    }
    let within = |m: usize, p: &PositionerJoints, q: &[PositionerJoints]| -> bool {
        if pb.tilt(m, p) > cone_rad {
            return false;
        }
        (0..2).all(|a| {
            let speed_ok = |k: usize, x: f64, y: f64| {
                !pb.max_speed[a].is_finite() || (y - x).abs() <= pb.max_speed[a] * pb.dt[k]
            };
            p[a] >= pb.lower[a]
                && p[a] <= pb.upper[a]
                && (m == 0 || speed_ok(m, q[m - 1][a], p[a]))
                && (m + 1 == n || speed_ok(m + 1, p[a], q[m + 1][a]))
        })
    };
    for _ in 0..RELAX_SWEEPS {
        let mut moved = false;
        for m in 0..n {
            let target: PositionerJoints = match m {
                0 => q[1],
                _ if m + 1 == n => q[m - 1],
                _ => std::array::from_fn(|a| 0.5 * (q[m - 1][a] + q[m + 1][a])),
            };
            for f in [1.0, 0.5, 0.25] {
                let p: PositionerJoints =
                    std::array::from_fn(|a| q[m][a] + f * (target[a] - q[m][a]));
                if within(m, &p, q) {
                    moved |= p != q[m];
                    q[m] = p;
                    break;
                }
            }
        }
        if !moved {
            break;
        }
    }
}

/// The grids of positioner poses [`unreachable_point`] searches, coarse to
/// fine (deg): each is tried where the coarser one proved nothing. The
/// 0.5° grid costs about 0.3 s a 400-point layer (16 times the coarsest),
/// the 0.25° grid about 4 times that; they run only on a layer whose law
/// failed and that no coarser grid proved.
pub(super) const GRID_CELLS_DEG: [f64; 4] = [2.0, 1.0, 0.5, 0.25];

impl LawProblem<'_> {
    /// The first point [`unreachable_point`] proves out of reach on the
    /// first of the grids `cells_deg` (deg) that proves one.
    pub(super) fn unreachable_on(&self, cells_deg: &[f64]) -> Option<usize> {
        cells_deg.iter().find_map(|cell_deg| {
            unreachable_point(
                &self.cell.positioner,
                &self.r0,
                &self.b,
                &self.dt,
                self.cone,
                cell_deg.to_radians(),
            )
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::{Point3, UnitVector3};
    use crate::optimise::positioner::options::PositionerOptions;
    use crate::optimise::positioner::problem::check;
    use crate::optimise::positioner::tests::cell;
    use crate::robot::cell::CellPoint;

    /// A ROBOWAM positioner with a ±135° tilt, and a layer of 51 points
    /// whose `b` tilts from −40° to +40° about the table's Y axis in 1 s
    /// (0.02 s a step).
    fn tilting_layer() -> (Positioner, Vec<Vector3>, Vec<f64>) {
        let mut pos = Positioner::robowam_nominal();
        pos.limits[0] = crate::robot::model::JointLimit {
            lower_rad: -135f64.to_radians(),
            upper_rad: 135f64.to_radians(),
        };
        let n = 51;
        let b: Vec<Vector3> = (0..n)
            .map(|m| {
                let a = (-40.0 + 80.0 * m as f64 / (n - 1) as f64).to_radians();
                Vector3::new(a.sin(), 0.0, a.cos())
            })
            .collect();
        (pos, b, vec![0.02; n])
    }

    /// The grid search proves what the rate bound cannot: `b` tilting from
    /// −40° to +40° about the table's Y axis in 1 s needs the tilt to move
    /// by 50° (the turn cannot lessen a tilt from the table normal), which a
    /// 10°/s tilt cannot, however fast the turn (the rate bound sees
    /// 10 + 1000°/s); at 100°/s a path exists and none is claimed.
    #[test]
    fn the_grid_search_proves_a_tilt_too_slow_for_the_layer() {
        let (mut pos, b, dt) = tilting_layer();
        let n = b.len();
        let cone = 15f64.to_radians();
        let r0 = Matrix3::identity();
        let cell = 1f64.to_radians();
        pos.max_speed_rad_s = [10f64.to_radians(), 1000f64.to_radians()];
        let (rate, _) = required_rotation_rate(&b, &dt, cone);
        assert!(rate < pos.max_speed_rad_s[0] + pos.max_speed_rad_s[1]);
        let at = unreachable_point(&pos, &r0, &b, &dt, cone, cell);
        assert!(at.is_some_and(|m| m > 0 && m < n), "{at:?}");
        pos.max_speed_rad_s = [100f64.to_radians(), 1000f64.to_radians()];
        assert_eq!(unreachable_point(&pos, &r0, &b, &dt, cone, cell), None);
    }

    /// The grid's relaxation keeps a cell of slack on the cone and a cell
    /// of motion per anchor, so a finer grid proves layers a coarser one
    /// cannot. The layer of the test above (`b` tilting from −40° to +40° in
    /// 1 s, a 15° cone): with a 14°/s tilt the 2° grid proves nothing and
    /// the 1° grid proves it; with 16°/s only the 0.5° and 0.25° grids do;
    /// on this layer the 0.5° grid is already tight (both prove 16.6°/s,
    /// neither 16.7°/s; the S-bend's layer 92 is one the 0.25° grid proves
    /// and the 0.5° grid does not, `tests/optimise/torch_carried.rs`). The
    /// proof falls where `b` crosses the table normal (point 25 of 51). The
    /// rate bound proves none of them (the turn's 1000°/s).
    #[test]
    fn a_finer_grid_proves_what_the_coarse_one_cannot() {
        let (mut pos, b, dt) = tilting_layer();
        let cone = 15f64.to_radians();
        let r0 = Matrix3::identity();
        let proven = |pos: &Positioner| -> Vec<bool> {
            GRID_CELLS_DEG
                .iter()
                .map(|c| unreachable_point(pos, &r0, &b, &dt, cone, c.to_radians()).is_some())
                .collect()
        };
        for (v7, expected) in [
            (14.0, [false, true, true, true]),
            (16.0, [false, false, true, true]),
            (16.6, [false, false, true, true]),
            (16.7, [false, false, false, false]),
            (18.0, [false, false, false, false]),
        ] {
            pos.max_speed_rad_s = [f64::to_radians(v7), 1000f64.to_radians()];
            let (rate, _) = required_rotation_rate(&b, &dt, cone);
            assert!(rate < pos.max_speed_rad_s[0] + pos.max_speed_rad_s[1]);
            assert_eq!(proven(&pos), expected, "tilt at {v7}°/s");
        }
    }

    /// The grid's path against the closed form of a layer whose `b` tilts
    /// from −40° to +40° about the tilt axis in 1 s (11 points, 0.1 s a
    /// step; the turn at 1000°/s aligns `b`'s azimuth for free). Within a
    /// 15° cone the tilt must be at least 25° at both ends and at most 15°
    /// where `b` crosses the table normal half way: 10° in 0.5 s, 20°/s.
    /// At 25°/s the path keeps the cone, the travels and the speeds at
    /// every point (the law's own check); at 15°/s there is no path, and
    /// the proof's outer grid agrees.
    #[test]
    fn the_grids_path_keeps_every_constraint_where_the_closed_form_allows_one() {
        let mut c = cell(15.0);
        let n = 11;
        let points: Vec<CellPoint> = (0..n)
            .map(|m| {
                let a = (-40.0 + 8.0 * m as f64).to_radians();
                let b = UnitVector3::new_normalize(Vector3::new(a.sin(), 0.0, a.cos()));
                CellPoint {
                    position_mm: Point3::new(m as f64, 0.0, 0.0),
                    tool_axis: b,
                    build_direction: Some(b),
                    positioner: None,
                    travel_speed_mm_s: 10.0,
                }
            })
            .collect();
        let opts = PositionerOptions::default();
        c.positioner.max_speed_rad_s = [25f64.to_radians(), 1000f64.to_radians()];
        let pb = LawProblem::new(&c, &points, 0.0, &opts, &[]);
        let path = grid_path(&pb).expect("a path at 25°/s");
        assert_eq!(path.len(), n);
        assert!(
            check(&pb, &path).binding.is_none(),
            "{:?}",
            check(&pb, &path).binding
        );
        c.positioner.max_speed_rad_s = [15f64.to_radians(), 1000f64.to_radians()];
        let pb = LawProblem::new(&c, &points, 0.0, &opts, &[]);
        assert!(grid_path(&pb).is_none());
        let r0 = Matrix3::identity();
        let at = unreachable_point(
            &c.positioner,
            &r0,
            &pb.b,
            &pb.dt,
            pb.cone,
            0.25f64.to_radians(),
        );
        assert!(at.is_some(), "the outer grid proves 15°/s too slow");
    }

    /// Relaxing a path keeps what it kept and spreads its motion: on a
    /// layer whose `b` stays on the table normal (any tilt within 15° keeps
    /// the cone), a path that holds, then tilts 8° in one step, comes out
    /// with a fifth of the squared motion or less and every constraint
    /// kept.
    #[test]
    fn relaxing_a_path_keeps_its_constraints_and_spreads_its_motion() {
        let c = cell(15.0);
        let n = 41;
        let points: Vec<CellPoint> = (0..n)
            .map(|m| CellPoint {
                position_mm: Point3::new(m as f64, 0.0, 0.0),
                tool_axis: Vector3::z_axis(),
                build_direction: Some(Vector3::z_axis()),
                positioner: None,
                travel_speed_mm_s: 10.0,
            })
            .collect();
        let pb = LawProblem::new(&c, &points, 0.0, &PositionerOptions::default(), &[]);
        // tilt 0 → 8° in one step at the middle (within 90°/s · 0.1 s)
        let mut q: Vec<PositionerJoints> = (0..n)
            .map(|m| [if m < n / 2 { 0.0 } else { 8f64.to_radians() }, 0.0])
            .collect();
        assert!(check(&pb, &q).binding.is_none());
        let squared = |q: &[PositionerJoints]| -> f64 {
            q.windows(2).map(|w| (w[1][0] - w[0][0]).powi(2)).sum()
        };
        let before = squared(&q);
        relax(&pb, &mut q, pb.cone);
        assert!(
            check(&pb, &q).binding.is_none(),
            "{:?}",
            check(&pb, &q).binding
        );
        assert!(squared(&q) < 0.2 * before, "{} vs {before}", squared(&q));
    }
}
