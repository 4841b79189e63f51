//! The one contract every robot controller's program format implements:
//! its options (from the cell file's `[program]` table), its emitter (a
//! [`Program`] to files), its reader (files back to the controller's own
//! program model) and its decoder (that model to the checker's [`DecodedStep`]s,
//! checked by the one [`check_steps`]).
//! Each vendor implements [`Controller`] in its own folder; the registry
//! ([`crate::program::registry`]) lists them and is the one place that
//! turns a [`Vendor`] into its implementation, so nothing else spells out
//! the vendor list.
//!
//! Each controller states its memory budget ([`Controller::budget`]); a
//! build over it is emitted as groups the cell runs in turn
//! ([`crate::program::split`]), and [`check_files`](crate::program::registry::check_files) reads such a set back
//! and checks it as one build ([`validate_build`]).

use std::path::Path;

use crate::program::cycle::CycleOptions;
use crate::program::split::{parse_group_name, Budget};
use crate::program::validate::{
    check_home_ends, check_steps, push, vendor_matches, DecodedStep, ProblemKind, ValidationReport,
};
use crate::program::{EmittedFile, PlannedPoint, Program, ProgramError, ProgramOptions};
use crate::robot::{CellLayout, Vendor};

/// A robot controller's program format: options, emit, read, decode.
///
/// The round trip `emit` → `read` → `validate` of a feasible program gives
/// a report without problems (tests/program/contract.rs, for every vendor).
pub trait Controller {
    /// The controller's vendor: only that vendor's arms are written or read.
    const VENDOR: Vendor;
    /// The vendor's key: its table in a cell file (`[program.<key>]`) and
    /// its name on the command line (`--format <key>`), lower case.
    const KEY: &'static str;
    /// The format's name in messages, e.g. `FANUC TP`.
    const EMITTER: &'static str;
    /// Extensions of the format's files, lower case without the dot; the
    /// first is the main (entry) file's.
    const EXTENSIONS: &'static [&'static str];
    /// The emitter's options: the cell file's `[program.<key>]` table.
    type Options: Clone
        + std::fmt::Debug
        + Default
        + PartialEq
        + serde::Serialize
        + serde::de::DeserializeOwned;
    /// The files read back: the controller's program model.
    type Read;

    /// The emitter's options `own` (its `[program.<key>]` table) with the
    /// vendor-neutral set-up `common` (the rest of the `[program]` table)
    /// set in.
    fn with_common(own: &Self::Options, common: &ProgramOptions) -> Self::Options;

    /// Checks the emitter's options (its own keys, not `common`).
    ///
    /// # Errors
    /// [`ProgramError::InvalidOptions`] naming the field.
    fn check_options(opts: &Self::Options) -> Result<(), ProgramError>;

    /// The options of the cycle time ([`crate::program::cycle`]) for this
    /// format: the joint moves' speed as the emitter writes them, the
    /// assumed path acceleration.
    fn cycle_options(opts: &Self::Options) -> CycleOptions;

    /// The vendor-neutral set-up inside the options.
    fn common(opts: &Self::Options) -> &ProgramOptions;

    /// The controller's memory budget for the programs resident at once
    /// (one group of a build cut into groups, [`crate::program::split`]).
    fn budget(opts: &Self::Options) -> Budget;

    /// What a set of files read back (`files`, read as `read`) occupies
    /// against [`Controller::budget`], in its unit.
    fn occupied(files: &[EmittedFile], read: &Self::Read) -> usize;

    /// The groups a build's files make, in the order the cell runs them
    /// (each a complete program); one group for a build in one piece.
    /// By default the files named `NAME_P01`, `NAME_P02`, … (any
    /// extension) make the groups ([`groups_by_name`]); a vendor whose
    /// build has a loader (ABB's main module) checks it here, adding its
    /// problems to `report`.
    ///
    /// # Errors
    /// [`ProgramError::Read`] naming a file that belongs to no group or a
    /// missing group.
    fn groups(
        files: &[EmittedFile],
        report: &mut ValidationReport,
    ) -> Result<Vec<Vec<EmittedFile>>, ProgramError> {
        let _ = report;
        let (rest, groups) = groups_by_name(files)?;
        if let (Some(f), false) = (rest.first(), groups.is_empty()) {
            return Err(ProgramError::Read {
                file: f.name.clone(),
                line: 0,
                reason: "not one of the build's groups (NAME_P01, NAME_P02, ...) read with it"
                    .into(),
            });
        }
        Ok(if groups.is_empty() {
            vec![rest]
        } else {
            groups
        })
    }

    /// The program's files, the main (entry) file first.
    ///
    /// # Errors
    /// [`ProgramError::VendorMismatch`] for another vendor's robot,
    /// [`ProgramError::InvalidOptions`] naming the field, and what the
    /// format cannot hold, named.
    fn emit(program: &Program, opts: &Self::Options) -> Result<Vec<EmittedFile>, ProgramError>;

    /// Reads files of this format (the main first; the others are what it
    /// calls or pairs with).
    ///
    /// # Errors
    /// [`ProgramError::Read`] naming the file and line.
    fn read(files: &[EmittedFile]) -> Result<Self::Read, ProgramError>;

    /// The files a program on disk is made of, starting from `path` (one of
    /// them): its pair, the programs it calls, read from the same folder.
    ///
    /// # Errors
    /// [`ProgramError::Read`] naming the file that cannot be read.
    fn files_on_disk(path: &Path) -> Result<Vec<EmittedFile>, ProgramError>;

    /// The file that problems about the whole program are reported against.
    fn main_file(read: &Self::Read) -> &str;

    /// Decodes the program into the checker's steps in execution order,
    /// adding what is wrong with the files themselves to `report`; `None`
    /// when the options cannot be used to decode (the problem is in
    /// `report`).
    fn steps(
        read: &Self::Read,
        cell: &CellLayout,
        opts: &Self::Options,
        report: &mut ValidationReport,
    ) -> Option<Vec<DecodedStep>>;

    /// Validates a program read back against `cell`: the vendor, the
    /// files, then every step ([`check_steps`]). `planned`: the planned
    /// deposition points of the bead motions (part frame, mm), when known.
    fn validate(
        read: &Self::Read,
        cell: &CellLayout,
        opts: &Self::Options,
        planned: Option<&[PlannedPoint]>,
    ) -> ValidationReport
    where
        Self: Sized,
    {
        validate_decoded::<Self>(cell, Self::main_file(read), opts, planned, |report| {
            Self::steps(read, cell, opts, report)
        })
    }
}

/// [`Controller::validate`] with the decoding given: the vendor checked
/// (against `main_file`, line 1), then `decode`'s steps checked.
pub(crate) fn validate_decoded<C: Controller>(
    cell: &CellLayout,
    main_file: &str,
    opts: &C::Options,
    planned: Option<&[PlannedPoint]>,
    decode: impl FnOnce(&mut ValidationReport) -> Option<Vec<DecodedStep>>,
) -> ValidationReport {
    let mut report = ValidationReport::default();
    if !vendor_matches(cell, C::VENDOR, C::EMITTER, main_file, &mut report) {
        return report;
    }
    if let Some(steps) = decode(&mut report) {
        check_steps(&steps, cell, planned, C::common(opts), &mut report);
    }
    report
}

/// The stem of a file name (no folder, no extension).
pub fn file_stem(name: &str) -> &str {
    Path::new(name)
        .file_stem()
        .and_then(|s| s.to_str())
        .unwrap_or(name)
}

/// The files of a build sorted into its groups by name
/// ([`parse_group_name`]): the files of no group, then the groups in
/// order (empty when no file is a group's).
///
/// # Errors
/// [`ProgramError::Read`] when the groups are of two builds, or a group
/// between the first and the last is missing.
pub fn groups_by_name(
    files: &[EmittedFile],
) -> Result<(Vec<EmittedFile>, Vec<Vec<EmittedFile>>), ProgramError> {
    let mut rest = Vec::new();
    let mut groups: Vec<Vec<EmittedFile>> = Vec::new();
    let mut base: Option<String> = None;
    for f in files {
        let Some((b, k)) = parse_group_name(file_stem(&f.name)) else {
            rest.push(f.clone());
            continue;
        };
        match &base {
            Some(x) if !x.eq_ignore_ascii_case(b) => {
                return Err(ProgramError::Read {
                    file: f.name.clone(),
                    line: 0,
                    reason: format!("a group of build `{b}`, read with the groups of `{x}`"),
                })
            }
            _ => base = Some(b.to_string()),
        }
        if groups.len() < k {
            groups.resize(k, Vec::new());
        }
        groups[k - 1].push(f.clone());
    }
    if let Some(k) = groups.iter().position(Vec::is_empty) {
        return Err(ProgramError::Read {
            file: crate::program::split::group_name(base.as_deref().unwrap_or(""), k + 1),
            line: 0,
            reason: format!(
                "group {} of {} is missing: every group of the build is needed, in order",
                k + 1,
                groups.len()
            ),
        });
    }
    Ok((rest, groups))
}

/// Reads and validates the files of a whole build with controller `C`:
/// its groups ([`Controller::groups`]) decoded in order and checked as one
/// run of steps ([`check_steps`]: the deposition points against `planned`
/// over every group, the set-up carried across), each group within the
/// budget ([`Controller::occupied`]) and, in a build of several groups,
/// each starting and ending at home.
///
/// # Errors
/// [`ProgramError::Read`] naming the file and line that cannot be read.
pub fn validate_build<C: Controller>(
    files: &[EmittedFile],
    cell: &CellLayout,
    opts: &C::Options,
    planned: Option<&[PlannedPoint]>,
) -> Result<ValidationReport, ProgramError> {
    let mut report = ValidationReport::default();
    let groups = C::groups(files, &mut report)?;
    let budget = C::budget(opts);
    let mut steps: Vec<DecodedStep> = Vec::new();
    let mut ranges = Vec::with_capacity(groups.len());
    for g in &groups {
        let read = C::read(g)?;
        let main = C::main_file(&read).to_string();
        if !vendor_matches(cell, C::VENDOR, C::EMITTER, &main, &mut report) {
            return Ok(report);
        }
        let used = C::occupied(g, &read);
        if used > budget.limit {
            push(
                &mut report,
                ProblemKind::Budget,
                &main,
                0,
                format!(
                    "{used} {unit} resident at once, more than `{}` = {} {unit}: the controller cannot hold it",
                    budget.field,
                    budget.limit,
                    unit = budget.unit
                ),
            );
        }
        let Some(s) = C::steps(&read, cell, opts, &mut report) else {
            return Ok(report);
        };
        ranges.push(steps.len()..steps.len() + s.len());
        steps.extend(s);
    }
    check_steps(&steps, cell, planned, C::common(opts), &mut report);
    let n = ranges.len();
    if n > 1 {
        for (k, r) in ranges.into_iter().enumerate() {
            check_home_ends(
                &steps[r],
                cell,
                C::common(opts),
                [k > 0, k + 1 < n],
                &mut report,
            );
        }
    }
    Ok(report)
}

/// Reads the text of `path` as an [`EmittedFile`] named by its file name.
///
/// # Errors
/// [`ProgramError::Read`] naming the file.
pub fn read_file(path: &Path) -> Result<EmittedFile, ProgramError> {
    let text = std::fs::read_to_string(path).map_err(|e| ProgramError::Read {
        file: path.display().to_string(),
        line: 0,
        reason: format!("cannot read: {e}"),
    })?;
    Ok(EmittedFile {
        name: path.display().to_string(),
        text,
    })
}
