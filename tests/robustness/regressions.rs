//! Inputs that once crashed (panicked, hung or leaked a NaN), found by the
//! fuzz targets in `fuzz/` or by review; each is fed as it was and must now be
//! refused with an error naming the problem. Files too long to inline are in
//! `tests/robustness/regressions/`.

use std::path::Path;
use std::sync::Arc;
use waam_slicer::geometry::guide::Line;
use waam_slicer::geometry::{FrameMethod, GeometryError, ProfileLaw, Tube, TubeRange};
use waam_slicer::math::{Point3, Vector3};

#[allow(dead_code)]
fn regression_file(name: &str) -> Vec<u8> {
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/robustness/regressions")
        .join(name);
    std::fs::read(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

/// Review: a piecewise profile with no pieces panicked (index `0 - 1`) in
/// `ProfileLaw::radius`; part files refuse it earlier, the API did not.
#[test]
fn piecewise_profile_without_pieces_is_refused_by_the_tube() {
    let e = Tube::new(
        Arc::new(Line {
            origin: Point3::origin(),
            direction: Vector3::z_axis(),
        }),
        FrameMethod::default(),
        None,
        ProfileLaw::Piecewise(Vec::new()),
        TubeRange::new(0.0, 10.0),
    )
    .unwrap_err();
    assert!(
        matches!(e, GeometryError::NonFinite { t, .. } if t == 0.0),
        "{e:?}"
    );
    assert!(e.to_string().contains("profile radius"), "{e}");
}
