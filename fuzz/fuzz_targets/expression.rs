//! Expression parser: first byte = role (profile, guide x, guide z, piece),
//! the rest = expression text → evaluate → tube → three layers.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Some((&role, rest)) = data.split_first() {
        if let Ok(text) = std::str::from_utf8(rest) {
            waam_slicer_fuzz::expression(role, text);
        }
    }
});
