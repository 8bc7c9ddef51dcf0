//! Helpers shared by integration tests: where the real meshes are.

#![allow(dead_code)] // each test binary uses a different subset

use std::path::PathBuf;

use triorder::mesh::{Mesh, load};

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
