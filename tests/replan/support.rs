//! Synthetic scans and independent checks shared by the replan tests.

use crate::common::{part_path, rx, ry, rz, spec_fk};
use waam_slicer::math::{Matrix3, Point3, Vector3};
use waam_slicer::path::Discretisation;
use waam_slicer::pipeline::{slice_part_with, Control, SlicedPart};
use waam_slicer::{Part, PlanOptions, SliceOverrides};

/// The measured layer of most tests.
pub const K: usize = 10;
/// Stray points added to every scan (far from the wall).
pub const STRAYS: usize = 5;
/// The default law's exponent (process::height_law, SPEC §9).
pub const A: f64 = -0.5;

/// The elbow (parts/elbow.toml) at a coarse grid, `layers` layers.
pub fn elbow_opts(points: usize, layers: usize) -> PlanOptions {
    PlanOptions {
        slice: SliceOverrides {
            discretisation: Some(Discretisation::Points(points)),
            max_layers: Some(layers),
            ..SliceOverrides::default()
        },
        ..PlanOptions::default()
    }
}

/// A part file of the repository.
pub fn part(name: &str) -> Part {
    Part::read(part_path(name)).unwrap()
}

/// The nominal slice of `part` with `opts`.
pub fn nominal(part: &Part, opts: &PlanOptions) -> SlicedPart {
    slice_part_with(part, &opts.slice, &Control::default()).unwrap()
}

/// A height error field around the layer (mm, + high): `high` over the
/// quarter of the circumference `v in [0, pi/2]` (profile angle), `low`
/// elsewhere, with smoothstep transitions 0.35 rad wide.
#[derive(Debug, Clone, Copy)]
pub struct Field {
    pub high: f64,
    pub low: f64,
}

impl Field {
    pub fn at(&self, v: f64) -> f64 {
        use std::f64::consts::{FRAC_PI_4, TAU};
        let d = (v - FRAC_PI_4).rem_euclid(TAU);
        let d = d.min(TAU - d);
        let w = 0.35;
        let x = ((FRAC_PI_4 + 0.5 * w - d) / w).clamp(0.0, 1.0);
        let g = x * x * (3.0 - 2.0 * x);
        self.low + (self.high - self.low) * g
    }
}

/// A small deterministic generator (LCG) with Gaussian samples.
pub struct Rng(u64);

impl Rng {
    pub fn new(seed: u64) -> Self {
        Self(
            seed.wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407),
        )
    }
    pub fn uniform(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((self.0 >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    }
    pub fn gauss(&mut self) -> f64 {
        let (u, v) = (self.uniform(), self.uniform());
        (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
    }
}

/// The scan of layer `k` of `sliced`: each point and three points between
/// it and the next, at five offsets across the wall (−1 to +1 mm along the
/// surface normal), displaced by `field` along the build direction, with Gaussian
/// noise of 0.05 mm on each coordinate, 20 % of the points missing, and
/// [`STRAYS`] stray points 30 mm off the wall. Returns the scan and the true
/// error at each planned point of the layer.
pub fn synthetic_scan(
    sliced: &SlicedPart,
    k: usize,
    field: &Field,
    seed: u64,
) -> (Vec<Point3>, Vec<f64>) {
    let layer = &sliced.path.layers[k];
    let frames = &sliced.axes.frames[k];
    let n = layer.points.len();
    let mut rng = Rng::new(seed);
    let mut scan = Vec::new();
    for i in 0..n {
        let j = (i + 1) % n;
        for s in [0.0, 0.25, 0.5, 0.75] {
            let p = layer.points[i].position
                + (layer.points[j].position - layer.points[i].position) * s;
            let b = (frames[i].build * (1.0 - s) + frames[j].build * s).normalize();
            let nrm = (frames[i].normal * (1.0 - s) + frames[j].normal * s).normalize();
            // the profile angle between the two points (unwrapped across 2 pi)
            let (vi, mut vj) = (layer.points[i].v, layer.points[j].v);
            if (vj - vi).abs() > std::f64::consts::PI {
                vj += if vj < vi {
                    std::f64::consts::TAU
                } else {
                    -std::f64::consts::TAU
                };
            }
            let e = field.at(vi + (vj - vi) * s);
            for across in [-1.0, -0.5, 0.0, 0.5, 1.0] {
                if rng.uniform() < 0.2 {
                    continue;
                }
                let noise = Vector3::new(rng.gauss(), rng.gauss(), rng.gauss()) * 0.05;
                scan.push(p + b * e + nrm * across + noise);
            }
        }
    }
    for s in 0..STRAYS {
        let i = (s * n) / STRAYS;
        scan.insert(
            (s * 97) % scan.len(),
            layer.points[i].position + frames[i].normal * 30.0,
        );
    }
    let truth = layer.points.iter().map(|p| field.at(p.v)).collect();
    (scan, truth)
}

/// Index in layer `k` of the point with the same profile angle as `v`.
pub fn column(sliced: &SlicedPart, k: usize, v: f64) -> usize {
    sliced.path.layers[k]
        .points
        .iter()
        .position(|p| p.v == v)
        .expect("same columns")
}

/// Smallest distance from `p` to the closed polyline `poly` (mm), brute force.
pub fn distance_to_closed(p: &Point3, poly: &[Point3]) -> f64 {
    let n = poly.len();
    (0..n)
        .map(|i| {
            let (a, b) = (poly[i], poly[(i + 1) % n]);
            let ab = b - a;
            let s = ((p - a).dot(&ab) / ab.norm_squared()).clamp(0.0, 1.0);
            (p - (a + ab * s)).norm()
        })
        .fold(f64::INFINITY, f64::min)
}

/// Checks every planned point with the SPEC §6.1 forward kinematics against
/// the part-carried cell file `toml`: the part point carried by the flange
/// pose of its joints lands on the file's `deposition_point_mm` (1 µm), tool
/// axis vertical (1e-6); returns the points checked. Reads the file's
/// numbers itself.
pub fn fk_check_part_carried(toml: &str, planned: &waam_slicer::PlannedPart) -> usize {
    let doc: toml::Table = toml.parse().unwrap();
    let pc = doc["part_carried"].as_table().unwrap();
    let floats = |v: &toml::Value| -> Vec<f64> {
        v.as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_float().or(x.as_integer().map(|i| i as f64)).unwrap())
            .collect()
    };
    let d = floats(&pc["deposition_point_mm"]);
    let d_r = Vector3::new(d[0], d[1], d[2]);
    let (fp_rot, fp_t) = match pc.get("flange_from_part_xyzwpr") {
        Some(v) => {
            let v = floats(v);
            let r = rz(v[5].to_radians()) * ry(v[4].to_radians()) * rx(v[3].to_radians());
            (r, Vector3::new(v[0], v[1], v[2]))
        }
        None => (Matrix3::identity(), Vector3::zeros()),
    };
    let mut checked = 0;
    for (lp, pl) in planned.layers.iter().zip(&planned.plan.layers) {
        for (cp, pp) in lp.points.iter().zip(&pl.points) {
            let (r, p) = spec_fk(&pp.joints.unwrap());
            let m = r * (fp_rot * cp.position_mm.coords + fp_t) + p;
            assert!(
                (m - d_r).norm() < 1e-3,
                "layer {}: {m} vs D_R {d_r}",
                lp.layer
            );
            let t = r * fp_rot * cp.tool_axis.into_inner();
            assert!((t - Vector3::z()).norm() < 1e-6, "tool axis {t}");
            checked += 1;
        }
    }
    checked
}

/// The law's bead height (mm) at `v` (mm/s), anchored so that `v_nom` lays
/// `delta` (the default, process::height_law), written out here.
pub fn law_height(v: f64, v_nom: f64, delta: f64) -> f64 {
    delta * (v / v_nom).powf(A)
}

/// The law's speed (mm/s) for a height `h` (mm), anchored as above.
pub fn law_speed(h: f64, v_nom: f64, delta: f64) -> f64 {
    v_nom * (h / delta).powf(1.0 / A)
}
