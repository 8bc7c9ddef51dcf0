//! Naming meshes: a procedural spec (`grid:16x8`), a path, or a path inside the data directory,
//! optionally simplified to N triangles with an `@N` suffix (`models/bun_zipper.ply@20000`), or an
//! animation (`PATH#clip=NAME`). A name is parsed once, at the edge, into a [`Source`]; nothing
//! further in looks at the string again.
//!
//! Experiments name models relative to a data directory (`models/bunny_2k.ply`) so the same spec
//! works for every user. The data directory is `--data DIR`, else `$TRIORDER_DATA`, else
//! `../shared/data` when it exists (this repository's sibling checkout); see README.md and
//! scripts/fetch-data.sh for getting the public models.

use std::fmt;
use std::path::{Path, PathBuf};

use crate::error::{Error, Result};
use crate::mesh::frames::Frames;
use crate::mesh::gltf::animation::{self as gltf_animation, ClipSelection};
use crate::mesh::scene::Scene;
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

/// A mesh source as the user wrote it, parsed once: what to read or build, and how.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Source {
    /// A procedural mesh: `grid:16x8`, `disk:950`, `sphere:2000`, `helix:3`, `layers:4`.
    Procedural(String),
    /// A file (OBJ, PLY, glTF/GLB), found as given or in the data directory.
    File(String),
    /// A mesh simplified to about `target` triangles: `PATH@N` or `SPEC@N`.
    Simplified { base: Box<Source>, target: usize },
    /// A skinned glTF/GLB posed at its keyframes: `PATH#clip=NAME,frames=N,subdiv=L`.
    Animation(AnimationSource),
}

impl Source {
    /// Parses `text`, checking its syntax (a procedural spec's numbers, `@N`, the animation
    /// keys) but touching no file.
    pub fn parse(text: &str) -> Result<Source> {
        if let Some(animation) = AnimationSource::parse(text) {
            return animation.map(Source::Animation);
        }
        if let Some((base, count)) = parse_simplified(text) {
            let target = parse_target(text, count)?;
            return Ok(Source::Simplified { base: Box::new(Source::parse(base)?), target });
        }
        match procedural::check(text) {
            Some(checked) => checked.map(|()| Source::Procedural(text.to_string())),
            None => Ok(Source::File(text.to_string())),
        }
    }

    /// Checks that the source can be opened, without reading or building it: a file that exists,
    /// or an animation whose file has the clip it names (read, not posed). Lets a long run fail
    /// before any work.
    pub fn check(&self, data: Option<&Path>) -> Result<()> {
        match self {
            Source::Procedural(_) => Ok(()),
            Source::File(path) => locate_file(path, data).map(drop),
            Source::Simplified { base, .. } => base.check(data),
            Source::Animation(a) => gltf_animation::check_selection(&locate_file(&a.path, data)?, &a.selection),
        }
    }

    /// Reads or builds the mesh and derives what orderings and measurements need. `seed` drives
    /// seeded generators (`disk:N`).
    pub fn open(&self, data: Option<&Path>, seed: u64) -> Result<Scene> {
        match self {
            Source::Animation(animation) => {
                let (mesh, frames) = animation.open(data)?;
                Ok(Scene::animated(mesh, frames))
            }
            Source::File(path) => {
                let (mesh, draw_calls) = load::load_file_with_draw_calls(&locate_file(path, data)?)?;
                Ok(Scene { draw_calls, ..Scene::still(mesh) })
            }
            _ => Ok(Scene::still(self.mesh(data, seed)?)),
        }
    }

    /// The static mesh: for an animation, its rest mesh (subdivided if it says so).
    pub fn mesh(&self, data: Option<&Path>, seed: u64) -> Result<Mesh> {
        match self {
            Source::Procedural(spec) => procedural::generate(spec, seed).expect("parsed as procedural"),
            Source::File(path) => load::load_file(&locate_file(path, data)?),
            Source::Simplified { base, target } => simplify::simplify(&base.mesh(data, seed)?, *target),
            Source::Animation(animation) => Ok(animation.open(data)?.0),
        }
    }

    /// The file a file source names, found as [`Source::open`] finds it; `None` for any other
    /// source (procedural, simplified, animated).
    pub fn file(&self, data: Option<&Path>) -> Option<Result<PathBuf>> {
        match self {
            Source::File(path) => Some(locate_file(path, data)),
            _ => None,
        }
    }

    pub fn is_animation(&self) -> bool {
        matches!(self, Source::Animation(_))
    }

    /// True for what a fresh clone has: procedural meshes and files under `assets/`.
    pub fn is_bundled(&self) -> bool {
        match self {
            Source::Procedural(_) => true,
            Source::File(path) => path.starts_with("assets/"),
            Source::Simplified { base, .. } => base.is_bundled(),
            Source::Animation(a) => a.path.starts_with("assets/"),
        }
    }

    /// The source without its `@N` resolution: the series of a resolution sweep.
    pub fn base(&self) -> &Source {
        match self {
            Source::Simplified { base, .. } => base,
            other => other,
        }
    }

    /// The value of an animation key (`clip`, `frames`, `subdiv`), defaults written out (clip
    /// `all`, subdiv `0`); `None` for a static mesh, a key left to the keyframes (`frames`), or an
    /// unknown key.
    pub fn key(&self, key: &str) -> Option<String> {
        let Source::Animation(a) = self else { return None };
        match key {
            "clip" => Some(a.selection.clip.clone().unwrap_or_else(|| "all".to_string())),
            "frames" => a.selection.frames.map(|n| n.to_string()),
            "subdiv" => Some(a.subdiv.to_string()),
            _ => None,
        }
    }
}

/// Splits `PATH@N` into the base source and the triangle count; `None` when `source` has no such
/// suffix (in a file name, an `@` followed by something other than digits is part of the name;
/// after a procedural spec it can only be a count, checked by [`parse_target`]).
fn parse_simplified(source: &str) -> Option<(&str, &str)> {
    let (base, count) = source.rsplit_once('@')?;
    let digits = !count.is_empty() && count.bytes().all(|b| b.is_ascii_digit());
    (digits || procedural::check(base).is_some()).then_some((base, count))
}

/// Checks the `N` of `PATH@N`: a positive triangle count.
fn parse_target(source: &str, count: &str) -> Result<usize> {
    match count.parse::<usize>() {
        Ok(n) if n > 0 => Ok(n),
        _ => Err(Error::input(source, format!("`@{count}`: the target triangle count must be a positive integer"))),
    }
}

/// The keys of an animated source a figure may read (`source:KEY`).
pub const KEYS: &[&str] = &["clip", "frames", "subdiv"];

/// Written back as it is parsed, so results name a source the way it can be given again.
impl fmt::Display for Source {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Source::Procedural(text) | Source::File(text) => f.write_str(text),
            Source::Simplified { base, target } => write!(f, "{base}@{target}"),
            Source::Animation(a) => {
                write!(f, "{}#clip={}", a.path, a.selection.clip.as_deref().unwrap_or("all"))?;
                if let Some(frames) = a.selection.frames {
                    write!(f, ",frames={frames}")?;
                }
                if a.subdiv > 0 {
                    write!(f, ",subdiv={}", a.subdiv)?;
                }
                Ok(())
            }
        }
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

const FRAMES: &str = "is not a count in 1..=65535";
const SUBDIV: &str = "is not a level in 0..=3";

/// A resampling count an animation may ask for: every frame must fit a 16-bit lookup.
pub fn check_frames(n: usize) -> std::result::Result<usize, String> {
    if (1..=u16::MAX as usize).contains(&n) { Ok(n) } else { Err(FRAMES.into()) }
}

/// A subdivision level an animation may ask for.
pub fn check_subdiv(level: u32) -> std::result::Result<u32, String> {
    if level <= MAX_SUBDIVISION { Ok(level) } else { Err(SUBDIV.into()) }
}

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
                "clip" => return Some(Err(bad("`clip=` names no clip (write clip=all for every clip)".into()))),
                "frames" => match value.parse::<usize>().map_err(|_| FRAMES.to_string()).and_then(check_frames) {
                    Ok(n) => parsed.selection.frames = Some(n),
                    Err(why) => return Some(Err(bad(format!("frames `{value}` {why}")))),
                },
                "subdiv" => match value.parse::<u32>().map_err(|_| SUBDIV.to_string()).and_then(check_subdiv) {
                    Ok(n) => parsed.subdiv = n,
                    Err(why) => return Some(Err(bad(format!("subdiv `{value}` {why}")))),
                },
                _ => return Some(Err(bad(format!("unknown key `{key}` (known: clip, frames, subdiv)")))),
            }
        }
        Some(Ok(parsed))
    }

    /// Reads, subdivides and poses the animation: the rest mesh and its framed keyframes.
    pub fn open(&self, data: Option<&Path>) -> Result<(Mesh, Frames)> {
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
        let frames = Frames::of(&animated);
        if frames.len() > u16::MAX as usize {
            return Err(Error::input(
                path.display(),
                format!("{} keyframes in all; resample with frames=N (at most 65535)", frames.len()),
            ));
        }
        Ok((animated.mesh, frames))
    }
}
