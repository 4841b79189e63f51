//! Splitting a program at a point limit [SPEC §8, thesis §3.1.2.1]:
//! controllers cap the positions of one program (15 000 on the FANUC
//! R-30iB Plus, ~500 on a Stäubli CS8), so a long path becomes numbered
//! sub-programs of at most `limit` points, called in order by a main program.

use std::ops::Range;

/// Default point limit of one program (FANUC R-30iB Plus).
pub const DEFAULT_POINT_LIMIT: usize = 15_000;

/// Index ranges `[start, end)` cutting `n_points` points into
/// `ceil(n_points / limit)` consecutive chunks of at most `limit` points
/// (all full but the last). `limit = 0` is treated as 1.
pub fn chunks(n_points: usize, limit: usize) -> Vec<Range<usize>> {
    let limit = limit.max(1);
    (0..n_points.div_ceil(limit))
        .map(|k| k * limit..((k + 1) * limit).min(n_points))
        .collect()
}

/// Name of sub-program `k` (1-based) of `name`: `NAME_001`, `NAME_002`, ...
pub fn sub_name(name: &str, k: usize) -> String {
    format!("{name}_{k:03}")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn chunk_counts() {
        assert_eq!(chunks(10, 3), vec![0..3, 3..6, 6..9, 9..10]);
        assert_eq!(chunks(9, 3).len(), 3);
        assert!(chunks(0, 3).is_empty());
        assert_eq!(chunks(5, 15_000), vec![0..5]);
    }
}
