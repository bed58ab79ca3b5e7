//! Alembic bytes through the strict and the repairing reader: no panic.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    let _ = vkhair::groom::alembic::parse(data);
    let _ = vkhair::groom::alembic::parse_repairing(data);
});
