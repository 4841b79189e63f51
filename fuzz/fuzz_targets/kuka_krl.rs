//! KUKA `.src` + `.dat` reader behind `waam check`: first byte picks the
//! cell; the rest up to the first NUL is the `.src`, after it the `.dat`
//! → `parse_krl` → `validate_kuka`.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Some((&selector, rest)) = data.split_first() {
        let (src, dat) = match rest.iter().position(|&b| b == 0) {
            Some(i) => (&rest[..i], &rest[i + 1..]),
            None => (rest, &[][..]),
        };
        if let (Ok(src), Ok(dat)) = (std::str::from_utf8(src), std::str::from_utf8(dat)) {
            waam_slicer_fuzz::kuka_krl(selector, src, dat);
        }
    }
});
