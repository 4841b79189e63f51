//! Property tests (bounded case counts, run in CI): random tubes either slice
//! with every local distance at Delta and no NaN anywhere, or give a typed
//! error; random text never panics the part-file reader.

#[path = "../common/mod.rs"]
mod common;

// The CLI's plots, for their degenerate-data tests (`plots::tests`). They
// are not run as the example's own tests: `test = true` on the example
// would stop `cargo test` from building the `waam` binary the CLI tests run.
#[path = "../../examples/waam/plots.rs"]
mod plots;

mod determinism;
mod hostile_inputs;
mod house;
mod random_cells;
mod reach;
mod regressions;
mod work_estimate;

use proptest::prelude::*;
use std::path::Path;
use waam_slicer::io::part_file::parse_part;
use waam_slicer::path::{distance_map, slice, Discretisation, Strategy as SliceStrategy};

fn part_text(guide: &str, radius: &str, t_max: f64, delta: f64) -> String {
    format!(
        r#"
name = "random"
[guide]
{guide}
[profile]
kind = "expr"
radius = "{radius}"
[range]
t_min = 0
t_max = {t_max}
[substrate]
kind = "plane"
point = [0, 0, 0]
normal = [0, 0, 1]
[slicing]
delta_mm = {delta}
points = 60
"#
    )
}

fn guide_strategy() -> impl Strategy<Value = (String, f64)> {
    prop_oneof![
        (-0.3f64..0.3, -0.3f64..0.3).prop_map(|(a, b)| (
            format!("kind = \"line\"\norigin = [0, 0, 0]\ndirection = [{a}, {b}, 1]"),
            40.0
        )),
        (30.0f64..80.0).prop_map(|r| (
            format!("kind = \"arc\"\ncentre = [{}, 0, 0]\nradius = {r}\nradial0 = [1, 0, 0]\ntangent0 = [0, 0, 1]", -r),
            1.2
        )),
        (0.0f64..0.01, 0.0f64..0.05).prop_map(|(a, b)| (
            format!("kind = \"expr\"\nx = \"{a} * t^2\"\ny = \"{b} * t\"\nz = \"t\""),
            30.0
        )),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 24, .. ProptestConfig::default() })]

    #[test]
    fn random_tubes_slice_at_constant_distance_or_fail_cleanly(
        (guide, t_max) in guide_strategy(),
        r0 in 3.0f64..25.0,
        wobble in 0.0f64..0.5,
        delta in 0.5f64..6.0,
    ) {
        let radius = format!("{r0} * (1 + {wobble} * 0.3 * sin(t / 7))");
        let text = part_text(&guide, &radius, t_max, delta);
        let part = match parse_part(&text, "random.toml", Path::new(".")) {
            Ok(p) => p,
            Err(e) => {
                // A typed, located error (e.g. the tube folds on a tight arc).
                prop_assert!(e.to_string().starts_with("random.toml"));
                return Ok(());
            }
        };
        let mut o = part.slice_options();
        o.strategy = SliceStrategy::Constant;
        o.discretisation = Discretisation::Points(60);
        match slice(&part.tube, &part.substrate, &o) {
            Ok(path) => {
                for l in &path.layers {
                    for p in &l.points {
                        prop_assert!(p.t.is_finite() && p.v.is_finite());
                        prop_assert!(p.position.coords.iter().all(|c| c.is_finite()));
                        prop_assert!(p.delta.is_none_or(|d| d.is_finite()));
                    }
                }
                if let Some(s) = distance_map(&path).overall {
                    prop_assert!(s.min_rel.abs() < 1e-3 && s.max_rel.abs() < 1e-3, "{:?}", s);
                }
            }
            Err(e) => prop_assert!(!e.to_string().is_empty()),
        }
    }

    #[test]
    fn arbitrary_text_never_panics_the_part_reader(text in "\\PC{0,300}") {
        let _ = parse_part(&text, "fuzz.toml", Path::new("."));
    }

    #[test]
    fn mangled_sample_parts_never_panic(cut in 0usize..2000, junk in "[ -~]{0,12}") {
        let base = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/parts/nozzle.toml")).unwrap();
        let cut = cut.min(base.len());
        let cut = (0..=cut).rev().find(|&i| base.is_char_boundary(i)).unwrap_or(0);
        let text = format!("{}{}{}", &base[..cut], junk, &base[cut..]);
        let _ = parse_part(&text, "mangled.toml", Path::new("."));
    }
}
