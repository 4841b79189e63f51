//! **The driver**: open ends and start end, a first guide from the level
//! sets, then sections normal to the current guide, a circle per section and
//! a smooth refit of the guide, until the guide stops moving; a final pass
//! fits the radius law (and wall thickness) and measures the residuals.

use super::coarse::{bridge_between_rings, vertex_rings};
use super::coarse::{bridge_not_round, fill_from_cuts, sparse_rings, Coarseness, EndAnchor};
use super::features;
use super::first_guide::first_guide;
use super::laws::{coupling_gap, fit_law, outer_skin};
use super::options::units_warning;
use super::outcome::FeatureReport;
use super::outcome::RepairReport;
use super::outcome::{EndRing, FitReport, Station, TubeFit};
use super::samples::{self, carry_hints, project_all, Samples};
use super::section::{
    circle_in_plane, fit_circle, fit_plane, station_frames, CircleFit, SectionPoint,
};
use super::topology::{self, median_edge, Surfaces};
use super::{cut, ends, repair, report};
use super::{smooth, FitError, FitOptions, StartEnd, TubeMesh, Units};
use crate::geometry::guide::{CubicSpline, GuideCurve};
use crate::math::{Point3, UnitVector3, Vector3};
use nalgebra::DMatrix;
use rayon::prelude::*;

/// Default station spacing, in median mesh edges: two edges between
/// stations gives each section a full ring of vertices.
const STATION_SPACING_EDGES: f64 = 2.0;
/// Smallest default station spacing (mm): finer stations on a fine mesh
/// only cost time.
const MIN_STATION_SPACING_MM: f64 = 0.5;
/// Largest default station spacing, as a fraction of the smaller end
/// radius (dimensionless): a coarse mesh still gets four stations per radius.
const MAX_STATION_SPACING_RADII: f64 = 0.25;
/// Default knot spacing of the refit, as a fraction of the smaller end
/// radius (dimensionless): the guide bends over lengths of a radius or more.
const KNOT_SPACING_RADII: f64 = 0.5;
/// Default knot spacing's bounds (mm): short enough to follow a bend,
/// long enough for the sections between two knots to hold the spline.
const KNOT_SPACING_RANGE_MM: (f64, f64) = (4.0, 12.0);
/// Smallest knot spacing, in station spacings (dimensionless): every knot
/// interval holds more than one station.
const MIN_KNOT_STATIONS: f64 = 1.5;
/// How far past its ends the guide is searched for a vertex's nearest
/// point, in smaller end radii (dimensionless): an end cut obliquely has
/// vertices past the guide's end.
const PROJECT_PAST_END_RADII: f64 = 2.0;
/// A guide more than this many times its first length has diverged
/// (dimensionless).
const DIVERGED_LENGTH_RATIO: f64 = 3.0;
/// The guide has stalled when its largest move is under this many fit
/// tolerances (dimensionless)...
const STALL_TOLERANCES: f64 = 10.0;
/// ... or under this fraction of the sections' median RMS (dimensionless):
/// vertices changing station make the last moves go back and forth.
const STALL_NOISE_FRACTION: f64 = 0.25;
/// ... and no longer shrinking: the last move is over this fraction of the
/// one before (dimensionless).
const STALL_SHRINK_RATIO: f64 = 0.8;
/// A radius law whose spread is under this many
/// [`FitOptions::constant_radius_tol_mm`] is made constant (dimensionless):
/// the tolerance bounds each side of the mean.
const CONSTANT_RADIUS_SPREAD_TOLS: f64 = 2.0;
/// Largest tangent of the start end's tilt used for the range below `t = 0`
/// (dimensionless; about 84 degrees): a nearly tangent end plane would ask
/// for an endless extension.
const MAX_START_TILT_TAN: f64 = 10.0;
/// Margin added to the range below `t = 0` (mm), so that the substrate
/// cuts the tube inside the range.
const EXTEND_BEFORE_MARGIN_MM: f64 = 1.0;

/// Most knots a guide may have (dimensionless): the refit's least-squares
/// system is dense in them (a thousand take about a second), and a mesh with
/// one vertex metres away from its tube would otherwise ask for millions.
const MAX_KNOTS: f64 = 1000.0;

/// A station whose ring of points leaves a gap wider than this around its
/// circle (degrees) takes its neighbours' points too: fewer than six points
/// around, as rings of a coarse mesh between its stations give.
const WIDEN_GAP_DEG: f64 = 60.0;

/// Sections are checked from this refit on (dimensionless count) when the
/// samples hold points along a coarse bend's edges ([`samples::with_bend_edges`]):
/// the first guides of a coarse export (level sets a few edges wide) leave
/// sections that are not yet circles. Otherwise from the second.
const CHECK_SECTIONS_AFTER: usize = 6;
/// Refits to the round sections alone (dimensionless count) after the
/// vertices' pass first fails its check: a feature pulls the guide towards
/// it (a lug on one side, a flange holding an open end) until its sections
/// no longer steer the guide; then the sections are read for features.
const FEATURE_REFITS: usize = 4;
/// With [`FitOptions::trim`], the tube is cut this far (in tube radii) past
/// the extent of a feature beside it along the guide: the guide's normal
/// plane there clears the feature's side (a flange's face) on a guide a
/// little off its axis.
const TRIM_MARGIN_RADII: f64 = 0.05;
/// Most refits with the points along a coarse bend's edges (dimensionless
/// count); then the vertices alone.
const EDGE_REFITS: usize = 8;

/// Largest mesh the fit takes (mm, bounding box's largest side, after the
/// unit): 10 km, no part of a robot cell; a mesh that big is in another
/// unit or not a tube, and far past it the guide's splines overflow (the
/// fuzzer's 1.2e29 mm mesh made parry's projection panic on NaN points).
const MAX_MESH_SIZE_MM: f64 = 1e7;

/// Fits a tube to `mesh`.
///
/// # Errors
/// [`FitError`] naming the file and, where there is one, the station: a
/// bad option, a branch, a closed blob, a section not near a circle, a
/// residual over [`FitOptions::max_rms_mm`], a degenerate fit.
pub fn fit_tube(mesh: &TubeMesh, opts: &FitOptions) -> Result<TubeFit, FitError> {
    opts.validate(&mesh.file)?;
    let warning = units_warning(mesh.bounding_box_size(), opts.units);
    let in_mm;
    let mesh = if opts.units == Units::Mm {
        mesh
    } else {
        in_mm = mesh.scaled(opts.units.mm_per_unit());
        &in_mm
    };
    let size_mm = mesh.bounding_box_size();
    if !(size_mm <= MAX_MESH_SIZE_MM) {
        let e = FitError::Stl {
            file: mesh.file.clone(),
            reason: format!(
                "the mesh spans {size_mm:.4e} mm, over the {MAX_MESH_SIZE_MM:.0} mm a part of a robot cell can span"
            ),
        };
        return Err(match warning {
            Some(hint) => FitError::Units {
                hint,
                source: Box::new(e),
            },
            None => e,
        });
    }
    let repaired = repair::repair(mesh);
    if repaired.mesh.triangles.is_empty() {
        return Err(FitError::Stl {
            file: mesh.file.clone(),
            reason: "no triangle left after welding and dropping zero-area triangles".into(),
        });
    }
    match fit_in_mm(&repaired.mesh, opts, false) {
        Ok(mut fit) => {
            fit.vertex_distance_mm = repaired
                .vertex_of
                .iter()
                .map(|r| r.and_then(|r| fit.vertex_distance_mm.get(r as usize).copied().flatten()))
                .collect();
            fit.report.repair = RepairReport {
                welded_vertices: repaired.welded,
                weld_tolerance_mm: repaired.weld_tolerance_mm,
                degenerate_triangles: repaired.degenerate,
                left_out: repaired.left_out,
            };
            fit.report.units = opts.units;
            fit.report.warnings.extend(warning);
            Ok(fit)
        }
        Err(e) => Err(match warning {
            Some(hint) => FitError::Units {
                hint,
                source: Box::new(e),
            },
            None => e,
        }),
    }
}

/// [`fit_tube`] on a mesh already in mm; `trimmed`: the mesh was already
/// cut to a tubular stretch (features are not looked for again).
///
/// The fit runs on the skins' vertices; when their sections fail (not near
/// a circle, too few), it runs again with points along the edges of a
/// coarse bend too ([`samples::with_bend_edges`]), and the first failure stands when
/// that fails as well: a mesh that fits on its vertices is fitted as before.
///
/// A coarse export whose rings of vertices lie further apart along the
/// guide than its knots allow, and are not flat rings that bridge the guide
/// between them ([`bridge_between_rings`]), gets a warning
/// ([`Coarseness::warning`]) (unless [`FitOptions::knot_spacing_mm`] is
/// set): between its rings no vertex holds the guide, which then follows
/// the facets' chords, inside a curved tube.
fn fit_in_mm(mesh: &TubeMesh, opts: &FitOptions, trimmed: bool) -> Result<TubeFit, FitError> {
    let mut coarse = Coarseness::default();
    let mut fit = fit_passes(mesh, opts, trimmed, &mut coarse)?;
    if opts.knot_spacing_mm.is_none() {
        fit.report.warnings.extend(coarse.warning());
    }
    Ok(fit)
}

/// The passes of [`fit_in_mm`] with the options' knots: the vertices, then
/// (where their sections fail) a coarse bend's edges, then plane cuts; the
/// first failure stands. `coarse` is the fitting pass's.
fn fit_passes(
    mesh: &TubeMesh,
    opts: &FitOptions,
    trimmed: bool,
    coarse: &mut Coarseness,
) -> Result<TubeFit, FitError> {
    match fit_pass(mesh, opts, trimmed, Pass::Vertices, coarse) {
        Err(e @ (FitError::SectionNotCircle { .. } | FitError::Degenerate { .. })) => {
            fit_pass(mesh, opts, trimmed, Pass::BendEdges, coarse)
                .or_else(|_| fit_pass(mesh, opts, trimmed, Pass::Cuts, coarse))
                .map_err(|_| e)
        }
        fitted => fitted,
    }
}

/// What a pass of [`fit_pass`] refits the guide to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Pass {
    /// Sections of the skins' vertices.
    Vertices,
    /// Sections of the skins' vertices and of points along a coarse bend's
    /// edges ([`samples::with_bend_edges`]), then of the vertices alone.
    BendEdges,
    /// Sections cut from the skins' triangles by the stations' planes
    /// ([`cut::cut_sections`]): a coarse export whose rings lie askew to
    /// the stations all along (a helix, an S-bend in a few stretches).
    Cuts,
}

/// One fit of [`fit_in_mm`]: on the skins' vertices, or with
/// [`Pass::BendEdges`] on points along a coarse bend's edges first (an error
/// when the mesh has no such edges: nothing new to try), or with
/// [`Pass::Cuts`] on the skins' plane cuts. The final sections, the laws
/// and the residuals are the vertices' in every pass.
fn fit_pass(
    mesh: &TubeMesh,
    opts: &FitOptions,
    trimmed: bool,
    pass: Pass,
    coarse: &mut Coarseness,
) -> Result<TubeFit, FitError> {
    let surf = topology::surfaces(mesh, opts)?;
    let ends = end_rings(mesh, &surf)?;
    let [mut start, mut finish] = choose_start(mesh, ends, opts)?;
    let edge = median_edge(mesh, &surf.skins[0].triangles);
    let r0 = start.radius.min(finish.radius);
    let (spacing, knot_h) = spacings(opts, edge, r0);
    coarse.knot_h = knot_h;
    let march = pass == Pass::Cuts;
    let sizes = (edge, knot_h, opts.section_rms_allowed(r0));
    let mut guide = first_guide(mesh, &surf, [&start, &finish], sizes, march)?;
    let later = pass != Pass::Vertices;
    let mut samples = pass_samples(mesh, &surf, &guide, spacing, r0, pass)?;
    let check_after = if later { CHECK_SECTIONS_AFTER } else { 1 };
    let failed = |spline: &CubicSpline, stations: &[Station], samples: &Samples, t: &[f64]| {
        let cx = (mesh, &surf, spline, stations, samples, t, 2.0 * r0);
        failed_sections(cx, opts, trimmed, later)
    };
    let mut hints: Option<Vec<f64>> = None;
    // Refits to the plane cuts first (Pass::Cuts), then to the vertices.
    let mut cutting = pass == Pass::Cuts;
    // The radius law's slope from the previous pass (none at first).
    let mut slope: Option<(Vec<f64>, Vec<f64>)> = None;
    let (mut iterations, mut converged, mut last_move) = (0, false, f64::INFINITY);
    let first_length = {
        let r = tube_range(&guide);
        r.1 - r.0
    };
    // The vertices' pass's first failed check and its refit, while the
    // guide is refitted to the round sections alone (FEATURE_REFITS): every
    // outcome but a feature named, or every section round again, is then
    // this failure.
    let mut postponed: Option<(FitError, usize)> = None;
    // The last refit's sections (where the final radius law turns), and
    // its knots on the guide before and after it (carry_hints).
    let mut last_stations: Vec<Station> = Vec::new();
    let mut last_carry: (Vec<f64>, Vec<f64>) = (Vec::new(), Vec::new());
    // Every refit's guide, and the last: one too long for its knots, or
    // diverged from the first guide's length, goes no further.
    let too_long = |range: (f64, f64)| {
        let len = range.1 - range.0;
        let knots = len / knot_h;
        let reason = if knots > MAX_KNOTS {
            format!("the guide is {len:.1} mm long for an end radius of {r0:.3} mm: {knots:.0} knots {knot_h:.2} mm apart, over the limit of {MAX_KNOTS:.0} (a vertex far from the tube? a longer tube fits with a larger knot_spacing_mm)")
        } else if len > DIVERGED_LENGTH_RATIO * first_length {
            format!("the guide diverged ({len:.1} mm long, from {first_length:.1} mm)")
        } else {
            return None;
        };
        Some(FitError::Degenerate {
            file: mesh.file.clone(),
            station: 0,
            reason,
        })
    };
    while iterations < opts.max_iterations {
        iterations += 1;
        let spline = spline_of(mesh, &guide).map_err(|e| postponed.take().map_or(e, |p| p.0))?;
        let range = tube_range(&guide);
        if let Some(e) = too_long(range) {
            return Err(postponed.take().map_or(e, |p| p.0));
        }
        let t = project_all(
            &spline,
            range,
            &samples,
            hints.as_deref(),
            PROJECT_PAST_END_RADII * r0,
        );
        let mut stations = if cutting {
            let (step, frames) = station_frames(&spline, range, spacing);
            let mut cuts = cut::cut_sections(mesh, &surf, &samples, &t, &frames, step, 2.0 * r0);
            cut::hold_ends(&mut cuts, [&start, &finish]);
            cuts
        } else {
            sections(&spline, range, spacing, &samples, &t, slope.as_ref(), r0)
        };
        cut_then_bridge(
            (mesh, &surf, &samples, &t),
            (&spline, range, spacing, r0),
            &mut stations,
            opts,
        );
        if iterations > check_after {
            match (check_sections(mesh, &stations, opts), postponed.take()) {
                // Round now (with a failure postponed: the refits to the
                // round sections brought the rest round too, an early guide
                // that cut a tight bend short): on as if it had not failed.
                (Ok(()), _) => {}
                (Err(e), None) => {
                    if pass == Pass::Vertices {
                        postponed = Some((e, iterations));
                    } else if let Some(exit) = failed(&spline, &stations, &samples, &t) {
                        return exit;
                    }
                }
                (Err(_), Some((first, at))) if iterations - at < FEATURE_REFITS => {
                    postponed = Some((first, at));
                }
                (Err(_), Some((first, _))) => {
                    return match failed(&spline, &stations, &samples, &t) {
                        Some(Err(FitError::SectionNotCircle { .. })) | None => Err(first),
                        Some(exit) => exit,
                    };
                }
            }
        }
        let knots = fit_knots(range, knot_h, spacing.max(coupling_gap(slope.as_ref())));
        // Each station's radius at the station: read at its points' place
        // (Station::radius_read, the final law's), the widened stations'
        // moved this slope law and broke the refits of coarse coils and
        // bends.
        slope = fit_law(
            mesh,
            &stations,
            &knots,
            &|s| s.radius.map(|r| (s.t, r)),
            false,
            false,
        )
        .ok()
        .map(|law| (knots.clone(), law.values));
        let ends = [(range.0, &start), (range.1, &finish)].map(|(t, e)| (t, e.centre, *e.normal));
        let round_only = postponed.as_ref().map(|_| (opts, ends));
        let mut next = refit_guide(mesh, &stations, &knots, round_only)
            .map_err(|e| postponed.take().map_or(e, |p| p.0))?;
        anchor_ends(&mut next, &start, &finish);
        let previous = last_move;
        // The points past the ends are left out: the data barely hold them.
        // A move along the guide is its parameter's, not its shape's (the
        // chord lengths from the point past the start shift every knot's
        // place along the guide a little): left out.
        let across = |k: f64, p: &Point3| {
            let d = spline.point(k) - p;
            let along = spline.d1(k).normalize();
            (d - along * d.dot(&along)).norm()
        };
        last_move = knots
            .iter()
            .zip(&next)
            .skip(1)
            .take(knots.len() - 2)
            .map(|(&k, p)| across(k, p))
            .fold(0.0, f64::max);
        let next_knots = chord_knots(&next);
        hints = Some(carry_hints(t, &knots, &next_knots));
        last_carry = (knots, next_knots);
        guide = next;
        // Converged, or stalled at the level of the mesh's noise (a quarter
        // of the sections' typical scatter: vertices changing station make
        // the last moves go back and forth).
        let noise = median_section_rms(&stations);
        last_stations = stations;
        let stall_level = (STALL_TOLERANCES * opts.tolerance_mm).max(STALL_NOISE_FRACTION * noise);
        let stalled = last_move < stall_level && last_move > STALL_SHRINK_RATIO * previous;
        let settled = last_move < opts.tolerance_mm || stalled;
        // Settled on the edges' points too, or they had their refits: on to
        // the vertices alone (the points along a coarse export's edges lie
        // on its chords, inside the true surface, more on a bend's outer
        // side than on its inner).
        if (settled || iterations >= EDGE_REFITS) && std::mem::take(&mut cutting) {
            last_move = f64::INFINITY;
            continue;
        }
        if (settled || iterations >= EDGE_REFITS) && samples.drop_edges(&mut hints) {
            last_move = f64::INFINITY;
            continue;
        }
        if settled {
            converged = true;
            break;
        }
    }
    // Kinks of a profile held by rings far apart; a radius held at every
    // station (a fine mesh) needs no trial law.
    let rings_apart = last_stations
        .iter()
        .any(|s| s.widened || s.radius.is_none());
    let kinks = if rings_apart {
        fit_law(
            mesh,
            &last_stations,
            &last_carry.0,
            &Station::radius_read,
            true,
            false,
        )
        .map_or_else(|_| Vec::new(), |law| law.kinks)
    } else {
        Vec::new()
    };
    let kinks = carry_hints(kinks, &last_carry.0, &last_carry.1);
    let guide = kinked_guide(mesh, guide, &kinks, knot_h)
        .map_err(|e| postponed.take().map_or(e, |p| p.0))?;
    let spline = spline_of(mesh, &guide).map_err(|e| postponed.take().map_or(e, |p| p.0))?;
    let knots = chord_knots(&guide);
    let range = tube_range(&guide);
    if let Some(e) = too_long(range) {
        return Err(postponed.take().map_or(e, |p| p.0));
    }
    let samples = samples.vertex_only();
    let t = project_all(
        &spline,
        range,
        &samples,
        hints
            .as_deref()
            .map(|h| &h[..samples.vertices.min(h.len())]),
        PROJECT_PAST_END_RADII * r0,
    );
    let mut stations = sections(&spline, range, spacing, &samples, &t, slope.as_ref(), r0);
    coarse.bridged = cut_then_bridge(
        (mesh, &surf, &samples, &t),
        (&spline, range, spacing, r0),
        &mut stations,
        opts,
    );
    match (failed(&spline, &stations, &samples, &t), postponed) {
        (Some(Err(FitError::SectionNotCircle { .. })) | None, Some((first, _))) => {
            return Err(first)
        }
        (Some(exit), _) => return exit,
        (None, None) => {}
    }
    coarse.measure(&stations, &spline);
    let pieces = separate_pieces(mesh, &surf, &stations, &spline, opts)?;
    let law = |pick: &dyn Fn(&Station) -> Option<(f64, f64)>| {
        fit_law(mesh, &stations, &knots, pick, true, !kinks.is_empty()).map(|law| law.values)
    };
    let mut radius_mm = law(&Station::radius_read)?;
    let spread = radius_mm
        .iter()
        .fold((f64::MAX, f64::MIN), |a, &r| (a.0.min(r), a.1.max(r)));
    let constant = spread.1 - spread.0 < CONSTANT_RADIUS_SPREAD_TOLS * opts.constant_radius_tol_mm;
    if constant {
        let mean = radius_mm.iter().sum::<f64>() / radius_mm.len() as f64;
        radius_mm.iter_mut().for_each(|r| *r = mean);
    }
    let sparse = (!constant).then(|| sparse_rings(&stations, r0)).flatten();
    let thickness_mm = match samples.skins {
        2 => Some(law(&|s| s.thickness.map(|e| (s.t, e)))?),
        _ => None,
    };
    let outer = outer_skin(&stations);
    let mut normal = start.normal;
    if normal.dot(&spline.d1(range.0)) < 0.0 {
        normal = -normal;
    }
    let tilt = normal.angle(&spline.d1(range.0));
    let extend_before_mm =
        start.radius * tilt.tan().min(MAX_START_TILT_TAN) + EXTEND_BEFORE_MARGIN_MM;
    let mut fit = TubeFit {
        file: mesh.file.clone(),
        substrate_point: guide[1],
        t_min: range.0,
        t_max: range.1,
        guide_points: guide,
        knots,
        radius_mm,
        thickness_mm,
        substrate_normal: normal,
        extend_before_mm,
        vertex_distance_mm: Vec::new(),
        report: FitReport::default(),
    };
    classify_ends(
        mesh,
        &surf,
        [&mut start, &mut finish],
        &spline,
        &stations,
        opts,
    )?;
    let ctx = report::Context {
        mesh,
        surfaces: &surf,
        samples_pos: &samples.pos,
        samples_skin: &samples.skin,
        outer,
        t: &t,
        stations: &stations,
        start: &start,
        finish: &finish,
        iterations,
        converged,
        last_move_mm: last_move,
        check_surface: opts.check_surface,
    };
    (fit.report, fit.vertex_distance_mm) = report::build(&ctx, &fit);
    fit.report.features = pieces;
    fit.report.warnings.extend(sparse);
    if !converged {
        fit.report.warnings.push(format!(
            "the guide did not settle in {iterations} refits: its last refit moved it by up to {last_move:.3} mm (tolerance {:.3} mm); the residuals above are those of its last place",
            opts.tolerance_mm
        ));
    }
    check_residual(mesh, fit, opts)
}

/// Completes a refit's `stations`: when under half the stations hold a
/// section, those without one take plane cuts ([`fill_from_cuts`]); then
/// those between two rings of vertices of a coarse export that hold no ring
/// of their own are bridged between the rings ([`bridge_between_rings`]).
/// The cuts go first: the facets of a straight written as one strip lie on
/// it, and they tell the bridge which stretches between rings are long
/// enough to be a straight leg.
/// `data`: the mesh, its surfaces, the samples and their guide parameters;
/// `at`: the guide, its range, the stations' spacing and the end radius
/// (mm). Returns how many stations it bridged.
fn cut_then_bridge(
    data: (&TubeMesh, &Surfaces, &Samples, &[f64]),
    at: (&CubicSpline, (f64, f64), f64, f64),
    stations: &mut [Station],
    opts: &FitOptions,
) -> usize {
    let (_, _, samples, t) = data;
    let (spline, _, spacing, _) = at;
    fill_from_cuts(data, at, stations);
    // Every station holding a ring of its own (a fine mesh): nothing to
    // bridge, and no runs of vertices to sort.
    if stations
        .iter()
        .all(|s| !s.widened && !s.cut && s.centre.is_some())
    {
        return 0;
    }
    let rings = vertex_rings(samples, t, spline, spacing, WIDEN_GAP_DEG, opts);
    bridge_between_rings(stations, &rings)
}

/// The stations' spacing and the guide's knot spacing (mm), from the
/// options or else the mesh's median edge `edge` and the smaller end
/// radius `r0` (mm).
fn spacings(opts: &FitOptions, edge: f64, r0: f64) -> (f64, f64) {
    let spacing = opts.station_spacing_mm.unwrap_or_else(|| {
        (STATION_SPACING_EDGES * edge).clamp(
            MIN_STATION_SPACING_MM,
            (MAX_STATION_SPACING_RADII * r0).max(MIN_STATION_SPACING_MM),
        )
    });
    let knot_h = opts
        .knot_spacing_mm
        .unwrap_or_else(|| {
            (KNOT_SPACING_RADII * r0).clamp(KNOT_SPACING_RANGE_MM.0, KNOT_SPACING_RANGE_MM.1)
        })
        .max(MIN_KNOT_STATIONS * spacing);
    (spacing, knot_h)
}

/// The samples of a pass of [`fit_pass`] with the first `guide` (points):
/// the skins' vertices, and with [`Pass::BendEdges`] the points along a
/// coarse bend's edges (an error when it has none). `spacing`: the stations' (mm);
/// `r0`: the smaller end radius (mm).
fn pass_samples(
    mesh: &TubeMesh,
    surf: &Surfaces,
    guide: &[Point3],
    spacing: f64,
    r0: f64,
    pass: Pass,
) -> Result<Samples, FitError> {
    let vertices = Samples::vertices(mesh, surf);
    if pass != Pass::BendEdges {
        return Ok(vertices);
    }
    let (spline, range) = (spline_of(mesh, guide)?, tube_range(guide));
    let past_end = PROJECT_PAST_END_RADII * r0;
    samples::with_bend_edges(mesh, surf, vertices, &spline, range, spacing, past_end).ok_or_else(
        || FitError::Degenerate {
            file: mesh.file.clone(),
            station: 0,
            reason: "no edge spans a bend".into(),
        },
    )
}

/// The median RMS of the stations' circle fits (mm; 0 with none): the
/// level of the mesh's noise. A bridged station's borrowed section is left
/// out: its scatter is the guide's error at the rings it borrowed from.
fn median_section_rms(stations: &[Station]) -> f64 {
    let mut scatter: Vec<f64> = stations
        .iter()
        .filter(|s| !s.bridged)
        .flat_map(|s| s.fits.iter().flatten().map(|f| f.rms))
        .collect();
    if scatter.is_empty() {
        return 0.0;
    }
    let k = scatter.len() / 2;
    *scatter.select_nth_unstable_by(k, f64::total_cmp).1
}

/// `fit`, unless its residual is over [`FitOptions::max_rms_mm`].
fn check_residual(mesh: &TubeMesh, fit: TubeFit, opts: &FitOptions) -> Result<TubeFit, FitError> {
    if fit.report.rms_mm <= opts.max_rms_mm {
        return Ok(fit);
    }
    let worst = fit
        .report
        .stations
        .iter()
        .max_by(|a, b| a.vertex_rms_mm.total_cmp(&b.vertex_rms_mm))
        .expect("stations");
    Err(FitError::Residual {
        file: mesh.file.clone(),
        rms_mm: fit.report.rms_mm,
        max_rms_mm: opts.max_rms_mm,
        station: worst.index,
        t_mm: worst.t_mm,
        station_rms_mm: worst.vertex_rms_mm,
    })
}

fn spline_of(mesh: &TubeMesh, points: &[Point3]) -> Result<CubicSpline, FitError> {
    CubicSpline::new(points).map_err(|e| FitError::Degenerate {
        file: mesh.file.clone(),
        station: 0,
        reason: format!("the guide's spline: {e}"),
    })
}

/// The tube's parameter range: from the second guide point to the one
/// before last (the outer points lie past the ends).
fn tube_range(points: &[Point3]) -> (f64, f64) {
    let k = chord_knots(points);
    (k[1], k[k.len() - 2])
}

/// Halvings of the knot spacing toward a kink of the profile
/// ([`kinked_guide`]): knots at 1/2 to 1/64 of it either side.
const KINK_KNOT_LEVELS: i32 = 6;

/// The final `guide` (points) with knots toward each of `kinks` (guide
/// parameters, mm; [`Law::kinks`](super::laws::Law::kinks)), at 1/2, 1/4,
/// ... of the knot spacing `knot_h` (mm) either side
/// ([`KINK_KNOT_LEVELS`]) and at the kink: a smooth radius law then turns a
/// reducer's kink within a fraction of a mm, where knots 12 mm apart swung
/// it by 3 mm. The guide keeps its shape: its spline is sampled there.
fn kinked_guide(
    mesh: &TubeMesh,
    guide: Vec<Point3>,
    kinks: &[f64],
    knot_h: f64,
) -> Result<Vec<Point3>, FitError> {
    if kinks.is_empty() {
        return Ok(guide);
    }
    let spline = spline_of(mesh, &guide)?;
    let mut knots = chord_knots(&guide);
    let range = tube_range(&guide);
    let apart = knot_h * 0.5_f64.powi(KINK_KNOT_LEVELS + 1);
    for &k in kinks {
        let steps = (1..=KINK_KNOT_LEVELS).map(|i| knot_h * 0.5_f64.powi(i));
        for t in steps.flat_map(|d| [k - d, k + d]).chain([k]) {
            if t > range.0 && t < range.1 && knots.iter().all(|&x| (x - t).abs() > apart) {
                knots.push(t);
            }
        }
    }
    knots.sort_by(f64::total_cmp);
    Ok(knots.iter().map(|&k| spline.point(k)).collect())
}

/// Knots of the refit: graded over the tube's range, plus one knot past
/// each end (as far as the first interval is long).
fn fit_knots(range: (f64, f64), knot_h: f64, spacing: f64) -> Vec<f64> {
    let inner = smooth::graded_knots(range.1 - range.0, knot_h, spacing);
    let (first, last) = (
        inner[1] - inner[0],
        inner[inner.len() - 1] - inner[inner.len() - 2],
    );
    let mut k = vec![range.0 - first];
    k.extend(inner.iter().map(|x| x + range.0));
    k.push(range.1 + last);
    k
}

/// Cumulative chord lengths of `points` (mm): the spline guide's `t`.
pub(super) fn chord_knots(points: &[Point3]) -> Vec<f64> {
    let mut k = vec![0.0];
    for w in points.windows(2) {
        k.push(k[k.len() - 1] + (w[1] - w[0]).norm());
    }
    k
}

/// Plane and circle of one open end.
fn ring(mesh: &TubeMesh, vertices: &[u32]) -> Option<(Point3, UnitVector3, f64)> {
    let pts: Vec<Point3> = vertices
        .iter()
        .map(|&v| mesh.vertices[v as usize])
        .collect();
    let (c, n, _) = fit_plane(&pts)?;
    let (centre, f) = circle_in_plane(&pts, &c, &n)?;
    Some((centre, n, f.radius))
}

/// The two open ends, each averaged over the skins (loops paired by nearest centre).
fn end_rings(mesh: &TubeMesh, surf: &Surfaces) -> Result<[EndRing; 2], FitError> {
    let fitted: Vec<[(Point3, UnitVector3, f64); 2]> = surf
        .skins
        .iter()
        .map(|s| {
            let f = |l: &Vec<u32>| {
                ring(mesh, l).ok_or_else(|| FitError::Degenerate {
                    file: mesh.file.clone(),
                    station: 0,
                    reason: format!("the open end of {} vertices is not a ring", l.len()),
                })
            };
            Ok([f(&s.loops[0])?, f(&s.loops[1])?])
        })
        .collect::<Result<_, FitError>>()?;
    let capped = |skin: usize, l: usize| {
        surf.caps.iter().any(|c| {
            surf.skins[skin].loops[l]
                .iter()
                .any(|v| c.vertices.binary_search(v).is_ok())
        })
    };
    let make = |l0: usize| -> Result<EndRing, FitError> {
        let (c0, n0, r0) = fitted[0][l0];
        let mut end = EndRing {
            centre: c0,
            normal: n0,
            radius: r0,
            capped: capped(0, l0),
            shape: None,
            loops: vec![l0],
        };
        if let Some(other) = fitted.get(1) {
            let l1 = if (other[0].0 - c0).norm() <= (other[1].0 - c0).norm() {
                0
            } else {
                1
            };
            let (c1, _, r1) = other[l1];
            if (c1 - c0).norm() > 0.5 * r0.max(r1) {
                return Err(FitError::NotATube {
                    file: mesh.file.clone(),
                    found: format!(
                        "two surfaces whose ends are {:.2} mm apart (radii {r0:.2} and {r1:.2} mm): not the two skins of one wall",
                        (c1 - c0).norm()
                    ),
                });
            }
            end.centre = Point3::from(0.5 * (c0.coords + c1.coords));
            end.radius = 0.5 * (r0 + r1);
            end.capped |= capped(1, l1);
            end.loops.push(l1);
        }
        Ok(end)
    };
    Ok([make(0)?, make(1)?])
}

fn choose_start(
    mesh: &TubeMesh,
    ends: [EndRing; 2],
    opts: &FitOptions,
) -> Result<[EndRing; 2], FitError> {
    let [a, b] = ends;
    let swap = match opts.start {
        StartEnd::Lowest => b.centre.z < a.centre.z,
        StartEnd::Highest => b.centre.z > a.centre.z,
        StartEnd::Near(p) => {
            let p = Point3::new(p[0], p[1], p[2]);
            (b.centre - p).norm() < (a.centre - p).norm()
        }
        StartEnd::Capped => match (a.capped, b.capped) {
            (true, false) => false,
            (false, true) => true,
            (x, _) => {
                return Err(FitError::NotATube {
                    file: mesh.file.clone(),
                    found: format!(
                        "start = capped, but {} ends are closed by a flat cap (need exactly one)",
                        if x { "both" } else { "no" }
                    ),
                })
            }
        },
    };
    Ok(if swap { [b, a] } else { [a, b] })
}

/// Minimal rotation taking unit `a` to unit `b`, applied to `x`.
fn rotate(a: &Vector3, b: &Vector3, x: &Vector3) -> Vector3 {
    let v = a.cross(b);
    let c = a.dot(b);
    if c < -0.999 {
        return *x;
    }
    x * c + v.cross(x) + v * (v.dot(x) / (1.0 + c))
}

/// Stations every `spacing` mm over the tube's range; each takes the samples
/// whose nearest guide parameter is nearest to it, carried into its normal
/// plane by the minimal rotation of their own normal plane, and fits one
/// circle per skin. A station whose ring is open (a coarse mesh) also takes
/// its neighbours' samples, out to `reach` mm either side.
fn sections(
    spline: &CubicSpline,
    range: (f64, f64),
    spacing: f64,
    s: &Samples,
    t: &[f64],
    law: Option<&(Vec<f64>, Vec<f64>)>,
    reach: f64,
) -> Vec<Station> {
    let law = law.map(|(k, v)| (k, v, smooth::natural_second_derivatives(k, v)));
    let slope_at = |t: f64| {
        law.as_ref().map_or(0.0, |(k, v, m)| {
            let h = 0.5 * spacing;
            (smooth::eval(k, v, m, t + h) - smooth::eval(k, v, m, t - h)) / (2.0 * h)
        })
    };
    let (step, frames) = station_frames(spline, range, spacing);
    let n = frames.len() - 1;
    let mut bins: Vec<Vec<SectionPoint>> = vec![Vec::new(); (n + 1) * s.skins];
    for (k, (p, &tv)) in s.pos.iter().zip(t).enumerate() {
        let i = (((tv - range.0) / step).round().max(0.0) as usize).min(n);
        let (ti, _, tan_i, e1, e2) = &frames[i];
        let o = p - spline.point(tv);
        let o = rotate(&spline.d1(tv).normalize(), tan_i, &o);
        bins[i * s.skins + s.skin[k] as usize].push(SectionPoint {
            x: o.dot(e1),
            y: o.dot(e2),
            dt: tv - ti,
        });
    }
    // A station with under half the usual points is a partial ring (past an
    // end cut obliquely): left out, ...
    let mut counts: Vec<usize> = (0..=n)
        .map(|i| (0..s.skins).map(|k| bins[i * s.skins + k].len()).sum())
        .collect();
    let median = *counts.select_nth_unstable(n / 2).1;
    // ... unless its ring is open: a coarse mesh (rings of vertices further
    // apart than the stations) leaves stations with a partial ring or none.
    // Those take the points of their neighbours too, out to `reach` mm either
    // side, until every skin's ring is closed.
    let widest = ((reach / step).ceil() as usize).max(1);
    let closed = |fits: &[Option<CircleFit>]| {
        fits.iter()
            .all(|f| f.is_some_and(|f| f.max_gap_rad <= WIDEN_GAP_DEG.to_radians()))
    };
    frames
        .par_iter()
        .enumerate()
        .map(|(i, (ti, ..))| {
            let slope = slope_at(*ti);
            let mut fits: Vec<Option<CircleFit>> = (0..s.skins)
                .map(|k| fit_circle(&bins[i * s.skins + k], slope))
                .collect();
            let mut points = (0..s.skins).map(|k| bins[i * s.skins + k].len()).sum();
            let mut full = 2 * points >= median;
            let mut widened = false;
            if !closed(&fits) {
                let mut wide: Vec<Vec<SectionPoint>> = (0..s.skins)
                    .map(|k| bins[i * s.skins + k].clone())
                    .collect();
                for w in 1..=widest {
                    for j in [i.checked_sub(w), Some(i + w).filter(|&j| j <= n)]
                        .into_iter()
                        .flatten()
                    {
                        for (k, pts) in wide.iter_mut().enumerate() {
                            let dt = frames[j].0 - ti;
                            pts.extend(bins[j * s.skins + k].iter().map(|p| SectionPoint {
                                dt: p.dt + dt,
                                ..*p
                            }));
                        }
                    }
                    let f: Vec<Option<CircleFit>> =
                        wide.iter().map(|pts| fit_circle(pts, slope)).collect();
                    if closed(&f) {
                        (fits, points, full) = (f, wide.iter().map(Vec::len).sum(), true);
                        widened = true;
                        break;
                    }
                }
            }
            let mut station = Station::from_fits(&frames[i], fits, points, full);
            station.widened = widened;
            station
        })
        .collect()
}

/// A station's sections are circles by their check (RMS within the
/// allowance of [`FitOptions::section_rms_allowed`]).
fn round(s: &Station, opts: &FitOptions) -> bool {
    s.fits
        .iter()
        .flatten()
        .all(|f| f.rms <= opts.section_rms_allowed(f.radius))
}

/// The guide's new points at `knots`: the smoothing fit of the section
/// centres; with `round_only`, the centres of the sections that are not
/// circles by their check (a lug on one side pulls its circle's centre
/// towards it) bridged from the round ones beside them, or from an end's
/// ring (its guide parameter, centre and normal, start and finish) beside
/// a run at that end ([`bridge_not_round`]). With every section a circle,
/// as without.
fn refit_guide(
    mesh: &TubeMesh,
    stations: &[Station],
    knots: &[f64],
    round_only: Option<(&FitOptions, [EndAnchor; 2])>,
) -> Result<Vec<Point3>, FitError> {
    let ok: Vec<&Station> = stations.iter().filter(|s| s.centre.is_some()).collect();
    if ok.len() < 3 || ok.len() * 2 < stations.len() {
        let first_bad = stations
            .iter()
            .position(|s| s.centre.is_none())
            .unwrap_or(0);
        return Err(FitError::Degenerate {
            file: mesh.file.clone(),
            station: first_bad,
            reason: format!(
                "only {} of {} stations have enough points for a circle (need half of them)",
                ok.len(),
                stations.len()
            ),
        });
    }
    let ts: Vec<f64> = ok.iter().map(|s| s.t).collect();
    let w: Vec<f64> = ok.iter().map(|s| s.points as f64).collect();
    let mut centres: Vec<Point3> = ok.iter().map(|s| s.centre.expect("filtered")).collect();
    if let Some((opts, ends)) = round_only {
        let round: Vec<bool> = ok.iter().map(|s| round(s, opts)).collect();
        bridge_not_round(&ts, &mut centres, &round, ends);
    }
    let ys = DMatrix::from_fn(ok.len(), 3, |i, k| centres[i][k]);
    let sol = smooth::fit(knots, &ts, &ys, &w, 1e-6).ok_or_else(|| FitError::Degenerate {
        file: mesh.file.clone(),
        station: 0,
        reason: "the guide's least-squares system is singular".into(),
    })?;
    let pts: Vec<Point3> = (0..knots.len())
        .map(|j| Point3::new(sol[(j, 0)], sol[(j, 1)], sol[(j, 2)]))
        .collect();
    if pts.windows(2).any(|w| (w[1] - w[0]).norm() < 1e-6) {
        return Err(FitError::Degenerate {
            file: mesh.file.clone(),
            station: 0,
            reason: "two points of the fitted guide coincide".into(),
        });
    }
    Ok(pts)
}

/// Slides each end point of the guide along its end chord onto its open
/// end's plane: the guide runs from end to end (a least-squares refit alone
/// lets the ends creep along the tangent).
fn anchor_ends(points: &mut [Point3], start: &EndRing, finish: &EndRing) {
    let n = points.len();
    for (i, j, ring) in [(1, 2, start), (n - 2, n - 3, finish)] {
        let d = points[j] - points[i];
        let along = d.dot(&ring.normal);
        if along.abs() > 0.2 * d.norm() {
            let s = (ring.centre - points[i]).dot(&ring.normal) / along;
            // Never past the neighbouring point.
            if s < 0.9 {
                points[i] += d * s;
            }
        }
    }
}

/// Refuses a section far from a circle, or a run of three sections that are
/// not closed rings (one alone is a ring split between two stations).
fn check_sections(
    mesh: &TubeMesh,
    stations: &[Station],
    opts: &FitOptions,
) -> Result<(), FitError> {
    let gap_max = opts.max_section_gap_deg.to_radians();
    let mut run = 0;
    for (i, s) in stations.iter().enumerate() {
        let mut open = None;
        for (k, f) in s.fits.iter().enumerate() {
            let Some(f) = f.filter(|_| !s.bridged) else {
                continue;
            };
            let skin = if s.fits.len() == 2 {
                format!("skin {k}: ")
            } else {
                String::new()
            };
            let allowed = opts.section_rms_allowed(f.radius);
            if f.rms > allowed {
                return Err(FitError::SectionNotCircle {
                    file: mesh.file.clone(),
                    station: i,
                    t_mm: s.t,
                    found: format!(
                        "{skin}{} points {:.3} mm RMS (largest {:.3} mm) from their best circle of radius {:.3} mm; allowed {allowed:.3} mm",
                        f.points, f.rms, f.max_dev, f.radius
                    ),
                });
            }
            if f.max_gap_rad > gap_max {
                open = Some((skin, f.max_gap_rad));
            }
        }
        run = if open.is_some() { run + 1 } else { 0 };
        if let (Some((skin, gap)), 3) = (open, run) {
            return Err(FitError::SectionNotCircle {
                file: mesh.file.clone(),
                station: i - 2,
                t_mm: stations[i - 2].t,
                found: format!(
                    "{skin}not a closed ring: the points of this station and the next two leave a gap of up to {:.0} degrees around the circle (allowed {:.0})",
                    gap.to_degrees(),
                    opts.max_section_gap_deg
                ),
            });
        }
    }
    Ok(())
}

/// Classifies both ends ([`ends::classify`]) at the first and last stations.
fn classify_ends(
    mesh: &TubeMesh,
    surf: &Surfaces,
    rings: [&mut EndRing; 2],
    spline: &CubicSpline,
    stations: &[Station],
    opts: &FitOptions,
) -> Result<(), FitError> {
    let last = stations.len() - 1;
    for (ring, station) in rings.into_iter().zip([0, last]) {
        let t_end = stations[station].t;
        let first = station == 0;
        let tangent = spline.d1(t_end);
        let shape = ends::classify(mesh, surf, ring, first, &tangent, station, t_end, opts)?;
        ring.shape = Some((shape, station, t_end));
    }
    Ok(())
}

/// The separate pieces beside the tube as tabs: refused unless
/// [`FitOptions::trim`].
fn separate_pieces(
    mesh: &TubeMesh,
    surf: &Surfaces,
    stations: &[Station],
    spline: &CubicSpline,
    opts: &FitOptions,
) -> Result<Vec<FeatureReport>, FitError> {
    let pieces: Vec<FeatureReport> = surf
        .pieces
        .iter()
        .map(|p| features::piece(mesh, p, stations, spline))
        .collect();
    match (pieces.first(), opts.trim) {
        (Some(f), false) => Err(features::refusal(mesh, f, pieces.len())),
        _ => Ok(pieces),
    }
}

/// What [`not_tube`] looks at: the pass whose sections failed (the mesh,
/// its surfaces, the guide, its stations, the samples and their guide
/// parameters) and how far from a cut plane a vertex is sided by its
/// distance to the plane rather than its guide parameter (mm).
type NotTube<'a> = (
    &'a TubeMesh,
    &'a Surfaces,
    &'a CubicSpline,
    &'a [Station],
    &'a Samples,
    &'a [f64],
    f64,
);

/// The exit of a pass whose sections fail [`check_sections`] (`None` when
/// they pass): [`not_tube`] on the vertices' pass, the sections' own error
/// on a later pass (`later`: its
/// failure gives way to the vertices' pass's, features and all).
fn failed_sections(
    cx: NotTube<'_>,
    opts: &FitOptions,
    trimmed: bool,
    later: bool,
) -> Option<Result<TubeFit, FitError>> {
    let error = check_sections(cx.0, cx.3, opts).err()?;
    Some(if later {
        Err(error)
    } else {
        not_tube(cx, opts, trimmed, error)
    })
}

/// Sections that failed `error`: features that are not tube refused by
/// name, or with [`FitOptions::trim`] the longest tubular stretch cut out
/// and fitted (once: `trimmed`); `error` itself when no feature is found.
fn not_tube(
    cx: NotTube<'_>,
    opts: &FitOptions,
    trimmed: bool,
    error: FitError,
) -> Result<TubeFit, FitError> {
    let (mesh, surf, spline, stations, samples, t, reach) = cx;
    let nv = samples.vertices;
    let (mut pos, mut skin) = (samples.pos[..nv].to_vec(), samples.skin[..nv].to_vec());
    let mut at = t[..nv].to_vec();
    let (mut tube, mut found) = features::detect(spline, stations, &pos, &skin, &at, opts);
    // Stations without a vertex (a solid as a CAD tool writes it, vertices
    // only where its shape changes: a spool whose flanges hold every ring)
    // take the points of their plane cuts too.
    if found.is_empty() && stations.iter().any(|s| s.points == 0) {
        let ts: Vec<f64> = stations.iter().map(|s| s.t).collect();
        let cuts = cut::cut_points((mesh, surf, samples, &t[..nv]), spline, &ts, reach);
        pos.extend(cuts.0);
        skin.extend(cuts.1);
        at.extend(cuts.2);
        (tube, found) = features::detect(spline, stations, &pos, &skin, &at, opts);
    }
    let Some(first) = found.first() else {
        return Err(error);
    };
    if !opts.trim || trimmed {
        return Err(features::refusal(mesh, first, found.len()));
    }
    // Tubular runs that touch make one stretch; the longest is fitted.
    let mut stretches: Vec<(usize, usize)> = Vec::new();
    for r in tube {
        match stretches.last_mut() {
            Some(s) if s.1 + 1 == r.0 => s.1 = r.1,
            _ => stretches.push(r),
        }
    }
    let n = stations.len();
    let Some(&(a, b)) = stretches.iter().max_by(|x, y| {
        let len = |s: &(usize, usize)| stations[s.1].t - stations[s.0].t;
        len(x).total_cmp(&len(y))
    }) else {
        return Err(features::refusal(mesh, first, found.len()));
    };
    // Cut a little past the features beside the stretch (their points'
    // extent along the guide), between its first round station and the one
    // before; at its first round station when no feature is named before.
    let t0 = stations[0].t;
    let margin = TRIM_MARGIN_RADII * 0.5 * reach;
    let t_lo = (a > 0).then(|| {
        let past = found.iter().filter(|f| f.last_station < a);
        let past = past.map(|f| t0 + f.t_to_mm + margin).reduce(f64::max);
        past.map_or(stations[a].t, |t| t.clamp(stations[a - 1].t, stations[a].t))
    });
    let t_hi = (b + 1 < n).then(|| {
        let before = found.iter().filter(|f| f.first_station > b);
        let before = before.map(|f| t0 + f.t_from_mm - margin).reduce(f64::min);
        before.map_or(stations[b].t, |t| t.clamp(stations[b].t, stations[b + 1].t))
    });
    let mut t_of = vec![None; mesh.vertices.len()];
    let skin_vertices = surf.skins.iter().flat_map(|s| s.vertices.iter());
    for (&v, &tv) in skin_vertices.zip(t) {
        t_of[v as usize] = Some(tv);
    }
    let sub = features::clip(mesh, spline, &t_of, t_lo, t_hi, reach);
    let mut fit = fit_in_mm(&sub, opts, true)?;
    fit.vertex_distance_mm.truncate(mesh.vertices.len());
    let rep = &mut fit.report;
    for cut in [t_lo, t_hi].into_iter().flatten() {
        let c = spline.point(cut);
        let from = |e: &super::EndReport| (Point3::from(e.centre_mm) - c).norm();
        let end = if from(&rep.start) <= from(&rep.end) {
            &mut rep.start
        } else {
            &mut rep.end
        };
        end.kind = super::EndKind::Trimmed;
    }
    rep.features.splice(0..0, found);
    Ok(fit)
}
