//! Splitting a program at a point limit [SPEC §8, thesis §3.1.2.1]:
//! controllers cap the positions of one program (15 000 on the FANUC
//! R-30iB Plus, ~500 on a Stäubli CS8), so a long path becomes numbered
//! sub-programs of at most `limit` points, called in order by a main program.
//!
//! **Cuts fall between beads only.** A bead (its approach point, its points
//! from arc start to arc end, its retract point) is never split across two
//! sub-programs: the arc would stay on while the controller leaves one
//! program and enters the next, and the motion blending into the next
//! program's first point is not defined there. Sub-programs are filled
//! greedily with whole beads, so there may be more than
//! `ceil(points / limit)` of them. A single bead longer than the limit is
//! refused ([`BeadTooLong`]) rather than cut inside: a cell operator raises
//! the limit or discretises the layer more coarsely, and the arc is never
//! switched by a program boundary.

use std::ops::Range;

use crate::program::{opens_bead, ArcFlag};

/// Default point limit of one program (FANUC R-30iB Plus).
pub const DEFAULT_POINT_LIMIT: usize = 15_000;

/// A bead with more points (approach and retract included) than the limit.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct BeadTooLong {
    /// Index of the bead's first point (its approach point, or its first
    /// bead point without one).
    pub first: usize,
    /// Its points, approach and retract included.
    pub len: usize,
}

/// The beads of a point sequence: index ranges `[start, end)`, each from an
/// approach point (or a bead start without one) to just before the next.
pub fn beads(arcs: &[ArcFlag]) -> Vec<Range<usize>> {
    let mut starts: Vec<usize> = (0..arcs.len())
        .filter(|&i| opens_bead(i.checked_sub(1).map(|k| arcs[k]), arcs[i]))
        .collect();
    if starts.first() != Some(&0) {
        starts.insert(0, 0);
    }
    if arcs.is_empty() {
        return Vec::new();
    }
    starts
        .iter()
        .enumerate()
        .map(|(k, &a)| a..starts.get(k + 1).copied().unwrap_or(arcs.len()))
        .collect()
}

/// Index ranges `[start, end)` cutting the points (their arc flags `arcs`)
/// into consecutive chunks of at most `limit` points, each made of whole
/// beads ([`beads`]), filled greedily (module doc). `limit = 0` is treated
/// as 1.
///
/// # Errors
/// [`BeadTooLong`] for the first bead longer than `limit`.
pub fn chunks(arcs: &[ArcFlag], limit: usize) -> Result<Vec<Range<usize>>, BeadTooLong> {
    let limit = limit.max(1);
    let mut out: Vec<Range<usize>> = Vec::new();
    for b in beads(arcs) {
        if b.len() > limit {
            return Err(BeadTooLong {
                first: b.start,
                len: b.len(),
            });
        }
        match out.last_mut() {
            Some(c) if c.len() + b.len() <= limit => c.end = b.end,
            _ => out.push(b),
        }
    }
    Ok(out)
}

/// Name of sub-program `k` (1-based) of `name`: `NAME_001`, `NAME_002`, ...
pub fn sub_name(name: &str, k: usize) -> String {
    format!("{name}_{k:03}")
}

#[cfg(test)]
mod tests {
    use super::*;
    use ArcFlag::*;

    /// Three beads of 4 points each (approach, start, end, retract) and one
    /// without approach and retract (start, on, end).
    fn arcs() -> Vec<ArcFlag> {
        let mut v = Vec::new();
        for _ in 0..3 {
            v.extend([Approach, Start, End, Retract]);
        }
        v.extend([Start, On, End]);
        v
    }

    #[test]
    fn cuts_fall_between_beads() {
        let a = arcs();
        assert_eq!(beads(&a), vec![0..4, 4..8, 8..12, 12..15]);
        assert_eq!(chunks(&a, 4).unwrap(), vec![0..4, 4..8, 8..12, 12..15]);
        // by count 0..7 would be the first chunk, but that cuts bead 2
        assert_eq!(chunks(&a, 7).unwrap(), vec![0..4, 4..8, 8..15]);
        assert_eq!(chunks(&a, 8).unwrap(), vec![0..8, 8..15]);
        assert_eq!(chunks(&a, 15).unwrap(), vec![0..15]);
        assert_eq!(chunks(&a, 3).unwrap_err(), BeadTooLong { first: 0, len: 4 });
        assert!(chunks(&[], 3).unwrap().is_empty());
    }
}
