//! The one checker of decoded [`Step`]s (module doc of
//! [`validate`](super)): bead points, joint limits, speeds, configuration
//! consistency, deposition points against the plan, process on and off.

use std::f64::consts::PI;

use crate::math::Point3;
use crate::program::fanuc::MoveKind;
use crate::robot::{Cell, Joints};

use super::ProblemKind;
use super::{
    deposition_point, push, MotionSpeed, Step, ValidationReport, NAMES, REACH_TOLERANCE_MM,
};

/// Checks decoded `steps` against `cell` (module doc), adding problems and
/// counts to `report`. `planned`: the planned deposition points (part
/// frame, mm), one per bead motion in execution order.
pub fn check_steps(
    steps: &[Step],
    cell: &Cell,
    planned: Option<&[Point3]>,
    common: &crate::program::ProgramOptions,
    report: &mut ValidationReport,
) {
    let _ = common;
    // which motions are bead points: made with the process on, or the last
    // motion before the process starts
    let mut bead = vec![false; steps.len()];
    let mut on = false;
    let mut last_motion: Option<usize> = None;
    for (i, s) in steps.iter().enumerate() {
        match s {
            Step::Motion(_) => {
                bead[i] = on;
                last_motion = Some(i);
            }
            Step::ProcessOn { .. } => {
                if let Some(k) = last_motion {
                    bead[k] = true;
                }
                on = true;
            }
            Step::ProcessOff { .. } => on = false,
            Step::Wait { .. } | Step::Payload { .. } => {}
        }
    }
    let robot = cell.robot();
    let mut arc_on: Option<(String, usize)> = None;
    let mut prev: Option<(Joints, Option<[f64; 2]>, Option<Point3>)> = None;
    let mut bead_motions = 0;
    let mut first_file: Option<String> = None;
    for (i, s) in steps.iter().enumerate() {
        let m = match s {
            Step::ProcessOn { file, line } => {
                if let Some((f, l)) = &arc_on {
                    let msg = format!(
                        "bead starts while the bead started at {f}:{l} is still on (missing Arc End / end instruction)"
                    );
                    push(report, ProblemKind::Bead, file, *line, msg);
                }
                arc_on = Some((file.clone(), *line));
                continue;
            }
            Step::ProcessOff { file, line } => {
                if arc_on.take().is_none() {
                    push(
                        report,
                        ProblemKind::Bead,
                        file,
                        *line,
                        "bead stops but none was started".into(),
                    );
                } else {
                    report.beads += 1;
                }
                continue;
            }
            Step::Wait { .. } | Step::Payload { .. } => continue,
            Step::Motion(m) => m,
        };
        first_file.get_or_insert_with(|| m.file.clone());
        report.motions += 1;
        let k = bead_motions;
        if bead[i] {
            bead_motions += 1;
        }
        if m.kind == MoveKind::Joint && arc_on.is_some() {
            push(
                report,
                ProblemKind::Bead,
                &m.file,
                m.line,
                "joint move with the arc on".into(),
            );
        }
        let Some(q) = m.joints else {
            prev = None;
            continue;
        };
        for (j, name) in NAMES.iter().enumerate() {
            let l = robot.limits[j];
            if !l.contains(q[j]) {
                push(
                    report,
                    ProblemKind::JointLimit,
                    &m.record_file,
                    m.value_lines[j],
                    format!(
                        "{}: {name} = {:.4}° outside [{:.1}°, {:.1}°]",
                        m.label,
                        q[j].to_degrees(),
                        l.lower_rad.to_degrees(),
                        l.upper_rad.to_degrees()
                    ),
                );
            }
        }
        let cfg = robot.configuration_of(&q);
        if !m.from_cartesian && cfg != cell.configuration() {
            push(
                report,
                ProblemKind::Configuration,
                &m.record_file,
                m.record_line,
                format!(
                    "{}: joints are in configuration '{cfg}', not the cell's '{}'",
                    m.label,
                    cell.configuration()
                ),
            );
        }
        let qp = m.positioner;
        if let Cell::TorchCarried(c) = cell {
            match qp {
                None => push(
                    report,
                    ProblemKind::Format,
                    &m.record_file,
                    m.record_line,
                    format!("{}: no positioner values", m.label),
                ),
                Some(qp) => {
                    for (n, l) in c.positioner.limits.iter().enumerate() {
                        if !l.contains(qp[n]) {
                            push(
                                report,
                                ProblemKind::JointLimit,
                                &m.record_file,
                                m.record_line,
                                format!(
                                    "{}: positioner J{} = {:.4}° outside its travel",
                                    m.label,
                                    n + 1,
                                    qp[n].to_degrees()
                                ),
                            );
                        }
                    }
                }
            }
        }
        let dep = deposition_point(cell, &q, qp);
        if let (true, Some(plan), Some(d)) = (bead[i], planned, dep) {
            if let Some(target) = plan.get(k) {
                let e = (d - target).norm();
                if e > REACH_TOLERANCE_MM {
                    push(
                        report,
                        ProblemKind::Deviation,
                        &m.record_file,
                        m.value_lines[0],
                        format!(
                            "{}: deposition point {e:.4} mm from the planned point {k}",
                            m.label
                        ),
                    );
                }
            }
        }
        if let Some((pq, pqp, pm)) = &prev {
            let mut msgs = Vec::new();
            let linear = m.speed != MotionSpeed::Joint;
            // joint moves (between beads) may rewind J4/J6; linear moves may not jump
            for j in (0..6).filter(|_| linear) {
                if (q[j] - pq[j]).abs() >= PI {
                    msgs.push((ProblemKind::Configuration, format!(
                        "{} jumps by {:.2}° from the previous position (turn or configuration change)",
                        NAMES[j],
                        (q[j] - pq[j]).to_degrees()
                    )));
                }
            }
            let dt = match (m.speed, dep, pm) {
                (MotionSpeed::Linear(v), Some(a), Some(b)) => {
                    let d = (a - b).norm();
                    (d > 0.0).then(|| (d / v, format!("at {v:.3} mm/s")))
                }
                (
                    MotionSpeed::Tcp {
                        mm_s,
                        flange_from_tcp,
                        extax_fraction,
                    },
                    _,
                    _,
                ) => {
                    let tcp =
                        |q: &Joints| (robot.flange_pose(q) * flange_from_tcp).translation.vector;
                    let mut t = (tcp(&q) - tcp(pq)).norm() / mm_s;
                    if let (Cell::TorchCarried(c), Some(a), Some(b)) = (cell, qp, pqp) {
                        for n in 0..2 {
                            let max = c.positioner.max_speed_rad_s[n] * extax_fraction[n];
                            let turn = (a[n] - b[n]).abs();
                            if max.is_finite() && max > 0.0 && turn > 0.0 {
                                t = t.max(turn / max);
                            }
                        }
                    }
                    if t == 0.0 && crate::program::joints_move(&q, pq) {
                        // the controller then runs the move at its
                        // orientation speed, not at any planned speed
                        msgs.push((ProblemKind::Timing, format!(
                            "linear move at {mm_s:.3} mm/s TCP speed with the TCP still while the joints turn: \
                             the controller would turn at its orientation speed limit (write it time-based)"
                        )));
                    }
                    (t > 0.0).then(|| (t, format!("at {mm_s:.3} mm/s TCP speed")))
                }
                (MotionSpeed::Time(t), _, _) => {
                    if t > 0.0 {
                        Some((t, format!("in {:.0} ms", t * 1000.0)))
                    } else {
                        msgs.push((ProblemKind::Timing, "zero duration".into()));
                        None
                    }
                }
                _ => None,
            };
            if let Some((dt, how)) = dt {
                for j in 0..6 {
                    let sp = (q[j] - pq[j]).abs() / dt;
                    if sp > robot.max_speed_rad_s[j] {
                        msgs.push((
                            ProblemKind::JointSpeed,
                            format!(
                                "{} needs {:.2}°/s {how}, maximum {:.1}°/s",
                                NAMES[j],
                                sp.to_degrees(),
                                robot.max_speed_rad_s[j].to_degrees()
                            ),
                        ));
                    }
                }
                if let (Cell::TorchCarried(c), Some(a), Some(b)) = (cell, qp, pqp) {
                    for n in 0..2 {
                        let sp = (a[n] - b[n]).abs() / dt;
                        if sp > c.positioner.max_speed_rad_s[n] {
                            msgs.push((
                                ProblemKind::JointSpeed,
                                format!("positioner J{} needs {:.2}°/s", n + 1, sp.to_degrees()),
                            ));
                        }
                    }
                }
            }
            for (kind, msg) in msgs {
                push(report, kind, &m.file, m.line, msg);
            }
        }
        prev = Some((q, qp, dep));
    }
    if let Some((file, line)) = arc_on {
        push(
            report,
            ProblemKind::Bead,
            &file,
            line,
            "bead started here never stops (no Arc End / end instruction before the program ends)"
                .into(),
        );
    }
    if let Some(p) = planned {
        if p.len() != bead_motions {
            push(
                report,
                ProblemKind::Deviation,
                first_file.as_deref().unwrap_or(""),
                0,
                format!(
                    "{bead_motions} bead motions in the programs, {} planned points",
                    p.len()
                ),
            );
        }
    }
}
