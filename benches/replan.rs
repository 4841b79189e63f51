//! Stage 9 — the closed loop: replanning the elbow (parts/elbow.toml, its
//! own grid: Delta 2 mm, 400 points a layer, 62 layers) after layer 10 in the
//! ROBOWAM part-carried cell, from a synthetic scan of layer 10 (+0.8 mm over
//! a quarter of the circumference, −0.5 mm elsewhere, 0.05 mm noise, 20 % of
//! the points missing), optimisation and program model and files included.
//! Goal: well inside a 30 s interlayer dwell, < 1 s. Three cases, compared
//! within one run: the whole `plan_part` (what a replan replaces),
//! `replan_part` (slices the part again and optimises all 51 remaining
//! layers) and `replan_planned` (from the plan made before the build: only
//! the corrected layers are optimised again). `cargo bench --bench replan`.

use std::hint::black_box;
use std::path::PathBuf;

use criterion::{criterion_group, criterion_main, Criterion};
use waam_slicer::math::{Point3, Vector3};
use waam_slicer::pipeline::{slice_part_with, Control};
use waam_slicer::replan::{replan_planned, ReplanOptions};
use waam_slicer::{plan_part, replan_part, Cell, Measured, Part, PlanOptions};

fn parts_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("parts")
}

/// The scan of layer `k`: every point and three between it and the next,
/// five offsets across the wall, the field along `b`, noise, 20 % dropped.
#[allow(clippy::needless_range_loop)] // point i and its successor side by side
fn scan(part: &Part, opts: &PlanOptions, k: usize) -> Vec<Point3> {
    let sliced = slice_part_with(part, &opts.slice, &Control::default()).unwrap();
    let layer = &sliced.path.layers[k];
    let frames = &sliced.axes.frames[k];
    let n = layer.points.len();
    let mut state = 0x2545_f491_4f6c_dd1d_u64;
    let mut uniform = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    let field = |v: f64| {
        use std::f64::consts::{FRAC_PI_4, TAU};
        let d = (v - FRAC_PI_4).rem_euclid(TAU);
        let d = d.min(TAU - d);
        let x = ((FRAC_PI_4 + 0.175 - d) / 0.35).clamp(0.0, 1.0);
        -0.5 + 1.3 * x * x * (3.0 - 2.0 * x)
    };
    let mut out = Vec::new();
    for i in 0..n {
        let j = (i + 1) % n;
        for s in [0.0, 0.25, 0.5, 0.75] {
            let p = layer.points[i].position
                + (layer.points[j].position - layer.points[i].position) * s;
            let b = frames[i].build;
            let e = field(layer.points[i].v);
            for across in [-1.0, -0.5, 0.0, 0.5, 1.0] {
                if uniform() < 0.2 {
                    continue;
                }
                // uniform noise of the same spread as 0.05 mm Gaussian noise
                let noise = Vector3::new(uniform() - 0.5, uniform() - 0.5, uniform() - 0.5)
                    * (0.05 * 12f64.sqrt());
                out.push(p + b * e + frames[i].normal * across + noise);
            }
        }
    }
    out
}

fn elbow_after_10(c: &mut Criterion) {
    let part = Part::read(parts_dir().join("elbow.toml")).unwrap();
    let cell = Cell::read(parts_dir().join("cells/robowam_part_carried.toml")).unwrap();
    let opts = PlanOptions::default();
    let measured = Measured::Points(scan(&part, &opts, 10));
    let planned = plan_part(&part, &cell, &opts).unwrap();
    assert!(planned.is_feasible());
    let mut g = c.benchmark_group("replan");
    g.sample_size(10);
    g.bench_function("elbow_plan_part", |b| {
        b.iter(|| {
            let p = plan_part(black_box(&part), &cell, &opts).unwrap();
            p.program_files().unwrap()
        })
    });
    g.bench_function("elbow_replan_part_after_10", |b| {
        b.iter(|| {
            let r = replan_part(black_box(&part), &cell, &measured, 10, &opts).unwrap();
            assert!(r.is_feasible());
            r.planned.program_files().unwrap()
        })
    });
    g.bench_function("elbow_replan_planned_after_10", |b| {
        b.iter(|| {
            let r = replan_planned(
                black_box(&part),
                &planned,
                &measured,
                10,
                &ReplanOptions::default(),
            )
            .unwrap();
            assert!(r.is_feasible());
            r.planned.program_files().unwrap()
        })
    });
    g.finish();
}

criterion_group!(benches, elbow_after_10);
criterion_main!(benches);
