//! `.tfx` bytes through the strict and the repairing reader: no panic.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    let _ = vkhair::groom::tfx::TfxFile::parse(data);
    let _ = vkhair::groom::tfx::TfxFile::parse_repairing(data);
});
