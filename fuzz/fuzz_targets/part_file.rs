//! Part-file reader: arbitrary text → `parse_part` → tube → three layers.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    // Non-UTF-8 bytes are refused by `read_part_file` before parsing.
    if let Ok(text) = std::str::from_utf8(data) {
        waam_slicer_fuzz::part_file(text);
    }
});
