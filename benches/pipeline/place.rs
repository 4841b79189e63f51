//! Placement of the part in the cell (`pipeline::place_part`) with the
//! default search (64 Halton candidates on an 8-layer × 24-point subsample,
//! two compass refinements, certification with early exit on every point,
//! up to 6 rounds feeding the failing layers back into the subsample):
//!
//! * the hemisphere (Delta 5, 500 points a layer) in the KUKA KR 16-2
//!   part-carried example cell, where it is refused where the cell file
//!   puts it (J5's ±130° travel);
//! * the elbow (Delta 2, 400 points a layer) in the ROBOWAM torch-carried
//!   cell, refused there at J4/J6 speed: the positioner's pose is searched
//!   (the search may end with no placement; the bench times it either way).
//!
//! Goal: seconds, not minutes. Measured: see the README's placement line.

use std::hint::black_box;
use std::path::PathBuf;

use criterion::Criterion;
use waam_slicer::pipeline::{place_part, PlaceRequest};
use waam_slicer::{Cell, Part};

fn parts_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("parts")
}

/// The whole placement search of a sample part, part carried and torch
/// carried.
pub fn hemisphere_in_kuka_part_carried(c: &mut Criterion) {
    let req = PlaceRequest::default();
    let mut g = c.benchmark_group("place");
    g.sample_size(10);
    let part = Part::read(parts_dir().join("hemisphere.toml")).unwrap();
    let cell = Cell::read(parts_dir().join("cells/kuka_kr16_2_part_carried.toml")).unwrap();
    g.bench_function("hemisphere_kuka_part_carried", |b| {
        b.iter(|| {
            let placed = place_part(black_box(&part), black_box(&cell), &req).unwrap();
            assert!(placed.placement.feasible);
            placed
        })
    });
    let part = Part::read(parts_dir().join("elbow.toml")).unwrap();
    let cell = Cell::read(parts_dir().join("cells/robowam_torch_carried.toml")).unwrap();
    g.bench_function("elbow_robowam_torch_carried", |b| {
        b.iter(|| place_part(black_box(&part), black_box(&cell), &req).unwrap())
    });
    g.finish();
}
