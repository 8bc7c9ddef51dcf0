//! glTF 2.0 (`.gltf` + buffers, or binary `.glb`): reading static meshes and writing GLB.
//!
//! The `gltf` crate parses and validates the JSON and loads the buffers; the accessor data is
//! decoded here. Its own readers assume a valid file: they index and subtract without checks
//! (a debug-build panic on a zero count, an element type that does not match the attribute, or a
//! stride too small), and return `None`, not an error, for data past the end of a buffer view.
//! Decoding here checks every byte range and says which accessor or buffer view is wrong; node
//! transforms are composed here too, refusing hierarchies that are not trees (the crate does not
//! check). Three more inputs make the `gltf` crate itself panic, so they are refused before it
//! sees them: a GLB header whose length field is below 12, a `POSITION` accessor index past the
//! end (its validator indexes without checking), and a buffer URI whose percent-escapes are not
//! UTF-8. [`animation`] reads skins and animations with the same pieces (parsing,
//! accessors, hierarchy, primitives), so its rest mesh is this reader's mesh before posing.

mod accessors;
pub mod animation;
mod document;
mod primitive;
mod rewrite;
mod scene;
mod write;

pub use rewrite::{Rewritten, contents, rewrite};
pub use write::{write, write_levels};

use std::collections::HashMap;
use std::collections::hash_map::Entry;
use std::path::Path;

use glam::Mat4;

use crate::error::{Error, Result};
use crate::mesh::Mesh;
use crate::mesh::load::LoadReport;
pub use document::allow_outside_uris;
use document::open;
use primitive::merge;
use scene::{ScenePart, joint_matrices, scene_parts, world_transforms};

/// Reads a glTF or GLB file. `base` is the directory external buffers are resolved from;
/// `binary` says the file was named `.glb`, so it must start with the GLB magic.
///
/// Every primitive of every mesh node of the default scene (of all scenes if none is the
/// default) is merged into one mesh, in node and primitive order, placed by its node's world
/// transform: positions by the matrix, normals by its inverse transpose (renormalised), and each
/// triangle's winding reversed where the matrix mirrors. Skinned meshes are posed at rest, as a
/// viewer shows the file with no animation playing: linear blend skinning with every joint at its
/// node's world transform (`JOINTS_n`/`WEIGHTS_n`, inverse bind matrices), the skinned node's own
/// transform ignored as the glTF spec requires; so skinned and rigid parts line up. Strips and
/// fans become triangle lists; point and line primitives are skipped and reported. Attributes:
/// `POSITION`, `NORMAL`, `TEXCOORD_0`, `COLOR_0` and scalar `_NAME` attributes (as extra
/// attribute `NAME`), each kept only if every primitive has it.
pub fn read(bytes: &[u8], origin: &str, base: Option<&Path>, binary: bool) -> Result<(Mesh, LoadReport)> {
    let fail = |problem: String| Error::input(origin, problem);
    let (document, buffers) = open(bytes, origin, base, binary)?;
    let mut report = LoadReport::default();
    let world = world_transforms(&document).map_err(fail)?;
    let mut skins: HashMap<usize, Vec<Mat4>> = HashMap::new();
    let mut parts = Vec::new();
    for ScenePart { node, at, part, .. } in scene_parts(&document, &buffers, &mut report).map_err(fail)? {
        parts.push(match node.skin() {
            Some(skin) => {
                let joints = match skins.entry(skin.index()) {
                    Entry::Occupied(known) => known.into_mut(),
                    Entry::Vacant(slot) => slot.insert(joint_matrices(&skin, &world, &buffers).map_err(fail)?),
                };
                part.skinned(joints, &at).map_err(fail)?
            }
            None => part.transformed(world[node.index()]),
        });
    }
    let (positions, triangles, attributes) = merge(parts, &mut report);
    Ok((Mesh::new(origin, positions, triangles, attributes)?, report))
}
