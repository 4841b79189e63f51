//! `waam fit --substrate`: the written part stands on the given STL
//! substrate (named by its absolute path, so `waam slice` reads it from any
//! working directory) and slices as on the start end's plane; a start end
//! off the substrate is refused naming the file and the distance.

use crate::common::waam;
use crate::gen;
use std::path::Path;
use waam_slicer::math::Point3;

/// A flat square plate at height `z` (mm), normal +z, `half` mm across
/// from (20, 0): under the elbow's start end (the origin) and its bend.
fn plate(z: f64, half: f64) -> (Vec<Point3>, Vec<[u32; 3]>) {
    let (cx, cy) = (20.0, 0.0);
    let v = vec![
        Point3::new(cx - half, cy - half, z),
        Point3::new(cx + half, cy - half, z),
        Point3::new(cx + half, cy + half, z),
        Point3::new(cx - half, cy + half, z),
    ];
    (v, vec![[0, 1, 2], [0, 2, 3]])
}

/// The top band (±`deg` degrees) of a cylinder of radius `r` whose axis runs
/// along y through (0, 0, -r): its top line is the y axis, on which the
/// elbow's start end stands. `n` facets around the band, `m` along.
fn cylinder_band(r: f64, deg: f64, n: usize, m: usize) -> (Vec<Point3>, Vec<[u32; 3]>) {
    let mut v = Vec::new();
    for i in 0..=n {
        let a = (-deg + 2.0 * deg * i as f64 / n as f64).to_radians();
        for j in 0..=m {
            let y = -60.0 + 120.0 * j as f64 / m as f64;
            v.push(Point3::new(r * a.sin(), y, r * a.cos() - r));
        }
    }
    let id = |i: usize, j: usize| (i * (m + 1) + j) as u32;
    let mut f = Vec::new();
    for i in 0..n {
        for j in 0..m {
            f.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
            f.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    (v, f)
}

fn write_stl(dir: &Path, name: &str, mesh: (Vec<Point3>, Vec<[u32; 3]>)) -> std::path::PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, gen::binary_stl(&mesh.0, &mesh.1)).unwrap();
    p
}

fn run(cmd: &mut std::process::Command) -> std::process::Output {
    let done = cmd.output().unwrap();
    assert!(
        done.status.success(),
        "{}",
        String::from_utf8_lossy(&done.stderr)
    );
    done
}

/// `waam fit` of `stl` into `out`, with `extra` arguments.
fn fit(stl: &Path, out: &Path, extra: &[&std::ffi::OsStr]) {
    run(waam()
        .args(["--quiet", "fit"])
        .arg(stl)
        .arg("--out")
        .arg(out)
        .args(extra));
}

/// `waam slice` of `part` run from the folder `cwd`: the number of layers.
fn slice_layers(part: &Path, out: &Path, cwd: &Path) -> u64 {
    run(waam()
        .current_dir(cwd)
        .args(["--quiet", "slice"])
        .arg(part)
        .args(["--points", "60", "--no-wall", "--out"])
        .arg(out));
    let s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    s["layers"]
        .as_u64()
        .unwrap_or_else(|| panic!("no layer count in {s}"))
}

#[test]
fn an_elbow_on_a_flat_and_on_a_cylindrical_stl_substrate_slices() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let (v, f) = gen::mesh(&gen::elbow(), 1.5, 0.02, 0.0, 5);
    let stl = write_stl(d, "elbow.stl", (v, f));
    let flat = write_stl(d, "plate.stl", plate(0.0, 60.0));
    let round = write_stl(d, "drum.stl", cylinder_band(150.0, 20.0, 80, 12));
    // Another working directory: the part files must not depend on it.
    let elsewhere = tempfile::tempdir().unwrap();

    fit(&stl, &d.join("plane"), &[]);
    let on_plane = slice_layers(
        &d.join("plane/part.toml"),
        &d.join("s-plane"),
        elsewhere.path(),
    );

    fit(
        &stl,
        &d.join("plate"),
        &["--substrate".as_ref(), flat.as_os_str()],
    );
    let text = std::fs::read_to_string(d.join("plate/part.toml")).unwrap();
    assert!(text.contains("kind = \"mesh\""), "{text}");
    let named = std::fs::canonicalize(&flat).unwrap();
    assert!(text.contains(named.to_str().unwrap()), "{text}");
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(d.join("plate/fit.json")).unwrap()).unwrap();
    let gap = report["substrate_distance_mm"].as_f64().unwrap();
    assert!(gap < 0.1, "the start end stands on the plate: {report}");
    let on_plate = slice_layers(
        &d.join("plate/part.toml"),
        &d.join("s-plate"),
        elsewhere.path(),
    );
    assert!(
        on_plate.abs_diff(on_plane) <= 1,
        "{on_plate} layers on the plate, {on_plane} on the plane"
    );

    fit(
        &stl,
        &d.join("drum"),
        &["--substrate".as_ref(), round.as_os_str()],
    );
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(d.join("drum/fit.json")).unwrap()).unwrap();
    let drum_gap = report["substrate_distance_mm"].as_f64().unwrap();
    // The flat start end's rim lies above the drum by up to
    // 150 - sqrt(150² - 12²) = 0.48 mm at x = ±12.
    assert!(drum_gap > 0.3 && drum_gap < 0.6, "{report}");
    let on_drum = slice_layers(
        &d.join("drum/part.toml"),
        &d.join("s-drum"),
        elsewhere.path(),
    );
    assert!(on_drum > 0);
    assert!(d.join("drum/report.html").exists());
    eprintln!(
        "layers: {on_plane} on the start plane, {on_plate} on the STL plate (rim {gap:.4} mm off), {on_drum} on the STL drum (rim {drum_gap:.4} mm off)"
    );
}

#[test]
fn a_start_end_off_the_substrate_is_refused_naming_the_file_and_the_distance() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let (v, f) = gen::mesh(&gen::elbow(), 2.0, 0.0, 0.0, 1);
    let stl = write_stl(d, "elbow.stl", (v, f));
    let low = write_stl(d, "low-plate.stl", plate(-5.0, 60.0));
    let done = waam()
        .arg("fit")
        .arg(&stl)
        .arg("--out")
        .arg(d.join("o"))
        .arg("--substrate")
        .arg(&low)
        .output()
        .unwrap();
    assert_eq!(done.status.code(), Some(1));
    let err = String::from_utf8_lossy(&done.stderr);
    assert!(
        err.contains("elbow.stl") && err.contains("low-plate.stl") && err.contains("5.000 mm"),
        "{err}"
    );
    assert!(!d.join("o").join("part.toml").exists());
    // A missing substrate file is named too.
    let done = waam()
        .arg("fit")
        .arg(&stl)
        .arg("--out")
        .arg(d.join("o"))
        .arg("--substrate")
        .arg(d.join("missing.stl"))
        .output()
        .unwrap();
    assert_eq!(done.status.code(), Some(1));
    let err = String::from_utf8_lossy(&done.stderr);
    assert!(err.contains("missing.stl"), "{err}");
}
