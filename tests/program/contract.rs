//! The vendor contract (`program::contract`): one dispatch from a vendor
//! to its emitter, reader and decoder, and one round trip (emit → read →
//! validate, no problem) run in the same way for FANUC, KUKA and ABB in
//! every sample cell, through the cell file's own `[program]` settings.

use waam_slicer::io::cell_file::read_cell_file;
use waam_slicer::program::contract::Controller;
use waam_slicer::program::registry::{
    check_files, emit, files_on_disk, vendor_of_extension, Abb, Fanuc, Kuka, Registered,
};
use waam_slicer::program::{write_files, EmittedFile, Program};
use waam_slicer::robot::Vendor;

use crate::fixture::{program, ABB_CELLS, FANUC_CELLS, KUKA_CELLS};

#[test]
fn each_extension_names_its_vendor() {
    for (ext, vendor) in [
        ("ls", Some(Vendor::Fanuc)),
        ("LS", Some(Vendor::Fanuc)),
        ("src", Some(Vendor::Kuka)),
        ("dat", Some(Vendor::Kuka)),
        ("mod", Some(Vendor::Abb)),
        ("tp", None),
        ("", None),
    ] {
        assert_eq!(vendor_of_extension(ext), vendor, "`.{ext}`");
    }
    // The constants agree with the dispatch.
    assert_eq!(Fanuc::VENDOR, Vendor::Fanuc);
    assert_eq!(Kuka::VENDOR, Vendor::Kuka);
    assert_eq!(Abb::VENDOR, Vendor::Abb);
}

/// The files `emit` writes for `prog` with the cell file's settings are
/// those of `C`'s emitter with `C`'s options from the same settings.
fn same_as_direct<C: Registered>(
    prog: &Program,
    settings: &waam_slicer::program::ProgramSettings,
) -> Vec<EmittedFile> {
    let via = emit(prog, settings).unwrap();
    assert_eq!(via, C::emit(prog, &C::options(settings)).unwrap());
    via
}

#[test]
fn every_sample_cell_round_trips_through_the_contract() {
    let dir = std::env::temp_dir().join(format!("waam-contract-{}", std::process::id()));
    for file in FANUC_CELLS.iter().chain(&KUKA_CELLS).chain(&ABB_CELLS) {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("parts/cells")
            .join(file);
        let cf = read_cell_file(&path).unwrap();
        let cell = cf.cell.clone().expect("a cell");
        // The cell file's emitter options; the set-up (home, dwell,
        // payload) of `build_program`, which the fixture's program has.
        let mut settings = cf.program.clone();
        settings.common = waam_slicer::program::ProgramOptions::default();
        let (prog, _) = program(&cell, 0..3, 24);
        let vendor = cell.robot().vendor;
        let files = match vendor {
            Vendor::Fanuc => same_as_direct::<Fanuc>(&prog, &settings),
            Vendor::Kuka => same_as_direct::<Kuka>(&prog, &settings),
            Vendor::Abb => same_as_direct::<Abb>(&prog, &settings),
        };
        let planned: Vec<_> = prog.planned.clone();
        let r = check_files(vendor, &files, &cell, &settings, Some(&planned)).unwrap();
        assert!(r.is_ok(), "{file}:\n{r}");
        assert_eq!((r.motions, r.beads), (prog.points.len(), 3), "{file}");
        // And from disk, found by the main file's extension.
        let out = dir.join(file);
        std::fs::create_dir_all(&out).unwrap();
        write_files(&out, &files).unwrap();
        let (v, on_disk) = files_on_disk(&out.join(&files[0].name)).unwrap();
        assert_eq!(v, vendor, "{file}");
        assert_eq!(on_disk.len(), files.len(), "{file}");
        let r = check_files(v, &on_disk, &cell, &settings, Some(&planned)).unwrap();
        assert!(r.is_ok(), "{file} from disk:\n{r}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn an_unknown_extension_is_refused_naming_the_file() {
    let e = files_on_disk(std::path::Path::new("out/PART.tp")).unwrap_err();
    let m = e.to_string();
    assert!(
        m.contains("PART.tp") && m.contains("unknown program type"),
        "{m}"
    );
}
