//! KUKA KRL writer: the `.src` and `.dat` pair of a [`Program`]
//! ([`write_src`], [`write_dat`], [`kuka_files`]) and the KRL pieces the
//! reader shares (status and turn, frame literals, trigger lines). Stage 7
//! (controller programs); the [vendor module](super) describes the format.

use std::io::Write;

use crate::math::Isometry3;
use crate::program::contract::Controller;
use crate::program::fmt::{ascii_comment, floor_to, Deg, Fixed, Mm};
use crate::program::frames::held_tool;
use crate::program::kuka::options::{is_call, ArcLoss, KukaOptions, StatedBase, KRL_NAME_MAX};
use crate::program::kuka::{Kuka, EMITTER};
use crate::program::split::split_to_budget;
use crate::program::PositionMode;
use crate::program::{
    check_name, check_vendor, joint_move_target, move_start, opens_bead, positioner_moves, render,
    ArcFlag, BeadSetup, EmittedFile, ProcessControl, Program, ProgramError,
};
use crate::robot::orientation::KukaAbc;
use crate::robot::{ArmSide, CellLayout, Joints, RobotModel, Vendor};

/// Name of the arc-loss interrupt routine, a local `DEF` after the main
/// routine's `END` in the `.src`.
pub const ARC_LOST_HANDLER: &str = "WAAM_ARC_LOST";

/// A KRL `FRAME` aggregate `{X …,Y …,Z …,A …,B …,C …}` of `f` (mm, deg).
pub fn frame_literal(f: &Isometry3) -> String {
    let t = f.translation.vector;
    let abc = KukaAbc::from_rotation(&f.rotation.to_rotation_matrix()).to_degrees();
    format!(
        "{{X {},Y {},Z {},A {},B {},C {}}}",
        Mm(t.x),
        Mm(t.y),
        Mm(t.z),
        Deg(abc[0]),
        Deg(abc[1]),
        Deg(abc[2])
    )
}

/// `TRIGGER WHEN DISTANCE=d DELAY=0 DO action`, with ` PRIO=-1` when the
/// action is a subprogram call (KRL requires a priority there; `-1` lets
/// the controller choose a free one).
pub fn trigger_line(distance: u8, action: &str) -> String {
    let prio = if is_call(action) { " PRIO=-1" } else { "" };
    format!("TRIGGER WHEN DISTANCE={distance} DELAY=0 DO {action}{prio}")
}
/// KUKA Status bits of joints `q` (A1..A6, KUKA convention, rad) (module
/// doc).
pub fn status(robot: &RobotModel, q: &Joints) -> u8 {
    let c = robot.configuration_of(q);
    let back = c.side == ArmSide::Back;
    let a5_negative = crate::program::fmt::as_printed_rad(q[4]) < 0.0;
    (back as u8)
        | ((crate::robot::controller::elbow_positive_cos(&c) as u8) << 1)
        | ((a5_negative as u8) << 2)
}

/// KUKA Turn bits of joints `q`: bit `i` set when `A(i+1) < 0`.
pub fn turn(q: &Joints) -> u8 {
    q.iter().enumerate().fold(0, |t, (i, v)| {
        t | (((crate::program::fmt::as_printed_rad(*v) < 0.0) as u8) << i)
    })
}

pub(crate) fn switch_statements(opts: &KukaOptions) -> (String, String) {
    match &opts.process {
        ProcessControl::Arc { schedule } => (
            format!("$OUT[{schedule}]=TRUE"),
            format!("$OUT[{schedule}]=FALSE"),
        ),
        ProcessControl::Custom { start, end } => (start.clone(), end.clone()),
    }
}

/// The speeds of a timed `LIN` (module doc, "Torch-carried cell,
/// positioner turning").
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TimedSegment {
    /// The segment's planned time (s): the length of the path it deposits
    /// over the part ([`deposited_length_mm`](crate::program::deposited_length_mm))
    /// / the planned speed.
    pub time_s: f64,
    /// `$VEL.CP` (mm/s; written in m/s) making the TCP's travel in the robot
    /// base frame take `time_s` (at least 0.001 mm/s).
    pub vel_cp_mm_s: f64,
    /// `$VEL_EXTAX[1]`, `$VEL_EXTAX[2]` (% of the positioner axes' maximum
    /// speeds, at most 100) making each axis's turn take `time_s`; `None`
    /// for an axis that does not move or has no finite maximum speed.
    pub vel_extax_percent: [Option<f64>; 2],
}

/// The speeds of the `LIN` into point `i` when it must be timed: in a
/// torch-carried cell outside the fixed-tool mode, where the positioner
/// moves ([`positioner_moves`]); `None` elsewhere (the planned speed is the
/// TCP's: `$VEL.CP` = the planned speed).
pub fn timed_segment(program: &Program, opts: &KukaOptions, i: usize) -> Option<TimedSegment> {
    let CellLayout::TorchCarried(c) = &program.cell else {
        return None;
    };
    if opts.uses_external_tcp(&program.cell)
        || opts.coordinated(&program.cell)
        || !positioner_moves(program, i)
    {
        return None;
    }
    let start = move_start(program, i)?;
    let (p, a) = (&program.points[i], &program.points[start]);
    // over the path it deposits: the controller interpolates in the robot
    // base frame here, the part turning under the TCP
    let time_s = crate::program::deposited_length_mm(program, i, false) / p.speed_mm_s;
    let robot = &c.robot;
    let tool = held_tool(&program.cell, opts.flange_from_tool);
    let tcp =
        |q: &Joints| crate::math::Point3::from((robot.flange_pose(q) * tool).translation.vector);
    // a circular move's TCP runs on the arc through its via
    let tcp_mm = if start + 2 == i {
        let via = &program.points[i - 1].joints;
        crate::program::compress::arc_length(&tcp(&a.joints), &tcp(via), &tcp(&p.joints))
    } else {
        (tcp(&p.joints) - tcp(&a.joints)).norm()
    };
    let (qp, qa) = (p.positioner?, a.positioner?);
    let vel_extax_percent = std::array::from_fn(|n| {
        let max = c.positioner.max_speed_rad_s[n];
        let turn = (qp[n] - qa[n]).abs();
        (max.is_finite() && turn > 0.0).then(|| (100.0 * turn / time_s / max).clamp(1e-4, 100.0))
    });
    Some(TimedSegment {
        time_s,
        vel_cp_mm_s: (tcp_mm / time_s).max(1e-3),
        vel_extax_percent,
    })
}

/// `$ORI_TYPE` written before the first `CIRC`: the orientation changes
/// continuously from the start to the end orientation (KUKA system
/// software, "Orientation control"), the slerp of
/// [`interpolate`](crate::program::compress::interpolate).
pub const CIRC_ORI_TYPE: &str = "#VAR";
/// `$CIRC_TYPE` written before the first `CIRC`: orientation control
/// relative to the base (`#PATH` would turn it with the circle's tangent),
/// the auxiliary point's orientation ignored.
pub const CIRC_CIRC_TYPE: &str = "#BASE";

/// `$ANOUT[wire_feed_anout]` commanding `wire_feed_mm_s` (module doc,
/// "Wire feed"): the wire feed over the full scale, as written (4
/// decimals, nearest).
pub fn wire_feed_anout(opts: &KukaOptions, wire_feed_mm_s: f64) -> f64 {
    (wire_feed_mm_s / opts.wire_feed_full_scale_mm_s * 1e4).round() / 1e4
}

/// Name of the home position in the `.dat` (an `E6AXIS`).
pub const HOME_NAME: &str = "PHOME";

/// Writes the `.src` of `program`.
///
/// # Errors
/// I/O errors of `w`; an error of kind `Other` wrapping
/// [`ProgramError::VendorMismatch`] when the cell's robot is not a KUKA arm.
pub fn write_src(w: &mut dyn Write, program: &Program, opts: &KukaOptions) -> std::io::Result<()> {
    check_vendor(&program.cell, Vendor::Kuka, EMITTER).map_err(std::io::Error::other)?;
    let (on, off) = switch_statements(opts);
    let arc = opts.arc_process();
    writeln!(w, "&ACCESS RVP")?;
    writeln!(w, "&REL 1")?;
    writeln!(w, "DEF {}( )", program.name)?;
    writeln!(
        w,
        "  ; waam-slicer: {}, {} points, {} beads",
        ascii_comment(program.cell.name()),
        program.points.len(),
        program.num_beads()
    )?;
    if arc {
        // the message of a failed ignition (KSS 8 Set_KrlMsg)
        write_message_decls(w)?;
    }
    writeln!(w, "  ;FOLD INI")?;
    writeln!(
        w,
        "  GLOBAL INTERRUPT DECL 3 WHEN $STOPMESS==TRUE DO IR_STOPM ( )"
    )?;
    writeln!(w, "  INTERRUPT ON 3")?;
    writeln!(w, "  BAS (#INITMOV,0 )")?;
    writeln!(w, "  ;ENDFOLD")?;
    writeln!(w, "  $BWDSTART = FALSE")?;
    // BAS sets $TOOL and $LOAD (TOOL_DATA[n], LOAD_DATA[n]), and $BASE;
    // the frames the positions assume are then stated explicitly
    writeln!(w, "  BAS (#TOOL,{})", opts.tool)?;
    writeln!(w, "  BAS (#BASE,{})", opts.base)?;
    let (_, tool) = opts.frames(&program.cell);
    if opts.uses_external_tcp(&program.cell) {
        writeln!(
            w,
            "  ; external TCP: the tool is the part on the flange, the base the fixed torch (z towards the part)"
        )?;
    } else if matches!(program.cell, CellLayout::TorchCarried(_)) && opts.flange_from_tool.is_none()
    {
        writeln!(
            w,
            "  ; the tool is the torch, +Z along the wire out of the torch (set $TOOL_DIRECTION = #Z for tool-frame weaving and jogging)"
        )?;
    }
    writeln!(w, "  $TOOL = {}", frame_literal(&tool))?;
    match opts.stated_base(&program.cell) {
        StatedBase::Fixed(base) => writeln!(w, "  $BASE = {}", frame_literal(&base))?,
        StatedBase::Coupled { machine, offset } => {
            writeln!(
                w,
                "  ; positioner math-coupled: the base is the part on the positioner, $VEL.CP the speed over it"
            )?;
            writeln!(
                w,
                "  $BASE = EK (MACHINE_DEF[{machine}].ROOT, MACHINE_DEF[{machine}].MECH_TYPE, {})",
                frame_literal(&offset)
            )?;
        }
    }
    if opts.uses_external_tcp(&program.cell) {
        writeln!(w, "  $IPO_MODE = #TCP")?;
    } else {
        writeln!(w, "  $IPO_MODE = #BASE")?;
    }
    if program.points.iter().any(|p| p.via) {
        // the orientation on a circle: from start to end, the auxiliary
        // point's ignored, relative to the base (the checker's model)
        writeln!(w, "  $ORI_TYPE = {CIRC_ORI_TYPE}")?;
        writeln!(w, "  $CIRC_TYPE = {CIRC_CIRC_TYPE}")?;
    }
    writeln!(w, "  $APO.CDIS = {}", Mm(opts.cdis_mm))?;
    writeln!(w, "  BAS (#VEL_PTP,{} )", opts.ptp_percent)?;
    if arc {
        writeln!(
            w,
            "  ; arc-loss supervision: interrupt {} fires when IN {} (arc established) goes off; on only in the beads",
            opts.arc_loss_interrupt, opts.arc_ok_input
        )?;
        writeln!(
            w,
            "  INTERRUPT DECL {} WHEN $IN[{}]==FALSE DO {ARC_LOST_HANDLER}( )",
            opts.arc_loss_interrupt, opts.arc_ok_input
        )?;
    }
    // external-axis speeds (%) written since the last PTP speed setting
    let mut extax: [Option<f64>; 2] = [None; 2];
    // before a PTP after timed moves: the PTP speeds again (BAS sets the
    // external axes' speeds too)
    let restore_ptp = |w: &mut dyn Write, extax: &mut [Option<f64>; 2]| -> std::io::Result<()> {
        if extax.iter().any(Option::is_some) {
            writeln!(w, "  BAS (#VEL_PTP,{} )", opts.ptp_percent)?;
            *extax = [None; 2];
        }
        Ok(())
    };
    let mut vel: Option<f64> = None;
    let mut set_vel = |w: &mut dyn Write, mm_s: f64| -> std::io::Result<()> {
        // m/s, rounded down to the written 6 decimals: never faster than
        // planned
        let v = floor_to(mm_s / 1000.0, 6).max(1e-6);
        if vel != Some(v) {
            writeln!(w, "  $VEL.CP = {}", crate::program::fmt::Fixed::new(v, 6))?;
            vel = Some(v);
        }
        Ok(())
    };
    if program.home.is_some() {
        writeln!(w, "  ; home, arc off")?;
        writeln!(w, "  PTP {HOME_NAME}")?;
    }
    let mut bead = 0usize;
    // the wire feed command as last written (arc process)
    let mut anout: Option<f64> = None;
    let channel = opts.wire_feed_anout;
    for (i, p) in program.points.iter().enumerate() {
        let name = format!("P{}", i + 1);
        let prev = i.checked_sub(1).map(|k| &program.points[k]);
        if opens_bead(prev.map(|q| q.arc), p.arc) {
            if let Some(setup) = program.bead_setup.get(bead) {
                write_bead_setup(w, setup)?;
            }
            bead += 1;
        }
        match p.arc {
            ArcFlag::Approach | ArcFlag::Transit => {
                let what = if p.arc == ArcFlag::Approach {
                    "approach, arc off"
                } else {
                    "arc-off transit via point"
                };
                writeln!(w, "  ; bead {} (layer {}): {what}", p.bead_label(), p.layer)?;
                restore_ptp(w, &mut extax)?;
                writeln!(w, "  PTP {name}")?;
            }
            ArcFlag::Start => {
                match prev {
                    Some(a) if a.arc == ArcFlag::Approach => {
                        set_vel(w, a.speed_mm_s)?;
                        writeln!(w, "  LIN {name}")?;
                    }
                    _ => {
                        writeln!(
                            w,
                            "  ; bead {} (layer {}), arc off",
                            p.bead_label(),
                            p.layer
                        )?;
                        restore_ptp(w, &mut extax)?;
                        writeln!(w, "  PTP {name}")?;
                    }
                }
                if arc {
                    let a = wire_feed_anout(opts, p.wire_feed_mm_s);
                    writeln!(
                        w,
                        "  ; wire feed {} mm/s (power source's analog command, full scale {} mm/s)",
                        Fixed::new(p.wire_feed_mm_s, 2),
                        Fixed::new(opts.wire_feed_full_scale_mm_s, 2)
                    )?;
                    writeln!(w, "  $ANOUT[{channel}] = {}", Fixed::new(a, 4))?;
                    anout = Some(a);
                    write_ignition(w, opts, &on, &off, p.layer)?;
                }
            }
            // a via is written with the circular move it is the via of
            ArcFlag::On if p.via => continue,
            ArcFlag::On | ArcFlag::End => match timed_segment(program, opts, i) {
                Some(t) => {
                    set_vel(w, t.vel_cp_mm_s)?;
                    for (n, pct) in t.vel_extax_percent.iter().enumerate() {
                        if let Some(pct) = pct {
                            if extax[n] != Some(*pct) {
                                writeln!(
                                    w,
                                    "  $VEL_EXTAX[{}] = {}",
                                    n + 1,
                                    Fixed::new(floor_to(*pct, 4).max(1e-4), 4)
                                )?;
                                extax[n] = Some(*pct);
                            }
                        }
                    }
                }
                None => set_vel(w, p.speed_mm_s)?,
            },
            ArcFlag::Retract => {}
        }
        match p.arc {
            ArcFlag::Approach | ArcFlag::Start | ArcFlag::Transit => {}
            ArcFlag::On | ArcFlag::End => {
                let start = move_start(program, i).map(|k| &program.points[k]);
                if !arc && start.is_some_and(|q| q.arc == ArcFlag::Start) {
                    writeln!(w, "  {}", trigger_line(0, &on))?;
                }
                // the wire feed changes from the move's start on
                let a = wire_feed_anout(opts, p.wire_feed_mm_s);
                if arc && anout != Some(a) {
                    writeln!(
                        w,
                        "  {}",
                        trigger_line(0, &format!("$ANOUT[{channel}]={}", Fixed::new(a, 4)))
                    )?;
                    anout = Some(a);
                }
                // `CIRC aux, end` through the via written just before
                let mv = match prev {
                    Some(v) if v.via => format!("CIRC P{}, {name}", i),
                    _ => format!("LIN {name}"),
                };
                if p.arc == ArcFlag::End {
                    if !arc {
                        writeln!(w, "  {}", trigger_line(1, &off))?;
                    }
                    writeln!(w, "  {mv}")?;
                    if arc {
                        write_arc_end(w, opts, &off)?;
                    }
                } else {
                    writeln!(w, "  {mv} C_DIS")?;
                }
            }
            ArcFlag::Retract => {
                set_vel(w, p.speed_mm_s)?;
                writeln!(w, "  LIN {name}")?;
            }
        }
    }
    if program.home.is_some() {
        writeln!(w, "  ; home, arc off")?;
        restore_ptp(w, &mut extax)?;
        writeln!(w, "  PTP {HOME_NAME}")?;
    }
    writeln!(w, "END")?;
    if arc {
        write_arc_lost_handler(w, opts, &on, &off)?;
    }
    Ok(())
}

/// Seconds as written in `WAIT SEC` (3 decimals).
fn sec(s: f64) -> Fixed {
    Fixed::new(s, 3)
}

/// What happens before a bead: payload, dwell, interpass wait (module doc).
fn write_bead_setup(w: &mut dyn Write, setup: &BeadSetup) -> std::io::Result<()> {
    if let Some(load) = &setup.payload {
        writeln!(
            w,
            "  ; payload: substrate, fixture and the metal deposited so far (kg; CoG mm, flange frame; J of a point mass)"
        )?;
        writeln!(w, "  $LOAD.M = {}", Fixed::new(load.mass_kg, 3))?;
        let c = load.cog_mm;
        writeln!(
            w,
            "  $LOAD.CM = {{X {},Y {},Z {},A 0.0,B 0.0,C 0.0}}",
            Mm(c.x),
            Mm(c.y),
            Mm(c.z)
        )?;
        writeln!(w, "  $LOAD.J = {{X 0.0,Y 0.0,Z 0.0}}")?;
    }
    if setup.dwell_s > 0.0 {
        writeln!(w, "  ; interlayer dwell")?;
        writeln!(w, "  WAIT SEC {}", sec(setup.dwell_s))?;
    }
    if let Some(n) = setup.wait_input {
        writeln!(w, "  ; interpass temperature reached")?;
        writeln!(w, "  WAIT FOR $IN[{n}]")?;
    }
    Ok(())
}

/// Arc on at a bead's first point (the robot stands there, exact stop)
/// with the ignition handshake ([`write_handshake`]), then the arc-loss
/// interrupt armed: the arc is established, so the interrupt fires on its
/// loss (an edge).
fn write_ignition(
    w: &mut dyn Write,
    opts: &KukaOptions,
    on: &str,
    off: &str,
    layer: usize,
) -> std::io::Result<()> {
    writeln!(
        w,
        "  ; arc on, then wait at most {} s for the arc (IN {}); without it: arc off, message, HALT, and the start tries again",
        sec(opts.ignition_timeout_s),
        opts.arc_ok_input
    )?;
    write_handshake(w, opts, on, off, "  ", &format!("arc on, layer {layer}"))?;
    writeln!(
        w,
        "  ; arc established: arc-loss supervision on (interrupt {})",
        opts.arc_loss_interrupt
    )?;
    writeln!(w, "  INTERRUPT ON {}", opts.arc_loss_interrupt)?;
    Ok(())
}

/// The ignition handshake at `indent`, a `LOOP` left only with the arc
/// established: arc on, `$TIMER[t]` set to minus the timeout (ms) and
/// started, `WAIT FOR $IN[n] OR $TIMER_FLAG[t]` (KRL's `WAIT FOR` has no
/// timeout; the flag turns on when the timer reaches 0), `EXIT` if the
/// input is on; else arc off, a message ("No arc … after `after`") and
/// `HALT`, and the operator's start tries again.
fn write_handshake(
    w: &mut dyn Write,
    opts: &KukaOptions,
    on: &str,
    off: &str,
    indent: &str,
    after: &str,
) -> std::io::Result<()> {
    let (t, n) = (opts.ignition_timer, opts.arc_ok_input);
    let ms = (opts.ignition_timeout_s * 1000.0).round() as i64;
    writeln!(w, "{indent}LOOP")?;
    writeln!(w, "{indent}  {on}")?;
    writeln!(w, "{indent}  $TIMER_STOP[{t}] = TRUE")?;
    writeln!(w, "{indent}  $TIMER[{t}] = -{ms}")?;
    writeln!(w, "{indent}  $TIMER_STOP[{t}] = FALSE")?;
    writeln!(w, "{indent}  WAIT FOR $IN[{n}] OR $TIMER_FLAG[{t}]")?;
    writeln!(w, "{indent}  $TIMER_STOP[{t}] = TRUE")?;
    writeln!(w, "{indent}  IF $IN[{n}] THEN")?;
    writeln!(w, "{indent}    EXIT")?;
    writeln!(w, "{indent}  ENDIF")?;
    writeln!(w, "{indent}  {off}")?;
    write_message(
        w,
        &format!("{indent}  "),
        1,
        &format!(
            "No arc: IN {n} off {} s after {after}",
            sec(opts.ignition_timeout_s)
        ),
    )?;
    writeln!(w, "{indent}  HALT")?;
    writeln!(w, "{indent}ENDLOOP")?;
    Ok(())
}

/// A message the operator acknowledges (`Set_KrlMsg(#QUIT, …)`, KSS 8)
/// with number `nr`, in the routine's `WAAM_MSG`/`WAAM_PAR`/`WAAM_OPT`/
/// `WAAM_H` ([`write_message_decls`]). KRL's `MSG_TXT[]` holds 80
/// characters.
fn write_message(w: &mut dyn Write, indent: &str, nr: u32, text: &str) -> std::io::Result<()> {
    debug_assert!(text.len() <= 80, "{text}");
    writeln!(
        w,
        "{indent}WAAM_MSG = {{MODUL[] \"WAAM\",NR {nr},MSG_TXT[] \"{text}\"}}"
    )?;
    writeln!(
        w,
        "{indent}WAAM_OPT = {{VL_STOP TRUE,CLEAR_P_RESET TRUE,CLEAR_P_SAW FALSE,LOG_TO_DB TRUE}}"
    )?;
    writeln!(
        w,
        "{indent}WAAM_H = SET_KRLMSG(#QUIT,WAAM_MSG,WAAM_PAR[],WAAM_OPT)"
    )?;
    Ok(())
}

/// The declarations [`write_message`] uses, at the top of a routine.
fn write_message_decls(w: &mut dyn Write) -> std::io::Result<()> {
    writeln!(w, "  DECL KRLMSG_T WAAM_MSG")?;
    writeln!(w, "  DECL KRLMSGPAR_T WAAM_PAR[3]")?;
    writeln!(w, "  DECL KRLMSGOPT_T WAAM_OPT")?;
    writeln!(w, "  DECL INT WAAM_H")?;
    Ok(())
}

/// At a bead's last point (exact stop): crater fill with the arc on (a
/// `WAIT SEC 0.000` without one: an advance-run stop, so that what follows
/// runs when the robot stands at the last point), the arc-loss interrupt
/// off, arc off, burn-back wait.
fn write_arc_end(w: &mut dyn Write, opts: &KukaOptions, off: &str) -> std::io::Result<()> {
    if opts.crater_fill_s > 0.0 {
        writeln!(w, "  ; crater fill, arc on")?;
    } else {
        writeln!(
            w,
            "  ; advance-run stop: the supervision goes off at the bead's last point"
        )?;
    }
    writeln!(w, "  WAIT SEC {}", sec(opts.crater_fill_s))?;
    writeln!(
        w,
        "  ; arc-loss supervision off (interrupt {}), then arc off",
        opts.arc_loss_interrupt
    )?;
    writeln!(w, "  INTERRUPT OFF {}", opts.arc_loss_interrupt)?;
    write_arc_off(w, opts, off, "  ")
}

/// Arc off, then the burn-back wait: the end of a bead and of the arc-loss
/// handler.
fn write_arc_off(
    w: &mut dyn Write,
    opts: &KukaOptions,
    off: &str,
    indent: &str,
) -> std::io::Result<()> {
    writeln!(w, "{indent}{off}")?;
    if opts.burn_back_s > 0.0 {
        writeln!(w, "{indent}; burn-back")?;
        writeln!(w, "{indent}WAIT SEC {}", sec(opts.burn_back_s))?;
    }
    Ok(())
}

/// The arc-loss interrupt routine ([`ARC_LOST_HANDLER`], a local `DEF`
/// after the main routine): interrupt off, `BRAKE F`, arc off as at a
/// bead's end, a message, then per [`KukaOptions::arc_loss`] an endless
/// `HALT` (abort) or `HALT`, the ignition handshake and the interrupt
/// re-armed (reignite). Module doc, "Arc supervision".
fn write_arc_lost_handler(
    w: &mut dyn Write,
    opts: &KukaOptions,
    on: &str,
    off: &str,
) -> std::io::Result<()> {
    let (p, n) = (opts.arc_loss_interrupt, opts.arc_ok_input);
    writeln!(w)?;
    writeln!(w, "DEF {ARC_LOST_HANDLER}( )")?;
    writeln!(
        w,
        "  ; arc lost in a bead (interrupt {p}: IN {n} off): stop on the path, arc off; the bead never goes on with the arc off"
    )?;
    write_message_decls(w)?;
    writeln!(w, "  INTERRUPT OFF {p}")?;
    writeln!(w, "  BRAKE F")?;
    write_arc_off(w, opts, off, "  ")?;
    match opts.arc_loss {
        ArcLoss::Abort => {
            write_message(
                w,
                "  ",
                2,
                &format!("Arc lost (IN {n} off) in a bead: layer incomplete, cancel the program"),
            )?;
            writeln!(w, "  ; abort: the start never leaves this routine")?;
            writeln!(w, "  LOOP")?;
            writeln!(w, "    HALT")?;
            writeln!(w, "  ENDLOOP")?;
        }
        ArcLoss::Reignite => {
            write_message(
                w,
                "  ",
                2,
                &format!(
                    "Arc lost (IN {n} off) in a bead: start re-ignites here, the bead goes on"
                ),
            )?;
            writeln!(w, "  HALT")?;
            writeln!(
                w,
                "  ; re-ignite where the robot stopped: arc on, then wait at most {} s for the arc (IN {n}); without it: arc off, message, HALT, and the start tries again",
                sec(opts.ignition_timeout_s)
            )?;
            write_handshake(w, opts, on, off, "  ", "re-ignition")?;
            writeln!(
                w,
                "  ; arc established again: supervision on, the bead goes on from here"
            )?;
            writeln!(w, "  INTERRUPT ON {p}")?;
        }
    }
    writeln!(w, "END")?;
    Ok(())
}

/// Writes the `.dat` of `program`.
///
/// # Errors
/// I/O errors of `w`; an error of kind `Other` wrapping
/// [`ProgramError::VendorMismatch`] when the cell's robot is not a KUKA arm.
pub fn write_dat(w: &mut dyn Write, program: &Program, opts: &KukaOptions) -> std::io::Result<()> {
    check_vendor(&program.cell, Vendor::Kuka, EMITTER).map_err(std::io::Error::other)?;
    let robot = program.cell.robot();
    let (_, tool) = opts.frames(&program.cell);
    // An endless turn written modulo 360° (the controller's infinitely
    // rotating axis takes the shortest way, at most 180° a motion).
    let modulo = crate::program::pose::turn_modulo(&program.cell);
    let ext_of = |q: Option<[f64; 2]>| {
        let mut e = q.unwrap_or([0.0; 2]).map(f64::to_degrees);
        if modulo {
            e[1] = modulo_180(e[1]);
        }
        format!(
            "E1 {},E2 {},E3 0.0,E4 0.0,E5 0.0,E6 0.0",
            Deg(e[0]),
            Deg(e[1])
        )
    };
    let axis = |q: &Joints| {
        let a = q.map(f64::to_degrees);
        format!(
            "A1 {},A2 {},A3 {},A4 {},A5 {},A6 {}",
            Deg(a[0]),
            Deg(a[1]),
            Deg(a[2]),
            Deg(a[3]),
            Deg(a[4]),
            Deg(a[5])
        )
    };
    writeln!(w, "&ACCESS RVP")?;
    writeln!(w, "&REL 1")?;
    writeln!(w, "DEFDAT {}", program.name)?;
    if let Some(h) = &program.home {
        writeln!(
            w,
            "  DECL E6AXIS {HOME_NAME}={{{},{}}}",
            axis(&h.joints),
            ext_of(h.positioner)
        )?;
    }
    for (i, p) in program.points.iter().enumerate() {
        let ext = ext_of(p.positioner);
        let user_from_base = opts.base_at(&program.cell, p.positioner).inverse();
        match (opts.positions, joint_move_target(program, i)) {
            (PositionMode::Joint, true) => {
                writeln!(w, "  DECL E6AXIS P{}={{{},{ext}}}", i + 1, axis(&p.joints))?;
            }
            (PositionMode::Cartesian, _) | (PositionMode::Joint, false) => {
                let pose = user_from_base * robot.flange_pose(&p.joints) * tool;
                let t = pose.translation.vector;
                let abc = KukaAbc::from_rotation(&pose.rotation.to_rotation_matrix()).to_degrees();
                writeln!(
                    w,
                    "  DECL E6POS P{}={{X {},Y {},Z {},A {},B {},C {},S {},T {},{ext}}}",
                    i + 1,
                    Mm(t.x),
                    Mm(t.y),
                    Mm(t.z),
                    Deg(abc[0]),
                    Deg(abc[1]),
                    Deg(abc[2]),
                    status(robot, &p.joints),
                    turn(&p.joints)
                )?;
            }
        }
    }
    writeln!(w, "ENDDAT")?;
    Ok(())
}

/// The `.src` and `.dat` files of `program`: one pair when its bytes fit
/// [`KukaOptions::max_file_bytes`], else one pair per group of whole beads,
/// `NAME_P01`, `NAME_P02`, … in the order the cell runs them
/// ([`split::split_to_budget`](crate::program::split::split_to_budget)).
///
/// # Errors
/// [`ProgramError::InvalidOptions`] for bad options or a bad name (or one
/// longer than [`KRL_NAME_MAX`], group suffix included);
/// [`ProgramError::OverBudget`] for a bead whose program alone does not
/// fit `max_file_bytes`; [`ProgramError::VendorMismatch`] when the cell's
/// robot is not a KUKA arm.
pub fn kuka_files(program: &Program, opts: &KukaOptions) -> Result<Vec<EmittedFile>, ProgramError> {
    let size = |g: &Program| -> Result<usize, ProgramError> {
        Ok(kuka_pair(g, opts)?.iter().map(|f| f.text.len()).sum())
    };
    let parts = split_to_budget(program, &Kuka::budget(opts), size)?;
    let mut out = Vec::with_capacity(2 * parts.len());
    for part in &parts {
        out.extend(kuka_pair(part, opts)?);
    }
    Ok(out)
}

/// The `.src` and `.dat` of `program` as one KRL program.
fn kuka_pair(program: &Program, opts: &KukaOptions) -> Result<Vec<EmittedFile>, ProgramError> {
    check_vendor(&program.cell, Vendor::Kuka, EMITTER)?;
    program.check_finite()?;
    opts.validate()?;
    check_name(&program.name)?;
    if program.name.len() > KRL_NAME_MAX {
        return Err(ProgramError::InvalidOptions {
            field: "name",
            value: program.name.clone(),
            reason: "KRL names (DEF, DEFDAT, file name) have at most 24 characters",
        });
    }
    if let Some(p) = program
        .bead_points()
        .find(|p| opts.arc_process() && p.wire_feed_mm_s > opts.wire_feed_full_scale_mm_s)
    {
        return Err(ProgramError::InvalidOptions {
            field: "wire_feed_full_scale_mm_s",
            value: format!(
                "{} (layer {}, point {}: wire feed {} mm/s)",
                opts.wire_feed_full_scale_mm_s, p.layer, p.point, p.wire_feed_mm_s
            ),
            reason: "a bead's wire feed is above the analog command's full scale ($ANOUT <= 1)",
        });
    }
    if opts.arc_process() && program.name.eq_ignore_ascii_case(ARC_LOST_HANDLER) {
        return Err(ProgramError::InvalidOptions {
            field: "name",
            value: program.name.clone(),
            reason: "taken by the arc-loss interrupt routine, a local DEF in the same .src",
        });
    }
    Ok(vec![
        EmittedFile {
            name: format!("{}.src", program.name),
            text: render(|w| write_src(w, program, opts))?,
        },
        EmittedFile {
            name: format!("{}.dat", program.name),
            text: render(|w| write_dat(w, program, opts))?,
        },
    ])
}

/// `deg` in (−180°, 180°], the value an infinitely rotating KUKA axis is
/// written with.
pub fn modulo_180(deg: f64) -> f64 {
    let r = deg.rem_euclid(360.0);
    if r > 180.0 {
        r - 360.0
    } else {
        r
    }
}
