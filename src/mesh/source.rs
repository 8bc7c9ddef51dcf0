//! Naming meshes: a procedural spec (`grid:16x8`), a path, or a path inside the data directory.
//!
//! Experiments name models relative to a data directory (`models/bunny_2k.ply`) so the same spec
//! works for every user. The data directory is `--data DIR`, else `$TRIORDER_DATA`, else
//! `../shared/data` when it exists (this repository's sibling checkout); see README.md and
//! scripts/fetch-data.sh for getting the public models.

use std::path::{Path, PathBuf};

use crate::error::{Error, Result};
use crate::mesh::{Mesh, load, procedural};

/// The directory models are looked up in, if any.
pub fn data_dir(explicit: Option<&Path>) -> Option<PathBuf> {
    if let Some(dir) = explicit {
        return Some(dir.to_path_buf());
    }
    if let Some(dir) = std::env::var_os("TRIORDER_DATA").filter(|d| !d.is_empty()) {
        return Some(PathBuf::from(dir));
    }
    let sibling = Path::new("../shared/data");
    sibling.is_dir().then(|| sibling.to_path_buf())
}

/// Loads `source`: a procedural spec, an existing path, or a path relative to `data`.
/// `seed` drives seeded generators (`disk:N`).
pub fn open(source: &str, data: Option<&Path>, seed: u64) -> Result<Mesh> {
    if let Some(generated) = procedural::generate(source, seed) {
        return generated;
    }
    let direct = Path::new(source);
    if direct.exists() {
        return load::load_file(direct);
    }
    match data {
        Some(dir) if dir.join(source).exists() => load::load_file(&dir.join(source)),
        Some(dir) => {
            Err(Error::input(source, format!("no such file, here or in the data directory {}", dir.display())))
        }
        None => Err(Error::input(
            source,
            "no such file, and no data directory (give --data DIR or set TRIORDER_DATA; scripts/fetch-data.sh downloads the models)",
        )),
    }
}
