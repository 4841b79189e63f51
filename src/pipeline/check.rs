//! Checking a program file against a cell in one call: the program's
//! vendor from the extension, its files read from disk as that vendor's
//! [`Controller`](crate::program::contract::Controller) says (a FANUC main
//! program's `CALL`s followed, a KUKA `.src` with its `.dat`, the groups
//! of a build cut to the memory budget in order), then
//! validated for joint limits, speeds, reachability, configuration and
//! beads (SPEC §8).

use std::path::Path as FsPath;

use super::Cell;
use crate::program::contract::{check_files, files_on_disk};
use crate::program::fanuc::TpProgram;
use crate::program::validate::ValidationReport;
use crate::program::ProgramError;
use crate::Error;

/// Reads the program at `path` — a FANUC `.ls` main program (the
/// sub-programs it calls are read from the same folder), a KUKA `.src` or
/// `.dat` (its pair beside it) or an ABB `.mod` (with the part modules a
/// main module loads); for a build cut to the controller's memory budget,
/// any of its groups `NAME_P01`, `NAME_P02`, … (or `NAME` itself) brings
/// all of them, checked as one build — and validates it against
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
    let (vendor, files) = files_on_disk(path.as_ref())?;
    Ok(check_files(
        vendor,
        &files,
        &cell.layout,
        &cell.program,
        None,
    )?)
}

/// The FANUC program at `main` and every program it calls, read from the
/// same folder (`NAME.ls`), each once, in the order first called.
///
/// # Errors
/// [`ProgramError::Read`] naming the file (and the line for a parse error).
pub fn read_fanuc_with_calls(main: &FsPath) -> Result<Vec<TpProgram>, ProgramError> {
    use crate::program::contract::Controller;
    use crate::program::fanuc::Fanuc;
    Fanuc::read(&Fanuc::files_on_disk(main)?)
}
