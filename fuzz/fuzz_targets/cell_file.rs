//! Cell-file reader: arbitrary text → `parse_cell_file` → joints of a few points.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data) {
        waam_slicer_fuzz::cell_file(text);
    }
});
