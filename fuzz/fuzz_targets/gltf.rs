//! `triorder::mesh::gltf::read` on arbitrary bytes named `.gltf` (JSON; a GLB magic still
//! switches to the binary reader). No base directory: external buffers are never read, only
//! embedded `data:` URIs.
#![no_main]

libfuzzer_sys::fuzz_target!(|bytes: &[u8]| {
    let _ = triorder::mesh::gltf::read(bytes, "fuzz.gltf", None, false);
});
