//! Reader of our own FANUC TP ASCII output (the subset [`write_ls`]
//! writes), so that every emitted program can be re-read and checked
//! [SPEC §8]. Errors name the file and line; a file without `/END`
//! (truncated) is an error.
//!
//! [`write_ls`]: crate::program::fanuc::write_ls

use crate::program::contract::read_file;
use crate::program::fanuc::{
    ArmPosition, Instruction, MotionOptions, MoveKind, Op, PayloadField, Position, Speed,
    Termination, TpProgram,
};
use crate::program::{EmittedFile, ProgramError};

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Section {
    Start,
    Attr,
    Appl,
    Mn,
    Pos,
    End,
}

#[derive(Debug, Default)]
struct Partial {
    index: usize,
    line: usize,
    group: u8,
    uf_ut: Option<(u8, u8)>,
    config: Option<String>,
    values: [Option<(f64, usize)>; 6],
    cart: [Option<(f64, usize)>; 6],
    group2: [Option<f64>; 2],
    group2_line: usize,
}

/// Parses one `.ls` file written by [`write_ls`](crate::program::fanuc::write_ls).
/// `file` names it in errors.
///
/// # Errors
/// [`ProgramError::Read`] with the line: missing or misplaced section, bad
/// instruction or value, a move to a position without record, `LINE_COUNT`
/// different from the `/MN` lines, and a file ending before `/END`.
pub fn parse_ls(text: &str, file: &str) -> Result<TpProgram, ProgramError> {
    let mut r = LsReader {
        file,
        tp: TpProgram {
            name: String::new(),
            comment: String::new(),
            groups: 1,
            arc_welding: false,
            arc_enabled: false,
            remote_tcp: false,
            instructions: Vec::new(),
            positions: Vec::new(),
        },
        section: Section::Start,
        line_count: None,
        mn_line: 0,
        current: None,
        pending_circular: None,
    };
    let mut last_line = 0;
    for (i, raw) in text.lines().enumerate() {
        let n = i + 1;
        last_line = n;
        let l = raw.trim();
        if l.is_empty() || r.header_or_marker(n, l)? {
            continue;
        }
        match r.section {
            Section::Attr => r.attr(n, l)?,
            Section::Appl => r.appl(l),
            Section::Mn => r.instruction(n, l)?,
            Section::Pos => r.position(n, l)?,
            Section::Start | Section::End => unreachable!("handled above"),
        }
    }
    r.end(last_line)
}

/// What [`parse_ls`] carries from line to line.
struct LsReader<'a> {
    /// The file's name, in errors.
    file: &'a str,
    tp: TpProgram,
    section: Section,
    /// `LINE_COUNT` and its line.
    line_count: Option<(usize, usize)>,
    /// Line of `/MN`.
    mn_line: usize,
    /// The position record open.
    current: Option<Partial>,
    /// A `C P[v]` line waiting for its `:  P[n] ...` continuation.
    pending_circular: Option<(usize, String)>,
}

impl LsReader<'_> {
    fn err(&self, line: usize, reason: String) -> ProgramError {
        ProgramError::Read {
            file: self.file.to_string(),
            line,
            reason,
        }
    }

    /// `/PROG` and the section markers (`/ATTR`, `/APPL`, `/MN`, `/POS`,
    /// `/END`) at line `n`: `true` when `l` is one (read).
    fn header_or_marker(&mut self, n: usize, l: &str) -> Result<bool, ProgramError> {
        if self.section == Section::End {
            return Err(self.err(n, "text after /END".into()));
        }
        if let Some(name) = l.strip_prefix("/PROG") {
            if self.section != Section::Start {
                return Err(self.err(n, "/PROG not on the first line".into()));
            }
            self.tp.name = name.trim().to_string();
            if self.tp.name.is_empty() {
                return Err(self.err(n, "/PROG without a name".into()));
            }
            self.section = Section::Attr;
            return Ok(true);
        }
        if self.section == Section::Start {
            return Err(self.err(n, "expected /PROG".into()));
        }
        match l {
            "/ATTR" => {}
            "/APPL" => self.section = Section::Appl,
            "/MN" => {
                self.section = Section::Mn;
                self.mn_line = n;
            }
            "/POS" => {
                if let Some((start, _)) = &self.pending_circular {
                    return Err(self.err(
                        *start,
                        "circular move without its end line `:  P[n] ...`".into(),
                    ));
                }
                if self.section != Section::Mn {
                    return Err(self.err(n, "/POS before /MN".into()));
                }
                self.section = Section::Pos;
            }
            "/END" => {
                if let Some(p) = &self.current {
                    return Err(self.err(
                        n,
                        format!("/END inside P[{}] (opened at line {})", p.index, p.line),
                    ));
                }
                if self.section != Section::Pos {
                    return Err(self.err(n, "/END before /POS".into()));
                }
                self.section = Section::End;
            }
            _ => return Ok(false),
        }
        Ok(true)
    }

    /// A line `l` (line `n`) of `/ATTR`.
    fn attr(&mut self, n: usize, l: &str) -> Result<(), ProgramError> {
        let tp = &mut self.tp;
        if let Some(v) = attr_value(l, "COMMENT") {
            tp.comment = v.trim_matches('"').to_string();
        } else if let Some(v) = attr_value(l, "DEFAULT_GROUP") {
            tp.groups = v.split(',').filter(|g| g.trim() == "1").count();
        } else if let Some(v) = attr_value(l, "CONTROL_CODE") {
            tp.remote_tcp = v
                .split_whitespace()
                .next()
                .is_some_and(|c| c.ends_with('1'));
        } else if let Some(v) = attr_value(l, "LINE_COUNT") {
            let c = v
                .parse()
                .map_err(|_| self.err(n, format!("bad LINE_COUNT `{v}`")))?;
            self.line_count = Some((c, n));
        }
        Ok(())
    }

    /// A line `l` of `/APPL`.
    fn appl(&mut self, l: &str) {
        let compact: String = l.chars().filter(|c| !c.is_whitespace()).collect();
        if compact.eq_ignore_ascii_case("ARC:TRUE;") {
            self.tp.arc_enabled = true;
        } else if l.starts_with("ARC Welding Equipment") {
            self.tp.arc_welding = true;
        }
    }

    /// A line `l` (line `n`) of `/MN`: an instruction, or the continuation
    /// line of a circular move.
    fn instruction(&mut self, n: usize, l: &str) -> Result<(), ProgramError> {
        // the continuation line of a circular move: `:  P[n] ... ;`
        if let Some((start, head)) = self.pending_circular.take() {
            let rest = l.strip_prefix(':').ok_or_else(|| {
                self.err(
                    n,
                    format!("expected the end line `:  P[n] <speed> <FINE|CNTn> ;` of the circular move of line {start}"),
                )
            })?;
            let body = rest
                .trim_end()
                .strip_suffix(';')
                .ok_or_else(|| self.err(n, "instruction without `;`".into()))?
                .trim();
            let op = parse_op(&format!("{head} {body}")).map_err(|r| self.err(start, r))?;
            self.tp.instructions.push(Instruction { line: start, op });
            return Ok(());
        }
        let (num, body) = l
            .split_once(':')
            .ok_or_else(|| self.err(n, format!("expected `<n>:<instruction> ;`, got `{l}`")))?;
        let num: usize = num
            .trim()
            .parse()
            .map_err(|_| self.err(n, format!("bad line number `{num}`")))?;
        if num != self.tp.instructions.len() + 1 {
            return Err(self.err(
                n,
                format!(
                    "instruction number {num}, expected {}",
                    self.tp.instructions.len() + 1
                ),
            ));
        }
        let body = body.trim();
        if body.starts_with("C ") && !body.ends_with(';') {
            self.pending_circular = Some((n, body.to_string()));
            return Ok(());
        }
        let body = body
            .strip_suffix(';')
            .ok_or_else(|| self.err(n, "instruction without `;`".into()))?
            .trim();
        let op = parse_op(body).map_err(|r| self.err(n, r))?;
        self.tp.instructions.push(Instruction { line: n, op });
        Ok(())
    }

    /// A line `l` (line `n`) of `/POS`: a record's header, group, frames,
    /// values or end.
    fn position(&mut self, n: usize, l: &str) -> Result<(), ProgramError> {
        if let Some(rest) = l.strip_prefix("P[") {
            if let Some(p) = &self.current {
                return Err(self.err(
                    n,
                    format!("P[{}] opened at line {} not closed", p.index, p.line),
                ));
            }
            let idx = rest
                .strip_suffix("]{")
                .and_then(|s| s.parse::<usize>().ok())
                .ok_or_else(|| self.err(n, format!("bad position header `{l}`")))?;
            self.current = Some(Partial {
                index: idx,
                line: n,
                ..Default::default()
            });
            return Ok(());
        }
        let Some(mut p) = self.current.take() else {
            return Err(self.err(n, format!("`{l}` outside a position record")));
        };
        if l == "};" {
            let position = finish(p).map_err(|(line, r)| self.err(line, r))?;
            self.tp.positions.push(position);
            return Ok(());
        }
        let read = if l == "GP1:" {
            p.group = 1;
            Ok(())
        } else if l == "GP2:" {
            p.group = 2;
            Ok(())
        } else if l.starts_with("UF") {
            self.frames(&mut p, n, l)
        } else {
            self.values(&mut p, n, l)
        };
        self.current = Some(p);
        read
    }

    /// `UF : n, UT : n[, CONFIG : '...']` (line `n`) of record `p`.
    fn frames(&self, p: &mut Partial, n: usize, l: &str) -> Result<(), ProgramError> {
        let mut rest = l.to_string();
        if let Some(start) = l.find("CONFIG") {
            let q: Vec<&str> = l[start..].split('\'').collect();
            if q.len() < 3 {
                return Err(self.err(n, "CONFIG without a quoted string".into()));
            }
            p.config = Some(q[1].to_string());
            rest = l[..start].to_string();
        }
        let mut uf = None;
        let mut ut = None;
        for part in rest.split(',') {
            if let Some((k, v)) = part.split_once(':') {
                let v: u8 = v
                    .trim()
                    .parse()
                    .map_err(|_| self.err(n, format!("bad frame number in `{part}`")))?;
                match k.trim() {
                    "UF" => uf = Some(v),
                    "UT" => ut = Some(v),
                    k => return Err(self.err(n, format!("unknown key `{k}`"))),
                }
            }
        }
        match (uf, ut) {
            (Some(a), Some(b)) if p.group == 1 => p.uf_ut = Some((a, b)),
            (Some(_), Some(_)) => {}
            _ => return Err(self.err(n, "expected `UF : n, UT : n`".into())),
        }
        Ok(())
    }

    /// `KEY = value unit, ...` (line `n`) of record `p`'s current group.
    fn values(&self, p: &mut Partial, n: usize, l: &str) -> Result<(), ProgramError> {
        for part in l.split(',') {
            let part = part.trim();
            if part.is_empty() {
                continue;
            }
            let (k, v) = part
                .split_once('=')
                .ok_or_else(|| self.err(n, format!("expected `KEY = value`, got `{part}`")))?;
            let v = v.trim();
            let v = v
                .strip_suffix("deg")
                .or_else(|| v.strip_suffix("mm"))
                .ok_or_else(|| self.err(n, format!("value without unit: `{part}`")))?
                .trim();
            let x: f64 = v
                .parse()
                .ok()
                .filter(|x: &f64| x.is_finite())
                .ok_or_else(|| self.err(n, format!("bad number `{v}`")))?;
            let k = k.trim();
            let slot = match (p.group, k) {
                (2, "J1") => {
                    p.group2[0] = Some(x);
                    p.group2_line = n;
                    continue;
                }
                (2, "J2") => {
                    p.group2[1] = Some(x);
                    p.group2_line = n;
                    continue;
                }
                (1, "J1") => &mut p.values[0],
                (1, "J2") => &mut p.values[1],
                (1, "J3") => &mut p.values[2],
                (1, "J4") => &mut p.values[3],
                (1, "J5") => &mut p.values[4],
                (1, "J6") => &mut p.values[5],
                (1, "X") => &mut p.cart[0],
                (1, "Y") => &mut p.cart[1],
                (1, "Z") => &mut p.cart[2],
                (1, "W") => &mut p.cart[3],
                (1, "P") => &mut p.cart[4],
                (1, "R") => &mut p.cart[5],
                _ => return Err(self.err(n, format!("unexpected key `{k}` in group {}", p.group))),
            };
            *slot = Some((x, n));
        }
        Ok(())
    }

    /// After the last line (`last_line`): the file ended with `/END`, its
    /// `LINE_COUNT` and every move's record checked.
    fn end(self, last_line: usize) -> Result<TpProgram, ProgramError> {
        if self.section != Section::End {
            let where_ = match (&self.current, self.section) {
                (Some(p), _) => format!(" inside P[{}] (opened at line {})", p.index, p.line),
                (None, Section::Mn) => " inside /MN".into(),
                (None, Section::Pos) => " inside /POS".into(),
                _ => String::new(),
            };
            return Err(self.err(
                last_line,
                format!("file ends{where_} without /END (truncated?)"),
            ));
        }
        let tp = &self.tp;
        if let Some((c, line)) = self.line_count {
            if c != tp.instructions.len() {
                return Err(self.err(
                    line,
                    format!(
                        "LINE_COUNT = {c} but /MN (line {}) has {} instructions",
                        self.mn_line,
                        tp.instructions.len()
                    ),
                ));
            }
        }
        for ins in &tp.instructions {
            if let Op::Move { position, via, .. } = ins.op {
                for position in via.into_iter().chain([position]) {
                    if !tp.positions.iter().any(|p| p.index == position) {
                        return Err(self.err(ins.line, format!("P[{position}] has no /POS record")));
                    }
                }
            }
        }
        Ok(self.tp)
    }
}

fn attr_value<'a>(l: &'a str, key: &str) -> Option<&'a str> {
    let rest = l.strip_prefix(key)?;
    let rest = rest.trim_start().strip_prefix('=')?;
    Some(rest.trim().trim_end_matches(';').trim())
}

fn parse_op(body: &str) -> Result<Op, String> {
    let mut tokens: Vec<&str> = body.split_whitespace().collect();
    if let Some(kind) = match tokens.first() {
        Some(&"J") => Some(MoveKind::Joint),
        Some(&"L") => Some(MoveKind::Linear),
        Some(&"C") => Some(MoveKind::Circular),
        _ => None,
    } {
        let index = |t: &str| {
            t.strip_prefix("P[")
                .and_then(|s| s.strip_suffix(']'))
                .and_then(|s| s.parse::<usize>().ok())
                .ok_or_else(|| format!("bad position `{t}`"))
        };
        // `C P[v] P[n] ...`: the via, then what a linear move has
        let via = match kind {
            MoveKind::Circular if tokens.len() >= 2 => Some(index(tokens.remove(1))?),
            _ => None,
        };
        if tokens.len() < 4 {
            return Err(format!(
                "expected `J|L P[n] <speed> <FINE|CNTn> [COORD] [RTCP]` or `C P[v]` then `:  P[n] <speed> <FINE|CNTn> ...`, got `{body}`"
            ));
        }
        let mut options = MotionOptions::default();
        for t in &tokens[4..] {
            let flag = match *t {
                "COORD" => &mut options.coord,
                "RTCP" => &mut options.rtcp,
                t => return Err(format!("unknown motion option `{t}` in `{body}`")),
            };
            if *flag {
                return Err(format!("motion option `{t}` twice in `{body}`"));
            }
            *flag = true;
        }
        let position = index(tokens[1])?;
        let s = tokens[2];
        let num = |t: &str| t.parse::<u32>().map_err(|_| format!("bad speed `{s}`"));
        let speed = if let Some(v) = s.strip_suffix('%') {
            Speed::Percent(num(v)?)
        } else if let Some(v) = s.strip_suffix("mm/sec") {
            Speed::MmPerSec(num(v)?)
        } else if let Some(v) = s.strip_suffix("cm/min") {
            Speed::CmPerMin(num(v)?)
        } else if let Some(v) = s.strip_suffix("msec") {
            Speed::Msec(num(v)?)
        } else {
            return Err(format!("bad speed `{s}`"));
        };
        if matches!(speed, Speed::Percent(_)) != (kind == MoveKind::Joint)
            || (kind == MoveKind::Joint && speed.time_s().is_some())
        {
            return Err(format!("speed `{s}` does not fit a {kind:?} move"));
        }
        let term = match tokens[3] {
            "FINE" => Termination::Fine,
            t => Termination::Cnt(
                t.strip_prefix("CNT")
                    .and_then(|c| c.parse::<u8>().ok())
                    .filter(|c| *c <= 100)
                    .ok_or_else(|| format!("bad termination `{t}`"))?,
            ),
        };
        return Ok(Op::Move {
            kind,
            position,
            via,
            speed,
            term,
            options,
        });
    }
    let bracket = |prefix: &str| -> Option<Result<u32, String>> {
        let rest = body.strip_prefix(prefix)?;
        Some(
            rest.strip_suffix(']')
                .and_then(|s| s.parse().ok())
                .ok_or_else(|| format!("bad `{body}`")),
        )
    };
    if let Some(r) = bracket("Arc Start[") {
        return r.map(Op::ArcStart);
    }
    if let Some(r) = bracket("Arc End[") {
        return r.map(Op::ArcEnd);
    }
    let pair = |prefix: &str| -> Option<Result<(u32, u32), String>> {
        let rest = body.strip_prefix(prefix)?;
        Some(
            rest.strip_suffix(']')
                .and_then(|s| s.split_once(','))
                .and_then(|(a, b)| Some((a.trim().parse().ok()?, b.trim().parse().ok()?)))
                .ok_or_else(|| format!("bad `{body}` (expected `{prefix}procedure,schedule]`)")),
        )
    };
    if let Some(r) = pair("Weld Start[") {
        return r.map(|(p, s)| Op::WeldStart(p, s));
    }
    if let Some(r) = pair("Weld End[") {
        return r.map(|(p, s)| Op::WeldEnd(p, s));
    }
    if let Some(rest) = body.strip_prefix("WAIT ") {
        let rest = rest.trim();
        if let Some(t) = rest.strip_suffix("(sec)") {
            return t
                .trim()
                .parse::<f64>()
                .ok()
                .filter(|t| t.is_finite() && *t >= 0.0)
                .map(Op::WaitTime)
                .ok_or_else(|| format!("bad wait time in `{body}`"));
        }
        let compact: String = rest.chars().filter(|c| !c.is_whitespace()).collect();
        if let Some(n) = compact
            .strip_prefix("DI[")
            .and_then(|r| r.strip_suffix("]=ON"))
        {
            return n
                .parse()
                .map(Op::WaitInput)
                .map_err(|_| format!("bad input number in `{body}`"));
        }
        return Ok(Op::Other(body.to_string()));
    }
    if let Some(rest) = body.strip_prefix("$PLST_GRP1[") {
        let (n, rest) = rest
            .split_once("].")
            .ok_or_else(|| format!("bad `{body}`"))?;
        let schedule: u8 = n
            .trim()
            .parse()
            .map_err(|_| format!("bad schedule in `{body}`"))?;
        let (name, value) = rest
            .split_once('=')
            .ok_or_else(|| format!("expected `=` in `{body}`"))?;
        let field = PayloadField::ALL
            .into_iter()
            .find(|f| f.name() == name.trim())
            .ok_or_else(|| format!("unknown payload field `{}` in `{body}`", name.trim()))?;
        let value: f64 = value
            .trim()
            .parse()
            .ok()
            .filter(|v: &f64| v.is_finite())
            .ok_or_else(|| format!("bad value in `{body}`"))?;
        return Ok(Op::PayloadValue {
            schedule,
            field,
            value,
        });
    }
    if let Some(r) = bracket("PAYLOAD[") {
        return r.and_then(|n| {
            u8::try_from(n)
                .map(Op::Payload)
                .map_err(|_| format!("bad `{body}`"))
        });
    }
    if let Some(v) = body.strip_prefix("UFRAME_NUM=") {
        return v
            .trim()
            .parse()
            .map(Op::UFrame)
            .map_err(|_| format!("bad `{body}`"));
    }
    if let Some(v) = body.strip_prefix("UTOOL_NUM=") {
        return v
            .trim()
            .parse()
            .map(Op::UTool)
            .map_err(|_| format!("bad `{body}`"));
    }
    if let Some(v) = body.strip_prefix('!') {
        return Ok(Op::Remark(v.trim().to_string()));
    }
    if let Some(v) = body.strip_prefix("CALL ") {
        return Ok(Op::Call(v.trim().to_string()));
    }
    if body.is_empty() {
        return Err("empty instruction".into());
    }
    Ok(Op::Other(body.to_string()))
}

fn finish(p: Partial) -> Result<Position, (usize, String)> {
    let uf_ut = p.uf_ut.ok_or((
        p.line,
        format!("P[{}]: no `UF : n, UT : n` in GP1", p.index),
    ))?;
    let joints = p.values.iter().all(Option::is_some);
    let cart = p.cart.iter().all(Option::is_some);
    let (arm, value_lines) = if joints && p.cart.iter().all(Option::is_none) {
        let v = p.values.map(|x| x.expect("checked"));
        (ArmPosition::Joint(v.map(|x| x.0)), v.map(|x| x.1))
    } else if cart && p.values.iter().all(Option::is_none) {
        let v = p.cart.map(|x| x.expect("checked"));
        let config = p.config.ok_or((
            p.line,
            format!("P[{}]: Cartesian position without CONFIG", p.index),
        ))?;
        (
            ArmPosition::Cartesian {
                xyzwpr: v.map(|x| x.0),
                config,
            },
            v.map(|x| x.1),
        )
    } else {
        return Err((
            p.line,
            format!(
                "P[{}]: expected all of J1..J6 or all of X Y Z W P R in GP1",
                p.index
            ),
        ));
    };
    let group2 = match p.group2 {
        [Some(a), Some(b)] => Some([a, b]),
        [None, None] => None,
        _ => return Err((p.line, format!("P[{}]: GP2 needs J1 and J2", p.index))),
    };
    Ok(Position {
        index: p.index,
        uf_ut,
        arm,
        group2,
        line: p.line,
        value_lines,
        group2_line: p.group2_line,
    })
}

/// Most sub-programs a FANUC main program may call (directly or not).
const MAX_CALLED_PROGRAMS: usize = 10_000;

/// The files of the FANUC program at `main` and of every program it calls,
/// read from the same folder (`NAME.ls`), each once, in the order first
/// called; each named by its path.
///
/// # Errors
/// [`ProgramError::Read`] naming the file (and the line for a parse error).
pub fn files_with_calls(main: &std::path::Path) -> Result<Vec<EmittedFile>, ProgramError> {
    let dir = main
        .parent()
        .map(std::path::Path::to_path_buf)
        .unwrap_or_default();
    let first = read_file(main)?;
    let mut names = vec![parse_ls(&first.text, &first.name)?.name];
    let mut files = vec![first];
    let mut k = 0;
    while k < files.len() {
        let calls: Vec<String> = parse_ls(&files[k].text, &files[k].name)?
            .instructions
            .into_iter()
            .filter_map(|i| match i.op {
                Op::Call(n) => Some(n),
                _ => None,
            })
            .collect();
        for called in calls {
            if !names.contains(&called) {
                if files.len() >= MAX_CALLED_PROGRAMS {
                    return Err(ProgramError::Read {
                        file: main.display().to_string(),
                        line: 0,
                        reason: format!("calls more than {MAX_CALLED_PROGRAMS} programs"),
                    });
                }
                files.push(read_file(&dir.join(format!("{called}.ls")))?);
                names.push(called);
            }
        }
        k += 1;
    }
    Ok(files)
}
