//! Corpora: a `models` entry that names many meshes at once, expanded when a run starts.
//!
//! - a **directory** (`corpus/thingi/`): every OBJ, PLY, glTF and GLB file under it, at any depth;
//! - a **glob** (`corpus/*.ply`, `corpus/**/*.obj`): the mesh files it matches;
//! - a **list file** (`corpus.txt` or `corpus.list`): one model per line, as a spec would name it
//!   (a path, `PATH@N`, a procedural spec, an animation); blank lines and `#` comments skipped;
//!   a relative path is taken from the list file's folder when the file is there, else looked
//!   up like any model (so a list may name `models/bunny_2k.ply` in the data directory).
//!
//! Each is looked up as given, then in the data directory, like any model. The expanded models are
//! named so that they can be given again (`corpus/thingi/100349.ply`), sorted, so every shard of
//! a run expands an entry into the same list. A model the spec names itself must exist before any
//! work starts; a model that fails to load or measure, named or expanded, is recorded as an error
//! row and the run goes on: in ten thousand files of a public corpus some are broken, and one
//! must not sink the run.

use std::path::{Path, PathBuf};

use super::spec::Model;
use crate::mesh::Source;
use crate::mesh::source::AnimationSource;

/// The file extensions a directory or glob entry takes as meshes (any case).
const MESH_EXTENSIONS: &[&str] = &["obj", "ply", "gltf", "glb"];

/// Whether a `models` entry names a corpus by its form alone (a glob, a list file, a path ending
/// in `/`), before any file is looked at: what a spec's checks can know.
pub fn is_corpus(entry: &str) -> bool {
    entry.contains(['*', '?', '[']) || entry.ends_with('/') || list_file(Path::new(entry))
}

fn list_file(path: &Path) -> bool {
    path.extension().is_some_and(|e| e.eq_ignore_ascii_case("txt") || e.eq_ignore_ascii_case("list"))
}

fn mesh_file(path: &Path) -> bool {
    path.is_file() && path.extension().is_some_and(|e| MESH_EXTENSIONS.iter().any(|m| e.eq_ignore_ascii_case(m)))
}

/// Expands the corpus entries of `models` (`key` is how errors name the list, `models` or
/// `quick.models`); other models pass through, checked to exist (so a typo fails the run before
/// any work). A model named twice (by two entries, or twice in one list) is measured once.
pub fn expand(models: &[Model], data: Option<&Path>, key: &str) -> std::result::Result<Vec<Model>, String> {
    let mut out: Vec<Model> = Vec::new();
    let mut seen = std::collections::HashSet::new();
    for (i, model) in models.iter().enumerate() {
        let err = |problem: String| format!("{key}[{i}] `{}`: {problem}", model.name);
        let named = |out: &mut Vec<Model>| {
            model.source.check(data).map_err(|e| format!("{key}[{i}]: {e}"))?;
            out.push(model.clone());
            Ok::<_, String>(())
        };
        let Source::File(entry) = &model.source else {
            named(&mut out)?;
            continue;
        };
        let names = if entry.contains(['*', '?', '[']) {
            glob(entry, data).map_err(err)?
        } else if locate(entry, data).is_some_and(|found| found.is_dir()) {
            glob(&format!("{}/**/*", glob::Pattern::escape(entry.trim_end_matches('/'))), data).map_err(err)?
        } else if list_file(Path::new(entry)) {
            let found =
                locate(entry, data).ok_or_else(|| err("no such list file, here or in the data directory".into()))?;
            read_list(entry, &found, data).map_err(err)?
        } else {
            named(&mut out)?;
            continue;
        };
        if names.is_empty() {
            return Err(err("names no mesh file (OBJ, PLY, glTF or GLB)".into()));
        }
        for name in names {
            let source = Source::parse(&name).map_err(|e| err(e.to_string()))?;
            out.push(Model { name, source });
        }
    }
    out.retain(|m| seen.insert(m.name.clone()));
    Ok(out)
}

/// Where `entry` is: as given, else in `data`.
fn locate(entry: &str, data: Option<&Path>) -> Option<PathBuf> {
    let direct = Path::new(entry);
    if direct.exists() {
        return Some(direct.to_path_buf());
    }
    let inside = data?.join(entry);
    inside.exists().then_some(inside)
}

/// The mesh files `pattern` matches, as given or else inside `data`, named as `pattern` names
/// them (relative to the data directory when found there), sorted.
fn glob(pattern: &str, data: Option<&Path>) -> std::result::Result<Vec<String>, String> {
    let matches = |root: Option<&Path>| -> std::result::Result<Vec<String>, String> {
        let full = match root {
            Some(dir) => format!("{}/{pattern}", glob::Pattern::escape(&dir.to_string_lossy())),
            None => pattern.to_string(),
        };
        let paths = glob::glob(&full).map_err(|e| format!("is not a valid glob: {e}"))?;
        let mut names = Vec::new();
        for path in paths {
            let path = path.map_err(|e| format!("cannot list {}: {}", e.path().display(), e.error()))?;
            if !mesh_file(&path) {
                continue;
            }
            let name = match root {
                Some(dir) => path.strip_prefix(dir).unwrap_or(&path).to_path_buf(),
                None => path,
            };
            names.push(name.to_string_lossy().into_owned());
        }
        names.sort();
        Ok(names)
    };
    let here = matches(None)?;
    match data {
        Some(dir) if here.is_empty() && Path::new(pattern).is_relative() => matches(Some(dir)),
        _ => Ok(here),
    }
}

/// The models of the list file `entry` (found at `found`), relative paths joined to the folder
/// `entry` names where the file is there, so the names resolve as the entry did.
fn read_list(entry: &str, found: &Path, data: Option<&Path>) -> std::result::Result<Vec<String>, String> {
    let text = std::fs::read_to_string(found).map_err(|e| format!("cannot read the list: {e}"))?;
    let text = text.strip_prefix('\u{feff}').unwrap_or(&text);
    let folder = Path::new(entry).parent().unwrap_or(Path::new(""));
    let mut names = Vec::new();
    for (n, line) in text.lines().enumerate() {
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let source = Source::parse(line).map_err(|e| format!("line {}: {e}", n + 1))?;
        names.push(rebase(source, folder, data).to_string());
    }
    Ok(names)
}

/// `source` with a relative file path joined to `folder` where the file is there.
fn rebase(source: Source, folder: &Path, data: Option<&Path>) -> Source {
    let join = |path: String| {
        let joined = folder.join(&path).to_string_lossy().into_owned();
        if Path::new(&path).is_relative() && !folder.as_os_str().is_empty() && locate(&joined, data).is_some() {
            joined
        } else {
            path
        }
    };
    match source {
        Source::File(path) => Source::File(join(path)),
        Source::Simplified { base, target } => {
            Source::Simplified { base: Box::new(rebase(*base, folder, data)), target }
        }
        Source::Animation(a) => Source::Animation(AnimationSource { path: join(a.path.clone()), ..a }),
        procedural => procedural,
    }
}
