//! Calibration of d2, d3, d4, r4, r6 (thesis §3.2.2.3, eq. 3.17) on the
//! thesis's 486-point design with synthetic noisy measurements.

use waam_slicer::math::{Point3, Vector3};
use waam_slicer::robot::calibration::{
    calibrate_lengths, thesis_random_motion_design, CalibrationMeasurement, CalibrationOptions,
};
use waam_slicer::robot::{RobotError, RobotModel};

use crate::common::Rng;

fn synthetic(truth: &RobotModel, noise_mm: f64, seed: u64) -> Vec<CalibrationMeasurement> {
    let mut rng = Rng::new(seed);
    thesis_random_motion_design()
        .into_iter()
        .map(|q| {
            let p = truth.flange_position(&q);
            let n = Vector3::new(rng.normal(), rng.normal(), rng.normal()) * noise_mm;
            CalibrationMeasurement {
                joints: q,
                flange_position_mm: p + n,
            }
        })
        .collect()
}

#[test]
fn design_has_486_points() {
    assert_eq!(thesis_random_motion_design().len(), 486);
}

#[test]
fn recovers_table_3_6_lengths_from_486_noisy_measurements() {
    let truth = RobotModel::arcmate_120ic_random_motions();
    let nominal = RobotModel::arcmate_120ic_nominal();
    let noise = 0.02; // laser tracker ±0.02 mm [§3.2.1]
    let data = synthetic(&truth, noise, 486);
    let res = calibrate_lengths(&nominal, &data, &CalibrationOptions::default()).unwrap();
    let want = truth.geometry.segment_lengths();
    for (k, want_k) in want.iter().enumerate() {
        let err = (res.lengths_mm[k] - want_k).abs();
        // within 4 standard deviations, and the standard deviations are of the
        // order of the noise
        assert!(
            err < 4.0 * res.std_dev_mm[k],
            "length {k}: err {err} vs sd {}",
            res.std_dev_mm[k]
        );
        assert!(res.std_dev_mm[k] < noise, "sd {k} = {}", res.std_dev_mm[k]);
    }
    // residuals are the noise: per-coordinate sigma ≈ 0.02, rms distance ≈ sqrt(3)·0.02
    assert!((res.sigma_mm / noise - 1.0).abs() < 0.1, "{}", res.sigma_mm);
    assert!((res.rms_residual_mm / (3f64.sqrt() * noise) - 1.0).abs() < 0.1);
    assert!(
        res.mean_distance_mm < res.rms_residual_mm && res.max_distance_mm > res.rms_residual_mm
    );
    assert!(res.iterations <= 3);
    assert_eq!(res.model.geometry.segment_lengths(), res.lengths_mm);
}

#[test]
fn exact_data_gives_exact_lengths() {
    let truth = RobotModel::arcmate_120ic_axis_by_axis();
    let data = synthetic(&truth, 0.0, 1);
    let res = calibrate_lengths(
        &RobotModel::arcmate_120ic_nominal(),
        &data,
        &CalibrationOptions::default(),
    )
    .unwrap();
    for (a, b) in res.lengths_mm.iter().zip(truth.geometry.segment_lengths()) {
        assert!((a - b).abs() < 1e-9);
    }
    assert!(res.rms_residual_mm < 1e-9);
}

#[test]
fn bad_calibration_input_is_reported() {
    let r = RobotModel::arcmate_120ic_nominal();
    let one = [CalibrationMeasurement {
        joints: [0.0; 6],
        flange_position_mm: Point3::origin(),
    }];
    let e = calibrate_lengths(&r, &one, &CalibrationOptions::default()).unwrap_err();
    assert!(matches!(e, RobotError::Calibration { count: 1, .. }), "{e}");
    // the same pose repeated does not determine the lengths
    let same = vec![
        CalibrationMeasurement {
            joints: [0.1; 6],
            flange_position_mm: Point3::new(1.0, 2.0, 3.0)
        };
        10
    ];
    let e = calibrate_lengths(&r, &same, &CalibrationOptions::default()).unwrap_err();
    assert!(e.to_string().contains("rank-deficient"), "{e}");
    let mut nan = synthetic(&r, 0.0, 2);
    nan[3].joints[2] = f64::NAN;
    let e = calibrate_lengths(&r, &nan, &CalibrationOptions::default()).unwrap_err();
    assert!(e.to_string().contains("non-finite"), "{e}");
}
