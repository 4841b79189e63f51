//! Integration tests of the closed loop (`waam_slicer::replan`, issue 29) on
//! synthetic scans made here: a planned layer displaced along its build
//! direction by a known error field, with noise, missing points and stray
//! points. The expected speeds, heights and tops are computed here from the
//! law `ln h = a ln v + b` and the true field, not read from the library;
//! the joints are checked with the SPEC §6.1 kinematics written out in
//! `tests/common`.

#[path = "../common/mod.rs"]
mod common;

mod cli;
mod geometry;
mod refusals;
mod speed;
mod support;
mod torch_carried;
