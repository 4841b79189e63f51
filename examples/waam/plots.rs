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

fn err<E: std::fmt::Display>(file: &FsPath) -> impl Fn(E) -> String + '_ {
    move |e| format!("{}: {e}", file.display())
}

/// The path seen from azimuth -50 deg, elevation 25 deg (part frame), each
/// point coloured by (delta - Delta) / Delta; first layer in grey.
pub fn path_view(path: &Path, title: &str, file: &FsPath) -> Result<(), String> {
    let (az, el) = ((-50.0_f64).to_radians(), 25.0_f64.to_radians());
    let project = |p: &waam_slicer::math::Point3| {
        let x = p.x * az.cos() - p.y * az.sin();
        let depth = p.x * az.sin() + p.y * az.cos();
        let y = p.z * el.cos() - depth * el.sin();
        (x, y)
    };
    let pts: Vec<(f64, f64, Option<f64>)> = path
        .layers
        .iter()
        .flat_map(|l| {
            l.points.iter().map(|p| {
                let (x, y) = project(&p.position);
                (x, y, p.delta)
            })
        })
        .collect();
    let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for (x, y, _) in &pts {
        x0 = x0.min(*x);
        x1 = x1.max(*x);
        y0 = y0.min(*y);
        y1 = y1.max(*y);
    }
    let pad = 0.05 * (x1 - x0).max(y1 - y0).max(1.0);
    let span = (x1 - x0).max(y1 - y0) + 2.0 * pad;
    let (cx, cy) = (0.5 * (x0 + x1), 0.5 * (y0 + y1));
    let whole = SVGBackend::new(file, (900, 930)).into_drawing_area();
    whole.fill(&WHITE).map_err(err(file))?;
    let (root, note) = whole.split_vertically(900);
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
        .fold(0.0, f64::max);
    let scale = max_dev.max(0.01);
    chart
        .draw_series(pts.iter().map(|&(x, y, d)| {
            let c = d.map_or(RGBColor(150, 150, 150), |d| {
                colour((d - delta) / delta, scale)
            });
            Circle::new((x, y), 1, c.filled())
        }))
        .map_err(err(file))?;
    note.draw(&Text::new(
        format!("colour: (delta - Delta)/Delta, blue -{:.1} %, green 0, red +{:.1} %; grey: first layer", 100.0 * scale, 100.0 * scale),
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
    let (lo, hi) = rows
        .iter()
        .fold((1.0_f64, 1.0_f64), |(a, b), r| (a.min(r.1), b.max(r.3)));
    let pad = 0.1 * (hi - lo).max(0.002);
    let n = path.layers.len().max(2);
    let mut chart = ChartBuilder::on(&root)
        .caption(title, ("sans-serif", 22))
        .margin(20)
        .x_label_area_size(40)
        .y_label_area_size(60)
        .build_cartesian_2d(0.0..(n - 1) as f64, (lo - pad)..(hi + pad))
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
        chart
            .draw_series(LineSeries::new(series.clone(), colour.stroke_width(2)))
            .map_err(err(file))?
            .label(name)
            .legend(move |(x, y)| PathElement::new([(x, y), (x + 20, y)], colour.stroke_width(2)));
        chart
            .draw_series(
                series
                    .into_iter()
                    .map(|p| Circle::new(p, 2, colour.filled())),
            )
            .map_err(err(file))?;
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
/// allowed band drawn as red lines (infinite bounds are not drawn).
pub fn joint_panels(
    title: &str,
    y_unit: &str,
    series: &[Vec<(f64, f64)>; 6],
    bounds: [(f64, f64); 6],
    file: &FsPath,
) -> Result<(), String> {
    let whole = SVGBackend::new(file, (1200, 900)).into_drawing_area();
    whole.fill(&WHITE).map_err(err(file))?;
    let whole = whole.titled(title, ("sans-serif", 22)).map_err(err(file))?;
    let panels = whole.split_evenly((3, 2));
    for (j, area) in panels.iter().enumerate() {
        let data = &series[j];
        let x_max = data.last().map_or(1.0, |p| p.0).max(1.0);
        let (mut lo, mut hi) = data
            .iter()
            .fold((f64::MAX, f64::MIN), |(a, b), p| (a.min(p.1), b.max(p.1)));
        let (blo, bhi) = bounds[j];
        if blo.is_finite() {
            lo = lo.min(blo);
        }
        if bhi.is_finite() {
            hi = hi.max(bhi);
        }
        if !(lo.is_finite() && hi.is_finite()) {
            lo = -1.0;
            hi = 1.0;
        }
        let pad = 0.05 * (hi - lo).max(1e-6);
        let mut chart = ChartBuilder::on(area)
            .caption(format!("J{}", j + 1), ("sans-serif", 16))
            .margin(10)
            .x_label_area_size(30)
            .y_label_area_size(55)
            .build_cartesian_2d(0.0..x_max, (lo - pad)..(hi + pad))
            .map_err(err(file))?;
        chart
            .configure_mesh()
            .x_desc("point")
            .y_desc(y_unit)
            .draw()
            .map_err(err(file))?;
        for b in [blo, bhi] {
            if b.is_finite() {
                chart
                    .draw_series(LineSeries::new([(0.0, b), (x_max, b)], RED.stroke_width(2)))
                    .map_err(err(file))?;
            }
        }
        chart
            .draw_series(LineSeries::new(data.iter().copied(), BLUE.stroke_width(1)))
            .map_err(err(file))?;
    }
    whole.present().map_err(err(file))
}
