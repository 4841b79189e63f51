//! Reader of our own KUKA KRL output (`.src` + `.dat`, the subset
//! [`write_src`](crate::program::kuka::write_src) and
//! [`write_dat`](crate::program::kuka::write_dat) write): the `.src`'s main
//! routine and the local subprograms after it (the arc-loss interrupt
//! routine), the `.dat`'s positions. Errors name the file and line; a
//! `.src` routine without `END` or a `.dat` without `ENDDAT` (truncated) is
//! an error.

use crate::program::kuka::is_call;
use crate::program::ProgramError;

/// One `.src` statement.
#[derive(Debug, Clone, PartialEq)]
pub enum KrlOp {
    /// `PTP name`.
    Ptp(String),
    /// `LIN name [C_DIS]`.
    Lin {
        /// Target name.
        target: String,
        /// Blended (`C_DIS`).
        blended: bool,
    },
    /// `CIRC aux, name [C_DIS]`: circular move through the auxiliary
    /// point `aux` to `target`.
    Circ {
        /// Auxiliary (via) point name.
        aux: String,
        /// Target name.
        target: String,
        /// Blended (`C_DIS`).
        blended: bool,
    },
    /// `$VEL.CP = v` (m/s).
    VelCp(f64),
    /// `TRIGGER WHEN DISTANCE=d DELAY=0 DO action [PRIO=p]`.
    Trigger {
        /// 0: at the next motion's start point, 1: at its end point.
        distance: u8,
        /// The statement switched.
        action: String,
        /// `PRIO=p` (required when the action is a subprogram call).
        prio: Option<i32>,
    },
    /// `$TOOL = {X …,Y …,Z …,A …,B …,C …}` (mm, deg).
    ToolFrame([f64; 6]),
    /// `$BASE = {X …,Y …,Z …,A …,B …,C …}` (mm, deg).
    BaseFrame([f64; 6]),
    /// `$BASE = EK (MACHINE_DEF[m].ROOT, MACHINE_DEF[m].MECH_TYPE, {…})`:
    /// the base math-coupled to external kinematic `m`, `offset` (mm, deg)
    /// on its flange.
    BaseEk {
        /// `MACHINE_DEF` index.
        machine: u8,
        /// `[X, Y, Z, A, B, C]` (mm, deg).
        offset: [f64; 6],
    },
    /// `$LOAD.M = m` (kg).
    LoadMass(f64),
    /// `$LOAD.CM = {X …,Y …,Z …,A …,B …,C …}` (mm, deg; flange frame).
    LoadCm([f64; 6]),
    /// `$LOAD.J = {X …,Y …,Z …}` (kg·m²).
    LoadJ([f64; 3]),
    /// `WAIT SEC s` (s).
    WaitSec(f64),
    /// `WAIT FOR $IN[n]`.
    WaitIn(u32),
    /// `WAIT FOR $IN[n] OR $TIMER_FLAG[t]`: an input wait with a timeout.
    WaitInOrTimer {
        /// Input `n`.
        input: u32,
        /// Timer `t`.
        timer: u8,
    },
    /// `$TIMER[t] = v` (ms).
    Timer {
        /// Timer `t`.
        timer: u8,
        /// Value (ms).
        ms: f64,
    },
    /// `$TIMER_STOP[t] = TRUE|FALSE`.
    TimerStop {
        /// Timer `t`.
        timer: u8,
        /// `TRUE`: stopped.
        stop: bool,
    },
    /// `IF NOT $IN[n] THEN`.
    IfNotIn(u32),
    /// `IF $IN[n] THEN`.
    IfIn(u32),
    /// `ENDIF`.
    EndIf,
    /// `HALT`.
    Halt,
    /// `LOOP`: an endless loop, left only by `EXIT`.
    Loop,
    /// `ENDLOOP`.
    EndLoop,
    /// `EXIT`: leaves the innermost loop.
    Exit,
    /// `[GLOBAL] INTERRUPT DECL prio WHEN condition DO handler( )`.
    InterruptDecl {
        /// `GLOBAL`: valid in the callers too.
        global: bool,
        /// Priority (1 the highest).
        prio: u8,
        /// The condition, as written (see [`falling_input`]).
        when: String,
        /// The interrupt routine's name (arguments dropped).
        handler: String,
    },
    /// `INTERRUPT ON|OFF|ENABLE|DISABLE [prio]`.
    Interrupt {
        /// What is done.
        action: InterruptAction,
        /// The priority; `None`: all interrupts.
        prio: Option<u8>,
    },
    /// `BRAKE` (normal ramp) or `BRAKE F` (as fast as possible).
    Brake {
        /// `BRAKE F`.
        fast: bool,
    },
    /// `RESUME`: aborts the interrupted routine's motions.
    Resume,
    /// `$IPO_MODE = #TCP` (`true`) or `#BASE` (`false`).
    IpoTcp(bool),
    /// `$ORI_TYPE = v`: orientation control of CP moves (`#VAR` written).
    OriType(String),
    /// `$CIRC_TYPE = v`: orientation reference of `CIRC` (`#BASE` written).
    CircType(String),
    /// `$VEL_EXTAX[n] = p`: external axis `n` (1-based) at `p` % of its
    /// maximum speed in path motions.
    VelExtax {
        /// Axis `n`, 1-based.
        axis: u8,
        /// Percent.
        percent: f64,
    },
    /// `$ANOUT[n] = v`: analog output `n` (1-based) at `v` (−1 to 1, KRL's
    /// full scale).
    Anout {
        /// Output `n`, 1-based.
        channel: u8,
        /// Value (−1 to 1).
        value: f64,
    },
    /// `BAS (#VEL_PTP,n )`: PTP speeds (robot and external axes) at `n` %.
    VelPtp(f64),
    /// `BAS (#TOOL,n)` or `$TOOL = TOOL_DATA[n]`.
    Tool(u8),
    /// `BAS (#BASE,n)` or `$BASE = BASE_DATA[n]`.
    Base(u8),
    /// Anything else (other `BAS (...)`, `$APO.CDIS = ...`), as written.
    Other(String),
}

/// What `INTERRUPT … [prio]` does to a declared interrupt.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum InterruptAction {
    /// `ON`: the condition is monitored (an edge: it fires when the
    /// condition becomes true).
    On,
    /// `OFF`: not monitored.
    Off,
    /// `ENABLE`: events detected are handled again.
    Enable,
    /// `DISABLE`: events are detected and kept, handled at `ENABLE`.
    Disable,
}

impl InterruptAction {
    /// The KRL keyword (`ON`, `OFF`, `ENABLE`, `DISABLE`).
    pub fn keyword(self) -> &'static str {
        match self {
            Self::On => "ON",
            Self::Off => "OFF",
            Self::Enable => "ENABLE",
            Self::Disable => "DISABLE",
        }
    }
}

/// Input `n` when `when` is `$IN[n]==FALSE` (or `NOT $IN[n]`): the
/// condition of an interrupt that fires when the input goes off.
pub fn falling_input(when: &str) -> Option<u32> {
    let c: String = when.chars().filter(|c| !c.is_whitespace()).collect();
    let input = c
        .strip_suffix("==FALSE")
        .or_else(|| c.strip_prefix("NOT"))?;
    index_of(input, "$IN[").and_then(|n| u32::try_from(n).ok())
}

/// A statement with its `.src` line (1-based).
#[derive(Debug, Clone, PartialEq)]
pub struct KrlStatement {
    /// Line.
    pub line: usize,
    /// Statement.
    pub op: KrlOp,
}

/// A `.dat` position.
#[derive(Debug, Clone, PartialEq)]
pub enum KrlValue {
    /// `E6AXIS`: `A1..A6` (deg).
    Axis([f64; 6]),
    /// `E6POS`: `X Y Z A B C` (mm, deg), Status and Turn.
    Pos {
        /// `[X, Y, Z, A, B, C]` (mm, deg).
        xyzabc: [f64; 6],
        /// `S`.
        status: u8,
        /// `T`.
        turn: u8,
    },
}

/// One `DECL` of the `.dat`.
#[derive(Debug, Clone, PartialEq)]
pub struct KrlPosition {
    /// Name (`P1`).
    pub name: String,
    /// `.dat` line.
    pub line: usize,
    /// The robot part.
    pub value: KrlValue,
    /// `E1`, `E2` (deg).
    pub external: [f64; 2],
}

/// A local subprogram: a `DEF … END` after the main routine's in the same
/// `.src` (the arc-loss interrupt routine).
#[derive(Debug, Clone, PartialEq)]
pub struct KrlRoutine {
    /// `DEF` name.
    pub name: String,
    /// Line of its `DEF`.
    pub line: usize,
    /// Its statements in order (the `DECL`s as [`KrlOp::Other`]).
    pub statements: Vec<KrlStatement>,
}

/// A KRL program as read.
#[derive(Debug, Clone, PartialEq)]
pub struct KrlProgram {
    /// `DEF` name.
    pub name: String,
    /// `.src` file name (for messages).
    pub src_file: String,
    /// `.dat` file name.
    pub dat_file: String,
    /// The main routine's statements in order.
    pub statements: Vec<KrlStatement>,
    /// The local subprograms after the main routine, in order.
    pub routines: Vec<KrlRoutine>,
    /// The `.dat` positions.
    pub positions: Vec<KrlPosition>,
}

/// Parses a `.src` and its `.dat`.
///
/// # Errors
/// [`ProgramError::Read`] naming the file and line: missing `DEF`/`DEFDAT`,
/// bad statement or value, names that differ, and a file ending before its
/// `END`/`ENDDAT`.
pub fn parse_krl(
    src: &str,
    src_file: &str,
    dat: &str,
    dat_file: &str,
) -> Result<KrlProgram, ProgramError> {
    let (name, statements, routines) = parse_src(src, src_file)?;
    let (dat_name, positions) = parse_dat(dat, dat_file)?;
    if !dat_name.eq_ignore_ascii_case(&name) {
        return Err(ProgramError::Read {
            file: dat_file.into(),
            line: 1,
            reason: format!("DEFDAT {dat_name} does not match DEF {name}"),
        });
    }
    Ok(KrlProgram {
        name,
        src_file: src_file.into(),
        dat_file: dat_file.into(),
        statements,
        routines,
        positions,
    })
}

impl KrlProgram {
    /// The local subprogram `name` (any case).
    pub fn routine(&self, name: &str) -> Option<&KrlRoutine> {
        self.routines
            .iter()
            .find(|r| r.name.eq_ignore_ascii_case(name))
    }
}

fn err(file: &str, line: usize, reason: String) -> ProgramError {
    ProgramError::Read {
        file: file.into(),
        line,
        reason,
    }
}

/// The statement part of a line: `;` comments and `&` headers dropped.
fn code(raw: &str) -> &str {
    let l = raw.trim();
    if l.starts_with('&') {
        return "";
    }
    l.split(';').next().unwrap_or("").trim()
}

type Routines = Vec<KrlRoutine>;

/// The main routine's name and statements, and the local subprograms after
/// it.
fn parse_src(
    text: &str,
    file: &str,
) -> Result<(String, Vec<KrlStatement>, Routines), ProgramError> {
    let name_of = |rest: &str| rest.split('(').next().unwrap_or("").trim().to_string();
    let mut blocks = parse_blocks(
        text,
        file,
        ("DEF", "name( )", "END"),
        true,
        name_of,
        |l, n| {
            Ok(KrlStatement {
                line: n,
                op: parse_statement(l)?,
            })
        },
    )?
    .into_iter();
    let (name, _, statements) = blocks.next().expect("parse_blocks gives one block or more");
    let routines = blocks
        .map(|(name, line, statements)| KrlRoutine {
            name,
            line,
            statements,
        })
        .collect();
    Ok((name, statements, routines))
}

/// Reads the `DEF … END` blocks of a `.src` (`many`: local subprograms
/// after the first) or the one `DEFDAT … ENDDAT` of a `.dat`: each header's
/// name (from the text after `open` by `name_of`) and line, then each code
/// line up to `close` through `body`; errors name the file and line (text
/// after the end, a missing header or end).
fn parse_blocks<T>(
    text: &str,
    file: &str,
    (open, header, close): (&str, &str, &str),
    many: bool,
    name_of: impl Fn(&str) -> String,
    body: impl Fn(&str, usize) -> Result<T, String>,
) -> Result<Vec<(String, usize, Vec<T>)>, ProgramError> {
    let mut blocks: Vec<(String, usize, Vec<T>)> = Vec::new();
    // inside a block (its header read, its end not yet)
    let mut open_block = false;
    let mut last = 0;
    for (i, raw) in text.lines().enumerate() {
        let n = i + 1;
        last = n;
        let l = code(raw);
        if l.is_empty() {
            continue;
        }
        if !open_block {
            if !blocks.is_empty() && !many {
                return Err(err(file, n, format!("text after {close}")));
            }
            let rest = l
                .strip_prefix(open)
                .and_then(|r| r.strip_prefix(' '))
                .ok_or_else(|| {
                    if blocks.is_empty() {
                        err(file, n, format!("expected `{open} {header}`, got `{l}`"))
                    } else {
                        err(
                            file,
                            n,
                            format!("text after {close}: expected `{open} {header}` of a local subprogram, got `{l}`"),
                        )
                    }
                })?;
            let nm = name_of(rest);
            if nm.is_empty() {
                return Err(err(file, n, format!("{open} without a name")));
            }
            blocks.push((nm, n, Vec::new()));
            open_block = true;
            continue;
        }
        if l == close {
            open_block = false;
            continue;
        }
        let item = body(l, n).map_err(|r| err(file, n, r))?;
        if let Some(b) = blocks.last_mut() {
            b.2.push(item);
        }
    }
    if blocks.is_empty() {
        return Err(err(file, last.max(1), format!("no {open} (empty file?)")));
    }
    if open_block {
        return Err(err(
            file,
            last,
            format!("file ends without {close} (truncated?)"),
        ));
    }
    Ok(blocks)
}

/// One statement of a routine (`l`, comment stripped): a statement this
/// reader knows by its keyword or the variable it assigns, else
/// [`KrlOp::Other`].
fn parse_statement(l: &str) -> Result<KrlOp, String> {
    let tokens: Vec<&str> = l.split_whitespace().collect();
    match tokens.first().copied() {
        Some("PTP" | "LIN" | "CIRC") => return parse_motion(l, &tokens),
        Some("TRIGGER") => return parse_trigger(l),
        Some("WAIT") => return parse_wait(l),
        Some("HALT") if tokens.len() == 1 => return Ok(KrlOp::Halt),
        Some("ENDIF") if tokens.len() == 1 => return Ok(KrlOp::EndIf),
        Some("LOOP") if tokens.len() == 1 => return Ok(KrlOp::Loop),
        Some("ENDLOOP") if tokens.len() == 1 => return Ok(KrlOp::EndLoop),
        Some("EXIT") if tokens.len() == 1 => return Ok(KrlOp::Exit),
        Some("RESUME") if tokens.len() == 1 => return Ok(KrlOp::Resume),
        Some("BRAKE") => {
            return match tokens.as_slice() {
                [_] => Ok(KrlOp::Brake { fast: false }),
                [_, "F"] => Ok(KrlOp::Brake { fast: true }),
                _ => Err(format!("expected `BRAKE [F]`, got `{l}`")),
            };
        }
        Some("INTERRUPT" | "GLOBAL") => return parse_interrupt(l),
        Some("IF") => {
            if let Some(op) = parse_if_input(l)? {
                return Ok(op);
            }
        }
        Some(b) if b.starts_with("BAS") => {
            if let Some(op) = parse_bas(l)? {
                return Ok(op);
            }
        }
        _ => {}
    }
    if let Some((k, v)) = l.split_once('=') {
        let (k, v) = (k.trim(), v.trim());
        if let Some(op) = parse_setting(k, v)? {
            return Ok(op);
        }
        if let Some(op) = parse_frame_setting(l, k, v)? {
            return Ok(op);
        }
    }
    Ok(KrlOp::Other(l.to_string()))
}

/// `PTP name`, `LIN name [C_DIS]`, `CIRC aux, name [C_DIS]` (`tokens`: `l`
/// split at whitespace).
fn parse_motion(l: &str, tokens: &[&str]) -> Result<KrlOp, String> {
    match tokens.first().copied() {
        Some("PTP") => {
            if tokens.len() != 2 {
                return Err(format!("expected `PTP name`, got `{l}`"));
            }
            Ok(KrlOp::Ptp(tokens[1].to_string()))
        }
        Some("LIN") => match tokens {
            [_, t] => Ok(KrlOp::Lin {
                target: t.to_string(),
                blended: false,
            }),
            [_, t, "C_DIS"] => Ok(KrlOp::Lin {
                target: t.to_string(),
                blended: true,
            }),
            _ => Err(format!("expected `LIN name [C_DIS]`, got `{l}`")),
        },
        _ => {
            let circ = |aux: &str, t: &str, blended| {
                Ok(KrlOp::Circ {
                    aux: aux.to_string(),
                    target: t.to_string(),
                    blended,
                })
            };
            let args: Vec<&str> = l["CIRC".len()..].split(',').map(str::trim).collect();
            match args.as_slice() {
                [aux, rest] if !aux.is_empty() => {
                    match rest.split_whitespace().collect::<Vec<_>>().as_slice() {
                        [t] => circ(aux, t, false),
                        [t, "C_DIS"] => circ(aux, t, true),
                        _ => Err(format!("expected `CIRC aux, name [C_DIS]`, got `{l}`")),
                    }
                }
                _ => Err(format!("expected `CIRC aux, name [C_DIS]`, got `{l}`")),
            }
        }
    }
}

/// `TRIGGER WHEN DISTANCE=d DELAY=0 DO action [PRIO=p]`.
fn parse_trigger(l: &str) -> Result<KrlOp, String> {
    let rest = l
        .strip_prefix("TRIGGER WHEN DISTANCE=")
        .ok_or_else(|| format!("bad TRIGGER `{l}`"))?;
    let (d, rest) = rest
        .split_once(' ')
        .ok_or_else(|| format!("bad TRIGGER `{l}`"))?;
    let distance = match d {
        "0" => 0,
        "1" => 1,
        _ => return Err(format!("TRIGGER DISTANCE={d}: expected 0 or 1")),
    };
    let action = rest
        .trim()
        .strip_prefix("DELAY=0 DO ")
        .ok_or_else(|| format!("bad TRIGGER `{l}`"))?
        .trim();
    // a trailing `PRIO = p` (spaces optional)
    let (action, prio) = match action.rfind("PRIO") {
        Some(k) if action[..k].ends_with(' ') => {
            let v = action[k + 4..].trim_start();
            let v = v
                .strip_prefix('=')
                .map(str::trim)
                .ok_or_else(|| format!("bad PRIO in `{l}`"))?;
            let p: i32 = v.parse().map_err(|_| format!("bad PRIO `{v}` in `{l}`"))?;
            (action[..k].trim_end(), Some(p))
        }
        _ => (action, None),
    };
    Ok(KrlOp::Trigger {
        distance,
        action: action.to_string(),
        prio,
    })
}

/// `$ANOUT[n]` = `v`: the output (1..=32) and the value (−1 to 1); `None`
/// for anything else.
pub fn parse_anout(k: &str, v: &str) -> Option<(u8, f64)> {
    let channel = k
        .trim()
        .strip_prefix("$ANOUT[")?
        .strip_suffix(']')?
        .trim()
        .parse::<u8>()
        .ok()
        .filter(|n| (1..=32).contains(n))?;
    let value: f64 = v
        .trim()
        .parse()
        .ok()
        .filter(|x: &f64| x.is_finite() && (-1.0..=1.0).contains(x))?;
    Some((channel, value))
}

/// `IF NOT $IN[n] THEN`, `IF $IN[n] THEN`; `None` for another `IF`.
fn parse_if_input(l: &str) -> Result<Option<KrlOp>, String> {
    let input = |r: &str| {
        index_of(r.trim(), "$IN[")
            .map(|n| u32::try_from(n).map_err(|_| format!("bad input in `{l}`")))
    };
    let cond = l.strip_prefix("IF ").and_then(|r| r.strip_suffix("THEN"));
    if let Some(n) = cond
        .and_then(|r| r.trim().strip_prefix("NOT "))
        .and_then(input)
    {
        return Ok(Some(KrlOp::IfNotIn(n?)));
    }
    if let Some(n) = cond.and_then(input) {
        return Ok(Some(KrlOp::IfIn(n?)));
    }
    Ok(None)
}

/// `BAS (#TOOL, n)`, `BAS (#BASE, n)`, `BAS (#VEL_PTP, v)`; `None` for
/// another `BAS` call.
fn parse_bas(l: &str) -> Result<Option<KrlOp>, String> {
    if let Some(args) = l
        .strip_prefix("BAS")
        .map(str::trim)
        .and_then(|r| r.strip_prefix('('))
        .and_then(|r| r.strip_suffix(')'))
    {
        if let Some((what, n)) = args.split_once(',') {
            let n = n.trim();
            let int = || {
                n.parse::<u8>()
                    .map_err(|_| format!("bad number `{n}` in `{l}`"))
            };
            match what.trim() {
                "#TOOL" => return Ok(Some(KrlOp::Tool(int()?))),
                "#BASE" => return Ok(Some(KrlOp::Base(int()?))),
                "#VEL_PTP" => {
                    let v: f64 = n
                        .parse()
                        .ok()
                        .filter(|v: &f64| *v > 0.0 && *v <= 100.0)
                        .ok_or_else(|| format!("bad #VEL_PTP `{n}`"))?;
                    return Ok(Some(KrlOp::VelPtp(v)));
                }
                _ => {}
            }
        }
    }
    Ok(None)
}

/// `k = v` for a speed, load or timer variable (`$VEL.CP`,
/// `$VEL_EXTAX[n]`, `$LOAD.M`, `$LOAD.CM`, `$LOAD.J`, `$TIMER[t]`,
/// `$TIMER_STOP[t]`); `None` for another variable.
fn parse_setting(k: &str, v: &str) -> Result<Option<KrlOp>, String> {
    Ok(Some(match k {
        "$VEL.CP" => {
            let x: f64 = v
                .parse()
                .ok()
                .filter(|x: &f64| x.is_finite() && *x > 0.0)
                .ok_or_else(|| format!("bad $VEL.CP `{v}`"))?;
            KrlOp::VelCp(x)
        }
        _ if k.starts_with("$VEL_EXTAX[") => {
            let axis = k
                .strip_prefix("$VEL_EXTAX[")
                .and_then(|r| r.strip_suffix(']'))
                .and_then(|n| n.parse::<u8>().ok())
                .filter(|n| (1..=6).contains(n))
                .ok_or_else(|| format!("bad `{k}`"))?;
            let percent: f64 = v
                .parse()
                .ok()
                .filter(|x: &f64| x.is_finite() && *x > 0.0 && *x <= 100.0)
                .ok_or_else(|| format!("bad {k} `{v}` (0 < % <= 100)"))?;
            KrlOp::VelExtax { axis, percent }
        }
        "$LOAD.M" => {
            let m: f64 = v
                .parse()
                .ok()
                .filter(|x: &f64| x.is_finite() && *x >= 0.0)
                .ok_or_else(|| format!("bad $LOAD.M `{v}` (kg >= 0)"))?;
            KrlOp::LoadMass(m)
        }
        "$LOAD.CM" => KrlOp::LoadCm(frame_of(v)?),
        _ if k.starts_with("$ANOUT[") => {
            let (channel, value) = parse_anout(k, v)
                .ok_or_else(|| format!("bad `{k} = {v}` (n 1..32, -1 <= v <= 1)"))?;
            KrlOp::Anout { channel, value }
        }
        "$LOAD.J" => {
            let f = aggregate(v)?;
            let get = |k: &str| field(&f, k, v);
            KrlOp::LoadJ([get("X")?, get("Y")?, get("Z")?])
        }
        _ if k.starts_with("$TIMER[") => {
            let timer = index_of(k, "$TIMER[")
                .and_then(|n| u8::try_from(n).ok())
                .ok_or_else(|| format!("bad `{k}`"))?;
            let ms: f64 = v
                .parse()
                .ok()
                .filter(|x: &f64| x.is_finite())
                .ok_or_else(|| format!("bad {k} `{v}`"))?;
            KrlOp::Timer { timer, ms }
        }
        _ if k.starts_with("$TIMER_STOP[") => {
            let timer = index_of(k, "$TIMER_STOP[")
                .and_then(|n| u8::try_from(n).ok())
                .ok_or_else(|| format!("bad `{k}`"))?;
            let stop = match v {
                "TRUE" => true,
                "FALSE" => false,
                _ => return Err(format!("bad {k} `{v}`")),
            };
            KrlOp::TimerStop { timer, stop }
        }
        _ => return Ok(None),
    }))
}

/// `k = v` (the statement `l`) for a frame variable (`$ORI_TYPE`,
/// `$CIRC_TYPE`, `$IPO_MODE`, `$TOOL`, `$BASE`); `None` for another
/// variable.
fn parse_frame_setting(l: &str, k: &str, v: &str) -> Result<Option<KrlOp>, String> {
    Ok(Some(match k {
        "$ORI_TYPE" => KrlOp::OriType(v.to_string()),
        "$CIRC_TYPE" => KrlOp::CircType(v.to_string()),
        "$IPO_MODE" => match v {
            "#TCP" => KrlOp::IpoTcp(true),
            "#BASE" => KrlOp::IpoTcp(false),
            _ => return Err(format!("bad $IPO_MODE `{v}`")),
        },
        "$TOOL" | "$BASE" if v.starts_with('{') => {
            let f = frame_of(v)?;
            if k == "$TOOL" {
                KrlOp::ToolFrame(f)
            } else {
                KrlOp::BaseFrame(f)
            }
        }
        "$BASE" if v.starts_with("EK") => parse_ek(v)?,
        "$TOOL" | "$BASE" => {
            let prefix = if k == "$TOOL" {
                "TOOL_DATA["
            } else {
                "BASE_DATA["
            };
            let n = v
                .strip_prefix(prefix)
                .and_then(|s| s.strip_suffix(']'))
                .and_then(|s| s.parse::<u8>().ok())
                .ok_or_else(|| format!("bad `{l}`"))?;
            if k == "$TOOL" {
                KrlOp::Tool(n)
            } else {
                KrlOp::Base(n)
            }
        }
        _ => return Ok(None),
    }))
}

/// `[GLOBAL] INTERRUPT DECL p WHEN cond DO name(args)` and `INTERRUPT
/// ON|OFF|ENABLE|DISABLE [p]`.
fn parse_interrupt(l: &str) -> Result<KrlOp, String> {
    let (global, rest) = match l.strip_prefix("GLOBAL ") {
        Some(r) => (true, r.trim_start()),
        None => (false, l),
    };
    let rest = rest
        .strip_prefix("INTERRUPT ")
        .ok_or_else(|| format!("expected `INTERRUPT …`, got `{l}`"))?
        .trim();
    let prio_of = |p: &str| {
        p.trim()
            .parse::<u8>()
            .ok()
            .filter(|p| (1..=128).contains(p))
            .ok_or_else(|| format!("bad interrupt priority `{}` in `{l}` (1..=128)", p.trim()))
    };
    if let Some(decl) = rest.strip_prefix("DECL ") {
        let bad = || format!("expected `INTERRUPT DECL prio WHEN condition DO name( )`, got `{l}`");
        let (prio, rest) = decl.trim().split_once(' ').ok_or_else(bad)?;
        let rest = rest.trim().strip_prefix("WHEN ").ok_or_else(bad)?;
        let (when, handler) = rest.rsplit_once(" DO ").ok_or_else(bad)?;
        let handler = handler.trim();
        if !is_call(handler) || when.trim().is_empty() {
            return Err(bad());
        }
        return Ok(KrlOp::InterruptDecl {
            global,
            prio: prio_of(prio)?,
            when: when.trim().to_string(),
            handler: handler.split('(').next().unwrap_or("").trim().to_string(),
        });
    }
    if global {
        return Err(format!("GLOBAL only before `INTERRUPT DECL`, got `{l}`"));
    }
    let (action, prio) = match rest.split_once(' ') {
        Some((a, p)) => (a, Some(prio_of(p)?)),
        None => (rest, None),
    };
    let action = match action {
        "ON" => InterruptAction::On,
        "OFF" => InterruptAction::Off,
        "ENABLE" => InterruptAction::Enable,
        "DISABLE" => InterruptAction::Disable,
        _ => {
            return Err(format!(
                "expected `INTERRUPT ON|OFF|ENABLE|DISABLE [prio]`, got `{l}`"
            ))
        }
    };
    Ok(KrlOp::Interrupt { action, prio })
}

/// `n` of `PREFIX n]` at the start of `s` (`$IN[3]`, `$TIMER[1]`).
fn index_of(s: &str, prefix: &str) -> Option<i64> {
    s.strip_prefix(prefix)?
        .strip_suffix(']')?
        .trim()
        .parse::<i64>()
        .ok()
        .filter(|n| *n >= 1)
}

/// `WAIT SEC s`, `WAIT FOR $IN[n]`, `WAIT FOR $IN[n] OR $TIMER_FLAG[t]`.
fn parse_wait(l: &str) -> Result<KrlOp, String> {
    if let Some(v) = l.strip_prefix("WAIT SEC") {
        let s: f64 = v
            .trim()
            .parse()
            .ok()
            .filter(|x: &f64| x.is_finite() && *x >= 0.0)
            .ok_or_else(|| format!("bad `{l}` (seconds >= 0)"))?;
        return Ok(KrlOp::WaitSec(s));
    }
    let cond = l
        .strip_prefix("WAIT FOR")
        .map(str::trim)
        .ok_or_else(|| format!("bad WAIT `{l}`"))?;
    let input = |t: &str| {
        index_of(t.trim(), "$IN[")
            .and_then(|n| u32::try_from(n).ok())
            .ok_or_else(|| format!("expected `$IN[n]` in `{l}`"))
    };
    match cond.split_once(" OR ") {
        None => Ok(KrlOp::WaitIn(input(cond)?)),
        Some((a, b)) => {
            let timer = index_of(b.trim(), "$TIMER_FLAG[")
                .and_then(|n| u8::try_from(n).ok())
                .ok_or_else(|| format!("expected `$TIMER_FLAG[t]` in `{l}`"))?;
            Ok(KrlOp::WaitInOrTimer {
                input: input(a)?,
                timer,
            })
        }
    }
}

/// The `KEY value` fields of an aggregate `{KEY value,...}` (an optional
/// `FRAME:` type prefix accepted).
fn aggregate(v: &str) -> Result<Vec<(String, f64)>, String> {
    let body = v
        .trim()
        .strip_prefix('{')
        .and_then(|b| b.strip_suffix('}'))
        .ok_or_else(|| format!("expected `{{...}}`, got `{v}`"))?;
    let body = body.trim();
    let body = body.strip_prefix("FRAME:").unwrap_or(body);
    body.split(',')
        .map(|part| {
            let (k, x) = part
                .trim()
                .split_once(' ')
                .ok_or_else(|| format!("expected `KEY value`, got `{}`", part.trim()))?;
            let x: f64 = x
                .trim()
                .parse()
                .ok()
                .filter(|x: &f64| x.is_finite())
                .ok_or_else(|| format!("bad number `{}` for {k}", x.trim()))?;
            Ok((k.trim().to_ascii_uppercase(), x))
        })
        .collect()
}

fn field(f: &[(String, f64)], k: &str, v: &str) -> Result<f64, String> {
    f.iter()
        .find(|(n, _)| n == k)
        .map(|(_, x)| *x)
        .ok_or_else(|| format!("no {k} in `{v}`"))
}

/// `[X, Y, Z, A, B, C]` of a `FRAME` aggregate.
fn frame_of(v: &str) -> Result<[f64; 6], String> {
    let f = aggregate(v)?;
    let mut out = [0.0; 6];
    for (o, k) in out.iter_mut().zip(["X", "Y", "Z", "A", "B", "C"]) {
        *o = field(&f, k, v)?;
    }
    Ok(out)
}

/// `EK (MACHINE_DEF[m].ROOT, MACHINE_DEF[m].MECH_TYPE, {…})`.
fn parse_ek(v: &str) -> Result<KrlOp, String> {
    let bad = || {
        format!("bad `$BASE = {v}`: expected `EK (MACHINE_DEF[m].ROOT, MACHINE_DEF[m].MECH_TYPE, {{X …}})`")
    };
    let args = v
        .strip_prefix("EK")
        .map(str::trim)
        .and_then(|r| r.strip_prefix('('))
        .and_then(|r| r.strip_suffix(')'))
        .ok_or_else(bad)?;
    let brace = args.find('{').ok_or_else(bad)?;
    let (head, offset) = args.split_at(brace);
    let parts: Vec<&str> = head.split(',').map(str::trim).collect();
    let [root, mech, ""] = parts[..] else {
        return Err(bad());
    };
    let machine_of = |s: &str, field: &str| {
        s.strip_prefix("MACHINE_DEF[")
            .and_then(|r| r.strip_suffix(field))
            .and_then(|r| r.strip_suffix(']'))
            .and_then(|n| n.trim().parse::<u8>().ok())
    };
    let (Some(m), Some(m2)) = (machine_of(root, ".ROOT"), machine_of(mech, ".MECH_TYPE")) else {
        return Err(bad());
    };
    if m != m2 {
        return Err(format!(
            "`$BASE = {v}`: ROOT of MACHINE_DEF[{m}], MECH_TYPE of MACHINE_DEF[{m2}]"
        ));
    }
    Ok(KrlOp::BaseEk {
        machine: m,
        offset: frame_of(offset.trim())?,
    })
}

fn parse_dat(text: &str, file: &str) -> Result<(String, Vec<KrlPosition>), ProgramError> {
    let name_of = |rest: &str| rest.split_whitespace().next().unwrap_or("").to_string();
    let (name, _, positions) = parse_blocks(
        text,
        file,
        ("DEFDAT", "name", "ENDDAT"),
        false,
        name_of,
        |l, n| {
            Ok(KrlPosition {
                line: n,
                ..parse_decl(l)?
            })
        },
    )?
    .into_iter()
    .next()
    .expect("parse_blocks gives one block or more");
    Ok((name, positions))
}

fn parse_decl(l: &str) -> Result<KrlPosition, String> {
    let rest = l
        .strip_prefix("DECL ")
        .ok_or_else(|| format!("expected `DECL E6AXIS|E6POS name={{...}}`, got `{l}`"))?;
    let (ty, rest) = rest
        .split_once(' ')
        .ok_or_else(|| format!("bad DECL `{l}`"))?;
    let (name, body) = rest
        .split_once('=')
        .ok_or_else(|| format!("bad DECL `{l}`"))?;
    let body = body
        .trim()
        .strip_prefix('{')
        .and_then(|b| b.strip_suffix('}'))
        .ok_or_else(|| format!("DECL {}: value not in braces", name.trim()))?;
    let mut fields: Vec<(String, f64)> = Vec::new();
    for part in body.split(',') {
        let (k, v) = part
            .trim()
            .split_once(' ')
            .ok_or_else(|| format!("expected `KEY value`, got `{}`", part.trim()))?;
        let x: f64 = v
            .trim()
            .parse()
            .ok()
            .filter(|x: &f64| x.is_finite())
            .ok_or_else(|| format!("bad number `{}` for {k}", v.trim()))?;
        fields.push((k.to_string(), x));
    }
    let get = |k: &str| -> Result<f64, String> {
        fields
            .iter()
            .find(|(f, _)| f == k)
            .map(|(_, v)| *v)
            .ok_or_else(|| format!("{}: no {k}", name.trim()))
    };
    let value = match ty {
        "E6AXIS" => KrlValue::Axis([
            get("A1")?,
            get("A2")?,
            get("A3")?,
            get("A4")?,
            get("A5")?,
            get("A6")?,
        ]),
        "E6POS" => {
            let bits = |k: &str| -> Result<u8, String> {
                let v = get(k)?;
                if v.fract() == 0.0 && (0.0..64.0).contains(&v) {
                    Ok(v as u8)
                } else {
                    Err(format!("{}: bad {k} {v}", name.trim()))
                }
            };
            KrlValue::Pos {
                xyzabc: [
                    get("X")?,
                    get("Y")?,
                    get("Z")?,
                    get("A")?,
                    get("B")?,
                    get("C")?,
                ],
                status: bits("S")?,
                turn: bits("T")?,
            }
        }
        _ => return Err(format!("unsupported type `{ty}`")),
    };
    Ok(KrlPosition {
        name: name.trim().to_string(),
        line: 0,
        value,
        external: [get("E1")?, get("E2")?],
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn interrupt_statements() {
        assert_eq!(
            parse_statement("GLOBAL INTERRUPT DECL 3 WHEN $STOPMESS==TRUE DO IR_STOPM ( )"),
            Ok(KrlOp::InterruptDecl {
                global: true,
                prio: 3,
                when: "$STOPMESS==TRUE".into(),
                handler: "IR_STOPM".into(),
            })
        );
        assert_eq!(
            parse_statement("INTERRUPT OFF 20"),
            Ok(KrlOp::Interrupt {
                action: InterruptAction::Off,
                prio: Some(20)
            })
        );
        assert_eq!(
            parse_statement("INTERRUPT DISABLE"),
            Ok(KrlOp::Interrupt {
                action: InterruptAction::Disable,
                prio: None
            })
        );
        assert_eq!(parse_statement("BRAKE F"), Ok(KrlOp::Brake { fast: true }));
        assert_eq!(parse_statement("IF $IN[7] THEN"), Ok(KrlOp::IfIn(7)));
        assert_eq!(parse_statement("IF NOT $IN[7] THEN"), Ok(KrlOp::IfNotIn(7)));
        for bad in [
            "INTERRUPT ON 0",
            "INTERRUPT ON 129",
            "INTERRUPT 20 ON",
            "INTERRUPT DECL 20 WHEN $IN[1]==FALSE",
            "INTERRUPT DECL 20 WHEN DO ARC( )",
            "GLOBAL INTERRUPT ON 20",
            "BRAKE X",
        ] {
            assert!(parse_statement(bad).is_err(), "{bad}");
        }
        assert_eq!(falling_input("$IN[12] == FALSE"), Some(12));
        assert_eq!(falling_input("NOT $IN[4]"), Some(4));
        assert_eq!(falling_input("$IN[4]==TRUE"), None);
        assert_eq!(falling_input("$STOPMESS==FALSE"), None);
    }

    /// Local subprograms after the main routine are read as routines; other
    /// text after its `END`, or a routine without `END`, is an error naming
    /// the line.
    #[test]
    fn local_subprograms() {
        let dat = "DEFDAT P\nENDDAT\n";
        let src = "DEF P( )\n  HALT\nEND\n\nDEF SUB( )\n  BRAKE F\nEND\n";
        let p = parse_krl(src, "P.src", dat, "P.dat").unwrap();
        assert_eq!(p.statements.len(), 1);
        let r = p.routine("sub").unwrap();
        assert_eq!((r.name.as_str(), r.line), ("SUB", 5));
        assert_eq!(r.statements[0].op, KrlOp::Brake { fast: true });
        let e = parse_krl("DEF P( )\nEND\nHALT\n", "P.src", dat, "P.dat").unwrap_err();
        assert!(e.to_string().starts_with("P.src:3: text after END"), "{e}");
        let e =
            parse_krl("DEF P( )\nEND\nDEF SUB( )\n  HALT\n", "P.src", dat, "P.dat").unwrap_err();
        assert!(
            e.to_string().contains("P.src:4: file ends without END"),
            "{e}"
        );
        let e = parse_krl(
            "DEF P( )\nEND\n",
            "P.src",
            "DEFDAT P\nENDDAT\nDEFDAT Q\n",
            "P.dat",
        )
        .unwrap_err();
        assert!(
            e.to_string().starts_with("P.dat:3: text after ENDDAT"),
            "{e}"
        );
    }
}
