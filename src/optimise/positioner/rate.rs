//! **Stage 6a — the positioner's laws: the rate bound.** From the geometry
//! alone (the build directions `b` of a layer, part frame, and the step
//! times in s), the slowest rotation of the positioner (rad/s) that can keep
//! every `b` within the cone of the vertical: a proof that a layer cannot
//! be built where the positioner's axes are slower.

use crate::math::Vector3;

/// [`required_rotation_rate`] skips a pair whose build directions' cosine
/// is this much above the cone's width's (unitless): they need no rotation.
const PAIR_SKIP_COS: f64 = 1e-12;

/// The slowest rotation (rad/s) of the positioner that can keep every
/// build direction of a layer within `cone_rad` of the vertical, from the
/// geometry alone, with the points `(i, j)` where it binds.
///
/// Between points `i` and `j` the part-frame directions `b_i`, `b_j` are
/// `θ_ij` apart; seen in the world both are within the cone, so within
/// `2·cone` of each other, and the positioner's rotation between the two
/// poses is at least `θ_ij − 2·cone` (the triangle inequality of angles). A
/// tilt-turn table turns the part by at most `|Δq7| + |Δq8|`, so over the
/// stretch's time `t_ij` (its length over the travel speed) it needs
/// `v7 + v8 ≥ (θ_ij − 2·cone) / t_ij`. `b` unit vectors (part frame), `dt`
/// the time of the step into each point (s, `dt[0]` unused).
pub fn required_rotation_rate(b: &[Vector3], dt: &[f64], cone_rad: f64) -> (f64, (usize, usize)) {
    let n = b.len();
    let mut time = vec![0.0; n];
    for m in 1..n {
        time[m] = time[m - 1] + dt[m];
    }
    let mut best = (0.0f64, (0, 0));
    let reach = std::f64::consts::PI - 2.0 * cone_rad;
    if reach <= 0.0 {
        return best;
    }
    // pairs closer than the cone's width need no rotation: skipped before
    // the angle (a hair inside, so that rounding cannot skip a pair in need)
    let within = (2.0 * cone_rad).cos() + PAIR_SKIP_COS;
    for i in 0..n {
        // per block of j, the widest angle a pair of the block needs to beat
        // the best so far at the block's first (shortest) time: pairs within
        // it cannot, and are skipped before the angle
        let mut skip_above = within;
        for j in i + 1..n {
            let t = time[j] - time[i];
            // no later j can need more: θ ≤ π
            if t > 0.0 && reach / t <= best.0 {
                break;
            }
            if (j - i - 1) % RATE_BLOCK == 0 {
                let beat = 2.0 * cone_rad + best.0 * t;
                // (beat ≥ 2·cone: never fewer skipped than `within`)
                skip_above = if beat < std::f64::consts::PI {
                    beat.cos() + PAIR_SKIP_COS
                } else {
                    -2.0
                };
            }
            if b[i].dot(&b[j]) > skip_above {
                continue;
            }
            let theta = b[i].cross(&b[j]).norm().atan2(b[i].dot(&b[j]));
            let need = theta - 2.0 * cone_rad;
            if need > 0.0 {
                let rate = if t > 0.0 { need / t } else { f64::INFINITY };
                if rate > best.0 {
                    best = (rate, (i, j));
                }
            }
        }
    }
    best
}

/// Pairs of [`required_rotation_rate`] that share one skipping bound.
const RATE_BLOCK: usize = 16;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Rotation3;

    /// The bound against its closed form: `b` turning at a constant
    /// `ω` per mm along a straight layer needs `TS·(ω − 2·cone/S)` over the
    /// whole length `S` (the longest stretch binds when `ω·S > 2·cone`); a
    /// corner (a turn over no length) needs an infinite rate.
    #[test]
    fn the_geometric_rate_bound_matches_its_closed_form() {
        let (omega, step, n, ts) = (2f64.to_radians(), 0.5, 100, 6.0);
        let b: Vec<Vector3> = (0..n)
            .map(|m| {
                let a = omega * step * m as f64;
                Vector3::new(0.0, a.sin(), a.cos())
            })
            .collect();
        let dt = vec![step / ts; n];
        let cone = 15f64.to_radians();
        let (rate, (i, j)) = required_rotation_rate(&b, &dt, cone);
        let s = step * (n - 1) as f64;
        let expected = ts * (omega - 2.0 * cone / s);
        assert!(
            (rate - expected).abs() < 1e-9 * expected,
            "{rate} vs {expected}"
        );
        assert_eq!((i, j), (0, n - 1));
        // within the cone everywhere: no rate needed
        let (rate, _) = required_rotation_rate(&b[..20], &dt[..20], cone);
        assert_eq!(rate, 0.0);
        // a corner: 40° between two points at the same place
        let mut corner = b[..10].to_vec();
        let last = corner[9];
        corner.push(Rotation3::from_axis_angle(&Vector3::x_axis(), 0.7) * last);
        let mut dt2 = dt[..11].to_vec();
        dt2[10] = 0.0;
        assert!(required_rotation_rate(&corner, &dt2, cone).0.is_infinite());
    }

    /// The bound's skipping (the early break, the cone's width, the blocks'
    /// bound) against every pair computed: the same rate and the same pair,
    /// on `b` round a cone of 10–80° about the vertical (a dome's layers)
    /// with a wobble, at uneven steps.
    #[test]
    fn the_rate_bound_skips_no_pair_that_binds() {
        let cone = 15f64.to_radians();
        for half_angle in [10.0, 25.0, 40.0, 55.0, 80.0] {
            let n = 300;
            let b: Vec<Vector3> = (0..n)
                .map(|m| {
                    let v = std::f64::consts::TAU * m as f64 / n as f64;
                    let a = f64::to_radians(half_angle) * (1.0 + 0.2 * (5.0 * v).sin());
                    Vector3::new(a.sin() * v.cos(), a.sin() * v.sin(), a.cos())
                })
                .collect();
            let dt: Vec<f64> = (0..n).map(|m| 0.05 + 0.03 * (m % 7) as f64 / 7.0).collect();
            let mut time = vec![0.0; n];
            for m in 1..n {
                time[m] = time[m - 1] + dt[m];
            }
            let mut brute = (0.0f64, (0, 0));
            for i in 0..n {
                for j in i + 1..n {
                    let theta = b[i].angle(&b[j]);
                    let rate = (theta - 2.0 * cone) / (time[j] - time[i]);
                    if rate > brute.0 {
                        brute = (rate, (i, j));
                    }
                }
            }
            let (rate, pair) = required_rotation_rate(&b, &dt, cone);
            approx::assert_relative_eq!(rate, brute.0, max_relative = 1e-12);
            assert_eq!(pair, brute.1, "half angle {half_angle}°");
        }
    }
}
