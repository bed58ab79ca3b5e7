//! USD binary (crate) bytes as a stage's root layer, through the strict and
//! the repairing reader: no panic, no abort (an allocation the file's counts
//! ask for past what it holds), no hang.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    let Ok(dir) = tempfile::tempdir() else { return };
    let path = dir.path().join("fuzz.usdc");
    if std::fs::write(&path, data).is_ok() {
        let _ = vkhair::groom::usd::open(&path);
        let _ = vkhair::groom::usd::open_repairing(&path);
    }
});
