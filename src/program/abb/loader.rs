//! The main module of an ABB build cut into part modules (stage 7, a
//! build larger than [`AbbOptions::max_file_bytes`]): takes the build's
//! name and its groups' names and gives `MODULE MOD_<name>` whose entry
//! routine `PROC <name>()` loads each part module in turn, runs it and
//! unloads it; and reads such a module back into the order it loads them.
//!
//! For part `k` (RAPID Instructions manual 3HAC050917, `StartLoad`,
//! `WaitLoad`, `UnLoad`; RAPID overview 3HAC050947 §1.2, late binding):
//!
//! ```text
//! StartLoad \Dynamic, "HOME:/NAME_P01.mod", ldWaam;   ! start loading the part module
//! WaitLoad ldWaam;                                     ! wait until it is loaded and linked
//! %"NAME_P01"%;                                        ! late-bound call of its entry routine
//! UnLoad "HOME:/NAME_P01.mod";                         ! free its memory before the next
//! ```
//!
//! The call is late-bound (`%"…"%`, the routine's name as a string): the
//! part's routine does not exist when the main module is loaded and linked,
//! so a direct call would not link. `\Dynamic` makes the part a dynamic
//! module (unloaded by the controller when the program pointer is moved to
//! `main`, so a stopped build leaves nothing behind). Exactly one part
//! module is resident at a time beside this small module: each part is
//! within the budget alone. Loading waits with the robot at home and the
//! arc off (each part ends and starts there).

use crate::program::abb::{module_name, AbbOptions};
use crate::program::validate::{push, ProblemKind, ValidationReport};
use crate::program::{EmittedFile, ProgramError};

/// The `loadsession` variable of the main module.
pub const LOAD_SESSION: &str = "ldWaam";

/// Longest RAPID `string` (characters): a file path in `StartLoad` must fit.
pub const RAPID_STRING_MAX: usize = 80;

/// The controller path of part module `part` (`<load_path>/<part>.mod`).
pub fn part_path(opts: &AbbOptions, part: &str) -> String {
    format!("{}/{part}.mod", opts.load_path.trim_end_matches('/'))
}

/// The main module `<name>.mod` of a build of part modules `parts` (in
/// order): module doc.
///
/// # Errors
/// [`ProgramError::InvalidOptions`] (field `load_path`) when a part's path
/// is longer than a RAPID string ([`RAPID_STRING_MAX`]).
pub fn loader_file(
    name: &str,
    parts: &[String],
    opts: &AbbOptions,
) -> Result<EmittedFile, ProgramError> {
    let mut text = String::new();
    let mut line = |s: String| {
        text.push_str(&s);
        text.push('\n');
    };
    line(format!("MODULE {}", module_name(name)));
    line(format!(
        "  ! waam-slicer: the build in {} part modules (max_file_bytes {}), each loaded, run and unloaded in turn",
        parts.len(),
        opts.max_file_bytes
    ));
    line(format!(
        "  ! entry routine {name} (call it from the task's main); copy the part modules to {}",
        opts.load_path
    ));
    line(format!("  LOCAL VAR loadsession {LOAD_SESSION};"));
    line(format!("  PROC {name}()"));
    for part in parts {
        let path = part_path(opts, part);
        if path.len() > RAPID_STRING_MAX {
            return Err(ProgramError::InvalidOptions {
                field: "load_path",
                value: path,
                reason: "a part module's path must fit a RAPID string (80 characters)",
            });
        }
        line(format!(
            "    StartLoad \\Dynamic, \"{path}\", {LOAD_SESSION};"
        ));
        line(format!("    WaitLoad {LOAD_SESSION};"));
        line(format!("    %\"{part}\"%;"));
        line(format!("    UnLoad \"{path}\";"));
    }
    line("  ENDPROC".into());
    line("ENDMODULE".into());
    Ok(EmittedFile {
        name: format!("{name}.mod"),
        text,
    })
}

/// One part of a main module read back: what it loads, waits for, calls
/// and unloads, with the line of its `StartLoad`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct LoadedPart {
    /// The path of `StartLoad`.
    pub path: String,
    /// The routine called (`%"name"%`).
    pub routine: String,
    /// File line of `StartLoad` (1-based).
    pub line: usize,
}

/// `true` when `text` is a main module of part modules (it has a
/// `StartLoad`).
pub fn is_loader(text: &str) -> bool {
    text.lines()
        .any(|l| l.trim_start().starts_with("StartLoad"))
}

/// The file name (last path component) of a controller path.
pub fn path_file(path: &str) -> &str {
    path.rsplit(['/', '\\', ':']).next().unwrap_or(path)
}

/// Reads a main module back: the parts in the order it loads them, each
/// checked to be `StartLoad` → `WaitLoad` of the same session → the
/// late-bound call → `UnLoad` of the same path; what does not follow that
/// order, or a line it does not know, is a problem in `report`.
pub fn read_loader(file: &EmittedFile, report: &mut ValidationReport) -> Vec<LoadedPart> {
    let f = file.name.as_str();
    let mut parts: Vec<LoadedPart> = Vec::new();
    // 0: expect StartLoad, 1: WaitLoad, 2: call, 3: UnLoad
    let mut stage = 0;
    let mut session = String::new();
    let quoted = |s: &str| -> Option<String> {
        let a = s.find('"')?;
        let b = s[a + 1..].find('"')? + a + 1;
        Some(s[a + 1..b].to_string())
    };
    for (i, raw) in file.text.lines().enumerate() {
        let n = i + 1;
        let l = raw.trim();
        let mut bad = |msg: String| push(report, ProblemKind::Call, f, n, msg);
        if l.is_empty()
            || l.starts_with('!')
            || l.starts_with("MODULE ")
            || l == "ENDMODULE"
            || l == "ENDPROC"
            || (l.starts_with("PROC ") && l.ends_with("()"))
        {
            if l == "ENDPROC" && stage != 0 {
                bad("the routine ends before the last part module is run and unloaded".into());
            }
            continue;
        }
        if let Some(rest) = l.strip_prefix("LOCAL VAR loadsession ") {
            session = rest.trim_end_matches(';').trim().to_string();
            continue;
        }
        if let Some(rest) = l.strip_prefix("StartLoad") {
            if stage != 0 {
                bad("StartLoad before the previous part module was run and unloaded".into());
            }
            let Some(path) = quoted(rest) else {
                bad("StartLoad without a quoted file path".into());
                continue;
            };
            let sess = rest
                .rsplit(',')
                .next()
                .unwrap_or("")
                .trim_end_matches(';')
                .trim();
            if sess != session || session.is_empty() {
                bad(format!(
                    "StartLoad into `{sess}`, not the module's loadsession `{session}`"
                ));
            }
            parts.push(LoadedPart {
                path,
                routine: String::new(),
                line: n,
            });
            stage = 1;
        } else if let Some(rest) = l.strip_prefix("WaitLoad ") {
            if stage != 1 || rest.trim_end_matches(';').trim() != session {
                bad("WaitLoad not right after the StartLoad of its loadsession".into());
            }
            stage = 2;
        } else if l.starts_with('%') {
            let routine = quoted(l).unwrap_or_default();
            match parts.last_mut() {
                Some(p) if stage == 2 => p.routine = routine,
                _ => bad(format!(
                    "call of `{routine}` before its module is loaded (WaitLoad)"
                )),
            }
            stage = 3;
        } else if let Some(rest) = l.strip_prefix("UnLoad ") {
            let path = quoted(rest).unwrap_or_default();
            match parts.last() {
                Some(p) if stage == 3 && p.path == path => {}
                _ => bad(format!(
                    "UnLoad \"{path}\" is not of the part module just run"
                )),
            }
            stage = 0;
        } else {
            bad(format!(
                "`{l}`: not an instruction of a waam-slicer main module"
            ));
        }
    }
    parts
}
