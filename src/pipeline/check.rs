//! Checking a program file against a cell in one call: the program's
//! vendor from the extension, its files read from disk as that vendor's
//! [`Controller`](crate::program::contract::Controller) says (a FANUC main
//! program's `CALL`s followed, a KUKA `.src` with its `.dat`, the groups
//! of a build cut to the memory budget in order), then
//! validated for joint limits, speeds, reachability, configuration and
//! beads (SPEC §8).

use std::path::Path as FsPath;

use super::Cell;
use crate::program::registry::{
    check_files, files_on_disk, is_main_extension, main_extensions_text,
};
use crate::program::split::parse_group_name;
use crate::program::validate::ValidationReport;
use crate::program::ProgramError;
use crate::Error;

/// Reads the program at `path` — a FANUC `.ls` main program (the
/// sub-programs it calls are read from the same folder), a KUKA `.src` or
/// `.dat` (its pair beside it) or an ABB `.mod` (with the part modules a
/// main module loads); for a build cut to the controller's memory budget,
/// any of its groups `NAME_P01`, `NAME_P02`, … (or `NAME` itself) brings
/// all of them, checked as one build; a folder holding one program (as
/// `plan` writes it) stands for that program — and validates it against
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
    let path = if path.is_dir() {
        program_in_folder(path)?
    } else {
        path.to_path_buf()
    };
    let (vendor, files) = files_on_disk(&path)?;
    Ok(check_files(
        vendor,
        &files,
        &cell.layout,
        &cell.program,
        None,
    )?)
}

/// The one program in folder `dir`: its files of a main extension
/// ([`is_main_extension`]: `.ls`, `.src` or `.mod`),
/// their group suffix set aside ([`parse_group_name`]), must name one program; its main file
/// (`NAME`, else its first group).
///
/// # Errors
/// [`ProgramError::Read`] naming the folder when it holds no program or
/// several.
fn program_in_folder(dir: &FsPath) -> Result<std::path::PathBuf, ProgramError> {
    let read_error = |reason: String| ProgramError::Read {
        file: dir.display().to_string(),
        line: 0,
        reason,
    };
    let entries = std::fs::read_dir(dir).map_err(|e| read_error(format!("cannot list: {e}")))?;
    let mut files: Vec<(String, std::path::PathBuf)> = Vec::new();
    for entry in entries.flatten() {
        let path = entry.path();
        let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("");
        if !is_main_extension(ext) {
            continue;
        }
        let Some(stem) = path.file_stem().and_then(|s| s.to_str()) else {
            continue;
        };
        files.push((stem.to_string(), path));
    }
    files.sort();
    // a build's groups NAME_P01, NAME_P02, … are one program
    let base = |stem: &str| -> String {
        parse_group_name(stem)
            .map_or(stem, |(name, _)| name)
            .to_string()
    };
    let mut names: Vec<String> = files.iter().map(|(s, _)| base(s)).collect();
    names.sort();
    names.dedup();
    match names.as_slice() {
        [] => Err(read_error(format!(
            "no program file ({}) in this folder",
            main_extensions_text()
        ))),
        [name] => Ok(files
            .iter()
            .find(|(s, _)| s == name)
            .unwrap_or(&files[0])
            .1
            .clone()),
        several => Err(read_error(format!(
            "{} programs in this folder ({}): name the one to check",
            several.len(),
            several.join(", ")
        ))),
    }
}
