//! **Stage 4 — robot kinematics and cells.** Takes a robot described as data
//! (geometry, limits, speeds) and poses of its flange or tool in the robot base
//! frame (mm, rad) and returns joint values (rad), Jacobians and performance
//! indices; holds the two cell configurations of the thesis (part carried,
//! torch carried). SPEC §6.
