//! Path stage benches: constant-distance slicing (distance map included) on
//! the quarter torus (Delta = 1, 500 points per layer) and the general tube.

use criterion::{Criterion, Throughput};
use std::hint::black_box;
use std::path::PathBuf;
use waam_slicer::io::part_file::read_part_file;
use waam_slicer::path::{distance_map, slice, Discretisation, Strategy};

fn part(name: &str) -> waam_slicer::io::part_file::Part {
    let p = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("parts")
        .join(name);
    read_part_file(&p).expect("sample part reads")
}

pub fn constant_distance(c: &mut Criterion) {
    let mut g = c.benchmark_group("path");
    g.sample_size(10);
    for (name, delta) in [("quarter-torus.toml", 1.0), ("general-tube.toml", 1.0)] {
        let part = part(name);
        let mut o = part.slice_options();
        o.strategy = Strategy::Constant;
        o.delta_mm = delta;
        o.discretisation = Discretisation::Points(500);
        let points = slice(&part.tube, &part.substrate, &o)
            .expect("slices")
            .num_points();
        g.throughput(Throughput::Elements(points as u64));
        // `slice` computes the distance map itself (every point's delta).
        g.bench_function(format!("constant+map/{}/delta{delta}", part.name), |b| {
            b.iter(|| black_box(slice(&part.tube, &part.substrate, black_box(&o)).expect("slices")))
        });
    }
    // The spiral next to the layered path on the quarter torus.
    let part = part("quarter-torus.toml");
    let mut o = part.slice_options();
    o.strategy = Strategy::Spiral;
    o.delta_mm = 1.0;
    o.discretisation = Discretisation::Points(500);
    let points = slice(&part.tube, &part.substrate, &o)
        .expect("slices")
        .num_points();
    g.throughput(Throughput::Elements(points as u64));
    g.bench_function("spiral+map/quarter-torus/delta1", |b| {
        b.iter(|| black_box(slice(&part.tube, &part.substrate, black_box(&o)).expect("slices")))
    });
    // The distance map alone, as for a path read from a file.
    let path = slice(&part.tube, &part.substrate, &part.slice_options()).expect("slices");
    g.throughput(Throughput::Elements(path.num_points() as u64));
    g.bench_function("distance-map/quarter-torus/delta5", |b| {
        b.iter(|| black_box(distance_map(black_box(&path))))
    });
    g.finish();
}
