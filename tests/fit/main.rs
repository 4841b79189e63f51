//! Stage 0a — fitting a tube to a mesh, on meshes made by the independent
//! generator of `gen.rs`: the fitted guide and radius against the
//! generator's closed-form truth, the goals of issue 28, the refusals, the
//! written part sliced like the true part.

mod cli;
#[path = "../common/mod.rs"]
mod common;
mod ends;
mod features;
mod gen;
mod page;
mod real;
mod substrate;
mod units;

use gen::Truth;
use waam_slicer::fit::{FitError, TubeMesh};
use waam_slicer::math::{Point3, Vector3};
use waam_slicer::{Error, FitOptions, FittedPart, Part, StartEnd};

/// Errors of the fitted part against the truth (mm).
#[derive(Debug)]
struct Errors {
    guide_rms: f64,
    guide_max: f64,
    radius_rms: f64,
    radius_max: f64,
    vertex_rms: f64,
    vertex_max: f64,
}

fn fit_mesh(
    v: Vec<Point3>,
    f: Vec<[u32; 3]>,
    name: &str,
    opts: &FitOptions,
) -> Result<FittedPart, Error> {
    let mesh = TubeMesh::new(v, f, name).unwrap();
    Part::from_tube_mesh(&mesh, opts)
}

/// The true centre line sampled every `step_mm` or a little less: (arc
/// length, point) pairs, both ends included (mm).
fn true_line(truth: &Truth, step_mm: f64) -> Vec<(f64, Point3)> {
    let m = (truth.length / step_mm).ceil() as usize;
    (0..=m)
        .map(|i| {
            let s = truth.length * i as f64 / m as f64;
            (s, (truth.centre)(s))
        })
        .collect()
}

/// Compares the part read back from the written TOML with the truth: 400
/// samples of the fitted guide, each against the nearest point of the truth's
/// centre line (sampled every 0.02 mm), and the fitted radius there.
fn errors(truth: &Truth, fitted: &FittedPart) -> Errors {
    let part = Part::from_toml_str(&fitted.toml, "fitted.toml").unwrap();
    let tube = &part.tube;
    let range = tube.range();
    let line = true_line(truth, 0.02);
    let (mut g2, mut gmax, mut r2, mut rmax) = (0.0, 0.0_f64, 0.0, 0.0_f64);
    let n = 400;
    for i in 0..=n {
        let t = range.t_min + (range.t_max - range.t_min) * i as f64 / n as f64;
        let p = tube.guide().point(t);
        let (mut best, mut best_s) = (f64::INFINITY, 0.0);
        for w in line.windows(2) {
            let (a, b) = (w[0].1, w[1].1);
            let ab = b - a;
            let u = ((p - a).dot(&ab) / ab.norm_squared()).clamp(0.0, 1.0);
            let d = (a + ab * u - p).norm();
            if d < best {
                best = d;
                best_s = w[0].0 + u * (w[1].0 - w[0].0);
            }
        }
        let dr = tube.radius(t) - (truth.radius)(best_s);
        g2 += best * best;
        gmax = gmax.max(best);
        r2 += dr * dr;
        rmax = rmax.max(dr.abs());
    }
    // The ends: the fitted guide must reach the truth's ends.
    let ends = [
        (tube.guide().point(range.t_min) - (truth.centre)(0.0)).norm(),
        (tube.guide().point(range.t_max) - (truth.centre)(truth.length)).norm(),
    ];
    let rep = fitted.report();
    let k = (n + 1) as f64;
    Errors {
        guide_rms: (g2 / k).sqrt(),
        guide_max: gmax.max(ends[0]).max(ends[1]),
        radius_rms: (r2 / k).sqrt(),
        radius_max: rmax,
        vertex_rms: rep.rms_mm,
        vertex_max: rep.max_mm,
    }
}

fn run(truth: &Truth, h: f64, noise: f64, seed: u64) -> Errors {
    let (v, f) = gen::mesh(truth, h, noise, 0.0, seed);
    let tris = f.len();
    let fitted = fit_mesh(v, f, &format!("{}.stl", truth.name), &FitOptions::default())
        .unwrap_or_else(|e| panic!("{} h = {h} noise = {noise}: {e}", truth.name));
    let e = errors(truth, &fitted);
    eprintln!(
        "{:<16} h {h:>3} noise {noise:>3}: {tris:>7} tri, {:>2} it, guide rms {:.4} max {:.4}, radius rms {:.4} max {:.4}, vertex rms {:.4} max {:.4}, surface->mesh {:.4}",
        truth.name,
        fitted.report().iterations,
        e.guide_rms,
        e.guide_max,
        e.radius_rms,
        e.radius_max,
        e.vertex_rms,
        e.vertex_max,
        fitted.report().surface_to_mesh_max_mm.unwrap_or(f64::NAN),
    );
    e
}

#[test]
fn half_millimetre_meshes_without_noise_meet_the_goals() {
    for truth in gen::all() {
        let e = run(&truth, 0.5, 0.0, 1);
        assert!(e.guide_rms < 0.05, "{}: {e:?}", truth.name);
        assert!(e.radius_rms < 0.05, "{}: {e:?}", truth.name);
        assert!(e.vertex_max < 0.1, "{}: {e:?}", truth.name);
        assert!(e.guide_max < 0.1, "{}: {e:?}", truth.name);
    }
}

#[test]
fn half_millimetre_meshes_with_noise_meet_the_goals() {
    for (k, truth) in gen::all().iter().enumerate() {
        let e = run(truth, 0.5, 0.1, 7 + k as u64);
        assert!(e.guide_rms < 0.05, "{}: {e:?}", truth.name);
        assert!(e.radius_rms < 0.05, "{}: {e:?}", truth.name);
        // The vertices carry the noise: about its 3-D size normal to the surface.
        assert!(
            e.vertex_rms < 0.13 && e.vertex_rms > 0.07,
            "{}: {e:?}",
            truth.name
        );
    }
}

#[test]
fn coarse_meshes_with_and_without_noise() {
    for (k, truth) in gen::all().iter().enumerate() {
        for noise in [0.0, 0.1] {
            let e = run(truth, 2.0, noise, 40 + k as u64);
            assert!(e.guide_rms < 0.1, "{} noise {noise}: {e:?}", truth.name);
            assert!(e.radius_rms < 0.1, "{} noise {noise}: {e:?}", truth.name);
        }
    }
}

/// Coarse exports (facets within 0.5 mm of the surface: a straight pipe in
/// one stretch of long thin triangles, a 90° bend in eight rings), untidy
/// (duplicated seam, zero-area and flipped triangles, a stray piece) and in
/// metres, as other people's CAD tools write them. The other coarse exports:
/// `coarse_bends_fit_against_the_generators_tube`,
/// `a_coarse_swelling_radius_export_fits_within_what_its_rings_hold`,
/// `coarse_s_bend_and_helix_exports_fit_through_plane_cuts`.
#[test]
fn coarse_untidy_exports_in_metres_meet_the_goals() {
    for truth in [gen::straight(), gen::torus()] {
        let (v, f, around) = gen::coarse(&truth, 0.5);
        let (rings, tris) = (v.len() / around, f.len());
        let (v, f) = gen::untidy(&v, &f, around, Point3::new(300.0, 300.0, 300.0), 0.1);
        let opts = FitOptions {
            units: waam_slicer::fit::Units::M,
            ..FitOptions::default()
        };
        let name = format!("{}-coarse-m.stl", truth.name);
        let fitted = fit_mesh(gen::in_metres(&v), f, &name, &opts)
            .unwrap_or_else(|e| panic!("{}: {e}", truth.name));
        let e = errors(&truth, &fitted);
        eprintln!(
            "{:<16} coarse: {rings:>3} rings of {around}, {tris:>5} tri, {:>2} it, guide rms {:.4} max {:.4}, radius rms {:.4} max {:.4}, vertex rms {:.4} max {:.4}",
            truth.name,
            fitted.report().iterations,
            e.guide_rms,
            e.guide_max,
            e.radius_rms,
            e.radius_max,
            e.vertex_rms,
            e.vertex_max,
        );
        assert_eq!(fitted.report().repair.left_out.len(), 1, "{}", truth.name);
        // A few rings, each a polygon of a dozen sides.
        assert!(
            rings <= 8 && around <= 13,
            "{}: {rings} rings of {around}",
            truth.name
        );
        assert!(
            e.guide_rms < 0.05 && e.radius_rms < 0.05,
            "{}: {e:?}",
            truth.name
        );
        assert!(
            e.guide_max < 0.1 && e.radius_max < 0.1,
            "{}: {e:?}",
            truth.name
        );
    }
}

/// The fitted part's surface against the truth's: at 200 stations along the
/// fitted guide, 16 points around its circle (normal to the guide), each
/// point's distance to the true surface (its distance to the true centre
/// line, sampled every 0.05 mm, less the true radius there): RMS and largest
/// (mm).
fn surface_errors(truth: &Truth, fitted: &FittedPart) -> (f64, f64) {
    let part = Part::from_toml_str(&fitted.toml, "fitted.toml").unwrap();
    let tube = &part.tube;
    let range = tube.range();
    let line = true_line(truth, 0.05);
    let (mut sum2, mut max, mut count) = (0.0, 0.0_f64, 0);
    for i in 0..=200 {
        let t = range.t_min + (range.t_max - range.t_min) * i as f64 / 200.0;
        let (c, tan) = (tube.guide().point(t), tube.guide().d1(t).normalize());
        let side = if tan.z.abs() < 0.9 {
            Vector3::z()
        } else {
            Vector3::x()
        };
        let e1 = tan.cross(&side).normalize();
        let e2 = tan.cross(&e1);
        for k in 0..16 {
            let a = std::f64::consts::TAU * k as f64 / 16.0;
            let p = c + (e1 * a.cos() + e2 * a.sin()) * tube.radius(t);
            let (d, s) = line
                .iter()
                .map(|(s, q)| ((p - q).norm(), *s))
                .min_by(|x, y| x.0.total_cmp(&y.0))
                .unwrap();
            let e = (d - (truth.radius)(s)).abs();
            sum2 += e * e;
            max = max.max(e);
            count += 1;
        }
    }
    ((sum2 / count as f64).sqrt(), max)
}

/// Coarse exports of bends, as CAD tools write them (issue 47): a 90° bend
/// of R/r 2, 3 and 4 in 3 to 8 stretches, 16 or 32 points around, between
/// straight legs of 20 mm in one stretch each (`gen::coarse_bend`, 30
/// meshes), and the elbow of `gen::coarse`. Each ring of vertices is the
/// exporter's sample of the axis (its centre) and of the tangent (its
/// plane's normal); between two rings the guide runs on the cubic they
/// define (`fit::coarse::bridge_between_rings`): a straight between two
/// parallel rings, within microns of the arc between two rings of a bend.
/// Against the generator's exact tube, every bend fits: guide within 0.05
/// mm RMS and 0.1 mm at most, radius within 0.02 mm RMS, the fitted surface
/// within 0.05 mm RMS and 0.1 mm at most of the true one (measured: 0.011 /
/// 0.032, 0.002, 0.008 / 0.033 at worst); the elbow within 0.1 / 0.3 mm.
/// Before the bridge 25 of the 30 fitted, within 0.3 / 0.75 mm (the guide
/// followed the facets' chords between the rings), the others refused as
/// sections not near a circle.
#[test]
fn coarse_bends_fit_against_the_generators_tube() {
    let mut cases = Vec::new();
    for ratio in [2.0, 3.0, 4.0] {
        for stretches in [3, 4, 5, 6, 8] {
            for around in [16, 32] {
                let (truth, v, f) =
                    gen::coarse_bend(10.0, 10.0 * ratio, 20.0, stretches, around, false);
                let name = format!("R/r {ratio}, {stretches} stretches, {around} around");
                cases.push((name, stretches, truth, v, f));
            }
        }
    }
    let elbow = gen::elbow();
    let (v, f, around) = gen::coarse(&elbow, 0.5);
    let name = format!("coarse elbow, {} rings of {around}", v.len() / around);
    cases.push((name, 0, elbow, v, f));
    let mut bends_fitted = 0;
    for (name, stretches, truth, v, f) in cases {
        let fitted = fit_mesh(v, f, "bend.stl", &FitOptions::default())
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        bends_fitted += usize::from(stretches > 0);
        let e = errors(&truth, &fitted);
        let (surface_rms, surface_max) = surface_errors(&truth, &fitted);
        eprintln!(
            "{name}: guide rms {:.3} max {:.3}, radius rms {:.3}, surface rms {surface_rms:.3} max {surface_max:.3}",
            e.guide_rms, e.guide_max, e.radius_rms
        );
        let (guide, surface) = if stretches > 0 {
            ((0.05, 0.1), (0.05, 0.1))
        } else {
            ((0.1, 0.3), (0.1, 0.3))
        };
        assert!(
            e.guide_rms < guide.0 && e.guide_max < guide.1,
            "{name}: {e:?}"
        );
        assert!(e.radius_rms < 0.02, "{name}: {e:?}");
        assert!(
            surface_rms < surface.0 && surface_max < surface.1,
            "{name}: surface {surface_rms} {surface_max}"
        );
    }
    assert_eq!(bends_fitted, 30, "coarse bends fitted");
}

/// A coarse bend between long legs written in one stretch each, its rings'
/// planes taken from their neighbours' centres (`gen::coarse_bend`, `central`,
/// as a pipe network's exporter writes them; unseen exports, issue 47): the
/// ring where a leg joins the bend leans toward the bend, by up to 4
/// degrees here. Between two rings the guide runs on the cubic from one
/// ring's centre to the next (`fit::coarse::bridge_between_rings`), leaving
/// each along the tube's tangent: a leg held by its plane cuts and over
/// twice as long as the stretches beside it is straight, and the bend
/// leaves it along it (the tangent of a straight meeting an arc), not
/// along the leaning ring. Radius 10, legs 200 mm, bends of R/r 3, 4 and 6
/// in 2 to 6 stretches, 24 around: the fitted surface within 0.02 mm RMS
/// and 0.05 mm at most of the true one (measured: 0.010 / 0.019 at worst).
/// Before, 3 of the 12 were refused (sections not near a circle), 2 folded
/// and the rest lay up to 0.40 mm off (R/r 3 in 2 stretches: the cubic
/// along a leaning ring left the straight, and the cuts of a long bend
/// stretch held the guide on its chords).
#[test]
fn a_coarse_bend_with_long_legs_and_leaning_joins_fits() {
    for ratio in [3.0, 4.0, 6.0] {
        for stretches in [2, 3, 4, 6] {
            let (truth, v, f) = gen::coarse_bend(10.0, 10.0 * ratio, 200.0, stretches, 24, true);
            let name = format!("R/r {ratio}, {stretches} stretches");
            let fitted = fit_mesh(v, f, "bend.stl", &FitOptions::default())
                .unwrap_or_else(|e| panic!("{name}: {e}"));
            let (rms, max) = surface_errors(&truth, &fitted);
            eprintln!("{name}: surface {rms:.4} / {max:.4} mm");
            assert!(rms < 0.02 && max < 0.05, "{name}: surface {rms} {max}");
        }
    }
}

/// The fine meshes (0.2 mm, up to ~1 M triangles): `cargo test --release
/// --test fit -- --ignored`.
#[test]
#[ignore]
fn fine_meshes_with_and_without_noise() {
    for (k, truth) in gen::all().iter().enumerate() {
        for noise in [0.0, 0.1] {
            let e = run(truth, 0.2, noise, 80 + k as u64);
            assert!(e.guide_rms < 0.05, "{} noise {noise}: {e:?}", truth.name);
            assert!(e.radius_rms < 0.05, "{} noise {noise}: {e:?}", truth.name);
            if noise == 0.0 {
                assert!(e.vertex_max < 0.1, "{}: {e:?}", truth.name);
            }
        }
    }
}

#[test]
fn two_skins_give_the_mid_surface_and_the_wall_thickness() {
    let truth = gen::elbow();
    let (mut v, mut f) = gen::mesh(&truth, 0.8, 0.0, 1.5, 3);
    let (vi, fi) = gen::mesh(&truth, 0.8, 0.0, -1.5, 4);
    let base = v.len() as u32;
    v.extend(vi);
    f.extend(fi.into_iter().map(|t| t.map(|i| i + base)));
    let fitted = fit_mesh(v, f, "wall.stl", &FitOptions::default()).unwrap();
    let rep = fitted.report();
    assert_eq!(rep.skins, 2);
    let wall = rep.wall.as_ref().unwrap();
    assert!((wall.mean_mm - 3.0).abs() < 0.02, "{wall:?}");
    assert!(
        (wall.min_mm - 3.0).abs() < 0.05 && (wall.max_mm - 3.0).abs() < 0.05,
        "{wall:?}"
    );
    let e = errors(&truth, &fitted);
    assert!(e.guide_rms < 0.05 && e.radius_rms < 0.05, "{e:?}");
    assert!(rep.max_mm < 0.1, "{}", rep.max_mm);
}

#[test]
fn a_watertight_wall_is_split_into_its_skins() {
    // Outer and inner skins joined by flat annular end faces.
    let truth = gen::straight();
    let around = 100;
    let (mut v, mut f) = gen::mesh_around(&truth, 1.0, around, 0.0, 1.0, 0);
    let (vi, fi) = gen::mesh_around(&truth, 1.0, around, 0.0, -1.0, 0);
    let around = around as u32;
    let rings = (v.len() as u32) / around;
    let base = v.len() as u32;
    v.extend(vi);
    f.extend(fi.into_iter().map(|t| t.map(|i| i + base)));
    // Both skins have the same ring layout (same count around: the outer's).
    assert_eq!(v.len() as u32, 2 * base);
    for ring in [0, rings - 1] {
        for j in 0..around {
            let (o0, o1) = (ring * around + j, ring * around + (j + 1) % around);
            let (i0, i1) = (base + o0, base + o1);
            f.push([o0, i0, o1]);
            f.push([o1, i0, i1]);
        }
    }
    let fitted = fit_mesh(v, f, "solid.stl", &FitOptions::default()).unwrap();
    let rep = fitted.report();
    assert_eq!((rep.skins, rep.caps), (2, 2));
    assert!((rep.wall.as_ref().unwrap().mean_mm - 2.0).abs() < 0.02);
    let e = errors(&truth, &fitted);
    assert!(e.guide_rms < 0.05 && e.radius_rms < 0.05, "{e:?}");
}

#[test]
fn the_start_end_is_the_lowest_or_the_capped_one() {
    let truth = gen::straight();
    let (mut v, mut f) = gen::mesh(&truth, 1.0, 0.0, 0.0, 0);
    let around = (std::f64::consts::TAU * 15.0).ceil() as u32;
    let last = v.len() as u32 - around;
    v.push(Point3::new(5.0, -3.0, truth.length));
    let centre = v.len() as u32 - 1;
    for j in 0..around {
        f.push([last + j, last + (j + 1) % around, centre]);
    }
    let low = fit_mesh(v.clone(), f.clone(), "cup.stl", &FitOptions::default()).unwrap();
    let p0 = low.fit.substrate_point;
    assert!(p0.z.abs() < 0.05, "{p0}");
    assert!(!low.report().start.capped && low.report().end.capped);
    let opts = FitOptions {
        start: StartEnd::Capped,
        ..FitOptions::default()
    };
    let capped = fit_mesh(v, f, "cup.stl", &opts).unwrap();
    let p0 = capped.fit.substrate_point;
    assert!((p0.z - truth.length).abs() < 0.05, "{p0}");
    assert!(
        capped.fit.substrate_normal.z < -0.999,
        "the substrate faces the part"
    );
}

#[test]
fn a_bent_tube_slices_like_the_true_part() {
    let truth = gen::elbow();
    let dir = tempfile::tempdir().unwrap();
    let template = dir.path().join("template.toml");
    let slicing = "[slicing]\nstrategy = \"constant\"\ndelta_mm = 2.0\npoints = 120\n[tool_axis]\nmax_axis_rate_deg_per_mm = 10\n[process]\npreset = \"cmt-steel\"\n";
    let true_text = format!(
        "name = \"elbow-truth\"\n[guide]\nkind = \"pipe\"\nstart = [0, 0, 0]\ndirection = [0, 0, 1]\nsegments = [{{ straight_mm = 20 }}, {{ bend_radius_mm = 40, angle_deg = 90, toward = [1, 0, 0] }}, {{ straight_mm = 20 }}]\n[frame]\nmethod = \"rmf\"\n[profile]\nkind = \"constant\"\nradius = 12\n[range]\nt_min = 0\nt_max = \"40 + 40 * PI / 2\"\n[substrate]\nkind = \"plane\"\npoint = [0, 0, 0]\nnormal = [0, 0, 1]\n{slicing}"
    );
    std::fs::write(&template, &true_text).unwrap();
    let true_part = Part::read(&template).unwrap();
    let (v, f) = gen::mesh(&truth, 1.0, 0.1, 0.0, 11);
    let opts = FitOptions {
        template: Some(template.clone()),
        ..FitOptions::default()
    };
    let fitted = fit_mesh(v, f, "elbow.stl", &opts).unwrap();
    let layers = |p: &Part| {
        let s = waam_slicer::slice_part(p).unwrap_or_else(|e| panic!("{e}"));
        s.path.layers.iter().map(|l| l.slice).max().unwrap() + 1
    };
    let (a, b) = (layers(&true_part), layers(&fitted.part));
    eprintln!("elbow layers: true part {a}, fitted part {b}");
    assert!(a > 20 && a.abs_diff(b) <= 1, "true {a}, fitted {b}");
    // The template's tables were taken.
    assert!(fitted.toml.contains("points = 120"), "{}", fitted.toml);
}

#[test]
fn a_closed_blob_is_refused() {
    let (v, f) = gen::sphere(20.0, 24);
    let e = fit_mesh(v, f, "blob.stl", &FitOptions::default()).unwrap_err();
    assert!(
        matches!(e, Error::Fit(FitError::ClosedSurface { .. })),
        "{e}"
    );
    let msg = e.to_string();
    assert!(
        msg.starts_with("blob.stl: not a tube") && msg.contains("blob"),
        "{msg}"
    );
}

#[test]
fn a_branch_is_refused_naming_the_station() {
    let (v, f) = gen::y_branch(10.0, 30.0, 16);
    let e = fit_mesh(v, f, "y.stl", &FitOptions::default()).unwrap_err();
    let msg = e.to_string();
    let Error::Fit(FitError::Branch { station, z, .. }) = e else {
        panic!("{msg}")
    };
    assert!(
        msg.starts_with("y.stl: not one tube: a branch at station"),
        "{msg}"
    );
    assert!(station > 0 && z > 30.0 && z < 50.0, "{msg}");
}

#[test]
fn an_oval_section_is_refused_naming_the_station() {
    let (mut v, f) = gen::mesh(&gen::straight(), 1.0, 0.0, 0.0, 0);
    for p in &mut v {
        p.x = 5.0 + (p.x - 5.0) * 1.3;
    }
    let e = fit_mesh(v, f, "oval.stl", &FitOptions::default()).unwrap_err();
    let msg = e.to_string();
    assert!(
        matches!(e, Error::Fit(FitError::SectionNotCircle { .. })),
        "{msg}"
    );
    assert!(
        msg.starts_with("oval.stl: station ") && msg.contains("not near a circle"),
        "{msg}"
    );
}

#[test]
fn a_residual_over_the_bound_is_refused() {
    let (v, f) = gen::mesh(&gen::straight(), 1.0, 0.1, 0.0, 5);
    let opts = FitOptions {
        max_rms_mm: 0.05,
        max_section_rms_ratio: 1.0,
        ..FitOptions::default()
    };
    let e = fit_mesh(v, f, "noisy.stl", &opts).unwrap_err();
    let msg = e.to_string();
    assert!(matches!(e, Error::Fit(FitError::Residual { .. })), "{msg}");
    assert!(
        msg.contains("noisy.stl") && msg.contains("worst at station"),
        "{msg}"
    );
}

#[test]
fn a_bad_option_names_its_field() {
    let (v, f) = gen::mesh(&gen::straight(), 2.0, 0.0, 0.0, 0);
    let opts = FitOptions {
        max_rms_mm: -1.0,
        ..FitOptions::default()
    };
    let msg = fit_mesh(v, f, "pipe.stl", &opts).unwrap_err().to_string();
    assert!(
        msg.contains("pipe.stl") && msg.contains("max_rms_mm"),
        "{msg}"
    );
}

#[test]
fn binary_and_ascii_stl_files_give_the_same_fit() {
    let truth = gen::torus();
    let (v, f) = gen::mesh(&truth, 1.5, 0.0, 0.0, 0);
    let dir = tempfile::tempdir().unwrap();
    let (bin, ascii) = (dir.path().join("t.stl"), dir.path().join("a.stl"));
    std::fs::write(&bin, gen::binary_stl(&v, &f)).unwrap();
    std::fs::write(&ascii, gen::ascii_stl(&v, &f)).unwrap();
    let a = Part::from_mesh(&bin, &FitOptions::default()).unwrap();
    let b = Part::from_mesh(&ascii, &FitOptions::default()).unwrap();
    assert!(errors(&truth, &a).guide_rms < 0.05);
    assert!((a.report().rms_mm - b.report().rms_mm).abs() < 1e-4);
    let missing = Part::from_mesh(dir.path().join("none.stl"), &FitOptions::default()).unwrap_err();
    assert!(missing.to_string().contains("none.stl"), "{missing}");
    assert_eq!(missing.kind(), waam_slicer::ErrorKind::Io);
    let files = a.write(dir.path().join("out")).unwrap();
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&files[1]).unwrap()).unwrap();
    assert!(json["rms_mm"].as_f64().unwrap() < 0.01);
    assert!(json["stations"].as_array().unwrap().len() > 10);
    Part::read(&files[0]).unwrap();
}

/// A vertex a kilometre from a 12 mm pipe (the fuzzer's `fit_stl` found one
/// that took minutes in the refit): refused, naming the guide's length and
/// the knot limit.
#[test]
fn a_vertex_far_from_the_tube_is_refused_naming_the_knot_limit() {
    let truth = gen::straight();
    let (mut v, f) = gen::mesh(&truth, 2.0, 0.0, 0.0, 3);
    v[5].x += 1e6;
    let e = fit_mesh(v, f, "far.stl", &FitOptions::default()).unwrap_err();
    let text = e.to_string();
    assert!(
        text.contains("far.stl") && text.contains("over the limit of 1000"),
        "{text}"
    );
}

/// A coarse export of the swelling-radius tube (issue 47): 5 rings of 13
/// points over 90 mm, the radius 12 + 3 sin(pi s/L) - 1.5 sin(2 pi s/L) mm
/// known only at the rings. The export's own radius, linear between its
/// rings at the vertices' angles, is computed here from its vertices
/// against the generator's radius; the fitted radius must be no further
/// from the generator's than that (RMS and largest, over 400 points), and
/// within 0.2 mm RMS and 0.3 mm at most, plain and untidy in metres, with
/// a warning that the law is interpolated between its rings. Before,
/// the law took the stations that borrow their neighbours' rings too and
/// swung ±2 mm between the rings (0.92 mm RMS, 2.25 mm at most).
#[test]
fn a_coarse_swelling_radius_export_fits_within_what_its_rings_hold() {
    let truth = gen::swelling();
    let (v, f, around) = gen::coarse(&truth, 0.5);
    // The export's radius at z: linear between its rings (straight axis z).
    let rings: Vec<(f64, f64)> = v
        .chunks(around)
        .map(|ring| {
            (
                ring[0].z,
                (ring[0] - Point3::new(0.0, 0.0, ring[0].z)).norm(),
            )
        })
        .collect();
    assert_eq!(rings.len(), 5, "the export's rings: {rings:?}");
    let export = |z: f64| {
        let w = rings
            .windows(2)
            .find(|w| z <= w[1].0)
            .unwrap_or(&rings[rings.len() - 2..]);
        let u = (z - w[0].0) / (w[1].0 - w[0].0);
        w[0].1 + (w[1].1 - w[0].1) * u
    };
    let (mut sum2, mut max) = (0.0, 0.0_f64);
    for i in 0..=400 {
        let z = truth.length * i as f64 / 400.0;
        let e = (export(z) - (truth.radius)(z)).abs();
        sum2 += e * e;
        max = max.max(e);
    }
    let export_rms = (sum2 / 401.0).sqrt();
    let (v_m, f_m) = gen::untidy(&v, &f, around, Point3::new(300.0, 300.0, 300.0), 0.1);
    let metres = FitOptions {
        units: waam_slicer::fit::Units::M,
        ..FitOptions::default()
    };
    for (name, v, f, opts) in [
        (
            "swelling-coarse.stl",
            v.clone(),
            f.clone(),
            FitOptions::default(),
        ),
        ("swelling-coarse-m.stl", gen::in_metres(&v_m), f_m, metres),
    ] {
        let fitted = fit_mesh(v, f, name, &opts).unwrap_or_else(|e| panic!("{name}: {e}"));
        let e = errors(&truth, &fitted);
        eprintln!(
            "{name}: radius rms {:.4} max {:.4} (the export's own: rms {export_rms:.4} max {max:.4}), guide rms {:.4}",
            e.radius_rms, e.radius_max, e.guide_rms
        );
        assert!(
            e.radius_rms <= export_rms && e.radius_max <= max,
            "{name}: {e:?}"
        );
        assert!(e.radius_rms < 0.2 && e.radius_max < 0.3, "{name}: {e:?}");
        assert!(e.guide_rms < 0.01, "{name}: {e:?}");
        // Its rings are up to 31 mm apart: the fit says it interpolates.
        let w = &fitted.report().warnings;
        assert!(
            w.iter().any(|w| w.contains("only at rings up to 3")),
            "{name}: {w:?}"
        );
    }
}

/// Coarse exports of the S-bend (15 rings of 10) and of the helix (18 rings
/// of 9), facets within 0.5 mm of the surface (issue 47), plain and untidy
/// in metres. Their rings lie askew to the stations all along: both were
/// refused "not near a circle" (0.70 and 1.44 mm RMS) on their vertices and
/// on the points along their edges. The third pass marches a first guide
/// through plane cuts of the skin and refits it to plane cuts before the
/// vertices (`fit::cut`). Against the generator's tube: guide within
/// 0.1 mm RMS and 0.3 mm at most, radius within 0.05 mm RMS, the fitted
/// surface within 0.1 mm RMS and 0.3 mm at most (issue 47's goal for
/// exported meshes).
/// A reducer as CAD writes it, rings only where its profile bends: a pipe
/// of radius 23.5 mm for 185 mm, a cone flaring at 60 degrees to 117.5 mm
/// over 55 mm, a pipe to 1199 mm (the unseen exports' pebble-bed vessel, an
/// outer skin at a tenth of its size). Before, the law through its 5 rings
/// bowed below zero and the mesh was refused as "a cone or a cap, not a
/// tube?". Now the law runs straight between the rings, each ring's radius
/// read at its own place, with knots closer and closer toward each kink.
/// Against the exporter's straight facets: within 0.05 mm at the kinks,
/// 0.01 mm away from them (measured 0.027 and 0.0000), and the fitted
/// surface no further from the mesh than the 64-gon's facets from its
/// circle, r (1 - cos(pi / 64)). The same as a wall 50 mm thick at full
/// size in metres (knots 88 mm apart): within 0.3 mm at the kinks
/// (measured 0.20).
#[test]
fn a_reducer_written_as_rings_where_its_profile_bends_fits() {
    const PROFILE: [(f64, f64); 5] = [
        (0.0, 23.5),
        (185.0, 23.5),
        (240.0, 117.5),
        (1179.0, 117.5),
        (1199.0, 117.5),
    ];
    // Mid radius at z of the reducer scaled by `k` (mm).
    let profile = |z: f64, k: f64| {
        let w = PROFILE
            .windows(2)
            .find(|w| z <= k * w[1].0)
            .unwrap_or(&PROFILE[3..]);
        k * (w[0].1 + (w[1].1 - w[0].1) * (z / k - w[0].0) / (w[1].0 - w[0].0))
    };
    let skin = |k: f64, off: f64| {
        let rings: Vec<Vec<Point3>> = PROFILE
            .iter()
            .map(|&(z, r)| gen::circle_z(64, k * r + off, k * z))
            .collect();
        gen::lofted(&rings)
    };
    let (v, f) = gen::join(skin(10.0, 25.0), skin(10.0, -25.0));
    let metres = FitOptions {
        units: waam_slicer::fit::Units::M,
        ..FitOptions::default()
    };
    // (name, scale, mesh, options, bounds on the radius error near and
    // away from the kinks, mm; the largest ring radius, mm).
    for (name, k, (v, f), opts, bounds, largest) in [
        (
            "reducer.stl",
            1.0,
            skin(1.0, 0.0),
            FitOptions::default(),
            (0.05, 0.01),
            117.5,
        ),
        (
            "reducer-wall-m.stl",
            10.0,
            (gen::in_metres(&v), f),
            metres,
            (0.3, 0.01),
            1200.0,
        ),
    ] {
        let fitted = fit_mesh(v, f, name, &opts).unwrap_or_else(|e| panic!("{name}: {e}"));
        let part = Part::from_toml_str(&fitted.toml, "reducer.toml").unwrap();
        let (tube, range) = (&part.tube, part.tube.range());
        // The radius error (mm) near a kink (within 100 mm, or 1 m at full
        // size: eight knots) and away from them; the guide's distance to
        // the z axis (mm).
        let (mut near, mut far, mut off) = (0.0_f64, 0.0_f64, 0.0_f64);
        for i in 0..=20_000 {
            let t = range.t_min + (range.t_max - range.t_min) * i as f64 / 20_000.0;
            let p = tube.guide().point(t);
            let e = (tube.radius(t) - profile(p.z, k)).abs();
            if PROFILE[1..3]
                .iter()
                .any(|z| (p.z - k * z.0).abs() < k * 100.0)
            {
                near = near.max(e);
            } else {
                far = far.max(e);
            }
            off = off.max(p.x.hypot(p.y));
        }
        let rep = fitted.report();
        eprintln!(
            "{name}: radius error {far:.4} mm away from the kinks, {near:.4} near them; guide {off:.2e} mm off the axis; surface to mesh {:?} mm",
            rep.surface_to_mesh_max_mm
        );
        assert!(off < 1e-3, "{name}: guide off the axis by {off} mm");
        assert!(
            far < bounds.1,
            "{name}: radius error {far} mm away from the kinks"
        );
        assert!(
            near < bounds.0,
            "{name}: radius error {near} mm at the kinks"
        );
        let surface = rep.surface_to_mesh_max_mm.expect("measured");
        let facets = largest * (1.0 - (std::f64::consts::PI / 64.0).cos());
        assert!(
            surface < facets + bounds.0,
            "{name}: fitted surface {surface} mm from the mesh, its facets {facets} mm inside its circle"
        );
    }
}

#[test]
fn coarse_s_bend_and_helix_exports_fit_through_plane_cuts() {
    for truth in [gen::s_bend(), gen::helix()] {
        let (v, f, around) = gen::coarse(&truth, 0.5);
        let rings = v.len() / around;
        assert!(
            rings >= 15 && around <= 10,
            "{}: {rings} rings of {around}",
            truth.name
        );
        let (v_m, f_m) = gen::untidy(&v, &f, around, Point3::new(300.0, 300.0, 300.0), 0.1);
        let metres = FitOptions {
            units: waam_slicer::fit::Units::M,
            ..FitOptions::default()
        };
        for (name, v, f, opts) in [
            (
                format!("{}-coarse.stl", truth.name),
                v.clone(),
                f.clone(),
                FitOptions::default(),
            ),
            (
                format!("{}-coarse-m.stl", truth.name),
                gen::in_metres(&v_m),
                f_m,
                metres,
            ),
        ] {
            let fitted = fit_mesh(v, f, &name, &opts).unwrap_or_else(|e| panic!("{name}: {e}"));
            let e = errors(&truth, &fitted);
            let (s_rms, s_max) = surface_errors(&truth, &fitted);
            eprintln!(
                "{name}: {rings} rings of {around}: guide rms {:.3} max {:.3}, radius rms {:.3}, surface rms {s_rms:.3} max {s_max:.3}",
                e.guide_rms, e.guide_max, e.radius_rms
            );
            assert!(e.guide_rms < 0.1 && e.guide_max < 0.3, "{name}: {e:?}");
            assert!(e.radius_rms < 0.05, "{name}: {e:?}");
            assert!(s_rms < 0.1 && s_max < 0.3, "{name}: {s_rms} {s_max}");
        }
    }
}

/// A coarse export of a coil (`gen::helix`: radius 40, 60 mm a turn,
/// r 8, three quarters of a turn; rings of 24 vertices 12, 16 and 24 mm
/// apart along it, their facets up to 0.43, 0.76 and 1.7 mm inside its
/// curve between the rings). A ring's centre and plane are the exporter's
/// samples of the axis and its tangent: between two rings the guide runs on
/// the cubic they define (`fit::coarse::bridge_between_rings`), not along
/// the facets' chords. With the default knots (4 mm) the surface lies
/// within 0.02 mm RMS and 0.08 mm at most of the true one, with no
/// coarse-export warning; so it does with knots 1.5 times the rings'
/// distance. Before the bridge, the default knots followed the chords (0.14
/// mm RMS at 12 mm, with a warning naming the knots to take; refused at 16).
#[test]
fn a_coarse_coil_fits_smooth_between_its_rings() {
    let truth = gen::helix();
    for g in [12.0, 16.0, 20.0] {
        let (v, f) = gen::mesh_around(&truth, g, 24, 0.0, 0.0, 0);
        let wide = FitOptions {
            knot_spacing_mm: Some(1.5 * g),
            ..FitOptions::default()
        };
        for (knots, opts) in [("default", FitOptions::default()), ("wide", wide)] {
            let p = fit_mesh(v.clone(), f.clone(), "coil.stl", &opts)
                .unwrap_or_else(|e| panic!("{g} {knots}: {e}"));
            let (rms, max) = surface_errors(&truth, &p);
            eprintln!("rings {g} mm apart, {knots} knots: surface {rms:.4} / {max:.4} mm");
            assert!(rms < 0.02 && max < 0.08, "{g} {knots}: {rms} {max}");
            let w = &p.report().warnings;
            assert!(
                !w.iter().any(|w| w.starts_with("a coarse export")),
                "{g} {knots}: {w:?}"
            );
        }
    }
}

/// The coil of `gen::helix` (r 8) exported coarser still: rings of 24
/// vertices 24, 32 and 48 mm apart (3, 4 and 6 tube radii, 34 to 68
/// degrees of its turn). The level sets of the distance along its surface
/// shear across the turn, and the first guide through them left the rings
/// by 31 to 68 mm: every pass diverged ("the guide diverged (3576 mm long,
/// from 100 mm)"). A swept export's rings (`fit::topology::swept_rings`:
/// the vertices one edge, two edges, ... from the start end, each as many
/// as the end's and flat) are its samples of the axis; the first guide
/// runs through them when the level sets leave them by over half a radius.
/// Now the surface lies within 0.01 mm RMS and 0.03 mm at most of the true
/// one (measured 0.0022 / 0.0053 at worst).
#[test]
fn a_coil_in_rings_up_to_six_radii_apart_fits_through_its_rings() {
    let truth = gen::helix();
    for g in [24.0, 32.0, 48.0] {
        let (v, f) = gen::mesh_around(&truth, g, 24, 0.0, 0.0, 0);
        let p = fit_mesh(v, f, "coil.stl", &FitOptions::default())
            .unwrap_or_else(|e| panic!("rings {g} mm apart: {e}"));
        let (rms, max) = surface_errors(&truth, &p);
        eprintln!("rings {g} mm apart: surface {rms:.4} / {max:.4} mm");
        assert!(rms < 0.01 && max < 0.03, "{g}: {rms} {max}");
    }
}

/// The coil of VesselMeshGenerator's own defaults, an exporter the project
/// had not seen (issue 47): coil radius 100 mm, 100 mm a turn, 6 turns,
/// tube radius 15 mm, 100 rings of 20 vertices, 38.8 mm (2.6 tube radii)
/// apart along the coil, its facets up to 1.9 mm inside the curved tube
/// between the rings; written here from the closed-form helix
/// (`gen::coil`). With the default options it fits within 0.01 mm RMS and
/// 0.03 mm at most of the true surface (the author's own mesh: slices
/// 0.0001 / 0.0017 mm off the author's helix). Before the rings' bridge
/// the author's mesh was refused (station 0: not near a circle).
#[test]
fn the_coil_of_an_exporters_defaults_fits_between_its_rings() {
    let truth = gen::coil(100.0, 100.0, 6.0, 15.0);
    let gap = truth.length / 99.0 * (1.0 + 1e-9);
    let (v, f) = gen::mesh_around(&truth, gap, 20, 0.0, 0.0, 0);
    assert_eq!(v.len(), 100 * 20);
    let p = fit_mesh(v, f, "vessel.stl", &FitOptions::default()).unwrap_or_else(|e| panic!("{e}"));
    let (rms, max) = surface_errors(&truth, &p);
    eprintln!("coil in 100 rings: surface {rms:.4} / {max:.4} mm");
    assert!(rms < 0.01 && max < 0.03, "{rms} {max}");
    assert!(p.report().converged, "{:?}", p.report().warnings);
}

/// A sine tube (amplitude 60 mm, wavelength 300 mm, radius 15 mm: bends
/// down to 2.5 radii) as an exporter that frames each ring by its tangent
/// crossed with z writes it (ib565/colabdesign-stl, the unseen exports'
/// sine tube in cm): 300 rings of 24, the band of triangles at each crest
/// twisted through the axis. Its first guide cut the crests short, and the
/// second refit's sections there were refused as not near a circle (0.89
/// mm RMS, allowed 0.5 mm), a refusal that stood though the refits to the
/// round sections brought them round. Now it fits: guide and radius
/// against the closed form within 0.01 mm.
#[test]
fn a_sine_tube_with_twisted_bands_at_its_crests_fits() {
    let truth = gen::sine(60.0, 300.0, 15.0);
    let (v, f) = gen::flipped_sine(60.0, 300.0, 15.0, 300, 24);
    let p = fit_mesh(v, f, "sine.stl", &FitOptions::default()).unwrap_or_else(|e| panic!("{e}"));
    let e = errors(&truth, &p);
    eprintln!("sine tube: {e:?}");
    assert!(e.guide_max < 0.01 && e.radius_max < 0.01, "{e:?}");
}

/// A coarse export of the coil whose rings are not flat (each vertex but
/// the end rings' 0.6 or 1 mm along the tube either side of its ring, in
/// turn, over the 0.5 mm a ring's plane allows; rings 12 mm apart) has no
/// rings to bridge. Its first guide cut the coil short, and the sections
/// of the second refit were refused as not near a circle; the refits to the
/// round sections alone then brought them all round, and the fit goes on
/// on its vertices. Before, that refusal stood for the vertices' pass and
/// a later pass followed the facets' chords (guide 0.17 mm RMS, 0.35 mm at
/// most from the truth, with the coarse export's warning). Now: 0.027 /
/// 0.046 mm (0.6 mm along) and 0.045 / 0.075 mm (1 mm), asserted 0.06 /
/// 0.1, and no warning: the guide holds the vertices, not the chords.
/// (The warning itself: `coarse::tests::the_chords_warning_names_the_rings_and_the_knots`.)
#[test]
fn a_coarse_export_without_flat_rings_fits_on_its_vertices() {
    for amp in [0.6, 1.0] {
        let truth = gen::helix();
        let around = 24;
        let (mut v, f) = gen::mesh_around(&truth, 12.0, around, 0.0, 0.0, 0);
        let last = v.len() / around - 1;
        let gap = truth.length / last as f64;
        for (k, p) in v.iter_mut().enumerate() {
            let ring = k / around;
            if ring == 0 || ring == last {
                continue;
            }
            let s = ring as f64 * gap;
            let along = ((truth.centre)(s + 0.01) - (truth.centre)(s - 0.01)).normalize();
            *p += along * if k % 2 == 0 { amp } else { -amp };
        }
        let p = fit_mesh(v, f, "coil.stl", &FitOptions::default())
            .unwrap_or_else(|e| panic!("{amp} mm along: {e}"));
        let e = errors(&truth, &p);
        eprintln!("{amp} mm along: {e:?}");
        assert!(
            e.guide_rms < 0.05 && e.guide_max < 0.1,
            "{amp} mm along: {e:?}"
        );
        assert!(p.report().warnings.is_empty(), "{:?}", p.report().warnings);
    }
}

/// A fit stopped before its guide settled (here after 2 refits) says so in
/// fit.json's warnings, with its last move; the same mesh given its refits
/// settles and has no such warning.
#[test]
fn a_guide_that_did_not_settle_is_a_warning() {
    let (v, f) = gen::mesh(&gen::elbow(), 1.0, 0.0, 0.0, 0);
    let short = FitOptions {
        max_iterations: 2,
        ..FitOptions::default()
    };
    let p = fit_mesh(v.clone(), f.clone(), "elbow.stl", &short).unwrap();
    let r = p.report();
    assert!(!r.converged);
    let said = |r: &waam_slicer::fit::FitReport| {
        r.warnings
            .iter()
            .any(|w| w.starts_with("the guide did not settle in"))
    };
    assert!(said(r), "{:?}", r.warnings);
    let p = fit_mesh(v, f, "elbow.stl", &FitOptions::default()).unwrap();
    assert!(
        p.report().converged && !said(p.report()),
        "{:?}",
        p.report().warnings
    );
}

/// A straight written as CAD tools write it: one strip of long triangles
/// with vertices only at its two end rings (here 200 mm long, radius 10, 32
/// around; and between two finely meshed stubs of 20 mm). The stations
/// between the rings hold no vertex and borrow none (their rings are 20 r
/// apart). Between the strip's two end rings they are bridged (a straight
/// between parallel rings) and the radius is the rings' own: within 0.001
/// mm. Between the stubs, whose rings 1 mm apart run together along the
/// guide, they take plane cuts of the facets: radius within 0.05 mm (the
/// 32-gon's facets lie up to r (1 - cos(pi / 32)) = 0.048 mm inside the
/// circle). Both fit the pipe's length and end centres within 0.01 mm and
/// warn of nothing coarse (a straight's facets lie on it along the guide).
#[test]
fn a_straight_written_as_one_strip_of_long_triangles_fits() {
    let strip = vec![gen::circle_z(32, 10.0, 0.0), gen::circle_z(32, 10.0, 200.0)];
    let mut stubs = gen::pipe_rings(32, 10.0, 0.0, 20.0, 1.0);
    stubs.extend(gen::pipe_rings(32, 10.0, 180.0, 200.0, 1.0));
    for (name, rings) in [("strip", strip), ("stubs", stubs)] {
        let (v, f) = gen::lofted(&rings);
        let p = fit_mesh(v, f, "strip.stl", &FitOptions::default())
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        let r = p.report();
        assert!(
            (r.length_mm - 200.0).abs() < 0.01,
            "{name}: {}",
            r.length_mm
        );
        let tol = if name == "strip" { 1e-3 } else { 0.05 };
        assert!(
            (r.radius_min_mm - 10.0).abs() < tol && (r.radius_max_mm - 10.0).abs() < tol,
            "{name}: {} {}",
            r.radius_min_mm,
            r.radius_max_mm
        );
        for e in [&r.start, &r.end] {
            let c = e.centre_mm;
            assert!(c[0].hypot(c[1]) < 0.01, "{name}: {c:?}");
        }
        assert!(
            !r.warnings.iter().any(|w| w.starts_with("a coarse export")),
            "{name}: {:?}",
            r.warnings
        );
    }
}
