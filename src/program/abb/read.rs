//! Reader of our own ABB RAPID output (the subset
//! [`write_mod`](crate::program::abb::write_mod) writes): the declarations
//! (`[LOCAL|TASK] PERS|CONST|VAR type name := value;`: tool, work object,
//! `seamdata`, `welddata`, `loaddata`, `robtarget`s and `jointtarget`s), the
//! routines (`[LOCAL] PROC name()`), and the motion, process, wait, payload
//! and mechanical-unit (`ActUnit`, `DeactUnit`) instructions of the
//! routines. Errors name the file and line; a module without `ENDMODULE`
//! (truncated) and `LOCAL` inside a routine (RAPID allows it at module
//! level only) are errors.

use crate::math::{Isometry3, Point3, Vector3};
use crate::program::ProgramError;
use crate::robot::orientation::rotation_from_abb_quaternion;

/// A bracketed RAPID aggregate, parsed.
#[derive(Debug, Clone, PartialEq)]
pub enum Node {
    /// `[a, b, ...]`.
    List(Vec<Node>),
    /// A scalar as written (`1.5`, `TRUE`, `""`, `9E+09`).
    Atom(String),
}

impl Node {
    fn list(&self) -> Result<&[Node], String> {
        match self {
            Node::List(v) => Ok(v),
            Node::Atom(a) => Err(format!("expected `[...]`, got `{a}`")),
        }
    }

    fn num(&self) -> Result<f64, String> {
        match self {
            Node::Atom(a) => a
                .parse::<f64>()
                .ok()
                .filter(|x| x.is_finite())
                .ok_or_else(|| format!("bad number `{a}`")),
            Node::List(_) => Err("expected a number, got `[...]`".into()),
        }
    }

    fn bool(&self) -> Result<bool, String> {
        match self {
            Node::Atom(a) if a == "TRUE" => Ok(true),
            Node::Atom(a) if a == "FALSE" => Ok(false),
            _ => Err("expected TRUE or FALSE".into()),
        }
    }

    fn nums<const N: usize>(&self) -> Result<[f64; N], String> {
        let v = self.list()?;
        if v.len() != N {
            return Err(format!("expected {N} values, got {}", v.len()));
        }
        let mut out = [0.0; N];
        for (o, n) in out.iter_mut().zip(v) {
            *o = n.num()?;
        }
        Ok(out)
    }

    /// A pose `[[x, y, z], [q1, q2, q3, q4]]` (mm, quaternion `w x y z`).
    fn pose(&self) -> Result<Isometry3, String> {
        let v = self.list()?;
        if v.len() != 2 {
            return Err("expected `[[x,y,z],[q1,q2,q3,q4]]`".into());
        }
        pose_of(&v[0], &v[1])
    }
}

fn pose_of(t: &Node, q: &Node) -> Result<Isometry3, String> {
    let t = t.nums::<3>()?;
    let q = q.nums::<4>()?;
    let n = (q.iter().map(|x| x * x).sum::<f64>()).sqrt();
    if (n - 1.0).abs() > 1e-4 {
        return Err(format!("quaternion of norm {n:.6}, not 1"));
    }
    let r = rotation_from_abb_quaternion(q).ok_or("bad quaternion")?;
    Ok(Isometry3::from_parts(
        nalgebra::Translation3::from(Vector3::new(t[0], t[1], t[2])),
        nalgebra::UnitQuaternion::from_rotation_matrix(&r),
    ))
}

/// Deepest nesting of brackets accepted in an aggregate: the RAPID data
/// written here nest three deep (`tooldata`); a deeper one is refused
/// before the recursive parser could overflow its stack.
pub const MAX_AGGREGATE_DEPTH: usize = 16;

/// Parses one aggregate `[...]` (the whole of `s`).
///
/// # Errors
/// A message saying what is malformed, or that brackets nest deeper than
/// [`MAX_AGGREGATE_DEPTH`].
pub fn parse_aggregate(s: &str) -> Result<Node, String> {
    let chars: Vec<char> = s.trim().chars().collect();
    let mut depth = 0usize;
    for c in &chars {
        match c {
            '[' => {
                depth += 1;
                if depth > MAX_AGGREGATE_DEPTH {
                    return Err(format!(
                        "brackets nest more than {MAX_AGGREGATE_DEPTH} deep"
                    ));
                }
            }
            ']' => depth = depth.saturating_sub(1),
            _ => {}
        }
    }
    let mut i = 0;
    let n = parse_node(&chars, &mut i)?;
    if i != chars.len() {
        return Err(format!("text after the aggregate: `{}`", s.trim()));
    }
    Ok(n)
}

fn parse_node(c: &[char], i: &mut usize) -> Result<Node, String> {
    while *i < c.len() && c[*i].is_whitespace() {
        *i += 1;
    }
    if c.get(*i) == Some(&'[') {
        *i += 1;
        let mut items = Vec::new();
        loop {
            items.push(parse_node(c, i)?);
            while *i < c.len() && c[*i].is_whitespace() {
                *i += 1;
            }
            match c.get(*i) {
                Some(',') => *i += 1,
                Some(']') => {
                    *i += 1;
                    return Ok(Node::List(items));
                }
                _ => return Err("unbalanced `[`".into()),
            }
        }
    }
    let start = *i;
    while *i < c.len() && !matches!(c[*i], ',' | ']' | '[') {
        *i += 1;
    }
    let a: String = c[start..*i].iter().collect::<String>().trim().to_string();
    if a.is_empty() {
        return Err("empty value".into());
    }
    Ok(Node::Atom(a))
}

/// Splits at the commas outside brackets and quotes.
fn split_top(s: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut depth = 0i32;
    let mut quoted = false;
    let mut cur = String::new();
    for ch in s.chars() {
        match ch {
            '"' => quoted = !quoted,
            '[' if !quoted => depth += 1,
            ']' if !quoted => depth -= 1,
            ',' if depth == 0 && !quoted => {
                out.push(cur.trim().to_string());
                cur.clear();
                continue;
            }
            _ => {}
        }
        cur.push(ch);
    }
    out.push(cur.trim().to_string());
    out
}

/// A `tooldata` or `wobjdata` declaration.
#[derive(Debug, Clone, PartialEq)]
pub struct RapidFrame {
    /// Name.
    pub name: String,
    /// Declaration line.
    pub line: usize,
    /// `robhold`.
    pub robhold: bool,
    /// `tframe` (tool) or `uframe · oframe` (work object) (mm).
    pub pose: Isometry3,
    /// Work object: `ufprog` (`true` for a tool).
    pub ufprog: bool,
    /// Work object: `ufmec`, the mechanical unit moving it, unquoted (`""`
    /// for a tool).
    pub ufmec: String,
    /// Work object: `oframe` (mm; the identity for a tool).
    pub oframe: Isometry3,
    /// Tool: `tload` (`None` for a work object).
    pub load: Option<RapidLoad>,
}

/// A `loaddata` value: `[mass, cog, aom, ix, iy, iz]`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RapidLoad {
    /// Mass (kg).
    pub mass_kg: f64,
    /// Centre of gravity (mm), in the frame RAPID defines for its use.
    pub cog_mm: Point3,
    /// Axes of moment (quaternion `w x y z`).
    pub aom: [f64; 4],
    /// Moments of inertia `ix iy iz` (kg·m²).
    pub inertia_kg_m2: [f64; 3],
}

/// A `welddata` declaration (RobotWare 6 Arc: `[weld_speed,
/// org_weld_speed, main_arc, org_arc]`).
#[derive(Debug, Clone, PartialEq)]
pub struct RapidWeld {
    /// Name.
    pub name: String,
    /// Line.
    pub line: usize,
    /// `weld_speed` (mm/s).
    pub weld_speed_mm_s: f64,
    /// `main_arc.sched`.
    pub sched: f64,
    /// `main_arc.wirefeed` (m/min, RobotWare Arc's SI unit; module doc of
    /// [`abb`](crate::program::abb)).
    pub wirefeed_m_min: f64,
}

/// A `seamdata` declaration (RobotWare 6 Arc, 16 components): its gas
/// times.
#[derive(Debug, Clone, PartialEq)]
pub struct RapidSeam {
    /// Name.
    pub name: String,
    /// Line.
    pub line: usize,
    /// `purge_time` (s), component 1.
    pub purge_time_s: f64,
    /// `preflow_time` (s), component 2.
    pub preflow_time_s: f64,
    /// `postflow_time` (s), component 16.
    pub postflow_time_s: f64,
}

/// A routine: `[LOCAL] PROC name()`.
#[derive(Debug, Clone, PartialEq)]
pub struct RapidRoutine {
    /// Name.
    pub name: String,
    /// `true` when declared `LOCAL`.
    pub local: bool,
    /// Line of `PROC`.
    pub line: usize,
}

/// Any declaration: storage class, type and name.
#[derive(Debug, Clone, PartialEq)]
pub struct RapidDecl {
    /// `PERS`, `CONST` or `VAR`.
    pub storage: String,
    /// `LOCAL` or `TASK` if written.
    pub scope: Option<String>,
    /// Data type.
    pub ty: String,
    /// Name.
    pub name: String,
    /// Line.
    pub line: usize,
}

/// A target.
#[derive(Debug, Clone, PartialEq)]
pub enum RapidTargetValue {
    /// `robtarget`: pose (mm) and `confdata`.
    Rob {
        /// `[[x,y,z],[q1..q4]]` as a transform (mm).
        pose: Isometry3,
        /// `[cf1, cf4, cf6, cfx]`.
        conf: [i32; 4],
    },
    /// `jointtarget` (deg).
    Joint([f64; 6]),
}

/// A `CONST robtarget` / `CONST jointtarget`.
#[derive(Debug, Clone, PartialEq)]
pub struct RapidTarget {
    /// Name.
    pub name: String,
    /// Line.
    pub line: usize,
    /// Value.
    pub value: RapidTargetValue,
    /// External axes `eax_a` .. `eax_f` (deg), `None` where `9E+09`.
    pub external: [Option<f64>; 6],
}

/// The tool and work object arguments of a motion (`tWaam\\WObj:=wWaam`).
#[derive(Debug, Clone, PartialEq)]
pub struct ToolArg {
    /// The tool.
    pub tool: String,
    /// The work object, if given.
    pub wobj: Option<String>,
}

/// One instruction of a routine.
#[derive(Debug, Clone, PartialEq)]
pub enum RapidOp {
    /// `MoveAbsJ target, speed, zone, tool\WObj:=wobj`.
    MoveAbsJ {
        /// Target.
        target: String,
        /// Zone (`fine`, `z1`).
        zone: String,
        /// Tool and work object.
        tool: ToolArg,
    },
    /// `MoveL`, `ArcLStart`, `ArcL`, `ArcLEnd`, or the circular `MoveC`,
    /// `ArcC`, `ArcCEnd` (circle point first): instruction name, target and
    /// `v_tcp` (mm/s).
    Linear {
        /// `MoveL`, `ArcLStart`, `ArcL`, `ArcLEnd`, `MoveC`, `ArcC` or
        /// `ArcCEnd`.
        instruction: String,
        /// The circle point (`CirPoint`) of a circular instruction.
        via: Option<String>,
        /// Target.
        target: String,
        /// `v_tcp` of the speeddata (mm/s).
        speed_mm_s: f64,
        /// `v_reax` of the speeddata (°/s).
        v_reax_deg_s: f64,
        /// Seam data name for arc instructions (`seamWaam`).
        seam: Option<String>,
        /// Weld data name for arc instructions (`weldWaam1`).
        weld: Option<String>,
        /// The move's time (s) when the speed argument carries `\T:=t`.
        time_s: Option<f64>,
        /// Zone (`fine`, `z1`).
        zone: String,
        /// Tool and work object.
        tool: ToolArg,
    },
    /// `ConfL \On` (`true`) or `\Off`.
    ConfL(bool),
    /// `CirPathMode \Mode`: how circular moves reorient the tool (the
    /// switch's name without its `\`).
    CirPathMode(String),
    /// `WaitTime s` (s).
    WaitTime(f64),
    /// `WaitDI signal, value`.
    WaitDi {
        /// The signal.
        signal: String,
        /// The awaited value (0 or 1).
        value: u8,
    },
    /// `GripLoad load`.
    GripLoad(String),
    /// `ActUnit unit`: the mechanical unit.
    ActUnit(String),
    /// `DeactUnit unit`: the mechanical unit.
    DeactUnit(String),
    /// Any other statement, as written without `;`.
    Other(String),
}

/// An instruction with its line.
#[derive(Debug, Clone, PartialEq)]
pub struct RapidInstruction {
    /// Line.
    pub line: usize,
    /// Instruction.
    pub op: RapidOp,
}

/// A RAPID module as read.
#[derive(Debug, Clone, PartialEq)]
pub struct RapidModule {
    /// Module name.
    pub name: String,
    /// Line of `MODULE`.
    pub line: usize,
    /// File name (for messages).
    pub file: String,
    /// The (last) `tooldata` declared.
    pub tool: Option<RapidFrame>,
    /// The (last) `wobjdata` declared.
    pub wobj: Option<RapidFrame>,
    /// Targets.
    pub targets: Vec<RapidTarget>,
    /// `welddata` declarations.
    pub welds: Vec<RapidWeld>,
    /// `loaddata` declarations: name, line, value.
    pub loads: Vec<(String, usize, RapidLoad)>,
    /// `seamdata` declarations.
    pub seams: Vec<RapidSeam>,
    /// Every data declaration at module level, in order.
    pub declarations: Vec<RapidDecl>,
    /// The routines, in order (the format has one: the entry routine).
    pub routines: Vec<RapidRoutine>,
    /// The routines' instructions, in file order.
    pub instructions: Vec<RapidInstruction>,
}

impl RapidModule {
    /// The declaration of `name`, if any.
    pub fn declaration(&self, name: &str) -> Option<&RapidDecl> {
        self.declarations.iter().find(|d| d.name == name)
    }
}

/// Parses one `.mod` written by [`write_mod`](crate::program::abb::write_mod).
///
/// # Errors
/// [`ProgramError::Read`] with the line: missing `MODULE`, bad declaration
/// or instruction, and a file ending before `ENDMODULE`.
pub fn parse_mod(text: &str, file: &str) -> Result<RapidModule, ProgramError> {
    let err = |line: usize, reason: String| ProgramError::Read {
        file: file.into(),
        line,
        reason,
    };
    let mut m = RapidModule {
        name: String::new(),
        line: 0,
        file: file.into(),
        tool: None,
        wobj: None,
        targets: Vec::new(),
        welds: Vec::new(),
        loads: Vec::new(),
        seams: Vec::new(),
        declarations: Vec::new(),
        routines: Vec::new(),
        instructions: Vec::new(),
    };
    let mut names = std::collections::HashSet::new();
    let mut started = false;
    // the routine being read
    let mut in_proc: Option<String> = None;
    let mut ended = false;
    let mut last = 0;
    for (i, raw) in text.lines().enumerate() {
        let n = i + 1;
        last = n;
        let l = raw.trim();
        if l.is_empty() || l.starts_with('!') {
            continue;
        }
        if ended {
            return Err(err(n, "text after ENDMODULE".into()));
        }
        if !started {
            let name = l
                .strip_prefix("MODULE ")
                .ok_or_else(|| err(n, format!("expected `MODULE name`, got `{l}`")))?;
            m.name = name.trim().to_string();
            m.line = n;
            started = true;
            continue;
        }
        if l == "ENDMODULE" {
            if let Some(p) = &in_proc {
                return Err(err(n, format!("ENDMODULE inside PROC {p} (no ENDPROC)")));
            }
            ended = true;
            continue;
        }
        let (local, rest) = match l.strip_prefix("LOCAL ") {
            Some(r) => (true, r.trim_start()),
            None => (false, l),
        };
        if let Some(head) = rest.strip_prefix("PROC ") {
            if let Some(p) = &in_proc {
                return Err(err(n, format!("PROC inside PROC {p} (no ENDPROC)")));
            }
            let name = head
                .trim()
                .strip_suffix("()")
                .map(str::trim_end)
                .filter(|s| crate::program::abb::is_rapid_name(s))
                .ok_or_else(|| err(n, format!("expected `[LOCAL] PROC name()`, got `{l}`")))?;
            if !names.insert(name.to_string()) {
                return Err(err(n, format!("`{name}` is declared twice")));
            }
            m.routines.push(RapidRoutine {
                name: name.to_string(),
                local,
                line: n,
            });
            in_proc = Some(name.to_string());
            continue;
        }
        if l == "ENDPROC" {
            if in_proc.take().is_none() {
                return Err(err(n, "ENDPROC outside a routine".into()));
            }
            continue;
        }
        if local && in_proc.is_some() {
            return Err(err(
                n,
                "LOCAL inside a routine: RAPID allows it at module level only".into(),
            ));
        }
        let stmt = l
            .strip_suffix(';')
            .ok_or_else(|| err(n, "statement without `;`".into()))?
            .trim();
        if in_proc.is_some() {
            let op = parse_instruction(stmt).map_err(|r| err(n, r))?;
            m.instructions.push(RapidInstruction { line: n, op });
        } else {
            parse_declaration(stmt, n, &mut m, &mut names).map_err(|r| err(n, r))?;
        }
    }
    if !ended {
        let where_ = in_proc.map_or(String::new(), |p| format!(" inside PROC {p}"));
        return Err(err(
            last,
            format!("file ends{where_} without ENDMODULE (truncated?)"),
        ));
    }
    Ok(m)
}

/// Components of an `arcdata` inside `seamdata` and `welddata` (RobotWare 6
/// Arc): `[sched, mode, voltage, wirefeed, control, current, voltage2,
/// wirefeed2, control2]`.
const ARCDATA_LEN: usize = 9;

fn arcdata(n: &Node, what: &str) -> Result<[f64; ARCDATA_LEN], String> {
    n.nums::<ARCDATA_LEN>()
        .map_err(|e| format!("{what}: arcdata [sched, mode, voltage, wirefeed, control, current, voltage2, wirefeed2, control2]: {e}"))
}

fn loaddata(n: &Node) -> Result<RapidLoad, String> {
    let v = n.list()?;
    if v.len() != 6 {
        return Err("loaddata: expected [mass, [x,y,z], [q1,q2,q3,q4], ix, iy, iz]".into());
    }
    let mass_kg = v[0].num()?;
    let c = v[1].nums::<3>()?;
    let aom = v[2].nums::<4>()?;
    let inertia_kg_m2 = [v[3].num()?, v[4].num()?, v[5].num()?];
    if mass_kg < 0.0 || inertia_kg_m2.iter().any(|i| *i < 0.0) {
        return Err("loaddata: negative mass or inertia".into());
    }
    Ok(RapidLoad {
        mass_kg,
        cog_mm: Point3::new(c[0], c[1], c[2]),
        aom,
        inertia_kg_m2,
    })
}

fn parse_declaration(
    stmt: &str,
    line: usize,
    m: &mut RapidModule,
    names: &mut std::collections::HashSet<String>,
) -> Result<(), String> {
    let (head, value) = stmt
        .split_once(":=")
        .ok_or_else(|| format!("expected a declaration `... := [...]`, got `{stmt}`"))?;
    let words: Vec<&str> = head.split_whitespace().collect();
    let (scope, storage, ty, name) = match words.as_slice() {
        [s @ ("LOCAL" | "TASK"), st, ty, name] => (Some(s.to_string()), *st, *ty, *name),
        [st, ty, name] => (None, *st, *ty, *name),
        _ => return Err(format!("bad declaration `{head}`")),
    };
    if !matches!(storage, "PERS" | "CONST" | "VAR") {
        return Err(format!(
            "bad declaration `{head}`: PERS, CONST or VAR expected"
        ));
    }
    if !names.insert(name.to_string()) {
        return Err(format!("`{name}` is declared twice"));
    }
    let v = parse_aggregate(value)?;
    let items = v.list()?;
    let ext = |n: &Node| -> Result<[Option<f64>; 6], String> {
        Ok(n.nums::<6>()?.map(|e| (e < 8.9e9).then_some(e)))
    };
    match ty {
        "tooldata" => {
            if items.len() != 3 {
                return Err("tooldata: expected [robhold, tframe, tload]".into());
            }
            m.tool = Some(RapidFrame {
                name: name.to_string(),
                line,
                robhold: items[0].bool()?,
                pose: items[1].pose()?,
                ufprog: true,
                ufmec: String::new(),
                oframe: Isometry3::identity(),
                load: Some(loaddata(&items[2]).map_err(|e| format!("tooldata tload: {e}"))?),
            });
        }
        "wobjdata" => {
            if items.len() != 5 {
                return Err("wobjdata: expected [robhold, ufprog, ufmec, uframe, oframe]".into());
            }
            let ufmec = match &items[2] {
                Node::Atom(a) if a.len() >= 2 && a.starts_with('"') && a.ends_with('"') => {
                    a[1..a.len() - 1].to_string()
                }
                _ => return Err("wobjdata: ufmec must be a string".into()),
            };
            let oframe = items[4].pose()?;
            m.wobj = Some(RapidFrame {
                name: name.to_string(),
                line,
                robhold: items[0].bool()?,
                pose: items[3].pose()? * oframe,
                ufprog: items[1].bool()?,
                ufmec,
                oframe,
                load: None,
            });
        }
        "seamdata" => {
            // RobotWare 6 Arc: 16 components, arcdata at 2, 8, 11, 14
            if items.len() != 16 {
                return Err(format!(
                    "seamdata: expected 16 components (RobotWare 6 Arc), got {}",
                    items.len()
                ));
            }
            for (k, it) in items.iter().enumerate() {
                if matches!(k, 2 | 8 | 11 | 14) {
                    arcdata(it, "seamdata")?;
                } else {
                    it.num()?;
                }
            }
            m.seams.push(RapidSeam {
                name: name.to_string(),
                line,
                purge_time_s: items[0].num()?,
                preflow_time_s: items[1].num()?,
                postflow_time_s: items[15].num()?,
            });
        }
        "welddata" => {
            if items.len() != 4 {
                return Err(
                    "welddata: expected [weld_speed, org_weld_speed, main_arc, org_arc] (RobotWare 6 Arc)"
                        .into(),
                );
            }
            let weld_speed_mm_s = items[0].num()?;
            items[1].num()?;
            let main = arcdata(&items[2], "welddata main_arc")?;
            arcdata(&items[3], "welddata org_arc")?;
            m.welds.push(RapidWeld {
                name: name.to_string(),
                line,
                weld_speed_mm_s,
                sched: main[0],
                wirefeed_m_min: main[3],
            });
        }
        "loaddata" => m.loads.push((name.to_string(), line, loaddata(&v)?)),
        "robtarget" => {
            if items.len() != 4 {
                return Err("robtarget: expected [trans, rot, robconf, extax]".into());
            }
            let c = items[2].nums::<4>()?;
            if c.iter().any(|x| x.fract() != 0.0) {
                return Err("confdata: not integers".into());
            }
            m.targets.push(RapidTarget {
                name: name.to_string(),
                line,
                value: RapidTargetValue::Rob {
                    pose: pose_of(&items[0], &items[1])?,
                    conf: c.map(|x| x as i32),
                },
                external: ext(&items[3])?,
            });
        }
        "jointtarget" => {
            if items.len() != 2 {
                return Err("jointtarget: expected [robax, extax]".into());
            }
            m.targets.push(RapidTarget {
                name: name.to_string(),
                line,
                value: RapidTargetValue::Joint(items[0].nums::<6>()?),
                external: ext(&items[1])?,
            });
        }
        _ => return Err(format!("unsupported type `{ty}`")),
    }
    m.declarations.push(RapidDecl {
        storage: storage.to_string(),
        scope,
        ty: ty.to_string(),
        name: name.to_string(),
        line,
    });
    Ok(())
}

/// `tool\WObj:=wobj` (or `tool` alone).
fn tool_arg(a: &str) -> Result<ToolArg, String> {
    let (tool, wobj) = match a.split_once("\\WObj:=") {
        Some((t, w)) => (t.trim(), Some(w.trim().to_string())),
        None => (a.trim(), None),
    };
    if tool.is_empty() || wobj.as_ref().is_some_and(|w| w.is_empty()) {
        return Err(format!("bad tool argument `{a}`"));
    }
    Ok(ToolArg {
        tool: tool.to_string(),
        wobj,
    })
}

fn parse_instruction(stmt: &str) -> Result<RapidOp, String> {
    if let Some(v) = stmt.strip_prefix("CirPathMode") {
        let mode = v.trim().strip_prefix('\\').unwrap_or("");
        return if !mode.is_empty() && mode.chars().all(|c| c.is_ascii_alphanumeric()) {
            Ok(RapidOp::CirPathMode(mode.to_string()))
        } else {
            Err(format!("bad `{stmt}`: expected `CirPathMode \\<switch>`"))
        };
    }
    if let Some(v) = stmt.strip_prefix("ConfL") {
        return match v.trim() {
            "\\On" => Ok(RapidOp::ConfL(true)),
            "\\Off" => Ok(RapidOp::ConfL(false)),
            _ => Err(format!("bad `{stmt}`")),
        };
    }
    let (name, rest) = stmt.split_once(' ').unwrap_or((stmt, ""));
    let args = split_top(rest);
    match name {
        "MoveAbsJ" => {
            if args.len() != 4 {
                return Err(format!(
                    "MoveAbsJ: expected target, speed, zone, tool: `{stmt}`"
                ));
            }
            Ok(RapidOp::MoveAbsJ {
                target: args[0].clone(),
                zone: args[2].clone(),
                tool: tool_arg(&args[3])?,
            })
        }
        "MoveL" | "ArcLStart" | "ArcL" | "ArcLEnd" | "MoveC" | "ArcC" | "ArcCEnd" => {
            let arc = !name.starts_with("Move");
            // `MoveC CirPoint, ToPoint, …`: one argument more, first
            let circular = matches!(name, "MoveC" | "ArcC" | "ArcCEnd");
            let via = circular.then(|| args.first().cloned()).flatten();
            let args = &args[usize::from(circular).min(args.len())..];
            let want = if arc { 6 } else { 4 };
            if args.len() != want {
                return Err(format!(
                    "{name}: expected {want} arguments, got {}",
                    args.len()
                ));
            }
            let (speed_arg, time_s) = match args[1].split_once("\\T:=") {
                Some((v, t)) => {
                    let t: f64 = t
                        .trim()
                        .parse()
                        .ok()
                        .filter(|t: &f64| t.is_finite() && *t > 0.0)
                        .ok_or_else(|| format!("{name}: bad \\T `{}`", t.trim()))?;
                    (v.trim().to_string(), Some(t))
                }
                None => (args[1].clone(), None),
            };
            let speed = parse_aggregate(&speed_arg)
                .and_then(|n| n.nums::<4>())
                .map_err(|e| format!("{name}: speeddata: {e}"))?;
            if !(speed[0] > 0.0) || !(speed[3] > 0.0) {
                return Err(format!(
                    "{name}: v_tcp {} and v_reax {} must be > 0",
                    speed[0], speed[3]
                ));
            }
            Ok(RapidOp::Linear {
                instruction: name.to_string(),
                via,
                target: args[0].clone(),
                speed_mm_s: speed[0],
                v_reax_deg_s: speed[3],
                seam: arc.then(|| args[2].clone()),
                weld: arc.then(|| args[3].clone()),
                time_s,
                zone: args[want - 2].clone(),
                tool: tool_arg(&args[want - 1])?,
            })
        }
        "WaitTime" => {
            let t: f64 = rest
                .trim()
                .parse()
                .ok()
                .filter(|t: &f64| t.is_finite() && *t >= 0.0)
                .ok_or_else(|| format!("WaitTime: bad time `{}`", rest.trim()))?;
            Ok(RapidOp::WaitTime(t))
        }
        "WaitDI" => match args.as_slice() {
            [signal, v] if !signal.is_empty() && (v == "0" || v == "1") => Ok(RapidOp::WaitDi {
                signal: signal.clone(),
                value: v.parse().expect("0 or 1"),
            }),
            _ => Err(format!("WaitDI: expected `signal, 0|1`: `{stmt}`")),
        },
        "GripLoad" => match args.as_slice() {
            [load] if !load.is_empty() && !load.contains(' ') => {
                Ok(RapidOp::GripLoad(load.clone()))
            }
            _ => Err(format!("GripLoad: expected one loaddata: `{stmt}`")),
        },
        "ActUnit" | "DeactUnit" => match args.as_slice() {
            [unit] if crate::program::abb::is_rapid_name(unit) => Ok(if name == "ActUnit" {
                RapidOp::ActUnit(unit.clone())
            } else {
                RapidOp::DeactUnit(unit.clone())
            }),
            _ => Err(format!("{name}: expected one mechanical unit: `{stmt}`")),
        },
        _ => Ok(RapidOp::Other(stmt.to_string())),
    }
}
