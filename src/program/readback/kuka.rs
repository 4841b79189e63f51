//! Reader of our own KUKA KRL output (`.src` + `.dat`, the subset
//! [`write_src`](crate::program::kuka::write_src) and
//! [`write_dat`](crate::program::kuka::write_dat) write). Errors name the
//! file and line; a `.src` without `END` or a `.dat` without `ENDDAT`
//! (truncated) is an error.

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
    /// `$VEL.CP = v` (m/s).
    VelCp(f64),
    /// `TRIGGER WHEN DISTANCE=d DELAY=0 DO action`.
    Trigger {
        /// 0: at the next motion's start point, 1: at its end point.
        distance: u8,
        /// The statement switched.
        action: String,
    },
    /// `$IPO_MODE = #TCP` (`true`) or `#BASE` (`false`).
    IpoTcp(bool),
    /// `$VEL_EXTAX[n] = p`: external axis `n` (1-based) at `p` % of its
    /// maximum speed in path motions.
    VelExtax {
        /// Axis `n`, 1-based.
        axis: u8,
        /// Percent.
        percent: f64,
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

/// A KRL program as read.
#[derive(Debug, Clone, PartialEq)]
pub struct KrlProgram {
    /// `DEF` name.
    pub name: String,
    /// `.src` file name (for messages).
    pub src_file: String,
    /// `.dat` file name.
    pub dat_file: String,
    /// The `.src` statements in order.
    pub statements: Vec<KrlStatement>,
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
    let (name, statements) = parse_src(src, src_file)?;
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
        positions,
    })
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

fn parse_src(text: &str, file: &str) -> Result<(String, Vec<KrlStatement>), ProgramError> {
    let name_of = |rest: &str| rest.split('(').next().unwrap_or("").trim().to_string();
    parse_block(text, file, ("DEF", "name( )", "END"), name_of, |l, n| {
        Ok(KrlStatement {
            line: n,
            op: parse_statement(l)?,
        })
    })
}

/// Reads a `DEF … END` or `DEFDAT … ENDDAT` file: the header's name (from
/// the text after `open` by `name_of`), then each code line up to `close`
/// through `body`; errors name the file and line (text after the end, a
/// missing header or end).
fn parse_block<T>(
    text: &str,
    file: &str,
    (open, header, close): (&str, &str, &str),
    name_of: impl Fn(&str) -> String,
    body: impl Fn(&str, usize) -> Result<T, String>,
) -> Result<(String, Vec<T>), ProgramError> {
    let mut name: Option<String> = None;
    let mut ended = false;
    let mut out = Vec::new();
    let mut last = 0;
    for (i, raw) in text.lines().enumerate() {
        let n = i + 1;
        last = n;
        let l = code(raw);
        if l.is_empty() {
            continue;
        }
        if ended {
            return Err(err(file, n, format!("text after {close}")));
        }
        if name.is_none() {
            let rest = l
                .strip_prefix(open)
                .and_then(|r| r.strip_prefix(' '))
                .ok_or_else(|| err(file, n, format!("expected `{open} {header}`, got `{l}`")))?;
            let nm = name_of(rest);
            if nm.is_empty() {
                return Err(err(file, n, format!("{open} without a name")));
            }
            name = Some(nm);
            continue;
        }
        if l == close {
            ended = true;
            continue;
        }
        out.push(body(l, n).map_err(|r| err(file, n, r))?);
    }
    let Some(name) = name else {
        return Err(err(file, last.max(1), format!("no {open} (empty file?)")));
    };
    if !ended {
        return Err(err(
            file,
            last,
            format!("file ends without {close} (truncated?)"),
        ));
    }
    Ok((name, out))
}

fn parse_statement(l: &str) -> Result<KrlOp, String> {
    let tokens: Vec<&str> = l.split_whitespace().collect();
    match tokens.first().copied() {
        Some("PTP") => {
            if tokens.len() != 2 {
                return Err(format!("expected `PTP name`, got `{l}`"));
            }
            return Ok(KrlOp::Ptp(tokens[1].to_string()));
        }
        Some("LIN") => {
            return match tokens.as_slice() {
                [_, t] => Ok(KrlOp::Lin {
                    target: t.to_string(),
                    blended: false,
                }),
                [_, t, "C_DIS"] => Ok(KrlOp::Lin {
                    target: t.to_string(),
                    blended: true,
                }),
                _ => Err(format!("expected `LIN name [C_DIS]`, got `{l}`")),
            };
        }
        Some("TRIGGER") => {
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
                .ok_or_else(|| format!("bad TRIGGER `{l}`"))?;
            return Ok(KrlOp::Trigger {
                distance,
                action: action.trim().to_string(),
            });
        }
        Some(b) if b.starts_with("BAS") => {
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
                        "#TOOL" => return Ok(KrlOp::Tool(int()?)),
                        "#BASE" => return Ok(KrlOp::Base(int()?)),
                        "#VEL_PTP" => {
                            let v: f64 = n
                                .parse()
                                .ok()
                                .filter(|v: &f64| *v > 0.0 && *v <= 100.0)
                                .ok_or_else(|| format!("bad #VEL_PTP `{n}`"))?;
                            return Ok(KrlOp::VelPtp(v));
                        }
                        _ => {}
                    }
                }
            }
        }
        _ => {}
    }
    if let Some((k, v)) = l.split_once('=') {
        let (k, v) = (k.trim(), v.trim());
        match k {
            "$VEL.CP" => {
                let x: f64 = v
                    .parse()
                    .ok()
                    .filter(|x: &f64| x.is_finite() && *x > 0.0)
                    .ok_or_else(|| format!("bad $VEL.CP `{v}`"))?;
                return Ok(KrlOp::VelCp(x));
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
                return Ok(KrlOp::VelExtax { axis, percent });
            }
            "$IPO_MODE" => {
                return match v {
                    "#TCP" => Ok(KrlOp::IpoTcp(true)),
                    "#BASE" => Ok(KrlOp::IpoTcp(false)),
                    _ => Err(format!("bad $IPO_MODE `{v}`")),
                };
            }
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
                return Ok(if k == "$TOOL" {
                    KrlOp::Tool(n)
                } else {
                    KrlOp::Base(n)
                });
            }
            _ => {}
        }
    }
    Ok(KrlOp::Other(l.to_string()))
}

fn parse_dat(text: &str, file: &str) -> Result<(String, Vec<KrlPosition>), ProgramError> {
    let name_of = |rest: &str| rest.split_whitespace().next().unwrap_or("").to_string();
    parse_block(text, file, ("DEFDAT", "name", "ENDDAT"), name_of, |l, n| {
        Ok(KrlPosition {
            line: n,
            ..parse_decl(l)?
        })
    })
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
