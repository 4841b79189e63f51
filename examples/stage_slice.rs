//! Stage 2 alone (deposition paths, [`waam_slicer::path`]): slice the
//! quarter torus with layers normal to the guide and with constant local
//! interlayer distance, and map the distance between layers.
//!
//! The normal layers fan out on the bend: at distance `r` from the guide on a
//! torus of guide radius `R` the layers are `(1 ± r/R) Delta` apart, a 60 %
//! variation for `r/R = 0.3` (parts/quarter-torus.toml; thesis §2.2, fig.
//! 2.6). The constant-distance layers hold `Delta` everywhere (the thesis's
//! method; we hold it to 1e-6 of `Delta`).
//!
//! ```text
//! cargo run --example stage_slice
//! ```

use waam_slicer::path::{distance_map, slice, Strategy};
use waam_slicer::Part;

fn main() -> Result<(), waam_slicer::Error> {
    let file = concat!(env!("CARGO_MANIFEST_DIR"), "/parts/quarter-torus.toml");
    let part = Part::read(file)?;
    let mut opts = part.slice_options();
    opts.delta_mm = 5.0;

    opts.strategy = Strategy::Perpendicular;
    let normal = slice(&part.tube, &part.substrate, &opts)?;
    let normal = distance_map(&normal).overall.expect("two layers or more");

    opts.strategy = Strategy::Constant;
    let constant = slice(&part.tube, &part.substrate, &opts)?;
    let layers = constant.num_slices();
    let constant = distance_map(&constant).overall.expect("two layers or more");

    println!(
        "normal to the guide: distance varies by {:.1} % (closed form 60 %); \
         constant distance: {layers} layers, varies by {:.2e}",
        100.0 * normal.variation,
        constant.variation
    );
    // closed form 2 r / R = 0.6; 0.5 % of Delta covers the polyline's chords
    assert!((normal.variation - 0.6).abs() < 0.005, "{normal:?}");
    assert!(constant.variation < 1e-6, "{constant:?}");
    Ok(())
}
