//! The mesh fit: first byte the unit, then STL bytes → `fit_tube`.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Some((&units, stl)) = data.split_first() {
        waam_slicer_fuzz::fit_stl(units, stl)
    }
});
