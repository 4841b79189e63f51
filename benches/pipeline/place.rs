//! Placement of the part in the cell (`pipeline::place_part`): the
//! hemisphere (Delta 5, 500 points a layer) in the KUKA KR 16-2
//! part-carried example cell, where it is refused where the cell file puts
//! it (J5's ±130° travel), with the default search (64 Halton candidates on
//! an 8-layer × 24-point subsample, two compass refinements, certification
//! on every point). Goal: seconds, not minutes. Measured 2026-12-02 with
//! another build on the box: 7.5 s (criterion median of 10).

use std::hint::black_box;
use std::path::PathBuf;

use criterion::Criterion;
use waam_slicer::pipeline::{place_part, PlaceRequest};
use waam_slicer::{Cell, Part};

fn parts_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("parts")
}

/// The whole placement search of a sample part.
pub fn hemisphere_in_kuka_part_carried(c: &mut Criterion) {
    let part = Part::read(parts_dir().join("hemisphere.toml")).unwrap();
    let cell = Cell::read(parts_dir().join("cells/kuka_kr16_2_part_carried.toml")).unwrap();
    let req = PlaceRequest::default();
    let mut g = c.benchmark_group("place");
    g.sample_size(10);
    g.bench_function("hemisphere_kuka_part_carried", |b| {
        b.iter(|| {
            let placed = place_part(black_box(&part), black_box(&cell), &req).unwrap();
            assert!(placed.placement.feasible);
            placed
        })
    });
    g.finish();
}
