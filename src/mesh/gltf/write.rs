//! Writing a mesh as a binary glTF (GLB).

use std::io::{self, Write};

use crate::mesh::Mesh;

/// Writes `mesh` as a GLB with one mesh, one node, one triangle primitive: `POSITION` (with
/// min/max), `NORMAL`, `TEXCOORD_0`, `COLOR_0` (float RGBA) and each extra attribute as a
/// scalar float `_NAME` attribute, and `u32` indices in draw order, winding kept. Everything is
/// stored as 32-bit floats or integers, so reading it back gives the same bits. GLB holds every
/// attribute the mesh has, so nothing is dropped.
pub fn write(mesh: &Mesh, out: &mut dyn Write) -> io::Result<Vec<String>> {
    write_levels(mesh, &[(String::new(), &mesh.triangles)], out)
}

/// Writes `mesh`'s vertices once with one index buffer per entry of `levels` (a name and
/// triangles indexing `mesh`'s vertices), as [`write`] does for one: the levels of a progressive
/// mesh, which share their vertices. Level i is mesh i, drawn by node i, alone in scene i (named
/// for the level); scene 0, the default, is the first level, so a viewer shows that one and an
/// engine picks the others by scene or node. The names go in each scene and mesh.
pub fn write_levels(mesh: &Mesh, levels: &[(String, &[[u32; 3]])], out: &mut dyn Write) -> io::Result<Vec<String>> {
    let a = &mesh.attributes;
    let mut bin: Vec<u8> = Vec::new();
    let mut views = Vec::new();
    let mut accessors = Vec::new();
    let mut attributes = serde_json::Map::new();
    // Every element is a 4-byte float or integer, so each view starts 4-byte aligned.
    let mut add = |floats: &mut dyn Iterator<Item = f32>, kind: &str, semantic: &str, extra: serde_json::Value| {
        let start = bin.len();
        floats.for_each(|f| bin.extend_from_slice(&f.to_le_bytes()));
        views.push(
            serde_json::json!({"buffer": 0, "byteOffset": start, "byteLength": bin.len() - start, "target": 34962}),
        );
        let mut accessor = serde_json::json!({
            "bufferView": views.len() - 1, "componentType": 5126, "count": mesh.vertex_count(), "type": kind
        });
        if let (Some(target), serde_json::Value::Object(more)) = (accessor.as_object_mut(), extra) {
            target.extend(more);
        }
        accessors.push(accessor);
        attributes.insert(semantic.to_string(), (accessors.len() - 1).into());
    };
    let (min, max) = mesh.bounds();
    add(
        &mut mesh.positions.iter().flat_map(|p| p.to_array()),
        "VEC3",
        "POSITION",
        serde_json::json!({"min": min.to_array(), "max": max.to_array()}),
    );
    if let Some(n) = &a.normals {
        add(&mut n.iter().flatten().copied(), "VEC3", "NORMAL", serde_json::Value::Null);
    }
    if let Some(t) = &a.uvs {
        add(&mut t.iter().flatten().copied(), "VEC2", "TEXCOORD_0", serde_json::Value::Null);
    }
    if let Some(c) = &a.colors {
        add(&mut c.iter().flatten().copied(), "VEC4", "COLOR_0", serde_json::Value::Null);
    }
    for e in &a.extra {
        add(&mut e.values.iter().copied(), "SCALAR", &format!("_{}", e.name), serde_json::Value::Null);
    }
    let (mut scenes, mut nodes, mut meshes) = (Vec::new(), Vec::new(), Vec::new());
    for (i, (name, triangles)) in levels.iter().enumerate() {
        let start = bin.len();
        triangles.iter().flatten().for_each(|v| bin.extend_from_slice(&v.to_le_bytes()));
        views.push(
            serde_json::json!({"buffer": 0, "byteOffset": start, "byteLength": bin.len() - start, "target": 34963}),
        );
        accessors.push(serde_json::json!({
            "bufferView": views.len() - 1, "componentType": 5125, "count": triangles.len() * 3, "type": "SCALAR"
        }));
        let primitive = serde_json::json!({"attributes": attributes, "indices": accessors.len() - 1, "mode": 4});
        let (mut scene, mut named) = (serde_json::json!({"nodes": [i]}), mesh.name.clone());
        if !name.is_empty() {
            scene["name"] = name.as_str().into();
            named = format!("{named} ({name})");
        }
        scenes.push(scene);
        nodes.push(serde_json::json!({"mesh": i}));
        meshes.push(serde_json::json!({"name": named, "primitives": [primitive]}));
    }

    let json = serde_json::json!({
        "asset": {"version": "2.0", "generator": "triorder"},
        "scene": 0,
        "scenes": scenes,
        "nodes": nodes,
        "meshes": meshes,
        "accessors": accessors,
        "bufferViews": views,
        "buffers": [{"byteLength": bin.len()}],
    });
    let json = serde_json::to_vec(&json).map_err(io::Error::other)?;
    let glb = ::gltf::binary::Glb {
        header: ::gltf::binary::Header { magic: *b"glTF", version: 2, length: 0 },
        json: json.into(),
        bin: Some(bin.into()),
    };
    glb.to_writer(out).map_err(|e| io::Error::other(e.to_string()))?;
    Ok(Vec::new())
}
