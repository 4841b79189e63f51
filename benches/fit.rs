//! Criterion bench of stage 0a (a tube from a mesh): fit time against the
//! triangle count, on an elbow (straight legs of 20 mm, a 90° bend of
//! radius 40 mm, tube radius 12 mm) meshed at 10 k, 100 k and (with
//! `WAAM_BENCH_FULL=1`) 1 M triangles. The mesh is built outside the timed
//! loop; the load average is printed so that ratios can be read with it.
//!
//! `cargo bench --bench fit`

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use std::f64::consts::{FRAC_PI_2, TAU};
use std::hint::black_box;
use waam_slicer::fit::{fit_tube, TubeMesh};
use waam_slicer::math::{Point3, Vector3};
use waam_slicer::FitOptions;

/// The elbow meshed with about `triangles` triangles (circles in the normal
/// planes; the bend lies in the xz plane, so (0, 1, 0) is a normal everywhere).
fn elbow(triangles: usize) -> TubeMesh {
    let (leg, bend, r) = (20.0, 40.0, 12.0);
    let length = 2.0 * leg + bend * FRAC_PI_2;
    let h = (2.0 * length * TAU * r / triangles as f64).sqrt();
    let (rings, around) = ((length / h).ceil() as usize, (TAU * r / h).ceil() as usize);
    let mut v = Vec::with_capacity((rings + 1) * around);
    for i in 0..=rings {
        let s = length * i as f64 / rings as f64;
        let a = ((s - leg) / bend).clamp(0.0, FRAC_PI_2);
        let c = if s <= leg {
            Point3::new(0.0, 0.0, s)
        } else if s <= leg + bend * FRAC_PI_2 {
            Point3::new(bend * (1.0 - a.cos()), 0.0, leg + bend * a.sin())
        } else {
            Point3::new(bend + s - leg - bend * FRAC_PI_2, 0.0, leg + bend)
        };
        let t = Vector3::new(a.sin(), 0.0, a.cos());
        let (y, x) = (Vector3::y(), Vector3::y().cross(&t));
        for j in 0..around {
            let u = TAU * j as f64 / around as f64;
            v.push(c + (x * u.cos() + y * u.sin()) * r);
        }
    }
    let id = |i: usize, j: usize| (i * around + j % around) as u32;
    let mut f = Vec::with_capacity(2 * rings * around);
    for i in 0..rings {
        for j in 0..around {
            f.push([id(i, j), id(i, j + 1), id(i + 1, j)]);
            f.push([id(i, j + 1), id(i + 1, j + 1), id(i + 1, j)]);
        }
    }
    TubeMesh::new(v, f, "elbow.stl").expect("valid mesh")
}

fn fit_time_against_triangles(c: &mut Criterion) {
    let load = std::fs::read_to_string("/proc/loadavg").unwrap_or_default();
    eprintln!("load average at start: {}", load.trim());
    let mut sizes = vec![10_000, 100_000];
    if std::env::var_os("WAAM_BENCH_FULL").is_some() {
        sizes.push(1_000_000);
    }
    let mut group = c.benchmark_group("fit/elbow");
    group.sample_size(10);
    for n in sizes {
        let mesh = elbow(n);
        let opts = FitOptions::default();
        group.bench_with_input(
            BenchmarkId::from_parameter(mesh.num_triangles()),
            &mesh,
            |b, m| b.iter(|| fit_tube(black_box(m), &opts).expect("fits")),
        );
    }
    group.finish();
    let load = std::fs::read_to_string("/proc/loadavg").unwrap_or_default();
    eprintln!("load average at end: {}", load.trim());
}

criterion_group!(benches, fit_time_against_triangles);
criterion_main!(benches);
