//! Tells the tests what this machine has, at build time, so that a test needing the shared models
//! or a Vulkan driver is reported by `cargo test` itself as ignored, with the reason, where they
//! are absent, rather than passing without checking anything.
//!
//! - `triorder_data`: a data directory was found, as the tests look for it: `TRIORDER_DATA`, else
//!   `../shared/data` beside the crate.
//! - `triorder_gpu`: a Vulkan driver is installed (an ICD manifest where the loader looks, or one
//!   named by `VK_DRIVER_FILES` / `VK_ICD_FILENAMES`).
//!
//! `TRIORDER_REQUIRE_DATA` and `TRIORDER_REQUIRE_GPU` (CI sets both) turn the cfg on regardless,
//! so a missing directory or driver fails the tests with a clear message instead. Cargo reruns
//! this when one of these variables changes or a driver manifest is added; after fetching the
//! models into a new directory, set `TRIORDER_DATA` to it.

use std::path::PathBuf;

fn main() {
    println!("cargo::rustc-check-cfg=cfg(triorder_data)");
    println!("cargo::rustc-check-cfg=cfg(triorder_gpu)");
    println!("cargo::rerun-if-changed=build.rs");
    for var in ["TRIORDER_DATA", "TRIORDER_REQUIRE_DATA", "TRIORDER_REQUIRE_GPU", "VK_DRIVER_FILES", "VK_ICD_FILENAMES"]
    {
        println!("cargo::rerun-if-env-changed={var}");
    }
    let set = |var: &str| std::env::var_os(var).is_some_and(|v| !v.is_empty());
    let data = std::env::var_os("TRIORDER_DATA").filter(|d| !d.is_empty()).map(PathBuf::from).unwrap_or_else(|| {
        // Read when the script runs (Cargo sets it then), not baked in when it was compiled.
        let root = std::env::var_os("CARGO_MANIFEST_DIR").map(PathBuf::from).unwrap_or_default();
        root.join("../shared/data")
    });
    if set("TRIORDER_REQUIRE_DATA") || data.is_dir() {
        println!("cargo::rustc-cfg=triorder_data");
    }
    let named = ["VK_DRIVER_FILES", "VK_ICD_FILENAMES"].iter().any(|v| set(v));
    let icd_dirs = ["/usr/share/vulkan/icd.d", "/etc/vulkan/icd.d", "/usr/local/share/vulkan/icd.d"];
    // Rerun when a driver is installed after the first build, which would otherwise leave the GPU
    // tests ignored as if there were none: watch each manifest directory, or the `vulkan`
    // directory it would be made in (small, unlike its parent, which Cargo would scan whole).
    for dir in icd_dirs.map(PathBuf::from) {
        if let Some(watched) = [dir.as_path(), dir.parent().unwrap_or(&dir)].into_iter().find(|d| d.is_dir()) {
            println!("cargo::rerun-if-changed={}", watched.display());
        }
    }
    let manifests = icd_dirs
        .iter()
        .filter_map(|dir| std::fs::read_dir(dir).ok())
        .flatten()
        .any(|entry| entry.is_ok_and(|e| e.path().extension().is_some_and(|x| x == "json")));
    if set("TRIORDER_REQUIRE_GPU") || named || manifests {
        println!("cargo::rustc-cfg=triorder_gpu");
    }
}
