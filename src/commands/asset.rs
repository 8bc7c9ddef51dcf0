//! `order`'s output: the input asset with its triangles reordered draw call by draw call, and
//! everything else kept. Same format in and out keeps everything (glTF and GLB rewritten in place,
//! OBJ and PLY with their face lines or records moved whole); a conversion keeps one mesh and
//! lists, in one warning, what the output cannot hold (`--strict` makes that an error and writes
//! nothing).

use std::path::Path;

use triorder::mesh::{Mesh, Scene, gltf, obj, ply, save};
use triorder::order::{self, Resolved};
use triorder::{Error, Result};

/// The file kinds `order` reads and writes, by extension.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Kind {
    Gltf { binary: bool },
    Obj,
    Ply,
}

fn kind_of(path: &Path) -> Option<Kind> {
    match path.extension()?.to_string_lossy().to_ascii_lowercase().as_str() {
        "glb" => Some(Kind::Gltf { binary: true }),
        "gltf" => Some(Kind::Gltf { binary: false }),
        "obj" => Some(Kind::Obj),
        "ply" => Some(Kind::Ply),
        _ => None,
    }
}

/// Whether `order` can write `output`'s format.
pub fn writable(output: &Path) -> bool {
    kind_of(output).is_some()
}

/// What writing did besides the file: notes for the user, and the ordering's time.
pub struct Written {
    pub notes: Vec<String>,
    pub seconds: f64,
}

/// Writes `scene` (loaded from `input`, if a file) to `output` with each draw call ordered by
/// `resolved`, vertices renumbered in first-use order when `remap`.
pub fn write(
    input: Option<&Path>,
    scene: &Scene,
    output: &Path,
    resolved: &Resolved,
    remap: bool,
    strict: bool,
) -> Result<Written> {
    let out_kind = kind_of(output)
        .ok_or_else(|| Error::output(output, "unknown output format (use .glb, .gltf, .obj or .ply)"))?;
    let in_kind = input.and_then(kind_of);
    let read = |path: &Path| std::fs::read(path).map_err(|e| Error::input(path.display(), format!("cannot read: {e}")));
    let start = std::time::Instant::now();
    match (input, in_kind, out_kind) {
        (Some(input), Some(Kind::Gltf { binary }), Kind::Gltf { binary: out_binary }) => {
            if binary != out_binary {
                return Err(Error::output(
                    output,
                    "write a .glb from a .glb and a .gltf from a .gltf: `order` rewrites an asset in place and does not convert between the two",
                ));
            }
            let bytes = read(input)?;
            let mut order_one = |mesh: Mesh| -> Result<Vec<u32>> {
                let orders = order::run(resolved, &Scene::still(mesh))?;
                let buffer = orders
                    .single()
                    .ok_or_else(|| order::needs_one_order(resolved.method.name, "`order` cannot write it"))?;
                Ok(buffer.order.clone())
            };
            let origin = input.display().to_string();
            let rewritten = gltf::rewrite(&bytes, &origin, input.parent(), binary, output, remap, &mut order_one)?;
            let seconds = start.elapsed().as_secs_f64();
            let folder = output.parent().unwrap_or(Path::new(""));
            let beside: Vec<_> = rewritten.beside.iter().map(|(name, data)| (folder.join(name), data)).collect();
            let mut files: Vec<(&Path, triorder::atomic::Fill<'_>)> =
                vec![(output, Box::new(|out: &mut dyn std::io::Write| out.write_all(&rewritten.main)))];
            for (path, data) in &beside {
                files.push((path.as_path(), Box::new(move |out: &mut dyn std::io::Write| out.write_all(data))));
            }
            triorder::atomic::write_all(files)?;
            let mut notes = rewritten.notes;
            notes.insert(
                0,
                format!("{} primitive(s) reordered, each on its own; everything else kept", rewritten.reordered),
            );
            Ok(Written { notes, seconds })
        }
        (Some(input), Some(Kind::Obj), Kind::Obj) => {
            let order = per_draw_call(resolved, scene)?;
            let seconds = start.elapsed().as_secs_f64();
            let lost = if remap {
                vec!["--remap-vertices: OBJ numbers positions, normals and texture coordinates apart, so its `v` lines keep their order".to_string()]
            } else {
                Vec::new()
            };
            refuse_or_warn(input, output, &lost, strict)?;
            let (bytes, notes) = obj::reorder(&read(input)?, &input.display().to_string(), &order)?;
            triorder::atomic::write_with(output, |out| out.write_all(&bytes))?;
            Ok(Written { notes, seconds })
        }
        (Some(input), Some(Kind::Ply), Kind::Ply) if !remap => {
            let order = per_draw_call(resolved, scene)?;
            let seconds = start.elapsed().as_secs_f64();
            let (bytes, notes) = ply::reorder(&read(input)?, &input.display().to_string(), &order)?;
            triorder::atomic::write_with(output, |out| out.write_all(&bytes))?;
            Ok(Written { notes, seconds })
        }
        _ => {
            let order = per_draw_call(resolved, scene)?;
            let seconds = start.elapsed().as_secs_f64();
            let mut mesh = scene.mesh.reordered(&order);
            if remap {
                mesh = mesh.remap_vertices_first_use();
            }
            let source = input.unwrap_or(Path::new(&scene.mesh.name));
            let mut lost = match (input, in_kind) {
                (Some(input), Some(kind)) => held_beyond_a_mesh(input, kind, scene)?,
                _ => Vec::new(),
            };
            if strict {
                lost.extend(save::would_drop(&mesh, output)?);
                refuse_or_warn(source, output, &lost, true)?;
            }
            // Streamed to its temporary: a large mesh is never held twice in memory.
            let saved = save::save(&mesh, output)?;
            lost.extend(saved.dropped);
            refuse_or_warn(source, output, &lost, false)?;
            Ok(Written { notes: Vec::new(), seconds })
        }
    }
}

/// The scene's order with each draw call ordered on its own.
fn per_draw_call(resolved: &Resolved, scene: &Scene) -> Result<Vec<u32>> {
    let orders = order::draw_calls::run(resolved, scene)?;
    let buffer =
        orders.single().ok_or_else(|| order::needs_one_order(resolved.method.name, "`order` cannot write it"))?;
    Ok(buffer.order.clone())
}

/// What `input` holds that one mesh in another format cannot: a glTF's nodes, skins,
/// animations, materials…; an OBJ's groups and materials; what the loader left out.
fn held_beyond_a_mesh(input: &Path, kind: Kind, scene: &Scene) -> Result<Vec<String>> {
    let bytes = std::fs::read(input).map_err(|e| Error::input(input.display(), format!("cannot read: {e}")))?;
    let origin = input.display().to_string();
    let mut held = match kind {
        Kind::Gltf { binary } => gltf::contents(&bytes, &origin, input.parent(), binary)?,
        Kind::Obj => obj_statements(&bytes),
        Kind::Ply => Vec::new(),
    };
    if !matches!(kind, Kind::Gltf { .. }) && scene.draw_calls.len() > 1 {
        held.push(format!("{} draw calls merged into one", scene.draw_calls.len()));
    }
    held.extend(triorder::mesh::load::load_file_with_report(input)?.1.dropped);
    Ok(held)
}

/// An OBJ's statements that only an OBJ holds: materials, objects and groups, smoothing groups.
fn obj_statements(bytes: &[u8]) -> Vec<String> {
    let text = String::from_utf8_lossy(bytes);
    let count = |keyword: &str| text.lines().filter(|l| l.split_whitespace().next() == Some(keyword)).count();
    [
        (count("mtllib"), "material librar(ies) (mtllib)"),
        (count("usemtl"), "material assignment(s) (usemtl)"),
        (count("o") + count("g"), "object and group statement(s) (o, g)"),
        (count("s"), "smoothing group statement(s) (s)"),
    ]
    .into_iter()
    .filter(|(n, _)| *n > 0)
    .map(|(n, what)| format!("{n} {what}"))
    .collect()
}

/// `lost` (what `output` cannot hold of `input`) as one warning, or with `strict` an error
/// before anything is written.
fn refuse_or_warn(input: &Path, output: &Path, lost: &[String], strict: bool) -> Result<()> {
    if lost.is_empty() {
        return Ok(());
    }
    let list = lost.join("; ");
    if strict {
        return Err(Error::output(
            output,
            format!("--strict: it cannot hold everything {} does, so nothing was written: {list}", input.display()),
        ));
    }
    eprintln!(
        "warning: {} cannot hold everything {} does; not written: {list} (--strict makes this an error)",
        output.display(),
        input.display()
    );
    Ok(())
}
