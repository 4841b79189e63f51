//! ABB modules as [`DecodedStep`]s: the module read by
//! [`parse_mod`](crate::program::abb::read::parse_mod), each
//! `robtarget` decoded with its `confdata` in the file's own frames (a
//! fixed, robot-held or positioner-coordinated work object), every
//! identifier the module uses checked to be declared in it (or to be the
//! controller data named in the options, or RobotWare's predefined `fine`,
//! `z<n>`, `load0`), ArcWare's weld speed taken from the `welddata`, and
//! `WaitTime`, `WaitDI` and `GripLoad` read as waits and payloads. The
//! module's names are checked (one global routine, named
//! after the program of `MODULE MOD_<program>`, every data `LOCAL`), the
//! positioner's unit active for every motion in the torch-carried cell
//! (`ActUnit` before the first, `DeactUnit` after the last), and the
//! `seamdata` gas times against the options.

use std::collections::HashMap;
use std::f64::consts::TAU;

use crate::math::{Isometry3, Point3};
use crate::program::abb::read::{RapidModule, RapidOp, RapidTarget, RapidTargetValue};
use crate::program::abb::AbbOptions;
use crate::program::MoveKind;
use crate::program::PlannedPoint;
use crate::program::ProcessControl;
use crate::robot::{CellLayout, Configuration, Joints};

use crate::program::validate::ProblemKind;
use crate::program::validate::{arm_of, wrist_of_j5};
use crate::program::validate::{
    decode_pose, push, DecodedStep, Motion, MotionSpeed, ValidationReport, WireFeed,
};

mod declarations;

use declarations::{check_declared, check_gas_times, check_motion_args, check_scope, Decls};

/// The value of `q` (its solution in `(-π, π]`) shifted by whole turns to
/// lie in ABB quadrant `cf` (`floor(q / 90°)`), `None` if more than 1e-6 rad
/// away from it.
fn abb_quadrant(q: f64, cf: i32) -> Option<f64> {
    let quarter = std::f64::consts::FRAC_PI_2;
    let centre = (cf as f64 + 0.5) * quarter;
    let v = q + TAU * ((centre - q) / TAU).round();
    let lo = cf as f64 * quarter;
    (v >= lo - 1e-6 && v <= lo + quarter + 1e-6).then_some(v)
}

/// The frames of the file: its tool and work object.
#[derive(Debug, Clone, Copy)]
enum FileFrames {
    /// Robot-held tool over a fixed work object.
    Held {
        flange_from_tool: Isometry3,
        base_from_work: Isometry3,
    },
    /// Robot-held tool over a work object moved by the positioner: the
    /// object frame is `base_from_positioner · positioner_from_table(q) ·
    /// oframe` at the positioner's joints `q`.
    Coordinated {
        flange_from_tool: Isometry3,
        oframe: Isometry3,
    },
    /// Stationary tool, robot-held work object.
    Stationary {
        base_from_tool: Isometry3,
        flange_from_work: Isometry3,
    },
}

impl FileFrames {
    /// `tooldata`/`wobjdata` as a [`crate::program::frames::ToolFrames`] at
    /// positioner joints `qp` (`None` when a coordinated work object has
    /// no positioner joints or no positioner).
    fn at(
        &self,
        cell: &CellLayout,
        qp: Option<[f64; 2]>,
    ) -> Option<crate::program::abb::AbbFrames> {
        use crate::program::abb::AbbFrames;
        Some(match *self {
            FileFrames::Held {
                flange_from_tool,
                base_from_work,
            } => AbbFrames::Held {
                flange_from_tool,
                base_from_work,
            },
            FileFrames::Coordinated {
                flange_from_tool,
                oframe,
            } => {
                let CellLayout::TorchCarried(c) = cell else {
                    return None;
                };
                AbbFrames::Held {
                    flange_from_tool,
                    base_from_work: c.base_from_positioner
                        * c.positioner.positioner_from_table(&qp?)
                        * oframe,
                }
            }
            FileFrames::Stationary {
                base_from_tool,
                flange_from_work,
            } => AbbFrames::Stationary {
                base_from_tool,
                flange_from_work,
            },
        })
    }

    /// The flange frame from the frame a payload's centre of gravity is
    /// written in (RAPID `loaddata.cog`: the tool frame, or the object frame
    /// of a robot-held work object).
    fn flange_from_payload_frame(&self) -> Isometry3 {
        match *self {
            FileFrames::Held {
                flange_from_tool, ..
            }
            | FileFrames::Coordinated {
                flange_from_tool, ..
            } => flange_from_tool,
            FileFrames::Stationary {
                flange_from_work, ..
            } => flange_from_work,
        }
    }
}

/// The file's frames from its `tooldata` and `wobjdata`, with problems
/// pushed for a combination the controller or the cell cannot run, and for
/// a coordination that differs from the options.
fn file_frames(
    module: &RapidModule,
    cell: &CellLayout,
    opts: &AbbOptions,
    report: &mut ValidationReport,
) -> Option<FileFrames> {
    let file = &module.file;
    let (Some(t), Some(w)) = (&module.tool, &module.wobj) else {
        push(
            report,
            ProblemKind::Declaration,
            file,
            1,
            "no `tooldata` or `wobjdata` declaration".into(),
        );
        return None;
    };
    let frames = match (t.robhold, w.robhold, w.ufprog) {
        (true, false, true) => FileFrames::Held {
            flange_from_tool: t.pose,
            base_from_work: w.pose,
        },
        (true, false, false) => {
            if !matches!(cell, CellLayout::TorchCarried(_)) {
                push(
                    report,
                    ProblemKind::Frame,
                    file,
                    w.line,
                    format!(
                        "{}: moved by mechanical unit \"{}\" (ufprog FALSE), but the cell has no positioner",
                        w.name, w.ufmec
                    ),
                );
                return None;
            }
            if w.ufmec != opts.ufmec {
                push(
                    report,
                    ProblemKind::Options,
                    file,
                    w.line,
                    format!(
                        "{}: ufmec \"{}\", the options give \"{}\"",
                        w.name, w.ufmec, opts.ufmec
                    ),
                );
            }
            FileFrames::Coordinated {
                flange_from_tool: t.pose,
                oframe: w.oframe,
            }
        }
        (false, true, true) => FileFrames::Stationary {
            base_from_tool: t.pose,
            flange_from_work: w.pose,
        },
        (false, true, false) => {
            push(
                report,
                ProblemKind::Frame,
                file,
                w.line,
                format!(
                    "{}: a robot-held work object cannot be moved by another unit (ufprog FALSE)",
                    w.name
                ),
            );
            return None;
        }
        _ => {
            push(
                report,
                ProblemKind::Declaration,
                file,
                t.line,
                format!(
                    "{} and {}: exactly one of them must be held by the robot",
                    t.name, w.name
                ),
            );
            return None;
        }
    };
    let coordinated = matches!(frames, FileFrames::Coordinated { .. });
    let want = opts.coordinated(cell) && !matches!(frames, FileFrames::Stationary { .. });
    if coordinated != want {
        push(
            report,
            ProblemKind::Options,
            file,
            w.line,
            format!(
                "{}: {} the positioner, the options say coordinated = {}",
                w.name,
                if coordinated {
                    "coordinated with"
                } else {
                    "not coordinated with"
                },
                opts.common.coordinated
            ),
        );
    }
    if t.robhold && t.load.is_some_and(|l| l.mass_kg <= 0.0) {
        push(
            report,
            ProblemKind::Declaration,
            file,
            t.line,
            format!(
                "{}: a robot-held tool needs its load (tload mass > 0 kg)",
                t.name
            ),
        );
    }
    Some(frames)
}

/// Validates an ABB module read by
/// [`parse_mod`](crate::program::abb::read::parse_mod) against `cell`
/// with the options `opts`; the frames are the file's own `tooldata` and
/// `wobjdata` (held, coordinated with the positioner, or stationary tool).
/// `robtarget`s are decoded with their `confdata`: `cfx` gives the branch
/// (checked against the cell's), `cf1`, `cf4`, `cf6` the quadrant of J1,
/// J4, J6 (`ConfL \On` makes the controller keep them on linear moves).
/// Arc-on moves run at their `welddata`'s `weld_speed` (checked equal to
/// the `speeddata`'s `v_tcp`); timed moves (`\T`) must not let the
/// positioner outrun the time at their `v_reax`. `WaitTime` becomes a
/// [`DecodedStep::Wait`] with seconds, `WaitDI <interpass_signal>, 1` one with
/// `[program] interpass_input`, `GripLoad` a [`DecodedStep::Payload`] (centre of
/// gravity back in the flange frame). A cell whose robot is not an ABB arm
/// is refused: the report holds that one problem (line 1 of the module).
pub fn validate_abb(
    module: &RapidModule,
    cell: &CellLayout,
    opts: &AbbOptions,
    planned: Option<&[PlannedPoint]>,
) -> ValidationReport {
    use crate::program::abb::Abb;
    use crate::program::contract::Controller;
    Abb::validate(module, cell, opts, planned)
}

/// The [`DecodedStep`]s of an ABB module (motions decoded, process on and off,
/// waits, payloads) in execution order, with the problems of the file
/// itself (declarations, frames, motion arguments) added to `report`;
/// `None` when the options themselves are unusable (the problem is in
/// `report`). The cell's robot must be an ABB arm.
pub(crate) fn abb_steps(
    module: &RapidModule,
    cell: &CellLayout,
    opts: &AbbOptions,
    report: &mut ValidationReport,
) -> Option<Vec<DecodedStep>> {
    let file = &module.file;
    let slots = match opts.positioner_slots() {
        Ok(s) => s,
        Err(e) => {
            push(report, ProblemKind::Options, file, 1, e.to_string());
            return None;
        }
    };
    check_scope(module, report);
    check_gas_times(module, opts, report);
    let mut d = Decoder::new(module, cell, opts, slots, report);
    for ins in &module.instructions {
        let line = ins.line;
        if matches!(ins.op, RapidOp::MoveAbsJ { .. } | RapidOp::Linear { .. }) {
            d.unit.motion(file, line, &opts.ufmec, report);
        }
        match &ins.op {
            RapidOp::ConfL(on) => d.conf_l = *on,
            RapidOp::CirPathMode(mode) => d.cir_path_mode = Some(mode.clone()),
            RapidOp::WaitTime(t) => d.steps.push(DecodedStep::Wait {
                file: file.clone(),
                line,
                seconds: Some(*t),
                input: None,
            }),
            RapidOp::WaitDi { signal, value } => d.wait_di(signal, *value, line, report),
            RapidOp::ActUnit(u) | RapidOp::DeactUnit(u) => {
                let act = matches!(ins.op, RapidOp::ActUnit(_));
                d.unit.switch(act, u, file, line, &opts.ufmec, report);
            }
            RapidOp::GripLoad(name) => d.grip_load(name, line, report),
            RapidOp::Other(s) => d.custom_switch(s, line, report),
            RapidOp::MoveAbsJ { target, zone, tool } => {
                check_motion_args(module, &d.decls, zone, tool, line, report);
                d.move_to(
                    target,
                    MoveKind::Joint,
                    line,
                    MotionSpeed::Joint,
                    None,
                    report,
                );
            }
            RapidOp::Linear { .. } => d.linear(&ins.op, line, report),
        }
    }
    d.unit.end(file, &opts.ufmec, report);
    Some(d.steps)
}

/// What [`abb_steps`] carries from instruction to instruction.
struct Decoder<'a> {
    module: &'a RapidModule,
    cell: &'a CellLayout,
    opts: &'a AbbOptions,
    /// The positioner's two axes among `eax_a` .. `eax_f`.
    slots: [usize; 2],
    /// The file's tool and work object (`None` when unusable, reported).
    frames: Option<FileFrames>,
    decls: Decls<'a>,
    targets: HashMap<&'a str, &'a RapidTarget>,
    /// The custom process's start and end instructions.
    start: Option<(String, String)>,
    /// The arc process's weld schedule.
    schedule: Option<u32>,
    steps: Vec<DecodedStep>,
    /// `ConfL \On` in force.
    conf_l: bool,
    /// The `CirPathMode` switch in force (`None`: RobotWare's default,
    /// `\PathFrame`).
    cir_path_mode: Option<String>,
    /// The positioner joints (rad) of the last motion's end.
    prev_positioner: Option<[f64; 2]>,
    /// The wire feed of the arc-on move being decoded (its `welddata`'s).
    wire_feed: Option<WireFeed>,
    unit: UnitState,
}

impl<'a> Decoder<'a> {
    fn new(
        module: &'a RapidModule,
        cell: &'a CellLayout,
        opts: &'a AbbOptions,
        slots: [usize; 2],
        report: &mut ValidationReport,
    ) -> Self {
        let frames = file_frames(module, cell, opts, report);
        let decls: Decls = module
            .declarations
            .iter()
            .map(|d| (d.name.as_str(), d))
            .collect();
        let targets: HashMap<&str, _> = module
            .targets
            .iter()
            .map(|t| (t.name.as_str(), t))
            .collect();
        let (start, schedule) = match &opts.process {
            ProcessControl::Arc { schedule } => (None, Some(*schedule)),
            ProcessControl::Custom { start, end } => (Some((start.clone(), end.clone())), None),
        };
        Self {
            module,
            cell,
            opts,
            slots,
            frames,
            decls,
            targets,
            start,
            schedule,
            steps: Vec::new(),
            conf_l: false,
            cir_path_mode: None,
            prev_positioner: None,
            wire_feed: None,
            unit: UnitState::new(matches!(cell, CellLayout::TorchCarried(_))),
        }
    }

    /// The module's file name.
    fn file(&self) -> &'a String {
        &self.module.file
    }

    /// `WaitDI signal, value`: the interpass wait (a [`DecodedStep::Wait`] for
    /// `[program] interpass_input`).
    fn wait_di(&mut self, signal: &str, value: u8, line: usize, report: &mut ValidationReport) {
        let (file, opts) = (self.file(), self.opts);
        if signal != opts.interpass_signal {
            push(
                report,
                ProblemKind::Declaration,
                file,
                line,
                format!(
                    "signal {signal} is neither declared in the module nor the options' controller signal (interpass_signal = {})",
                    opts.interpass_signal
                ),
            );
        } else if value != 1 {
            push(
                report,
                ProblemKind::Instruction,
                file,
                line,
                format!("WaitDI {signal}, {value}: the interpass wait waits for 1"),
            );
        } else {
            match opts.common.interpass_input {
                Some(n) => self.steps.push(DecodedStep::Wait {
                    file: file.clone(),
                    line,
                    seconds: None,
                    input: Some(n),
                }),
                None => push(
                    report,
                    ProblemKind::Options,
                    file,
                    line,
                    format!("WaitDI {signal}: the options have no interpass_input"),
                ),
            }
        }
    }

    /// `GripLoad name`: a [`DecodedStep::Payload`], its centre of gravity back in
    /// the flange frame.
    fn grip_load(&mut self, name: &str, line: usize, report: &mut ValidationReport) {
        let module = self.module;
        let load = if name == "load0" {
            Some(crate::program::abb::LOAD0).map(|l| (l.mass_kg, Point3::from(l.cog_mm)))
        } else if check_declared(module, &self.decls, name, "loaddata", false, line, report) {
            module
                .loads
                .iter()
                .find(|(n, _, _)| n == name)
                .map(|(_, _, l)| (l.mass_kg, l.cog_mm))
        } else {
            None
        };
        if let (Some((mass_kg, cog)), Some(f)) = (load, &self.frames) {
            self.steps.push(DecodedStep::Payload {
                file: module.file.clone(),
                line,
                mass_kg,
                cog_mm: f.flange_from_payload_frame() * cog,
            });
        }
    }

    /// Any other instruction: the custom process's start or end.
    fn custom_switch(&mut self, s: &str, line: usize, report: &mut ValidationReport) {
        let file = self.file();
        match &self.start {
            Some((a, _)) if s == a => self.steps.push(DecodedStep::ProcessOn {
                file: file.clone(),
                line,
            }),
            Some((_, b)) if s == b => self.steps.push(DecodedStep::ProcessOff {
                file: file.clone(),
                line,
            }),
            _ => push(
                report,
                ProblemKind::Instruction,
                file,
                line,
                format!("unexpected instruction `{s}`"),
            ),
        }
    }

    /// A linear or circular move (`MoveL`, `MoveC`, ArcWare's `ArcL…`,
    /// `ArcC…`): its targets as motion steps at the speed the controller
    /// runs them, then the arc switched on or off by it.
    fn linear(&mut self, op: &RapidOp, line: usize, report: &mut ValidationReport) {
        let RapidOp::Linear {
            instruction,
            via,
            target,
            speed_mm_s,
            v_reax_deg_s,
            seam,
            weld,
            time_s,
            zone,
            tool,
        } = op
        else {
            return;
        };
        check_motion_args(self.module, &self.decls, zone, tool, line, report);
        let arc = !instruction.starts_with("Move");
        let mut v = *speed_mm_s;
        let mut wire_feed = None;
        if arc {
            let (weld_v, wirefeed_m_min) = self.weld_speed(
                instruction,
                seam.as_deref(),
                weld.as_deref(),
                v,
                line,
                report,
            );
            v = weld_v;
            // the written steps: wirefeed 4 decimals (nearest), weld_speed
            // 4 decimals or \T 3 decimals
            wire_feed = wirefeed_m_min.map(|m| WireFeed {
                mm_s: m * 1000.0 / 60.0,
                tolerance: 0.5e-4 / m + time_s.map_or(1e-4 / v, |t| 1e-3 / t),
            });
        }
        let event = match instruction.as_str() {
            "ArcLStart" => Some(true),
            "ArcLEnd" | "ArcCEnd" => Some(false),
            _ => None,
        };
        let speed = self.linear_speed(*time_s, v, *v_reax_deg_s);
        if via.is_some()
            && self.cir_path_mode.as_deref() != Some(crate::program::abb::CIR_PATH_MODE)
        {
            let mode = self
                .cir_path_mode
                .as_deref()
                .unwrap_or("PathFrame (the default)");
            push(
                report,
                ProblemKind::Frame,
                self.file(),
                line,
                format!(
                    "{instruction} under CirPathMode \\{mode}: the controller reorients the tool otherwise than the checker's start-to-end slerp in the work object's frame (write `CirPathMode \\{}` before the circular moves)",
                    crate::program::abb::CIR_PATH_MODE
                ),
            );
        }
        // a circular move's circle point first, as its own step
        let moves_to = match via {
            Some(c) => vec![(c, MoveKind::Via), (target, MoveKind::Circular)],
            None => vec![(target, MoveKind::Linear)],
        };
        let v_reax_time = time_s.map(|t| (t, *v_reax_deg_s));
        self.wire_feed = wire_feed;
        for (target, kind) in moves_to {
            self.move_to(target, kind, line, speed, v_reax_time, report);
        }
        self.wire_feed = None;
        let file = self.file();
        match event {
            Some(true) => self.steps.push(DecodedStep::ProcessOn {
                file: file.clone(),
                line,
            }),
            Some(false) => self.steps.push(DecodedStep::ProcessOff {
                file: file.clone(),
                line,
            }),
            None => {}
        }
    }

    /// An ArcWare move's `seamdata` and `welddata` checked; the speed
    /// (mm/s) it runs at: the `welddata`'s weld speed, else `v` (the
    /// speeddata's `v_tcp`); and the wire feed (m/min) of an arc-on move
    /// (not `ArcLStart`, which moves with the arc off): the `welddata`'s
    /// `main_arc.wirefeed`, `None` where there is none, a problem then.
    fn weld_speed(
        &self,
        instruction: &str,
        seam: Option<&str>,
        weld: Option<&str>,
        mut v: f64,
        line: usize,
        report: &mut ValidationReport,
    ) -> (f64, Option<f64>) {
        let mut wirefeed = None;
        let (module, file, decls) = (self.module, self.file(), &self.decls);
        if self.start.is_some() {
            push(
                report,
                ProblemKind::Options,
                file,
                line,
                format!("{instruction}: the options give a custom process"),
            );
        }
        if let Some(s) = seam {
            check_declared(module, decls, s, "seamdata", false, line, report);
        }
        let wd = weld.unwrap_or("");
        if check_declared(module, decls, wd, "welddata", false, line, report) {
            let d = module.welds.iter().find(|d| d.name == wd);
            if let (Some(d), Some(sched)) = (d, self.schedule) {
                if d.sched != sched as f64 {
                    push(
                        report,
                        ProblemKind::Options,
                        file,
                        line,
                        format!(
                            "{instruction} with {wd}: schedule {} (main_arc.sched, line {}), the options give {sched}",
                            d.sched, d.line
                        ),
                    );
                }
            }
            // ArcWare runs arc-on moves at weld_speed
            if let (Some(d), true) = (d, instruction != "ArcLStart") {
                if (d.weld_speed_mm_s - v).abs() > 1e-9 {
                    push(
                        report,
                        ProblemKind::Timing,
                        file,
                        line,
                        format!(
                            "{instruction}: {wd}.weld_speed {} mm/s (line {}) differs from the speeddata's v_tcp {v} mm/s",
                            d.weld_speed_mm_s, d.line
                        ),
                    );
                }
                v = d.weld_speed_mm_s;
                if d.wirefeed_m_min > 0.0 {
                    wirefeed = Some(d.wirefeed_m_min);
                } else {
                    push(
                        report,
                        ProblemKind::Feed,
                        file,
                        line,
                        format!(
                            "{instruction}: {wd}.main_arc.wirefeed is {} m/min (line {}): the wire feed is left to the power source, not the planned one",
                            d.wirefeed_m_min, d.line
                        ),
                    );
                }
            }
        }
        (v, wirefeed)
    }

    /// The speed of a linear move at `v` mm/s (or in `time_s` s), its
    /// external axes at most `v_reax_deg_s`, in the frame it holds in.
    fn linear_speed(&self, time_s: Option<f64>, v: f64, v_reax_deg_s: f64) -> MotionSpeed {
        match (time_s, &self.frames) {
            (Some(t), _) => MotionSpeed::Time(t),
            // v_tcp is the speed of the robot-held tool in the world
            (
                None,
                Some(FileFrames::Held {
                    flange_from_tool, ..
                }),
            ) => MotionSpeed::Tcp {
                mm_s: v,
                flange_from_tcp: *flange_from_tool,
                extax_fraction: match self.cell {
                    CellLayout::TorchCarried(c) => [0, 1].map(|n| {
                        let max = c.positioner.max_speed_rad_s[n];
                        if max.is_finite() && max > 0.0 {
                            (v_reax_deg_s.to_radians() / max).min(1.0)
                        } else {
                            1.0
                        }
                    }),
                    CellLayout::PartCarried(_) => [1.0; 2],
                },
            },
            // a stationary tool or a coordinated work object: v_tcp
            // is the torch's speed over the part
            (None, _) => MotionSpeed::Linear(v),
        }
    }

    /// A move of the instruction at `line` to `target` (`kind`) at
    /// `speed`: a motion step, its joints decoded; a `\T` time with its
    /// `v_reax` (s, deg/s) checked against the positioner's turn.
    fn move_to(
        &mut self,
        target: &str,
        kind: MoveKind,
        line: usize,
        speed: MotionSpeed,
        v_reax_time: Option<(f64, f64)>,
        report: &mut ValidationReport,
    ) {
        let file = self.file();
        if kind == MoveKind::Linear && !self.conf_l {
            push(
                report,
                ProblemKind::Configuration,
                file,
                line,
                "linear move without `ConfL \\On`: the controller may change the configuration"
                    .into(),
            );
        }
        let Some(t) = self.targets.get(target).copied() else {
            push(
                report,
                ProblemKind::Declaration,
                file,
                line,
                format!("{target} is not declared"),
            );
            self.prev_positioner = None;
            return;
        };
        let slots = self.slots;
        let positioner = match (t.external[slots[0]], t.external[slots[1]]) {
            (Some(a), Some(b)) => Some([a.to_radians(), b.to_radians()]),
            _ => None,
        };
        // checked over the whole move, at its end (not at a circle point)
        let v_reax_time = v_reax_time.filter(|_| kind != MoveKind::Via);
        if let (Some((time, v_reax)), Some(a), Some(b)) =
            (v_reax_time, positioner, self.prev_positioner)
        {
            // a controller running the move at weld_speed instead of \T
            // is held back by v_reax only
            let turn = (a[0] - b[0]).abs().max((a[1] - b[1]).abs()).to_degrees();
            if turn / v_reax < time - 1e-3 {
                push(
                    report,
                    ProblemKind::Timing,
                    file,
                    line,
                    format!(
                        "v_reax {v_reax} deg/s lets the positioner turn {turn:.4} deg in {:.3} s, less than the \\T time {time} s",
                        turn / v_reax
                    ),
                );
            }
        }
        if kind != MoveKind::Via {
            self.prev_positioner = positioner;
        }
        let (joints, from_cartesian) = match (&t.value, kind) {
            (RapidTargetValue::Joint(a), MoveKind::Joint) => (Some(a.map(f64::to_radians)), false),
            (
                RapidTargetValue::Rob { pose, conf },
                MoveKind::Linear | MoveKind::Via | MoveKind::Circular,
            ) => (
                self.decode_robtarget(t, pose, conf, positioner, report),
                true,
            ),
            _ => {
                push(
                    report,
                    ProblemKind::Declaration,
                    file,
                    line,
                    format!("{target}: wrong target type for this instruction"),
                );
                return;
            }
        };
        self.steps.push(DecodedStep::Motion(Box::new(Motion {
            file: file.clone(),
            line,
            label: t.name.clone(),
            record_file: file.clone(),
            record_line: t.line,
            value_lines: [t.line; 6],
            joints,
            from_cartesian,
            positioner,
            kind,
            speed,
            wire_feed: self.wire_feed,
        })));
    }

    /// The arm joints (rad) of the `robtarget` `t` (`pose` in the file's
    /// work object at the positioner joints `positioner`), its `confdata`
    /// checked against the cell's configuration and giving each of A1,
    /// A4, A6 its quadrant.
    fn decode_robtarget(
        &self,
        t: &RapidTarget,
        pose: &Isometry3,
        conf: &[i32; 4],
        positioner: Option<[f64; 2]>,
        report: &mut ValidationReport,
    ) -> Option<Joints> {
        let (cell, file) = (self.cell, self.file());
        let robot = cell.robot();
        // cfx bit 2: wrist centre behind axis 1; bit 1: behind the
        // lower arm, the elbow joint test (abb::confdata)
        let (side, elbow) = arm_of(conf[3] & 4 != 0, conf[3] & 2 == 0);
        let cfg = Configuration {
            wrist: wrist_of_j5(robot, conf[3] & 1 == 0),
            elbow,
            side,
        };
        if !(0..8).contains(&conf[3]) || cfg != cell.configuration() {
            push(
                report,
                ProblemKind::Configuration,
                file,
                t.line,
                format!(
                    "{}: cfx {} is configuration '{cfg}', not the cell's '{}' (configuration flip)",
                    t.name,
                    conf[3],
                    cell.configuration()
                ),
            );
        }
        let f = self.frames.and_then(|f| {
            let at = f.at(cell, positioner);
            if at.is_none() {
                push(
                    report,
                    ProblemKind::Format,
                    file,
                    t.line,
                    format!(
                        "{}: no positioner values for the coordinated work object",
                        t.name
                    ),
                );
            }
            at
        });
        f.and_then(|f| {
            decode_pose(
                robot,
                &f.flange(pose),
                cfg,
                |j, q| {
                    let cf = match j {
                        0 => conf[0],
                        3 => conf[1],
                        _ => conf[2],
                    };
                    abb_quadrant(q, cf)
                },
                &t.name,
                file,
                t.line,
                report,
            )
        })
    }
}

/// The positioner's mechanical unit along the entry routine: in the
/// torch-carried cell every motion runs with it active (`ActUnit` before
/// the first motion) and it is deactivated after the last (`DeactUnit`).
#[derive(Debug)]
struct UnitState {
    /// The cell has a positioner.
    needed: bool,
    /// Activated and not deactivated since.
    active: bool,
    /// Line of the last `DeactUnit` of the unit, if any.
    deactivated: Option<usize>,
    /// Line of the last motion.
    last_motion: Option<usize>,
    /// A motion with the unit inactive was reported (once).
    reported: bool,
}

impl UnitState {
    fn new(needed: bool) -> Self {
        Self {
            needed,
            active: false,
            deactivated: None,
            last_motion: None,
            reported: false,
        }
    }

    fn motion(&mut self, file: &str, line: usize, unit: &str, report: &mut ValidationReport) {
        self.last_motion = Some(line);
        if self.needed && !self.active && !self.reported {
            self.reported = true;
            let why = match self.deactivated {
                Some(d) => format!("after DeactUnit {unit} (line {d})"),
                None => format!("before ActUnit {unit}"),
            };
            push(
                report,
                ProblemKind::Setup,
                file,
                line,
                format!("motion {why}: the positioner's mechanical unit {unit} is not active"),
            );
        }
    }

    fn switch(
        &mut self,
        act: bool,
        u: &str,
        file: &str,
        line: usize,
        unit: &str,
        report: &mut ValidationReport,
    ) {
        let ins = if act { "ActUnit" } else { "DeactUnit" };
        if !self.needed {
            push(
                report,
                ProblemKind::Instruction,
                file,
                line,
                format!("{ins} {u}: the cell has no positioner"),
            );
        } else if u != unit {
            push(
                report,
                ProblemKind::Options,
                file,
                line,
                format!("{ins} {u}: the options give the positioner's unit ufmec = {unit}"),
            );
        } else {
            self.active = act;
            if !act {
                self.deactivated = Some(line);
            }
        }
    }

    fn end(&self, file: &str, unit: &str, report: &mut ValidationReport) {
        if let (true, true, Some(l)) = (self.needed, self.active, self.last_motion) {
            push(
                report,
                ProblemKind::Setup,
                file,
                l,
                format!("no DeactUnit {unit} after the last motion: the positioner's mechanical unit stays active"),
            );
        }
    }
}
