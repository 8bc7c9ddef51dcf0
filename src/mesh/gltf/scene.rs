//! The scene: its mesh nodes and their primitives, node transforms (checked to form a tree),
//! and the joint matrices of skins.

use std::collections::BTreeSet;

use ::gltf::Document;
use ::gltf::accessor::{DataType, Dimensions};
use ::gltf::mesh::Mode;
use glam::Mat4;

use super::accessors::accessor_values;
use super::primitive::Part;
use crate::mesh::load::LoadReport;

/// One triangle primitive of a mesh node of the scene, read but not yet placed.
pub(super) struct ScenePart<'a> {
    pub(super) node: ::gltf::Node<'a>,
    pub(super) primitive: ::gltf::Primitive<'a>,
    /// "mesh M primitive P", to name the primitive in errors.
    pub(super) at: String,
    pub(super) part: Part,
}

/// Every triangle primitive of every mesh node of the scene, in node and primitive order, with
/// its skinning attributes if its node has a skin. Point and line primitives, and attributes not
/// loaded, are noted in `report`. Fails if no primitive has a triangle.
pub(super) fn scene_parts<'a>(
    document: &'a Document,
    buffers: &[Vec<u8>],
    report: &mut LoadReport,
) -> std::result::Result<Vec<ScenePart<'a>>, String> {
    let mut parts = Vec::new();
    let mut unloaded = BTreeSet::new();
    // Instancing reuses one accessor under many nodes, so a few kilobytes can describe any
    // number of triangles: the merged mesh is held to what a spec may ask for.
    let mut total = 0u64;
    for node in scene_nodes(document)? {
        let Some(mesh) = node.mesh() else { continue };
        for primitive in mesh.primitives() {
            let at = format!("mesh {} primitive {}", mesh.index(), primitive.index());
            match primitive.mode() {
                Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan => {}
                mode => {
                    report.dropped.push(format!("{at}: {mode:?} primitive skipped (only triangles are loaded)"));
                    continue;
                }
            }
            let part = Part::read(&primitive, buffers, &at, node.skin().is_some(), &mut unloaded)?;
            total += part.triangles.len() as u64;
            if total > crate::mesh::procedural::MAX_TRIANGLES {
                return Err(format!(
                    "{at} (node {}): the scene's instances add up to more than {} triangles, the most triorder loads",
                    node.index(),
                    crate::mesh::procedural::MAX_TRIANGLES
                ));
            }
            parts.push(ScenePart { node: node.clone(), primitive, at, part });
        }
    }
    if !unloaded.is_empty() {
        let names: Vec<String> = unloaded.into_iter().collect();
        report.dropped.push(format!("attributes not loaded: {}", names.join(", ")));
    }
    if parts.iter().all(|p| p.part.triangles.is_empty()) {
        return Err("no triangles: the scene has no triangle primitive with faces".into());
    }
    Ok(parts)
}

/// Every node's world transform at rest.
pub(super) fn world_transforms(document: &Document) -> std::result::Result<Vec<Mat4>, String> {
    let hierarchy = Hierarchy::of(document)?;
    Ok(hierarchy.world(&local_transforms(document)?))
}

/// Every node's own transform (its matrix, or its translation, rotation and scale composed).
pub(super) fn local_transforms(document: &Document) -> std::result::Result<Vec<Mat4>, String> {
    document
        .nodes()
        .map(|node| {
            let matrix = Mat4::from_cols_array_2d(&node.transform().matrix());
            match matrix.is_finite() {
                true => Ok(matrix),
                false => Err(format!("node {}: its transform has a non-finite value", node.index())),
            }
        })
        .collect()
}

/// The node tree: each node's parent, and every node listed after its parent.
pub(super) struct Hierarchy {
    parent: Vec<Option<usize>>,
    parents_first: Vec<usize>,
}

impl Hierarchy {
    /// glTF node hierarchies must be trees: a node with two parents would be drawn twice and a
    /// cycle has no root, so both are refused.
    pub(super) fn of(document: &Document) -> std::result::Result<Hierarchy, String> {
        let count = document.nodes().len();
        let mut parent: Vec<Option<usize>> = vec![None; count];
        let mut children: Vec<Vec<usize>> = vec![Vec::new(); count];
        for node in document.nodes() {
            for child in node.children() {
                let slot = parent
                    .get_mut(child.index())
                    .ok_or_else(|| format!("node {}: no child {}", node.index(), child.index()))?;
                if let Some(other) = slot.replace(node.index()) {
                    return Err(format!(
                        "node {}: it is a child of both node {other} and node {}",
                        child.index(),
                        node.index()
                    ));
                }
                children[node.index()].push(child.index());
            }
        }
        // Every node has at most one parent, so the nodes no root reaches are on or below a cycle.
        let mut parents_first = Vec::with_capacity(count);
        let mut stack: Vec<usize> = (0..count).rev().filter(|&n| parent[n].is_none()).collect();
        while let Some(n) = stack.pop() {
            parents_first.push(n);
            stack.extend(children[n].iter().rev());
        }
        if parents_first.len() < count {
            let mut reached = vec![false; count];
            parents_first.iter().for_each(|&n| reached[n] = true);
            let first = reached.iter().position(|&r| !r).unwrap_or_default();
            return Err(format!("node {first}: the node hierarchy has a cycle"));
        }
        Ok(Hierarchy { parent, parents_first })
    }

    /// The world transforms of nodes whose own transforms are `local` (one per node).
    pub(super) fn world(&self, local: &[Mat4]) -> Vec<Mat4> {
        let mut world = local.to_vec();
        for &n in &self.parents_first {
            if let Some(p) = self.parent[n] {
                world[n] = world[p] * local[n];
            }
        }
        world
    }
}

/// The nodes of the default scene (of every scene if none is the default), parents first.
fn scene_nodes(document: &Document) -> std::result::Result<Vec<::gltf::Node<'_>>, String> {
    let scenes: Vec<::gltf::Scene<'_>> = match document.default_scene() {
        Some(scene) => vec![scene],
        None => document.scenes().collect(),
    };
    if scenes.is_empty() {
        return Err("no scene: the file defines no scenes to take meshes from".into());
    }
    let mut out = Vec::new();
    for scene in scenes {
        let mut seen = vec![false; document.nodes().len()];
        let mut stack: Vec<::gltf::Node<'_>> = scene.nodes().collect::<Vec<_>>().into_iter().rev().collect();
        while let Some(node) = stack.pop() {
            match seen.get_mut(node.index()) {
                Some(s) if !*s => *s = true,
                _ => {
                    return Err(format!("scene {}: node {} is listed twice", scene.index(), node.index()));
                }
            }
            stack.extend(node.children().collect::<Vec<_>>().into_iter().rev());
            out.push(node);
        }
    }
    Ok(out)
}

/// Each joint's skinning matrix at rest: its node's world transform times its inverse bind
/// matrix.
pub(super) fn joint_matrices(
    skin: &::gltf::Skin<'_>,
    world: &[Mat4],
    buffers: &[Vec<u8>],
) -> std::result::Result<Vec<Mat4>, String> {
    let inverse_bind = inverse_bind_matrices(skin, buffers)?;
    Ok(skin
        .joints()
        .zip(inverse_bind)
        .map(|(j, ibm)| world.get(j.index()).copied().unwrap_or(Mat4::IDENTITY) * ibm)
        .collect())
}

/// A skin's inverse bind matrices, one per joint (identity when the skin gives none).
pub(super) fn inverse_bind_matrices(
    skin: &::gltf::Skin<'_>,
    buffers: &[Vec<u8>],
) -> std::result::Result<Vec<Mat4>, String> {
    let joints = skin.joints().len();
    let Some(accessor) = skin.inverse_bind_matrices() else { return Ok(vec![Mat4::IDENTITY; joints]) };
    if accessor.dimensions() != Dimensions::Mat4 || accessor.data_type() != DataType::F32 {
        return Err(format!(
            "skin {}: inverse bind matrix accessor {} is not MAT4 of floats",
            skin.index(),
            accessor.index()
        ));
    }
    if accessor.count() < joints {
        return Err(format!(
            "skin {}: inverse bind matrix accessor {} has {} matrices for {joints} joints",
            skin.index(),
            accessor.index(),
            accessor.count(),
        ));
    }
    let values = accessor_values(&accessor, buffers, 16)?;
    Ok(values
        .chunks_exact(16)
        .take(joints)
        .map(|m| Mat4::from_cols_slice(&m.iter().map(|&v| v as f32).collect::<Vec<_>>()))
        .collect())
}
