//! Criterion benches of the pipeline, one module per stage, on named sample parts.
//!
//! Stage modules live in `benches/pipeline/<stage>.rs`; this crate root is
//! `benches/pipeline.rs`, so they are declared inside an inline `pipeline`
//! module (folder = module, no `#[path]`).
use criterion::{criterion_group, criterion_main};

mod pipeline {
    pub mod optimise;
    pub mod path;
    pub mod place;
    pub mod program;
    pub mod robot;
}

use pipeline::{optimise, path, place, program, robot};

criterion_group!(
    benches,
    path::constant_distance,
    path::at_scale,
    robot::kinematics,
    robot::hemisphere_trajectory,
    optimise::whole_parts,
    optimise::plan_at_scale,
    optimise::torch_vs_part_carried,
    place::hemisphere_in_kuka_part_carried,
    program::readers,
    program::late_stages
);
criterion_main!(benches);
