//! `triorder::mesh::ply::read` on arbitrary bytes (ascii and binary PLY both go through it): it
//! must return a mesh or an error, never panic, hang or allocate far beyond what the bytes
//! describe.
#![no_main]

libfuzzer_sys::fuzz_target!(|bytes: &[u8]| {
    let _ = triorder::mesh::ply::read(bytes, "fuzz.ply");
});
