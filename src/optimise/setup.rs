//! What is fixed about one layer before its branch is chosen: its points,
//! the times between them at the travel speed (s), their cylindrical angles
//! (rad), the spiral anchor, and in the torch-carried cell what each
//! point's pose keeps whatever `R_Z` (computed once per layer); builds the
//! layer's [`LayerProblem`] in a branch and its dexterity floors [SPEC §7,
//! eq. 4.6].

use std::sync::Arc;

use super::branch_types::Anchor;
use super::parameterisation::{cylindrical_angles, turns_about_z};
use super::problem::{encoder_sigma_rad, point_frames, LayerProblem};
use super::{Abscissa, DexterityFloor, OptimiseOptions, Parameterisation};
use crate::robot::cell::{CellLayout, CellPoint, TorchPointFrame};
use crate::robot::ik::Configuration;
use crate::robot::indices::{dexterity_warm, SvdWarmStart};

/// One layer (or spiral turn) as every branch sees it.
pub(super) struct LayerSetup<'a> {
    pub(super) cell: &'a CellLayout,
    pub(super) opts: &'a OptimiseOptions,
    pub(super) points: &'a [CellPoint],
    pub(super) dt: Vec<f64>,
    pub(super) theta: Vec<f64>,
    pub(super) turning: bool,
    pub(super) cylindrical: bool,
    pub(super) anchor: Option<Anchor>,
    /// Per point, what its pose keeps whatever `R_Z` ([`point_frames`]).
    pub(super) frames: Arc<[Option<TorchPointFrame>]>,
}

impl<'a> LayerSetup<'a> {
    /// The setup of `points` (a layer, or a spiral turn continuing from
    /// `anchor`): times between points at their travel speeds, cylindrical
    /// angles, whether the layer turns about the part Z axis, and the
    /// polynomial abscissa the options ask for.
    pub(super) fn new(
        cell: &'a CellLayout,
        points: &'a [CellPoint],
        opts: &'a OptimiseOptions,
        anchor: Option<Anchor>,
    ) -> Self {
        let p = points.len();
        let mut dt = vec![0.0; p];
        for m in 1..p {
            dt[m] = (points[m].position_mm - points[m - 1].position_mm).norm()
                / points[m].travel_speed_mm_s;
        }
        let theta = cylindrical_angles(&points.iter().map(|c| c.position_mm).collect::<Vec<_>>());
        let turning = turns_about_z(&theta);
        let cylindrical = match opts.parameterisation {
            Parameterisation::Polynomial { abscissa, .. } => match abscissa {
                Abscissa::PointIndex => false,
                Abscissa::CylindricalAngle => true,
                Abscissa::Auto => turning,
            },
            _ => false,
        };
        LayerSetup {
            cell,
            opts,
            points,
            dt,
            theta,
            turning,
            cylindrical,
            anchor,
            frames: point_frames(cell, points),
        }
    }

    pub(super) fn problem(&self, cfg: Configuration, psi: Vec<f64>) -> LayerProblem<'a> {
        let robot = self.cell.robot();
        let margin = self.opts.joint_limit_margin_rad;
        let gamma = std::array::from_fn(|j| {
            let l = &robot.limits[j];
            if l.is_unlimited() {
                0.0
            } else {
                1.0 / l.range_rad()
            }
        });
        let sigma_rad = encoder_sigma_rad(robot);
        LayerProblem {
            cell: self.cell,
            configuration: cfg,
            points: self.points,
            dt: self.dt.clone(),
            psi,
            gamma,
            lower: std::array::from_fn(|j| robot.limits[j].lower_rad + margin),
            upper: std::array::from_fn(|j| robot.limits[j].upper_rad - margin),
            wrist_margin: self.opts.trajectory.wrist_singularity_margin_rad,
            hose: match self.cell {
                CellLayout::TorchCarried(c) => Some(c.max_hose_torsion_rad),
                CellLayout::PartCarried(_) => None,
            },
            max_speed: robot.max_speed_rad_s,
            centring: self.opts.centring_weight / self.points.len() as f64,
            objective: self.opts.objective,
            // I in micrometres·1e3 (thesis §4.2.2 scales sigma by 1e6 too)
            sigma: sigma_rad.map(|s| s * 1e6),
            dex_scale: self.opts.trajectory.dexterity_length_scale_mm,
            start_near: self.anchor.map(|a| a.joints),
            weights: None,
            frames: Arc::clone(&self.frames),
        }
    }

    /// Dexterity floor per point from the unoptimised path (`R_Z = 0`).
    pub(super) fn floors(&self, cfg: Configuration) -> Vec<f64> {
        let p = self.points.len();
        match self.opts.dexterity_floor {
            DexterityFloor::Off => vec![0.0; p],
            DexterityFloor::Absolute { dexterity } => vec![dexterity; p],
            DexterityFloor::FractionOfUnoptimised { fraction } => {
                let prob = self.problem(cfg, vec![0.0; p]);
                let robot = self.cell.robot();
                let mut q8 = 0.0;
                let mut warm = SvdWarmStart::default();
                let d: Vec<f64> = (0..p)
                    .map(|m| match prob.joints_at(m, 0.0, None, q8) {
                        Ok((q, pose)) => {
                            if let Some(qp) = pose.positioner {
                                q8 = qp[1];
                            }
                            dexterity_warm(&robot.jacobian(&q), prob.dex_scale, &mut warm)
                        }
                        Err(_) => f64::NAN,
                    })
                    .collect();
                let fallback = d
                    .iter()
                    .copied()
                    .filter(|x| x.is_finite())
                    .fold(f64::INFINITY, f64::min);
                let fallback = if fallback.is_finite() { fallback } else { 0.0 };
                // one floor per layer: the mean over the layer (see the
                // option's doc for why not the thesis's per-point value)
                let mean = d
                    .iter()
                    .map(|x| if x.is_finite() { *x } else { fallback })
                    .sum::<f64>()
                    / p as f64;
                vec![fraction * mean; p]
            }
        }
    }
}
