//! Cycle time against the closed forms of trapezoidal profiles.

use super::*;
use crate::math::{Point3, Vector3};
use crate::program::{BeadSetup, HomePosition, Program, ProgramPoint};
use crate::robot::{CellLayout, Configuration};

fn cell(name: &str) -> CellLayout {
    let path = format!("{}/parts/cells/{name}.toml", env!("CARGO_MANIFEST_DIR"));
    crate::pipeline::Cell::read(path)
        .expect("sample cell")
        .layout
}

fn point(layer: usize, k: usize, x: f64, speed: f64, arc: ArcFlag, q: [f64; 6]) -> ProgramPoint {
    ProgramPoint {
        layer,
        bead: 0,
        point: k,
        position_mm: Point3::new(x, 0.0, 0.0),
        tool_axis: Vector3::z_axis(),
        r_z: 0.0,
        joints: q,
        positioner: None,
        speed_mm_s: speed,
        wire_feed_mm_s: if arc.is_bead() { 10.0 } else { 0.0 },
        arc,
        via: false,
    }
}

/// A straight bead of `length` mm in `n` equal pieces at `speed` mm/s,
/// the joints still (so that only the path's profile counts).
fn straight_bead(length: f64, n: usize, speed: f64, q: [f64; 6]) -> Vec<ProgramPoint> {
    (0..=n)
        .map(|k| {
            let arc = if k == 0 {
                ArcFlag::Start
            } else if k == n {
                ArcFlag::End
            } else {
                ArcFlag::On
            };
            point(0, k, length * k as f64 / n as f64, speed, arc, q)
        })
        .collect()
}

fn program(cell: CellLayout, points: Vec<ProgramPoint>, home: Option<HomePosition>) -> Program {
    Program {
        name: "T".into(),
        cell,
        configuration: Configuration::NUT,
        points,
        home,
        bead_setup: vec![BeadSetup {
            layer: 0,
            payload: None,
            dwell_s: 0.0,
            wait_input: None,
        }],
        planned: Vec::new(),
    }
}

/// The closed form of a rest-to-rest trapezoid, written out again.
fn closed_form(l: f64, v: f64, a: f64) -> f64 {
    if l >= v * v / a {
        l / v + v / a
    } else {
        2.0 * (l / a).sqrt()
    }
}

#[test]
fn trapezoid_closed_forms() {
    // 100 mm at 10 mm/s, 2000 mm/s²: speed reached after 0.025 mm
    assert!((trapezoid_time(100.0, 10.0, 2000.0) - (10.0 + 0.005)).abs() < 1e-12);
    // 1 mm at 100 mm/s, 1000 mm/s²: v²/a = 10 mm > 1 mm, a triangle
    assert!((trapezoid_time(1.0, 100.0, 1000.0) - 2.0 * (1.0f64 / 1000.0).sqrt()).abs() < 1e-12);
    // the two branches meet at L = v²/a
    let (v, a) = (50.0, 400.0);
    let l = v * v / a;
    assert!((trapezoid_time(l, v, a) - 2.0 * v / a).abs() < 1e-12);
    assert!((trapezoid_time(l * (1.0 - 1e-9), v, a) - 2.0 * v / a).abs() < 1e-6);
    assert_eq!(trapezoid_time(0.0, v, a), 0.0);
    assert_eq!(trapezoid_time(f64::NAN, v, a), 0.0);
    assert!((trapezoid_time(3.0, 2.0, f64::INFINITY) - 1.5).abs() < 1e-12);
}

#[test]
fn blended_pieces_are_one_trapezoid() {
    // one bead cut into unequal pieces at one speed runs as one profile
    let a = 500.0;
    for (length, v) in [(120.0, 8.0), (2.0, 60.0), (0.5, 10.0)] {
        let cuts = [0.0, 0.1, 0.13, 0.5, 0.51, 0.9, 1.0];
        let segments: Vec<Segment> = cuts
            .windows(2)
            .map(|w| Segment {
                length_mm: (w[1] - w[0]) * length,
                speed_mm_s: v,
                min_time_s: 0.0,
            })
            .collect();
        let t = profile_time(&segments, a);
        assert!(
            (t - closed_form(length, v, a)).abs() < 1e-9,
            "{length} mm at {v} mm/s: {t} s"
        );
    }
}

#[test]
fn speed_change_inside_a_bead() {
    // 100 mm at 20 mm/s then 50 mm at 5 mm/s, a = 100 mm/s²: the first
    // piece accelerates to 20, cruises and slows to 5 before the junction;
    // the second cruises at 5 and stops.
    let (v1, v2, a, l1, l2) = (20.0, 5.0, 100.0, 100.0, 50.0);
    let up = v1 * v1 / (2.0 * a);
    let down = (v1 * v1 - v2 * v2) / (2.0 * a);
    let t1 = v1 / a + (v1 - v2) / a + (l1 - up - down) / v1;
    let stop = v2 * v2 / (2.0 * a);
    let t2 = v2 / a + (l2 - stop) / v2;
    let segments = [
        Segment {
            length_mm: l1,
            speed_mm_s: v1,
            min_time_s: 0.0,
        },
        Segment {
            length_mm: l2,
            speed_mm_s: v2,
            min_time_s: 0.0,
        },
    ];
    assert!((profile_time(&segments, a) - (t1 + t2)).abs() < 1e-9);
}

#[test]
fn straight_bead_in_a_program_against_the_closed_form() {
    let cell = cell("robowam_part_carried");
    let q = [0.1, 0.2, -0.1, 0.0, -0.5, 0.3];
    let opts = CycleOptions::default();
    let a = opts.path_acceleration_mm_s2;
    for (length, v) in [(300.0, 10.0), (0.02, 10.0)] {
        let p = program(cell.clone(), straight_bead(length, 37, v, q), None);
        let c = cycle_time(&p, &opts);
        assert_eq!(c.layers.len(), 1);
        let expected = closed_form(length, v, a);
        assert!(
            (c.total_s - expected).abs() < 1e-9,
            "{length} mm: {} s, closed form {expected} s",
            c.total_s
        );
        assert!((c.layers[0].bead_s - expected).abs() < 1e-9);
        assert_eq!(c.arc_on_s, c.layers[0].bead_s);
    }
}

#[test]
fn joint_move_home_against_the_closed_form() {
    // home differs from the bead in J2 only: the move in and the move out
    // each take the trapezoid of that joint at the joint-move fraction
    let cell = cell("robowam_part_carried");
    let robot = cell.robot().clone();
    let q = [0.1, 0.2, -0.1, 0.0, -0.5, 0.3];
    for delta in [1.2, 0.002] {
        let mut home = q;
        home[1] -= delta;
        let h = HomePosition {
            joints: home,
            positioner: None,
        };
        let p = program(cell.clone(), straight_bead(100.0, 4, 10.0, q), Some(h));
        let opts = CycleOptions {
            joint_speed_fraction: 0.25,
            ..CycleOptions::default()
        };
        let c = cycle_time(&p, &opts);
        let v = 0.25 * robot.max_speed_rad_s[1];
        let acc = robot.max_speed_rad_s[1] / ASSUMED_RAMP_S;
        let expected = closed_form(delta, v, acc);
        assert!((c.layers[0].transit_s - expected).abs() < 1e-12, "{delta}");
        assert!((c.home_return_s - expected).abs() < 1e-12);
        let bead = closed_form(100.0, 10.0, opts.path_acceleration_mm_s2);
        assert!((c.total_s - (2.0 * expected + bead)).abs() < 1e-9);
    }
}

#[test]
fn joint_speed_caps_a_bead_piece() {
    // a bead piece over which J6 turns faster than its maximum at the
    // programmed speed takes the joint's time instead
    let cell = cell("robowam_part_carried");
    let vmax6 = cell.robot().max_speed_rad_s[5];
    let q = [0.1, 0.2, -0.1, 0.0, -0.5, 0.0];
    let mut pts = straight_bead(10.0, 1, 10.0, q);
    pts[1].joints[5] = 5.0 * vmax6; // 5 s at J6's maximum, 1 s at 10 mm/s
    let c = cycle_time(&program(cell, pts, None), &CycleOptions::default());
    // the piece runs at 2 mm/s: 5 s plus the ramps' loss 2/2000 s
    let expected = closed_form(10.0, 2.0, ASSUMED_PATH_ACCELERATION_MM_S2);
    assert!((c.total_s - expected).abs() < 1e-9, "{}", c.total_s);
}

#[test]
fn dwell_and_approach_count() {
    let cell = cell("robowam_part_carried");
    let q = [0.1, 0.2, -0.1, 0.0, -0.5, 0.3];
    let mut pts = vec![point(0, 0, -20.0, 20.0, ArcFlag::Approach, q)];
    pts.extend(straight_bead(100.0, 3, 10.0, q));
    pts.push(point(0, 3, 120.0, 20.0, ArcFlag::Retract, q));
    let mut p = program(cell, pts, None);
    p.bead_setup[0].dwell_s = 30.0;
    p.bead_setup[0].wait_input = Some(3);
    let c = cycle_time(&p, &CycleOptions::default());
    let a = ASSUMED_PATH_ACCELERATION_MM_S2;
    let linear = closed_form(20.0, 20.0, a);
    let l = &c.layers[0];
    assert!((l.approach_s - linear).abs() < 1e-12);
    assert!((l.retract_s - linear).abs() < 1e-12);
    assert_eq!(l.dwell_s, 30.0);
    assert_eq!(c.waits, 1);
    assert!((c.total_s - (30.0 + 2.0 * linear + closed_form(100.0, 10.0, a))).abs() < 1e-9);
}
