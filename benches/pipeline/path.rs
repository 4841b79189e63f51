//! Path stage benches: constant-distance slicing (distance map included) on
//! the quarter torus (Delta = 1, 500 points per layer) and the general tube;
//! at scale, the whole slice of a 0.87 M-point part and its `path.csv`.

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

/// The issue-21 reference part: the quarter torus of `parts/quarter-torus.toml`
/// scaled to R = 80 mm, r = 20 mm (the sample's text with those two
/// constants), sliced at Delta = 0.5 mm with 4000 points a layer: 866 671
/// points kept (1 040 000 computed, the rest past the end plane).
pub fn reference_part() -> waam_slicer::Part {
    let file = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("parts/quarter-torus.toml");
    let text = std::fs::read_to_string(&file).expect("sample part reads");
    let scaled = text
        .replacen("R = 50.0", "R = 80.0", 1)
        .replacen("r = 15.0", "r = 20.0", 1)
        .replacen(
            "name = \"quarter-torus\"",
            "name = \"quarter-torus-r80\"",
            1,
        );
    assert_ne!(
        scaled, text,
        "the sample's constants moved: update the bench"
    );
    waam_slicer::Part::from_toml_str(&scaled, &file.to_string_lossy()).expect("scaled part reads")
}

/// A million-point slice end to end in the library: path, distance map
/// (certificate of every point), tool axes and process plan
/// (`slice_part_with`), then `path.csv` formatted into a sink. Each
/// iteration takes seconds: 10 samples, no more.
pub fn at_scale(c: &mut Criterion) {
    use std::time::Duration;
    use waam_slicer::{slice_part_with, SliceOverrides};
    let part = reference_part();
    let o = SliceOverrides {
        delta_mm: Some(0.5),
        discretisation: Some(Discretisation::Points(4000)),
        ..SliceOverrides::default()
    };
    let sliced = slice_part_with(&part, &o, &Default::default()).expect("slices");
    let points = sliced.path.num_points();
    let mut g = c.benchmark_group("path-at-scale");
    g.sample_size(10);
    g.warm_up_time(Duration::from_millis(100));
    g.measurement_time(Duration::from_secs(5));
    g.throughput(Throughput::Elements(points as u64));
    g.bench_function("slice-part/quarter-torus-r80/delta0.5x4000", |b| {
        b.iter(|| {
            black_box(slice_part_with(&part, black_box(&o), &Default::default()).expect("slices"))
        })
    });
    g.bench_function("path-csv/quarter-torus-r80/delta0.5x4000", |b| {
        b.iter(|| {
            sliced
                .write_path_csv(&mut std::io::sink())
                .expect("written")
        })
    });
    g.finish();
}
