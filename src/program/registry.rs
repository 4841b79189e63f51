//! Stage 7, the registry of program formats: the one list of the vendors
//! whose controllers the crate writes and reads (the `registry!` list below: one
//! line per vendor), and what the rest of the crate asks of a vendor chosen
//! at run time: its options in a cell file's `[program]` table
//! ([`ProgramSettings`]), its key, emitter name, file extensions and cycle
//! options, and the emit/read/check of its files ([`emit`],
//! [`check_files`], [`files_on_disk`]). Each vendor implements the contract
//! ([`Controller`]) in its own folder; this module imports them, they
//! import only the contract.

use std::path::Path;
use std::str::FromStr;

use serde::Serialize;

use crate::program::contract::{validate_build, Controller};
use crate::program::cycle::CycleOptions;
use crate::program::split::parse_group_name;
use crate::program::validate::ValidationReport;
use crate::program::{EmittedFile, PlannedPoint, Program, ProgramError, ProgramOptions};
use crate::robot::{CellLayout, Vendor};

pub use crate::program::abb::Abb;
pub use crate::program::fanuc::Fanuc;
pub use crate::program::kuka::Kuka;

/// A controller listed in the registry: its options found in a cell
/// file's [`ProgramSettings`].
pub trait Registered: Controller {
    /// The emitter's options from a cell file's `[program]` table (its
    /// `[program.<key>]` table), the vendor-neutral set-up (`common`)
    /// included.
    fn options(settings: &ProgramSettings) -> Self::Options;
}

/// The registry: for each vendor, its [`Vendor`] variant, its field in
/// [`ProgramSettings`] (= [`Controller::KEY`]) and its [`Controller`].
macro_rules! registry {
    ($($vendor:ident: $key:ident => $controller:ty),* $(,)?) => {
        /// A cell file's `[program]` table: the vendor-independent
        /// [`ProgramOptions`] and each vendor's emitter options (its
        /// `[program.<key>]` table), whose `common` field is set from the
        /// former by [`Registered::options`].
        #[derive(Debug, Clone, PartialEq, Default, Serialize)]
        pub struct ProgramSettings {
            /// The vendor-independent options.
            pub common: ProgramOptions,
            $(
                #[doc = concat!("`[program.", stringify!($key), "]`.")]
                pub $key: <$controller as Controller>::Options,
            )*
        }

        $(
            impl Registered for $controller {
                fn options(settings: &ProgramSettings) -> Self::Options {
                    <$controller>::with_common(&settings.$key, &settings.common)
                }
            }
        )*

        /// Every vendor with a program format, in the order of messages.
        pub const VENDORS: &[Vendor] = &[$(Vendor::$vendor),*];

        /// Runs `task` with the implementation of `vendor`'s controller: the
        /// one place the vendor list is matched.
        pub fn with_controller<T: ControllerTask>(vendor: Vendor, task: T) -> T::Output {
            match vendor {
                $(Vendor::$vendor => task.run::<$controller>(),)*
            }
        }

        impl ProgramSettings {
            /// The vendors' `[program.<key>]` tables taken out of `table`
            /// (a cell file's `[program]` table), each read as its
            /// options, in registry order; `common` left at its default.
            ///
            /// # Errors
            /// The key of the first table that is not its vendor's options,
            /// with the reason.
            pub fn take_vendor_tables(
                table: &mut toml::Table,
            ) -> Result<Self, (&'static str, toml::de::Error)> {
                Ok(Self {
                    common: ProgramOptions::default(),
                    $(
                        $key: match table.remove(<$controller>::KEY) {
                            None => Default::default(),
                            Some(v) => v.try_into().map_err(|e| (<$controller>::KEY, e))?,
                        },
                    )*
                })
            }

            /// Checks each vendor's options ([`Controller::check_options`]),
            /// in registry order.
            ///
            /// # Errors
            /// The key of the first vendor whose options are invalid, with
            /// the error naming the field.
            pub fn check_vendor_options(&self) -> Result<(), (&'static str, ProgramError)> {
                $(
                    <$controller>::check_options(&self.$key)
                        .map_err(|e| (<$controller>::KEY, e))?;
                )*
                Ok(())
            }
        }
    };
}

registry! {
    Fanuc: fanuc => Fanuc,
    Kuka: kuka => Kuka,
    Abb: abb => Abb,
}

/// Something done with one controller's implementation, chosen at run time
/// by [`with_controller`].
pub trait ControllerTask {
    /// What the task returns.
    type Output;
    /// Runs the task with controller `C`.
    fn run<C: Registered>(self) -> Self::Output;
}

/// The vendor whose format uses files with extension `ext` (any case, no
/// dot).
pub fn vendor_of_extension(ext: &str) -> Option<Vendor> {
    struct Owns<'a>(&'a str);
    impl ControllerTask for Owns<'_> {
        type Output = bool;
        fn run<C: Registered>(self) -> bool {
            C::EXTENSIONS.iter().any(|e| e.eq_ignore_ascii_case(self.0))
        }
    }
    VENDORS
        .iter()
        .copied()
        .find(|v| with_controller(*v, Owns(ext)))
}

/// The files of `program` in its robot's format, with that format's
/// options from `settings`.
///
/// # Errors
/// As [`Controller::emit`].
pub fn emit(
    program: &Program,
    settings: &ProgramSettings,
) -> Result<Vec<EmittedFile>, ProgramError> {
    struct Emit<'a>(&'a Program, &'a ProgramSettings);
    impl ControllerTask for Emit<'_> {
        type Output = Result<Vec<EmittedFile>, ProgramError>;
        fn run<C: Registered>(self) -> Self::Output {
            C::emit(self.0, &C::options(self.1))
        }
    }
    with_controller(program.cell.robot().vendor, Emit(program, settings))
}

/// Reads `files` as a program of `vendor`'s format — one program, or a
/// build cut into groups ([`validate_build`]) — and validates it against
/// `cell` with the options of `settings`.
///
/// # Errors
/// [`ProgramError::Read`] naming the file and line that cannot be read.
pub fn check_files(
    vendor: Vendor,
    files: &[EmittedFile],
    cell: &CellLayout,
    settings: &ProgramSettings,
    planned: Option<&[PlannedPoint]>,
) -> Result<ValidationReport, ProgramError> {
    struct Check<'a> {
        files: &'a [EmittedFile],
        cell: &'a CellLayout,
        settings: &'a ProgramSettings,
        planned: Option<&'a [PlannedPoint]>,
    }
    impl ControllerTask for Check<'_> {
        type Output = Result<ValidationReport, ProgramError>;
        fn run<C: Registered>(self) -> Self::Output {
            validate_build::<C>(
                self.files,
                self.cell,
                &C::options(self.settings),
                self.planned,
            )
        }
    }
    with_controller(
        vendor,
        Check {
            files,
            cell,
            settings,
            planned,
        },
    )
}

/// The files of the program on disk at `path`, and its vendor (from the
/// extension).
///
/// # Errors
/// [`ProgramError::Read`] naming the file: an extension of no format, or a
/// file that cannot be read.
pub fn files_on_disk(path: &Path) -> Result<(Vendor, Vec<EmittedFile>), ProgramError> {
    struct OnDisk<'a>(&'a Path);
    impl ControllerTask for OnDisk<'_> {
        type Output = Result<Vec<EmittedFile>, ProgramError>;
        fn run<C: Registered>(self) -> Self::Output {
            C::files_on_disk(self.0)
        }
    }
    let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("");
    let vendor = vendor_of_extension(ext).ok_or_else(|| ProgramError::Read {
        file: path.display().to_string(),
        line: 0,
        reason: format!(
            "unknown program type `.{}`; expected {}",
            ext.to_ascii_lowercase(),
            one_of(VENDORS.iter().map(|v| {
                let exts: Vec<String> = extensions(*v).iter().map(|e| format!(".{e}")).collect();
                let exts = exts.join("/");
                format!("{exts} ({})", v.display_name())
            }))
        ),
    })?;
    // a build cut into groups: `NAME.ext` stands for its groups when only
    // they are on disk; any group brings its siblings, in order
    let first_group = |p: &Path| {
        let stem = p.file_stem().and_then(|s| s.to_str()).unwrap_or("");
        p.with_file_name(format!(
            "{}.{ext}",
            crate::program::split::group_name(stem, 1)
        ))
    };
    let path = if !path.exists() && first_group(path).exists() {
        first_group(path)
    } else {
        path.to_path_buf()
    };
    let stem = path.file_stem().and_then(|s| s.to_str()).unwrap_or("");
    let Some((base, _)) = parse_group_name(stem) else {
        return Ok((vendor, with_controller(vendor, OnDisk(&path))?));
    };
    let mut files = Vec::new();
    for k in 1.. {
        let p = path.with_file_name(format!(
            "{}.{ext}",
            crate::program::split::group_name(base, k)
        ));
        if !p.exists() {
            break;
        }
        files.extend(with_controller(vendor, OnDisk(&p))?);
    }
    Ok((vendor, files))
}

/// `a`, `a or b`, `a, b or c`: the items of a list in a message.
fn one_of(items: impl IntoIterator<Item = String>) -> String {
    let items: Vec<String> = items.into_iter().collect();
    match items.split_last() {
        Some((last, [])) => last.clone(),
        Some((last, rest)) => format!("{} or {last}", rest.join(", ")),
        None => String::new(),
    }
}

/// The extensions of `vendor`'s files ([`Controller::EXTENSIONS`]), the
/// main file's first.
pub fn extensions(vendor: Vendor) -> &'static [&'static str] {
    struct Extensions;
    impl ControllerTask for Extensions {
        type Output = &'static [&'static str];
        fn run<C: Registered>(self) -> Self::Output {
            C::EXTENSIONS
        }
    }
    with_controller(vendor, Extensions)
}

/// `true` when `ext` (any case, no dot) is the extension of a format's
/// main (entry) file: the first of its [`Controller::EXTENSIONS`].
pub fn is_main_extension(ext: &str) -> bool {
    VENDORS
        .iter()
        .any(|v| extensions(*v)[0].eq_ignore_ascii_case(ext))
}

/// The main files' extensions in a message: `.ls, .src or .mod`.
pub fn main_extensions_text() -> String {
    one_of(VENDORS.iter().map(|v| format!(".{}", extensions(*v)[0])))
}

impl Vendor {
    /// The vendor's key ([`Controller::KEY`]): its table in a cell file
    /// and its name on the command line and in files, e.g. `fanuc`.
    pub fn key(self) -> &'static str {
        struct Key;
        impl ControllerTask for Key {
            type Output = &'static str;
            fn run<C: Registered>(self) -> Self::Output {
                C::KEY
            }
        }
        with_controller(self, Key)
    }

    /// The name of the vendor's program format in messages
    /// ([`Controller::EMITTER`]), e.g. `FANUC TP`.
    pub fn emitter(self) -> &'static str {
        struct Emitter;
        impl ControllerTask for Emitter {
            type Output = &'static str;
            fn run<C: Registered>(self) -> Self::Output {
                C::EMITTER
            }
        }
        with_controller(self, Emitter)
    }

    /// The options of the cycle time ([`crate::program::cycle`]) of this
    /// vendor's format with the options of `settings`
    /// ([`Controller::cycle_options`]).
    pub fn cycle_options(self, settings: &ProgramSettings) -> CycleOptions {
        struct Cycle<'a>(&'a ProgramSettings);
        impl ControllerTask for Cycle<'_> {
            type Output = CycleOptions;
            fn run<C: Registered>(self) -> Self::Output {
                C::cycle_options(&C::options(self.0))
            }
        }
        with_controller(self, Cycle(settings))
    }
}

impl std::fmt::Display for Vendor {
    /// The vendor's [`key`](Vendor::key): `fanuc`, `kuka`, `abb`.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.key())
    }
}

/// A word that names no vendor's format (or no `R_Z` law).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("`{given}`: expected {expected}")]
pub struct ParseOptionError {
    /// What was given.
    pub given: String,
    /// What is accepted.
    pub expected: &'static str,
}

impl FromStr for Vendor {
    type Err = ParseOptionError;
    /// The vendor whose [`key`](Vendor::key) is `s` (any case).
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        static EXPECTED: std::sync::OnceLock<String> = std::sync::OnceLock::new();
        VENDORS
            .iter()
            .copied()
            .find(|v| v.key().eq_ignore_ascii_case(s))
            .ok_or_else(|| ParseOptionError {
                given: s.to_string(),
                expected: EXPECTED
                    .get_or_init(|| one_of(VENDORS.iter().map(|v| v.key().to_string()))),
            })
    }
}
