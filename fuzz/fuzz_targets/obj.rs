//! `triorder::mesh::obj::read` on arbitrary bytes: it must return a mesh or an error, never
//! panic, hang or allocate far beyond what the bytes describe.
#![no_main]

libfuzzer_sys::fuzz_target!(|bytes: &[u8]| {
    let _ = triorder::mesh::obj::read(bytes, "fuzz.obj");
});
