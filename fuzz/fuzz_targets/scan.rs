//! The replan's scan reader: text → `Measured::from_csv_str`.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data) {
        waam_slicer_fuzz::scan(text)
    }
});
