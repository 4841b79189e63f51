//! **Stage 5 — robot kinematics and cells.** Takes a robot described as data
//! (geometry, limits, speeds) and poses of its flange or tool in the robot base
//! frame (mm, rad) and returns joint values (rad), Jacobians and performance
//! indices; holds the two cell configurations of the thesis (part carried,
//! torch carried). SPEC §6.
//!
//! | piece | module | entry points |
//! |---|---|---|
//! | arm as data, presets | [`model`] | [`RobotModel`], [`RobotModel::arcmate_120ic_nominal`], [`RobotModel::validate`] |
//! | forward kinematics | [`kinematics`] | [`RobotModel::flange_pose`] |
//! | the arm's joint frame origins (the chain the cell check and the report draw) | [`chain`] | [`chain::arm_chain`] |
//! | inverse kinematics, FANUC configurations | [`ik`] | [`RobotModel::inverse`], [`RobotModel::inverse_all`], [`Configuration`] |
//! | Jacobian | [`jacobian`] | [`RobotModel::jacobian`] |
//! | indices (eq. 1.4–1.8, 4.10–4.12) | [`indices`] | [`indices::dexterity`], [`indices::positioning_uncertainty`] |
//! | Bryant, FANUC WPR, KUKA ABC, quaternions | [`orientation`] | [`orientation::Bryant`], [`orientation::FanucWpr`] |
//! | 2-axis positioner | [`positioner`] | [`Positioner::angles_for_vertical`] |
//! | part-carried / torch-carried cells | [`cell`] | [`CellLayout`], [`CellLayout::dq_drz`] |
//! | joint trajectory of a path and its report | [`trajectory`] | [`trajectory::joint_trajectory`] |
//! | calibration of the lengths (eq. 3.17) | [`calibration`] | [`calibration::calibrate_lengths`] |
//!
//! Cell files (TOML, degrees at the edge) are read by
//! [`io::cell_file`](super::io::cell_file).
//!
//! # Example
//! ```
//! use waam_slicer::robot::{Configuration, RobotModel};
//! let robot = RobotModel::arcmate_120ic_nominal();
//! let flange = robot.flange_pose(&[0.0; 6]);
//! assert!((flange.translation.vector - waam_slicer::math::Vector3::new(1085.0, 0.0, 1040.0)).norm() < 1e-9);
//! // tool down (J5 = -90°): FANUC home posture, configuration N U T
//! let home = [0.0, 0.0, 0.0, 0.0, -90f64.to_radians(), 0.0];
//! let pose = robot.flange_pose(&home);
//! let q = robot.inverse(&pose, Configuration::NUT).unwrap();
//! assert!(q.iter().zip(home).all(|(a, b)| (a - b).abs() < 1e-9));
//! ```

pub mod calibration;
pub mod cell;
pub mod chain;
pub mod controller;
mod error;
pub mod ik;
pub mod indices;
pub mod jacobian;
pub mod kinematics;
pub mod model;
pub mod orientation;
pub mod positioner;
pub mod trajectory;

pub use cell::{CellLayout, CellPoint, CellPose, PartCarriedCell, TorchCarriedCell};
pub use error::{OutOfReach, RobotError};
pub use ik::{ArmSide, Configuration, Elbow, FanucConfig, Wrist};
pub use jacobian::{Jacobian, Twist};
pub use model::{
    ArmGeometry, JointConvention, JointLimit, Joints, RobotModel, RobotPreset, Vendor,
};
pub use positioner::Positioner;

#[cfg(test)]
mod tests;
