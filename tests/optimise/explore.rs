use crate::common::{load_part, part_path};
use waam_slicer::io::cell_file::read_cell_file;
use waam_slicer::optimise::*;
use waam_slicer::path::slice;
use waam_slicer::toolaxis::local_frames;

#[test]
#[ignore]
fn explore() {
    let part = load_part(&std::env::var("PART").unwrap_or("hemisphere.toml".into()));
    let mut so = part.slice_options();
    so.delta_mm = std::env::var("DELTA")
        .map(|s| s.parse().unwrap())
        .unwrap_or(5.0);
    let path = slice(&part.tube, &part.substrate, &so).unwrap();
    let frames = local_frames(&path, &part.tube);
    let layers = layer_points(&path, &frames);
    let cell = read_cell_file(part_path("cells/robowam_part_carried.toml"))
        .unwrap()
        .cell
        .unwrap();
    let mut opts = OptimiseOptions::default();
    if let Ok(f) = std::env::var("FIXED") {
        opts.parameterisation = Parameterisation::Fixed {
            r_z_rad: f.parse::<f64>().unwrap().to_radians(),
        };
    }
    if std::env::var("PBP").is_ok() {
        opts.parameterisation = Parameterisation::PointByPoint;
    }
    let plan = optimise(&cell, &layers, &opts).unwrap();
    for l in &plan.layers {
        let q0 = l.points[0].joints.unwrap();
        println!("layer {} {} {} law {:?} Φ {:.3e} it {} qp {}/{} t {:.3}ms q0 {:?} sumacc {:.3e} mindex {:.3e} lim {:.2}°J{}",
          l.layer, l.status, l.configuration.chosen, l.law, l.objective.joint_displacement, l.solver.iterations, l.solver.qp_solves, l.solver.qp_failures, l.solver.time_s*1e3,
          q0.map(|x| (x.to_degrees()*100.0).round()/100.0), l.quality.summed_acceleration_rad_s, l.quality.min_dexterity, l.quality.min_limit_distance_rad.to_degrees(), l.quality.min_limit_distance_joint);
    }
    println!("time {:.3}s feasible {}", plan.time_s, plan.is_feasible());
}
