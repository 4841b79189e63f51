//! Checking a program file against a cell in one call: reads it back with
//! the reader of its vendor (by extension), follows a FANUC main program's
//! `CALL`s, and validates joint limits, speeds, reachability, configuration
//! and beads (SPEC §8).

use std::path::{Path as FsPath, PathBuf};

use super::Cell;
use crate::program::fanuc::{Op, TpProgram};
use crate::program::readback::parse_ls;
use crate::program::validate::{validate_abb, validate_fanuc, validate_kuka, ValidationReport};
use crate::program::ProgramError;
use crate::Error;

/// Most sub-programs a FANUC main program may call (directly or not).
const MAX_CALLED_PROGRAMS: usize = 10_000;

fn read_text(path: &FsPath) -> Result<String, ProgramError> {
    std::fs::read_to_string(path).map_err(|e| ProgramError::Read {
        file: path.display().to_string(),
        line: 0,
        reason: format!("cannot read: {e}"),
    })
}

/// Reads the program at `path` — a FANUC `.ls` main program (the
/// sub-programs it calls are read from the same folder), a KUKA `.src` or
/// `.dat` (its pair beside it) or an ABB `.mod` — and validates it against
/// `cell`, with the emitter options and set-up (home, dwell, interpass
/// wait, payload, transit) of the cell file's `[program]` table. Problems
/// found are data: the report lists each with its `file:line`.
///
/// # Errors
/// [`ProgramError::Read`] naming the file and line when a file cannot be
/// read or parsed, or its extension names no known program type;
/// [`ProgramError::VendorMismatch`] is reported as a problem by the
/// validators, not as an error.
pub fn check_program(path: impl AsRef<FsPath>, cell: &Cell) -> Result<ValidationReport, Error> {
    let path = path.as_ref();
    let shown = |p: &FsPath| p.display().to_string();
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .unwrap_or("")
        .to_ascii_lowercase();
    let layout = &cell.layout;
    Ok(match ext.as_str() {
        "src" | "dat" => {
            let src = path.with_extension("src");
            let dat = path.with_extension("dat");
            let program = crate::program::readback::kuka::parse_krl(
                &read_text(&src)?,
                &shown(&src),
                &read_text(&dat)?,
                &shown(&dat),
            )?;
            validate_kuka(&program, layout, &cell.program.kuka(), None)
        }
        "mod" => {
            let module = crate::program::readback::abb::parse_mod(&read_text(path)?, &shown(path))?;
            validate_abb(&module, layout, &cell.program.abb(), None)
        }
        "ls" => {
            let programs = read_fanuc_with_calls(path)?;
            validate_fanuc(&programs, layout, &cell.program.fanuc(), None)
        }
        other => {
            return Err(ProgramError::Read {
                file: shown(path),
                line: 0,
                reason: format!(
                    "unknown program type `.{other}`; expected .ls (FANUC), .src/.dat (KUKA) or .mod (ABB)"
                ),
            }
            .into())
        }
    })
}

/// The FANUC program at `main` and every program it calls, read from the
/// same folder (`NAME.ls`), each once, in the order first called.
///
/// # Errors
/// [`ProgramError::Read`] naming the file (and the line for a parse error).
pub fn read_fanuc_with_calls(main: &FsPath) -> Result<Vec<TpProgram>, ProgramError> {
    let dir: PathBuf = main.parent().map(FsPath::to_path_buf).unwrap_or_default();
    let read = |p: &FsPath| parse_ls(&read_text(p)?, &p.display().to_string());
    let mut programs = vec![read(main)?];
    let mut k = 0;
    while k < programs.len() {
        let calls: Vec<String> = programs[k]
            .instructions
            .iter()
            .filter_map(|i| match &i.op {
                Op::Call(n) => Some(n.clone()),
                _ => None,
            })
            .collect();
        for called in calls {
            if !programs.iter().any(|p| p.name == called) {
                if programs.len() >= MAX_CALLED_PROGRAMS {
                    return Err(ProgramError::Read {
                        file: main.display().to_string(),
                        line: 0,
                        reason: format!("calls more than {MAX_CALLED_PROGRAMS} programs"),
                    });
                }
                programs.push(read(&dir.join(format!("{called}.ls")))?);
            }
        }
        k += 1;
    }
    Ok(programs)
}
