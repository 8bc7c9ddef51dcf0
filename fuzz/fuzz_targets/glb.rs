//! `triorder::mesh::gltf::read` on arbitrary bytes named `.glb` (binary glTF). No base
//! directory: external buffers are never read.
#![no_main]

libfuzzer_sys::fuzz_target!(|bytes: &[u8]| {
    let _ = triorder::mesh::gltf::read(bytes, "fuzz.glb", None, true);
});
