//! OBJ bytes through the mesh reader: no panic.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    let _ = vkhair::groom::mesh::TriMesh::parse_obj(data);
});
