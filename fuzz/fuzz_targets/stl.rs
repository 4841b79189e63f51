//! STL reader: arbitrary bytes → mesh substrate → first layer of a cylinder.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| waam_slicer_fuzz::stl(data));
