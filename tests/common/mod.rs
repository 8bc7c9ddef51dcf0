//! Helpers shared by integration tests: where the real meshes are.

#![allow(dead_code)] // each test binary uses a different subset

use std::path::PathBuf;

use triorder::mesh::{Mesh, load};

/// Every static model in the shared data directory (`models/`), as MANIFEST.md lists them.
pub const STATIC_MODELS: [&str; 13] = [
    "bun_zipper.ply",
    "bunny_2k.ply",
    "dragon_vrip_res2.ply",
    "dragon_vrip_res3.ply",
    "dragon_vrip_res4.ply",
    "happy_buddha_100k.obj",
    "horse.ply",
    "feline.obj",
    "armadillo.obj",
    "spot.obj",
    "nefertiti_lowres.obj",
    "pirate.obj",
    "rocker-arm.obj",
];

/// The shared data directory (`$TRIORDER_DATA`, else ../shared/data beside the crate), if present.
pub fn data_dir() -> Option<PathBuf> {
    let dir = std::env::var_os("TRIORDER_DATA")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../shared/data"));
    if dir.is_dir() {
        Some(dir)
    } else {
        eprintln!("note: no data directory at {}; skipping tests on real meshes", dir.display());
        None
    }
}

/// Loads `models/NAME` from the data directory, or `None` (with a notice) when there is none.
pub fn real_mesh(name: &str) -> Option<Mesh> {
    let path = data_dir()?.join("models").join(name);
    Some(load::load_file(&path).unwrap_or_else(|e| panic!("{e}")))
}
