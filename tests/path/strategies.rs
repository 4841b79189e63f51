use crate::common::load_part;
use waam_slicer::path::{distance_map, slice, EndRule, SliceOptions, Strategy};

#[test]
fn smoke_quarter_torus() {
    let part = load_part("quarter-torus.toml");
    for s in [
        Strategy::Constant,
        Strategy::Iso,
        Strategy::Perpendicular,
        Strategy::Planar,
    ] {
        let mut o = part.slice_options();
        o.strategy = s;
        let t0 = std::time::Instant::now();
        let path = slice(&part.tube, &part.substrate, &o).unwrap();
        let m = distance_map(&path);
        println!(
            "{s:?}: {} layers, {} slices, {} points, {:?} in {:?}; overall {:?}",
            path.layers.len(),
            path.num_slices(),
            path.num_points(),
            path.report,
            t0.elapsed(),
            m.overall
        );
    }
    let mut o = SliceOptions::new(Strategy::Constant, 5.0);
    o.end = EndRule::WholeLayers;
    let path = slice(&part.tube, &part.substrate, &o).unwrap();
    println!("whole layers: {} ", path.layers.len());
}
