//! Naming meshes: a procedural spec (`grid:16x8`), a path, or a path inside the data directory,
//! optionally simplified to N triangles with an `@N` suffix (`models/bun_zipper.ply@20000`).
//!
//! Experiments name models relative to a data directory (`models/bunny_2k.ply`) so the same spec
//! works for every user. The data directory is `--data DIR`, else `$TRIORDER_DATA`, else
//! `../shared/data` when it exists (this repository's sibling checkout); see README.md and
//! scripts/fetch-data.sh for getting the public models.

use std::path::{Path, PathBuf};

use crate::error::{Error, Result};
use crate::mesh::gltf_animation::{self, ClipSelection};
use crate::mesh::keyframes::Keyframes;
use crate::mesh::{Mesh, load, procedural, simplify, subdivide};

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

/// Loads `source`: a procedural spec, an existing path, or a path relative to `data`; for an
/// [`AnimationSource`], its rest mesh (subdivided if it says so).
/// `seed` drives seeded generators (`disk:N`).
pub fn open(source: &str, data: Option<&Path>, seed: u64) -> Result<Mesh> {
    if let Some(animation) = AnimationSource::parse(source) {
        return Ok(animation?.open(data)?.0);
    }
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
/// procedural spec, a file that exists, or an animation whose file has the clip it names (read,
/// not posed). Lets a long run fail before any work.
pub fn check(source: &str, data: Option<&Path>) -> Result<()> {
    if let Some(animation) = AnimationSource::parse(source) {
        let animation = animation?;
        return gltf_animation::check_selection(&locate_file(&animation.path, data)?, &animation.selection);
    }
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

/// Most Loop subdivision levels an animated source may ask for (Han & Sander 2017 use 0 to 3).
pub const MAX_SUBDIVISION: u32 = 3;

/// An animation named as `PATH#clip=NAME,frames=N,subdiv=L`: the glTF/GLB file, which clip
/// (`all`, the default, keeps every clip), `frames` to resample each clip to that many evenly
/// spaced instants (default: its own keyframes), and `subdiv` levels of Loop subdivision of the
/// rest mesh (default 0). Every key is optional; `PATH#` alone is every clip at its keyframes.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct AnimationSource {
    pub path: String,
    pub selection: ClipSelection,
    pub subdiv: u32,
}

impl AnimationSource {
    /// `None` when `source` has no `#` (a static mesh); otherwise the parsed source or an error
    /// naming the bad key.
    pub fn parse(source: &str) -> Option<Result<AnimationSource>> {
        let (path, keys) = source.split_once('#')?;
        let bad = |why: String| {
            Error::usage(format!("animation `{source}`: {why} (expected PATH#clip=NAME,frames=N,subdiv=L)"))
        };
        let mut parsed = AnimationSource { path: path.to_string(), selection: ClipSelection::default(), subdiv: 0 };
        for pair in keys.split(',').filter(|p| !p.is_empty()) {
            let Some((key, value)) = pair.split_once('=') else {
                return Some(Err(bad(format!("`{pair}` is not key=value"))));
            };
            match key {
                "clip" if value == "all" => parsed.selection.clip = None,
                "clip" if !value.is_empty() => parsed.selection.clip = Some(value.to_string()),
                "frames" => match value.parse::<usize>() {
                    Ok(n) if (1..=u16::MAX as usize).contains(&n) => parsed.selection.frames = Some(n),
                    _ => return Some(Err(bad(format!("frames `{value}` is not a count in 1..=65535")))),
                },
                "subdiv" => match value.parse::<u32>() {
                    Ok(n) if n <= MAX_SUBDIVISION => parsed.subdiv = n,
                    _ => return Some(Err(bad(format!("subdiv `{value}` is not a level in 0..={MAX_SUBDIVISION}")))),
                },
                _ => return Some(Err(bad(format!("unknown key `{key}` (known: clip, frames, subdiv)")))),
            }
        }
        Some(Ok(parsed))
    }

    /// Reads, subdivides and poses the animation: the rest mesh and its framed keyframes.
    pub fn open(&self, data: Option<&Path>) -> Result<(Mesh, Keyframes)> {
        let path = locate_file(&self.path, data)?;
        let mut animated = gltf_animation::read_animated(&path, &self.selection)?;
        if animated.clips.is_empty() {
            return Err(Error::input(
                path.display(),
                "has no animation clips to pose; name it without `#...` to load it as a static mesh",
            ));
        }
        if self.subdiv > 0 {
            animated = subdivide::loop_subdivide(&animated, self.subdiv)?;
        }
        let keyframes = Keyframes::of(&animated);
        if keyframes.len() > u16::MAX as usize {
            return Err(Error::input(
                path.display(),
                format!("{} keyframes in all; resample with frames=N (at most 65535)", keyframes.len()),
            ));
        }
        Ok((animated.mesh, keyframes))
    }
}
