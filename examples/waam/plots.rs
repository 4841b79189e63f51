//! Pictures a person can check (SVG, plotters): the path in 3-D coloured by
//! local interlayer distance, and the distance map per layer.

use plotters::prelude::*;
use std::path::Path as FsPath;
use waam_slicer::path::{DistanceMap, Path};

/// Colour for a relative deviation of the local distance from Delta:
/// blue below, green on target, red above (saturating at ±`span`).
fn colour(rel: f64, span: f64) -> RGBColor {
    let x = (rel / span).clamp(-1.0, 1.0);
    if x < 0.0 {
        let a = -x;
        RGBColor(
            (40.0 * (1.0 - a)) as u8,
            (170.0 * (1.0 - a) + 60.0 * a) as u8,
            (60.0 * (1.0 - a) + 220.0 * a) as u8,
        )
    } else {
        RGBColor(
            (40.0 + 200.0 * x) as u8,
            (170.0 * (1.0 - x) + 40.0 * x) as u8,
            (60.0 * (1.0 - x)) as u8,
        )
    }
}

/// Largest magnitude drawn on an axis: beyond it (a typo such as `1e308`,
/// or a diverged value) a panel says so instead of asking plotters for the
/// ticks of a range it cannot subdivide.
const MAX_DRAWN: f64 = 1e12;

/// The range of an axis over `values` (non-finite values ignored), padded
/// by `pad` of its width; a constant series is widened to ±1 unit (or
/// ±0.1 % of its value). `Err` says why there is nothing to draw: no
/// finite value, or a value beyond [`MAX_DRAWN`].
fn axis_range(values: impl IntoIterator<Item = f64>, pad: f64) -> Result<(f64, f64), String> {
    let (lo, hi) = values
        .into_iter()
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(v), b.max(v))
        });
    if lo > hi {
        return Err("no data".to_string());
    }
    let big = lo.abs().max(hi.abs());
    if big > MAX_DRAWN {
        return Err(format!(
            "no data: values up to {big:.3e}, beyond the drawable ±{MAX_DRAWN:.0e}"
        ));
    }
    let width = hi - lo;
    if width <= 1e-9 * big.max(1.0) {
        let half = (1e-3 * big).max(1.0);
        return Ok((lo - half, hi + half));
    }
    Ok((lo - pad * width, hi + pad * width))
}

/// Draws an empty panel with `caption` and the reason there is no plot.
fn no_data_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    caption: &str,
    reason: &str,
    file: &FsPath,
) -> Result<(), String> {
    let (w, h) = area.dim_in_pixel();
    area.draw(&Text::new(
        caption.to_string(),
        (10, 10),
        ("sans-serif", 16),
    ))
    .map_err(|e| format!("{}: {e}", file.display()))?;
    area.draw(&Text::new(
        reason.to_string(),
        (w as i32 / 2 - 120, h as i32 / 2),
        ("sans-serif", 18).into_font().color(&RED),
    ))
    .map_err(|e| format!("{}: {e}", file.display()))?;
    Ok(())
}

fn err<E: std::fmt::Display>(file: &FsPath) -> impl Fn(E) -> String + '_ {
    move |e| format!("{}: {e}", file.display())
}

/// Most points drawn in `path.svg` (about 100 bytes each: the file stays
/// under 5 MB); above, every k-th point is drawn and the picture says so.
pub const MAX_PATH_VIEW_POINTS: usize = 40_000;
/// Most layers drawn one by one in `distance.svg` (a dot each, about 300
/// bytes a layer); above, each series keeps its extremes per bucket of
/// layers, without dots, and the title says so.
pub const MAX_DISTANCE_LAYERS: usize = 4_000;
/// Most points drawn per joint panel; above, each bucket of consecutive
/// points keeps its lowest and highest value (peaks and limits stay visible)
/// and the title says so.
pub const MAX_PANEL_POINTS: usize = 8_000;

/// `data` (in x order) thinned to about `max` points: each bucket of
/// consecutive points keeps its lowest and its highest value, in x order.
fn keep_extremes(data: Vec<(f64, f64)>, max: usize) -> Vec<(f64, f64)> {
    if data.len() <= max {
        return data;
    }
    let k = data.len().div_ceil(max / 2);
    data.chunks(k)
        .flat_map(|c| {
            let lo = c
                .iter()
                .copied()
                .fold(c[0], |a, b| if b.1 < a.1 { b } else { a });
            let hi = c
                .iter()
                .copied()
                .fold(c[0], |a, b| if b.1 > a.1 { b } else { a });
            if lo.0 <= hi.0 {
                [lo, hi]
            } else {
                [hi, lo]
            }
        })
        .collect()
}

/// `k` as an English ordinal: 1st, 2nd, 3rd, 4th, 11th, 12th, 13th, 21st, …
pub fn ordinal(k: usize) -> String {
    let suffix = match (k % 10, k % 100) {
        (_, 11..=13) => "th",
        (1, _) => "st",
        (2, _) => "nd",
        (3, _) => "rd",
        _ => "th",
    };
    format!("{k}{suffix}")
}

/// Every how many points `path.svg` draws one, for `total` drawable points
/// (1: all), so that at most [`MAX_PATH_VIEW_POINTS`] are drawn.
pub fn path_view_every(total: usize) -> usize {
    total.div_ceil(MAX_PATH_VIEW_POINTS).max(1)
}

/// The path seen from azimuth -50 deg, elevation 25 deg (part frame), each
/// point coloured by (delta - Delta) / Delta; first layer in grey. Above
/// [`MAX_PATH_VIEW_POINTS`] points, every k-th is drawn and the picture
/// says so under the chart.
pub fn path_view(path: &Path, title: &str, file: &FsPath) -> Result<(), String> {
    let (az, el) = ((-50.0_f64).to_radians(), 25.0_f64.to_radians());
    let project = |p: &waam_slicer::math::Point3| {
        let x = p.x * az.cos() - p.y * az.sin();
        let depth = p.x * az.sin() + p.y * az.cos();
        let y = p.z * el.cos() - depth * el.sin();
        (x, y)
    };
    // only points with both view coordinates finite are drawn; a large path
    // is thinned to every k-th of them (said under the picture), counted
    // first so that only the drawn points are held
    let finite = || {
        path.layers
            .iter()
            .flat_map(|l| l.points.iter())
            .map(|p| {
                let (x, y) = project(&p.position);
                (x, y, p.delta)
            })
            .filter(|p| p.0.is_finite() && p.1.is_finite())
    };
    let total = finite().count();
    let every = path_view_every(total);
    let thinned = if every > 1 {
        format!(" Every {} of {total} points drawn.", ordinal(every))
    } else {
        String::new()
    };
    let pts: Vec<(f64, f64, Option<f64>)> = finite().step_by(every).collect();
    let whole = SVGBackend::new(file, (900, 930)).into_drawing_area();
    whole.fill(&WHITE).map_err(err(file))?;
    let (root, note) = whole.split_vertically(900);
    let ranges = axis_range(pts.iter().map(|p| p.0), 0.05)
        .and_then(|x| Ok((x, axis_range(pts.iter().map(|p| p.1), 0.05)?)));
    let ((x0, x1), (y0, y1)) = match ranges {
        Ok(r) => r,
        Err(reason) => {
            no_data_panel(&root, title, &reason, file)?;
            return whole.present().map_err(err(file));
        }
    };
    let span = (x1 - x0).max(y1 - y0);
    let (cx, cy) = (0.5 * (x0 + x1), 0.5 * (y0 + y1));
    let mut chart = ChartBuilder::on(&root)
        .caption(title, ("sans-serif", 22))
        .margin(20)
        .x_label_area_size(35)
        .y_label_area_size(45)
        .build_cartesian_2d(
            cx - span / 2.0..cx + span / 2.0,
            cy - span / 2.0..cy + span / 2.0,
        )
        .map_err(err(file))?;
    chart
        .configure_mesh()
        .x_desc("view x (mm)")
        .y_desc("view y (mm)")
        .light_line_style(WHITE)
        .draw()
        .map_err(err(file))?;
    let delta = path.delta_mm;
    let max_dev = pts
        .iter()
        .filter_map(|p| p.2)
        .map(|d| ((d - delta) / delta).abs())
        .filter(|r| r.is_finite())
        .fold(0.0, f64::max);
    let scale = max_dev.clamp(0.01, 1e6);
    chart
        .draw_series(pts.iter().map(|&(x, y, d)| {
            let c = d.map_or(RGBColor(150, 150, 150), |d| {
                colour((d - delta) / delta, scale)
            });
            Circle::new((x, y), 1, c.filled())
        }))
        .map_err(err(file))?;
    note.draw(&Text::new(
        format!("colour: (delta - Delta)/Delta, blue -{:.1} %, green 0, red +{:.1} %; grey: first layer.{thinned}", 100.0 * scale, 100.0 * scale),
        (30, 5),
        ("sans-serif", 15),
    ))
    .map_err(err(file))?;
    whole.present().map_err(err(file))
}

/// Min, mean and max of the local distance (relative to Delta) per layer.
pub fn distance_plot(
    path: &Path,
    map: &DistanceMap,
    title: &str,
    file: &FsPath,
) -> Result<(), String> {
    let delta = path.delta_mm;
    let rows: Vec<(usize, f64, f64, f64)> = map
        .per_layer
        .iter()
        .enumerate()
        .filter_map(|(i, s)| s.map(|s| (i, s.min_mm / delta, s.mean_mm / delta, s.max_mm / delta)))
        .collect();
    let root = SVGBackend::new(file, (900, 500)).into_drawing_area();
    root.fill(&WHITE).map_err(err(file))?;
    // rows with a non-finite ratio (Delta 0, a diverged distance) are not drawn
    let rows: Vec<(usize, f64, f64, f64)> = rows
        .into_iter()
        .filter(|r| r.1.is_finite() && r.2.is_finite() && r.3.is_finite())
        .collect();
    let (lo, hi) = match axis_range(rows.iter().flat_map(|r| [r.1, r.3]).chain([1.0]), 0.1) {
        Ok(r) if !rows.is_empty() => r,
        Ok(_) => {
            no_data_panel(
                &root,
                title,
                "no data: no layer has a measured distance",
                file,
            )?;
            return root.present().map_err(err(file));
        }
        Err(reason) => {
            no_data_panel(&root, title, &reason, file)?;
            return root.present().map_err(err(file));
        }
    };
    // many layers: each series keeps its extremes per bucket of layers
    // (said in the title), without the per-layer dots
    let many = rows.len() > MAX_DISTANCE_LAYERS;
    let title = if many {
        format!(
            "{title} [{} layers: per bucket of layers its lowest and highest drawn]",
            rows.len()
        )
    } else {
        title.to_string()
    };
    let n = path.layers.len().max(2);
    let mut chart = ChartBuilder::on(&root)
        .caption(title, ("sans-serif", 22))
        .margin(20)
        .x_label_area_size(40)
        .y_label_area_size(60)
        .build_cartesian_2d(0.0..(n - 1) as f64, lo..hi)
        .map_err(err(file))?;
    chart
        .configure_mesh()
        .x_desc("layer")
        .y_desc("local distance / Delta")
        .draw()
        .map_err(err(file))?;
    chart
        .draw_series(LineSeries::new(
            [(0.0, 1.0), ((n - 1) as f64, 1.0)],
            BLACK.stroke_width(1),
        ))
        .map_err(err(file))?
        .label("target")
        .legend(|(x, y)| PathElement::new([(x, y), (x + 20, y)], BLACK));
    for (k, (name, colour)) in [("min", BLUE), ("mean", GREEN), ("max", RED)]
        .into_iter()
        .enumerate()
    {
        let series: Vec<(f64, f64)> = rows
            .iter()
            .map(|r| (r.0 as f64, [r.1, r.2, r.3][k]))
            .collect();
        let series = keep_extremes(series, MAX_DISTANCE_LAYERS);
        chart
            .draw_series(LineSeries::new(series.clone(), colour.stroke_width(2)))
            .map_err(err(file))?
            .label(name)
            .legend(move |(x, y)| PathElement::new([(x, y), (x + 20, y)], colour.stroke_width(2)));
        if !many {
            chart
                .draw_series(
                    series
                        .into_iter()
                        .map(|p| Circle::new(p, 2, colour.filled())),
                )
                .map_err(err(file))?;
        }
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .draw()
        .map_err(err(file))?;
    root.present().map_err(err(file))
}

/// Six panels (J1..J6) of a quantity against the point index, with the
/// allowed band drawn as red lines (infinite bounds are not drawn). A
/// panel with no finite point, or values beyond ±1e12, says "no data"
/// (and why) instead of a chart.
pub fn joint_panels(
    title: &str,
    y_unit: &str,
    series: &[Vec<(f64, f64)>],
    bounds: &[(f64, f64)],
    file: &FsPath,
) -> Result<(), String> {
    let longest = series.iter().map(Vec::len).max().unwrap_or(0);
    let title = if longest > MAX_PANEL_POINTS {
        format!("{title} [{longest} points: per bucket of points its min and max drawn]")
    } else {
        title.to_string()
    };
    // two panels a row: J1-J6, and J7, J8 (the positioner) when given
    let rows = series.len().div_ceil(2);
    let whole = SVGBackend::new(file, (1200, 300 * rows as u32)).into_drawing_area();
    whole.fill(&WHITE).map_err(err(file))?;
    let whole = whole
        .titled(&title, ("sans-serif", 22))
        .map_err(err(file))?;
    let panels = whole.split_evenly((rows, 2));
    for (j, area) in panels.iter().enumerate().take(series.len()) {
        let caption = format!("J{}", j + 1);
        // only finite points are drawn; the bounds widen the axis only
        // when there is something to draw
        let data: Vec<(f64, f64)> = series[j]
            .iter()
            .copied()
            .filter(|p| p.0.is_finite() && p.1.is_finite())
            .collect();
        let data = keep_extremes(data, MAX_PANEL_POINTS);
        let drawn = |b: f64| b.is_finite() && b.abs() <= MAX_DRAWN;
        let (blo, bhi) = bounds[j];
        let (blo, bhi) = (
            if drawn(blo) { blo } else { f64::NAN },
            if drawn(bhi) { bhi } else { f64::NAN },
        );
        let ranges = axis_range(data.iter().map(|p| p.0).chain([0.0]), 0.0).and_then(|x| {
            if data.is_empty() {
                return Err("no data".to_string());
            }
            let y = axis_range(data.iter().map(|p| p.1).chain([blo, bhi]), 0.05)?;
            Ok((x, y))
        });
        let ((_, x_max), (lo, hi)) = match ranges {
            Ok(r) => r,
            Err(reason) => {
                no_data_panel(area, &caption, &reason, file)?;
                continue;
            }
        };
        let x_max = x_max.max(1.0);
        let mut chart = ChartBuilder::on(area)
            .caption(caption, ("sans-serif", 16))
            .margin(10)
            .x_label_area_size(30)
            .y_label_area_size(55)
            .build_cartesian_2d(0.0..x_max, lo..hi)
            .map_err(err(file))?;
        chart
            .configure_mesh()
            .x_desc("point")
            .y_desc(y_unit)
            .draw()
            .map_err(err(file))?;
        for b in [blo, bhi] {
            if drawn(b) {
                chart
                    .draw_series(LineSeries::new([(0.0, b), (x_max, b)], RED.stroke_width(2)))
                    .map_err(err(file))?;
            }
        }
        chart
            .draw_series(LineSeries::new(data, BLUE.stroke_width(1)))
            .map_err(err(file))?;
    }
    whole.present().map_err(err(file))
}

#[cfg(test)]
mod tests {
    //! Every plot function on empty, constant, NaN and huge data: each must
    //! return quickly with an SVG, a "no data" panel where nothing can be
    //! drawn and a chart where something can (issue 22: a plan with no joint
    //! values spun for minutes inside plotters' tick computation).

    use super::*;
    use std::time::{Duration, Instant};
    use waam_slicer::math::Point3;
    use waam_slicer::path::{DistanceStats, Layer, PathPoint, SliceReport, Strategy};

    /// The inputs every plot is fed: (name, values, whether a chart is expected).
    fn cases() -> Vec<(&'static str, Vec<f64>, bool)> {
        vec![
            ("empty", vec![], false),
            ("constant", vec![2.5; 20], true),
            ("nan", vec![f64::NAN; 20], false),
            ("huge", vec![1e308, -1e308, 1e308], false),
            ("infinite", vec![f64::INFINITY, f64::NEG_INFINITY], false),
            ("ramp with a NaN", vec![0.0, 1.0, f64::NAN, 3.0], true),
        ]
    }

    fn path_of(values: &[f64]) -> Path {
        let points = values
            .iter()
            .enumerate()
            .map(|(i, &v)| PathPoint {
                t: v,
                v: 0.1 * i as f64,
                position: Point3::new(v, 0.5 * v, v),
                delta: Some(v),
            })
            .collect();
        Path {
            strategy: Strategy::Constant,
            delta_mm: 2.5,
            layers: vec![
                Layer {
                    slice: 0,
                    points: Vec::new(),
                    closed: true,
                },
                Layer {
                    slice: 1,
                    points,
                    closed: true,
                },
            ],
            report: SliceReport::default(),
            spiral: None,
        }
    }

    /// Statistics as the distance map gives them: NaN distances are not
    /// counted, infinite and huge ones are.
    fn stats_of(values: &[f64]) -> Option<DistanceStats> {
        let values: Vec<f64> = values.iter().copied().filter(|v| !v.is_nan()).collect();
        let (lo, hi) = values
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
                (a.min(v), b.max(v))
            });
        (!values.is_empty()).then(|| DistanceStats {
            count: values.len(),
            min_mm: lo,
            max_mm: hi,
            mean_mm: values.iter().sum::<f64>() / values.len() as f64,
            variation: (hi - lo) / 2.5,
            min_rel: (lo - 2.5) / 2.5,
            max_rel: (hi - 2.5) / 2.5,
            boundary_points: 0,
        })
    }

    /// Runs `draw` into a fresh file, checks it returned in under 10 s and
    /// wrote an SVG, and returns the SVG text.
    fn timed(name: &str, draw: impl FnOnce(&FsPath) -> Result<(), String>) -> String {
        let dir = tempfile::tempdir().expect("temp dir");
        let file = dir.path().join("plot.svg");
        let start = Instant::now();
        draw(&file).unwrap_or_else(|e| panic!("{name}: {e}"));
        let took = start.elapsed();
        assert!(took < Duration::from_secs(10), "{name}: took {took:?}");
        let svg = std::fs::read_to_string(&file).expect("the plot was written");
        assert!(svg.starts_with("<svg"), "{name}: not an SVG");
        svg
    }

    fn check(name: &str, svg: &str, chart: bool) {
        assert_eq!(
            !svg.contains("no data"),
            chart,
            "{name}: expected {}",
            if chart { "a chart" } else { "a no-data panel" }
        );
    }

    #[test]
    fn path_view_survives_degenerate_data() {
        for (name, values, chart) in cases() {
            let path = path_of(&values);
            let svg = timed(name, |f| path_view(&path, name, f));
            check(name, &svg, chart);
        }
    }

    #[test]
    fn distance_plot_survives_degenerate_data() {
        for (name, values, chart) in cases() {
            let path = path_of(&values);
            let map = DistanceMap {
                per_layer: vec![None, stats_of(&values)],
                overall: stats_of(&values),
                points: Vec::new(),
            };
            let svg = timed(name, |f| distance_plot(&path, &map, name, f));
            check(name, &svg, chart);
        }
    }

    #[test]
    fn joint_panels_survive_degenerate_data() {
        let limited = (-2.0, 2.0);
        let unlimited = (f64::NEG_INFINITY, f64::INFINITY);
        for (name, values, chart) in cases() {
            let s: Vec<(f64, f64)> = values
                .iter()
                .enumerate()
                .map(|(i, &v)| (i as f64, v))
                .collect();
            let series: [Vec<(f64, f64)>; 6] = std::array::from_fn(|_| s.clone());
            // the case: no joint values, unlimited J6
            let bounds = [limited, limited, limited, limited, limited, unlimited];
            let svg = timed(name, |f| joint_panels(name, "rad", &series, &bounds, f));
            let panels = svg.matches("no data").count();
            assert_eq!(
                panels,
                if chart { 0 } else { 6 },
                "{name}: {panels} no-data panels"
            );
        }
        // huge x (point index) and a huge bound
        let series: [Vec<(f64, f64)>; 6] = std::array::from_fn(|_| vec![(1e308, 1.0), (0.0, 2.0)]);
        let svg = timed("huge x", |f| {
            joint_panels("huge x", "rad", &series, &[(-1e308, 1e308); 6], f)
        });
        assert_eq!(svg.matches("no data").count(), 6);
    }

    #[test]
    fn thinning_keeps_each_buckets_extremes_and_bounds_the_count() {
        let data: Vec<(f64, f64)> = (0..100_000)
            .map(|i| (i as f64, ((i * 7919) % 1000) as f64))
            .chain([(100_000.0, 5000.0)])
            .collect();
        let kept = keep_extremes(data.clone(), MAX_PANEL_POINTS);
        assert!(kept.len() <= MAX_PANEL_POINTS + 2, "{}", kept.len());
        // the global peak survives, x stays ordered
        assert!(kept.iter().any(|p| p.1 == 5000.0));
        assert!(kept.windows(2).all(|w| w[0].0 <= w[1].0));
        let small: Vec<(f64, f64)> = data[..10].to_vec();
        assert_eq!(keep_extremes(small.clone(), MAX_PANEL_POINTS), small);
    }

    /// Five megabytes: the most a picture may weigh (issue 21: an 80 MB
    /// `path.svg` of a 0.87 M-point path opened in no viewer).
    const MAX_PICTURE_BYTES: u64 = 5_000_000;

    /// A path of `layers` closed rings of `per_layer` points (a cylinder of
    /// radius 50 mm, 0.5 mm a layer), with distances around 0.5 mm.
    fn big_path(layers: usize, per_layer: usize) -> Path {
        let layers = (0..layers)
            .map(|k| Layer {
                slice: k,
                points: (0..per_layer)
                    .map(|i| {
                        let a = std::f64::consts::TAU * i as f64 / per_layer as f64;
                        PathPoint {
                            t: k as f64,
                            v: a,
                            position: Point3::new(50.0 * a.cos(), 50.0 * a.sin(), 0.5 * k as f64),
                            delta: (k > 0).then(|| 0.5 + 0.01 * (3.0 * a).sin()),
                        }
                    })
                    .collect(),
                closed: true,
            })
            .collect();
        Path {
            strategy: Strategy::Constant,
            delta_mm: 0.5,
            layers,
            report: SliceReport::default(),
            spiral: None,
        }
    }

    #[test]
    fn ordinals() {
        let got: Vec<String> = [1, 2, 3, 4, 11, 12, 13, 17, 21, 22, 23, 101, 111, 112]
            .into_iter()
            .map(ordinal)
            .collect();
        assert_eq!(
            got,
            [
                "1st", "2nd", "3rd", "4th", "11th", "12th", "13th", "17th", "21st", "22nd", "23rd",
                "101st", "111th", "112th"
            ]
        );
    }

    #[test]
    fn a_large_path_view_is_thinned_under_five_megabytes_and_says_so() {
        // 400 layers of 2000 points: 800 000 points, every 20th drawn
        let path = big_path(400, 2000);
        let dir = tempfile::tempdir().expect("temp dir");
        let file = dir.path().join("path.svg");
        path_view(&path, "big", &file).expect("drawn");
        let size = std::fs::metadata(&file).expect("written").len();
        assert!(size < MAX_PICTURE_BYTES, "path.svg: {size} bytes");
        let svg = std::fs::read_to_string(&file).expect("text");
        assert_eq!(path_view_every(800_000), 20);
        assert!(
            svg.contains("Every 20th of 800000 points drawn."),
            "the picture states its thinning"
        );
        // the points drawn: one circle each (no other circle in the picture)
        let circles = svg.matches("<circle").count();
        assert_eq!(circles, 40_000, "{circles} points drawn");
        // a small path is drawn whole and says nothing
        let small = big_path(10, 100);
        let svg = timed("small", |f| path_view(&small, "small", f));
        assert!(!svg.contains("points drawn"));
        assert_eq!(svg.matches("<circle").count(), 1000);
    }

    #[test]
    fn a_distance_plot_of_many_layers_stays_under_five_megabytes_and_says_so() {
        let layers = 50_000;
        let path = big_path(layers, 3);
        let stats: Vec<Option<DistanceStats>> = (0..layers)
            .map(|k| {
                let d = 0.5 + 0.01 * (k as f64 * 0.01).sin();
                stats_of(&[d - 0.002, d, d + 0.002])
            })
            .collect();
        let map = DistanceMap {
            overall: stats[1],
            per_layer: stats,
            points: Vec::new(),
        };
        let dir = tempfile::tempdir().expect("temp dir");
        let file = dir.path().join("distance.svg");
        distance_plot(&path, &map, "many", &file).expect("drawn");
        let size = std::fs::metadata(&file).expect("written").len();
        assert!(size < MAX_PICTURE_BYTES, "distance.svg: {size} bytes");
        let svg = std::fs::read_to_string(&file).expect("text");
        assert!(
            svg.contains("[50000 layers: per bucket of layers its lowest and highest drawn]"),
            "the picture states its thinning"
        );
        // below the bound, every layer has its dots and no such note
        let path = big_path(100, 3);
        let map = DistanceMap {
            overall: stats_of(&[0.5]),
            per_layer: (0..100).map(|_| stats_of(&[0.49, 0.5, 0.51])).collect(),
            points: Vec::new(),
        };
        let svg = timed("few layers", |f| distance_plot(&path, &map, "few", f));
        assert!(!svg.contains("per bucket"));
        assert!(svg.matches("<circle").count() >= 300);
    }

    #[test]
    fn axis_range_cases() {
        assert!(axis_range([], 0.05).is_err());
        assert!(axis_range([f64::NAN], 0.05).is_err());
        assert!(axis_range([1e308], 0.05).is_err());
        assert_eq!(axis_range([3.0, 3.0], 0.05), Ok((2.0, 4.0)));
        assert_eq!(axis_range([5000.0], 0.05), Ok((4995.0, 5005.0)));
        let (lo, hi) = axis_range([0.0, 10.0, f64::NAN], 0.1).unwrap();
        assert!((lo + 1.0).abs() < 1e-12 && (hi - 11.0).abs() < 1e-12);
    }
}
