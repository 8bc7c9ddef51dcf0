//! Ordering an asset as an engine draws it: each draw call (a glTF primitive, a run of OBJ faces
//! with one group and material) on its own, the calls kept in their sequence.
//!
//! An engine cannot interleave the triangles of two draw calls: each is its own index range
//! bound with its own material. So an ordering that would be free to move triangles between
//! calls measures an asset nobody can draw; here every call is ordered as a mesh of its own
//! (with the whole vertex array, so vertex ids are the asset's), and the buffers are joined in
//! the calls' order, each call one cluster or more. The papers order whole meshes, which is what
//! [`super::run`] does; this is `triorder order`'s way and `eval --draw-calls`'.

use std::collections::HashMap;
use std::ops::Range;

use super::{Clustered, Orders, Resolved};
use crate::error::{Error, Result};
use crate::mesh::{Mesh, Scene};

/// The order of `scene` with each of its draw calls ordered on its own by `resolved`, or the
/// whole mesh when it is one call. Static meshes and static methods only: a method that picks a
/// buffer per (keyframe, view), or a scene of keyframes or levels, is refused.
pub fn run(resolved: &Resolved, scene: &Scene) -> Result<Orders> {
    let calls = &scene.draw_calls;
    if calls.len() <= 1 {
        return super::run(resolved, scene);
    }
    if resolved.method.per_node || scene.frames.len() != 1 {
        return Err(Error::usage(format!(
            "{}: ordering each draw call on its own needs a static mesh and a method that gives one order",
            resolved.method.name
        )));
    }
    let (mut order, mut starts) = (Vec::with_capacity(scene.mesh.triangle_count()), vec![0]);
    for call in calls {
        let part = call_scene(&scene.mesh, call.clone());
        let orders = super::run(resolved, &part)?;
        let buffer = orders.single().ok_or_else(|| super::needs_one_order(resolved.method.name, "a draw call"))?;
        order.extend(buffer.order.iter().map(|&t| t + call.start as u32));
        starts.extend(buffer.starts[1..].iter().map(|&s| s + call.start));
    }
    Ok(Orders::from(Clustered { order, starts }))
}

/// The draw call `call` of `mesh` as a scene of its own: its triangles over the vertices they
/// use, numbered in order of first use, so a call costs its own size and not the asset's.
fn call_scene(mesh: &Mesh, call: Range<usize>) -> Scene {
    let mut local: HashMap<u32, u32> = HashMap::new();
    let mut positions = Vec::new();
    let triangles = mesh.triangles[call]
        .iter()
        .map(|t| {
            t.map(|v| {
                *local.entry(v).or_insert_with(|| {
                    positions.push(mesh.positions[v as usize]);
                    positions.len() as u32 - 1
                })
            })
        })
        .collect();
    Scene::still(Mesh { name: mesh.name.clone(), positions, triangles, attributes: Default::default() })
}
