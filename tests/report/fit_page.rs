//! The fit page in headless Chromium: an elbow mesh from the fit tests'
//! generator, fitted, its page opened with `#selftest`: no script error,
//! nothing loaded, the mesh alone (unshaded) drawn in more than two colours
//! by the distance of its vertices to the fitted tube.

use super::{chromium, open_and_check, out_dir, pixels};
use crate::gen;
use waam_slicer::fit::TubeMesh;
use waam_slicer::report::{write_fit_report_html, FitReportInput};
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

/// The two skins of a wall: the page offers the wall thickness along the
/// guide and draws both fitted skins; bad input is refused naming the file
/// and the place (no browser needed).
#[test]
fn a_wall_page_has_the_thickness_and_bad_input_is_named() {
    let truth = gen::elbow();
    let (mut v, mut f) = gen::mesh(&truth, 1.5, 0.0, 1.5, 3);
    let (vi, fi) = gen::mesh(&truth, 1.5, 0.0, -1.5, 4);
    let base = v.len() as u32;
    v.extend(vi);
    f.extend(fi.into_iter().map(|t| t.map(|i| i + base)));
    let mesh = TubeMesh::new(v, f, "wall.stl").unwrap();
    let fitted = Part::from_tube_mesh(&mesh, &FitOptions::default()).unwrap();
    let mut page = Vec::new();
    write_fit_report_html(
        &mut page,
        &FitReportInput::new("wall", &fitted.mesh, &fitted.fit),
    )
    .unwrap();
    let page = String::from_utf8(page).unwrap();
    let open = "id=\"report-data\">";
    let start = page.find(open).unwrap() + open.len();
    let end = start + page[start..].find("</script>").unwrap();
    let data: serde_json::Value = serde_json::from_str(&page[start..end]).unwrap();
    let keys: Vec<&str> = data["fields"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| f["key"].as_str().unwrap())
        .collect();
    assert_eq!(keys, ["distance", "radius", "wall"]);
    let wall = data["fit"]["report"]["wall"]["mean_mm"].as_f64().unwrap();
    assert!((wall - 3.0).abs() < 0.05, "{wall}");
    assert_eq!(data["fit"]["report"]["skins"], 2);

    // Distances of another mesh.
    let mut other = fitted.fit.clone();
    other.vertex_distance_mm.pop();
    let err = write_fit_report_html(
        &mut Vec::new(),
        &FitReportInput::new("wall", &fitted.mesh, &other),
    )
    .unwrap_err()
    .to_string();
    assert!(
        err.contains("wall.stl") && err.contains("vertex distances"),
        "{err}"
    );
    // A vertex that is not finite.
    let mut bad = fitted.mesh.clone();
    bad.vertices[7].y = f64::NAN;
    let err = write_fit_report_html(
        &mut Vec::new(),
        &FitReportInput::new("wall", &bad, &fitted.fit),
    )
    .unwrap_err()
    .to_string();
    assert!(
        err.contains("wall.stl") && err.contains("vertex 7"),
        "{err}"
    );
    // A bound below 2.
    let input = FitReportInput {
        max_triangles: 1,
        ..FitReportInput::new("wall", &fitted.mesh, &fitted.fit)
    };
    let err = write_fit_report_html(&mut Vec::new(), &input)
        .unwrap_err()
        .to_string();
    assert!(err.contains("max_triangles"), "{err}");
}
