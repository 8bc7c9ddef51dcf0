//! Naming meshes: a procedural spec (`grid:16x8`), a path, or a path inside the data directory,
//! optionally simplified to N triangles with an `@N` suffix (`models/bun_zipper.ply@20000`).
//!
//! Experiments name models relative to a data directory (`models/bunny_2k.ply`) so the same spec
//! works for every user. The data directory is `--data DIR`, else `$TRIORDER_DATA`, else
//! `../shared/data` when it exists (this repository's sibling checkout); see README.md and
//! scripts/fetch-data.sh for getting the public models.

use std::path::{Path, PathBuf};

use crate::error::{Error, Result};
use crate::mesh::{Mesh, load, procedural, simplify};

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
    if let Some((base, count)) = simplify::parse_source(source) {
        let target = simplify::parse_target(source, count)?;
        return simplify::simplify(&open(base, data, seed)?, target);
    }
    match procedural::generate(source, seed) {
        Some(generated) => generated,
        None => load::load_file(&locate_file(source, data)?),
    }
}

/// Checks that `source` can be opened, without reading or generating it: a well-formed
/// procedural spec, or a file that exists. Lets a long run fail before any work.
pub fn check(source: &str, data: Option<&Path>) -> Result<()> {
    if let Some((base, count)) = simplify::parse_source(source) {
        simplify::parse_target(source, count)?;
        return check(base, data);
    }
    match procedural::check(source) {
        Some(checked) => checked,
        None => locate_file(source, data).map(drop),
    }
}

/// The file `source` names: the path as given if it exists, else the same path inside `data`.
/// The error says where it looked and how to get the models.
fn locate_file(source: &str, data: Option<&Path>) -> Result<PathBuf> {
    let direct = Path::new(source);
    if direct.exists() {
        return Ok(direct.to_path_buf());
    }
    let looked = match data {
        Some(dir) if dir.join(source).exists() => return Ok(dir.join(source)),
        Some(dir) => format!("no such file, here or in the data directory {}", dir.display()),
        None => "no such file, and no data directory".to_string(),
    };
    Err(Error::input(
        source,
        format!(
            "{looked}; give --data DIR or set TRIORDER_DATA to the directory holding models/, or run scripts/fetch-data.sh to download the models"
        ),
    ))
}
