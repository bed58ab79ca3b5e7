//! glTF bytes (a GLB or JSON document without external buffers) through the
//! character reader: no panic, no unbounded allocation.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    let _ = vkhair::character::Character::parse(data);
});
