//! `triorder::experiment::Spec::parse` on arbitrary text. A spec's `id` must equal its file
//! name, so the file is named after the first `id = "..."` line, letting the fuzzer past that
//! check into the rest of the checks.
#![no_main]

use std::path::PathBuf;

libfuzzer_sys::fuzz_target!(|bytes: &[u8]| {
    let Ok(text) = std::str::from_utf8(bytes) else { return };
    let id = text
        .lines()
        .find_map(|line| {
            line.trim().strip_prefix("id")?.trim_start().strip_prefix('=')?.trim().strip_prefix('"')?.split('"').next()
        })
        .unwrap_or("fuzz");
    let path = PathBuf::from("experiments").join(format!("{id}.toml"));
    let _ = triorder::experiment::Spec::parse(text, &path);
});
