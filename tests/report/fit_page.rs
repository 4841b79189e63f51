//! The fit page in headless Chromium: an elbow mesh from the fit tests'
//! generator, fitted, its page opened with `#selftest`: no script error,
//! nothing loaded, the mesh alone (unshaded) drawn in more than two colours
//! by the distance of its vertices to the fitted tube.

use super::{chromium, open_and_check, out_dir, pixels};
use crate::gen;
use waam_slicer::fit::TubeMesh;
use waam_slicer::{FitOptions, Part};

#[test]
fn fit_report_draws_the_mesh_coloured_by_distance_in_chromium() {
    let Some(browser) = chromium() else { return };
    let (dir, _keep) = out_dir();
    let (v, f) = gen::mesh(&gen::elbow(), 1.5, 0.05, 0.0, 3);
    let mesh = TubeMesh::new(v, f, "elbow.stl").unwrap();
    let fitted = Part::from_tube_mesh(&mesh, &FitOptions::default()).unwrap();
    let html = fitted.write_report(dir.join("fit")).unwrap();
    let r = open_and_check(&browser, &html);
    let keys: Vec<&str> = r["fields"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| f[0].as_str().unwrap())
        .collect();
    assert_eq!(keys, ["distance", "radius"], "{r}");
    assert_eq!(r["mesh_field"], "distance", "{r}");
    let of = r["first"]["of"].as_u64().unwrap();
    let mesh_only = &r["mesh_only"];
    // The mesh covers a good part of the canvas, in the distance's colours.
    assert!(pixels(mesh_only) > of / 20, "mesh barely drawn: {r}");
    let colours = mesh_only["colours"].as_u64().unwrap();
    assert!(colours > 2, "mesh drawn in {colours} colours: {r}");
    // Under a field of the guide the mesh is one colour (and its edges).
    let plain = r["mesh_plain"]["colours"].as_u64().unwrap();
    assert!(
        plain < colours,
        "plain mesh {plain} colours, by distance {colours}: {r}"
    );
    // Hovering a vertex shows its distance.
    let text = r["pick"]["text"].as_str().unwrap_or_default();
    assert!(
        text.starts_with("mesh vertex ")
            && text.contains("distance of the mesh to the fitted tube"),
        "{r}"
    );
}
