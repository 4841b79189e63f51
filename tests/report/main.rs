//! The interactive report in a real browser (issue 20): the reports of a
//! sliced and of a planned sample part are opened in headless Chromium,
//! which must run the page without a script error, draw the canvas (the page
//! reads its own pixels back), load nothing (the page lists the resources the
//! browser fetched; every host name resolves to nothing), and animate the
//! robot of the plan. Without WebGL the page must say so.
//!
//! Chromium comes from the system's packages (`.ci/run` installs Debian's
//! `chromium`). If it is missing the tests fail saying so, unless
//! `WAAM_SKIP_BROWSER=1` is set; `WAAM_CHROMIUM` names another binary.
//! `WAAM_REPORT_KEEP=<folder>` keeps the reports and screenshots there.

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
    let layers = layer_points(&path, &axes.frames);
    let opts = OptimiseOptions {
        travel_speed_mm_s: part.process.travel_speed_mm_s,
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
            travel_speed_mm_s: opts.travel_speed_mm_s,
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
