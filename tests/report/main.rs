//! The interactive report in a real browser (issue 20): the reports of a
//! sliced and of a planned sample part are opened in headless Chromium,
//! which must run the page without a script error, draw the canvas (the page
//! reads its own pixels back), load nothing (the page lists the resources the
//! browser fetched; every host name resolves to nothing), and animate the
//! robot of the plan. Without WebGL the page must say so. The page of a
//! tube fitted to a mesh (`fit_page.rs`) draws the mesh coloured by the
//! distance of its vertices to the fitted tube.
//!
//! Chromium comes from the system's packages (`.ci/run` installs Debian's
//! `chromium`). If it is missing the tests fail saying so, unless
//! `WAAM_SKIP_BROWSER=1` is set; `WAAM_CHROMIUM` names another binary.
//! `WAAM_REPORT_KEEP=<folder>` keeps the reports and screenshots there.

mod fit_page;
// The fit tests' independent tube-mesh generator.
#[allow(dead_code)]
#[path = "../fit/gen.rs"]
mod gen;

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use waam_slicer::io::cell_file::read_cell_file;
use waam_slicer::io::part_file::read_part_file;
use waam_slicer::optimise::{layer_points, optimise, OptimiseOptions};
use waam_slicer::path::{distance_map, slice, Discretisation};
use waam_slicer::process::plan_process;
use waam_slicer::report::{write_report, PlanView, ReportInput};
use waam_slicer::toolaxis::tool_axes;

fn repo(rel: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(rel)
}

/// The Chromium binary, or `None` when the browser tests are skipped on purpose.
fn chromium() -> Option<PathBuf> {
    if let Some(p) = std::env::var_os("WAAM_CHROMIUM") {
        return Some(PathBuf::from(p));
    }
    for p in ["/usr/bin/chromium", "/usr/bin/chromium-browser"] {
        if Path::new(p).exists() {
            return Some(PathBuf::from(p));
        }
    }
    if std::env::var("WAAM_SKIP_BROWSER").as_deref() == Ok("1") {
        eprintln!("WAAM_SKIP_BROWSER=1: browser test skipped");
        return None;
    }
    panic!(
        "headless Chromium not found at /usr/bin/chromium: install it \
         (`apt-get install -y --no-install-recommends chromium`; .ci/run does), \
         name it with WAAM_CHROMIUM, or set WAAM_SKIP_BROWSER=1 to skip the browser tests"
    );
}

/// Where reports go: `WAAM_REPORT_KEEP` if set, else a temporary folder.
fn out_dir() -> (PathBuf, Option<tempfile::TempDir>) {
    match std::env::var_os("WAAM_REPORT_KEEP") {
        Some(d) => {
            let d = PathBuf::from(d);
            std::fs::create_dir_all(&d).unwrap();
            (d, None)
        }
        None => {
            let t = tempfile::tempdir().unwrap();
            (t.path().to_path_buf(), Some(t))
        }
    }
}

/// Runs headless Chromium on `page` with `extra` arguments (120 s at most)
/// and returns its standard output.
fn run_chromium(browser: &Path, extra: &[String], page: &str) -> String {
    let profile = tempfile::tempdir().unwrap();
    let mut cmd = Command::new(browser);
    cmd.args([
        "--headless",
        "--no-sandbox",
        "--disable-gpu",
        "--disable-background-networking",
        "--disable-component-update",
        "--disable-sync",
        "--disable-quic",
        "--no-first-run",
        "--use-angle=swiftshader",
        "--enable-unsafe-swiftshader",
        "--host-resolver-rules=MAP * ~NOTFOUND",
        "--window-size=1280,800",
        "--virtual-time-budget=30000",
    ])
    .arg(format!("--user-data-dir={}", profile.path().display()))
    .args(extra)
    .arg(page)
    .stdin(Stdio::null())
    .stdout(Stdio::piped())
    .stderr(Stdio::piped());
    let mut child = cmd
        .spawn()
        .unwrap_or_else(|e| panic!("{}: {e}", browser.display()));
    let stdout = child.stdout.take().unwrap();
    let reader = std::thread::spawn(move || std::io::read_to_string(stdout).unwrap_or_default());
    let t0 = Instant::now();
    loop {
        if child.try_wait().unwrap().is_some() {
            break;
        }
        if t0.elapsed() > Duration::from_secs(120) {
            let _ = child.kill();
            panic!("chromium did not finish within 120 s on {page}");
        }
        std::thread::sleep(Duration::from_millis(100));
    }
    reader.join().unwrap()
}

/// The text of the element `<pre id="{id}" ...>` in a dumped DOM, unescaped.
fn element_text(dom: &str, id: &str) -> String {
    let open = format!("id=\"{id}\"");
    let at = dom
        .find(&open)
        .unwrap_or_else(|| panic!("no element #{id} in the dumped page"));
    let start = at + dom[at..].find('>').unwrap() + 1;
    let end = start + dom[start..].find("</pre>").unwrap();
    dom[start..end]
        .replace("&lt;", "<")
        .replace("&gt;", ">")
        .replace("&quot;", "\"")
        .replace("&amp;", "&")
}

/// Opens `html` with `#selftest` and returns the page's self-test record;
/// fails on any script error. Keeps a screenshot next to the page.
fn open_and_check(browser: &Path, html: &Path) -> serde_json::Value {
    let text = std::fs::read_to_string(html).unwrap();
    // Nothing that could load from the network: no URL with a scheme, no
    // external script, style, font or fetch.
    for bad in [
        "http://",
        "https://",
        "//cdn",
        "<link",
        " src=",
        "@import",
        "url(",
        "fetch(",
        "XMLHttpRequest",
        "import(",
    ] {
        assert!(!text.contains(bad), "{}: contains `{bad}`", html.display());
    }
    let url = format!("file://{}#selftest", html.display());
    let dom = run_chromium(browser, &["--dump-dom".into()], &url);
    assert!(
        dom.contains("data-selftest=\"done\""),
        "{}: the page's self-test did not finish; errors: {}\n{}",
        html.display(),
        element_text(&dom, "errors"),
        &dom[..dom.len().min(2000)]
    );
    let errors = element_text(&dom, "errors");
    assert!(
        errors.trim().is_empty(),
        "{}: script errors:\n{errors}",
        html.display()
    );
    let title = &dom[dom.find("<title>").unwrap()..dom.find("</title>").unwrap()];
    assert!(
        !title.contains("SCRIPT ERROR"),
        "error in the title: {title}"
    );
    let record: serde_json::Value = serde_json::from_str(&element_text(&dom, "selftest")).unwrap();
    eprintln!("{}: {record}", html.display());
    assert_eq!(record["webgl"], true, "WebGL did not start: {record}");
    assert_eq!(record["errors"], 0, "{record}");
    assert_eq!(
        record["resources"].as_array().map(Vec::len),
        Some(0),
        "the page loaded resources: {record}"
    );
    let screenshot = html.with_extension("png");
    run_chromium(
        browser,
        &[format!("--screenshot={}", screenshot.display())],
        &format!("file://{}", html.display()),
    );
    assert!(screenshot.exists(), "no screenshot written");
    record
}

fn pixels(v: &serde_json::Value) -> u64 {
    v["pixels"].as_u64().unwrap()
}

/// The drawing checks shared by both reports.
fn check_drawing(r: &serde_json::Value) {
    let of = r["first"]["of"].as_u64().unwrap();
    // The path covers a visible part of the canvas, in several colours
    // (the deviation field's ramp, the axis triad, the substrate).
    assert!(pixels(&r["first"]) > of / 200, "canvas nearly blank: {r}");
    assert!(pixels(&r["first"]) < of, "canvas one colour: {r}");
    assert!(r["first"]["colours"].as_u64().unwrap() >= 4, "{r}");
    // the layer field is a ramp: many colours
    let layer = r["fields"]
        .as_array()
        .unwrap()
        .iter()
        .find(|f| f[0] == "layer")
        .unwrap();
    assert!(layer[1].as_u64().unwrap() >= 8, "layer colours: {r}");
    // the wall and tool axes cover more than the path alone; a layer range less
    assert!(pixels(&r["all_layers"]) > pixels(&r["first"]), "{r}");
    assert!(pixels(&r["some_layers"]) < pixels(&r["all_layers"]), "{r}");
    // hovering the projected point of a vertex finds that vertex (or one drawn over it)
    let pick = &r["pick"];
    assert!(pick.is_object(), "nothing picked: {r}");
    let text = pick["text"].as_str().unwrap();
    assert!(
        text.starts_with("layer ") && text.contains("mm (part frame)"),
        "{text}"
    );
}

#[test]
fn sliced_report_draws_in_chromium() {
    let Some(browser) = chromium() else { return };
    let (dir, _keep) = out_dir();
    let part = read_part_file(&repo("parts/quarter-torus.toml")).unwrap();
    let path = slice(&part.tube, &part.substrate, &part.slice_options()).unwrap();
    let axes = tool_axes(
        &path,
        Some(&part.tube),
        Some(&part.substrate),
        &part.tool_axis,
    )
    .unwrap();
    let map = distance_map(&path);
    let process = plan_process(&path, &part.process, &Default::default()).unwrap();
    let input = ReportInput {
        substrate: Some(&part.substrate),
        process: Some(&process),
        ..ReportInput::new(&part.name, &path, &axes.frames, &map, path.delta_mm)
    };
    let html = dir.join("sliced.html");
    write_report(&html, &input).unwrap();
    let r = open_and_check(&browser, &html);
    check_drawing(&r);
    assert!(r.get("robot_only").is_none());
    let keys: Vec<&str> = r["fields"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| f[0].as_str().unwrap())
        .collect();
    assert_eq!(keys, ["deviation", "lean", "speed", "layer"]);
}

/// Plans `part` (its first `layers` layers, `points` a layer) in `cell`,
/// writes its report and opens it in Chromium: the page's check object.
fn planned_report(
    browser: &std::path::Path,
    part: &str,
    cell: &str,
    points: usize,
    layers: Option<usize>,
) -> serde_json::Value {
    let (dir, _keep) = out_dir();
    let part = read_part_file(&repo(&format!("parts/{part}"))).unwrap();
    let cell = read_cell_file(repo(&format!("parts/cells/{cell}")))
        .unwrap()
        .cell
        .unwrap();
    let mut so = part.slice_options();
    so.discretisation = Discretisation::Points(points);
    so.max_layers = layers;
    let path = slice(&part.tube, &part.substrate, &so).unwrap();
    let axes = tool_axes(
        &path,
        Some(&part.tube),
        Some(&part.substrate),
        &part.tool_axis,
    )
    .unwrap();
    let map = distance_map(&path);
    let layers = layer_points(&path, &axes.frames, part.process.travel_speed_mm_s);
    let opts = OptimiseOptions {
        configuration: waam_slicer::optimise::ConfigurationChoice::Cell,
        ..OptimiseOptions::default()
    };
    let plan = optimise(&cell, &layers, &opts).unwrap();
    let input = ReportInput {
        substrate: Some(&part.substrate),
        plan: Some(PlanView {
            cell: &cell,
            layers: &layers,
            plan: &plan,
            travel_speed_mm_s: part.process.travel_speed_mm_s,
            cycle: None,
            keep_out: &[],
            clearance: None,
            refusal: None,
        }),
        ..ReportInput::new(&part.name, &path, &axes.frames, &map, path.delta_mm)
    };
    let html = dir.join("planned.html");
    write_report(&html, &input).unwrap();
    open_and_check(browser, &html)
}

fn field_keys(r: &serde_json::Value) -> Vec<&str> {
    r["fields"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| f[0].as_str().unwrap())
        .collect()
}

#[test]
fn planned_report_animates_the_robot_in_chromium() {
    let Some(browser) = chromium() else { return };
    let r = planned_report(
        &browser,
        "hemisphere.toml",
        "robowam_part_carried.toml",
        36,
        None,
    );
    check_drawing(&r);
    // the robot alone covers a good part of the cell view
    let of = r["first"]["of"].as_u64().unwrap();
    assert!(pixels(&r["robot_only"]) > of / 100, "robot not drawn: {r}");
    // playing moves the animation on, and the joint table has a row per joint
    assert!(r["played_to_frame"].as_u64().unwrap() > 0, "{r}");
    assert!(r["joint_rows"].as_u64().unwrap() >= 8, "{r}");
    assert_eq!(
        field_keys(&r),
        ["deviation", "lean", "rz", "margin", "layer"]
    );
}

/// A torch-carried plan offers the build direction's tilt from the
/// vertical as a colour (issue 33), and it varies over the elbow's layers.
#[test]
fn a_torch_carried_report_colours_the_tilt_of_the_build_direction() {
    let Some(browser) = chromium() else { return };
    let r = planned_report(
        &browser,
        "elbow.toml",
        "kuka_kr16_2_torch_carried.toml",
        60,
        Some(20),
    );
    check_drawing(&r);
    let keys = field_keys(&r);
    assert_eq!(keys, ["deviation", "lean", "rz", "margin", "tilt", "layer"]);
    let colours = r["fields"][4][1].as_u64().unwrap();
    assert!(colours > 2, "tilt drawn in {colours} colours: {r}");
}

#[test]
fn page_without_webgl_says_so() {
    let Some(browser) = chromium() else { return };
    let (dir, _keep) = out_dir();
    let part = read_part_file(&repo("parts/quarter-torus.toml")).unwrap();
    let mut so = part.slice_options();
    so.max_layers = Some(3);
    let path = slice(&part.tube, &part.substrate, &so).unwrap();
    let axes = tool_axes(
        &path,
        Some(&part.tube),
        Some(&part.substrate),
        &part.tool_axis,
    )
    .unwrap();
    let map = distance_map(&path);
    let html = dir.join("nowebgl.html");
    write_report(
        &html,
        &ReportInput::new(&part.name, &path, &axes.frames, &map, 5.0),
    )
    .unwrap();
    let dom = run_chromium(
        &browser,
        &["--disable-webgl".into(), "--dump-dom".into()],
        &format!("file://{}#selftest", html.display()),
    );
    assert!(
        dom.contains("data-webgl=\"none\""),
        "WebGL was not disabled"
    );
    assert!(
        element_text(&dom, "errors").trim().is_empty(),
        "script errors without WebGL"
    );
    let record: serde_json::Value = serde_json::from_str(&element_text(&dom, "selftest")).unwrap();
    assert_eq!(record["nogl_visible"], true, "{record}");
    // the message is there and no longer hidden
    let at = dom.find("id=\"nogl\"").unwrap();
    let tag = &dom[dom[..at].rfind('<').unwrap()..at + dom[at..].find('>').unwrap()];
    assert!(!tag.contains("hidden"), "{tag}");
    assert!(dom.contains("WebGL is not available in this browser"));
}

// ---- the whole-cell check's bodies and closest pair (issue 30) ----

/// `hemisphere.toml` planned through the front door in `parts/cells/{cell}.toml`
/// on a coarse grid (60 points a layer, 3 layers): program built and checked.
fn planned_part(cell: &str) -> waam_slicer::PlannedPart {
    let part = waam_slicer::Part::read(repo("parts/hemisphere.toml")).unwrap();
    let name = cell;
    let cell = waam_slicer::Cell::read(repo(&format!("parts/cells/{name}.toml"))).unwrap();
    let opts = waam_slicer::PlanOptions {
        slice: waam_slicer::SliceOverrides {
            discretisation: Some(Discretisation::Points(60)),
            max_layers: Some(3),
            ..Default::default()
        },
        ..Default::default()
    };
    let p = waam_slicer::plan_part(&part, &cell, &opts).unwrap();
    assert!(p.is_feasible(), "{name}: {:?}", p.refusal());
    p
}

/// The page's data object, read back from the written page.
fn page_data(html: &Path) -> serde_json::Value {
    let text = std::fs::read_to_string(html).unwrap();
    let open = "id=\"report-data\">";
    let start = text.find(open).unwrap() + open.len();
    let end = start + text[start..].find("</script>").unwrap();
    serde_json::from_str(&text[start..end]).unwrap()
}

/// Decoded length (bytes) of a base64 text.
fn b64_len(s: &str) -> usize {
    s.len() / 4 * 3 - s.chars().rev().take_while(|c| *c == '=').count()
}

/// Little-endian `f32`s of a base64 text.
fn b64_f32(s: &str) -> Vec<f32> {
    let val = |c: u8| -> u32 {
        match c {
            b'A'..=b'Z' => u32::from(c - b'A'),
            b'a'..=b'z' => u32::from(c - b'a') + 26,
            b'0'..=b'9' => u32::from(c - b'0') + 52,
            b'+' => 62,
            _ => 63,
        }
    };
    let mut bytes = vec![];
    for chunk in s.as_bytes().chunks(4) {
        let pad = chunk.iter().filter(|c| **c == b'=').count();
        let n = chunk
            .iter()
            .filter(|c| **c != b'=')
            .fold(0u32, |n, c| (n << 6) | val(*c))
            << (6 * pad);
        bytes.extend(&n.to_be_bytes()[1..4 - pad]);
    }
    bytes
        .chunks_exact(4)
        .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        .collect()
}

/// The page data holds, per layer, the whole-cell check's closest approach
/// and pair, and the check's bodies: the arm's five capsules (the forearm's
/// first end the chain's J3 offset point, as the check builds it), with a
/// positioner the table (moving) and the tilt body (fixed).
#[test]
fn report_data_holds_the_closest_pair_of_every_layer() {
    let (dir, _keep) = out_dir();
    for cell in ["robowam_part_carried", "robowam_torch_carried"] {
        let p = planned_part(cell);
        let html = dir.join(format!("closest-{cell}.html"));
        p.write_report(&html, None).unwrap();
        let d = page_data(&html);
        let plan = &d["plan"];
        let clearance = p.clearance.as_ref().unwrap();
        let closest = plan["closest"].as_array().unwrap();
        assert_eq!(closest.len(), p.layers.len(), "{cell}");
        for (lp, c) in p.layers.iter().zip(closest) {
            let lc = clearance
                .layers
                .iter()
                .find(|l| l.layer == lp.layer)
                .unwrap();
            assert_eq!(c["layer"], lp.layer, "{cell}");
            let (a, b) = lc.closest_pair.clone().expect("a pair measured");
            assert_eq!(c["pair"], serde_json::json!([a, b]), "{cell}: {c}");
            assert!(
                (c["distance_mm"].as_f64().unwrap() - lc.closest_approach_mm).abs() < 1e-9,
                "{cell}: {c}"
            );
        }
        assert!(plan["collision"].is_null());
        let bodies: Vec<(&str, &str, bool)> = plan["bodies"]
            .as_array()
            .unwrap()
            .iter()
            .map(|b| {
                (
                    b["name"].as_str().unwrap(),
                    b["kind"].as_str().unwrap(),
                    b["moving"].as_bool().unwrap(),
                )
            })
            .collect();
        let mut want = vec![
            ("J1 column", "capsule", true),
            ("upper arm", "capsule", true),
            ("forearm", "capsule", true),
            ("wrist", "capsule", true),
            ("wrist", "capsule", true),
        ];
        if cell.contains("torch") {
            want.push(("positioner table", "cylinder", true));
            want.push(("positioner tilt body", "capsule", false));
        }
        assert_eq!(bodies, want, "{cell}");
        let moving = want.iter().filter(|b| b.2).count();
        let frames = plan["frames"].as_u64().unwrap() as usize;
        let f_bodies = plan["f_bodies"].as_str().unwrap();
        assert_eq!(b64_len(f_bodies), frames * moving * 6 * 4, "{cell}");
        let ends = b64_f32(f_bodies);
        let chain = b64_f32(plan["f_chain"].as_str().unwrap());
        for f in [0, frames - 1] {
            let forearm = &ends[6 * (moving * f + 2)..][..3];
            assert_eq!(forearm, &chain[24 * f + 12..][..3], "{cell}, frame {f}");
            let column = &ends[6 * moving * f..][..6];
            assert_eq!(&column[..3], &chain[24 * f..][..3], "{cell}, frame {f}");
        }
    }
}

/// A plan refused for a collision (a keep-out box around the wrist at the
/// last bead point): the page names the two bodies, marks the layer and
/// draws the box.
fn refused_part() -> waam_slicer::PlannedPart {
    use waam_slicer::program::cell_check::{check_cell, CellScene, KeepOut};
    use waam_slicer::robot::chain::arm_chain;
    use waam_slicer::robot::trajectory::{joint_trajectory, TrajectoryOptions};
    let mut p = planned_part("robowam_part_carried");
    let inputs = waam_slicer::optimise::trajectory_inputs(&p.layers, &p.plan);
    let traj = joint_trajectory(&p.cell.layout, &inputs, &TrajectoryOptions::default()).unwrap();
    let program = p.program.clone().unwrap();
    let last = traj
        .points
        .iter()
        .rev()
        .find(|j| j.joints.is_some())
        .unwrap();
    let w = arm_chain(program.cell.robot(), &last.joints.unwrap())[5];
    let keep = KeepOut {
        name: "fixture clamp".into(),
        min_mm: [w.x - 5.0, w.y - 5.0, w.z - 5.0],
        max_mm: [w.x + 5.0, w.y + 5.0, w.z + 5.0],
    };
    let scene = CellScene {
        keep_out: vec![keep.clone()],
        clearance_mm: 10.0,
        transits: true,
    };
    let e = check_cell(&program, &traj, &p.layers, &scene).unwrap_err();
    p.cell.keep_out = vec![keep];
    p.program = Err(e);
    p.clearance = None;
    p
}

#[test]
fn a_collision_refusal_is_named_and_marked_in_the_report() {
    let (dir, _keep) = out_dir();
    let p = refused_part();
    let html = dir.join("collision.html");
    p.write_report(&html, None).unwrap();
    let d = page_data(&html);
    let c = &d["plan"]["collision"];
    let Some(waam_slicer::program::ProgramError::Collision {
        layer,
        body_a,
        body_b,
        ..
    }) = p.refusal()
    else {
        panic!("not a collision: {:?}", p.refusal())
    };
    assert_eq!(c["layer"], *layer);
    assert_eq!(
        c["layer_index"].as_u64(),
        p.layers
            .iter()
            .position(|l| l.layer == *layer)
            .map(|i| i as u64)
    );
    assert_eq!((&c["body_a"], &c["body_b"]), (&json(body_a), &json(body_b)));
    assert!([body_a, body_b].contains(&&"fixture clamp".to_string()));
    // the layer is marked, the message names both bodies
    let marks = d["marks"].as_array().unwrap();
    let mark = marks
        .iter()
        .find(|m| m["text"].as_str().unwrap().starts_with("collision:"))
        .expect("the collision is marked");
    let text = mark["text"].as_str().unwrap();
    assert!(
        text.contains(body_a.as_str()) && text.contains(body_b.as_str()),
        "{text}"
    );
    // the box is drawn where the cell file puts it
    let k = &p.cell.keep_out[0];
    let b = d["plan"]["bodies"]
        .as_array()
        .unwrap()
        .iter()
        .find(|b| b["name"] == "fixture clamp")
        .unwrap();
    assert_eq!(b["kind"], "box");
    assert_eq!(b["a"], json(k.min_mm));
    assert_eq!(b["b"], json(k.max_mm));
    assert!(d["plan"]["closest"].as_array().unwrap().is_empty());
}

fn json(v: impl serde::Serialize) -> serde_json::Value {
    serde_json::to_value(v).unwrap()
}

/// In Chromium, a planned part-carried and torch-carried report, and a
/// refused one, load without a script error and draw the closest pair (or
/// the colliding pair) in the highlight colour, named in the HUD.
#[test]
fn the_closest_pair_is_highlighted_in_chromium() {
    let Some(browser) = chromium() else { return };
    let (dir, _keep) = out_dir();
    for cell in ["robowam_part_carried", "robowam_torch_carried", "refused"] {
        let p = if cell == "refused" {
            refused_part()
        } else {
            planned_part(cell)
        };
        let html = dir.join(format!("highlight-{cell}.html"));
        p.write_report(&html, None).unwrap();
        let r = open_and_check(&browser, &html);
        let c = &r["closest"];
        assert!(c.is_object(), "{cell}: no closest pair shown: {r}");
        let pair: Vec<&str> = c["pair"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_str().unwrap())
            .collect();
        let hud = c["hud"].as_str().unwrap();
        assert_eq!(hud, c["text"].as_str().unwrap(), "{cell}");
        assert!(
            hud.contains(&format!("{}\u{2013}{}", pair[0], pair[1])) && hud.contains(" mm"),
            "{cell}: {hud}"
        );
        if cell == "refused" {
            assert_eq!(c["collision"], true, "{r}");
            assert!(hud.starts_with("COLLISION"), "{hud}");
        } else {
            assert!(hud.starts_with("closest: "), "{hud}");
            let shown = c["layer"]["layer"].as_u64().unwrap() as usize;
            let lc = p
                .clearance
                .as_ref()
                .unwrap()
                .layers
                .iter()
                .find(|l| l.layer == shown)
                .unwrap();
            let (a, b) = lc.closest_pair.clone().unwrap();
            assert_eq!(pair, [a.as_str(), b.as_str()], "{cell}");
        }
        // both bodies (an arm link, a box, or the part's wall) are drawn
        // in the highlight colour, and nothing is without the highlight
        let mut named: Vec<&str> = c["highlighted"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_str().unwrap())
            .collect();
        named.sort();
        let mut want = pair.clone();
        want.sort();
        want.dedup();
        assert_eq!(named, want, "{cell}: {r}");
        let on = c["highlight_pixels"].as_u64().unwrap();
        let off = c["highlight_pixels_off"].as_u64().unwrap();
        assert!(
            on > 200 && off * 20 < on,
            "{cell}: {on} highlighted pixels, {off} without: {r}"
        );
    }
}

/// The layers' corners and the plan's bead splits are marked on the path
/// (issue 45): the quarter torus's first 12 layers at its own grid in the
/// ROBOWAM torch-carried cell, whose open layer 11 turns one corner (77°)
/// inside its bead and is split there. The page data lists every corner of
/// the path (layer, point, the split flagged), a note counts them, and in
/// Chromium the page draws them and names the split on hover.
#[test]
fn corners_and_splits_are_marked_in_the_report() {
    let part = waam_slicer::Part::read(repo("parts/quarter-torus.toml")).unwrap();
    let cell = waam_slicer::Cell::read(repo("parts/cells/robowam_torch_carried.toml")).unwrap();
    let opts = waam_slicer::PlanOptions {
        slice: waam_slicer::SliceOverrides {
            max_layers: Some(12),
            ..Default::default()
        },
        ..Default::default()
    };
    let p = waam_slicer::plan_part(&part, &cell, &opts).unwrap();
    assert!(p.is_feasible(), "{:?}", p.refusal());
    let splits: Vec<(usize, usize)> = p.splits.iter().map(|s| (s.layer, s.point)).collect();
    assert_eq!(splits.len(), 1, "{splits:?}");
    assert_eq!(splits[0].0, 11);
    let threshold = p.sliced.options.corner_threshold_rad;
    let corners: Vec<(usize, usize)> = p
        .sliced
        .path
        .layers
        .iter()
        .enumerate()
        .flat_map(|(li, l)| l.corners(threshold).into_iter().map(move |c| (li, c.point)))
        .collect();
    assert!(corners.contains(&splits[0]));
    let (dir, _keep) = out_dir();
    let html = dir.join("corners.html");
    p.write_report(&html, None).unwrap();
    let d = page_data(&html);
    let marked: Vec<(usize, usize, bool)> = d["corners"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| {
            (
                c["layer"].as_u64().unwrap() as usize,
                c["point"].as_u64().unwrap() as usize,
                c["split"].as_bool().unwrap(),
            )
        })
        .collect();
    let want: Vec<(usize, usize, bool)> = corners
        .iter()
        .map(|&(l, m)| (l, m, (l, m) == splits[0]))
        .collect();
    assert_eq!(marked, want);
    let notes = d["notes"].to_string();
    assert!(
        notes.contains(&format!("{} corners marked", corners.len()))
            && notes.contains("split at 1 of them"),
        "{notes}"
    );
    let Some(browser) = chromium() else { return };
    let r = open_and_check(&browser, &html);
    let c = &r["corners"];
    assert_eq!(c["marked"].as_u64(), Some(corners.len() as u64), "{r}");
    assert_eq!(c["splits"], 1, "{r}");
    let hover = c["split_pick"].as_str().unwrap_or_default();
    assert!(hover.contains("the bead is split here"), "{r}");
}
