//! The closed loop in the ROBOWAM torch-carried cell (thesis §3.2.2): the
//! hemisphere (PLA, Delta 5 mm) measured after layer 4; every replanned
//! point checked with the SPEC §6.1 arm and the positioner of thesis
//! eq. C.5–C.6 written out here, numbers read from the cell file.

use crate::common::{part_path, rx, ry, rz, spec_fk};
use crate::support::*;
use waam_slicer::math::{Matrix3, Vector3};
use waam_slicer::path::Discretisation;
use waam_slicer::{replan_part, Cell, Measured, PlanOptions, SliceOverrides};

type Frame = (Matrix3, Vector3);

fn compose(a: &Frame, b: &Frame) -> Frame {
    (a.0 * b.0, a.0 * b.1 + a.1)
}

fn xyzwpr(v: &[f64]) -> Frame {
    (
        rz(v[5].to_radians()) * ry(v[4].to_radians()) * rx(v[3].to_radians()),
        Vector3::new(v[0], v[1], v[2]),
    )
}

fn floats(v: &toml::Value) -> Vec<f64> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_float().or(x.as_integer().map(|i| i as f64)).unwrap())
        .collect()
}

#[test]
fn the_hemisphere_replans_in_the_torch_carried_cell_and_its_joints_check_out() {
    let k = 4;
    let part = part("hemisphere.toml");
    let file = part_path("cells/robowam_torch_carried.toml");
    let cell = Cell::read(&file).unwrap();
    let opts = PlanOptions {
        slice: SliceOverrides {
            discretisation: Some(Discretisation::Points(90)),
            ..SliceOverrides::default()
        },
        ..PlanOptions::default()
    };
    let sliced = nominal(&part, &opts);
    let field = Field {
        high: 0.8,
        low: -0.5,
    };
    let (scan, truth) = synthetic_scan(&sliced, k, &field, 5);
    let r = replan_part(&part, &cell, &Measured::Points(scan), k, &opts).unwrap();
    assert_eq!(r.scan.outlier_count, STRAYS);
    assert!(r.is_feasible(), "{:?}", r.planned.refusal());
    // PLA's window absorbs both errors in one layer: speeds follow the error
    assert_eq!(r.rejoined_at, Some(k + 1));
    let first = &r.corrections[0];
    let v_nom = sliced.process.travel_speed_mm_s;
    for (m, p) in sliced.path.layers[k + 1].points.iter().enumerate() {
        let e = truth[column(&sliced, k, p.v)];
        if e > 0.7 {
            assert!(first.speed_mm_s[m] > v_nom * 1.2, "point {m}");
        }
        if e < -0.45 {
            assert!(first.speed_mm_s[m] < v_nom * 0.9, "point {m}");
        }
    }

    let doc: toml::Table = std::fs::read_to_string(&file).unwrap().parse().unwrap();
    let tc = doc["torch_carried"].as_table().unwrap();
    let base_from_positioner = xyzwpr(&floats(&tc["positioner_pose_xyzwpr"]));
    let flange_from_tcp = xyzwpr(&floats(&tc["tool_xyzwpr"]));
    let c7c8 = tc["positioner"]["tilt_to_table_mm"].as_float().unwrap();
    let cone = tc["max_vertical_error_deg"]
        .as_float()
        .unwrap()
        .to_radians();
    let mut checked = 0;
    for (lp, pl) in r.planned.layers.iter().zip(&r.planned.plan.layers) {
        for (cp, pp) in lp.points.iter().zip(&pl.points) {
            let (q, e) = (pp.joints.unwrap(), pp.positioner.unwrap());
            let table: Frame = (ry(e[0]) * rz(e[1]), ry(e[0]) * Vector3::new(0.0, 0.0, c7c8));
            let part_frame = compose(&base_from_positioner, &table);
            let point = part_frame.0 * cp.position_mm.coords + part_frame.1;
            let tool = part_frame.0 * cp.tool_axis.into_inner();
            let tcp = compose(&spec_fk(&q), &flange_from_tcp);
            assert!((tcp.1 - point).norm() < 1e-3, "layer {}", lp.layer);
            assert!((tcp.0.column(2) - tool).norm() < 1e-6, "layer {}", lp.layer);
            let b = part_frame.0 * cp.build_direction.unwrap().into_inner();
            assert!(
                b.xy().norm().atan2(b.z) <= cone + 1e-9,
                "layer {}",
                lp.layer
            );
            checked += 1;
        }
    }
    assert_eq!(
        checked,
        r.planned
            .layers
            .iter()
            .map(|l| l.points.len())
            .sum::<usize>()
    );
    let dir = tempfile::tempdir().unwrap();
    let files = r.write_programs(dir.path()).unwrap();
    let report = waam_slicer::check_program(&files[0], &cell).unwrap();
    assert!(report.problems.is_empty(), "{:?}", report.problems);
}
