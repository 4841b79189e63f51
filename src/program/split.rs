//! Cutting a build into groups of layers that each fit a controller's
//! memory budget [SPEC §8, thesis §3.1.2.1; issue 32 item 3]: takes a
//! thinned [`Program`] and a [`Budget`] with a way to measure one
//! candidate group against it, and gives the bead ranges of the groups, each
//! turned into a complete [`Program`] by [`group_program`]: the same cell,
//! home and configuration, its beads' points, bead set-up and planned points.
//! The cell loads and runs the groups in turn (`NAME_P01`, `NAME_P02`, …):
//! one group is resident at a time, so each alone must fit.
//!
//! **Cuts fall between beads only** (one bead a layer): a bead (its approach
//! point, its points from arc start to arc end, its retract point) is never
//! split across two groups, so the arc is never switched by a program
//! boundary. Groups are filled greedily with whole beads, the longest run
//! of beads that still fits. A single bead that does not fit alone is
//! refused with the numbers ([`ProgramError::OverBudget`]).
//!
//! **What carries over between groups.** Each group starts and ends at the
//! cell's home (when it has one), so group `k + 1` starts where group `k`
//! ended; a group that ends on a bead followed by a transit's via points
//! ([`ArcFlag::Transit`], leading to the next group's first bead) leaves
//! them out and goes home from the bead's retract point. The positioner's turn is unchanged (the points keep their
//! unwound values). The payload in effect at a group's first bead is set
//! again before it, so that a group loaded after a restart carries the
//! right load; the interlayer dwell and interpass wait of that bead stay
//! (it is not the build's first bead).

use std::ops::Range;

use crate::program::{opens_bead, ArcFlag, Program, ProgramError};

/// Default FANUC budget: positions of every program resident at once
/// (R-30iB standard program space for one motion group; more needs the
/// R709 option; FANUC R-30iB operator's manual B-83284EN-2/05 ch. 29).
pub const DEFAULT_MAX_POSITIONS: usize = 15_000;

/// A controller's memory budget for one group: what is counted, its limit,
/// and the cell-file key that states it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Budget {
    /// The key in the cell file, e.g. `[program.fanuc] max_positions`.
    pub field: &'static str,
    /// The most a group may hold, in `unit`.
    pub limit: usize,
    /// What is counted, plural (`positions`, `bytes`).
    pub unit: &'static str,
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

/// The block of points of every bead of `program` ([`beads`]).
pub fn bead_blocks(program: &Program) -> Vec<Range<usize>> {
    let arcs: Vec<ArcFlag> = program.points.iter().map(|p| p.arc).collect();
    beads(&arcs)
}

/// Name of group `k` (1-based) of a build named `name`: `NAME_P01`,
/// `NAME_P02`, … (three digits from the 100th on).
pub fn group_name(name: &str, k: usize) -> String {
    format!("{name}_P{k:02}")
}

/// The build's name and the group's number (1-based) of a group name
/// ([`group_name`]), compared without case; `None` for another name.
pub fn parse_group_name(stem: &str) -> Option<(&str, usize)> {
    let at = stem.rfind(['_'])?;
    let (base, rest) = stem.split_at(at);
    let digits = rest[1..].strip_prefix(['P', 'p'])?;
    if base.is_empty() || digits.len() < 2 || !digits.bytes().all(|b| b.is_ascii_digit()) {
        return None;
    }
    let k: usize = digits.parse().ok()?;
    (k >= 1 && (digits.len() == 2 || !digits.starts_with('0'))).then_some((base, k))
}

/// The range of `program.planned` each bead's points land on: from the
/// planned point equal to its first bead point to the one equal to its
/// last, scanning forwards (thinned beads keep their first and last
/// planned points exactly). `None` when the program has no planned points
/// or they cannot be matched.
fn planned_ranges(program: &Program, blocks: &[Range<usize>]) -> Option<Vec<Range<usize>>> {
    if program.planned.is_empty() {
        return None;
    }
    let mut cursor = 0;
    let mut out = Vec::with_capacity(blocks.len());
    for b in blocks {
        let pts = &program.points[b.clone()];
        let first = pts.iter().find(|p| p.arc == ArcFlag::Start)?;
        let last = pts.iter().rev().find(|p| p.arc == ArcFlag::End)?;
        let s = cursor
            + program.planned[cursor..]
                .iter()
                .position(|q| q.position_mm == first.position_mm)?;
        let e = s + program.planned[s..]
            .iter()
            .position(|q| q.position_mm == last.position_mm)?;
        out.push(s..e + 1);
        cursor = e + 1;
    }
    Some(out)
}

/// Group `k` (1-based, name [`group_name`]) of `program`: its beads `beads`
/// (indices into [`bead_blocks`]) as a complete program — the same cell,
/// configuration and home; those beads' points, set-up and planned points;
/// the payload in effect before its first bead set again there (module
/// doc).
pub fn group_program(program: &Program, beads: Range<usize>, k: usize) -> Program {
    let blocks = bead_blocks(program);
    group_of(
        program,
        &blocks,
        planned_ranges(program, &blocks).as_deref(),
        beads,
        k,
    )
}

fn group_of(
    program: &Program,
    blocks: &[Range<usize>],
    planned: Option<&[Range<usize>]>,
    beads: Range<usize>,
    k: usize,
) -> Program {
    let mut points = blocks[beads.start].start..blocks[beads.end - 1].end;
    if beads.end < blocks.len() {
        // a transit's via points lead to the next group's first bead: this
        // group goes home from its last retract point instead
        while points.end > points.start && program.points[points.end - 1].arc == ArcFlag::Transit {
            points.end -= 1;
        }
    }
    let mut bead_setup = program
        .bead_setup
        .get(beads.clone())
        .map(<[_]>::to_vec)
        .unwrap_or_default();
    if let Some(first) = bead_setup.first_mut() {
        if first.payload.is_none() {
            first.payload = program.bead_setup[..beads.start]
                .iter()
                .rev()
                .find_map(|s| s.payload);
        }
    }
    let planned = planned.map_or_else(Vec::new, |r| {
        program.planned[r[beads.start].start..r[beads.end - 1].end].to_vec()
    });
    Program {
        name: group_name(&program.name, k),
        cell: program.cell.clone(),
        configuration: program.configuration,
        points: program.points[points].to_vec(),
        home: program.home,
        bead_setup,
        planned,
    }
}

/// The groups of `program` within `budget`, as bead ranges (indices into
/// [`bead_blocks`]) in build order: one range of every bead when the whole
/// program fits (`size(program)` ≤ `budget.limit`), else the longest runs
/// of whole beads whose group program ([`group_program`]) measures within
/// the limit (module doc). `size` measures a candidate group in
/// `budget.unit`; it is called O(log n) times per group.
///
/// # Errors
/// [`ProgramError::OverBudget`] naming the field, the layer and the
/// numbers when one bead alone does not fit; [`ProgramError::Mismatch`]
/// when `program.bead_setup` is neither empty nor one per bead; the errors
/// of `size`.
pub fn layer_groups(
    program: &Program,
    budget: &Budget,
    mut size: impl FnMut(&Program) -> Result<usize, ProgramError>,
) -> Result<Vec<Range<usize>>, ProgramError> {
    let blocks = bead_blocks(program);
    let n = blocks.len();
    if n == 0 || size(program)? <= budget.limit {
        #[allow(clippy::single_range_in_vec_init)] // one group: every bead
        return Ok(vec![0..n]);
    }
    // a set-up list that does not fit the beads: a group must not drop it
    // silently (the emitters refuse it when they measure the whole)
    if !program.bead_setup.is_empty() && program.bead_setup.len() != n {
        return Err(ProgramError::Mismatch {
            index: program.points.len(),
            reason: format!(
                "{} bead_setup entries for {n} beads",
                program.bead_setup.len()
            ),
        });
    }
    let planned = planned_ranges(program, &blocks);
    let mut fits = |beads: Range<usize>| -> Result<(bool, usize), ProgramError> {
        let g = group_of(program, &blocks, planned.as_deref(), beads, 1);
        let s = size(&g)?;
        Ok((s <= budget.limit, s))
    };
    let mut out = Vec::new();
    let mut s = 0;
    while s < n {
        let (ok, alone) = fits(s..s + 1)?;
        if !ok {
            return Err(ProgramError::OverBudget {
                field: budget.field,
                limit: budget.limit,
                unit: budget.unit,
                layer: program.points[blocks[s].start].layer,
                size: alone,
            });
        }
        // gallop: the largest e with s..e fitting lies in [good, bad)
        let (mut good, mut step) = (s + 1, 1);
        let mut bad = loop {
            let e = (good + step).min(n);
            if e == good {
                break n + 1;
            }
            if fits(s..e)?.0 {
                good = e;
                step *= 2;
            } else {
                break e;
            }
        };
        while bad - good > 1 {
            let mid = good + (bad - good) / 2;
            if fits(s..mid)?.0 {
                good = mid;
            } else {
                bad = mid;
            }
        }
        out.push(s..good);
        s = good;
    }
    Ok(out)
}

/// `program` cut into its groups within `budget` ([`layer_groups`]): the
/// program itself (unchanged, its own name) when it fits whole, else one
/// complete program per group, named `NAME_P01`, `NAME_P02`, …
///
/// # Errors
/// As [`layer_groups`].
pub fn split_to_budget(
    program: &Program,
    budget: &Budget,
    size: impl FnMut(&Program) -> Result<usize, ProgramError>,
) -> Result<Vec<Program>, ProgramError> {
    let groups = layer_groups(program, budget, size)?;
    if groups.len() <= 1 {
        return Ok(vec![program.clone()]);
    }
    let blocks = bead_blocks(program);
    let planned = planned_ranges(program, &blocks);
    Ok(groups
        .into_iter()
        .enumerate()
        .map(|(k, r)| group_of(program, &blocks, planned.as_deref(), r, k + 1))
        .collect())
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
    fn beads_are_blocks_between_openings() {
        let a = arcs();
        assert_eq!(beads(&a), vec![0..4, 4..8, 8..12, 12..15]);
        assert!(beads(&[]).is_empty());
    }

    #[test]
    fn group_names_round_trip() {
        assert_eq!(group_name("HEMI", 1), "HEMI_P01");
        assert_eq!(group_name("HEMI", 123), "HEMI_P123");
        for k in [1, 9, 10, 99, 100, 123] {
            assert_eq!(parse_group_name(&group_name("A_B", k)), Some(("A_B", k)));
        }
        assert_eq!(parse_group_name("hemi_p02"), Some(("hemi", 2)));
        for bad in [
            "HEMI",
            "HEMI_P1",
            "HEMI_P00",
            "HEMI_P012",
            "_P01",
            "HEMI_001",
            "HEMI_PX1",
        ] {
            assert_eq!(parse_group_name(bad), None, "{bad}");
        }
    }
}
