//! Integration tests of the robot stage (SPEC §6).

mod calibration;
mod cell_file;
mod cells;
mod common;
mod errors;
mod hemisphere;
mod ik;
mod jacobian;
mod kinematics;
mod orientation;
mod positioner;
#[path = "../common/mod.rs"]
mod shared;
