//! Slicing perpendicular to the guide [SPEC §3.1.2; thesis eq. 2.15]: layer
//! `k` is the profile circle at guide arc length `s_0 + k Delta`.

use super::Step;

/// The column's point on the layer whose profile circle is at `t_layer`:
/// skipped while that circle is still below the column's point on the
/// substrate (`t_first`), ended past `t_hi`.
pub fn step(t_layer: f64, t_first: f64, t_hi: f64) -> Step {
    if t_layer > t_hi {
        Step::End
    } else if t_layer <= t_first {
        Step::Skip
    } else {
        Step::Point {
            t: t_layer,
            evaluations: 0,
            residual: 0.0,
        }
    }
}
