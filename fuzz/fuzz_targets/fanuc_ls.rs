//! FANUC `.ls` reader behind `waam check`: first byte picks the cell, the
//! rest → `parse_ls` → `validate_fanuc`.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Some((&selector, rest)) = data.split_first() {
        if let Ok(text) = std::str::from_utf8(rest) {
            waam_slicer_fuzz::fanuc_ls(selector, text);
        }
    }
});
